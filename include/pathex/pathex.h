// pathex: the installed C++ API.
//
// What a rendering engineer's program or CI does with pathex, and nothing more:
//   1. compile a path class (a full-path regular expression such as "L.*DD.*E") and test paths;
//   2. ask whether a renderer profile can sample the class (the checker's verdict and witnesses),
//      and what a render of a scene would run (its Plan);
//   3. classify full-path strings by a set of named classes in one pass;
//   4. measure how much of a scene's light a renderer cannot sample (`pathex bias`);
//   5. run a check file, the CI gate (`pathex check`);
//   6. measure what accuracy costs in time per renderer and class (`pathex converge`);
//   7. render a scene and say where its light travels, by class and by exact path (`pathex trace`).
//
//   #include <pathex/pathex.h>
//   pathex::api::PathClass caustic("L..S+D.*..E");
//   if (!caustic.ok()) { std::cerr << caustic.error() << "\n"; return 2; }
//   pathex::api::Answer a = pathex::api::query(caustic, pathex::api::Renderer("pt-nee"));
//   // a.verdict == Verdict::kPartial, a.unreachable_witnesses.front() == "LDSDDE" …
//
// Errors are values, as in RE2: an object that could not be built has ok() == false and error()
// holds the same located message the `pathex` command prints (a caret under the expression, the
// file and JSON pointer, what was expected). Nothing here throws, prints or exits. Every object
// is an immutable value, cheap to copy and safe to share between threads.
//
// The full-path notation, the built-in names ($all, $local, $direct, $indirect, $caustic,
// $emission), the renderer profiles and the verdicts are those of the `pathex` command: see its
// README. In CMake:
//
//   find_package(pathex 0.1 REQUIRED)
//   target_link_libraries(my_tool PRIVATE pathex::pathex)
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

// The API lives in pathex::api so that it never collides with the library's internal types.
namespace pathex::api {

// "0.1.0": the version of the installed library (and of the `pathex` command built with it).
std::string_view version();

// How an expression is written: full-path letters (L, E, S, D with two letters at each end) or
// classic Heckbert strings such as "LS+DE", whose L and E stand for every light and sensor type.
enum class Notation { kFull, kHeckbert };

// A path class: an expression compiled to its minimal automaton, intersected with the valid full
// paths L[SD]{4,}E. An expression written eye-first (E…L) denotes the reversed paths.
class PathClass {
 public:
  explicit PathClass(std::string_view expression, Notation notation = Notation::kFull);

  bool ok() const;
  const std::string& error() const;  // empty when ok()

  const std::string& expression() const;  // as written
  // Whether `full_path` (such as "LDDSDE") belongs to the class; false for a malformed path and
  // for a class that is not ok().
  bool matches(std::string_view full_path) const;
  bool empty() const;       // no valid full path belongs to the class
  int dfa_states() const;   // states of the minimal DFA (complete: with its dead state)
  // The first `n` members in shortlex order (fewer letters first, then D < E < L < S), up to
  // `max_letters` letters each.
  std::vector<std::string> shortest(int n, int max_letters = 24) const;

 private:
  friend struct Access;
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

// A renderer profile: a built-in name (pt, pt-nee, lt, bdpt, pbrt-v4-path, …) or the path of a
// profile JSON file (schema grammar/profile.schema.json).
class Renderer {
 public:
  explicit Renderer(const std::string& name_or_file);

  bool ok() const;
  const std::string& error() const;
  const std::string& name() const;  // the profile's own name
  // The built-in profiles' names, in the order `pathex renderers` lists them.
  static std::vector<std::string> builtin_names();

 private:
  friend struct Access;
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

enum class Verdict {
  kEmpty,        // no valid path of the universe belongs to the class
  kReachable,    // every path of the class can be sampled by the renderer
  kPartial,      // some can, some cannot
  kUnreachable,  // none can
};
std::string_view to_string(Verdict v);  // "empty", "reachable", "partial", "unreachable"

struct QueryOptions {
  // Bounds the class (at most N interior vertices) and overrides the profile's own bound.
  std::optional<int> max_bounces;
  // A scene file: restricts the universe to its light types, sensor type and materials.
  std::string scene;
};

// The checker's answer for one class and one renderer. When !ok(), error says why (a bad scene,
// a class that is not ok(), a limit) and the other fields are empty.
struct Answer {
  Verdict verdict = Verdict::kEmpty;
  std::vector<std::string> reachable_witnesses;    // shortest paths the renderer samples
  std::vector<std::string> unreachable_witnesses;  // shortest paths it never samples
  std::string error;
  bool ok() const { return error.empty(); }
};

Answer query(const PathClass& path_class, const Renderer& renderer, const QueryOptions& options = {});

// What a render of `renderer` over the scene file `scene` runs: the plan `pathex trace` (and
// converge, bias) makes before it renders (DESIGN §11). `only` are the requested classes as
// --only takes them (expressions, or $name of a built-in class); `max_bounces` overrides the
// profile's bound (else 16).
class Plan {
 public:
  Plan(const Renderer& renderer, const std::string& scene, const std::vector<std::string>& only = {},
       std::optional<int> max_bounces = std::nullopt);

  bool ok() const;
  const std::string& error() const;
  // The strategies that run, in the profile's order, each as its name and what runs of it:
  // "name (s, chain, t)" (narrowed where pruning narrowed it).
  const std::vector<std::string>& strategies() const;
  // The scene's lights (indices into its "lights") whose emission is aimed at the shapes with a
  // specular component, because every requested path scatters specularly at its first vertex.
  const std::vector<int>& aimed_lights() const;
  // Whether the render records `full_path` (every path without `only`; false for a malformed one).
  bool records(std::string_view full_path) const;

 private:
  friend struct Access;
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

// Named classes compiled into one automaton: classifying a path is one pass over its letters.
class ClassSet {
 public:
  // The built-in classes ($local, $emission, $direct, $indirect, $caustic; $all left out).
  static ClassSet builtins();
  // A class file (schema grammar/classes.schema.json); errors name the file and JSON pointer.
  static ClassSet from_file(const std::string& filename);
  // (name, expression) pairs in order; each expression may use the built-ins and earlier names.
  static ClassSet from_expressions(const std::vector<std::pair<std::string, std::string>>& named_expressions);

  bool ok() const;
  const std::string& error() const;
  const std::vector<std::string>& names() const;
  // The names of the classes `full_path` belongs to, in the set's order (none for a malformed path).
  std::vector<std::string> classify(std::string_view full_path) const;

 private:
  ClassSet() = default;
  friend struct Access;
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

// How much of a scene's light a renderer cannot sample, as `pathex bias SCENE --renderer R`
// measures it: one render of the scene with a reference profile (by default bdpt plus the
// connectors the scene needs) whose classifier holds the paths R cannot sample (the checker's
// language), so the missed light is an estimate from the reference's own samples, with its stderr.
struct BiasOptions {
  std::uint64_t spp = 16;  // the reference's samples per pixel
  std::uint64_t seed = 1;
  int threads = 0;         // 0: all cores; the numbers do not depend on it
  std::string reference;   // a profile name or file; empty: the default reference
};

struct BiasAnswer {
  std::string reference;        // the reference's name, e.g. "bdpt+mirror+manifold"
  double total = 0;             // the image's mean luminance, as the reference finds it
  double missed = 0;            // the part on paths the renderer cannot sample
  double share = 0;             // missed / total (0 when the total is 0)
  double share_stderr = 0;      // its standard error
  // The checker proves that the renderer samples every path of the scene within the reference's
  // bound: share is then exactly 0, not an estimate.
  bool exact = false;
  std::string shortest_missed;  // the shortest path the renderer cannot sample; empty: none
  std::string error;            // why there is no answer (a bad scene, renderer or reference)
  bool ok() const { return error.empty(); }
};

BiasAnswer bias(const std::string& scene_file, const Renderer& renderer, const BiasOptions& options = {});

// A check file (`pathex check FILE`, schema grammar/check.schema.json): every requirement of every
// case decided exactly, in the file's order.
struct CheckOutcome {
  std::string case_name;       // the case's "name"
  std::string requirement;     // as the command prints it: "LSDSDE is unreachable"
  bool passed = false;
  std::string found;           // the verdict or measure found: "reachable", "0.00 % ± 0.00 % of what bdpt finds"
  std::string counterexample;  // for a failure, the shortest path that shows it (may be empty)
};

struct CheckAnswer {
  std::vector<CheckOutcome> outcomes;
  std::string error;  // the check file could not be run: the command's located message
  bool ok() const { return error.empty(); }
  bool passed() const;  // ok() and every outcome passed
};

CheckAnswer check(const std::string& check_file);

// What accuracy costs in time, as `pathex converge SCENE --renderer R1 --renderer R2 …` measures
// it: every renderer renders the scene at every rung of a ladder of samples per pixel (rung i of
// renderer k with seed + 1000 k + i), and each rung's estimate per class is compared with a
// reference: the scene's closed form, an earlier run's histogram.json or EXR, or a reference run
// made with `reference_renderer` (by default bdpt plus the connectors the scene needs) at
// `reference_factor` times the last rung. The numbers are the command's, bit for bit (its
// converge.json); only the times differ between runs. Ctrl-C (SIGINT) and SIGTERM are caught while
// the call renders: they end the rung in progress and the answer holds the finished rungs.
struct ConvergeOptions {
  std::vector<std::uint64_t> spp = {4, 16, 64, 256};  // the ladder, increasing
  std::uint64_t seed = 1;
  int threads = 0;                     // 0: all cores; the numbers do not depend on it
  std::optional<int> max_bounces;      // unset: each profile's own bound, else 16
  std::string classes_file;            // empty: the scene's closed-form classes, else the built-ins
  std::vector<std::string> only;       // the requested classes (expressions or $name), as --only
  std::string reference;               // an earlier run's histogram.json or EXR; empty: see above
  std::string reference_renderer;      // a profile name or file; empty: the default
  std::uint64_t reference_factor = 4;
  // A folder to write converge.json, converge.svg and converge.png into (with reference.json and
  // reference.exr after a reference run), as one set; empty: nothing is written.
  std::string out;
};

struct ConvergeRung {
  std::uint64_t spp = 0;
  double cpu_s = 0;                  // rendering CPU seconds, all threads
  double estimate = 0;               // the class's mean luminance over the image
  double std_error = 0;              // its reported standard error
  std::optional<double> error;       // estimate − reference (none without a reference, or not finite)
  std::optional<double> z;           // error / std_error (none when not finite)
};

struct ConvergeSeries {
  std::string renderer;
  std::vector<ConvergeRung> rungs;
  double slope = 0;                  // of log |error| against log CPU time (−0.5 for 1/sqrt(t)); NaN: none
  double efficiency = 0;             // 1 / mean(error² × CPU s) over the ladder; NaN: none
  std::string cannot_sample;         // a path of the class it cannot sample (then it is not ranked)
  std::string warning;               // the reported stderr does not tell the truth, when not empty
};

struct ConvergeClass {
  std::string name;                  // "total" (or "requested" with `only`), then each class
  std::string expression;
  std::optional<double> reference;   // none: no error is measured on this class
  std::vector<ConvergeSeries> renderers;  // in the order given
  std::string best;                  // the most efficient renderer; empty: none ranked
};

struct ConvergeAnswer {
  std::string reference_kind;        // "closed-form", "file" or "run"
  std::string reference_source;
  std::vector<ConvergeClass> classes;
  std::vector<std::string> warnings;
  bool complete = true;              // false: interrupted, the finished rungs only
  std::string error;                 // why there is no answer: the command's located message
  bool ok() const { return error.empty(); }
};

ConvergeAnswer converge(const std::string& scene_file, const std::vector<Renderer>& renderers,
                        const ConvergeOptions& options = {});

// A render of a scene, as `pathex trace SCENE --renderer R` makes it: every sampled path labelled
// with its full-path string, and the image's mean luminance split by class and by exact path, each
// with its standard error. The numbers are those of the command's histogram.json, bit for bit.
struct TraceOptions {
  std::uint64_t spp = 16;
  std::uint64_t seed = 1;
  int threads = 0;                 // 0: all cores; the numbers do not depend on it
  std::optional<int> max_bounces;  // unset: the profile's own bound, else 16
  std::string classes_file;        // empty: the built-in classes
  std::vector<std::string> only;   // the requested classes (expressions or $name), as --only
  std::uint64_t max_paths = 1000;  // exact paths listed, largest first (the rest are summed in "other")
  // A folder to write the render into (histogram.json, run.json, classes.exr, the PNGs and
  // render.shard) as one set, whole or not at all; empty: nothing is written.
  std::string out;
};

struct TraceEstimate {
  std::string name;         // a class's name, or an exact path ("LDDE"); "other" for the paths past max_paths
  std::string expression;   // a class's expression (empty for a path)
  double luminance = 0;     // mean luminance over the image
  double std_error = 0;     // its standard error (NaN with fewer than two batches)
  double share = 0;         // of the total (0 when the total is 0)
  bool rendered = true;     // false: a class `only` left out, whose estimate is unknown (never 0)
};

struct TraceAnswer {
  std::string renderer;                 // the profile's name
  std::uint64_t spp = 0;                // samples per pixel rendered
  TraceEstimate total;                  // the image (with `only`, the requested classes' paths)
  std::vector<TraceEstimate> classes;   // in the class set's order
  std::vector<TraceEstimate> paths;     // largest first, then "other" when paths were left out
  std::uint64_t distinct_paths = 0;     // every path sampled
  std::uint64_t nonfinite_samples = 0;  // dropped; any is a bug
  double cpu_s = 0;                     // rendering CPU seconds, all threads
  bool complete = true;                 // false: interrupted (Ctrl-C, SIGTERM), the passes rendered only
  std::string error;                    // why there is no answer: the command's located message
  bool ok() const { return error.empty(); }
};

// An empty `scene_file` renders the embedded default scene (the Cornell box of `pathex trace`).
TraceAnswer trace(const std::string& scene_file, const Renderer& renderer, const TraceOptions& options = {});

}  // namespace pathex::api
