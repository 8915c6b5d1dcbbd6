// Comparing two renders' estimates of one path string by their batch-means stderrs: the rule the
// statistical tests share (tests/trace/agreement_test.cpp, tests/scene/import_test.cpp, and
// render_test's Sampling.SolidAngle... and Sampling.EverySettingAgrees...), so that what "enough
// samples for a stderr to mean anything" is has one copy.
//
// A batch-means stderr describes an estimate made of enough samples only (issue 36's sweeps):
//   - with few nonzero samples, whether a batch holds a contribution at all decides its mean, and
//     the batch-means t is far from Student's: light tracing meets materials.json's LDDDDDDSE about
//     76 times in 128 spp at 16 x 16 and a few heavy splats carry it; pt-nee meets cornell.json's
//     caustic LDDSDSE by chance;
//   - with few degrees of freedom (Estimate::dof: the pixel groups whose replicates hold the path)
//     a stderr can be exactly 0: cornell.json's lamp seen directly covers a few of the 256 pixels at
//     16 x 16, every sample there adds the lamp's radiance, and under `sobol` both replicates of
//     those pixels can meet the lamp equally often, while the seed-to-seed spread is 0.4 % of the
//     value (agreement_test's seed 70, import_test's seed 39 of issue 36's sweeps). At 5 or more
//     degrees of freedom a stderr of 0 needs five such coincidences.
// Such a pair is checked for being found, not for its value. A comparison is judged by Student's t
// at the two errors' Welch–Satterthwaite degrees of freedom.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "stats/histogram.h"
#include "stats/significance.h"
#include "support/stat_seed.h"

namespace pathex::test {

// The fewest nonzero samples (4 a batch of the default 32) for which an estimate is compared by
// its stderr.
inline constexpr std::uint64_t kMinSamples = 4 * kDefaultBatches;
// The fewest degrees of freedom for which a stderr is compared.
inline constexpr int kMinDof = 5;

// Whether both estimates have the samples and degrees of freedom for their stderrs to be compared.
inline bool comparable(const Estimate& a, const Estimate& b) {
  return std::min(a.samples, b.samples) >= kMinSamples && std::min(a.dof, b.dof) >= kMinDof;
}

struct Comparison {
  std::string what;
  double deviation = 0, sigma = 0;  // |a - b| and the combined stderr
  int dof = 0;                      // Welch–Satterthwaite, rounded down
  double allowance = 0;             // a difference the test allows beyond the noise, stated by it
};

// a against b (by their stderrs: comparable(a, b) says whether that means anything); `what` names
// them in a failure.
inline Comparison compare(const std::string& what, const Estimate& a, const Estimate& b) {
  const double va = a.std_error * a.std_error, vb = b.std_error * b.std_error;
  return {what + ": " + std::to_string(a.luminance) + " ± " + std::to_string(a.std_error) + " (" + std::to_string(a.dof) +
              " dof) against " + std::to_string(b.luminance) + " ± " + std::to_string(b.std_error) + " (" +
              std::to_string(b.dof) + " dof)",
          std::fabs(a.luminance - b.luminance), std::sqrt(va + vb), static_cast<int>(welch_dof(va, std::max(a.dof, 1), vb, std::max(b.dof, 1)))};
}

// Every path string of `a` carrying more than `share` of a's total, against the same string of `b`:
// the comparable ones appended to `comparisons` (named "what, path"), the others counted and
// returned. A path `b` never samples fails the test unless `a` met it too rarely for a stderr.
inline int compare_paths(const HistogramReport& a, const HistogramReport& b, double share, const std::string& what,
                         std::vector<Comparison>* comparisons) {
  std::map<std::string, const PathEstimate*> by_path;
  for (const PathEstimate& p : b.paths) by_path[p.path] = &p;
  int sparse = 0;
  for (const PathEstimate& p : a.paths) {
    if (!(p.estimate.luminance > share * a.total.luminance)) continue;
    auto it = by_path.find(p.path);
    if (it == by_path.end()) {
      EXPECT_LT(p.estimate.samples, kMinSamples) << what << ": " << p.path << " is never sampled";
      ++sparse;
    } else if (!comparable(p.estimate, it->second->estimate)) {
      ++sparse;
    } else {
      comparisons->push_back(compare(what + ", " + p.path, p.estimate, it->second->estimate));
    }
  }
  return sparse;
}

// Every comparison within the tolerance that holds the family of them to `family_rate`
// (family_sigmas at each one's own degrees of freedom) plus its allowance; each logged for
// PATHEX_STAT_LOG as (deviation - allowance) / sigma against that tolerance.
// Returns the failures' descriptions.
inline std::vector<std::string> family_failures(const std::vector<Comparison>& comparisons, double family_rate = 1e-3) {
  std::vector<std::string> failed;
  for (const Comparison& c : comparisons) {
    const double tolerance = family_sigmas(static_cast<int>(comparisons.size()), family_rate, std::max(c.dof, 1));
    const double excess = c.deviation - c.allowance;  // logged on the tolerance's scale: fails above it
    stat_log(c.what, c.sigma > 0 ? excess / c.sigma : (excess > 0 ? HUGE_VAL : 0.0), tolerance);
    if (!(c.deviation <= tolerance * c.sigma + c.allowance + 1e-9))
      failed.push_back(c.what + " (tolerance " + std::to_string(tolerance) + " σ" +
                       (c.allowance > 0 ? " + " + std::to_string(c.allowance) : std::string()) + ")");
  }
  return failed;
}

}  // namespace pathex::test
