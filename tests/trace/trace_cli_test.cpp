// `pathex trace` end to end: the files it writes (histogram.json with the documented keys, one
// EXR with a layer per class and the total, a PNG per layer), the table, and refusals.
#include <gtest/gtest.h>

#include "support/cli_run.h"

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/image_io.h"

namespace {

using pathex::test::CliRun;

CliRun run(const std::string& args) { return pathex::test::run_pathex(args); }

std::string out_dir(const std::string& name) {
  const std::string d = (std::filesystem::temp_directory_path() / ("pathex-trace-" + std::to_string(::getpid()) + "-" + name)).string();
  std::filesystem::remove_all(d);
  return d;
}

TEST(TraceCli, WritesHistogramExrAndPreviews) {
  const std::string dir = out_dir("files");
  const CliRun r = run("trace samples/scenes/closed-sphere-point.json --renderer bdpt --spp 8 --seed 2 --threads 2 --out " + dir +
                       " --classes samples/classes/basic.json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.err, "");  // no progress bar when stderr is not a terminal
  std::ifstream in(dir + "/histogram.json");
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  EXPECT_EQ(keys, std::vector<std::string>({"scene", "renderer", "spp", "spp_requested", "seed", "complete",
                                            "nonfinite_samples", "distinct_paths", "max_paths", "total",
                                            "classes", "paths"}));
  EXPECT_EQ(j["scene"], "samples/scenes/closed-sphere-point.json");
  EXPECT_EQ(j["renderer"], "bdpt");
  EXPECT_EQ(j["spp"], 8);
  EXPECT_EQ(j["seed"], 2);
  // How the run went is beside it, in run.json, so that histogram.json is the same bytes for any thread count.
  std::ifstream run_in(dir + "/run.json");
  const nlohmann::ordered_json run_json = nlohmann::ordered_json::parse(run_in);
  EXPECT_EQ(run_json["threads"], 2);
  EXPECT_GT(run_json["time_s"].get<double>(), 0.0);
  EXPECT_EQ(j["complete"], true);
  EXPECT_EQ(j["nonfinite_samples"], 0);
  // The sphere's wall radiance is 1/pi in every pixel (DESIGN §9), up to the bound of 16 bounces.
  EXPECT_NEAR(j["total"]["luminance"].get<double>(), 1.0 / 3.14159265358979, 6 * j["total"]["stderr"].get<double>() + 2e-3);
  ASSERT_EQ(j["classes"].size(), 12u);
  for (const auto& c : j["classes"])
    for (const char* key : {"name", "expr", "estimate", "luminance", "stderr", "samples", "share"}) EXPECT_TRUE(c.contains(key)) << key;
  ASSERT_FALSE(j["paths"].empty());
  EXPECT_EQ(j["paths"][0]["path"], "LSDDDSE");  // the largest: one bounce, half of the light
  // Every technique is a split of the profile's one strategy, "bdpt (s, DD, t)", here with s + t = 5.
  double shares = 0;
  for (const auto& [name, t] : j["paths"][0]["strategies"].items()) {
    EXPECT_EQ(name.rfind("bdpt (", 0), 0u) << name;
    shares += t["share"].get<double>();
  }
  EXPECT_NEAR(shares, 1.0, 1e-12);
  // One EXR with the total and a layer per class; a PNG per layer.
  pathex::Result<std::vector<pathex::ImageLayer>> layers = pathex::read_exr_layers(dir + "/classes.exr");
  ASSERT_TRUE(layers.ok()) << layers.error().render();
  ASSERT_EQ(layers->size(), 13u);
  std::set<std::string> names;
  for (const auto& l : *layers) {
    names.insert(l.name);
    EXPECT_EQ(l.image.width, 32);
    EXPECT_TRUE(std::filesystem::exists(dir + "/" + l.name + ".png")) << l.name;
  }
  EXPECT_TRUE(names.count("total"));
  EXPECT_TRUE(names.count("caustic-local"));
  std::filesystem::remove_all(dir);
}

// Per-technique accounting (issue 13): on the mirror caustic under a point light, bdpt reaches the
// caustic LSDSDDSE only by light tracing from its floor vertex, (3, DD, 1): a point light cannot be
// hit and the mirror blocks every other join, so that technique carries all of the class, its
// estimate and its variance, exactly. The class "local" mixes techniques: their shares and
// variance shares each sum to 1.
TEST(TraceCli, ClassesSayWhichTechniqueCarriesThem) {
  const std::string dir = out_dir("techniques");
  const CliRun r = run("trace samples/scenes/point-mirror-caustic.json --renderer bdpt --spp 16 --seed 5 --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir + "/histogram.json");
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);
  const nlohmann::ordered_json* caustic = nullptr;
  const nlohmann::ordered_json* local = nullptr;
  for (const auto& c : j["classes"]) {
    if (c["name"] == "caustic") caustic = &c;
    if (c["name"] == "local") local = &c;
  }
  ASSERT_TRUE(caustic != nullptr && local != nullptr);
  ASSERT_EQ((*caustic)["strategies"].size(), 1u) << (*caustic)["strategies"].dump();
  const auto& lt = (*caustic)["strategies"]["bdpt (3, DD, 1)"];
  EXPECT_EQ(lt["share"].get<double>(), 1.0);
  EXPECT_EQ(lt["variance_share"].get<double>(), 1.0);
  EXPECT_EQ(lt["samples"], (*caustic)["samples"]);
  double share = 0, variance = 0;
  std::uint64_t samples = 0;
  ASSERT_GE((*local)["strategies"].size(), 3u);
  for (const auto& [name, t] : (*local)["strategies"].items()) {
    share += t["share"].get<double>();
    variance += t["variance_share"].get<double>();
    samples += t["samples"].get<std::uint64_t>();
  }
  EXPECT_NEAR(share, 1.0, 1e-12);
  EXPECT_NEAR(variance, 1.0, 1e-9);
  EXPECT_EQ(samples, (*local)["samples"].get<std::uint64_t>());
  EXPECT_NE(r.out.find("\n  from bdpt (3, DD, 1) 100.0 % (100.0 % of the variance)\n"), std::string::npos) << r.out;
  std::filesystem::remove_all(dir);
}

TEST(TraceCli, TableShowsSharesAndVerdicts) {
  const std::string dir = out_dir("table");
  const CliRun r = run("trace samples/scenes/point-mirror-caustic.json --renderer pt-nee --spp 4 --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("caustic: 0.0 % of the image, ±0.00 %; pt-nee: unreachable; luminance 0.00000 ± 0.00000\n"),
            std::string::npos) << r.out;
  EXPECT_NE(r.out.find("direct: "), std::string::npos);
  EXPECT_NE(r.out.find("most important paths\n  LSDDDSE"), std::string::npos) << r.out;
  std::filesystem::remove_all(dir);
}

// histogram.json gives the total's and each class's stderr stability (Estimate::stability, in
// [0, 1]), and the table says "its stderr is unstable" on exactly the lines whose stability is at
// least kUnstableVariance (0.7) — here the caustic seen through the ball, whose variance a few
// fold events carry (about 3 renders in 4 at 256 spp are flagged), and a well-spread render.
TEST(TraceCli, TheTableFlagsExactlyTheEstimatesWhoseStderrIsUnstable) {
  int flagged = 0;
  for (const std::string args : {"samples/scenes/lamp-glass.json --renderer pt-nee+manifold --only LDDSSDSSDSE --spp 256 --seed 1",
                                 "samples/scenes/point-plane.json --renderer pt-nee --spp 16 --seed 1"}) {
    const std::string dir = out_dir("unstable");
    const CliRun r = run("trace " + args + " --threads 1 --no-images --out " + dir);
    ASSERT_EQ(r.code, 0) << r.err;
    std::ifstream in(dir + "/histogram.json");
    const nlohmann::json h = nlohmann::json::parse(in);
    std::filesystem::remove_all(dir);
    std::vector<std::pair<std::string, nlohmann::json>> rows = {{h.contains("only") ? "luminance of those paths " : "image mean luminance ", h["total"]}};
    for (const auto& c : h["classes"])
      if (!c.contains("rendered")) rows.emplace_back(c["name"].get<std::string>() + ": ", c);
    for (const auto& [start, e] : rows) {
      const std::size_t at = r.out.find("\n" + start);
      ASSERT_NE(at, std::string::npos) << start << "\n" << r.out;
      const std::string line = r.out.substr(at + 1, r.out.find('\n', at + 1) - at - 1);
      if (e["stderr_stability"].is_null()) {  // unknown: an empty class (no group with a variance)
        EXPECT_EQ(line.find("unstable"), std::string::npos) << line;
        continue;
      }
      ASSERT_TRUE(e["stderr_stability"].is_number()) << line;
      const double eps = e["stderr_stability"].get<double>();
      EXPECT_GE(eps, 0.0);
      EXPECT_LE(eps, 1.0 + 1e-12);
      char text[96];
      std::snprintf(text, sizeof text, "; its stderr is unstable (a few pixel groups carry it: its square's relative error is %.2f)", eps);
      const bool says = line.find("its stderr is unstable") != std::string::npos;
      EXPECT_EQ(says, eps >= 0.7) << line;
      if (says) {
        EXPECT_NE(line.find(text), std::string::npos) << line;
        ++flagged;
      }
    }
  }
  // Where no line is flagged (a render whose fold events spread over the groups) the test checks
  // the other branch only; at seed 1 on the development machine the seen-through lines are flagged.
  RecordProperty("flagged_lines", flagged);
}

TEST(TraceCli, JsonToStdoutMatchesTheFile) {
  const std::string dir = out_dir("json");
  const CliRun r = run("trace --spp 2 --json --no-images --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream in(dir + "/histogram.json");
  std::stringstream ss;
  ss << in.rdbuf();
  EXPECT_EQ(r.out, ss.str());
  EXPECT_FALSE(std::filesystem::exists(dir + "/classes.exr"));
  std::filesystem::remove_all(dir);
}

// A profile with a connector adds "connectors" to histogram.json and a row per connector to the
// table; every attempt is counted once, as a success or under one failure reason.
TEST(TraceCli, ConnectorStatisticsInTheJsonAndTheTable) {
  const std::string dir = out_dir("connectors");
  const CliRun r = run("trace samples/scenes/sun-window.json --renderer pt-nee+distant --spp 1 --threads 2 --no-images --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\nconnectors     attempts  successes   outside  occluded  no transport\n  nee-distant "), std::string::npos)
      << r.out;
  std::ifstream in(dir + "/histogram.json");
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(in);
  ASSERT_EQ(j["connectors"].size(), 1u);
  const nlohmann::ordered_json& c = j["connectors"][0];
  EXPECT_EQ(c["strategy"], "nee-distant");
  EXPECT_EQ(c["connector"], "distant-projection");
  const nlohmann::ordered_json& f = c["failures"];
  EXPECT_GT(c["successes"].get<std::uint64_t>(), 0u);
  EXPECT_EQ(c["attempts"].get<std::uint64_t>(), c["successes"].get<std::uint64_t>() + f["outside"].get<std::uint64_t>() +
                                                    f["occluded"].get<std::uint64_t>() + f["no_transport"].get<std::uint64_t>());
  for (const auto& p : j["paths"]) EXPECT_EQ(p["path"].get<std::string>().substr(0, 4), "LDSD") << p["path"];
  std::filesystem::remove_all(dir);
}

TEST(TraceCli, RefusalsExitTwo) {
  EXPECT_EQ(run("trace samples/scenes/nosuch.json --out /tmp/pathex-never").code, 2);
  EXPECT_FALSE(std::filesystem::exists("/tmp/pathex-never"));
  EXPECT_EQ(run("trace --spp 0").code, 2);
}

}  // namespace
