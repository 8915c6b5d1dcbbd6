// `pathex bias`, the check file's `missed` requirement and `pathex trace --missed` end to end:
// outputs, exact messages, exit codes, the JUnit report parsed back.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>
#include <pugixml.hpp>

#include "io/image_io.h"
#include "support/cli_run.h"

namespace {

using pathex::test::CliRun;
using pathex::test::run_pathex;
using pathex::test::scratch_dir;

std::string out_dir(const std::string& name) { return (scratch_dir() / name).string(); }

TEST(BiasCli, MirrorSceneTableAndOutputs) {
  const std::string dir = out_dir("mirror");
  const CliRun r = run_pathex("bias samples/scenes/point-mirror-caustic.json --renderer pt-nee --reference bdpt --spp 4 --out " + dir);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("pt-nee against the reference bdpt, rendered at 4 spp up to 16 interior vertices in "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\npt-nee misses "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("  LSDSDDSE    "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("chains SD(0..1) DSD(1..3)[mirror|manifold] DD(3..4) DS(4..5); its DD joins (c3..c4) are not "
                       "where pt-nee joins: (0, DD, 2..), (1, DD, 2..)\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  paths neither pt-nee nor bdpt can sample (their light is unknown, not 0), the shortest:\n"
                       "    LSDSDSE, chains SD(0..1) DSD(1..3)[mirror|manifold] DS(3..4); no DD join: the point light "
                       "fixes x0, x1 is specular and the pinhole camera fixes x2\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  light on paths with more than 16 interior vertices (the reference's bound, --reference-bounces)\n"),
            std::string::npos);
  for (const char* f : {"bias.json", "histogram.json", "classes.exr", "missed.exr", "missed.png", "total.png", "caustic.png"})
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + f)) << f;
  // missed.exr holds the one missed layer; classes.exr the total and the classes, not it.
  const auto missed = pathex::read_exr_layers(dir + "/missed.exr");
  ASSERT_TRUE(missed.ok());
  ASSERT_EQ(missed->size(), 1u);
  EXPECT_EQ((*missed)[0].name, "missed");
  const auto classes = pathex::read_exr_layers(dir + "/classes.exr");
  ASSERT_TRUE(classes.ok());
  for (const auto& l : *classes) EXPECT_NE(l.name, "missed");
  // bias.json: the missed light is the sum of its paths, and a share of the total.
  const nlohmann::json j = nlohmann::json::parse(pathex::test::read_file(dir + "/bias.json"));
  EXPECT_EQ(j["renderer"], "pt-nee");
  EXPECT_EQ(j["reference"]["name"], "bdpt");
  EXPECT_EQ(j["reference"]["max_bounces"], 16);
  EXPECT_EQ(j["missed"]["exact"], false);
  double sum = 0;
  for (const auto& p : j["paths"]) {
    EXPECT_EQ(p["verdict"], "unreachable");
    sum += p["luminance"].get<double>();
  }
  EXPECT_NEAR(j["missed"]["luminance"].get<double>(), sum, 1e-12);
  EXPECT_NEAR(j["missed"]["share"].get<double>(),
              j["missed"]["luminance"].get<double>() / j["total"]["luminance"].get<double>(), 1e-15);
  EXPECT_EQ(j["not_counted"]["neither"]["witnesses"][0]["path"], "LSDSDSE");
  // histogram.json is the reference's, with the missed class beside the user's.
  const nlohmann::json h = nlohmann::json::parse(pathex::test::read_file(dir + "/histogram.json"));
  EXPECT_EQ(h["renderer"], "bdpt");
  EXPECT_EQ(h["classes"].back()["name"], "missed");
  EXPECT_EQ(h["classes"].back()["luminance"], j["missed"]["luminance"]);
}

TEST(BiasCli, JsonOnStdoutAndTheExactZero) {
  const CliRun r = run_pathex("bias samples/scenes/cornell.json --renderer pt --spp 1 --resolution 8x8 --json --no-images --out " +
                              out_dir("cornell"));
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["missed"]["exact"], true);
  EXPECT_EQ(j["missed"]["luminance"], 0.0);
  EXPECT_TRUE(j["paths"].empty());
  EXPECT_FALSE(std::filesystem::exists(out_dir("cornell") + "/missed.exr"));
  const CliRun t = run_pathex("bias samples/scenes/cornell.json --renderer pt --spp 1 --resolution 8x8 --no-images --out " +
                              out_dir("cornell"));
  EXPECT_NE(t.out.find("pt misses nothing: it samples every path of the scene's universe up to 16 interior vertices "
                       "(the checker proves it), so the missed light is 0 exactly\n"),
            std::string::npos)
      << t.out;
}

TEST(BiasCli, BadInputIsLocated) {
  const CliRun bound = run_pathex("bias samples/scenes/cornell.json --renderer pbrt-v4-path --reference-bounces 5 --out " +
                                  out_dir("bound"));
  EXPECT_EQ(bound.code, 2);
  EXPECT_EQ(bound.err,
            "pathex: error: --reference-bounces 5 must exceed pbrt-v4-path's bound of 5 interior vertices, or the light "
            "beyond that bound could not be counted\n");
  const std::string classes = out_dir("missed-class.json");
  std::ofstream(classes) << R"({"classes": [{"name": "glass", "expr": "$caustic"}, {"name": "missed", "expr": "L.*E"}]})";
  const CliRun reserved = run_pathex("bias samples/scenes/cornell.json --renderer pt --classes " + classes + " --out " +
                                     out_dir("reserved"));
  EXPECT_EQ(reserved.code, 2);
  EXPECT_EQ(reserved.err, "pathex: error: " + classes +
                              ":/classes/1/name: the class name 'missed' is reserved for what the renderer misses "
                              "(missed.exr), expected another name\n");
}

TEST(BiasCli, TraceMissedLine) {
  const CliRun r = run_pathex("trace samples/scenes/point-mirror-caustic.json --renderer pt-nee --spp 4 --missed --reference bdpt --out " +
                              out_dir("trace"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\nthis renderer cannot sample 69."), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" of what bdpt finds (luminance "), std::string::npos) << r.out;
  const CliRun cornell =
      run_pathex("trace --renderer pt --spp 1 --resolution 8x8 --missed --reference bdpt --no-images --out " + out_dir("trace2"));
  // pt rendered up to trace's bound of 16 misses the light beyond it, which the reference finds (up to 24).
  EXPECT_NE(cornell.out.find("\nthis renderer cannot sample "), std::string::npos) << cornell.out;
  const nlohmann::json j = nlohmann::json::parse(pathex::test::read_file(out_dir("trace2") + "/missed.json"));
  EXPECT_EQ(j["reference"]["name"], "bdpt");
  EXPECT_EQ(j["reference"]["max_bounces"], 24);  // trace's bound 16, plus 8
  EXPECT_EQ(j["missed"]["exact"], false);
  const CliRun shard = run_pathex("trace --spp 2 --shard 0/2 --missed --out " + out_dir("trace3"));
  EXPECT_EQ(shard.code, 2);
  EXPECT_EQ(shard.err, "pathex: error: --missed measures a whole render in one process: it cannot be given with --shard, "
                       "--resume or MPI\n");
  EXPECT_EQ(run_pathex("trace --reference bdpt --out " + out_dir("trace4")).code, 2);  // --reference needs --missed
}

TEST(BiasCli, UnderSampledLightIsReportedWithItsLevel) {
  // samples/scenes/small-light-caustic.json: pt-nee at 4 spp never finds the lamp's caustic through
  // the glass ball (reachable for it), and its stderr says 0 ± 0.
  const std::string dir = out_dir("lamp");
  const CliRun r = run_pathex("bias samples/scenes/small-light-caustic.json --renderer pt-nee --reference bdpt --spp 64 "
                              "--renderer-spp 4 --no-images --out " + dir);
  ASSERT_EQ(r.code, 0) << r.out << r.err;
  const nlohmann::json j = nlohmann::json::parse(pathex::test::read_file(dir + "/bias.json"));
  const nlohmann::json& u = j["undersampled"];
  EXPECT_EQ(u["spp"], 4);
  EXPECT_EQ(u["seed"], 2);
  EXPECT_EQ(u["dof"], 16);
  EXPECT_EQ(u["false_alarm_rate"], 0.01);
  EXPECT_EQ(u["min_share"], 0.01);
  const int n = u["comparisons"];
  char each[32];
  std::snprintf(each, sizeof each, "%.2g", 1 - std::pow(0.99, 1.0 / n));
  EXPECT_NE(r.out.find("\nunder-sampled: light pt-nee can sample where its estimate at 4 spp and bdpt's differ beyond their "
                       "combined stderr (two-sided p < " + std::string(each) + ": 1 % false alarms over " + std::to_string(n) +
                       " comparisons, Šidák; Student's t, Welch's dof) by at least 1.0 % of the light it can sample:\n"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("\n  caustic: reachable, under-sampled at 4 spp: estimate 0.00000 ± 0.00000, reference 0.0"), std::string::npos)
      << r.out;
  bool path = false;
  for (const nlohmann::json& f : u["flagged"])
    if (f.contains("path") && f["path"] == "LDDSSDDSE") {
      path = true;
      EXPECT_EQ(f["renderer"]["luminance"], 0.0);
      EXPECT_LT(f["z"].get<double>(), -4.0);
    }
  EXPECT_TRUE(path) << u.dump(1);
  // --renderer-spp 0: no comparison, and bias.json says so.
  const CliRun none = run_pathex("bias samples/scenes/small-light-caustic.json --renderer pt-nee --reference bdpt --spp 4 "
                                 "--renderer-spp 0 --no-images --out " + out_dir("lamp0"));
  ASSERT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(none.out.find("under-sampled"), std::string::npos) << none.out;
  EXPECT_TRUE(nlohmann::json::parse(pathex::test::read_file(out_dir("lamp0") + "/bias.json"))["undersampled"].is_null());
  // trace --missed compares the render it made (same spp and seed as its reference).
  const CliRun trace = run_pathex("trace samples/scenes/small-light-caustic.json --renderer pt-nee --spp 4 --missed "
                                  "--reference bdpt --no-images --out " + out_dir("lamp-trace"));
  ASSERT_EQ(trace.code, 0) << trace.err;
  EXPECT_NE(trace.out.find("\nunder-sampled: light pt-nee can sample where its estimate at 4 spp and bdpt's differ"),
            std::string::npos)
      << trace.out;
  const nlohmann::json m = nlohmann::json::parse(pathex::test::read_file(out_dir("lamp-trace") + "/missed.json"));
  EXPECT_EQ(m["undersampled"]["seed"], 1);  // trace's own render
}

TEST(CheckMissed, UndersampledRequirementPassesAndFails) {
  const CliRun r = run_pathex("check tests/bias/checks/undersampled.json");
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find("PASS  lamp-bdpt: under-samples at most 0 classes or paths at 16 spp (0 under-sampled of "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("FAIL  lamp-pt-nee: under-samples at most 0 classes or paths at 4 spp ("), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\n      path LDDSSDDSE: reachable, under-sampled at 4 spp: estimate 0.00000 ± 0.00000, reference "),
            std::string::npos)
      << r.out;
  const nlohmann::json j = nlohmann::json::parse(run_pathex("check --json tests/bias/checks/undersampled.json").out);
  EXPECT_EQ(j["requirements"][1]["undersampled"]["spp"], 4);
  EXPECT_EQ(j["requirements"][1]["undersampled"]["flagged"][0]["path"], "LDDSSDDSE");
}

TEST(CheckMissed, PassingFileExitsZero) {
  const std::string junit = out_dir("pass.xml");
  const CliRun r = run_pathex("check tests/bias/checks/pass.json --junit " + junit);
  EXPECT_EQ(r.code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("PASS  cornell-pt: misses at most 0.00 % of the scene's light (0.00 % ± 0.00 % of what bdpt"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("check: 2 passed, 0 failed\n"), std::string::npos) << r.out;
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file(junit.c_str()));
  const pugi::xml_node suite = doc.child("testsuites").child("testsuite");
  EXPECT_EQ(suite.attribute("tests").as_int(), 2);
  EXPECT_EQ(suite.attribute("failures").as_int(), 0);
}

TEST(CheckMissed, FailingFileNamesTheShortestWitnessAndTheLargestMissedPath) {
  const std::string junit = out_dir("fail.xml");
  const CliRun r = run_pathex("check tests/bias/checks/fail.json --junit " + junit);
  EXPECT_EQ(r.code, 1) << r.out << r.err;
  const std::string reason = "its DD joins (c1..c2) are not where pt-nee joins: (0, DD, 2..), (1, DD, 2..)";
  EXPECT_NE(r.out.find("FAIL  mirror-pt-nee: misses at most 1.00 % of the scene's light (69."), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("      shortest counterexample LSDDSE, chains SD(0..1) DD(1..2) DS(2..3); " + reason + "\n"
                       "      largest missed path LSDDSE, 63."),
            std::string::npos)
      << r.out;
  pugi::xml_document doc;
  ASSERT_TRUE(doc.load_file(junit.c_str()));
  const pugi::xml_node tc = doc.child("testsuites").child("testsuite").child("testcase");
  EXPECT_STREQ(tc.attribute("classname").value(), "mirror-pt-nee");
  EXPECT_STREQ(tc.attribute("name").value(), "misses at most 1.00 % of the scene's light");
  const pugi::xml_node f = tc.child("failure");
  ASSERT_TRUE(f);
  const std::string message = f.attribute("message").value();
  EXPECT_EQ(message.rfind("misses at most 1.00 % of the scene's light: found 69.", 0), 0u) << message;
  EXPECT_NE(message.find(" of what bdpt finds"), std::string::npos) << message;
  EXPECT_NE(std::string(f.child_value()).find("largest missed path LSDDSE, 63."), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(run_pathex("check --json tests/bias/checks/fail.json").out);
  EXPECT_EQ(j["requirements"][0]["missed"]["largest_path"]["path"], "LSDDSE");
  EXPECT_EQ(j["requirements"][0]["missed"]["max_share"], 0.01);
}

TEST(CheckMissed, BadRequirementsAreLocated) {
  const auto check = [](const std::string& text) {
    const std::string f = out_dir("bad.json");
    std::ofstream(f) << text;
    return run_pathex("check " + f);
  };
  const std::string f = out_dir("bad.json");
  const std::string scene = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/cornell.json";
  CliRun r = check(R"({"cases": [{"name": "a", "renderer": "pt", "require": [{"missed": {"max_share": 0.01}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + f + ":/cases/0/require/0/missed: a missed requirement needs the case's scene\n");
  r = check(R"({"cases": [{"name": "a", "renderer": "pt", "scene": ")" + scene +
            R"(", "require": [{"missed": {"max_share": 2}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(f + ":/cases/0/require/0/missed/max_share: "), std::string::npos) << r.err;
  r = check(R"({"cases": [{"name": "a", "renderer": "pt", "scene": ")" + scene +
            R"(", "require": [{"missed": {"max_share": 0.1, "sp": 4}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(f + ":/cases/0/require/0/missed/sp: "), std::string::npos) << r.err;
  r = check(R"({"cases": [{"name": "a", "renderer": "pt", "require": [{"undersampled": {"spp": 4}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + f + ":/cases/0/require/0/undersampled: an undersampled requirement needs the case's scene\n");
  r = check(R"({"cases": [{"name": "a", "renderer": "pt", "scene": ")" + scene +
            R"(", "require": [{"undersampled": {"spp": 4}, "missed": {"max_share": 0.1}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + f + ":/cases/0/require/0: undersampled stands alone: no other key beside it\n");
  r = check(R"({"cases": [{"name": "a", "renderer": "pt", "scene": ")" + scene +
            R"(", "require": [{"undersampled": {"spp": 0}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(f + ":/cases/0/require/0/undersampled/spp: "), std::string::npos) << r.err;
  r = check(R"({"cases": [{"name": "a", "renderer": "pt", "scene": ")" + scene +
            R"(", "require": [{"undersampled": {"min_share": 3}}]}]})");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find(f + ":/cases/0/require/0/undersampled/min_share: "), std::string::npos) << r.err;
}

}  // namespace
