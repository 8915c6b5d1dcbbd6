#include "stats/significance.h"

#include <algorithm>
#include <cmath>

namespace pathex {

double student_two_sided_tail(double x, int dof) {
  const double nu = std::max(dof, 1);
  const double c = std::exp(std::lgamma((nu + 1) / 2) - std::lgamma(nu / 2)) / std::sqrt(nu * 3.14159265358979323846);
  auto f = [&](double t) { return c * std::pow(1 + t * t / nu, -(nu + 1) / 2); };
  const int n = 4000;  // even
  const double h = x / n;
  double sum = f(0) + f(x);
  for (int i = 1; i < n; ++i) sum += f(i * h) * (i % 2 ? 4 : 2);
  return std::max(0.0, 1 - 2 * sum * h / 3);
}

double normal_equivalent(double x, int dof) {
  const double p = student_two_sided_tail(std::fabs(x), dof);
  if (!(p > 1e-12)) return std::fabs(x);  // beyond what the tail's quadrature resolves
  double lo = 0, hi = std::fabs(x);       // a normal tail is lighter: its point lies below x
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (std::erfc(mid / std::sqrt(2.0)) > p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double sidak_sigmas(int checks, double family_rate, int dof) {
  const double each = 1 - std::pow(1 - family_rate, 1.0 / std::max(checks, 1));
  double lo = 0, hi = 60;
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (student_two_sided_tail(mid, dof) > each ? lo : hi) = mid;
  }
  return hi;
}

double welch_dof(double va, int dof_a, double vb, int dof_b) {
  const double denominator = va * va / dof_a + vb * vb / dof_b;
  if (!(denominator > 0)) return std::min(dof_a, dof_b);
  return std::clamp((va + vb) * (va + vb) / denominator, static_cast<double>(std::min(dof_a, dof_b)),
                    static_cast<double>(dof_a + dof_b));
}

}  // namespace pathex
