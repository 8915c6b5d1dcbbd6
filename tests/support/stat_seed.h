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

namespace pathex::test {

// `fixed`, or PATHEX_STAT_SEED when it is set.
inline std::uint64_t stat_seed(std::uint64_t fixed) {
  const char* env = std::getenv("PATHEX_STAT_SEED");
  return env != nullptr && *env != '\0' ? std::strtoull(env, nullptr, 10) : fixed;
}

// One checked value and its tolerance, printed when PATHEX_STAT_LOG is set (nothing otherwise).
inline void stat_log(const std::string& what, double value, double tolerance) {
  static const bool on = std::getenv("PATHEX_STAT_LOG") != nullptr;
  if (on) std::printf("stat-log %s\t%.6g\t%.6g\n", what.c_str(), value, tolerance);
}

// P(|T| > x) for Student's t with `dof` degrees of freedom (the batch-means z of an estimate from
// B batches has B − 1), by Simpson's rule over [0, x] of its density: plenty for tolerances.
inline double student_two_sided_tail(double x, int dof) {
  const double nu = dof;
  const double c = std::exp(std::lgamma((nu + 1) / 2) - std::lgamma(nu / 2)) / std::sqrt(nu * 3.14159265358979323846);
  auto f = [&](double t) { return c * std::pow(1 + t * t / nu, -(nu + 1) / 2); };
  const int n = 4000;  // even
  const double h = x / n;
  double sum = f(0) + f(x);
  for (int i = 1; i < n; ++i) sum += f(i * h) * (i % 2 ? 4 : 2);
  return std::max(0.0, 1 - 2 * sum * h / 3);
}

// The tolerance, in standard errors, that makes `checks` independent two-sided checks fail
// together with probability `family_rate` (Šidák: each at 1 − (1 − rate)^(1/checks)), for
// standardised deviations distributed as Student's t with `dof` degrees of freedom (31 for the
// default 32 batches). One place that states a statistical test's false-failure rate.
inline double family_sigmas(int checks, double family_rate = 1e-3, int dof = 31) {
  const double each = 1 - std::pow(1 - family_rate, 1.0 / std::max(checks, 1));
  double lo = 0, hi = 60;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (student_two_sided_tail(mid, dof) > each ? lo : hi) = mid;
  }
  return hi;
}

}  // namespace pathex::test
