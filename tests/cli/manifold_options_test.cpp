// pathex trace --manifold-*: the manifold connector's limits as options. Their defaults are the
// library's (ManifoldOptions) and --help states them; a bad value is one message and exit 2; they
// reach the walk; and where the connector runs they are part of the render, so renders with other
// limits are not merged and --resume does not take them.
#include <gtest/gtest.h>

#include "support/cli_run.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <regex>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "trace/joins/manifold.h"

namespace {

using pathex::test::CliRun;

CliRun run(const std::string& args) { return pathex::test::run_pathex(args); }

std::string out_dir(const std::string& name) {
  const std::string d =
      (std::filesystem::temp_directory_path() / ("pathex-manifold-opt-" + std::to_string(::getpid()) + "-" + name)).string();
  std::filesystem::remove_all(d);
  return d;
}

const std::string kScene = "samples/scenes/point-glass.json";

// The manifold connector's row of histogram.json's "connectors".
nlohmann::json manifold_stats(const std::string& args) {
  const std::string dir = out_dir("stats");
  const CliRun r = run("trace " + kScene + " --renderer pt-nee+manifold --spp 2 --resolution 16x16 --no-images --quiet --json --out " +
                       dir + " " + args);
  std::filesystem::remove_all(dir);
  EXPECT_EQ(r.code, 0) << r.err;
  const nlohmann::json h = nlohmann::json::parse(r.out);
  for (const auto& c : h["connectors"])
    if (c["connector"] == "manifold") return c;
  ADD_FAILURE() << "no manifold connector in " << r.out;
  return {};
}

// The JSON header of DIR/render.shard (output/shard.h: magic, version, header length, header).
nlohmann::json shard_header(const std::string& dir) {
  std::ifstream in(dir + "/render.shard", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() < 16) return {};
  std::uint32_t n = 0;
  for (int i = 3; i >= 0; --i) n = (n << 8) | static_cast<unsigned char>(bytes[12 + static_cast<std::size_t>(i)]);
  return nlohmann::json::parse(bytes.substr(16, n));
}

TEST(ManifoldOptions, HelpStatesTheLibraryDefaults) {
  const CliRun r = run("trace --help");
  ASSERT_EQ(r.code, 0);
  const pathex::ManifoldOptions d;
  EXPECT_EQ(d.max_iterations, 64);  // what the README states
  EXPECT_EQ(d.max_trials, 2000);
  EXPECT_FALSE(d.seeds);  // resolved from the profile: 1 in bdpt+manifold, 4 in pt-nee+manifold (below)
  EXPECT_EQ(d.biased_trials, 0);  // unbiased by default
  EXPECT_FALSE(d.rate);            // resolved: 0.125 (where another strategy samples the path too: Integrator::manifold_rate())
  for (const std::string line : {"--manifold-iterations INT:INT in [1 - 10000]=64", "--manifold-threshold FLOAT:FLOAT in (0, 1)=1e-05",
                                 "--manifold-min-segment FLOAT:FLOAT in [0, 1)=0.001",
                                 "--manifold-singular FLOAT:FLOAT in [0, 1)=1e-07", "--manifold-trials INT:INT in [1 - 100000]=2000",
                                 "--manifold-seeds INT:INT in [1 - 64]", "--manifold-biased-trials INT:INT in [0 - 100000]=0",
                                 "--manifold-rate FLOAT:FLOAT in (0, 1]"})
    EXPECT_NE(r.out.find("  " + line + "\n"), std::string::npos) << line << "\n" << r.out;
}

TEST(ManifoldOptions, BadValuesAreOneMessageAndExitTwo) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"--manifold-iterations 0", "--manifold-iterations: Value 0 not in range 1 to 10000"},
      {"--manifold-iterations -3", "--manifold-iterations: expected a non-negative integer, got '-3'"},
      {"--manifold-threshold 0", "--manifold-threshold: expected a number in (0, 1), got '0'"},
      {"--manifold-threshold nan", "--manifold-threshold: expected a number in (0, 1), got 'nan'"},
      {"--manifold-threshold 1e-3x", "--manifold-threshold: expected a number in (0, 1), got '1e-3x'"},
      {"--manifold-min-segment 1", "--manifold-min-segment: expected a number in [0, 1), got '1'"},
      {"--manifold-singular -0.1", "--manifold-singular: expected a number in [0, 1), got '-0.1'"},
      {"--manifold-singular inf", "--manifold-singular: expected a number in [0, 1), got 'inf'"},
      {"--manifold-trials 100001", "--manifold-trials: Value 100001 not in range 1 to 100000"},
      {"--manifold-seeds 0", "--manifold-seeds: Value 0 not in range 1 to 64"},
      {"--manifold-biased-trials 100001", "--manifold-biased-trials: Value 100001 not in range 0 to 100000"},
      {"--manifold-biased-trials -1", "--manifold-biased-trials: expected a non-negative integer, got '-1'"},
      {"--manifold-rate 0", "--manifold-rate: expected a number in (0, 1], got '0'"},
      {"--manifold-rate 1.5", "--manifold-rate: expected a number in (0, 1], got '1.5'"},
      {"--manifold-rate nan", "--manifold-rate: expected a number in (0, 1], got 'nan'"},
  };
  for (const auto& [args, message] : cases) {
    const CliRun r = run("trace " + kScene + " --renderer pt-nee+manifold --spp 1 --out " + out_dir("bad") + " " + args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(r.err, message + "\nRun with --help for more information.\n") << args;
  }
}

// Issue 39: --splits takes a count or auto (per-pixel counts from a pilot, trace/accel/split_plan.h),
// recorded in the shard header as 0; anything else is one message and exit 2.
TEST(SplitsOption, TakesACountOrAutoAndNothingElse) {
  const std::string d = out_dir("splits-auto");
  const CliRun ok = run("trace samples/scenes/cornell.json --renderer pt-nee --spp 2 --resolution 16x16 --quiet --splits auto --out " + d);
  ASSERT_EQ(ok.code, 0) << ok.err;
  std::ifstream shard(d + "/render.shard", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(shard)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("\"splits\": 0,"), std::string::npos);
  for (const std::string bad : {"0", "1025", "-1", "Auto", "2x", "", "auto8"}) {
    const CliRun r = run("trace " + kScene + " --spp 1 --out " + out_dir("bad") + " --splits '" + bad + "'");
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_EQ(r.err, "--splits: expected auto or a whole number from 1 to 1024, got '" + bad + "'\nRun with --help for more information.\n") << bad;
  }
}

// Issue 39: --rr-threshold and --rr-join-threshold take a number in [0, 1000] or auto (the
// defaults: the pilot's choice, trace/accel/join_plan.h), which the trace says and the shard header
// records as the word; anything else is one message and exit 2.
TEST(JoinThresholdOption, TakesANumberOrAutoAndSaysWhatAutoTook) {
  const std::string d = out_dir("join-auto");
  const CliRun ok = run("trace samples/scenes/sun-window.json --renderer bdpt --spp 16 --quiet --out " + d);
  ASSERT_EQ(ok.code, 0) << ok.err;
  EXPECT_NE(ok.out.find("\nroulette (auto): --rr-threshold 1, --rr-join-threshold 2, where the pilot's model finds "), std::string::npos) << ok.out;
  EXPECT_NE(ok.out.find("x the efficiency of 0.3 and none\n"), std::string::npos) << ok.out;
  std::ifstream shard(d + "/render.shard", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(shard)), std::istreambuf_iterator<char>());
  EXPECT_NE(bytes.find("\"rr_threshold\": \"auto\","), std::string::npos);
  EXPECT_NE(bytes.find("\"rr_join_threshold\": \"auto\","), std::string::npos);
  // One given, the other auto: the pilot chooses the other against the one given.
  const CliRun eye = run("trace samples/scenes/sun-window.json --renderer bdpt --spp 16 --quiet --rr-threshold 0.3 --out " + out_dir("eye-fixed"));
  ASSERT_EQ(eye.code, 0) << eye.err;
  EXPECT_NE(eye.out.find("\nroulette (auto): --rr-threshold 0.3, --rr-join-threshold 2, where the pilot's model finds "), std::string::npos) << eye.out;
  const CliRun fixed = run("trace samples/scenes/sun-window.json --renderer bdpt --spp 1 --quiet --rr-threshold 0.3 --rr-join-threshold 0.5 --out " +
                           out_dir("join-fixed"));
  ASSERT_EQ(fixed.code, 0) << fixed.err;
  EXPECT_EQ(fixed.out.find("roulette"), std::string::npos);
  for (const std::string option : {"--rr-threshold", "--rr-join-threshold"})
    for (const std::string bad : {"-1", "1001", "Auto", "2x", "", "nan", "inf"}) {
      const CliRun r = run("trace " + kScene + " --spp 1 --out " + out_dir("bad") + " " + option + " '" + bad + "'");
      EXPECT_EQ(r.code, 2) << bad;
      EXPECT_EQ(r.err, option + ": expected auto or a number from 0 to 1000, got '" + bad + "'\nRun with --help for more information.\n") << bad;
    }
}

// Issue 39: --splits' default is the profile's (resolved_splits(), trace/render.h), recorded resolved:
// auto (0) with next-event estimation and without a light subpath or a manifold connector, else 1
// (pt too: it finds the light by chance); an explicit --splits wins.
TEST(SplitsOption, DefaultsPerProfileAndAnExplicitCountWins) {
  const std::vector<std::pair<std::string, int>> cases = {
      {"--renderer pt", 1},           {"--renderer pt-nee", 0},          {"--renderer pt-nee+distant", 0},
      {"--renderer pt-nee+mirror", 0}, {"--renderer pbrt-v4-path", 0},   {"--renderer mitsuba3-path", 0},
      {"--renderer pt-nee+manifold", 1}, {"--renderer lt", 1},           {"--renderer bdpt", 1},
      {"--renderer pbrt-v4-bdpt", 1}, {"--renderer mitsuba3-ptracer", 1}, {"--renderer pt-nee --splits 1", 1},
      {"--renderer bdpt --splits auto", 0}, {"--renderer pt-nee --splits 4", 4}};
  int n = 0;
  for (const auto& [args, splits] : cases) {
    const std::string d = out_dir("splits-default-" + std::to_string(n++));
    const CliRun r = run("trace samples/scenes/cornell.json --spp 1 --resolution 8x8 --no-images --quiet " + args + " --out " + d);
    ASSERT_EQ(r.code, 0) << args << r.err;
    std::ifstream shard(d + "/render.shard", std::ios::binary);
    const std::string bytes((std::istreambuf_iterator<char>(shard)), std::istreambuf_iterator<char>());
    EXPECT_NE(bytes.find("\"splits\": " + std::to_string(splits) + ","), std::string::npos) << args;
  }
}

// --splits auto's pilot reads the pixels' sums whatever the render keeps: with --no-images (as
// `pathex bias` renders R) the counts, and so the histogram, are those of the render with images.
TEST(SplitsOption, AutoSplitsAlikeWithoutImages) {
  const std::string common = "trace samples/scenes/small-light-caustic.json --renderer pt-nee --spp 4 --quiet --json --out ";
  const CliRun with = run(common + out_dir("auto-images"));
  const CliRun without = run(common + out_dir("auto-no-images") + " --no-images");
  const CliRun unsplit = run(common + out_dir("auto-unsplit") + " --no-images --splits 1");
  ASSERT_EQ(with.code, 0) << with.err;
  ASSERT_EQ(without.code, 0) << without.err;
  ASSERT_EQ(unsplit.code, 0) << unsplit.err;
  const nlohmann::json a = nlohmann::json::parse(with.out), b = nlohmann::json::parse(without.out),
                       c = nlohmann::json::parse(unsplit.out);
  EXPECT_EQ(a["total"], b["total"]);
  EXPECT_EQ(a["paths"], b["paths"]);
  EXPECT_NE(a["total"], c["total"]);  // and auto is not --splits 1 there
}

// Each limit reaches the walk: at its extreme every walk fails for the reason it governs.
TEST(ManifoldOptions, TheLimitsReachTheWalk) {
  const nlohmann::json d = manifold_stats("");
  ASSERT_GT(d["successes"].get<long>(), 0);

  const nlohmann::json one = manifold_stats("--manifold-iterations 1");
  EXPECT_GT(one["failures"]["iteration_limit"].get<long>(), d["failures"]["iteration_limit"].get<long>());
  EXPECT_LE(one["mean_iterations"].get<double>(), 1.0);

  const nlohmann::json shortest = manifold_stats("--manifold-min-segment 0.99");  // every segment is shorter
  EXPECT_EQ(shortest["successes"], 0);
  EXPECT_GT(shortest["failures"]["too_short"].get<long>(), d["failures"]["too_short"].get<long>());

  const nlohmann::json singular = manifold_stats("--manifold-singular 0.99");
  EXPECT_GT(singular["failures"]["singular"].get<long>(), 0);
  EXPECT_LT(singular["successes"].get<long>(), d["successes"].get<long>());

  // One seed to find the chains again: their inverse probability is capped, so fewer walks than the default.
  const nlohmann::json trials = manifold_stats("--manifold-trials 1");
  EXPECT_LT(trials["walks"].get<long>(), d["walks"].get<long>());
  EXPECT_GT(trials["truncated"].get<long>(), d["truncated"].get<long>());

  // One seed per batch: a quarter of the default's first-batch seeds.
  const nlohmann::json seeds = manifold_stats("--manifold-seeds 1");
  EXPECT_EQ(seeds["attempts"].get<long>() * 4, d["attempts"].get<long>());

  // The biased variant: as many seeds per join as asked, no batches after them (every walk is an
  // attempt's, nothing truncated).
  const nlohmann::json biased = manifold_stats("--manifold-biased-trials 8");
  EXPECT_EQ(biased["attempts"].get<long>(), d["attempts"].get<long>() * 2);
  EXPECT_LE(biased["walks"].get<long>(), biased["attempts"].get<long>());
  EXPECT_EQ(biased["truncated"].get<long>(), 0);
}

TEST(ManifoldOptions, MergeRefusesRendersWithOtherLimits) {
  const std::string a = out_dir("a"), b = out_dir("b"), m = out_dir("m");
  const std::string common = "trace " + kScene + " --renderer pt-nee+manifold --spp 1 --resolution 8x8 --no-images --quiet --out ";
  ASSERT_EQ(run(common + a).code, 0);
  ASSERT_EQ(run(common + b + " --manifold-iterations 20").code, 0);
  const CliRun r = run("merge " + a + " " + b + " --out " + m);
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: " + b + "/render.shard and " + a +
                       "/render.shard are not of one render: another --manifold-iterations (20 against 64)\n");
  // A real number is named with the shortest text that reads back the same.
  const std::string c = out_dir("c");
  ASSERT_EQ(run(common + c + " --manifold-threshold 0.0001").code, 0);
  const CliRun t = run("merge " + a + " " + c + " --out " + m);
  EXPECT_EQ(t.code, 2);
  EXPECT_NE(t.err.find("are not of one render: another --manifold-threshold (0.0001 against 1e-05)\n"), std::string::npos) << t.err;
  // Where no manifold connector runs, the limits change nothing and are not part of the render.
  const std::string s0 = out_dir("s0"), s1 = out_dir("s1");
  const std::string bdpt = "trace " + kScene + " --renderer bdpt --spp 2 --resolution 8x8 --no-images --quiet --out ";
  ASSERT_EQ(run(bdpt + s0 + " --shard 0/2").code, 0);
  ASSERT_EQ(run(bdpt + s1 + " --shard 1/2 --manifold-iterations 20").code, 0);
  const CliRun ok = run("merge " + s0 + " " + s1 + " --quiet --out " + m);
  EXPECT_EQ(ok.code, 0) << ok.err;
  // The shard header records the limits of a render that runs the connector, and null otherwise.
  EXPECT_EQ(shard_header(b)["options"]["manifold"],
            nlohmann::json::parse(R"({"max_iterations": 20, "threshold": 1e-05, "min_segment": 0.001, "singular": 1e-07,
                                     "max_trials": 2000, "seeds": 4, "rate": 0.125})"));
  EXPECT_TRUE(shard_header(s1)["options"]["manifold"].is_null());
  // The biased variant is recorded (only when set) and not merged with the unbiased estimator.
  const std::string e = out_dir("e");
  ASSERT_EQ(run(common + e + " --manifold-biased-trials 8").code, 0);
  EXPECT_EQ(shard_header(e)["options"]["manifold"]["biased_trials"], 8);
  const CliRun u = run("merge " + a + " " + e + " --out " + m);
  EXPECT_EQ(u.code, 2);
  EXPECT_NE(u.err.find("are not of one render: another --manifold-biased-trials (8 against 0)\n"), std::string::npos) << u.err;
  // So is a rate below 1 (its samples weigh the connector by it).
  const std::string q = out_dir("q");
  ASSERT_EQ(run(common + q + " --manifold-rate 0.25").code, 0);
  EXPECT_EQ(shard_header(q)["options"]["manifold"]["rate"], 0.25);
  // pt-nee+manifold's default rate (where an eye path that hits an area light shares the paths) is recorded too.
  EXPECT_EQ(shard_header(a)["options"]["manifold"]["rate"], 0.125);
  const CliRun v = run("merge " + a + " " + q + " --out " + m);
  EXPECT_EQ(v.code, 2);
  EXPECT_NE(v.err.find("are not of one render: another --manifold-rate (0.25 against 0.125)\n"), std::string::npos) << v.err;
  // bdpt+manifold's defaults (its light tracing and joins also sample the paths the camera sees directly):
  // recorded resolved, so its shards and a merge agree on them.
  const std::string bm = out_dir("bm");
  ASSERT_EQ(run("trace " + kScene + " --renderer bdpt+manifold --spp 1 --resolution 8x8 --no-images --quiet --out " + bm).code, 0);
  EXPECT_EQ(shard_header(bm)["options"]["manifold"]["rate"], 0.125);
  EXPECT_EQ(shard_header(bm)["options"]["manifold"]["seeds"], 1);
  for (const std::string& dir : {a, b, c, e, q, s0, s1, m, bm}) std::filesystem::remove_all(dir);
}

TEST(ManifoldOptions, ResumeTakesTheLimitsFromTheFolder) {
  const std::string a = out_dir("resume");
  ASSERT_EQ(run("trace " + kScene + " --renderer bdpt --spp 1 --resolution 8x8 --no-images --quiet --out " + a).code, 0);
  for (const std::string o : {"--manifold-iterations 8", "--manifold-threshold 0.001", "--manifold-min-segment 0",
                               "--manifold-singular 0", "--manifold-trials 3", "--manifold-seeds 2", "--manifold-biased-trials 4",
                               "--manifold-rate 0.5"}) {
    const CliRun r = run("trace --resume " + a + " " + o);
    EXPECT_EQ(r.code, 2) << o;
    EXPECT_EQ(r.err, "pathex: error: --resume takes the render's settings from " + a + "; " + o.substr(0, o.find(' ')) +
                         " cannot be given with it\n");
  }
  std::filesystem::remove_all(a);
}

}  // namespace
