#include "language/lpe_emit.h"

#include <algorithm>

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

// The interiors w that the class allows between one of `lights` and one of `sensors` (the paths
// L l0 l1 w s0 s1 E), as an NFA on the class's DFA: light first, or camera first with its D and S
// edges reversed.
Nfa interiors(const Dfa& d, const std::vector<LightType>& lights, const std::vector<SensorType>& sensors,
              bool camera_first) {
  Nfa n;
  const int states = d.num_states;
  n.states.resize(static_cast<std::size_t>(states + 2));
  const int light_side = states, sensor_side = states + 1;
  for (int q = 0; q < states; ++q)
    for (Letter l : {kD, kS}) {
      const int r = d.step(q, l);
      if (camera_first) n.states[static_cast<std::size_t>(r)].edges.push_back({static_cast<LetterMask>(1u << l), q});
      else n.states[static_cast<std::size_t>(q)].edges.push_back({static_cast<LetterMask>(1u << l), r});
    }
  auto eps = [&](int from, int to) { n.states[static_cast<std::size_t>(from)].eps.push_back(to); };
  for (int p = 0; p < states; ++p) {
    bool sensor_end = false;
    for (SensorType t : sensors) {
      const std::string s = sensor_letters(t);
      const int e = d.step(d.step(d.step(p, *letter_from_char(s[0])), *letter_from_char(s[1])), kE);
      sensor_end = sensor_end || d.accept[static_cast<std::size_t>(e)];
    }
    if (sensor_end) camera_first ? eps(sensor_side, p) : eps(p, sensor_side);
  }
  for (LightType t : lights) {
    const std::string s = light_letters(t);
    const int e = d.step(d.step(d.step(d.start, kL), *letter_from_char(s[0])), *letter_from_char(s[1]));
    camera_first ? eps(e, light_side) : eps(light_side, e);
  }
  n.start = camera_first ? sensor_side : light_side;
  n.accept = camera_first ? light_side : sensor_side;
  return n;
}

Dfa full_class(const std::string& expr) {
  Result<PathClass> c = compile_class(expr, ClassOptions{});
  return c ? c->dfa : dfa_empty();  // the expressions are constants of this file
}

// Two-letter words as an expression: a product of letter sets as two sets (`..`, `S.`), else an
// alternation in parentheses.
std::string pairs_text(const std::vector<std::string>& words) {
  LetterMask first = 0, second = 0;
  for (const std::string& w : words) {
    first |= static_cast<LetterMask>(1u << *letter_from_char(w[0]));
    second |= static_cast<LetterMask>(1u << *letter_from_char(w[1]));
  }
  auto set = [](LetterMask m) {
    Expr e;
    e.kind = Expr::Kind::kSet;
    e.mask = m;
    return to_full_notation(e);
  };
  if (static_cast<std::size_t>(__builtin_popcount(first) * __builtin_popcount(second)) == words.size())
    return set(first) + set(second);
  std::string s = "(";
  for (std::size_t i = 0; i < words.size(); ++i) s += (i ? "|" : "") + words[i];
  return s + ")";
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
  Result<Dfa> inner = determinize(
      interiors(cls, {kAllLightTypes.begin(), kAllLightTypes.end()}, {kAllSensorTypes.begin(), kAllSensorTypes.end()},
                /*camera_first=*/true),
      limits);
  if (!inner) return inner.error();
  Result<Expr> x = dfa_to_expr(minimize(*inner), kMaxEmitStates, kMaxEmitNodes);
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

Result<std::string> full_path_expression(const Dfa& cls, const Limits& limits) {
  // The interior language of each (light, sensor) pair; pairs with the same language share a term.
  struct Term {
    Dfa interior;
    std::vector<std::pair<LightType, SensorType>> ends;
  };
  std::vector<Term> terms;
  for (LightType l : kAllLightTypes)
    for (SensorType s : kAllSensorTypes) {
      Result<Dfa> inner = determinize(interiors(cls, {l}, {s}, /*camera_first=*/false), limits);
      if (!inner) return inner.error();
      Dfa w = minimize(*inner);
      if (is_empty(w)) continue;
      auto it = std::find_if(terms.begin(), terms.end(), [&](const Term& t) { return t.interior == w; });
      if (it == terms.end()) terms.push_back({std::move(w), {}}), it = terms.end() - 1;
      it->ends.push_back({l, s});
    }
  std::string out;
  for (const Term& t : terms) {
    Result<Expr> x = dfa_to_expr(t.interior, kMaxEmitStates, kMaxEmitNodes);
    if (!x) return x.error();
    const std::string middle = to_full_notation(*x);
    // Each light with the sensors it goes with; lights with the same sensors share a rectangle.
    std::vector<std::pair<std::vector<LightType>, std::vector<SensorType>>> rects;
    for (LightType l : kAllLightTypes) {
      std::vector<SensorType> with;
      for (const auto& [el, es] : t.ends)
        if (el == l) with.push_back(es);
      if (with.empty()) continue;
      auto it = std::find_if(rects.begin(), rects.end(), [&](const auto& r) { return r.second == with; });
      if (it == rects.end()) rects.push_back({{l}, with});
      else it->first.push_back(l);
    }
    for (const auto& [ls, ss] : rects) {
      std::vector<std::string> lw, sw;
      for (LightType l : ls) lw.push_back(light_letters(l));
      for (SensorType s : ss) sw.push_back(sensor_letters(s));
      if (!out.empty()) out += '|';
      out += "L" + pairs_text(lw) + middle + pairs_text(sw) + "E";
    }
  }
  return out;
}

}  // namespace pathex
