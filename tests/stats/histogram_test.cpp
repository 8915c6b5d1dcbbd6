// Path-class histograms and per-class images: exact fixed-point sums, batch-means statistics
// against closed forms and the textbook standard error, exact and order-independent merging,
// non-finite contributions, class shares, and lock-free image accumulation.
#include "stats/histogram.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <thread>

#include "film/image.h"
#include "io/estimate_text.h"
#include "io/histogram_json.h"
#include "support/stat_seed.h"

namespace pathex {
namespace {

// A small, fully specified generator (splitmix64), so that the statistical tests are the same
// on every platform. The statistical tests seed it from test::stat_seed (a fixed seed, or
// PATHEX_STAT_SEED: bench/stat_sweep.py) and state their tolerances at a family-wise
// false-failure rate of 0.1 % over their checks.
struct Rng {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1p-53; }
};

Rgb gray(double v) { return {v, v, v}; }

// --- exact sums ---

TEST(ExactSum, RoundsOnceToTheGridAndConvertsBack) {
  for (double v : {0.0, 0.5, -3.25, 1234567.875, -0x1p-64, 0x1p49}) {
    std::optional<ExactRgb> e = to_exact({v, v, v});
    ASSERT_TRUE(e) << v;
    EXPECT_EQ(to_double((*e)[0]), v) << "grid values are exact";
  }
  EXPECT_EQ(to_double((*to_exact(gray(1e-30)))[0]), 0.0) << "below the grid's resolution";
  EXPECT_EQ((*to_exact(gray(0x1p-65 * 3)))[0], ExactSum{2}) << "1.5 grid steps round to nearest even";
  const double inf = std::numeric_limits<double>::infinity();
  for (double bad : {std::nan(""), inf, -inf, kMaxContribution, -kMaxContribution})
    EXPECT_FALSE(to_exact({0.0, bad, 0.0})) << bad;
}

// round_to_fixed() avoids nearbyint's library call and the 128-bit conversion's; it must agree
// with them exactly: ties to even at every magnitude, both signs, and across the fast paths'
// edges (2^52, 2^63, 2^64) up to the 2^114 bound.
TEST(ExactSum, FastRoundingMatchesNearbyint) {
  const auto reference = [](double y) { return static_cast<ExactSum>(static_cast<SignedExactSum>(std::nearbyint(y))); };
  std::vector<double> ys = {0.0, -0.0, 0.5, 1.5, 2.5, -0.5, -1.5, -2.5, 0x1p52 - 0.5, 0x1p52 + 1, 0x1p53 + 2,
                            0x1p63 - 1024, 0x1p63, -0x1p63, 0x1p64, -0x1p64, 0x1p64 + 0x1p12, 0x1p113, -0x1p113,
                            std::nextafter(0x1p63, 0.0), std::nextafter(0x1p52, 0.0), 4503599627370495.5};
  Rng rng{3};
  for (int i = 0; i < 200000; ++i) {
    const double magnitude = std::ldexp(1.0, static_cast<int>(rng.next() % 114));
    const double y = (rng.uniform() * 2.0 - 1.0) * magnitude;
    ys.push_back(y);
    ys.push_back(std::floor(y) + 0.5);  // an exact tie, where representable
  }
  for (double y : ys) ASSERT_EQ(round_to_fixed(y), reference(y)) << std::hexfloat << y;
}

// luminance_exact() converts through 64 bits when a value fits: the same doubles as the 128-bit
// conversion, hence the same luminance, on both sides of the boundary and for wide values.
TEST(ExactSum, LuminanceMatchesThe128BitConversion) {
  const auto reference = [](const ExactRgb& c) {
    const auto v = [&](std::size_t i) { return static_cast<double>(static_cast<SignedExactSum>(c[i])); };
    return round_to_fixed(0.2126 * v(0) + 0.7152 * v(1) + 0.0722 * v(2));
  };
  const SignedExactSum edge = SignedExactSum{1} << 63;
  std::vector<SignedExactSum> vs = {0, 1, -1, edge - 1, edge, -edge, -edge - 1, edge + 1, edge * 3 + 12345,
                                    -(edge * 5) - 7, (SignedExactSum{1} << 100) + 1, -(SignedExactSum{1} << 100) - 1};
  Rng rng{11};
  for (int i = 0; i < 100000; ++i) {
    const ExactSum r = (static_cast<ExactSum>(rng.next()) << 64) | rng.next();
    const auto v = static_cast<SignedExactSum>(r >> (rng.next() % 128));  // of every width
    vs.push_back(rng.next() % 2 ? v : static_cast<SignedExactSum>(ExactSum{0} - static_cast<ExactSum>(v)));  // no signed overflow
  }
  for (std::size_t i = 0; i + 2 < vs.size(); ++i) {
    const ExactRgb c{static_cast<ExactSum>(vs[i]), static_cast<ExactSum>(vs[i + 1]), static_cast<ExactSum>(vs[i + 2])};
    ASSERT_EQ(luminance_exact(c), reference(c)) << i;
  }
}

TEST(ExactSum, TextRoundTrip) {
  const ExactSum top = static_cast<ExactSum>(1) << 127;
  for (ExactSum v : {ExactSum{0}, ExactSum{1}, ExactSum{0} - 1, static_cast<ExactSum>(0x1f) << 70, top - 1, top})
    EXPECT_EQ(exact_from_string(exact_to_string(v)), v) << exact_to_string(v);
  EXPECT_EQ(exact_to_string(ExactSum{0} - 31), "-0x1f");
  EXPECT_EQ(exact_to_string(ExactSum{1} << 64), "0x10000000000000000");  // the value 1.0
  EXPECT_EQ(exact_to_string(top), "-0x80000000000000000000000000000000");
  for (const char* bad : {"", "1", "0x", "0X1", "0x1G", "--0x1", "0x100000000000000000000000000000000",
                          "0x80000000000000000000000000000000"})
    EXPECT_FALSE(exact_from_string(bad)) << bad;
}

// --- batch means ---

TEST(BatchMeans, EqualBatchesGiveTheTextbookFormula) {
  // Four batches of 10 samples with batch means 1, 2, 3, 4: the mean is 2.5 and
  // stderr² = Σ (X_b − X̄)² / (B (B − 1)) = 5 / 12.
  std::vector<ExactRgb> sums;
  for (double s : {10.0, 20.0, 30.0, 40.0}) sums.push_back(*to_exact(gray(s)));
  Estimate e = estimate_of(sums, VarianceDesign({10, 10, 10, 10}, 1), 7);
  EXPECT_DOUBLE_EQ(e.luminance, 2.5);
  EXPECT_DOUBLE_EQ(e.rgb[0], 2.5);
  EXPECT_NEAR(e.std_error, std::sqrt(5.0 / 12.0), 1e-15);
  EXPECT_EQ(e.samples, 7u);
}

TEST(BatchMeans, UnequalBatchesUseTheUnbiasedWeightedForm) {
  // n = (1, 3), S = (2, 3): N = 4, X̄ = 5/4, Σ (S_b − n_b X̄)² = 9/8, N² − Σ n_b² = 6: stderr² = 3/16.
  Estimate e = estimate_of({*to_exact(gray(2)), *to_exact(gray(3))}, VarianceDesign({1, 3}, 1), 4);
  EXPECT_DOUBLE_EQ(e.luminance, 1.25);
  EXPECT_NEAR(e.std_error, std::sqrt(3.0 / 16.0), 1e-15);
}

TEST(BatchMeans, OneNonEmptyBatchHasNoErrorEstimate) {
  Estimate e = estimate_of({*to_exact(gray(3)), ExactRgb{}}, VarianceDesign({3, 0}, 1), 3);
  EXPECT_DOUBLE_EQ(e.luminance, 1.0);
  EXPECT_TRUE(std::isnan(e.std_error));
  Estimate none = estimate_of({ExactRgb{}, ExactRgb{}}, VarianceDesign({0, 0}, 1), 0);
  EXPECT_EQ(none.luminance, 0.0);
  EXPECT_TRUE(std::isnan(none.std_error));
}

// Samples of U(0,1) (variance 1/12) through the whole Histogram pipeline: one run's batch-means
// stderr against the true σ/√N and against the textbook sample stderr of the same data.
TEST(BatchMeans, MatchesTheTextbookStandardErrorOnSyntheticData) {
  const int B = 32, per_batch = 1000;
  const double N = B * per_batch;
  Histogram h(HistogramLayout{B, {}});
  const Histogram::PathId id = h.intern("LSDDSE");
  Rng rng{test::stat_seed(42)};
  double sum = 0, sum2 = 0;
  for (int b = 0; b < B; ++b) {
    for (int i = 0; i < per_batch; ++i) {
      const double u = rng.uniform();
      sum += u;
      sum2 += u * u;
      ASSERT_TRUE(h.add(id, b, Histogram::kNoStrategy, gray(u)));
    }
    h.add_samples(b, per_batch);
  }
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  ASSERT_TRUE(r) << r.error().render();
  const double truth = std::sqrt(1.0 / 12.0 / N);
  const double textbook = std::sqrt((sum2 - sum * sum / N) / (N - 1) / N);
  // The batch means are normal (means of 1000 uniforms), so (B − 1) stderr² / σ²_true is χ² with
  // B − 1 degrees of freedom: stderr / truth lies between the square roots of its two-sided
  // quantiles (Wilson–Hilferty), and stderr / textbook too (textbook / truth is 1 within 0.4 %).
  // 3 checks, 0.1 % together; three relative standard deviations (3 / √(2(B − 1))) were 0.5 %.
  const double z = test::family_sigmas(3, 1e-3, test::kNormalDof);
  const double lo = std::sqrt(test::chi2_upper_critical(B - 1, -z) / (B - 1)),
               hi = std::sqrt(test::chi2_upper_critical(B - 1, z) / (B - 1));
  test::stat_log("batch-means stderr / truth", r->total.std_error / truth, hi);
  EXPECT_GT(r->total.std_error / truth, lo);
  EXPECT_LT(r->total.std_error / truth, hi);
  EXPECT_GT(r->total.std_error / textbook, lo);
  EXPECT_LT(r->total.std_error / textbook, hi);
  EXPECT_NEAR(r->total.luminance, 0.5, z * truth);
  EXPECT_NEAR(r->total.rgb[0], sum / N, 1e-12) << "the exact sum against a naive floating-point one";
  EXPECT_EQ(r->total.samples, static_cast<std::uint64_t>(N));
}

// Many independent runs: the mean of stderr² is σ²/N (the estimator is unbiased) and the 95 %
// interval X̄ ± t·stderr covers the true mean about 95 % of the time.
TEST(BatchMeans, IsUnbiasedAndCoversOverManyRuns) {
  const int B = 32, per_batch = 20, runs = 500;
  const double N = B * per_batch, sigma2 = 1.0 / 12.0;
  Rng rng{test::stat_seed(7)};
  double ratio_sum = 0;
  int covered = 0;
  for (int run = 0; run < runs; ++run) {
    Histogram h(HistogramLayout{B, {}});
    const Histogram::PathId id = h.intern("LDDDSE");
    for (int b = 0; b < B; ++b) {
      for (int i = 0; i < per_batch; ++i) ASSERT_TRUE(h.add(id, b, Histogram::kNoStrategy, gray(rng.uniform())));
      h.add_samples(b, per_batch);
    }
    Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
    ASSERT_TRUE(r);
    ratio_sum += r->total.std_error * r->total.std_error / (sigma2 / N);
    if (std::fabs(r->total.luminance - 0.5) <= 2.040 * r->total.std_error) ++covered;  // t(31), 95 %
  }
  // stderr²·N/σ² has relative standard deviation √(2/(B−1)) per run; its mean over the runs is
  // near normal. Coverage 0.95, binomial standard error √(0.95·0.05/500) ≈ 0.0097. 2 checks, 0.1 %
  // together (the coverage's tolerance was 0.04 before: 4.1 of its standard errors).
  const double k = test::family_sigmas(2, 1e-3, test::kNormalDof);
  const double ratio_se = std::sqrt(2.0 / (B - 1) / runs), coverage_se = std::sqrt(0.95 * 0.05 / runs);
  test::stat_log("mean stderr² / truth", (ratio_sum / runs - 1.0) / ratio_se, k);
  test::stat_log("coverage", (static_cast<double>(covered) / runs - 0.95) / coverage_se, k);
  EXPECT_NEAR(ratio_sum / runs, 1.0, k * ratio_se);
  EXPECT_NEAR(static_cast<double>(covered) / runs, 0.95, k * coverage_se);
}

// --- pixel groups of replicates (issue 39) ---

TEST(ReplicateGroups, TwoReplicatesGiveThePairedDifferenceFormula) {
  // Two groups of two replicates: group 0 sums (10, 20) over (10, 10) samples, group 1 (15, 5)
  // over (5, 5). Σ_g (S_g1 − S_g2)² / N² = (100 + 100) / 30², with one degree of freedom each.
  const VarianceDesign design({10, 10, 5, 5}, 2);
  EXPECT_EQ(design.dof(), 2);
  EXPECT_EQ(design.replicates(), 2);
  std::vector<ExactRgb> sums;
  for (double v : {10.0, 20.0, 15.0, 5.0}) sums.push_back(*to_exact(gray(v)));
  const Estimate e = estimate_of(sums, design, 4);
  EXPECT_DOUBLE_EQ(e.luminance, 50.0 / 30.0);
  EXPECT_NEAR(e.std_error, std::sqrt(200.0) / 30.0, 1e-14);
  // The same batches read as four plain batch means: Σ (S_b − n_b X̄)² = 1000 / 9 over
  // N² − Σ n_b² = 650, with 3 degrees of freedom.
  const VarianceDesign plain({10, 10, 5, 5}, 1);
  EXPECT_EQ(plain.dof(), 3);
  EXPECT_NEAR(estimate_of(sums, plain, 4).std_error, std::sqrt(1000.0 / 9.0 / 650.0), 1e-14);
  // A group whose second replicate holds no samples adds none: one degree of freedom, group 0's.
  const VarianceDesign half({10, 10, 5, 0}, 2);
  EXPECT_EQ(half.dof(), 1);
  EXPECT_NEAR(half.variance({10, 20, 15, 0}), 100.0 / (25.0 * 25.0), 1e-15);
  EXPECT_TRUE(std::isnan(VarianceDesign({3, 0, 4, 0}, 2).variance({1, 0, 1, 0})));
}

// Without --replicates the groups follow the sensor's pixel count (issue 36): B / 2 groups of two
// replicates on any sensor of at least B / 2 pixels, else the largest divisor of B not above the
// pixel count, so no group stays empty and the stderr keeps B − G ≥ B / 2 degrees of freedom.
TEST(ReplicateGroups, TheDefaultGroupsFollowThePixelCount) {
  EXPECT_EQ(default_replicates(32, 256 * 256), 2);
  EXPECT_EQ(default_replicates(32, 16), 2);
  EXPECT_EQ(default_replicates(32, 15), 4);  // 8 groups
  EXPECT_EQ(default_replicates(32, 4), 8);
  EXPECT_EQ(default_replicates(32, 3), 16);  // 2 groups: 3 does not divide 32
  EXPECT_EQ(default_replicates(32, 1), 32);  // a spot meter: plain batch means, 31 dof
  EXPECT_EQ(default_replicates(64, 1000), 2);
  EXPECT_EQ(default_replicates(12, 5), 3);   // 4 groups of 3
  EXPECT_EQ(default_replicates(5, 100), 5);  // no divisor of 5 in 2..2: one group
  EXPECT_EQ(default_replicates(2, 1), 2);
  for (int b = 2; b <= 64; ++b)
    for (std::uint64_t pixels : {1u, 2u, 3u, 7u, 16u, 1000u}) {
      const int r = default_replicates(b, pixels);
      ASSERT_EQ(b % r, 0) << b << " " << pixels;
      EXPECT_GE(r, 2) << b << " " << pixels;
      EXPECT_LE(static_cast<std::uint64_t>(b / r), std::max<std::uint64_t>(pixels, 1)) << b << " " << pixels;
    }
}

TEST(ReplicateGroups, RendersFillEveryGroupAndTheHistogramReadsItsDesign) {
  HistogramLayout layout{8, {}, 4};  // four groups of two replicates
  EXPECT_EQ(layout.replicates(), 2);
  Histogram h(layout);
  for (int b = 0; b < 8; ++b) h.add_samples(b, 3);
  EXPECT_EQ(h.stderr_dof(), 4);
  Histogram plain(HistogramLayout{8, {}});
  for (int b = 0; b < 8; ++b) plain.add_samples(b, 3);
  EXPECT_EQ(plain.stderr_dof(), 7);
  Histogram other(HistogramLayout{8, {}, 2});
  EXPECT_FALSE(h.merge(other));  // another grouping is another layout
}

// Replicates that are stratified within themselves, as a pixel's Sobol points are: each of a
// group's R = 2 replicates takes n jittered points of f_g(u) = g + u (stratum i: u = (i + ξ) / n),
// so that a replicate's sum has variance 1 / (12 n), far below n independent points' n / 12, and
// the groups' means differ (plain batch means over these 32 batches would read that as noise).
// Over many runs the paired estimate's stderr² is unbiased for var(X̄) = G R / (12 n N²), and
// X̄ ± t₁₆ · stderr covers the true mean G / 2 95 % of the time.
TEST(ReplicateGroups, StratifiedReplicatesGetAnHonestStderr) {
  const int G = 16, R = 2, n = 8, runs = 400;
  const double N = G * R * n, truth = G * R / (12.0 * n) / (N * N), mean_truth = G / 2.0;
  Rng rng{test::stat_seed(11)};
  double ratio_sum = 0;
  int covered = 0;
  for (int run = 0; run < runs; ++run) {
    Histogram h(HistogramLayout{G * R, {}, G});
    const Histogram::PathId id = h.intern("LDDE");
    for (int g = 0; g < G; ++g)
      for (int r = 0; r < R; ++r) {
        for (int i = 0; i < n; ++i) ASSERT_TRUE(h.add(id, g * R + r, Histogram::kNoStrategy, gray(g + (i + rng.uniform()) / n)));
        h.add_samples(g * R + r, n);
      }
    Result<HistogramReport> rep = make_report(h, RunInfo{}, nullptr, {});
    ASSERT_TRUE(rep);
    ratio_sum += rep->total.std_error * rep->total.std_error / truth;
    if (std::fabs(rep->total.luminance - mean_truth) <= 2.120 * rep->total.std_error) ++covered;  // t(16), 95 %
  }
  // stderr² / truth is a χ²₁₆ / 16 variable per run (relative standard deviation √(2/16)); its
  // mean over the runs is nearly normal.
  const double k = test::family_sigmas(2, 1e-3, 1000);
  const double ratio_sd = std::sqrt(2.0 / G / runs);
  test::stat_log("mean stderr² / truth", ratio_sum / runs - 1.0, k * ratio_sd);
  EXPECT_NEAR(ratio_sum / runs, 1.0, k * ratio_sd);
  // The runs not covered are Binomial(400, 0.05), whose upper tail is far heavier than a normal
  // one at this level: their two-sided tail, exactly, against the same Šidák level per check.
  const int missed = runs - covered;
  double below = 0, above = 0;  // P(X ≤ missed), P(X ≥ missed)
  for (int i = 0; i <= runs; ++i) {
    const double pmf = std::exp(std::lgamma(runs + 1.0) - std::lgamma(i + 1.0) - std::lgamma(runs - i + 1.0) +
                                i * std::log(0.05) + (runs - i) * std::log(0.95));
    if (i <= missed) below += pmf;
    if (i >= missed) above += pmf;
  }
  const double tail = std::min(1.0, 2 * std::min(below, above)), each = 1 - std::sqrt(1 - 1e-3);
  test::stat_log("coverage: two-sided binomial tail", tail, each);
  EXPECT_GT(tail, each) << covered << " of " << runs << " covered";
}

// --- merging ---

struct Sample {
  std::string path;
  int batch;
  int strategy;
  Rgb value;
};

// A stream of contributions over a wide dynamic range (1e-9 … 1e9), so that floating-point
// summation would depend on the order.
std::vector<Sample> sample_stream(int n, int batches) {
  const std::vector<std::string> paths = {"LDDDSE", "LSDDSE", "LDDSDDSE", "LSDSDDSE", "LDDDDDSE", "LDSDDE", "LSSDDE"};
  Rng rng{2024};
  std::vector<Sample> out;
  for (int i = 0; i < n; ++i) {
    Sample s;
    s.path = paths[rng.next() % paths.size()];
    s.batch = static_cast<int>(static_cast<std::int64_t>(i) * batches / n);
    s.strategy = Technique{static_cast<int>(rng.next() % 3), static_cast<int>(rng.next() % 4), static_cast<int>(rng.next() % 3),
                           rng.next() % 2 == 0}
                     .code();
    for (double& c : s.value) c = std::exp((rng.uniform() - 0.5) * 41);
    if (i % 97 == 0) s.value[1] = -s.value[1];  // negative components are summed exactly too
    out.push_back(s);
  }
  return out;
}

HistogramLayout stream_layout() { return HistogramLayout{8, {"emitter-hit", "nee", "light-tracing"}}; }

Histogram accumulate(const std::vector<Sample>& stream, std::size_t begin, std::size_t end) {
  Histogram h(stream_layout());
  for (std::size_t i = begin; i < end; ++i) {
    const Sample& s = stream[i];
    EXPECT_TRUE(h.add(h.intern(s.path), s.batch, s.strategy, s.value));
    h.add_samples(s.batch, 1);
  }
  return h;
}

void expect_same_state(const Histogram& a, const Histogram& b) {
  ASSERT_EQ(a.num_paths(), b.num_paths());
  EXPECT_EQ(a.nonfinite(), b.nonfinite());
  EXPECT_TRUE(a.magnitude() == b.magnitude());
  for (int bt = 0; bt < a.num_batches(); ++bt) EXPECT_EQ(a.batch_samples(bt), b.batch_samples(bt));
  for (Histogram::PathId p = 0; p < a.num_paths(); ++p) {
    std::optional<Histogram::PathId> q = b.find(a.path(p));
    ASSERT_TRUE(q) << a.path(p);
    for (int bt = 0; bt < a.num_batches(); ++bt) {
      EXPECT_TRUE(a.cell(p, bt).sum == b.cell(*q, bt).sum) << a.path(p) << " batch " << bt;
      EXPECT_EQ(a.cell(p, bt).contributions, b.cell(*q, bt).contributions);
    }
    const std::vector<int> ra = a.sorted_rows(p), rb = b.sorted_rows(*q);
    ASSERT_EQ(ra.size(), rb.size()) << a.path(p);
    for (std::size_t i = 0; i < ra.size(); ++i) {
      EXPECT_EQ(a.row(ra[i]).technique, b.row(rb[i]).technique);
      EXPECT_EQ(a.row(ra[i]).contributions, b.row(rb[i]).contributions);
      for (int bt = 0; bt < a.num_batches(); ++bt) EXPECT_TRUE(a.row_sum(ra[i], bt) == b.row_sum(rb[i], bt));
    }
  }
}

std::string report_text(const Histogram& h) {
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  EXPECT_TRUE(r);
  return r ? histogram_json_text(*r) : "";
}

TEST(HistogramMerge, IsExactWhateverTheShardSplitAndOrder) {
  const std::vector<Sample> stream = sample_stream(20000, 8);
  const Histogram whole = accumulate(stream, 0, stream.size());
  const std::string whole_text = report_text(whole);
  Rng rng{99};
  for (int shards : {2, 3, 7, 16}) {
    // Random cut points: shards need not align with batches.
    std::vector<std::size_t> cuts = {0, stream.size()};
    for (int i = 1; i < shards; ++i) cuts.push_back(rng.next() % stream.size());
    std::sort(cuts.begin(), cuts.end());
    std::vector<Histogram> parts;
    for (std::size_t i = 0; i + 1 < cuts.size(); ++i) parts.push_back(accumulate(stream, cuts[i], cuts[i + 1]));
    for (bool reversed : {false, true}) {
      Histogram merged(stream_layout());
      for (std::size_t i = 0; i < parts.size(); ++i) {
        const Histogram& part = parts[reversed ? parts.size() - 1 - i : i];
        ASSERT_TRUE(merged.merge(part));
      }
      SCOPED_TRACE(std::to_string(shards) + (reversed ? " shards, reversed" : " shards"));
      expect_same_state(whole, merged);
      EXPECT_EQ(report_text(merged), whole_text) << "the report is a function of the exact sums";
    }
  }
}

TEST(HistogramMerge, ThreadsWithOneShardEachGiveBitIdenticalResults) {
  const std::vector<Sample> stream = sample_stream(12000, 8);
  std::string reference;
  for (int threads : {1, 2, 4}) {
    std::vector<Histogram> shards(static_cast<std::size_t>(threads), Histogram(stream_layout()));
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t) {
      workers.emplace_back([&, t] {
        Histogram& h = shards[static_cast<std::size_t>(t)];
        for (std::size_t i = static_cast<std::size_t>(t); i < stream.size(); i += static_cast<std::size_t>(threads)) {
          h.add(h.intern(stream[i].path), stream[i].batch, stream[i].strategy, stream[i].value);
          h.add_samples(stream[i].batch, 1);
        }
      });
    }
    for (std::thread& w : workers) w.join();
    Histogram merged(stream_layout());
    for (const Histogram& s : shards) ASSERT_TRUE(merged.merge(s));
    const std::string text = report_text(merged);
    if (reference.empty()) reference = text;
    EXPECT_EQ(text, reference) << threads << " threads";
  }
}

TEST(HistogramMerge, EstimateAgreesWithAPlainSum) {
  const std::vector<Sample> stream = sample_stream(5000, 8);
  const Histogram h = accumulate(stream, 0, stream.size());
  long double sum = 0;
  for (const Sample& s : stream) sum += s.value[0];
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  ASSERT_TRUE(r);
  EXPECT_NEAR(r->total.rgb[0], static_cast<double>(sum / stream.size()), 1e-12 * std::fabs(r->total.rgb[0]));
}

TEST(HistogramMerge, RefusesADifferentLayout) {
  Histogram a(HistogramLayout{8, {"nee"}}), b(HistogramLayout{16, {"nee"}}), c(HistogramLayout{8, {"bdpt"}});
  Result<bool> r = a.merge(b);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kUsage);
  EXPECT_EQ(r.error().message,
            "cannot merge histograms with different layouts (batch count, groups or strategy list differ)");
  EXPECT_FALSE(a.merge(c));
}

// A batch nothing was added to takes no memory and reads as zeros, also after a merge; the sums
// of the batches in use are those of the contributions.
TEST(Histogram, BatchesAreLaidOutOnlyWhenWritten) {
  Histogram a(HistogramLayout{8, {"nee"}}), b(HistogramLayout{8, {"nee"}});
  const Histogram::PathId p = a.intern("LDE"), q = a.intern("LDDE");
  EXPECT_TRUE(a.add(q, 5, 0, gray(0.5)));
  EXPECT_TRUE(b.add(b.intern("LDE"), 2, 0, gray(0.25)));
  for (int batch = 0; batch < 8; ++batch) EXPECT_EQ(a.batch_in_use(batch), batch == 5) << batch;
  EXPECT_EQ(a.cell(p, 5).contributions, 0u);  // a path interned before its batch was laid out
  EXPECT_EQ(a.cell(p, 3).contributions, 0u);
  EXPECT_TRUE(is_zero(a.cell(p, 3).sum));
  EXPECT_EQ(a.row_sum(0, 3), ExactSum{0});
  ASSERT_TRUE(a.merge(b));
  for (int batch = 0; batch < 8; ++batch) EXPECT_EQ(a.batch_in_use(batch), batch == 5 || batch == 2) << batch;
  EXPECT_EQ(a.cell(p, 2).contributions, 1u);
  EXPECT_EQ(a.cell(p, 2).sum, *to_exact(gray(0.25)));
  EXPECT_EQ(a.cell(q, 5).sum, *to_exact(gray(0.5)));
  EXPECT_EQ(a.cell(q, 2).contributions, 0u);
}

// The cells' store: a key holds up to kSparse (batch, value) pairs, then a block of all B values;
// every value must survive the move, and a (key, batch) never stored must read as absent.
TEST(BatchStore, KeepsEveryValueThroughTheMoveFromPairsToABlock) {
  constexpr int kBatches = 12;
  BatchStore<std::uint64_t> store(kBatches);
  std::map<std::pair<std::size_t, int>, std::uint64_t> expected;
  Rng rng{12345};
  for (int i = 0; i < 4000; ++i) {
    // Key k is met in about k + 1 batches: key 0 stays a single pair, the higher ones become blocks.
    const std::size_t key = rng.next() % 9;
    const int batch = static_cast<int>(rng.next() % static_cast<std::uint64_t>(std::min<std::size_t>(key + 1, kBatches)) * 7 % kBatches);
    const std::uint64_t v = rng.next() % 1000;
    store.at(key, batch) += v;
    expected[{key, batch}] += v;
  }
  EXPECT_EQ(store.keys(), 9u);
  int present = 0;
  for (std::size_t key = 0; key < 10; ++key)
    for (int batch = 0; batch < kBatches; ++batch) {
      const std::uint64_t* v = store.find(key, batch);
      const auto it = expected.find({key, batch});
      if (it == expected.end()) {
        // Absent, or a zero in a key's block.
        EXPECT_TRUE(v == nullptr || *v == 0) << key << " " << batch;
      } else {
        ASSERT_NE(v, nullptr) << key << " " << batch;
        EXPECT_EQ(*v, it->second) << key << " " << batch;
        ++present;
      }
    }
  EXPECT_EQ(present, static_cast<int>(expected.size()));
  // for_each: every kept value once, in ascending batch order (a block's zeros too).
  for (std::size_t key = 0; key < 9; ++key) {
    int last = -1, nonzero = 0;
    store.for_each(key, [&](int batch, std::uint64_t v) {
      EXPECT_GT(batch, last) << key;
      last = batch;
      const auto it = expected.find({key, batch});
      EXPECT_EQ(v, it == expected.end() ? 0u : it->second) << key << " " << batch;
      nonzero += it != expected.end() ? 1 : 0;
    });
    EXPECT_EQ(nonzero, static_cast<int>(std::count_if(expected.begin(), expected.end(), [&](const auto& e) { return e.first.first == key; })))
        << key;
  }
  EXPECT_EQ(store.find(0, 1), nullptr);  // key 0 met in batch 0 only: a single pair
  EXPECT_NE(store.find(8, 11), nullptr);  // key 8 met in more than kSparse batches: a block
}

TEST(Histogram, APathMetInEveryBatchKeepsEachBatchSum) {
  // Past the store's kSparse pairs a path's cells move to a block; the sums must not change.
  Histogram h(HistogramLayout{32, {"nee"}});
  const Histogram::PathId p = h.intern("LDE");
  for (int round = 0; round < 3; ++round)
    for (int batch = 31; batch >= 0; --batch) EXPECT_TRUE(h.add(p, batch, 0, gray(0.125 * (batch + 1))));
  for (int batch = 0; batch < 32; ++batch) {
    EXPECT_EQ(h.cell(p, batch).contributions, 3u) << batch;
    EXPECT_EQ(h.cell(p, batch).sum, *to_exact(gray(0.375 * (batch + 1)))) << batch;
    EXPECT_EQ(h.row_sum(0, batch), 3 * luminance_exact(*to_exact(gray(0.125 * (batch + 1))))) << batch;
    EXPECT_TRUE(h.batch_in_use(batch));
  }
}

// --- non-finite contributions ---

TEST(Histogram, NonFiniteContributionsAreCountedAndNeverAdded) {
  Histogram clean(HistogramLayout{2, {"nee"}}), dirty(HistogramLayout{2, {"nee"}});
  for (Histogram* h : {&clean, &dirty}) {
    const Histogram::PathId id = h->intern("LDDDSE");
    EXPECT_TRUE(h->add(id, 0, 0, gray(2.0)));
    EXPECT_TRUE(h->add(id, 1, 0, {1.0, 0.5, 0.25}));
    h->add_samples(0, 2);
    h->add_samples(1, 2);
  }
  const Histogram::PathId id = dirty.intern("LDDDSE");
  EXPECT_FALSE(dirty.add(id, 0, 0, {std::nan(""), 1.0, 1.0}));
  EXPECT_FALSE(dirty.add(id, 1, 0, {1.0, INFINITY, 1.0}));
  EXPECT_FALSE(dirty.add(id, 1, 0, {1.0, 1.0, -INFINITY}));
  EXPECT_FALSE(dirty.add(dirty.intern("LSDDSE"), 0, 0, gray(1e300)));
  dirty.add_nonfinite(2);  // rejected by the caller itself
  EXPECT_EQ(dirty.nonfinite(), 6u);
  EXPECT_EQ(clean.nonfinite(), 0u);
  Result<HistogramReport> rc = make_report(clean, RunInfo{}, nullptr, {});
  Result<HistogramReport> rd = make_report(dirty, RunInfo{}, nullptr, {});
  ASSERT_TRUE(rc && rd);
  ASSERT_TRUE(rd.ok());
  EXPECT_EQ(rd->nonfinite_samples, 6u);
  ASSERT_TRUE(rc.ok());
  EXPECT_EQ(rd->total.rgb, rc->total.rgb);
  EXPECT_EQ(rd->total.samples, 2u);
  EXPECT_DOUBLE_EQ(rd->total.rgb[0], 3.0 / 4);
  // The path that only ever received a rejected contribution is known but carries nothing.
  ASSERT_EQ(rd->paths.size(), 2u);
  EXPECT_EQ(rd->paths[1].path, "LSDDSE");
  EXPECT_EQ(rd->paths[1].estimate.samples, 0u);
  EXPECT_EQ(rd->paths[1].estimate.luminance, 0.0);
}

TEST(Histogram, ZeroContributionsAreNotCounted) {
  Histogram h(HistogramLayout{1, {}});
  const Histogram::PathId id = h.intern("LDDDSE");
  EXPECT_TRUE(h.add(id, 0, Histogram::kNoStrategy, gray(0.0)));
  EXPECT_TRUE(h.add(id, 0, Histogram::kNoStrategy, gray(1e-25)));  // rounds to zero on the grid
  EXPECT_EQ(h.cell(id, 0).contributions, 0u);
}

// --- classes, shares and strategies ---

struct Classes {
  ClassTable table;
  std::vector<const PathClass*> list;
  std::vector<ClassInfo> info;
  std::optional<Classifier> classifier;
  Classes(std::initializer_list<std::pair<const char*, const char*>> defs) {
    for (const auto& [name, expr] : defs) {
      Result<const PathClass*> c = table.add(name, expr, ClassOptions{});
      EXPECT_TRUE(c) << c.error().render();
      list.push_back(*c);
      info.push_back({name, expr});
    }
    Result<Classifier> cl = Classifier::build(list, Limits{});
    EXPECT_TRUE(cl);
    classifier = std::move(cl).value();
  }
};

TEST(HistogramReport, SharesOfAPartitionSumToOne) {
  // Point-like lights (c0 = S) and area-like lights (c0 = D) partition every valid path;
  // "everything" overlaps both.
  Classes classes({{"point", "LS.*E"}, {"area", "LD.*E"}, {"everything", "L.*E"}});
  const std::vector<Sample> stream = sample_stream(4000, 8);
  const Histogram h = accumulate(stream, 0, stream.size());
  Result<HistogramReport> r = make_report(h, RunInfo{}, &*classes.classifier, classes.info);
  ASSERT_TRUE(r) << r.error().render();
  ASSERT_EQ(r->classes.size(), 3u);
  EXPECT_EQ(r->classes[0].name, "point");
  EXPECT_EQ(r->classes[0].expr, "LS.*E");
  EXPECT_NEAR(r->classes[0].share + r->classes[1].share, 1.0, 1e-12);
  EXPECT_GT(r->classes[0].share, 0.1);
  EXPECT_GT(r->classes[1].share, 0.1);
  EXPECT_NEAR(r->classes[2].share, 1.0, 1e-15);
  EXPECT_EQ(r->classes[0].estimate.samples + r->classes[1].estimate.samples, r->total.samples);
  // A class's estimate is the sum of its paths' estimates.
  double point = 0;
  for (const PathEstimate& p : r->paths)
    if (p.path[1] == 'S') point += p.estimate.rgb[2];
  EXPECT_NEAR(r->classes[0].estimate.rgb[2], point, 1e-12 * std::fabs(point));
  // And its stderr comes from its own batch sums: the union of the partition has the total's.
  EXPECT_EQ(r->classes[2].estimate.std_error, r->total.std_error);
}

TEST(HistogramReport, TechniqueSharesVarianceAndOrdering) {
  Histogram h(HistogramLayout{2, {"nee", "emitter-hit", "light-tracing"}});
  const int nee = Technique{0, 1, 4}.code(), hit = Technique{1, 0, 5}.code(), lt = Technique{2, 4, 1}.code();
  const Histogram::PathId a = h.intern("LDDDSE"), b = h.intern("LSDDSE"), c = h.intern("LDDDDSE");
  ASSERT_TRUE(h.add(a, 0, nee, gray(3.0)));
  ASSERT_TRUE(h.add(a, 1, lt, gray(1.0)));
  ASSERT_TRUE(h.add(b, 0, hit, gray(1.0)));
  ASSERT_TRUE(h.add(b, 1, hit, gray(2.0)));
  ASSERT_TRUE(h.add(c, 1, hit, gray(1.0)));  // ties with b: ordered by path string
  ASSERT_TRUE(h.add(c, 1, hit, gray(2.0)));
  h.add_samples(0, 1);
  h.add_samples(1, 1);
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->paths.size(), 3u);
  EXPECT_EQ(r->paths[0].path, "LDDDSE");
  EXPECT_EQ(r->paths[1].path, "LDDDDSE");
  EXPECT_EQ(r->paths[2].path, "LSDDSE");
  ASSERT_EQ(r->paths[0].strategies.size(), 2u) << "only the techniques that contributed";
  const TechniqueEstimate& n0 = r->paths[0].strategies[0];
  const TechniqueEstimate& l0 = r->paths[0].strategies[1];
  EXPECT_EQ(n0.name, "nee (1, DD, 4)");
  EXPECT_EQ(l0.name, "light-tracing (4, DD, 1)");
  EXPECT_NEAR(n0.share, 0.75, 1e-15);
  EXPECT_NEAR(l0.share, 0.25, 1e-15);
  EXPECT_EQ(n0.samples, 1u);
  // Batch sums 3 and 1 (mean 2, deviations ±1, Σd² = 2); nee's are 3 and 0 (deviations ±1.5, own
  // Σd² = 4.5), light tracing's 0 and 1 (∓0.5, 0.5): own variance shares 0.9 and 0.1, both ≥ 0
  // (issue 36: the covariance shares 1.5 and -0.5 they replace), and each is perfectly
  // anticorrelated with the other: correlation -1.
  EXPECT_DOUBLE_EQ(n0.variance_share, 0.9);
  EXPECT_DOUBLE_EQ(l0.variance_share, 0.1);
  EXPECT_DOUBLE_EQ(n0.correlation, -1.0);
  EXPECT_DOUBLE_EQ(l0.correlation, -1.0);
  EXPECT_TRUE(std::isnan(r->paths[2].strategies[0].correlation)) << "one technique: nothing to correlate with";
  // One technique carries all of a path: share and variance share exactly 1.
  ASSERT_EQ(r->paths[2].strategies.size(), 1u);
  EXPECT_EQ(r->paths[2].strategies[0].name, "emitter-hit (0, DD, 5)");
  EXPECT_EQ(r->paths[2].strategies[0].share, 1.0);
  EXPECT_EQ(r->paths[2].strategies[0].variance_share, 1.0);
  EXPECT_EQ(r->paths[2].strategies[0].samples, 2u);
  // A path in one batch only has batch sums 3 and 0 — still a variance, all of it this technique's.
  EXPECT_EQ(r->paths[1].strategies[0].variance_share, 1.0);
  EXPECT_DOUBLE_EQ(r->paths[0].estimate.luminance, 2.0);
  EXPECT_DOUBLE_EQ(r->total.luminance, 5.0);
}

// The table's words for the shares (cli/estimate_text.h): both shares as percentages, and a
// correlation said in words only where it matters (|r| ≥ 0.3).
TEST(HistogramReport, TechniquesTextSaysWhereErrorsCancel) {
  TechniqueEstimate a{"nee (1, DD, 2)", 0.942, 10, 0.9, -0.57}, b{"emitter-hit (0, DD, 3)", 0.058, 3, 0.1, -0.57};
  EXPECT_EQ(techniques_text({a, b}, 3),
            "nee (1, DD, 2) 94.2 % (90.0 % of the variance; its errors partly cancel the others', r = -0.57), "
            "emitter-hit (0, DD, 3) 5.8 % (10.0 %; its errors partly cancel the others', r = -0.57)");
  a.correlation = b.correlation = 0.1;
  EXPECT_EQ(techniques_text({a, b}, 1), "nee (1, DD, 2) 94.2 % (90.0 % of the variance), and 1 more");
  a.correlation = 0.45;
  EXPECT_EQ(techniques_text({a}, 1), "nee (1, DD, 2) 94.2 % (90.0 % of the variance; its errors add to the others', r = 0.45)");
}

TEST(HistogramReport, ClassTechniquesSumTheirPaths) {
  // Two paths in one class, each with two techniques; the class's rows sum the paths' by technique.
  Classes classes({{"every", "LD.*E"}});
  Histogram h(HistogramLayout{4, {"bdpt"}}, &*classes.classifier);
  const int s0 = Technique{0, 0, 4}.code(), s1 = Technique{0, 1, 3}.code();
  const Histogram::PathId a = h.intern("LDDDSE"), b = h.intern("LDDSDDSE");
  Rng rng{7};
  for (int bt = 0; bt < 4; ++bt) {
    ASSERT_TRUE(h.add(a, bt, s0, gray(rng.uniform())));
    ASSERT_TRUE(h.add(a, bt, s1, gray(rng.uniform())));
    ASSERT_TRUE(h.add(b, bt, s1, gray(rng.uniform())));
    h.add_samples(bt, 1);
  }
  Result<HistogramReport> r = make_report(h, RunInfo{}, &*classes.classifier, classes.info);
  ASSERT_TRUE(r);
  const std::vector<TechniqueEstimate>& ts = r->classes[0].strategies;
  ASSERT_EQ(ts.size(), 2u);
  EXPECT_EQ(ts[0].name, "bdpt (0, DD, 4)");
  EXPECT_EQ(ts[0].samples, 4u);
  EXPECT_EQ(ts[1].samples, 8u);
  EXPECT_NEAR(ts[0].share + ts[1].share, 1.0, 1e-14);
  EXPECT_NEAR(ts[0].variance_share + ts[1].variance_share, 1.0, 1e-12);
}

TEST(HistogramReport, RejectsContributionsWithoutSamples) {
  Histogram h(HistogramLayout{4, {}});
  ASSERT_TRUE(h.add(h.intern("LDDDSE"), 3, Histogram::kNoStrategy, gray(1)));
  h.add_samples(0, 10);
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kUsage);
  EXPECT_EQ(r.error().message, "batch 3 holds contributions but no samples were registered for it");
}

TEST(HistogramReport, RefusesSumsThatMayHaveOverflowed) {
  Histogram h(HistogramLayout{1, {}});
  const Histogram::PathId id = h.intern("LDDDSE");
  h.add_samples(0, 1);
  // Each contribution adds 3·2^49 to the magnitude; 2^63 / (3·2^49) ≈ 5461.3.
  for (int i = 0; i < 5461; ++i) ASSERT_TRUE(h.add(id, 0, Histogram::kNoStrategy, gray(0x1p49)));
  EXPECT_FALSE(h.may_overflow());
  EXPECT_TRUE(make_report(h, RunInfo{}, nullptr, {}));
  ASSERT_TRUE(h.add(id, 0, Histogram::kNoStrategy, gray(0x1p49)));
  EXPECT_TRUE(h.may_overflow());
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, ErrorCode::kLimit);
}

TEST(Histogram, RecordsClassSetsWhenGivenAClassifier) {
  Classes classes({{"point", "LS.*E"}, {"area", "LD.*E"}});
  Histogram h(HistogramLayout{}, &*classes.classifier);
  const Histogram::PathId p = h.intern("LSDDSE"), a = h.intern("LDDDSE");
  EXPECT_EQ(classes.classifier->members(h.class_set(p)), std::vector<int>{0});
  EXPECT_EQ(classes.classifier->members(h.class_set(a)), std::vector<int>{1});
  EXPECT_EQ(h.intern("LSDDSE"), p);
}

// --- images ---

TEST(ClassImages, ConcurrentAddsAreExactAndIndependentOfTheThreadCount) {
  // Values just below 1 with a full fraction make the low word wrap on almost every add, which
  // exercises the carry into the high word under contention.
  const int kAdds = 20000;
  std::vector<ExactRgb> values;
  Rng rng{5};
  for (int i = 0; i < kAdds; ++i) {
    const double v = 1 - rng.uniform() * 1e-3;
    values.push_back(*to_exact({v, -v, v * 1e6}));
  }
  ExactRgb expected{};
  for (const ExactRgb& v : values) add_to(expected, v);
  for (int threads : {1, 2, 4}) {
    ClassImages images(2, 1, nullptr, {});
    std::vector<std::thread> workers;
    for (int t = 0; t < threads; ++t)
      workers.emplace_back([&, t] {
        for (int i = t; i < kAdds; i += threads) images.add(1, 0, 0, values[static_cast<std::size_t>(i)]);
      });
    for (std::thread& w : workers) w.join();
    EXPECT_TRUE(images.sum(0, 1, 0) == expected) << threads << " threads";
    EXPECT_TRUE(is_zero(images.sum(0, 0, 0)));
  }
}

TEST(ClassImages, ContributionsLandInTheTotalAndTheirClassesLayers) {
  Classes classes({{"point", "LS.*E"}, {"area", "LD.*E"}, {"long", "L.{6,}E"}});
  ClassImages images(3, 2, &*classes.classifier, {2, 0});  // layers: total, long, point
  ASSERT_EQ(images.num_layers(), 3);
  EXPECT_EQ(images.layer_name(0), "total");
  EXPECT_EQ(images.layer_name(1), "long");
  EXPECT_EQ(images.layer_name(2), "point");
  Histogram h(HistogramLayout{}, &*classes.classifier);
  const ExactRgb one = *to_exact(gray(1.0)), two = *to_exact({2.0, 0.0, 0.5});
  EXPECT_TRUE(images.add(0, 0, h.class_set(h.intern("LSDDSE")), one));     // point only
  EXPECT_TRUE(images.add(2, 1, h.class_set(h.intern("LSDSDDSE")), two));   // point and long
  EXPECT_TRUE(images.add(2, 1, h.class_set(h.intern("LDDDSE")), one));     // area: total only
  EXPECT_FALSE(images.add(3, 0, 0, one)) << "outside the image";
  EXPECT_FALSE(images.add(0, -1, 0, one));
  EXPECT_EQ(to_double(images.sum(0, 2, 1)), (Rgb{3.0, 1.0, 1.5}));
  EXPECT_EQ(to_double(images.sum(1, 2, 1)), (Rgb{2.0, 0.0, 0.5}));
  EXPECT_EQ(to_double(images.sum(2, 2, 1)), (Rgb{2.0, 0.0, 0.5}));
  EXPECT_EQ(to_double(images.sum(2, 0, 0)), (Rgb{1.0, 1.0, 1.0}));
  EXPECT_TRUE(is_zero(images.sum(1, 0, 0)));
  ImageLayer total = images.layer(0, 0.5);
  EXPECT_EQ(total.name, "total");
  EXPECT_EQ(total.image.width, 3);
  EXPECT_EQ(total.image.at(2, 1, 0), 1.5f);
  EXPECT_EQ(total.image.at(0, 0, 1), 0.5f);
  EXPECT_EQ(total.image.at(1, 0, 1), 0.0f);
}

// Two layers sum the same planes among those anything was added to exactly when every
// contribution so far lands in both (the default scene's "local" and the total): the image
// writers then make them once.
TEST(ClassImages, LayersThatSumTheSameUsedPlanesAreTheSame) {
  Classes classes({{"point", "LS.*E"}, {"any", "L.*E"}, {"long", "L.{6,}E"}});
  ClassImages images(3, 2, &*classes.classifier, {1, 0, 2});  // layers: total, any, point, long
  Histogram h(HistogramLayout{}, &*classes.classifier);
  EXPECT_TRUE(images.same_sums(0, 1) && images.same_sums(0, 2) && images.same_sums(0, 3)) << "nothing added: all empty";
  EXPECT_TRUE(images.add(0, 0, h.class_set(h.intern("LSDDSE")), *to_exact(gray(1.0))));  // any, point
  EXPECT_TRUE(images.same_sums(0, 1));
  EXPECT_TRUE(images.same_sums(1, 2)) << "so far every path is a point-light path";
  EXPECT_FALSE(images.same_sums(0, 3));
  EXPECT_TRUE(images.add(2, 1, h.class_set(h.intern("LDDDSE")), *to_exact(gray(2.0))));  // any only
  EXPECT_TRUE(images.same_sums(0, 1));
  EXPECT_FALSE(images.same_sums(0, 2));
  EXPECT_FALSE(images.same_sums(1, 2));
  EXPECT_EQ(images.layer(0, 1.0).image.rgb, images.layer(1, 1.0).image.rgb);
}

TEST(ClassImages, PixelSumFlushEqualsDirectAddsAndTheTotalMatchesTheHistogram) {
  Classes classes({{"point", "LS.*E"}, {"area", "LD.*E"}});
  ClassImages direct(4, 4, &*classes.classifier, {0, 1}), buffered(4, 4, &*classes.classifier, {0, 1});
  Histogram h(HistogramLayout{4, {}}, &*classes.classifier);
  ClassImages::PixelSum pixel(buffered);
  const std::vector<Sample> stream = sample_stream(3000, 4);
  for (std::size_t i = 0; i < stream.size(); ++i) {
    const Sample& s = stream[i];
    const int x = static_cast<int>(i / 16 % 4), y = static_cast<int>(i / 64 % 4);  // 16 contributions per pixel visit
    const ExactRgb c = *to_exact(s.value);
    const Histogram::PathId id = h.intern(s.path);
    h.add_exact(id, s.batch, Histogram::kNoStrategy, c);
    h.add_samples(s.batch, 1);
    direct.add(x, y, h.class_set(id), c);
    pixel.add(h.class_set(id), c);
    if (i % 16 == 15 || i + 1 == stream.size()) {
      EXPECT_TRUE(pixel.flush(buffered, x, y));
    }
  }
  ExactRgb image_total{};
  for (int l = 0; l < 3; ++l)
    for (int y = 0; y < 4; ++y)
      for (int x = 0; x < 4; ++x) {
        EXPECT_TRUE(direct.sum(l, x, y) == buffered.sum(l, x, y));
        if (l == 0) add_to(image_total, direct.sum(0, x, y));
      }
  ExactRgb histogram_total{};
  for (Histogram::PathId p = 0; p < h.num_paths(); ++p)
    for (int b = 0; b < h.num_batches(); ++b) add_to(histogram_total, h.cell(p, b).sum);
  EXPECT_TRUE(image_total == histogram_total) << "the same contributions, rounded once, summed exactly";
  ASSERT_TRUE(direct.merge(buffered));
  EXPECT_TRUE(direct.sum(1, 1, 1) == [&] {
    ExactRgb twice = buffered.sum(1, 1, 1);
    add_to(twice, buffered.sum(1, 1, 1));
    return twice;
  }());
  ClassImages other(4, 3, nullptr, {});
  EXPECT_FALSE(direct.merge(other));
}

TEST(ClassImages, SplatBufferEqualsDirectAddsThroughEvictionsAndIgnoresPixelsOutside) {
  Classes classes({{"point", "LS.*E"}, {"area", "LD.*E"}});
  ClassImages direct(5, 3, &*classes.classifier, {0, 1}), buffered(5, 3, &*classes.classifier, {0, 1});
  Histogram h(HistogramLayout{4, {}}, &*classes.classifier);
  ClassImages::SplatBuffer splats(4);  // 4 entries for 15 pixels in 3 planes: most adds evict
  const std::vector<Sample> stream = sample_stream(3000, 4);
  for (std::size_t i = 0; i < stream.size(); ++i) {
    const Sample& s = stream[i];
    // Scattered pixels, revisited now and then (i / 3), as light tracing's splats are.
    const int x = static_cast<int>((i / 3 * 7) % 5), y = static_cast<int>((i / 3 * 11) % 3);
    const ExactRgb c = *to_exact(s.value);
    const std::uint32_t set = h.class_set(h.intern(s.path));
    EXPECT_TRUE(direct.add(x, y, set, c));
    EXPECT_TRUE(splats.add(buffered, x, y, set, c));
  }
  EXPECT_FALSE(splats.add(buffered, 5, 0, 0, *to_exact(Rgb{1.0, 1.0, 1.0})));
  EXPECT_FALSE(splats.add(buffered, 0, -1, 0, *to_exact(Rgb{1.0, 1.0, 1.0})));
  splats.flush(buffered);
  for (int l = 0; l < 3; ++l)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) EXPECT_TRUE(direct.sum(l, x, y) == buffered.sum(l, x, y)) << l << " " << x << " " << y;
  EXPECT_FALSE(is_zero(buffered.sum(1, 0, 0)) && is_zero(buffered.sum(2, 0, 0))) << "both planes were reached";
  splats.flush(buffered);  // empty now: nothing is added twice
  EXPECT_TRUE(direct.sum(0, 2, 1) == buffered.sum(0, 2, 1));
  // Sized to hold every (plane, pixel): one plane of 64 × 64 pixels; capped for large images.
  EXPECT_EQ(ClassImages(64, 64, nullptr, {}).splat_entries(), 4096u);
  EXPECT_EQ(ClassImages(1000, 1000, nullptr, {}).splat_entries(), ClassImages::SplatBuffer::kMaxEntries);
  EXPECT_GT(splats.evictions(), 1000u) << "4 entries for 45 keys";
  // A buffer that holds every key (15 pixels x 3 planes) never evicts, and still sums exactly.
  ClassImages roomy(5, 3, &*classes.classifier, {0, 1});
  ASSERT_EQ(roomy.splat_keys(), 45u);
  ClassImages::SplatBuffer all(roomy.splat_entries(), roomy.splat_keys());
  for (std::size_t i = 0; i < stream.size(); ++i) {
    const int x = static_cast<int>((i / 3 * 7) % 5), y = static_cast<int>((i / 3 * 11) % 3);
    all.add(roomy, x, y, h.class_set(h.intern(stream[i].path)), *to_exact(stream[i].value));
  }
  EXPECT_EQ(all.evictions(), 0u);
  all.flush(roomy);
  for (int l = 0; l < 3; ++l)
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 5; ++x) EXPECT_TRUE(direct.sum(l, x, y) == roomy.sum(l, x, y)) << l << " " << x << " " << y;
}

}  // namespace
}  // namespace pathex
