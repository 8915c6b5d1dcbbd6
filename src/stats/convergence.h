// Accuracy against time (DESIGN §8, issue 13): the statistics `pathex converge` computes over a
// ladder of renders of one renderer and one class, and the check that a renderer's reported
// standard error tells the truth.
//
// A ladder is a list of rungs, each an independent render at a larger budget. At rung i the
// renderer reports an estimate X_i with a standard error s_i (batch means, stats/histogram.h),
// and the reference says R ± s_R (s_R = 0 for a closed form). If s_i is honest,
//
//     z_i = (X_i − R) / sqrt(s_i² + s_R²)
//
// is close to a standard normal variable, independent across rungs, and Σ z_i² follows a χ²
// distribution with n degrees of freedom. The first check flags a ladder whose Σ z_i² exceeds the
// χ²_n quantile at 1 − kStderrCheckAlpha, or falls below its quantile at kStderrCheckAlpha (the
// lower tail: the estimates are closer to the reference than their error bars allow, a stderr
// that overstates the error, as one computed from correlated batches did; issue 36). Upper: the
// estimates are further from the reference than their error bars allow (a renderer that misses a near-delta peak reports a tiny stderr while it
// is many σ off). A rung whose reported stderr is 0 while its error is not counts as infinitely
// far off. The tracer computes in single precision, so an error below kRoundingFloor of the
// reference is rounding, not noise: σ_i² gets (kRoundingFloor · R)² added (an estimator with no
// variance, such as next-event estimation of one bounce inside a closed sphere, is exact to
// within that).
//
// The second check needs no reference: the stability of the stderr itself, ε, the relative
// standard error of the variance estimate (Estimate::stability, VarianceDesign::variance_relative_error(),
// stats/histogram.h): with G pixel groups of two replicates, from the spread of the groups'
// terms, sqrt(2/G) = 0.35 for normal ones at G = 16; with B plain batch means of sample kurtosis κ,
// sqrt((κ − (B − 3)/(B − 1)) / B), 0.25 for normal batch means at B = 32. Either is about 1 when
// one group or batch holds nearly all of the estimate (a rare spike). The ladder is flagged as unstable when the median ε over its rungs is at
// least kUnstableVariance: then a few batches carry the estimate and the next render's stderr may
// differ from this one's by more than itself. pathex trace says so of a single render's total
// or class whose ε is at least kUnstableVariance.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "stats/histogram.h"

namespace pathex {

inline constexpr double kStderrCheckAlpha = 1e-3;  // false-alarm rate of the χ² check per ladder

// The upper quantile of the χ² distribution with `dof` ≥ 1 degrees of freedom: the x with
// P(χ²_dof > x) = alpha (the survival function in closed form for integer dof, solved by bisection).
double chi2_upper_quantile(int dof, double alpha);

// One rung as the checks see it.
struct RungError {
  double estimate = 0.0;
  double std_error = 0.0;   // reported; NaN when the render had too few batches
  double stability = 0.0;   // the relative error of its variance estimate (NaN: unknown)
  int dof = 0;              // the stderr's degrees of freedom (Histogram::stderr_dof()); 0: its z is taken as normal
};

struct StderrCheck {
  double chi2 = 0.0;        // Σ z_i² over the rungs with a stderr (each z_i as the normal deviate of its t tail)
  int dof = 0;              // how many
  double limit = 0.0;       // chi2_upper_quantile(dof, kStderrCheckAlpha)
  // The lower tail counts only the rungs whose stderr is above the rounding floor (an exact
  // estimator's error of 0 is no sign of an overstated stderr): their Σ z_i², how many, and
  // chi2_upper_quantile(lower_dof, 1 − kStderrCheckAlpha).
  double lower_chi2 = 0.0;
  int lower_dof = 0;
  double lower_limit = 0.0;
  double max_abs_z = 0.0;   // the largest |z_i| (inf: a zero stderr with a nonzero error)
  int max_z_rung = -1;
  double stability = 0.0;   // median ε over the rungs (NaN: unknown)
  bool disagrees = false;   // chi2 > limit: the stderr understates the error
  bool too_large = false;   // lower_chi2 < lower_limit: the stderr overstates the error
  bool unstable = false;    // stability ≥ kUnstableVariance
  bool lies() const { return disagrees || too_large || unstable; }
};

// Both checks over one ladder against a reference value R ± reference_stderr.
StderrCheck check_stderr(const std::vector<RungError>& rungs, double reference, double reference_stderr);

// The least-squares slope of log(y) against log(x) over the points with x, y > 0 (NaN for fewer
// than two): −0.5 for an error that falls as 1/√t.
double loglog_slope(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace pathex
