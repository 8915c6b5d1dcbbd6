#include "cli/common.h"

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <sstream>

#include "language/notation_hint.h"
#include "io/class_file.h"

namespace pathex::cli {

CLI::Validator auto_or(std::string sentinel, std::function<bool(const std::string&)> accepts, std::string expected, std::string name) {
  return CLI::Validator(
      [sentinel = std::move(sentinel), accepts = std::move(accepts), expected = std::move(expected)](std::string& value) -> std::string {
        if (value == "auto") {
          value = sentinel;
          return "";
        }
        return accepts(value) ? "" : "expected auto or " + expected + ", got '" + value + "'";
      },
      /*validator_desc=*/"", std::move(name));
}

const CLI::Validator& non_negative() {
  static const CLI::Validator v(
      [](std::string& value) -> std::string {
        const std::size_t first = value.find_first_not_of(" \t");
        if (first != std::string::npos && value[first] == '-')
          return "expected a non-negative integer, got '" + value + "'";
        return "";
      },
      /*validator_desc=*/"", /*validator_name=*/"non-negative");
  return v;
}

namespace {

// A finite number in the interval from lo to hi, each end included or not; CLI11's Range lets NaN
// through (every comparison with it is false).
CLI::Validator real_in(double lo, bool lo_open, double hi, bool hi_open) {
  std::ostringstream range;
  range << (lo_open ? "(" : "[") << lo << ", " << hi << (hi_open ? ")" : "]");
  const std::string text = range.str();
  return CLI::Validator(
      [=](std::string& value) -> std::string {
        std::istringstream in(value);
        double x = 0;
        in >> x;
        const bool whole = !in.fail() && (in >> std::ws).eof();
        if (whole && std::isfinite(x) && (lo_open ? x > lo : x >= lo) && (hi_open ? x < hi : x <= hi)) return "";
        return "expected a number in " + text + ", got '" + value + "'";
      },
      /*validator_desc=*/"FLOAT in " + text, /*validator_name=*/"real in " + text);
}

}  // namespace

void add_manifold_options(CLI::App* app, ManifoldOptions* o) {
  const std::vector<std::string>& name = manifold_option_names();
  const char* group = "Manifold connector";
  app->add_option(name[0], o->max_iterations, "Newton iterations of one walk before it fails (iteration_limit)")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(1, 10000))->group(group);
  app->add_option(name[1], o->threshold, "Largest constraint (tangential generalized half vector) of a solved chain, which must then polish to a root (a near miss past a fold is no chain)")
      ->capture_default_str()->check(real_in(0, true, 1, true))->group(group);
  app->add_option(name[2], o->min_segment,
                  "Shortest segment of a solution, as a fraction of the scene's bounding-box diagonal (too_short)")
      ->capture_default_str()->check(real_in(0, false, 1, true))->group(group);
  app->add_option(name[3], o->singular, "Smallest |pivot| / largest |pivot| of the constraint Jacobian (singular)")
      ->capture_default_str()->check(real_in(0, false, 1, true))->group(group);
  app->add_option(name[4], o->max_trials,
                  "Seeds spent finding a join's chains again, their inverse-probability estimate (a cap: a chain not found again by then is counted as truncated)")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(1, 100000))->group(group);
  app->add_option(name[5], o->seeds,
                  "Seeds per batch: the first batch's distinct chains are a join's contributions; default: 1 if the "
                  "profile has a plain strategy with s >= 2 (light tracing or bdpt's joins), else 4")
      ->check(non_negative())->check(CLI::Range(1, 64))->group(group);
  app->add_option(name[6], o->biased_trials,
                  "BIASED when > 0: a join draws this many seeds and counts each distinct chain they find once, "
                  "no inverse-probability estimate (Zeltner et al. 2020's fixed trials); 0: the unbiased estimator")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(0, 100000))->group(group);
  app->add_option(name[7], o->rate,
                  "Share of the eye subpaths whose joins run the connector (a coin per sample; unbiased: the contribution "
                  "is divided by it and MIS weighs the connector by it) where another strategy samples the path too: in a "
                  "profile with light subpaths (light tracing, bdpt's joins), where the camera sees the join's eye end "
                  "directly or past a diffuse vertex; in one without (pt-nee+manifold), where the light end is not a point "
                  "(an eye path can hit the light), also through glass; elsewhere every sample runs it; default 0.125")
      ->check(real_in(0, true, 1, false))->group(group);
}

const std::vector<std::string>& manifold_option_names() {
  static const std::vector<std::string> names = {"--manifold-iterations", "--manifold-threshold", "--manifold-min-segment",
                                                 "--manifold-singular", "--manifold-trials",
                                                 "--manifold-seeds", "--manifold-biased-trials", "--manifold-rate"};
  return names;
}

void add_limit_options(CLI::App* app, Limits* limits) {
  // Each limit has a floor of 1 (0 for none would refuse everything) and the ceiling the engine
  // provably survives (core/limits.h); a negative value is refused, never wrapped around.
  app->add_option("--max-states", limits->max_states, "Largest automaton (NFA or DFA states) to build")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxStatesCeiling))->group("Limits");
  app->add_option("--max-depth", limits->max_depth, "Deepest nesting of groups and operators")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(1, kMaxDepthCeiling))->group("Limits");
  app->add_option("--max-repeat", limits->max_repeat, "Largest count in {n}, {n,} and {n,m}")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(1, kMaxRepeatCeiling))->group("Limits");
  app->add_option("--max-length", limits->max_length, "Longest full-path string accepted as input")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxLengthCeiling))->group("Limits");
  app->add_option("--max-work", limits->max_work,
                  "Work budget of one operation: automaton states built, subset elements, counting cells")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxWorkCeiling))->group("Limits");
  app->add_option("--max-file-size", limits->max_file_bytes, "Largest input file read (class, profile, check, scene, mesh), bytes")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxFileBytesCeiling))->group("Limits");
}

void add_scene_limit_options(CLI::App* app, Limits* limits) {
  app->add_option("--max-scene-size", limits->max_scene_bytes, "Largest scene text read, the files it includes counted in, bytes")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxSceneBytesCeiling))->group("Limits");
  app->add_option("--max-scene-depth", limits->max_scene_depth, "Deepest nesting of a scene's materials (Mitsuba's nested BSDFs)")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(1, kMaxSceneDepthCeiling))->group("Limits");
  app->add_option("--max-material-nodes", limits->max_material_nodes,
                  "Most material components an imported scene's materials expand to (mixtures of mixtures flattened), summed")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxMaterialNodesCeiling))->group("Limits");
  app->add_option("--max-mesh-elements", limits->max_mesh_elements, "Most vertices plus triangles of a scene's meshes, summed")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxMeshElementsCeiling))->group("Limits");
  app->add_option("--max-texels", limits->max_texels, "Most pixels of a scene's images (textures, environment maps), summed")
      ->capture_default_str()->check(non_negative())->check(CLI::Range(std::size_t{1}, kMaxTexelsCeiling))->group("Limits");
}

void add_notation_options(CLI::App* app, NotationOptions* n) {
  app->add_option("--notation", n->notation,
                  "full (L c0 c1 … E), heckbert (L w E, one letter per interior vertex) or lpe (OSL light path "
                  "expression, camera first: C<RD>L)")
      ->check(CLI::IsMember({"full", "heckbert", "lpe"}))->capture_default_str();
  // The type names list the choices ("LIST:{area,distant,point,laser}"): --help shows them and
  // the generated bash completion offers them.
  std::string lights, sensors;
  for (LightType t : kAllLightTypes) lights += (lights.empty() ? "" : ",") + to_string(t);
  for (SensorType t : kAllSensorTypes) sensors += (sensors.empty() ? "" : ",") + to_string(t);
  app->add_option("--light", n->lights, "Light types for Heckbert and LPE notation, one comma-separated list (default all)")
      ->delimiter(',')->allow_extra_args(false)->type_name("LIST:{" + lights + "}");
  app->add_option("--sensor", n->sensors, "Sensor types for Heckbert and LPE notation, one comma-separated list (default all)")
      ->delimiter(',')->allow_extra_args(false)->type_name("LIST:{" + sensors + "}");
}

std::optional<std::string> misused_list_option(int argc, char** argv) {
  for (int i = 1; i + 2 < argc; ++i) {
    const std::string option = argv[i], next = argv[i + 2];
    const bool light = option == "--light" && light_type_from_string(next);
    const bool sensor = option == "--sensor" && sensor_type_from_string(next);
    if (light || sensor)
      return option + " takes one comma-separated list, such as " + option + " " + argv[i + 1] + "," + next +
             "; '" + next + "' after it would be read as an expression";
  }
  return std::nullopt;
}

Result<ClassOptions> class_options(const NotationOptions& n, const Limits& limits) {
  ClassOptions o;
  o.limits = limits;
  o.notation = notation_from_string(n.notation).value_or(Notation::kFull);
  if (!n.lights.empty()) {
    o.ends.lights.clear();
    for (const std::string& s : n.lights) {
      auto t = light_type_from_string(s);
      if (!t) return make_error(ErrorCode::kUsage, "--light: unknown light type '" + s + "', expected area, distant, point or laser");
      o.ends.lights.push_back(*t);
    }
  }
  if (!n.sensors.empty()) {
    o.ends.sensors.clear();
    for (const std::string& s : n.sensors) {
      auto t = sensor_type_from_string(s);
      if (!t)
        return make_error(ErrorCode::kUsage,
                          "--sensor: unknown sensor type '" + s + "', expected lens, pinhole, orthographic or spotmeter");
      o.ends.sensors.push_back(*t);
    }
  }
  if ((!n.lights.empty() || !n.sensors.empty()) && o.notation == Notation::kFull)
    return make_error(ErrorCode::kUsage, "--light and --sensor apply to --notation heckbert and lpe only");
  return o;
}

Result<PathClass> compile_cli_expression(const std::string& expr, const NotationOptions& n, const Limits& limits,
                                         const std::string& classes_file, ClassTable* table) {
  Result<ClassOptions> opts = class_options(n, limits);
  if (!opts) return opts.error();
  if (!classes_file.empty()) {
    Result<bool> r = read_class_file(classes_file, *opts, table);
    if (!r) return r.error();
  }
  Result<PathClass> pc = compile_class(expr, *opts, table);
  if (pc) print_notation_hint(expr, *pc, *opts, table);
  return pc;
}

void print_notation_hint(const std::string& expr, const PathClass& pc, const ClassOptions& options,
                         const ClassTable* table) {
  if (std::optional<std::string> h = heckbert_hint(expr, pc, options, table)) std::cerr << "pathex: hint: " << *h << "\n";
}

namespace {
std::atomic<bool> fast_exit_allowed{false};

// Under AddressSanitizer the process must return from main: LeakSanitizer runs its check from an
// atexit handler, which _Exit skips, so CI's sanitizer stage would never see a leak of `pathex
// trace`. GCC defines __SANITIZE_ADDRESS__; clang reports it through __has_feature.
#if defined(__SANITIZE_ADDRESS__)
constexpr bool kAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool kAddressSanitizer = true;
#else
constexpr bool kAddressSanitizer = false;
#endif
#else
constexpr bool kAddressSanitizer = false;
#endif
}  // namespace

void allow_fast_exit() { fast_exit_allowed.store(true); }

int finish_command(int code) {
  if (kAddressSanitizer || !fast_exit_allowed.load()) return code;
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::_Exit(code);
}

int report(const Error& e) {
  std::cerr << "pathex: error: " << e.render() << "\n";
  return kExitBadInput;
}

}  // namespace pathex::cli
