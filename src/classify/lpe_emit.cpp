#include "classify/lpe_emit.h"

#include "automata/nfa.h"
#include "automata/ops.h"
#include "automata/to_regex.h"
#include "classify/pathclass.h"

namespace pathex {
namespace {

constexpr int kMaxEmitStates = 2000;
constexpr int kMaxEmitNodes = 100000;

// pathex D is a diffuse or glossy event, S a singular one; R and T are both allowed.
std::string lpe_atom(LetterMask m) {
  const bool d = m & (1u << kD), s = m & (1u << kS);
  if (d && s) return "[DGS]";
  if (d) return "[DG]";
  if (s) return "S";
  return "";  // the interior language has no other letters
}

// The interiors the class allows with some light and sensor pair, read camera first: an NFA on the
// class's DFA with its D and S edges reversed, entered at the states from which a sensor pair and
// E accept, and left at the states a light pair leads to.
Nfa camera_first_interiors(const Dfa& d) {
  Nfa n;
  const int states = d.num_states;
  n.states.resize(static_cast<std::size_t>(states + 2));
  n.start = states;
  n.accept = states + 1;
  for (int q = 0; q < states; ++q)
    for (Letter l : {kD, kS}) n.states[static_cast<std::size_t>(d.step(q, l))].edges.push_back({static_cast<LetterMask>(1u << l), q});
  for (int p = 0; p < states; ++p) {
    bool sensor_end = false;
    for (SensorType t : kAllSensorTypes) {
      const std::string s = sensor_letters(t);
      const int e = d.step(d.step(d.step(p, *letter_from_char(s[0])), *letter_from_char(s[1])), kE);
      sensor_end = sensor_end || d.accept[static_cast<std::size_t>(e)];
    }
    if (sensor_end) n.states[static_cast<std::size_t>(n.start)].eps.push_back(p);
  }
  for (LightType t : kAllLightTypes) {
    const std::string s = light_letters(t);
    const int e = d.step(d.step(d.step(d.start, kL), *letter_from_char(s[0])), *letter_from_char(s[1]));
    n.states[static_cast<std::size_t>(e)].eps.push_back(n.accept);
  }
  return n;
}

Dfa full_class(const std::string& expr) {
  Result<PathClass> c = compile_class(expr, ClassOptions{});
  return c ? c->dfa : dfa_empty();  // the expressions are constants of this file
}

std::string join(const std::vector<std::string>& words) {
  std::string s;
  for (std::size_t i = 0; i < words.size(); ++i) s += (i == 0 ? "" : i + 1 == words.size() ? " and " : ", ") + words[i];
  return s;
}

}  // namespace

Result<LpeEmission> emit_lpe(const Dfa& cls, const Limits& limits) {
  LpeEmission out;
  if (is_empty(cls)) {
    out.empty = true;
    return out;
  }
  // --- which light and sensor types the class has ---
  EndTypes used;
  used.lights.clear();
  used.sensors.clear();
  std::vector<std::string> light_names, sensor_names;
  for (LightType t : kAllLightTypes)
    if (!is_empty(dfa_intersect(cls, full_class("L" + light_letters(t) + "[SD]*E")))) {
      used.lights.push_back(t);
      light_names.push_back(to_string(t));
    }
  for (SensorType t : kAllSensorTypes)
    if (!is_empty(dfa_intersect(cls, full_class("L[SD]*" + sensor_letters(t) + "E")))) {
      used.sensors.push_back(t);
      sensor_names.push_back(to_string(t));
    }

  // --- the LPE: C, the interiors camera first, the light ---
  Result<Dfa> interiors = determinize(camera_first_interiors(cls), limits);
  if (!interiors) return interiors.error();
  Result<Expr> x = dfa_to_expr(minimize(*interiors), kMaxEmitStates, kMaxEmitNodes);
  if (!x) return x.error();
  ExprStyle style;
  style.atom = lpe_atom;
  style.alternation_binds_items = true;  // OSL's '|' joins the items beside it
  style.optional = "{0,1}";              // OSL has no '?'
  style.min_run = 3;
  bool area = false;
  for (LightType t : used.lights) area = area || t == LightType::kArea;
  out.lpe = "C" + print_expr(*x, style) + (area ? "[LO]" : "L");

  // --- read it back, as a user would ---
  ClassOptions back;
  back.notation = Notation::kLpe;
  back.limits = limits;
  Result<PathClass> t = compile_class(out.lpe, back);
  if (!t) return t.error();
  out.exact = t->dfa == cls;
  if (out.exact) return out;
  if (!is_subset(cls, t->dfa))
    return make_error(ErrorCode::kBadValue, "internal error: the LPE " + out.lpe + " does not contain the class");
  out.example = shortest_member(dfa_difference(t->dfa, cls));
  if (used.lights.size() < kAllLightTypes.size())
    out.losses.push_back("light types: the class has only " + join(light_names) + " lights; an LPE's L is every light");
  if (used.sensors.size() < kAllSensorTypes.size())
    out.losses.push_back("sensor types: the class has only " + join(sensor_names) + " sensors; an LPE's C is every sensor");
  if (dfa_intersect(t->dfa, ends_universe(used)) != cls)
    out.losses.push_back("the class ties its interior letters to particular light or sensor types; an LPE cannot");
  return out;
}

}  // namespace pathex
