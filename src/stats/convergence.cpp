// The statistics of a convergence ladder; the formulas and thresholds are in convergence.h.
#include "stats/convergence.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "stats/significance.h"

namespace pathex {

namespace {

// P(χ²_k > x) for an integer k, in closed form: for even k, e^(-x/2) Σ_{i<k/2} (x/2)^i / i!; for
// odd k, erfc(sqrt(x/2)) + e^(-x/2) Σ_{i=1}^{(k-1)/2} (x/2)^(i-1/2) / Γ(i + 1/2).
double chi2_survival(double x, int k) {
  const double h = 0.5 * x;
  double sum = 0.0;
  if (k % 2 == 0) {
    double term = 1.0;
    for (int i = 0; i < k / 2; ++i) {
      sum += term;
      term *= h / (i + 1);
    }
    return std::exp(-h) * sum;
  }
  for (int i = 1; i <= (k - 1) / 2; ++i) sum += std::exp((i - 0.5) * std::log(h) - h - std::lgamma(i + 0.5));
  return std::erfc(std::sqrt(h)) + sum;
}

double median(std::vector<double> v) {
  v.erase(std::remove_if(v.begin(), v.end(), [](double x) { return !std::isfinite(x); }), v.end());
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

}  // namespace

double chi2_upper_quantile(int dof, double alpha) {
  // Bisection on the survival function, which falls from 1 at x = 0.
  double lo = 0.0, hi = 10.0 + 10.0 * dof;
  while (chi2_survival(hi, dof) > alpha) hi *= 2.0;
  for (int i = 0; i < 200 && hi - lo > 1e-12 * hi; ++i) {
    const double mid = 0.5 * (lo + hi);
    (chi2_survival(mid, dof) > alpha ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

StderrCheck check_stderr(const std::vector<RungError>& rungs, double reference, double reference_stderr) {
  StderrCheck c;
  std::vector<double> stabilities;
  for (std::size_t i = 0; i < rungs.size(); ++i) {
    const RungError& r = rungs[i];
    stabilities.push_back(r.stability);
    if (!std::isfinite(r.std_error)) continue;
    const double rounding = kRoundingFloor * std::fabs(reference);
    const double sigma =
        std::sqrt(r.std_error * r.std_error + reference_stderr * reference_stderr + rounding * rounding);
    const double err = std::fabs(r.estimate - reference);
    double z = 0.0;
    if (sigma > 0.0) z = err / sigma;
    else if (err > 0.0) z = std::numeric_limits<double>::infinity();  // a zero stderr, a zero reference, an error
    // z is Student's t with the estimate's degrees of freedom (Estimate::dof), whose tails are
    // heavier than the normal's that the χ² quantiles assume: summed as the normal deviate of the
    // same tail, its false-alarm rate is kStderrCheckAlpha at 16 dof as at 31 (max_abs_z reports z itself).
    const double zn = r.dof > 0 && std::isfinite(z) ? normal_equivalent(z, r.dof) : z;
    c.chi2 += zn * zn;
    ++c.dof;
    if (r.std_error > rounding) {
      c.lower_chi2 += zn * zn;
      ++c.lower_dof;
    }
    if (z > c.max_abs_z || c.max_z_rung < 0) {
      c.max_abs_z = z;
      c.max_z_rung = static_cast<int>(i);
    }
  }
  c.limit = c.dof > 0 ? chi2_upper_quantile(c.dof, kStderrCheckAlpha) : 0.0;
  c.disagrees = c.dof > 0 && c.chi2 > c.limit;
  c.lower_limit = c.lower_dof > 0 ? chi2_upper_quantile(c.lower_dof, 1.0 - kStderrCheckAlpha) : 0.0;
  c.too_large = c.lower_dof > 0 && c.lower_chi2 < c.lower_limit;
  c.stability = median(stabilities);
  c.unstable = std::isfinite(c.stability) && c.stability >= kUnstableVariance;
  return c;
}

double loglog_slope(const std::vector<double>& x, const std::vector<double>& y) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  int n = 0;
  for (std::size_t i = 0; i < x.size() && i < y.size(); ++i) {
    if (!(x[i] > 0.0) || !(y[i] > 0.0) || !std::isfinite(x[i]) || !std::isfinite(y[i])) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    sx += lx;
    sy += ly;
    sxx += lx * lx;
    sxy += lx * ly;
    ++n;
  }
  if (n < 2) return std::numeric_limits<double>::quiet_NaN();
  const double den = n * sxx - sx * sx;
  if (!(den > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (n * sxy - sx * sy) / den;
}

}  // namespace pathex
