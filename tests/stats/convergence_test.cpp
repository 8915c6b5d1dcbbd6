// The statistics of `pathex converge` (stats/convergence.h): the χ² quantile against tables,
// the stability of the batch variance for normal and spiky batch means, the stderr check on
// honest and lying ladders, and the log-log slope.
#include "stats/convergence.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "io/estimate_text.h"
#include "stats/significance.h"
#include "support/stat_seed.h"

namespace pathex {
namespace {

// Upper points of χ² (Abramowitz & Stegun table 26.8).
TEST(Convergence, ChiSquareQuantilesMatchTheTable) {
  EXPECT_NEAR(chi2_upper_quantile(1, 1e-3), 10.828, 1e-3);
  EXPECT_NEAR(chi2_upper_quantile(4, 1e-3), 18.467, 1e-3);
  EXPECT_NEAR(chi2_upper_quantile(5, 1e-3), 20.515, 1e-3);
  EXPECT_NEAR(chi2_upper_quantile(10, 1e-3), 29.588, 1e-3);
  EXPECT_NEAR(chi2_upper_quantile(4, 0.05), 9.488, 1e-3);
}

TEST(Convergence, BatchVarianceIsStableForNormalMeansAndNotForASpike) {
  std::mt19937_64 rng(test::stat_seed(3));
  std::normal_distribution<double> normal(1.0, 0.1);
  double sum = 0;
  for (int trial = 0; trial < 200; ++trial) {
    std::vector<double> x(32);
    for (double& v : x) v = normal(rng);
    sum += variance_relative_error(x);
  }
  EXPECT_NEAR(sum / 200, std::sqrt(2.0 / 31.0), 0.05);  // 0.254 for normal batch means
  std::vector<double> spike(32, 0.0);
  spike[7] = 32.0;  // one batch holds the whole estimate
  EXPECT_GT(variance_relative_error(spike), kUnstableVariance);
  EXPECT_TRUE(std::isnan(variance_relative_error({1.0, 2.0, 3.0})));  // too few batches
  EXPECT_TRUE(std::isnan(variance_relative_error(std::vector<double>(8, 2.0))));
}

// Every estimate carries its stderr's stability (16 pixel groups of two replicates, as the tracer
// writes them), and pathex trace flags it where it reaches kUnstableVariance, unless the stderr is
// rounding: normal groups (median 0.31) are not flagged, one group holding the variance is, and an
// estimator with no variance (the same value in every batch but one a float step off) is not.
TEST(Convergence, AnEstimatesStderrStabilityIsFlaggedWhereOneGroupCarriesIt) {
  const VarianceDesign design(std::vector<std::uint64_t>(32, 100), 16);
  const auto estimate = [&](const std::vector<double>& lum) {
    std::vector<ExactRgb> sums;
    for (double v : lum) sums.push_back(*to_exact(Rgb{v, v, v}));
    return estimate_of(sums, design, 3200);
  };
  std::mt19937_64 rng(test::stat_seed(5));
  std::normal_distribution<double> normal(100.0, 10.0);
  std::vector<double> lum(32);
  for (double& v : lum) v = normal(rng);
  const Estimate well = estimate(lum);
  EXPECT_LT(well.stability, kUnstableVariance);  // a normal render reaches it 3 times in 10,000
  EXPECT_EQ(unstable_text(well), "");
  std::vector<double> spike(32, 100.0);
  spike[10] = 400.0;  // group 5's first replicate: one rare large sample
  const Estimate spiky = estimate(spike);
  // One nonzero group term v of G: mean v / G, spread v² (G − 1) / G, so sqrt(spread / (G (G − 1))) / mean = 1.
  EXPECT_NEAR(spiky.stability, 1.0, 1e-12);
  EXPECT_EQ(unstable_text(spiky), "; its stderr is unstable (a few pixel groups carry it: its square's relative error is 1.00)");
  std::vector<double> exact(32, 100.0);
  exact[3] = 100.0 * (1.0 + 1e-9);
  const Estimate rounding = estimate(exact);
  EXPECT_GT(rounding.stability, kUnstableVariance);
  EXPECT_LT(rounding.std_error, kRoundingFloor * rounding.luminance);
  EXPECT_EQ(unstable_text(rounding), "");
}

TEST(Convergence, StderrCheckPassesHonestLaddersAndFlagsLyingOnes) {
  // Honest: errors of about one stderr.
  const StderrCheck honest = check_stderr({{1.01, 0.01, 0.25}, {0.995, 0.005, 0.3}, {1.002, 0.0025, 0.2}}, 1.0, 0.0);
  EXPECT_FALSE(honest.lies());
  EXPECT_EQ(honest.dof, 3);
  EXPECT_NEAR(honest.chi2, 1.0 + 1.0 + 0.64, 1e-6);
  // 14 sigma off at one rung.
  const StderrCheck off = check_stderr({{0.86, 0.01, 0.25}, {1.0, 0.005, 0.3}}, 1.0, 0.0);
  EXPECT_TRUE(off.disagrees);
  EXPECT_NEAR(off.max_abs_z, 14.0, 1e-6);
  EXPECT_EQ(off.max_z_rung, 0);
  // A peak missed entirely: estimate 0 with stderr 0 (off by a million times the rounding floor).
  const StderrCheck missed = check_stderr({{0.0, 0.0, std::numeric_limits<double>::quiet_NaN()}}, 0.04, 0.0);
  EXPECT_TRUE(missed.disagrees);
  EXPECT_NEAR(missed.max_abs_z, 1.0 / kRoundingFloor, 1.0);
  EXPECT_TRUE(std::isinf(check_stderr({{0.1, 0.0, 0.5}}, 0.0, 0.0).max_abs_z));  // a zero reference
  // An exact estimator (no variance) is within single-precision rounding of the closed form.
  EXPECT_FALSE(check_stderr({{0.15915494, 1e-11, 0.25}}, 0.159154943, 0.0).lies());
  // Unstable: most rungs' batch variance is carried by a few batches.
  EXPECT_TRUE(check_stderr({{1.0, 0.1, 0.9}, {1.0, 0.1, 0.8}, {1.0, 0.1, 0.2}}, 1.0, 0.0).unstable);
  // The reference's own stderr widens the band.
  EXPECT_FALSE(check_stderr({{1.05, 0.01, 0.25}}, 1.0, 0.02).disagrees);
}

// A batch-means z is Student's t with B − 1 degrees of freedom; the χ² check sums it as the normal
// deviate of the same two-sided tail. With many degrees of freedom that is z itself; with 31 a
// 3.5σ deviation is a normal 3.19σ (both tails 1.4e-3), and the χ² of four of them falls from 49
// to 40.8 — an honest ladder of 32 batches no longer alarms at t's heavier tail.
TEST(Convergence, StderrCheckReadsBatchMeansZAsStudentsT) {
  EXPECT_NEAR(normal_equivalent(3.0, 100000), 3.0, 1e-3);
  const double y = normal_equivalent(3.5, 31);
  EXPECT_LT(y, 3.5);
  EXPECT_NEAR(std::erfc(y / std::sqrt(2.0)), student_two_sided_tail(3.5, 31), 1e-9);
  EXPECT_NEAR(y, 3.19, 0.01);
  EXPECT_EQ(normal_equivalent(-3.5, 31), y);
  EXPECT_EQ(normal_equivalent(200.0, 31), 200.0);  // beyond the tail's quadrature: z itself
  std::vector<RungError> rungs(4, RungError{1.035, 0.01, 0.25, 31});
  const StderrCheck t = check_stderr(rungs, 1.0, 0.0);
  EXPECT_NEAR(t.chi2, 4 * y * y, 1e-6);
  for (RungError& r : rungs) r.dof = 0;  // taken as normal: z² as it is
  EXPECT_NEAR(check_stderr(rungs, 1.0, 0.0).chi2, 4 * 3.5 * 3.5, 1e-6);
}

// The Welch–Satterthwaite degrees of freedom of a difference: equal variances add their dof; one
// variance alone gives its own; one that dominates gives nearly its own; both 0 give the fewer.
TEST(Significance, WelchDofOfADifference) {
  EXPECT_DOUBLE_EQ(welch_dof(1.0, 16, 1.0, 16), 32.0);
  EXPECT_DOUBLE_EQ(welch_dof(4.0, 16, 0.0, 31), 16.0);
  EXPECT_DOUBLE_EQ(welch_dof(0.0, 16, 4.0, 31), 31.0);
  EXPECT_DOUBLE_EQ(welch_dof(0.0, 16, 0.0, 31), 16.0);
  // (va + vb)² / (va²/da + vb²/db) = 1.21 / (1/16 + 0.01/16) = 19.168…
  EXPECT_NEAR(welch_dof(1.0, 16, 0.1, 16), 1.21 / (1.01 / 16), 1e-12);
  EXPECT_NEAR(welch_dof(1.0, 16, 1e-4, 16), 16.0, 0.01);
}

// Issue 36: the lower tail. χ²_2's lower point at p is −2 ln(1 − p) in closed form (its survival
// function is e^(−x/2)); a ladder whose errors are far inside their error bars — a stderr 30×
// the true error at every rung — is flagged as too large, and an honest one is not. Rungs with a
// stderr at the rounding floor (exact estimators) do not count: an error of 0 there is no sign.
TEST(Convergence, StderrCheckFlagsAStderrThatIsTooLarge) {
  EXPECT_NEAR(chi2_upper_quantile(2, 1.0 - 1e-3), -2.0 * std::log(1.0 - 1e-3), 1e-9);
  EXPECT_NEAR(chi2_upper_quantile(4, 1.0 - 1e-3), 0.09080, 1e-4);  // A & S table 26.8
  const StderrCheck big = check_stderr({{1.0003, 0.01, 0.25}, {0.99985, 0.005, 0.3}, {1.0001, 0.0025, 0.2}, {1.00004, 0.00125, 0.2}}, 1.0, 0.0);
  EXPECT_TRUE(big.too_large);
  EXPECT_FALSE(big.disagrees);
  EXPECT_TRUE(big.lies());
  EXPECT_EQ(big.lower_dof, 4);
  EXPECT_NEAR(big.lower_chi2, 0.0009 + 0.0009 + 0.0016 + 0.001024, 1e-9);
  EXPECT_NEAR(big.lower_limit, 0.09080, 1e-4);
  EXPECT_FALSE(check_stderr({{1.01, 0.01, 0.25}, {0.995, 0.005, 0.3}, {1.002, 0.0025, 0.2}}, 1.0, 0.0).too_large);
  // An exact estimator: its stderr (1e-11) is below the rounding floor of 0.159 (1.6e-7), so its
  // error of 0 is not counted in the lower tail.
  const StderrCheck exact = check_stderr({{0.159154943, 1e-11, 0.25}, {0.159154943, 1e-12, 0.25}}, 0.159154943, 0.0);
  EXPECT_EQ(exact.lower_dof, 0);
  EXPECT_FALSE(exact.lies());
}

TEST(Convergence, LogLogSlope) {
  EXPECT_NEAR(loglog_slope({1, 4, 16, 64}, {1, 0.5, 0.25, 0.125}), -0.5, 1e-12);
  EXPECT_NEAR(loglog_slope({1, 10, 0, 100}, {3, 30, 1, 300}), 1.0, 1e-12);  // x = 0 is left out
  EXPECT_TRUE(std::isnan(loglog_slope({1}, {1})));
}

}  // namespace
}  // namespace pathex
