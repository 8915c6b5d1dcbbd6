// `pathex converge` end to end: on the closed sphere of DESIGN §9 (its declared closed form) the
// reported and per-pixel errors fall as 1/sqrt(budget) and the stderr check passes; on the
// near-delta GGX scene it raises the stderr warning; the files, the reference kinds and the
// refusals. The budget is samples per pixel here: time is measured and reported, never asserted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "stats/convergence.h"
#include "support/cli_run.h"
#include "support/stat_seed.h"

namespace {

using pathex::test::CliRun;
using pathex::test::run_pathex;

std::string out_dir(const std::string& name) { return (pathex::test::scratch_dir() / ("converge-" + name)).string(); }

std::vector<double> column(const nlohmann::json& rungs, const char* key) {
  std::vector<double> v;
  for (const auto& r : rungs) v.push_back(r.at(key).is_null() ? std::nan("") : r.at(key).get<double>());
  return v;
}

// The standard error of a least-squares slope of log(y) against log(x) when log(y_i) has standard
// error sigma_i: sqrt(sum (x_i - mean x)^2 sigma_i^2) / sum (x_i - mean x)^2 over log x.
double slope_std_error(const std::vector<double>& x, const std::vector<double>& sigma) {
  double mean = 0, sxx = 0, var = 0;
  for (double v : x) mean += std::log(v) / static_cast<double>(x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = std::log(x[i]) - mean;
    sxx += d * d;
    var += d * d * sigma[i] * sigma[i];
  }
  return std::sqrt(var) / sxx;
}

// The slopes of the errors against the budget, over a ladder spanning a factor 64, with tolerances
// in standard errors of the slope:
//
// - the reported stderr (batch means): at B batches (B = spp up to 32: passes go to the batches
//   round-robin) its log has standard error 1/sqrt(2 (B - 1)) for normal batch means, so the slope
//   has 0.049. It must fall at least as 1/sqrt(budget), within 5 of those (0.25): at most -0.25.
//   One-sided since issue 36: converge renders with the Sobol sampler, whose batches are now
//   independent replicates of budget/B points each, and both the true error and the (honest)
//   stderr fall faster than 1/sqrt(budget) once a replicate holds several points (at this seed
//   bdpt's one- and three-bounce stderr: slopes -0.86 and -1.36; pt-nee's three-bounce stderr
//   reaches rounding at 1024 spp: -5.1). That catches a stderr that does not fall; converge's χ²
//   check below (both tails) compares it with the true error rung by rung.
// - the per-pixel RMS error (256 pixels): its slope scattered by 0.015-0.020 at 100 seeds (normal
//   pixel errors would give 0.014), so kRmsSlopeSE = 0.02. Under Sobol the error may fall faster
//   than 1/sqrt(budget) (bdpt's three-bounce class: -1.37 at this seed with independent replicates),
//   so the check is one-sided: at most -0.5 + 4 kRmsSlopeSE = -0.42 (a false failure below 3e-5 per
//   slope, 2e-4 for the six). An error that falls as budget^-0.4 (a bias floor appearing; test-only,
//   the errors scaled by budget^0.1) failed 30 of 30 seeds, 104 of the 150 slopes (measured before
//   issue 36).
// - a series at single-precision rounding already at the smallest budget (its first value below
//   kRoundingFloor of the estimate: pt-nee's one- and two-bounce classes have no variance, and its
//   three-bounce estimate under the Sobol sampler is exact in every pixel though its batches differ)
//   has no noise to fall, and is not fitted.
//
// converge's own checks of each ladder (the χ² check at false-alarm rate kStderrCheckAlpha = 1e-3,
// the stability check) may raise at most one alarm over the run: at 100 seeds (2026-12-05) 4 runs
// had one (bdpt's two-bounce χ² 20.7 against 18.5 at seed 2), none two. Before this calibration
// (±0.1 on both slopes, rounding-level series fitted) the test failed at 69 of 100 seeds;
// bench/README.md (2026-12-03) has the command.
TEST(Converge, ClosedFormSceneErrorsFallAsOneOverSqrtAndStderrIsHonest) {
  constexpr double kStderrSlopeSigmas = 5.0, kRmsSlopeSE = 0.02, kRmsSlopeSigmas = 4.0;
  const std::string dir = out_dir("sphere");
  const CliRun r = run_pathex("converge samples/scenes/closed-sphere-point.json --renderer pt-nee --renderer bdpt "
                              "--spp 16,64,256,1024 --resolution 16x16 --json --seed " +
                              std::to_string(pathex::test::stat_seed(1)) + " --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("reference").at("kind"), "closed-form");
  EXPECT_EQ(j.at("complete"), true);
  // converge's checks each raise a false alarm at 1e-3 per ladder (χ² in each tail, stability):
  // over this run's ladders (2 renderers, 5 classes) one alarm is 1-3 % likely, two below 0.05 %.
  // So at most one may fire; a stderr that lies does on most ladders (NearDeltaScene... below).
  EXPECT_LE(j.at("warnings").size(), 1u) << j.at("warnings").dump();
  int alarms = 0;
  const std::vector<double> spp = {16, 64, 256, 1024};
  std::vector<double> log_stderr_se;
  // Every rung's stderr has kDefaultDof = 16 degrees of freedom (16 pixel groups of two replicates).
  for (std::size_t i = 0; i < spp.size(); ++i) log_stderr_se.push_back(1.0 / std::sqrt(2.0 * pathex::kDefaultDof));
  const double stderr_slope_se = slope_std_error(spp, log_stderr_se);
  EXPECT_NEAR(stderr_slope_se, 0.057, 0.001);
  int fitted = 0;
  for (const auto& ren : j.at("renderers")) {
    EXPECT_EQ(ren.at("nonfinite_samples"), 0);
    for (const auto& c : ren.at("classes")) {
      const std::string what = ren.at("name").get<std::string>() + " " + c.at("name").get<std::string>();
      const nlohmann::json& check = c.at("stderr_check");
      if (check.at("chi2").is_number() && check.at("limit").is_number())
        pathex::test::stat_log(what + " chi2/limit", check.at("chi2").get<double>() / check.at("limit").get<double>(), 1);
      if (check.at("stability").is_number()) pathex::test::stat_log(what + " stability", check.at("stability").get<double>(), 0.7);
      // converge does not judge a stderr against the reference where the renderer cannot sample the
      // whole class (cannot_sample): its χ² flags are reported there but raise no warning (seed 42:
      // pt-nee's total, too_large); the stability check does.
      const bool alarm = ((check.at("disagrees").get<bool>() || check.at("too_large").get<bool>()) && c.at("cannot_sample").is_null()) ||
                         check.at("unstable").get<bool>();
      EXPECT_EQ(alarm, !c.at("warning").is_null()) << what;
      alarms += alarm ? 1 : 0;
      ASSERT_EQ(c.at("rungs").size(), 4u) << what;
      const double rounding = pathex::kRoundingFloor * c.at("rungs").back().at("estimate").get<double>();
      const std::vector<double> se = column(c.at("rungs"), "stderr");
      if (se.front() >= rounding) {
        const double slope = pathex::loglog_slope(spp, se);
        pathex::test::stat_log(what + " reported stderr slope", slope, kStderrSlopeSigmas * stderr_slope_se);
        EXPECT_LE(slope, -0.5 + kStderrSlopeSigmas * stderr_slope_se) << what << " reported stderr";
        ++fitted;
      }
      const std::vector<double> rms = column(c.at("rungs"), "rms_pixel_error");
      if (rms.front() >= rounding) {
        const double slope = pathex::loglog_slope(spp, rms);
        pathex::test::stat_log(what + " per-pixel RMS slope", slope, kRmsSlopeSigmas * kRmsSlopeSE);
        EXPECT_LE(slope, -0.5 + kRmsSlopeSigmas * kRmsSlopeSE) << what << " per-pixel RMS";
        ++fitted;
      }
    }
  }
  EXPECT_LE(alarms, 1);
  // pt-nee: total (both), bounce3 (both: with independent replicates its 16-spp rung is no longer
  // exact in every pixel); bdpt: every class (both).
  EXPECT_EQ(fitted, 12);
  EXPECT_EQ(pathex::test::read_file(dir + "/converge.svg").substr(0, 5), "<?xml");
  EXPECT_EQ(pathex::test::read_file(dir + "/converge.png").substr(1, 3), "PNG");
  EXPECT_EQ(pathex::test::read_file(dir + "/converge.json"), r.out);
}

// Light tracing finds the 1e-3 highlight almost never (a light path must land within about 1e-3
// of the specular point), and reports its near-zero estimates with a near-zero stderr.
TEST(Converge, NearDeltaSceneRaisesTheStderrWarning) {
  const CliRun r = run_pathex("converge samples/scenes/hard/ggx-point-wide-0.001.json --renderer lt --spp 4,16,64 --out " +
                              out_dir("near-delta"));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("WARNING lt: the reported stderr disagrees with the true error: chi2 "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\nwarnings\n  lt on highlight: the reported stderr disagrees"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("most efficient renderer per class"), std::string::npos);
  const nlohmann::json j = nlohmann::json::parse(pathex::test::read_file(out_dir("near-delta") + "/converge.json"));
  const auto& c = j.at("renderers").at(0).at("classes").at(1);
  EXPECT_EQ(c.at("name"), "highlight");
  EXPECT_TRUE(c.at("stderr_check").at("disagrees"));
  EXPECT_GT(c.at("stderr_check").at("chi2").get<double>(), c.at("stderr_check").at("limit").get<double>());
  EXPECT_FALSE(c.at("warning").is_null());
  EXPECT_EQ(j.at("warnings").size(), 1u);  // the whole image has no reference: no check
}

// Without a closed form, converge makes a reference run, names it and writes it; that run can be
// the --reference of the next ladder, with per-pixel errors from its EXR.
TEST(Converge, ReferenceRunIsWrittenAndReadBack) {
  const std::string first = out_dir("run"), second = out_dir("file");
  CliRun r = run_pathex("converge samples/scenes/point-plane.json --renderer pt-nee --spp 4,16 --resolution 8x8 --quiet --out " + first);
  ASSERT_EQ(r.code, 0) << r.err;
  // The default reference renderer is pathex bias's (bdpt plus the connectors the scene needs), not
  // the first --renderer.
  EXPECT_NE(r.out.find("reference: run (a reference run of bdpt"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" at 64 spp"), std::string::npos) << r.out;
  ASSERT_TRUE(std::filesystem::exists(first + "/reference.json"));
  ASSERT_TRUE(std::filesystem::exists(first + "/reference.exr"));
  r = run_pathex("converge samples/scenes/point-plane.json --renderer bdpt --spp 4,16 --resolution 8x8 --json --out " + second +
                 " --reference " + first + "/reference.json");
  ASSERT_EQ(r.code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("reference").at("kind"), "file");
  EXPECT_EQ(j.at("reference").at("classes").at(0).at("per_pixel"), true);
  EXPECT_FALSE(j.at("renderers").at(0).at("classes").at(0).at("rungs").at(0).at("rms_pixel_error").is_null());
}

// Issue 36: on point-glass (a point light's caustic through a glass sphere) pt-nee cannot sample
// the caustic. The default reference samples everything the ladder's renderers sample, so every
// class is measurable, and pt-nee is never ranked on a class holding a path it cannot sample. With
// pt-nee as the reference, the classes holding paths bdpt samples and pt-nee cannot are "not
// measurable with this reference": no error, no z, no ranking against it.
TEST(Converge, ReferencesSeeWhatTheyJudgeAndNoRendererIsRankedOnWhatItCannotSample) {
  const std::string dir = out_dir("reach"), dir2 = out_dir("reach-pt-nee");
  CliRun r = run_pathex("converge samples/scenes/point-glass.json --renderer pt-nee --renderer bdpt --spp 4,16 --resolution 8x8 "
                        "--json --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  nlohmann::json j = nlohmann::json::parse(r.out);
  const std::string ref_name = j.at("reference").at("run").at("renderer");
  EXPECT_EQ(ref_name.rfind("bdpt+", 0), 0u) << ref_name;
  for (const auto& c : j.at("reference").at("classes")) EXPECT_EQ(c.at("measurable"), true) << c.dump();
  const auto& pt_nee = j.at("renderers").at(0);
  ASSERT_EQ(pt_nee.at("name"), "pt-nee");
  ASSERT_EQ(pt_nee.at("classes").at(0).at("name"), "total");
  EXPECT_TRUE(pt_nee.at("classes").at(0).at("cannot_sample").is_string());  // the caustic's paths
  std::size_t ranked_classes = 0;
  for (const auto& b : j.at("best")) {
    ++ranked_classes;
    for (const auto& c : j.at("renderers")) {
      if (c.at("name") != b.at("renderer")) continue;
      for (const auto& cc : c.at("classes")) {
        if (cc.at("name") == b.at("class")) {
          EXPECT_TRUE(cc.at("cannot_sample").is_null()) << b.dump();
        }
      }
    }
    EXPECT_NE(b.at("class"), "total") << "pt-nee and bdpt both miss light of the total that the reference samples";
  }
  EXPECT_GE(ranked_classes, 1u);  // bdpt on "local" (L.*DD.*E)
  // pt-nee's estimate of a class it cannot sample misses light that the reference holds: that error
  // is its bias, not a stderr that lies, so no stderr warning is given for it (but the check's
  // numbers are there, and say the error is far outside the stderr).
  const auto& total = pt_nee.at("classes").at(0);
  EXPECT_TRUE(total.at("warning").is_null()) << total.dump();
  EXPECT_TRUE(total.at("stderr_check").at("disagrees")) << total.dump();
  for (const auto& w : j.at("warnings")) EXPECT_EQ(w.get<std::string>().rfind("pt-nee on total", 0), std::string::npos) << w;
  // The first --renderer as the reference: the classes it cannot see are not measurable.
  r = run_pathex("converge samples/scenes/point-glass.json --renderer pt-nee --renderer bdpt --spp 4,16 --resolution 8x8 "
                 "--reference-renderer pt-nee --quiet --out " + dir2);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("class total $all: reference not measurable with this reference (pt-nee cannot sample LS"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("  total: not measurable with this reference (pt-nee cannot sample LS"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("sigma off"), std::string::npos) << "no error is measured against a reference that cannot see the class:\n"
                                                         << r.out;
  EXPECT_EQ(r.out.find("x pt-nee's"), std::string::npos) << r.out;
}

// --only measures the requested classes alone (as pathex trace --only): the table and
// converge.json name them, list every other class as not rendered, and the estimate is the closed
// form of those paths (two bounces in the closed sphere: rho^2 I / (pi r^2)), within 3 sigma.
TEST(Converge, OnlyMeasuresTheRequestedClassesAndListsTheOthersNotRendered) {
  const std::string dir = out_dir("only");
  CliRun r = run_pathex("converge samples/scenes/closed-sphere-point.json --renderer bdpt --renderer pt-nee --only 'L.{6}E' "
                        "--spp 4,16 --resolution 8x8 --quiet --out " + dir);
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("\nrendered only only-1 (L.{6}E)\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\ndirect: not rendered\n"), std::string::npos) << r.out;
  std::ifstream in(dir + "/converge.json");
  const nlohmann::json j = nlohmann::json::parse(in);
  ASSERT_EQ(j.at("only").size(), 1u);
  EXPECT_EQ(j.at("only")[0].at("name"), "only-1");
  std::vector<std::string> skipped;
  for (const auto& c : j.at("not_rendered")) {
    EXPECT_EQ(c.at("rendered"), false);
    skipped.push_back(c.at("name"));
  }
  EXPECT_EQ(skipped, (std::vector<std::string>{"local", "emission", "direct", "indirect", "caustic"}));
  const double expected = 0.25 / M_PI;
  for (const auto& renderer : j.at("renderers")) {
    std::vector<std::string> names;
    for (const auto& c : renderer.at("classes")) names.push_back(c.at("name"));
    EXPECT_EQ(names, (std::vector<std::string>{"requested", "only-1"}));  // the requested total, then the class
    const auto& last = renderer.at("classes").at(1).at("rungs").back();
    EXPECT_LE(std::fabs(last.at("estimate").get<double>() - expected), 3.0 * last.at("stderr").get<double>() + 1e-6 * expected)
        << renderer.at("name") << " " << last.dump();
  }
  // A class the scene cannot have: nothing runs, and it says why.
  r = run_pathex("converge samples/scenes/closed-sphere-point.json --renderer bdpt --only '$caustic' --spp 4 --resolution 8x8 "
                 "--quiet --out " + out_dir("only-none"));
  EXPECT_EQ(r.code, 1) << r.err;
  EXPECT_NE(r.out.find("nothing to render: no strategy of bdpt samples a path of the requested classes"), std::string::npos) << r.out;
}

TEST(Converge, RefusalsExitTwo) {
  CliRun r = run_pathex("converge samples/scenes/point-plane.json --renderer pt-nee --spp 16,4 --out " + out_dir("bad"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --spp '16,4': budgets must increase\n");
  r = run_pathex("converge samples/scenes/point-plane.json --renderer pt-nee --spp 4 --time 1 --out " + out_dir("bad"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --spp and --time are alternatives: give one ladder\n");
  r = run_pathex("converge samples/scenes/point-plane.json --renderer pt-nee --spp 4,x --out " + out_dir("bad"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --spp '4,x': 'x' is not a whole number of samples per pixel; expected a comma-separated list such as 4,16,64,256\n");
  r = run_pathex("converge samples/scenes/point-plane.json --renderer pt-nee --reference nothing.txt --out " + out_dir("bad"));
  EXPECT_EQ(r.code, 2);
  EXPECT_EQ(r.err, "pathex: error: --reference nothing.txt: expected a histogram.json or an .exr file of an earlier run\n");
}

// --- MPI: the rungs split across ranks give the numbers of one process ---

#ifndef PATHEX_MPI_BINARY
#define PATHEX_MPI_BINARY ""
#endif

// converge.json without what depends on the clock or the process layout: times, efficiencies (and
// the ranking made of them), the slopes against time, the output folder's name.
nlohmann::json without_timing(nlohmann::json j) {
  j.erase("timing");
  j.erase("best");
  j.erase("ranks");
  j.erase("threads");
  j["reference"].erase("source");
  j["reference"]["run"].erase("cpu_s");
  j["reference"]["run"].erase("wall_s");
  for (auto& ren : j["renderers"])
    for (auto& c : ren["classes"]) {
      c.erase("slope");
      c.erase("efficiency");
      for (auto& r : c["rungs"])
        for (const char* k : {"cpu_s", "wall_s", "efficiency"}) r.erase(k);
    }
  return j;
}

TEST(Converge, MpiRanksSplitEveryRungAndGiveTheNumbersOfOneProcess) {
  if (std::string(PATHEX_MPI_BINARY).empty()) GTEST_SKIP() << "pathex-mpi is not built (MPI was not found at configure time)";
  // A reference run of its own (no closed form) and two renderers: every render converge makes,
  // split three ways.
  const std::string args = " converge samples/scenes/cornell.json --renderer pt-nee --renderer bdpt --spp 4,8 --resolution 16x16 "
                           "--threads 1 --json --out ";
  const std::string one = out_dir("mpi-one"), three = out_dir("mpi-three");
  const CliRun s = run_pathex(args + one);
  ASSERT_EQ(s.code, 0) << s.err;
  const CliRun m = pathex::test::run_mpirun("-n 3 " + pathex::test::shell_quote(PATHEX_MPI_BINARY) + args + three);
  ASSERT_EQ(m.code, 0) << m.out;
  // Rank 0 alone prints: one JSON document (the other ranks print nothing).
  const nlohmann::json printed = nlohmann::json::parse(m.out);
  const nlohmann::json single = nlohmann::json::parse(s.out);
  EXPECT_EQ(printed.at("ranks"), 3);
  EXPECT_EQ(single.at("ranks"), 1);
  EXPECT_EQ(without_timing(printed), without_timing(single));
  EXPECT_EQ(pathex::test::read_file(three + "/converge.json"), m.out);
  // The reference run's outputs are computed from the same exact sums: the same bytes.
  for (const char* f : {"reference.json", "reference.exr"})
    EXPECT_TRUE(pathex::test::read_file(one + "/" + f) == pathex::test::read_file(three + "/" + f)) << f << " differs";
}

}  // namespace
