// Significance levels for many checks at once: Student's t tails and the Šidák tolerance. The one
// place that turns a false-alarm rate into a number of σ, for `pathex bias`'s under-sampling check
// (bias/bias.h) and the statistical tests (tests/support/stat_seed.h).
#pragma once

namespace pathex {

// P(|T| > x) for Student's t with `dof` ≥ 1 degrees of freedom (the z of an estimate has its
// Estimate::dof, 16 by default), by Simpson's rule over [0, x] of its density.
double student_two_sided_tail(double x, int dof);

// The |z| of a normal deviate as far into its two-sided tail as `x` is into Student's t's with
// `dof` degrees of freedom (x itself where that tail is below double precision): an estimate's z
// made fit for a χ² sum, which assumes normal deviates (stats/convergence.h check_stderr).
double normal_equivalent(double x, int dof);

// The tolerance, in standard errors, at which `checks` independent two-sided checks of
// t-distributed deviations (`dof` degrees of freedom) fail together with probability
// `family_rate` when nothing is wrong (Šidák: each at 1 − (1 − family_rate)^(1/checks)).
double sidak_sigmas(int checks, double family_rate, int dof);

// The Welch–Satterthwaite degrees of freedom of the difference of two estimates with variances
// `va`, `vb` (their squared stderrs) of `dof_a`, `dof_b` ≥ 1 degrees of freedom:
// (va + vb)² / (va² / dof_a + vb² / dof_b), in [min(dof_a, dof_b), dof_a + dof_b]; the smaller dof
// where both variances are 0.
double welch_dof(double va, int dof_a, double vb, int dof_b);

}  // namespace pathex
