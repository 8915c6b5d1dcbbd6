#include "cli/common.h"

#include <iostream>

#include "classify/notation_hint.h"
#include "io/class_file.h"

namespace pathex::cli {

void add_limit_options(CLI::App* app, Limits* limits) {
  app->add_option("--max-states", limits->max_states, "Largest automaton (NFA or DFA states) to build")
      ->capture_default_str()->group("Limits");
  app->add_option("--max-depth", limits->max_depth, "Deepest nesting of groups and operators")
      ->capture_default_str()->group("Limits");
  app->add_option("--max-repeat", limits->max_repeat, "Largest count in {n}, {n,} and {n,m}")
      ->capture_default_str()->group("Limits");
  app->add_option("--max-length", limits->max_length, "Longest full-path string accepted as input")
      ->capture_default_str()->group("Limits");
}

void add_notation_options(CLI::App* app, NotationOptions* n) {
  app->add_option("--notation", n->notation,
                  "full (L c0 c1 … E), heckbert (L w E, one letter per interior vertex) or lpe (OSL light path "
                  "expression, camera first: C<RD>L)")
      ->check(CLI::IsMember({"full", "heckbert", "lpe"}))->capture_default_str();
  app->add_option("--light", n->lights, "Light types for Heckbert and LPE notation: area, distant, point, laser (default all)")
      ->delimiter(',')->allow_extra_args(false);
  app->add_option("--sensor", n->sensors,
                  "Sensor types for Heckbert and LPE notation: lens, pinhole, orthographic, spotmeter (default all)")
      ->delimiter(',')->allow_extra_args(false);
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

int report(const Error& e) {
  std::cerr << "pathex: error: " << e.render() << "\n";
  return kExitBadInput;
}

}  // namespace pathex::cli
