// The statistics of a convergence ladder; the formulas and thresholds are in convergence.h.
#include "classify/convergence.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pathex {

std::vector<double> class_batch_means(const Histogram& histogram, const Classifier* classifier, int class_index) {
  const int batches = histogram.num_batches();
  std::vector<ExactRgb> sums(static_cast<std::size_t>(batches), ExactRgb{});
  for (Histogram::PathId id = 0; id < histogram.num_paths(); ++id) {
    if (class_index >= 0) {
      if (classifier == nullptr) return {};
      const std::vector<int>& members = classifier->members(histogram.class_set(id));
      if (std::find(members.begin(), members.end(), class_index) == members.end()) continue;
    }
    for (int b = 0; b < batches; ++b) add_to(sums[static_cast<std::size_t>(b)], histogram.cell(id, b).sum);
  }
  std::vector<double> means;
  for (int b = 0; b < batches; ++b) {
    const std::uint64_t n = histogram.batch_samples(b);
    if (n == 0) continue;
    means.push_back(luminance(to_double(sums[static_cast<std::size_t>(b)])) / static_cast<double>(n));
  }
  return means;
}

double variance_relative_error(const std::vector<double>& x) {
  const std::size_t n = x.size();
  if (n < 4) return std::numeric_limits<double>::quiet_NaN();
  double mean = 0.0;
  for (double v : x) mean += v;
  mean /= static_cast<double>(n);
  double m2 = 0.0, m4 = 0.0;
  for (double v : x) {
    const double d2 = (v - mean) * (v - mean);
    m2 += d2;
    m4 += d2 * d2;
  }
  m2 /= static_cast<double>(n);
  m4 /= static_cast<double>(n);
  if (!(m2 > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  const double b = static_cast<double>(n);
  const double kurtosis = m4 / (m2 * m2);
  return std::sqrt(std::max(0.0, (kurtosis - (b - 3.0) / (b - 1.0)) / b));
}

namespace {

// The upper quantile of the standard normal distribution (Acklam's rational approximation of the
// inverse, relative error below 1.2e-9), for 0 < alpha < 0.5.
double normal_upper_quantile(double alpha) {
  const double p = alpha;
  const double q = std::sqrt(-2.0 * std::log(p));
  const double c[] = {-7.784894002430293e-03, -3.223964580411365e-01, -2.400758277161838e+00,
                      -2.549732539343734e+00, 4.374664141464968e+00,  2.938163982698783e+00};
  const double d[] = {7.784695709041462e-03, 3.224671290700398e-01, 2.445134137142996e+00, 3.754408661907416e+00};
  const double lower = (((((c[0] * q + c[1]) * q + c[2]) * q + c[3]) * q + c[4]) * q + c[5]) /
                       ((((d[0] * q + d[1]) * q + d[2]) * q + d[3]) * q + 1.0);
  return -lower;  // the lower tail's quantile at p, negated
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
  const double k = static_cast<double>(dof);
  const double z = normal_upper_quantile(alpha);
  const double a = 2.0 / (9.0 * k);
  const double t = 1.0 - a + z * std::sqrt(a);
  return k * t * t * t;
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
    c.chi2 += z * z;
    ++c.dof;
    if (z > c.max_abs_z || c.max_z_rung < 0) {
      c.max_abs_z = z;
      c.max_z_rung = static_cast<int>(i);
    }
  }
  c.limit = c.dof > 0 ? chi2_upper_quantile(c.dof, kStderrCheckAlpha) : 0.0;
  c.disagrees = c.dof > 0 && c.chi2 > c.limit;
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
