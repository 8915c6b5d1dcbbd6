// Estimates as the tables of `trace` and `bias` print them.
#pragma once

#include <cmath>
#include <cstdio>
#include <string>

#include "classify/histogram.h"

namespace pathex::cli {

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

}  // namespace pathex::cli
