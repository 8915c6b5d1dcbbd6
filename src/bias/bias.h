// How much light does a renderer miss in this scene, and where (issue 18): the checker and the
// tracer joined into one answer.
//
// The scene is rendered once, with a reference profile (by default bdpt plus every connector the
// tracer runs whose chains the scene's universe contains). The paths a renderer R cannot sample
// within the reference's reach form a regular language,
//
//     M = U_s ∩ U_{≤B} ∖ R          (U_s the scene's universe, B the reference's bound),
//
// which the checker builds as a minimal DFA. It is handed to the reference render as one more class
// of its classifier, `missed`, and so is M ∩ C for every user class C. The tracer's exact per-class
// sums and per-class images then give the missed energy, its standard error, the missed energy per
// class and the missed image from the very samples of the reference, bit for bit: no new code in the
// estimator, and a path's classes are decided once per distinct path (when the histogram first
// meets it), never per sample. Per exact path, R's verdict and the checker's explanation are
// computed once for each missed path of the histogram.
//
// What is not counted, and said so: light on paths with more than B interior vertices (the
// reference does not render them), and the paths neither R nor the reference can sample
// (M ∖ Ref). The latter come from the checker as witnesses, never as an energy of 0.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "stats/histogram.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "reach/query.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace pathex {

// The name of the internal class, of its image layer (missed.exr, missed.png) and of its row in
// histogram.json's classes. A user class may not use it.
inline constexpr const char* kMissedClass = "missed";
// The reference's bound when none is asked for: this, or R's bound plus kReferenceExtraBounces
// when that is more, so that the reference always renders deeper than R.
inline constexpr int kDefaultReferenceBounces = 16;
inline constexpr int kReferenceExtraBounces = 8;
inline constexpr int kMaxReferenceBounces = 1000;  // the tracer's ceiling

// The default reference for a scene: the built-in `bdpt` plus, for each connector found in the
// built-in profiles that the tracer runs, the built-ins' widest strategies for that connector (each
// whose language no other's holds, e.g. bdpt+manifold's t >= 2 and t = 1) when their languages meet
// the scene's `universe` within `bound`. Named "bdpt+<connector>+…", each connector once.
Result<Profile> default_reference(const Dfa& universe, int bound, const Limits& limits);

// The reference's bound: `requested`, else the default above. Fails (kUsage) when a requested
// bound does not exceed R's own (the light beyond R's bound could not be counted).
Result<int> reference_bound(const std::string& renderer, std::optional<int> renderer_bound,
                            std::optional<int> requested);

// What a reference is judged on: the paths of the scene's universe with at most `bound` interior
// vertices (U_s ∩ U_{≤B} above).
Dfa reference_scope(const Scene& scene, int bound);

// The shortest path of `language` within `scope` outside `reachable` (a profile's, CompiledProfile),
// or nothing when the profile samples every one (then its estimate of `language` is unbiased;
// otherwise it may miss light there).
std::optional<std::string> first_unsampled(const Dfa& reachable, const Dfa& scope, const Dfa& language);

struct BiasOptions;
// The reference for `renderer` in `scene`: `name_or_path` (a built-in name or a profile file), or
// default_reference() when it is empty. Fails (kUsage) when the tracer cannot run it.
Result<Profile> choose_reference(const std::string& name_or_path, const Scene& scene, const Profile& renderer,
                                 const BiasOptions& options);

struct BiasOptions {
  std::uint64_t spp = 16;
  std::uint64_t seed = 1;
  int threads = 0;                       // 0: all cores
  std::optional<int> renderer_bounces;   // R's bound, overriding the profile's (as query's --max-bounces)
  std::optional<int> reference_bounces;  // the reference's; default: reference_bound()
  bool images = true;                    // the total, class and missed images
  int witnesses = 3;                     // of the paths neither R nor the reference samples
  // Rows of the reference histogram's path table (the rest summed into one "other" row, as
  // `trace --max-paths`); the missed paths are listed from these rows.
  std::uint64_t max_paths = 1000;
  // Light R can sample but did not find (UnderSampling below): R rendered at `renderer_spp` passes
  // (with seed + 1, independent of the reference's) and compared with the reference, or, when
  // `renderer_histogram` is given, R's render already made (`trace --missed`: the same spp and seed).
  // Neither: no comparison.
  std::uint64_t renderer_spp = 0;
  std::optional<int> renderer_splits;  // that render's --splits; unset: the profile's (resolved_splits())
  const Histogram* renderer_histogram = nullptr;
  // The false-alarm rate of the comparison over all its checks (a correct R with an honest stderr
  // is flagged somewhere with this probability).
  double undersampled_rate = 0.01;
  // Differences smaller than this share of the light R can sample are not flagged, however
  // significant (a path of 0.1 % of the image that a short render never met).
  double undersampled_share = 0.01;
  std::function<void(std::uint64_t done, std::uint64_t total)> progress;
  const std::atomic<bool>* cancel = nullptr;
  Limits limits;
};

// A missed exact path: the reference's estimate of its light, R's verdict (always unreachable:
// only those are listed) and the checker's explanation.
struct MissedPath {
  PathEstimate estimate;
  double share = 0;                   // of the image's total
  std::vector<ChainEvidence> chains;  // with the connectors that could join each chain
  std::string reason;                 // why R does not sample it (a bound, or no join where R joins)
};

// What R misses of one class.
struct MissedClass {
  std::string name;
  std::string expr;
  Verdict verdict = Verdict::kEmpty;     // R on the class within the scene and the reference's bound
  Estimate light;                        // the class's light, as the reference finds it
  Estimate missed;                       // the part of it on paths R cannot sample
  std::optional<Witness> witness;        // the shortest path of the class R cannot sample, with why
  std::optional<Witness> neither;        // the shortest one the reference cannot sample either
};

// Light a renderer R can sample but, at its budget, did not find (issue 36): R's own estimate of a
// class (of the part of it R can sample), of the image, or of an exact path R can sample, against
// the reference's estimate of the same light, flagged where they differ by more than `sigmas`
// combined standard errors, σ = √(σ_R² + σ_ref² + (10⁻⁶ · max(|R|, |ref|))²) (the last term is
// single precision's rounding, for estimates that are exact), while R's stderr alone claimed the
// estimate was tight. A path R never sampled counts as 0 ± 0: what a stderr cannot see (a rare,
// heavy path) is exactly what this finds. Each difference is judged as Student's t with the
// Welch–Satterthwaite degrees of freedom of the two stderrs, flagged when its two-sided tail is
// below `each`, the Šidák level that makes all `comparisons` together raise a false alarm with
// probability `rate`, and when the difference is at least `min_share` of the light R can sample.
struct UnderSampled {
  std::string name;     // "total", a class name, or an exact path
  bool path = false;
  Estimate renderer;    // R's estimate
  Estimate reference;   // the reference's estimate of the light R can sample there
  double z = 0;         // (R − reference) / combined σ
  double dof = 0;       // its Welch–Satterthwaite degrees of freedom
};

struct UnderSampling {
  std::uint64_t spp = 0;         // R's passes
  std::uint64_t seed = 0;        // R's seed
  double rate = 0.01;            // the family-wise false-alarm rate
  int dof = 0;                   // the smaller of R's and the reference's (Histogram::stderr_dof())
  int comparisons = 0;           // the image, each class, each listed path R can sample
  double each = 0;               // the two-sided tail below which one comparison is flagged
  double min_share = 0.01;       // and the smallest difference flagged, as a share of the light R can sample
  double min_difference = 0;     // that share as a luminance
  double sigmas = 0;             // that level in σ at `dof` (the largest threshold any comparison has)
  std::vector<UnderSampled> flagged;  // largest |z| first
};

struct BiasReport {
  std::string scene;
  std::string renderer;
  std::optional<int> renderer_bounces;  // R's bound in force
  std::string reference;
  std::vector<std::string> reference_strategies;  // Strategy::describe() of each
  int reference_bounces = 0;
  std::uint64_t spp = 0;                // passes done
  std::uint64_t seed = 0;
  bool complete = true;
  double time_s = 0;
  std::uint64_t nonfinite_samples = 0;

  Estimate total;                       // the reference image's mean
  Estimate missed;                      // the part R cannot sample
  double share = 0;                     // missed / total luminance (0 when the total is 0)
  double share_std_error = 0;           // missed's standard error / total luminance
  // The checker proves that R samples every path of the scene's universe within the reference's
  // bound: the missed light is then exactly 0, not an estimate.
  bool covered = false;
  std::optional<Witness> shortest;      // the shortest path R cannot sample (the checker's), with why
  std::vector<MissedClass> classes;     // in class-file order
  // The missed paths among the reference histogram's max_paths largest rows, largest first, and
  // how many more missed paths it sampled (their light is the missed light minus these rows').
  std::vector<MissedPath> paths;
  std::uint64_t other_missed_paths = 0;
  // The paths neither R nor the reference can sample (within the reference's bound): the checker's
  // shortest witnesses, each with the reference's reason; empty when there are none. Their light is
  // not known, which is not 0.
  std::vector<Witness> neither;
  bool neither_finite = true;           // whether there are finitely many
  std::optional<UnderSampling> undersampled;  // with BiasOptions::renderer_spp or renderer_histogram
};

struct BiasRun {
  BiasReport report;
  RenderOutput render;           // the reference render: images layers total, the classes, then "missed"
  HistogramReport histogram;     // its histogram, with the user classes and "missed" (histogram.json), max_paths rows
};

// Renders `scene` with `reference` and measures what `renderer` misses. `classes` are the user's
// (none may be named "missed"); `scene_name` is copied into the report.
Result<BiasRun> run_bias(const Scene& scene, const std::string& scene_name, const Profile& renderer,
                         const Profile& reference, const std::vector<const PathClass*>& classes,
                         const BiasOptions& options);

// The reference for `renderer` (`reference`: a name or file, or empty for the default) and its
// render with the measurement of what `renderer` misses.
Result<BiasRun> measure_missed(const Scene& scene, const std::string& scene_name, const Profile& renderer,
                               const std::string& reference, const std::vector<const PathClass*>& classes,
                               const BiasOptions& options);

}  // namespace pathex
