// The installed API (<pathex/pathex.h>) against the answers the `pathex` command gives: the same
// automata, verdicts, witnesses, classes and located error messages. (tests/package builds
// examples/ against the installed package; this test covers the API's cases in the build tree.)
#include "pathex/pathex.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <nlohmann/json.hpp>

#include "support/cli_run.h"

namespace {

namespace px = pathex::api;

TEST(Api, PathClassCompilesMatchesAndListsMembers) {
  const px::PathClass local("L.*DD.*E");
  ASSERT_TRUE(local.ok()) << local.error();
  EXPECT_EQ(local.error(), "");
  EXPECT_EQ(local.expression(), "L.*DD.*E");
  EXPECT_TRUE(local.matches("LDDDDE"));
  EXPECT_TRUE(local.matches("LSDDSE"));
  EXPECT_FALSE(local.matches("LSDSDE"));  // no two adjacent D
  EXPECT_FALSE(local.matches("LDDE"));    // not a valid full path (too short)
  EXPECT_FALSE(local.matches("hello"));
  EXPECT_FALSE(local.empty());
  // `pathex explain 'L..S+D.*..E'`: 10 states; shortlex D < E < L < S.
  const px::PathClass caustic("L..S+D.*..E");
  EXPECT_EQ(caustic.dfa_states(), 10);
  EXPECT_EQ(caustic.shortest(3), (std::vector<std::string>{"LDDSDDDE", "LDDSDDSE", "LDDSDSDE"}));
  EXPECT_TRUE(px::PathClass("LSSSSE & LDDDDE").empty());
}

TEST(Api, EyeFirstAndHeckbertNotation) {
  EXPECT_TRUE(px::PathClass("EDS*DL").matches("LDSDDE") == px::PathClass("LDS*DE").matches("LDSDDE"));
  EXPECT_TRUE(px::PathClass("EDDDDL").matches("LDDDDE"));
  const px::PathClass heckbert("LSDE", px::Notation::kHeckbert);
  ASSERT_TRUE(heckbert.ok()) << heckbert.error();
  EXPECT_TRUE(heckbert.matches("LSDSDDSE"));   // point light, mirror, diffuse, pinhole
  EXPECT_FALSE(heckbert.matches("LSDDDDSE"));  // two diffuse vertices is LDDE
}

TEST(Api, ErrorsAreTheCommandsLocatedMessages) {
  const px::PathClass bad("L(DD");
  EXPECT_FALSE(bad.ok());
  const pathex::test::CliRun cli = pathex::test::run_pathex_args({"explain", "L(DD"});
  EXPECT_EQ("pathex: error: " + bad.error() + "\n", cli.err);
  EXPECT_FALSE(bad.matches("LDDDDE"));
  EXPECT_EQ(bad.dfa_states(), 0);
  EXPECT_TRUE(bad.shortest(5).empty());
  const px::Answer a = px::query(bad, px::Renderer("bdpt"));
  EXPECT_FALSE(a.ok());
  EXPECT_EQ(a.error, bad.error());
}

TEST(Api, QueryGivesTheCheckersVerdictsAndWitnesses) {
  const px::PathClass caustic("$caustic");
  const px::Answer nee = px::query(caustic, px::Renderer("pt-nee"));
  ASSERT_TRUE(nee.ok()) << nee.error;
  EXPECT_EQ(nee.verdict, px::Verdict::kPartial);
  ASSERT_FALSE(nee.unreachable_witnesses.empty());
  EXPECT_EQ(nee.unreachable_witnesses.front(), "LDSSDDDE");
  EXPECT_EQ(px::to_string(px::query(px::PathClass("L.*DD.*E"), px::Renderer("bdpt")).verdict), "reachable");
  // The README's example: a point light seen in a mirror by an orthographic camera.
  EXPECT_EQ(px::query(px::PathClass("LSDSDE"), px::Renderer("pt-nee")).verdict, px::Verdict::kUnreachable);
  EXPECT_EQ(px::query(px::PathClass("LSDSDE"), px::Renderer("bdpt+ortho")).verdict, px::Verdict::kReachable);
  // Bounds and scenes: beyond the bound nothing is left; a scene without point lights has no LSD….
  px::QueryOptions bounded;
  bounded.max_bounces = 2;
  EXPECT_EQ(px::query(px::PathClass("L......+E"), px::Renderer("bdpt"), bounded).verdict, px::Verdict::kPartial);
  bounded.max_bounces = 1;
  EXPECT_EQ(px::query(px::PathClass("L......+E"), px::Renderer("bdpt"), bounded).verdict, px::Verdict::kEmpty);
  px::QueryOptions cornell;
  cornell.scene = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/cornell.json";
  EXPECT_EQ(px::query(px::PathClass("LSD.*E"), px::Renderer("bdpt"), cornell).verdict, px::Verdict::kEmpty);
  px::QueryOptions missing;
  missing.scene = "/nonexistent/scene.json";
  const px::Answer no_scene = px::query(caustic, px::Renderer("bdpt"), missing);
  EXPECT_FALSE(no_scene.ok());
  EXPECT_NE(no_scene.error.find("/nonexistent/scene.json"), std::string::npos) << no_scene.error;
}

TEST(Api, RenderersByNameOrFile) {
  const std::vector<std::string> names = px::Renderer::builtin_names();
  ASSERT_GE(names.size(), 4u);
  EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 4),
            (std::vector<std::string>{"pt", "pt-nee", "lt", "bdpt"}));
  for (const std::string& n : names) EXPECT_TRUE(px::Renderer(n).ok()) << n;
  const px::Renderer file(std::string(PATHEX_SOURCE_DIR) + "/samples/renderers/pt-nee.json");
  ASSERT_TRUE(file.ok()) << file.error();
  EXPECT_EQ(file.name(), "pt-nee");
  const px::Renderer unknown("no-such-renderer");
  EXPECT_FALSE(unknown.ok());
  EXPECT_NE(unknown.error().find("no-such-renderer"), std::string::npos);
  EXPECT_FALSE(px::query(px::PathClass("$all"), unknown).ok());
}

TEST(Api, ClassSetsClassifyInOnePass) {
  const px::ClassSet builtins = px::ClassSet::builtins();
  ASSERT_TRUE(builtins.ok()) << builtins.error();
  EXPECT_EQ(builtins.names(), (std::vector<std::string>{"local", "emission", "direct", "indirect", "caustic"}));
  EXPECT_EQ(builtins.classify("LDDSDDSE"), (std::vector<std::string>{"local", "indirect", "caustic"}));
  EXPECT_EQ(builtins.classify("LDDDDE"), (std::vector<std::string>{"local", "emission"}));
  EXPECT_TRUE(builtins.classify("LDXDDE").empty());

  const px::ClassSet mine = px::ClassSet::from_expressions({{"glass", "L.*SS.*E"}, {"glass-caustic", "$glass & $caustic"}});
  ASSERT_TRUE(mine.ok()) << mine.error();
  EXPECT_EQ(mine.classify("LDDSSDDSE"), (std::vector<std::string>{"glass", "glass-caustic"}));
  EXPECT_EQ(mine.classify("LDDDSSDSE"), (std::vector<std::string>{"glass"}));  // c2 is D: not a caustic

  const px::ClassSet undefined = px::ClassSet::from_expressions({{"a", "$nope"}});
  EXPECT_FALSE(undefined.ok());
  EXPECT_TRUE(undefined.names().empty());
  EXPECT_TRUE(undefined.classify("LDDDDE").empty());
}

TEST(Api, ClassFilesWithTheirErrors) {
  const px::ClassSet basic = px::ClassSet::from_file(std::string(PATHEX_SOURCE_DIR) + "/samples/classes/basic.json");
  ASSERT_TRUE(basic.ok()) << basic.error();
  EXPECT_FALSE(basic.names().empty());
  const std::filesystem::path bad = pathex::test::scratch_dir() / "bad-classes.json";
  std::ofstream(bad) << R"({"classes": [{"name": "x", "expr": "L(("}]})";
  const px::ClassSet refused = px::ClassSet::from_file(bad.string());
  EXPECT_FALSE(refused.ok());
  EXPECT_EQ(refused.error().rfind(bad.string() + ":/classes/0/expr", 0), 0u) << refused.error();
}

TEST(Api, VersionIsTheProjects) {
  EXPECT_EQ("pathex " + std::string(px::version()) + "\n", pathex::test::run_pathex_args({"--version"}).out);
}

}  // namespace

// api::bias is `pathex bias`: the same reference, the same missed share and stderr to the last bit
// (the same render, seed and classes), and the same located messages.
TEST(Api, BiasMeasuresWhatTheCommandMeasures) {
  const std::string scene = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-mirror-caustic.json";
  px::BiasOptions o;
  o.spp = 4;
  o.threads = 2;
  const px::BiasAnswer a = px::bias(scene, px::Renderer("pt-nee"), o);
  ASSERT_TRUE(a.ok()) << a.error;
  const std::string out = (pathex::test::scratch_dir() / "api-bias").string();
  const pathex::test::CliRun cli = pathex::test::run_pathex_args(
      {"bias", scene, "--renderer", "pt-nee", "--spp", "4", "--threads", "1", "--json", "--no-images", "--out", out});
  ASSERT_EQ(cli.code, 0) << cli.err;
  const nlohmann::json j = nlohmann::json::parse(cli.out);
  EXPECT_EQ(a.reference, j["reference"]["name"]);
  EXPECT_EQ(a.reference, "bdpt+mirror+manifold");
  EXPECT_EQ(a.share, j["missed"]["share"].get<double>());
  EXPECT_EQ(a.share_stderr, j["missed"]["share_stderr"].get<double>());
  EXPECT_EQ(a.total, j["total"]["luminance"].get<double>());
  EXPECT_EQ(a.missed, j["missed"]["luminance"].get<double>());
  EXPECT_FALSE(a.exact);
  // The mirror's caustic: pt-nee cannot join a point light's path through a specular vertex.
  EXPECT_EQ(a.shortest_missed, "LSDDSE");
  EXPECT_GT(a.share, 0.5);  // most of this scene's light comes off the mirror

  const px::BiasAnswer missing = px::bias("no-such-scene.json", px::Renderer("pt-nee"), o);
  EXPECT_FALSE(missing.ok());
  const pathex::test::CliRun cli_missing =
      pathex::test::run_pathex_args({"bias", "no-such-scene.json", "--renderer", "pt-nee", "--out", out});
  EXPECT_EQ(cli_missing.code, 2);
  EXPECT_EQ("pathex: error: " + missing.error + "\n", cli_missing.err);
  o.reference = "no-such-reference";
  const px::BiasAnswer bad_reference = px::bias(scene, px::Renderer("pt-nee"), o);
  EXPECT_FALSE(bad_reference.ok());
  EXPECT_NE(bad_reference.error.find("no-such-reference"), std::string::npos) << bad_reference.error;
  EXPECT_FALSE(px::bias(scene, px::Renderer("no-such-renderer")).ok());
}

// api::converge is `pathex converge`: the same references, estimates, stderrs, errors and z per
// class, renderer and rung as the command's converge.json, bit for bit (only times differ), and
// the same located message for a scene that cannot be read.
TEST(Api, ConvergeMeasuresWhatTheCommandMeasures) {
  const std::string scene = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/closed-sphere-point.json";
  px::ConvergeOptions o;
  o.spp = {4, 16};
  o.threads = 2;
  const px::ConvergeAnswer a = px::converge(scene, {px::Renderer("pt-nee"), px::Renderer("bdpt")}, o);
  ASSERT_TRUE(a.ok()) << a.error;
  const std::string out = (pathex::test::scratch_dir() / "api-converge").string();
  const pathex::test::CliRun cli = pathex::test::run_pathex_args({"converge", scene, "--renderer", "pt-nee", "--renderer", "bdpt",
                                                                  "--spp", "4,16", "--threads", "1", "--json", "--quiet", "--out", out});
  ASSERT_EQ(cli.code, 0) << cli.err;
  const nlohmann::json j = nlohmann::json::parse(cli.out);
  EXPECT_EQ(a.reference_kind, "closed-form");
  EXPECT_EQ(a.reference_kind, j["reference"]["kind"]);
  EXPECT_EQ(a.reference_source, j["reference"]["source"]);
  EXPECT_TRUE(a.complete);
  const nlohmann::json& refs = j["reference"]["classes"];
  ASSERT_EQ(a.classes.size(), refs.size());
  EXPECT_EQ(a.classes.front().name, "total");
  const auto same = [](const std::optional<double>& v, const nlohmann::json& n) {
    return n.is_null() ? !v.has_value() : v.has_value() && *v == n.get<double>();
  };
  int compared = 0;
  for (std::size_t i = 0; i < a.classes.size(); ++i) {
    const px::ConvergeClass& c = a.classes[i];
    EXPECT_EQ(c.name, refs[i]["name"]);
    EXPECT_EQ(c.expression, refs[i]["expr"]);
    EXPECT_TRUE(same(c.reference, refs[i]["luminance"])) << c.name;
    ASSERT_EQ(c.renderers.size(), 2u);
    for (std::size_t k = 0; k < 2; ++k) {
      const px::ConvergeSeries& s = c.renderers[k];
      const nlohmann::json& jc = j["renderers"][k]["classes"][i];
      EXPECT_EQ(s.renderer, j["renderers"][k]["name"]);
      EXPECT_EQ(c.name, jc["name"]);
      ASSERT_EQ(s.rungs.size(), 2u);
      ASSERT_EQ(jc["rungs"].size(), 2u);
      for (std::size_t r = 0; r < 2; ++r) {
        const nlohmann::json& jr = jc["rungs"][r];
        EXPECT_EQ(s.rungs[r].spp, jr["spp"].get<std::uint64_t>());
        EXPECT_EQ(s.rungs[r].estimate, jr["estimate"].get<double>()) << c.name << " " << s.renderer << " rung " << r;
        EXPECT_TRUE(same(s.rungs[r].std_error, jr["stderr"])) << c.name << " " << s.renderer << " rung " << r;
        EXPECT_TRUE(same(s.rungs[r].error, jr["error"])) << c.name << " " << s.renderer << " rung " << r;
        EXPECT_TRUE(same(s.rungs[r].z, jr["z"])) << c.name << " " << s.renderer << " rung " << r;
        ++compared;
      }
      EXPECT_EQ(s.cannot_sample, jc["cannot_sample"].is_null() ? "" : jc["cannot_sample"].get<std::string>());
    }
  }
  EXPECT_GE(compared, 8);  // at least the total and one class, two renderers, two rungs
  // The closed form's total is 1 / pi, and the total has an error on every rung.
  EXPECT_DOUBLE_EQ(*a.classes.front().reference, 0.31830988618379069);
  EXPECT_TRUE(a.classes.front().renderers[0].rungs[1].error.has_value());
  // The ranking weighs CPU time, which differs between two runs: the same best renderer is asserted
  // only where the call's best is at least twice as efficient as every other (bounce3's two are 2 %
  // apart, and either may win a run).
  int ranked = 0;
  for (const nlohmann::json& b : j["best"])
    for (const px::ConvergeClass& c : a.classes)
      if (c.name == b["class"]) {
        bool clear = !c.best.empty();
        for (const px::ConvergeSeries& s : c.renderers)
          if (s.renderer != c.best)
            for (const px::ConvergeSeries& w : c.renderers)
              if (w.renderer == c.best && !(w.efficiency > 2.0 * s.efficiency)) clear = false;
        if (!clear) continue;
        EXPECT_EQ(c.best, b["renderer"]) << c.name;
        ++ranked;
      }
  EXPECT_GE(ranked, 1) << "no class has a clear best renderer";

  const px::ConvergeAnswer missing = px::converge("no-such-scene.json", {px::Renderer("pt-nee")}, o);
  EXPECT_FALSE(missing.ok());
  const pathex::test::CliRun cli_missing =
      pathex::test::run_pathex_args({"converge", "no-such-scene.json", "--renderer", "pt-nee", "--out", out});
  EXPECT_EQ(cli_missing.code, 2);
  EXPECT_EQ("pathex: error: " + missing.error + "\n", cli_missing.err);
  EXPECT_FALSE(px::converge(scene, {px::Renderer("no-such-renderer")}, o).ok());
  px::ConvergeOptions decreasing = o;
  decreasing.spp = {16, 4};
  EXPECT_FALSE(px::converge(scene, {px::Renderer("pt-nee")}, decreasing).ok());
}

// api::trace is `pathex trace`: the same estimates, bit for bit, as the command's histogram.json
// for the total, every class and every listed path (and "other"), with or without a folder; the
// folder it writes is the command's set; `only` narrows as --only does; errors are the command's.
TEST(Api, TraceMeasuresWhatTheCommandMeasures) {
  const std::string scene = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/point-glass.json";
  px::TraceOptions o;
  o.spp = 4;
  o.threads = 2;
  o.max_paths = 5;  // fewer than the scene's paths: "other" is listed
  const px::TraceAnswer a = px::trace(scene, px::Renderer("bdpt"), o);
  ASSERT_TRUE(a.ok()) << a.error;
  const std::string out = (pathex::test::scratch_dir() / "api-trace").string();
  const pathex::test::CliRun cli = pathex::test::run_pathex_args(
      {"trace", scene, "--renderer", "bdpt", "--spp", "4", "--threads", "1", "--max-paths", "5", "--json", "--quiet", "--out", out});
  ASSERT_EQ(cli.code, 0) << cli.err;
  const nlohmann::json j = nlohmann::json::parse(cli.out);
  const auto same = [](const px::TraceEstimate& e, const nlohmann::json& n) {
    return e.luminance == n["luminance"].get<double>() &&
           (n["stderr"].is_null() ? std::isnan(e.std_error) : e.std_error == n["stderr"].get<double>());
  };
  EXPECT_EQ(a.renderer, "bdpt");
  EXPECT_EQ(a.spp, 4u);
  EXPECT_TRUE(a.complete);
  EXPECT_GT(a.total.luminance, 0.0);
  EXPECT_TRUE(same(a.total, j["total"]));
  EXPECT_EQ(a.total.share, 1.0);
  ASSERT_EQ(a.classes.size(), j["classes"].size());
  for (std::size_t i = 0; i < a.classes.size(); ++i) {
    EXPECT_EQ(a.classes[i].name, j["classes"][i]["name"]);
    EXPECT_EQ(a.classes[i].expression, j["classes"][i]["expr"]);
    EXPECT_TRUE(same(a.classes[i], j["classes"][i])) << a.classes[i].name;
    EXPECT_EQ(a.classes[i].share, j["classes"][i]["share"].get<double>()) << a.classes[i].name;
  }
  ASSERT_EQ(a.paths.size(), j["paths"].size());
  ASSERT_EQ(a.paths.size(), 6u);  // five listed, then "other"
  EXPECT_EQ(a.paths.back().name, "other");
  for (std::size_t i = 0; i < a.paths.size(); ++i) {
    EXPECT_EQ(a.paths[i].name, j["paths"][i]["path"]);
    EXPECT_TRUE(same(a.paths[i], j["paths"][i])) << a.paths[i].name;
  }
  EXPECT_EQ(a.distinct_paths, j["distinct_paths"].get<std::uint64_t>());
  EXPECT_EQ(a.nonfinite_samples, 0u);
  EXPECT_GT(a.cpu_s, 0.0);

  // With a folder: the same answer, and the folder holds the command's histogram.json.
  px::TraceOptions to_folder = o;
  to_folder.out = (pathex::test::scratch_dir() / "api-trace-folder").string();
  const px::TraceAnswer b = px::trace(scene, px::Renderer("bdpt"), to_folder);
  ASSERT_TRUE(b.ok()) << b.error;
  EXPECT_EQ(b.total.luminance, a.total.luminance);
  std::ifstream written(to_folder.out + "/histogram.json");
  ASSERT_TRUE(written) << "no histogram.json in " << to_folder.out;
  const nlohmann::json w = nlohmann::json::parse(written);
  EXPECT_EQ(w["total"], j["total"]);
  EXPECT_EQ(w["paths"], j["paths"]);
  EXPECT_TRUE(std::filesystem::exists(to_folder.out + "/classes.exr"));
  // Without a folder nothing is written (the command's default folder is not made either).
  EXPECT_FALSE(std::filesystem::exists("pathex-out/histogram.json"));

  // `only`: the caustic alone, the other classes not rendered, as --only reports them.
  px::TraceOptions caustic = o;
  caustic.only = {"$caustic"};
  const px::TraceAnswer c = px::trace(scene, px::Renderer("bdpt"), caustic);
  ASSERT_TRUE(c.ok()) << c.error;
  int rendered = 0;
  for (const px::TraceEstimate& e : c.classes) rendered += e.rendered ? 1 : 0;
  EXPECT_GE(rendered, 1);
  EXPECT_LT(rendered, static_cast<int>(c.classes.size()));
  EXPECT_LT(c.total.luminance, a.total.luminance);

  // Errors are the command's located messages.
  const px::TraceAnswer missing = px::trace("no-such-scene.json", px::Renderer("bdpt"), o);
  EXPECT_FALSE(missing.ok());
  const pathex::test::CliRun cli_missing = pathex::test::run_pathex_args({"trace", "no-such-scene.json", "--out", out});
  EXPECT_EQ(cli_missing.code, 2);
  EXPECT_EQ("pathex: error: " + missing.error + "\n", cli_missing.err);
  EXPECT_FALSE(px::trace(scene, px::Renderer("no-such-renderer"), o).ok());
  px::TraceOptions no_spp = o;
  no_spp.spp = 0;
  EXPECT_EQ(px::trace(scene, px::Renderer("bdpt"), no_spp).error, "spp must be 1 to 16777216, not 0");
  px::TraceOptions too_deep = o;
  too_deep.max_bounces = 1001;
  EXPECT_EQ(px::trace(scene, px::Renderer("bdpt"), too_deep).error, "max bounces must be 0 to 1000, not 1001");
}

// api::check is `pathex check`: the same outcomes, in order, as the lines the command prints, and
// the same located message for a file that cannot be run.
TEST(Api, CheckDecidesWhatTheCommandDecides) {
  const std::string file = std::string(PATHEX_SOURCE_DIR) + "/samples/checks/fails-on-purpose.json";
  const px::CheckAnswer a = px::check(file);
  ASSERT_TRUE(a.ok()) << a.error;
  EXPECT_FALSE(a.passed());
  const pathex::test::CliRun cli = pathex::test::run_pathex_args({"check", file});
  EXPECT_EQ(cli.code, 1);
  std::size_t at = 0;  // each outcome's line, in the command's order
  int failed = 0;
  for (const px::CheckOutcome& o : a.outcomes) {
    const std::string line = std::string(o.passed ? "PASS  " : "FAIL  ") + o.case_name + ": " + o.requirement + " (" + o.found + ")\n";
    at = cli.out.find(line, at);
    EXPECT_NE(at, std::string::npos) << cli.out << "\n---\n" << line;
    if (at == std::string::npos) break;
    failed += o.passed ? 0 : 1;
  }
  ASSERT_EQ(a.outcomes.size(), 2u);
  EXPECT_EQ(failed, 2);
  EXPECT_EQ(a.outcomes[0].requirement, "LSDSDE is reachable");
  EXPECT_EQ(a.outcomes[0].found, "unreachable");
  EXPECT_EQ(a.outcomes[0].counterexample, "LSDSDE");

  const px::CheckAnswer samples = px::check(std::string(PATHEX_SOURCE_DIR) + "/samples/checks/samples.json");
  ASSERT_TRUE(samples.ok()) << samples.error;
  EXPECT_TRUE(samples.passed());
  EXPECT_EQ(samples.outcomes.size(), 23u);

  const px::CheckAnswer missing = px::check("no-such-check.json");
  EXPECT_FALSE(missing.ok());
  EXPECT_FALSE(missing.passed());
  const pathex::test::CliRun cli_missing = pathex::test::run_pathex_args({"check", "no-such-check.json"});
  EXPECT_EQ(cli_missing.code, 2);
  EXPECT_EQ("pathex: error: " + missing.error + "\n", cli_missing.err);
}
