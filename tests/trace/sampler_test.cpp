// The `sobol` sampler (trace/sobol.h through trace/rng.h's Sampler): the generator matches the
// Sobol sequence's definition, its scrambles are nested permutations, every 2-D projection a
// pixel draws is stratified over its passes (one point in each elementary interval), its numbers
// are pure functions of (seed, pixel, pass, dimension) and the batch count, each batch of passes is
// a sequence scrambled on its own, and each number on its own is uniform and independent of the
// other dimension pairs.
//
// Statistical tolerances as in rng_test.cpp: chi-square against the critical value at z = 5
// (Wilson–Hilferty), fixed seeds.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <set>
#include <vector>

#include "trace/rng.h"
#include "trace/sobol.h"

namespace pathex {
namespace {

double chi2_critical(double k, double z) {
  const double h = 2.0 / (9.0 * k);
  return k * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

TEST(Sobol, FirstDimensionIsTheVanDerCorputSequence) {
  const std::uint32_t expected[] = {0x00000000u, 0x80000000u, 0x40000000u, 0xc0000000u, 0x20000000u, 0xa0000000u};
  for (std::uint32_t i = 0; i < 6; ++i) EXPECT_EQ(sobol::dimension0(i), expected[i]) << i;
}

TEST(Sobol, SecondDimensionIsSobolsWithPolynomialXPlusOne) {
  // Direction numbers 1/2, 3/4, 5/8 (m = 1, 3, 5, Joe and Kuo's second dimension); points in the
  // index's binary order, as pbrt-v4 generates them (the Gray-code order of Antonov and Saleev
  // visits the same blocks of points, in another order).
  const double expected[] = {0.0, 0.5, 0.75, 0.25, 0.625, 0.125, 0.375, 0.875};
  for (std::uint32_t i = 0; i < 8; ++i) EXPECT_EQ(sobol::dimension1(i) * 0x1p-32, expected[i]) << i;
  // Linear over GF(2): the point of i xor j is the xor of the points.
  for (std::uint32_t i : {3u, 255u, 256u, 70000u, 0x12345678u})
    for (std::uint32_t j : {1u, 1024u, 0x00ff00ffu, 0x80000000u})
      EXPECT_EQ(sobol::dimension1(i ^ j), sobol::dimension1(i) ^ sobol::dimension1(j));
}

// point1 and point2 are the definition's composition, computed with fewer bit reversals.
TEST(Sobol, PointsAreTheScrambledSequence) {
  for (std::uint32_t index : {0u, 1u, 7u, 1000u, 0x12345678u, 0xffffffffu})
    for (const sobol::Seeds& s : {sobol::Seeds{0u, 0u, 0u}, sobol::Seeds{1u, 2u, 3u}, sobol::Seeds{0xdeadbeefu, 0x9e3779b9u, 77u}}) {
      const std::uint32_t i = sobol::nested_scramble(index, s.shuffle);
      const std::uint32_t x = sobol::nested_scramble(sobol::dimension0(i), s.x);
      const std::uint32_t y = sobol::nested_scramble(sobol::dimension1(i), s.y);
      const std::uint32_t r = sobol::reverse_bits(index);
      EXPECT_EQ(sobol::point1(r, s), x);
      EXPECT_EQ(sobol::point2(r, s)[0], x);
      EXPECT_EQ(sobol::point2(r, s)[1], y);
    }
}

// A nested scramble maps each aligned block of 2^k values onto an aligned block of 2^k values, as
// a bijection: this is what keeps both the index shuffle and the Owen scramble net-preserving.
TEST(Sobol, NestedScrambleMapsAlignedBlocksOntoAlignedBlocks) {
  for (std::uint32_t seed : {0u, 1u, 0xdeadbeefu, 0x9e3779b9u}) {
    for (int k : {1, 4, 10}) {
      const std::uint32_t n = 1u << k;
      for (std::uint32_t block : {0u, 1u, 77u}) {
        std::set<std::uint32_t> out;
        std::uint32_t high = 0;
        for (std::uint32_t i = 0; i < n; ++i) {
          const std::uint32_t v = sobol::nested_scramble(block * n + i, seed);
          if (i == 0) high = v >> k;
          EXPECT_EQ(v >> k, high) << "seed " << seed << " k " << k;
          out.insert(v);
        }
        EXPECT_EQ(out.size(), n);
      }
    }
  }
}

// The 2-D projection (d, d + 1) of a pixel's first 2^m passes has one point in every elementary
// interval [a 2^-i, (a + 1) 2^-i) × [b 2^-(m-i), (b + 1) 2^-(m-i)), for every i = 0..m.
void expect_stratified(std::uint64_t seed, std::uint64_t pixel, std::uint64_t dim, int m) {
  const std::uint32_t n = 1u << m;
  std::vector<std::array<float, 2>> pts;
  for (std::uint32_t pass = 0; pass < n; ++pass) {
    Sampler s(seed, pixel, pass, SamplerKind::kSobol);
    s.set_dimension(dim);
    const glm::vec2 u = s.get2d();
    pts.push_back({u.x, u.y});
  }
  for (int i = 0; i <= m; ++i) {
    const std::uint32_t nx = 1u << i, ny = 1u << (m - i);
    std::vector<int> count(static_cast<std::size_t>(n), 0);
    for (const auto& p : pts) {
      const auto a = static_cast<std::uint32_t>(p[0] * static_cast<float>(nx));
      const auto b = static_cast<std::uint32_t>(p[1] * static_cast<float>(ny));
      ++count[a * ny + b];
    }
    for (std::uint32_t c = 0; c < n; ++c)
      ASSERT_EQ(count[c], 1) << "seed " << seed << " pixel " << pixel << " dimension " << dim << ": 2^" << m
                             << " passes, intervals " << nx << " x " << ny << ", interval " << c;
  }
}

TEST(SobolSampler, EveryPairOfDimensionsIsStratifiedOverThePassesOfAPixel) {
  // The dimension blocks render.cpp uses (eye 0, light 1024, joins 2048 on) are all alike.
  for (std::uint64_t dim : {0u, 1u, 5u, 1024u, 1029u, 2048u, 2600u})
    for (int m = 0; m <= 10; ++m) expect_stratified(/*seed=*/1, /*pixel=*/37, dim, m);
  for (std::uint64_t seed : {2u, 99u})
    for (std::uint64_t pixel : {0u, 65535u}) expect_stratified(seed, pixel, 4, 12);
}

TEST(SobolSampler, EachSingleDimensionIsStratifiedOverThePassesOfAPixel) {
  for (std::uint64_t dim : {0u, 7u, 2049u})
    for (int m : {2, 6, 10}) {
      const std::uint32_t n = 1u << m;
      std::vector<int> count(n, 0);
      for (std::uint32_t pass = 0; pass < n; ++pass)
        ++count[static_cast<std::size_t>(Sampler(3, 12, pass, SamplerKind::kSobol).at(dim) * static_cast<float>(n))];
      for (std::uint32_t c = 0; c < n; ++c) ASSERT_EQ(count[c], 1) << "dimension " << dim << ", 2^" << m << " passes";
    }
}

// Issue 36: under `sobol` every batch of passes (pass mod B) is a sequence scrambled on its own
// whose index is pass div B, so that the batch means the standard error is computed from are
// independent. The number is the definition's: point index pass div B, scrambling seeds from the
// stream of (seed, pixel, batch); with one batch, the key of the pixel's one sequence (pass >> 32).
TEST(SobolSampler, EachBatchIsASequenceScrambledOnItsOwn) {
  const auto expected = [](std::uint64_t seed, std::uint64_t pixel, std::uint64_t pass, std::uint64_t batches,
                           std::uint64_t dim) {
    const std::uint64_t key = stream_key(seed, pixel, ((pass % batches) << 32) | ((pass / batches) >> 32));
    const std::uint64_t h = stream_bits(key, dim);
    const sobol::Seeds s{static_cast<std::uint32_t>(h), static_cast<std::uint32_t>(h >> 32), 0u};
    return sobol::to_unit_float(sobol::point1(sobol::reverse_bits(static_cast<std::uint32_t>(pass / batches)), s));
  };
  for (std::uint64_t batches : {1u, 3u, 8u, 32u})
    for (std::uint64_t pass : {0u, 1u, 2u, 31u, 32u, 33u, 1000u})
      for (std::uint64_t dim : {0u, 7u, 2049u})
        EXPECT_EQ(Sampler(5, 77, pass, SamplerKind::kSobol, batches).at(dim), expected(5, 77, pass, batches, dim))
            << "batches " << batches << " pass " << pass << " dimension " << dim;
  // One batch: the pixel's one sequence, as before batches had their own (pass >> 32 keys it).
  EXPECT_EQ(Sampler(5, 77, 9, SamplerKind::kSobol, 1).at(3), Sampler(5, 77, 9, SamplerKind::kSobol).at(3));
  // The first points of two batches are different points (independent scrambles), while the
  // independent sampler does not depend on the batch count at all.
  EXPECT_NE(Sampler(5, 77, 0, SamplerKind::kSobol, 32).at(0), Sampler(5, 77, 1, SamplerKind::kSobol, 32).at(0));
  EXPECT_EQ(Sampler(5, 77, 40, SamplerKind::kIndependent, 32).at(3), Sampler(5, 77, 40, SamplerKind::kIndependent).at(3));
}

// Each batch's passes b, b + B, b + 2B, … are stratified as one pixel's passes are with one batch:
// its first 2^m put one point in every elementary interval of every pair of dimensions.
TEST(SobolSampler, TheFirstPassesOfEveryBatchAreStratified) {
  for (std::uint64_t batches : {3u, 32u})
    for (std::uint64_t batch : {std::uint64_t{0}, batches - 1})
      for (std::uint64_t dim : {0u, 1024u, 2600u})
        for (int m : {4, 8}) {
          const std::uint32_t n = 1u << m;
          std::vector<std::array<float, 2>> pts;
          for (std::uint32_t i = 0; i < n; ++i) {
            Sampler s(3, 12, batch + batches * i, SamplerKind::kSobol, batches);
            s.set_dimension(dim);
            const glm::vec2 u = s.get2d();
            pts.push_back({u.x, u.y});
          }
          for (int k = 0; k <= m; ++k) {
            const std::uint32_t nx = 1u << k, ny = 1u << (m - k);
            std::vector<int> count(n, 0);
            for (const auto& p : pts)
              ++count[static_cast<std::uint32_t>(p[0] * static_cast<float>(nx)) * ny + static_cast<std::uint32_t>(p[1] * static_cast<float>(ny))];
            for (std::uint32_t c = 0; c < n; ++c)
              ASSERT_EQ(count[c], 1) << "batches " << batches << " batch " << batch << " dimension " << dim << " 2^" << m;
          }
        }
}

TEST(SobolSampler, IsAPureFunctionOfSeedPixelPassAndDimension) {
  Sampler a(5, 1000, 17, SamplerKind::kSobol);
  std::vector<float> first;
  for (int i = 0; i < 50; ++i) first.push_back(i % 3 == 0 ? a.get1d() : a.get2d().y);
  Sampler b(5, 1000, 17, SamplerKind::kSobol);
  for (int i = 0; i < 50; ++i) EXPECT_EQ(first[static_cast<std::size_t>(i)], i % 3 == 0 ? b.get1d() : b.get2d().y);
  // at() is get1d() without moving, and the position after set_dimension is all that matters.
  Sampler c(5, 1000, 17, SamplerKind::kSobol);
  c.set_dimension(9);
  EXPECT_EQ(c.at(9), c.get1d());
  EXPECT_EQ(c.dimension(), 10u);
  // Seeds, pixels and passes each change the numbers.
  const float u = Sampler(5, 1000, 17, SamplerKind::kSobol).at(3);
  EXPECT_NE(u, Sampler(6, 1000, 17, SamplerKind::kSobol).at(3));
  EXPECT_NE(u, Sampler(5, 1001, 17, SamplerKind::kSobol).at(3));
  EXPECT_NE(u, Sampler(5, 1000, 18, SamplerKind::kSobol).at(3));
}

TEST(SobolSampler, NumbersAreInTheHalfOpenUnitInterval) {
  for (std::uint32_t pass = 0; pass < 4096; ++pass) {
    Sampler s(8, 3, pass, SamplerKind::kSobol);
    for (int d = 0; d < 8; ++d) {
      const glm::vec2 u = s.get2d();
      ASSERT_GE(u.x, 0.0f);
      ASSERT_LT(u.x, 1.0f);
      ASSERT_GE(u.y, 0.0f);
      ASSERT_LT(u.y, 1.0f);
    }
  }
}

// Across pixels (one pass each) a dimension is uniform, and two different dimension pairs of the
// same pass are independent: the pair (dimension 0 of pair A, dimension 0 of pair B) is uniform on
// the square. This is what keeps each pass, and so every estimate, unbiased.
TEST(SobolSampler, AcrossPixelsNumbersAreUniformAndPairsIndependent) {
  constexpr std::size_t kBins = 16;
  constexpr std::uint64_t kN = 200000;
  for (std::uint64_t pass : {0u, 1u, 1000u}) {
    std::vector<std::uint64_t> one(kBins, 0), two(kBins * kBins, 0);
    for (std::uint64_t px = 0; px < kN; ++px) {
      Sampler s(11, px, pass, SamplerKind::kSobol);
      const glm::vec2 a = s.get2d();
      s.set_dimension(6);
      const glm::vec2 b = s.get2d();
      ++one[std::min(static_cast<std::size_t>(a.y * kBins), kBins - 1)];
      ++two[std::min(static_cast<std::size_t>(a.x * kBins), kBins - 1) * kBins +
            std::min(static_cast<std::size_t>(b.x * kBins), kBins - 1)];
    }
    auto chi2 = [](const std::vector<std::uint64_t>& counts, std::uint64_t n) {
      const double e = static_cast<double>(n) / static_cast<double>(counts.size());
      double x = 0.0;
      for (std::uint64_t c : counts) x += (static_cast<double>(c) - e) * (static_cast<double>(c) - e) / e;
      return x;
    };
    EXPECT_LT(chi2(one, kN), chi2_critical(kBins - 1, 5.0)) << "pass " << pass;
    EXPECT_LT(chi2(two, kN), chi2_critical(kBins * kBins - 1, 5.0)) << "pass " << pass;
  }
}

// Within one pixel, the passes of two different dimension pairs are not correlated: over 2^12
// passes the sample correlation of dimension 0 of pair A with dimension 0 of pair B is within 5
// standard errors (1 / sqrt(n)) of 0.
TEST(SobolSampler, DifferentPairsOfAPixelAreUncorrelated) {
  constexpr int kN = 4096;
  for (std::uint64_t pixel : {0u, 123u, 99999u}) {
    double sa = 0, sb = 0, sab = 0, saa = 0, sbb = 0;
    for (std::uint32_t pass = 0; pass < kN; ++pass) {
      Sampler s(1, pixel, pass, SamplerKind::kSobol);
      const float a = s.get2d().x;
      s.set_dimension(1024);
      const float b = s.get2d().x;
      sa += a, sb += b, sab += a * b, saa += a * a, sbb += b * b;
    }
    const double n = kN, cov = sab / n - sa / n * sb / n;
    const double r = cov / std::sqrt((saa / n - sa / n * sa / n) * (sbb / n - sb / n * sb / n));
    EXPECT_LT(std::abs(r), 5.0 / std::sqrt(n)) << "pixel " << pixel;
  }
}

// get1d_if / get2d_if: the number get1d / get2d would draw when read, 0 when not, and the cursor
// moved the same either way, so every later number is unchanged (for both samplers).
TEST(Sampler, ConditionalDrawsMoveTheCursorLikeDraws) {
  for (const SamplerKind kind : {SamplerKind::kIndependent, SamplerKind::kSobol}) {
    Sampler a(3, 77, 5, kind), b(3, 77, 5, kind), c(3, 77, 5, kind);
    const float a1 = a.get1d();
    const glm::vec2 a2 = a.get2d();
    EXPECT_EQ(b.get1d_if(true), a1);
    EXPECT_EQ(b.get2d_if(true), a2);
    EXPECT_EQ(c.get1d_if(false), 0.0f);
    EXPECT_EQ(c.get2d_if(false), glm::vec2(0.0f));
    EXPECT_EQ(a.dimension(), 3u);
    EXPECT_EQ(b.dimension(), 3u);
    EXPECT_EQ(c.dimension(), 3u);
    const glm::vec2 next = a.get2d();
    EXPECT_EQ(b.get2d(), next);
    EXPECT_EQ(c.get2d(), next);
    EXPECT_EQ(a.at2d(3), next);
  }
}

}  // namespace
}  // namespace pathex
