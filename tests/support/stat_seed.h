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

// Student's t with this many degrees of freedom is the normal law to the precision of the tails
// used here: the `dof` to pass family_sigmas for a mean of many independent samples (thousands or
// more) whose standard error is estimated from the samples themselves, or is known exactly.
inline constexpr int kNormalDof = 1 << 20;

// The upper critical value of a chi-square statistic with `dof` degrees of freedom (Wilson and
// Hilferty's cube-root normal approximation) `z` standard normal deviates into its upper tail.
inline double chi2_upper_critical(double dof, double z) {
  const double h = 2.0 / (9.0 * dof);
  return dof * std::pow(1.0 - h + z * std::sqrt(h), 3.0);
}

// The inverse: how many standard normal deviates into its upper tail a chi-square statistic `x`
// with `dof` degrees of freedom lies (for stat_log, on the scale of the tolerance's z).
inline double chi2_deviate(double x, double dof) {
  const double h = 2.0 / (9.0 * dof);
  return (std::cbrt(x / dof) - 1.0 + h) / std::sqrt(h);
}

// The critical value that `checks` one-sided chi-square checks (each with `dof` degrees of
// freedom) exceed together with probability `family_rate` when nothing is wrong: Šidák's rate a per
// check, its upper-tail normal deviate (the two-sided one of 2a), through chi2_upper_critical.
// The same for a one-sided check of a normal deviate (a mean that must stay below a bound).
inline double family_sigmas_one_sided(int checks, double family_rate = 1e-3, int dof = kNormalDof) {
  const double each = 1.0 - std::pow(1.0 - family_rate, 1.0 / std::max(checks, 1));
  return sidak_sigmas(1, 2.0 * each, dof);
}

inline double family_chi2_critical(double dof, int checks, double family_rate = 1e-3) {
  return chi2_upper_critical(dof, family_sigmas_one_sided(checks, family_rate));
}

}  // namespace pathex::test
