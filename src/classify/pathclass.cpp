#include "classify/pathclass.h"

#include <cctype>

#include "automata/ops.h"
#include "core/budget.h"
#include "regex/lpe.h"
#include "regex/parser.h"

namespace pathex {
namespace {

struct BuiltinDef {
  const char* name;
  const char* expr;
  const char* description;
};

// The built-in names. Each is a full-notation expression; the comment is what `explain` shows.
constexpr BuiltinDef kBuiltins[] = {
    {"all", "L[SD]{4,}E", "every valid full path: the universe U"},
    {"local", "L.*DD.*E",
     "paths that local path sampling can reach: some join DD exists (Veach 8.3.3)"},
    {"emission", "L....E", "classic LE: the light seen directly, no interior vertex (k = 1)"},
    {"direct", "L.....E", "classic L.E: exactly one interior vertex (k = 2)"},
    {"indirect", "L......+E", "classic L..+E: two or more interior vertices (k >= 3)"},
    {"caustic", "L..S+D.*..E",
     "classic LS+D.*E: light reaches a diffuse vertex through one or more specular vertices"},
};

Error with_source(Error e, std::string_view text) {
  if (e.source.empty()) e.source = std::string(text);
  return e;
}

// E then anything: the shape of every member of an eye-first expression.
const Dfa& starts_with_e() {
  static const Dfa d = [] {
    ExemptFromBudget exempt;
    Dfa x;
    x.num_states = 3;  // 0 start, 1 after E (accepting, absorbing), 2 dead
    x.next = {2, 1, 2, 2, 1, 1, 1, 1, 2, 2, 2, 2};
    x.accept = {0, 1, 0};
    return minimize(x);
  }();
  return d;
}

// Classic L[SD]*E.
const Dfa& classic_universe() {
  static const Dfa d = [] {
    ExemptFromBudget exempt;
    Dfa x;
    x.num_states = 4;  // 0 start, 1 after L (loops on S D), 2 accept, 3 dead
    x.next.assign(16, 3);
    x.accept = {0, 0, 1, 0};
    x.next[0 * 4 + kL] = 1;
    x.next[1 * 4 + kS] = 1;
    x.next[1 * 4 + kD] = 1;
    x.next[1 * 4 + kE] = 2;
    return minimize(x);
  }();
  return d;
}

// Heckbert -> full: restrict to classic strings, then substitute L by L + light pair and E by
// sensor pair + E (a homomorphism, applied on the automaton so that complements stay correct).
Result<Dfa> expand_ends(const Dfa& classic, const EndTypes& ends, const Limits& limits) {
  std::vector<std::string> lw, sw;
  for (LightType t : ends.lights) lw.push_back("L" + light_letters(t));
  for (SensorType t : ends.sensors) sw.push_back(sensor_letters(t) + "E");
  Result<Dfa> a = determinize(substituted_nfa(dfa_intersect(classic, classic_universe()), kL, lw), limits);
  if (!a) return a.error();
  Result<Dfa> b = determinize(substituted_nfa(minimize(*a), kE, sw), limits);
  if (!b) return b.error();
  return minimize(*b);
}

}  // namespace

std::optional<Notation> notation_from_string(std::string_view s) {
  if (s == "full") return Notation::kFull;
  if (s == "heckbert") return Notation::kHeckbert;
  if (s == "lpe") return Notation::kLpe;
  return std::nullopt;
}

std::string to_string(Notation n) {
  switch (n) {
    case Notation::kFull: return "full";
    case Notation::kHeckbert: return "heckbert";
    case Notation::kLpe: return "lpe";
  }
  return "full";
}

Dfa ends_universe(const EndTypes& ends) {
  ExemptFromBudget exempt;
  return expand_ends(classic_universe(), ends, Limits{}).expect("L[SD]*E expands under the default limits");
}

Result<PathClass> compile_class_unbudgeted(std::string_view text, const ClassOptions& options, const ClassTable* names);

namespace {

// An LPE is read into an eye-first full-notation tree whose C and L already stand for the sensor
// and light types: compile it, reverse it, intersect with the universe. No names, no guessing of
// the direction (an LPE that starts with '.' is still camera-first).
Result<PathClass> compile_lpe(std::string_view text, const ClassOptions& options) {
  Result<Regex> ast = parse_lpe(text, options.ends.lights, options.ends.sensors, options.limits);
  if (!ast) return ast.error();
  Result<Dfa> raw = compile(*ast, options.limits);
  if (!raw) return with_source(raw.error(), text);
  Result<Dfa> rev = dfa_reverse(*raw, options.limits);
  if (!rev) return with_source(rev.error(), text);
  PathClass pc;
  pc.text = std::string(text);
  pc.notation = Notation::kLpe;
  pc.eye_first = true;
  pc.dfa = dfa_intersect(*rev, dfa_universe());
  pc.light_ast = reversed(*ast);
  pc.ast = std::move(*ast);
  return pc;
}

}  // namespace

Result<PathClass> compile_class(std::string_view text, const ClassOptions& options, const ClassTable* names) {
  Result<PathClass> c = within_budget(options.limits, [&] { return compile_class_unbudgeted(text, options, names); });
  if (!c && c.error().source.empty()) {
    Error e = with_source(c.error(), text);
    e.column = 1;
    return e;
  }
  return c;
}

Result<PathClass> compile_class_unbudgeted(std::string_view text, const ClassOptions& options, const ClassTable* names) {
  if (options.notation == Notation::kLpe) return compile_lpe(text, options);
  const ClassTable& table = names ? *names : ClassTable::builtins();
  Error notation_error;
  bool notation_mismatch = false;
  std::string mismatched_name;
  NameLookup lookup = [&](std::string_view name) -> const Regex* {
    const PathClass* c = table.find(name);
    if (!c) return nullptr;
    // An LPE class's tree is full notation (its ends are expanded already).
    const Notation tree = c->notation == Notation::kHeckbert ? Notation::kHeckbert : Notation::kFull;
    if (tree != options.notation && !notation_mismatch) {
      notation_mismatch = true;
      mismatched_name = "$" + std::string(name);
      notation_error.message = "'$" + std::string(name) + "' is written in " +
                               (tree == Notation::kFull ? "full" : "Heckbert") +
                               " notation and cannot be used in a " +
                               (options.notation == Notation::kFull ? "full" : "Heckbert") + "-notation expression";
    }
    return &c->light_ast;
  };
  Result<Regex> ast = parse(text, options.limits, lookup);
  if (!ast) return ast.error();
  if (notation_mismatch) {
    // Point at the first reference to the name in the other notation: "$name" not followed by
    // another name character (so "$a" is not found inside "$ab").
    std::size_t at = text.find(mismatched_name);
    while (at != std::string_view::npos) {
      const std::size_t end = at + mismatched_name.size();
      const bool name_goes_on = end < text.size() && (std::isalnum(static_cast<unsigned char>(text[end])) ||
                                                      text[end] == '_' || text[end] == '-');
      if (!name_goes_on) break;
      at = text.find(mismatched_name, at + 1);
    }
    Error e = make_error(ErrorCode::kUnknownName, notation_error.message);
    e.source = std::string(text);
    e.column = static_cast<int>(at == std::string_view::npos ? text.find('$') : at) + 1;
    return e;
  }
  Result<Dfa> raw = compile(*ast, options.limits);
  if (!raw) return with_source(raw.error(), text);

  PathClass pc;
  pc.text = std::string(text);
  pc.notation = options.notation;
  Dfa lang = std::move(*raw);
  // Eye-first: every member starts with E (E…L, as LPEs are written); the class is the reversal.
  if (!is_empty(lang) && is_subset(lang, starts_with_e())) {
    Result<Dfa> rev = dfa_reverse(lang, options.limits);
    if (!rev) return with_source(rev.error(), text);
    lang = std::move(*rev);
    pc.eye_first = true;
  }
  if (options.notation == Notation::kHeckbert) {
    Result<Dfa> full = expand_ends(lang, options.ends, options.limits);
    if (!full) return with_source(full.error(), text);
    lang = std::move(*full);
  }
  pc.dfa = dfa_intersect(lang, dfa_universe());
  pc.light_ast = pc.eye_first ? reversed(*ast) : *ast;
  pc.ast = std::move(*ast);
  return pc;
}

ClassTable::ClassTable() = default;

ClassTable::ClassTable(BuiltinTag) : is_builtin_table_(true) {
  ExemptFromBudget exempt;  // built on first use, by whichever operation comes first
  ClassOptions options;
  for (const BuiltinDef& b : kBuiltins) {
    // The built-in expressions are constants of this file; tests compile each of them.
    auto pc = std::make_unique<PathClass>(compile_class(b.expr, options, this).expect("a built-in class compiles"));
    pc->name = b.name;
    pc->description = b.description;
    builtin_.push_back(std::move(pc));
  }
}

const ClassTable& ClassTable::builtins() {
  static const ClassTable table{BuiltinTag{}};
  return table;
}

const PathClass* ClassTable::find(std::string_view name) const {
  for (const auto& c : user_)
    if (c->name == name) return c.get();
  for (const auto& c : builtin_)
    if (c->name == name) return c.get();
  if (!is_builtin_table_) return builtins().find(name);
  return nullptr;
}

Result<const PathClass*> ClassTable::add(const std::string& name, std::string_view text, const ClassOptions& options,
                                         std::string description) {
  if (find(name)) return make_error(ErrorCode::kBadValue, "class name '" + name + "' is already defined");
  Result<PathClass> c = compile_class(text, options, this);
  if (!c) return c.error();
  auto pc = std::make_unique<PathClass>(std::move(*c));
  pc->name = name;
  pc->description = std::move(description);
  user_.push_back(std::move(pc));
  return static_cast<const PathClass*>(user_.back().get());
}

void ClassTable::set_render(const PathClass* c, bool render) {
  for (auto& u : user_)
    if (u.get() == c) u->render = render;
}

}  // namespace pathex
