// The statistical tests run at fixed seeds; these two environment variables, read only here, let
// a person measure how often such a test would fail at other seeds (its false-failure rate, which
// its tolerance states), as PATHEX_LAWS_SEED does for the automata laws:
//
//   PATHEX_STAT_SEED=N  run the statistical test at seed N instead of its fixed seed;
//   PATHEX_STAT_LOG=1   print every standardised deviation it checks, one line each:
//                       "stat-log <what>\t<value>\t<tolerance>".
//
// bench/README.md (2026-12-03, "Statistical tests at other seeds") has the loop over seeds.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string>

#include "stats/histogram.h"
#include "stats/significance.h"

namespace pathex::test {

// `fixed`, or PATHEX_STAT_SEED when it is set.
inline std::uint64_t stat_seed(std::uint64_t fixed) {
  const char* env = std::getenv("PATHEX_STAT_SEED");
  return env != nullptr && *env != '\0' ? std::strtoull(env, nullptr, 10) : fixed;
}

// `fixed`, or shifted by PATHEX_STAT_SEED when it is set: for a helper that renders at seeds its
// callers choose (render_test's render_json: 7 by default, 11 and 13 beside it), which must stay
// distinct from each other at every swept seed.
inline std::uint64_t stat_seed_from(std::uint64_t fixed) {
  const char* env = std::getenv("PATHEX_STAT_SEED");
  return env != nullptr && *env != '\0' ? fixed + 1000003u * std::strtoull(env, nullptr, 10) : fixed;
}

// One checked value and its tolerance, printed when PATHEX_STAT_LOG is set (nothing otherwise).
inline void stat_log(const std::string& what, double value, double tolerance) {
  static const bool on = std::getenv("PATHEX_STAT_LOG") != nullptr;
  if (on) std::printf("stat-log %s\t%.6g\t%.6g\n", what.c_str(), value, tolerance);
}

// The tolerance, in standard errors, that makes `checks` independent two-sided checks fail
// together with probability `family_rate` (Šidák over Student's t with `dof` degrees of freedom,
// kDefaultDof = 16 for a render's default 16 pixel groups of two replicates: stats/histogram.h;
// stats/significance.h's sidak_sigmas, the library's one copy).
// One place that states a statistical test's false-failure rate.
inline double family_sigmas(int checks, double family_rate = 1e-3, int dof = kDefaultDof) {
  return sidak_sigmas(checks, family_rate, dof);
}

}  // namespace pathex::test
