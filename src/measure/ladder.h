// The ladder of `pathex converge` (DESIGN §8, issue 13): its budgets, the classes it measures with
// their references, each rung's measures, and the statistics of a renderer's rungs against the
// reference (error, z, efficiency 1/(error² × time), the error's slope against time and the check
// that the reported standard error tells the truth, stats in stats/convergence.h). The command
// (cli/converge.cpp) prints; its run (measure/converge.h) renders the rungs; what is measured and judged is here.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "stats/convergence.h"
#include "stats/histogram.h"
#include "film/image.h"
#include "core/error.h"
#include "trace/render.h"

namespace pathex {

// One rung's budget: samples per pixel, or seconds of wall time (the render stops after the chunk
// in progress when they run out).
struct Budget {
  std::uint64_t spp = 0;  // 0 for a time budget
  double seconds = 0.0;
  std::string text() const {
    std::ostringstream s;
    if (spp) s << spp << " spp";
    else s << seconds << " s";
    return s.str();
  }
};

// "4,16,64" (positive integers, strictly increasing) or "1,4,16" (positive seconds); errors name `option`.
Result<std::vector<Budget>> parse_ladder(const std::string& text, bool time, const std::string& option);

// Row 0 is the whole image ("total"); row i > 0 is classifier class i − 1.
struct ClassRow {
  std::string name;
  std::string expr;
  std::optional<double> reference;         // image mean luminance
  double reference_stderr = 0.0;           // 0 for a closed form
  std::optional<std::vector<float>> pixels;  // per-pixel reference luminance, row-major
  // Non-empty: the reference cannot sample every path of the class (the checker's shortest such
  // path, and whose), so its value is not the class's and no error is measured against it.
  std::string unmeasurable;
};

// Per-pixel luminance of an image, row-major.
std::vector<float> luminance_image(const RgbImage& im);

struct ClassMeasure {
  double estimate = 0.0;
  double std_error = 0.0;
  double stability = 0.0;
  int dof = 0;  // the stderr's degrees of freedom (Estimate::dof)
  std::optional<double> rms_pixel;  // against the per-pixel reference, when there is one
};

struct RungResult {
  Budget budget;
  std::uint64_t seed = 0;
  std::uint64_t spp = 0;  // done
  double cpu_s = 0.0, wall_s = 0.0;  // under MPI: every rank's CPU, rank 0's wall time (with the reduction)
  double own_cpu_s = 0.0;             // this process's rendering CPU (cpu_s for one process)
  std::uint64_t nonfinite = 0;
  std::vector<ClassMeasure> classes;  // per ClassRow
  std::optional<RenderOutput> output;  // kept for the reference run
  bool interrupted = false;           // by Ctrl-C: the rung is not kept
};

// A finished rung's measures per class row from its render `out` (of the rows' classifier): the
// estimate, its stderr and the stability of its batch variance, and the per-pixel RMS error
// against a row's per-pixel reference; also the rung's non-finite samples.
Result<bool> measure_rung(const RenderOutput& out, const Classifier* classifier, const std::vector<ClassRow>& rows,
                          RungResult* r);

// The reference from a file: an earlier run's histogram.json (with classes.exr beside it, or the EXR
// of the same name), or an EXR alone, into `rows` (by class name), checked against the ladder's
// image size. `renderer` gets the histogram's renderer (empty for an EXR alone).
Result<bool> load_reference_file(const std::string& file, int width, int height, std::vector<ClassRow>* rows,
                                 std::string* renderer);

// A number as the table prints it ("-" when not finite).
std::string fmt(double v, const char* f = "%.5g");

// Per renderer and class: the ladder's statistics.
struct Series {
  std::vector<double> error, z, efficiency;
  double pooled_efficiency = std::numeric_limits<double>::quiet_NaN();
  double slope = std::numeric_limits<double>::quiet_NaN();
  StderrCheck check;
  std::string warning;
};

// The statistics of one renderer's rungs on class row `row` against its reference `cr` (none
// without a reference), with the warning the table and converge.json give when the check fails.
// `biased`: the renderer cannot sample a path of the class that the reference holds, so its error
// is the light it misses, which no stderr covers: the check's numbers are kept, but a stderr that
// disagrees with that error is no fault of the stderr and gets no warning (the table says instead
// that the renderer cannot sample the class and is not ranked on it).
Series analyse(const std::vector<RungResult>& rungs, std::size_t row, const ClassRow& cr, bool biased = false);

// The most efficient renderer on a class row (pooled efficiency 1 / mean(error² × CPU time) over
// the ladder) and its lead over the runner-up. A renderer that cannot sample all of the class is
// not ranked on it.
struct Ranking {
  std::string cls;
  std::string renderer;
  double efficiency = 0.0;
  std::string runner_up;  // empty: none
  double ratio = 0.0;     // efficiency over the runner-up's
};
struct Rankings {
  std::vector<Ranking> best;
  std::vector<std::string> lines;  // the table's closing lines, one per class row that has one
};
// `series[k][i]` and `cannot[k][i]`: renderer k (named renderers[k]) on class row i.
Rankings rank_renderers(const std::vector<ClassRow>& rows, const std::vector<std::string>& renderers,
                        const std::vector<std::vector<Series>>& series,
                        const std::vector<std::vector<std::optional<std::string>>>& cannot);

// The reference run converge makes when there is no closed form or reference file.
struct ReferenceRun {
  std::string renderer;
  std::uint64_t spp = 0;
  std::uint64_t seed = 0;
  double cpu_s = 0.0, wall_s = 0.0;
  std::uint64_t nonfinite_samples = 0;
};

}  // namespace pathex
