// The statistics of the BSDF tests (trace/bsdf_test.cpp, trace/bsdf_materials_test.cpp): Monte
// Carlo means with their standard errors, the chi-square test of sample() against pdf() over a
// grid of the sphere, and directional albedos by sampling and by uniform evaluation.
//
// Tolerances: kZ = 4 standard errors and chi-square statistics below the critical value at z = 5
// (false-alarm probability ~3e-7, Wilson–Hilferty) are the defaults of the coated materials'
// tests; the others pass the tolerance their number of checks gives at a family-wise
// false-failure rate (test::family_sigmas, test::family_chi2_critical over Chi2::dof).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <vector>

#include <glm/geometric.hpp>

#include "support/stat_seed.h"
#include "trace/bsdf.h"
#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex::bsdf_stats {

constexpr double kZ = 4.0;
constexpr double kPiD = std::numbers::pi;

// --- statistics ---

struct Estimate {
  double mean = 0.0;
  double se = 0.0;
};

struct Accumulator {
  double sum = 0.0, sum2 = 0.0;
  std::uint64_t n = 0;
  void add(double x) {
    sum += x;
    sum2 += x * x;
    ++n;
  }
  Estimate estimate() const {
    const double mean = sum / static_cast<double>(n);
    const double var = std::max(0.0, sum2 / static_cast<double>(n) - mean * mean);
    return {mean, std::sqrt(var / static_cast<double>(n))};
  }
};

inline double chi2_critical(double k, double z) { return test::chi2_upper_critical(k, z); }

// Chi-square of observed against expected counts, pooling cells expected below 5 (pbrt's
// chi2test); a cell with nothing expected but something observed is an immediate failure.
struct Chi2 {
  double statistic = 0.0;
  double critical = 0.0;  // at z = 5
  int dof = 1;            // the cells compared, less one
  bool impossible_count = false;
};
inline Chi2 chi2_test(const std::vector<double>& observed, const std::vector<double>& expected) {
  std::vector<std::size_t> order(observed.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](std::size_t a, std::size_t b) { return expected[a] < expected[b]; });
  Chi2 r;
  double pooled_o = 0.0, pooled_e = 0.0;
  int cells = 0;
  for (std::size_t i : order) {
    if (expected[i] <= 0.0) {
      if (observed[i] > 0.0) r.impossible_count = true;
      continue;
    }
    if (expected[i] < 5.0 || pooled_e > 0.0) {
      pooled_o += observed[i];
      pooled_e += expected[i];
      if (pooled_e >= 5.0) {
        r.statistic += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
        ++cells;
        pooled_o = pooled_e = 0.0;
      }
      continue;
    }
    r.statistic += (observed[i] - expected[i]) * (observed[i] - expected[i]) / expected[i];
    ++cells;
  }
  if (pooled_e > 0.0) {
    r.statistic += (pooled_o - pooled_e) * (pooled_o - pooled_e) / pooled_e;
    ++cells;
  }
  r.dof = std::max(cells - 1, 1);
  r.critical = chi2_critical(r.dof, 5.0);
  return r;
}

// sample() against pdf(): the directions of n samples of `sampled` binned over the sphere
// (equal-area bins in cos θ × φ about the normal), plus one cell for all delta samples and one for
// "no sample". Expected counts integrate pdf() of `m` over each bin (midpoint rule on a 6 × 6
// sub-grid); the delta cell expects n · Σ component_probability; "no sample" gets the rest.
// The bins next to the poles (±n) integrate on a 32 × 32 sub-grid: a narrow lobe there (normal
// incidence, or a refraction straight through) varies too fast for 6 × 6 midpoints. `sub` replaces
// the 6 elsewhere: a Beckmann lobe of alpha 0.1 near the horizon covers a few dozen bins, and 6 × 6
// midpoints put its expected counts ~1 % off (chi-square 226 on 40 cells; 16 × 16: 48).
inline Chi2 chi2_sample_vs_pdf(const Material& sampled, const Material& m, const glm::vec3& wo,
                        const glm::vec3& n, std::uint64_t seed, int samples, int sub = 6) {
  constexpr int kU = 40, kPhi = 80;
  const Frame frame = Frame::from_normal(n);
  std::vector<double> observed(kU * kPhi + 2, 0.0), expected(kU * kPhi + 2, 0.0);
  int rim = 0;  // draws on the square's edge that a cosine lobe maps onto its rim (see below)
  bool impossible_draws = false;
  for (int i = 0; i < samples; ++i) {
    Sampler s(seed, 0, static_cast<std::uint64_t>(i));
    const float uc = s.get1d();
    const glm::vec2 u2 = s.get2d();
    const auto r = bsdf::sample(sampled, wo, n, n, uc, u2, TransportMode::kRadiance);
    if (!r && (u2.x == 0.0f || u2.y == 0.0f)) {
      // A coordinate exactly 0 (probability 2^-24 each) puts a cosine-distributed direction on
      // the horizon, where its density is 0, and sample() rightly returns nothing: a draw of
      // measure zero, left out (it filled the "no sample" cell, expected 0, in 10 seeds of 100).
      ++rim;
      continue;
    }
    if (!r) {
      observed[kU * kPhi + 1] += 1.0;
    } else if (r->is_delta) {
      observed[kU * kPhi] += 1.0;
    } else {
      // A draw pdf() calls impossible is a mismatch of sample() and pdf() whatever the bins say.
      if (!(bsdf::pdf(m, wo, r->wi, n) > 0.0f)) impossible_draws = true;
      const glm::vec3 l = frame.to_local(r->wi);
      const double u = std::clamp(static_cast<double>(l.z), -1.0, 1.0);
      double phi = std::atan2(static_cast<double>(l.y), static_cast<double>(l.x));
      if (phi < 0.0) phi += 2.0 * kPiD;
      const int iu = std::min(static_cast<int>((u + 1.0) / 2.0 * kU), kU - 1);
      const int ip = std::min(static_cast<int>(phi / (2.0 * kPiD) * kPhi), kPhi - 1);
      observed[static_cast<std::size_t>(iu * kPhi + ip)] += 1.0;
    }
  }
  samples -= rim;
  double total = 0.0;
  const double du = 2.0 / kU, dphi = 2.0 * kPiD / kPhi;
  for (int iu = 0; iu < kU; ++iu) {
    const int kSub = iu < 2 || iu >= kU - 2 ? std::max(32, sub) : sub;
    for (int ip = 0; ip < kPhi; ++ip) {
      double integral = 0.0;
      for (int a = 0; a < kSub; ++a) {
        for (int b = 0; b < kSub; ++b) {
          const double u = -1.0 + (iu + (a + 0.5) / kSub) * du;
          const double phi = (ip + (b + 0.5) / kSub) * dphi;
          const double r = std::sqrt(std::max(0.0, 1.0 - u * u));
          const glm::vec3 wi = frame.to_world(glm::vec3(static_cast<float>(r * std::cos(phi)),
                                                        static_cast<float>(r * std::sin(phi)),
                                                        static_cast<float>(u)));
          integral += bsdf::pdf(m, wo, wi, n);
        }
      }
      integral *= du * dphi / (kSub * kSub);
      expected[static_cast<std::size_t>(iu * kPhi + ip)] = integral * samples;
      total += integral;
    }
  }
  double p_delta = 0.0;
  const int components = std::holds_alternative<Mixture>(m)
                             ? static_cast<int>(std::get<Mixture>(m).components.size())
                             : 1;
  for (int c = 0; c < components; ++c)
    for (Lobe lobe : {Lobe::kSpecularReflection, Lobe::kSpecularTransmission})
      p_delta += bsdf::component_probability(m, wo, n, c, lobe);
  expected[kU * kPhi] = p_delta * samples;
  // "No sample" expects the rest, 1 − Σ pdf integral − p_delta: a difference whose error is the
  // quadrature's (~1e-4 of the total, tens of samples), so it cannot tell a small true rate from 0,
  // and clamping it to 0 made a rare failed draw an "impossible" count. A Beckmann conductor of
  // alpha 0.1 lit from 50° inside fails a draw at u1 = 1 − 2⁻²⁴ (its visible slope's 1 − 6e-8
  // quantile tilts the microfacet 28°, and the reflection leaves below the horizon): 4 of 29.4 M
  // draws, once in issue 36's sweep (seed 83). So a cell that the rest does not reach is given a
  // count above 0, which pools it with the smallest cells.
  expected[kU * kPhi + 1] = std::max(1e-9, (1.0 - total - p_delta) * samples);
  // Likewise a bin whose midpoints all miss a density that is positive on a sliver of it (rough
  // glass of alpha 0.15 x 0.6 seen at 40°: its refraction's density ends where the half vector
  // turns horizontal, and a draw fell beyond the last midpoint, issue 36's sweep, seed 96): its
  // expected count of 0 is the quadrature's. Every draw's own pdf() decides impossibility above;
  // a bin with draws is given a count above 0, which pools it with the smallest cells.
  for (std::size_t i = 0; i < static_cast<std::size_t>(kU * kPhi); ++i)
    if (observed[i] > 0.0) expected[i] = std::max(expected[i], 1e-9);
  Chi2 result = chi2_test(observed, expected);
  result.impossible_count = result.impossible_count || impossible_draws;
  return result;
}
inline Chi2 chi2_sample_vs_pdf(const Material& m, const glm::vec3& wo, const glm::vec3& n,
                        std::uint64_t seed, int samples, int sub = 6) {
  return chi2_sample_vs_pdf(m, m, wo, n, seed, samples, sub);
}

// Mean of sample().weight (first channel), a nullopt counting 0: the directional albedo.
inline Estimate albedo_by_sampling(const Material& m, const glm::vec3& wo, const glm::vec3& n,
                            std::uint64_t seed, int samples,
                            TransportMode mode = TransportMode::kRadiance) {
  Accumulator acc;
  for (int i = 0; i < samples; ++i) {
    Sampler s(seed, 1, static_cast<std::uint64_t>(i));
    const float uc = s.get1d();
    const auto r = bsdf::sample(m, wo, n, n, uc, s.get2d(), mode);
    acc.add(r ? r->weight.x : 0.0);
  }
  return acc.estimate();
}

// ∫ eval · |cos| over the sphere with uniformly distributed directions: independent of sample().
inline Estimate albedo_by_uniform_eval(const Material& m, const glm::vec3& wo, const glm::vec3& n,
                                std::uint64_t seed, int samples) {
  Accumulator acc;
  for (int i = 0; i < samples; ++i) {
    Sampler s(seed, 2, static_cast<std::uint64_t>(i));
    const glm::vec3 wi = sample_uniform_sphere(s.get2d());
    acc.add(bsdf::eval(m, wo, wi, n).x * std::abs(glm::dot(wi, n)) * 4.0 * kPiD);
  }
  return acc.estimate();
}

// ∫ eval · |cos| over the sphere with one uniformly jittered direction in each of `samples` equal
// cells (equal-area in cos θ × φ, about n), independent of sample() as the uniform estimate above.
// A narrow lobe (rough glass of alpha 0.1) covers a fixed number of cells here, where uniform
// directions hit it a Poisson number of times: their mean is skewed low with a standard error
// that shrinks with it (MaterialsAlbedo read 4.8 σ at one seed in 48, its deviates' mean 0.57 on
// that lobe). The variance comes from pairs of neighbouring cells, Σ (f_a − f_b)² / N²: it
// over-states the variance by the pairs' differences in mean, never under-states it.
inline Estimate albedo_by_stratified_eval(const Material& m, const glm::vec3& wo, const glm::vec3& n,
                                          std::uint64_t seed, int samples) {
  const Frame frame = Frame::from_normal(n);
  const int rings = std::max(1, static_cast<int>(std::sqrt(samples / 2.5)));
  const int cells = std::max(2, samples / rings / 2 * 2);  // per ring, even: the pairs
  double sum = 0.0, pairs = 0.0;
  for (int i = 0; i < rings; ++i) {
    for (int j = 0; j < cells; j += 2) {
      double f[2];
      for (int k = 0; k < 2; ++k) {
        Sampler s(seed, 3, static_cast<std::uint64_t>(i) * static_cast<std::uint64_t>(cells) + static_cast<std::uint64_t>(j + k));
        const glm::vec2 v = s.get2d();
        const double u = -1.0 + 2.0 * (i + static_cast<double>(v.x)) / rings;
        const double phi = 2.0 * kPiD * (j + k + static_cast<double>(v.y)) / cells;
        const double r = std::sqrt(std::max(0.0, 1.0 - u * u));
        const glm::vec3 wi = frame.to_world(glm::vec3(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                                                      static_cast<float>(u)));
        f[k] = bsdf::eval(m, wo, wi, n).x * std::abs(glm::dot(wi, n)) * 4.0 * kPiD;
      }
      sum += f[0] + f[1];
      pairs += (f[0] - f[1]) * (f[0] - f[1]);
    }
  }
  const double count = static_cast<double>(rings) * cells;
  return {sum / count, std::sqrt(pairs) / count};
}

// An estimate within `sigmas` of its standard errors (plus `slack`, float rounding) of the value
// it estimates.
inline void expect_mean(const Estimate& e, double expected, double sigmas, const std::string& what, double slack = 0.0) {
  if (e.se > 0.0) test::stat_log(what, (e.mean - expected) / e.se, sigmas);
  EXPECT_NEAR(e.mean, expected, sigmas * e.se + slack) << what << ": " << e.mean << " ± " << e.se;
}

// Two independent estimates of one value agree within `sigmas` combined standard errors (and
// float rounding).
inline void expect_agree(const Estimate& a, const Estimate& b, const char* what, double sigmas = kZ) {
  const double combined = std::sqrt(a.se * a.se + b.se * b.se);
  if (combined > 0.0) test::stat_log(what, (a.mean - b.mean) / combined, sigmas);
  EXPECT_NEAR(a.mean, b.mean, sigmas * combined + 1e-6)
      << what << ": " << a.mean << " ± " << a.se << " vs " << b.mean << " ± " << b.se;
}

}  // namespace pathex::bsdf_stats
