// Estimates as the tables of `trace` and `bias` print them.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include <algorithm>

#include "stats/histogram.h"

namespace pathex {

// "12.3 %"
inline std::string percent(double share, int decimals = 1) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f %%", decimals, 100.0 * share);
  return buf;
}

// An absolute estimate: the mean pixel luminance and its standard error, "0.01234 ± 0.00012".
inline std::string absolute(const Estimate& e) {
  char buf[64];
  if (std::isfinite(e.std_error)) std::snprintf(buf, sizeof buf, "%.5f ± %.5f", e.luminance, e.std_error);
  else std::snprintf(buf, sizeof buf, "%.5f (too few batches for an error)", e.luminance);
  return buf;
}

// Whether an estimate's stderr is unstable: Estimate::stability ≥ kUnstableVariance, and the stderr
// more than rounding. Why, in words: "a few pixel groups carry it: its square's relative error is 0.83".
inline bool stderr_unstable(const Estimate& e) {
  return std::isfinite(e.stability) && e.stability >= kUnstableVariance && e.std_error > kRoundingFloor * std::fabs(e.luminance);
}
inline std::string unstable_reason(const Estimate& e) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "a few pixel groups carry it: its square's relative error is %.2f", e.stability);
  return buf;
}
// What trace's table adds to an estimate whose stderr is unstable: "; its stderr is unstable (…)".
inline std::string unstable_text(const Estimate& e) {
  return stderr_unstable(e) ? "; its stderr is unstable (" + unstable_reason(e) + ")" : "";
}

// The techniques that carry an estimate, largest share first, at most `most` of them (the rest are
// counted): "bdpt (2, DD, 0) 97.0 % (80.0 % of the variance), bdpt (1, DD, 1) 3.0 % (20.0 %)".
// Where a technique's errors are correlated with the rest's (|r| ≥ kCorrelationWorthSaying) it is
// said in words: "…(90.0 % of the variance; its errors partly cancel the others', r = -0.57)".
inline constexpr double kCorrelationWorthSaying = 0.3;
inline std::string techniques_text(std::vector<TechniqueEstimate> ts, std::size_t most) {
  std::stable_sort(ts.begin(), ts.end(), [](const TechniqueEstimate& a, const TechniqueEstimate& b) { return a.share > b.share; });
  std::string out;
  for (std::size_t i = 0; i < ts.size() && i < most; ++i) {
    out += (i == 0 ? "" : ", ") + ts[i].name + " " + percent(ts[i].share);
    if (std::isfinite(ts[i].variance_share)) {
      out += " (" + percent(ts[i].variance_share) + (i == 0 ? " of the variance" : "");
      const double r = ts[i].correlation;
      if (std::isfinite(r) && std::fabs(r) >= kCorrelationWorthSaying) {
        char buf[32];
        std::snprintf(buf, sizeof buf, "%.2f", r);
        out += std::string(r < 0 ? "; its errors partly cancel the others'" : "; its errors add to the others'") + ", r = " + buf;
      }
      out += ")";
    }
  }
  if (ts.size() > most) out += ", and " + std::to_string(ts.size() - most) + " more";
  return out;
}

}  // namespace pathex
