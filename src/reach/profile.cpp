// Strategy languages are built as automata from their definition: the light-side prefix
// L [SD]{s}, the chain's minimal DFA, the eye-side suffix [SD]{t} E, concatenated and intersected
// with the (bounded) universe. Everything else in reach/ is language algebra over these.
#include "reach/profile.h"

#include <cctype>

#include "automata/ops.h"
#include "core/budget.h"
#include "regex/parser.h"

namespace pathex {
namespace {

Result<Dfa> compile_text(const std::string& text, const Limits& limits) {
  Result<Regex> r = parse(text, limits);
  if (!r) return r.error();
  return compile(*r, limits);
}

// A fixed language of this file, built once outside any operation's budget.
Dfa constant_language(const char* text) {
  ExemptFromBudget exempt;
  return compile_text(text, Limits{}).expect("a constant chain language compiles");
}

std::string range_regex(const Range& r) {
  if (r.hi == Range::kOpen) return "{" + std::to_string(r.lo) + ",}";
  return "{" + std::to_string(r.lo) + "," + std::to_string(r.hi) + "}";
}

Error pointer_error(const std::string& pointer, std::string message) {
  Error e = make_error(ErrorCode::kBadValue, std::move(message));
  e.where = pointer;
  return e;
}

}  // namespace

std::string Range::to_string() const {
  if (hi == kOpen) return std::to_string(lo) + "..";
  if (hi == lo) return std::to_string(lo);
  return std::to_string(lo) + ".." + std::to_string(hi);
}

Result<Range> parse_range(const std::string& text) {
  auto number = [](const std::string& s, int* out) {
    if (s.empty() || s.size() > 6) return false;
    for (char c : s)
      if (!std::isdigit(static_cast<unsigned char>(c))) return false;
    *out = std::stoi(s);
    return true;
  };
  const std::string expected = "expected a count like 2, a range like 0..1, or an open range like 2..";
  Range r;
  const std::size_t dots = text.find("..");
  if (dots == std::string::npos) {
    if (!number(text, &r.lo)) return make_error(ErrorCode::kBadValue, "'" + text + "': " + expected);
    r.hi = r.lo;
    return r;
  }
  if (!number(text.substr(0, dots), &r.lo)) return make_error(ErrorCode::kBadValue, "'" + text + "': " + expected);
  const std::string hi = text.substr(dots + 2);
  if (hi.empty()) return r;
  if (!number(hi, &r.hi)) return make_error(ErrorCode::kBadValue, "'" + text + "': " + expected);
  if (r.hi < r.lo)
    return make_error(ErrorCode::kBadValue, "'" + text + "': the range is inverted (" + std::to_string(r.lo) +
                                                " > " + std::to_string(r.hi) + ")");
  return r;
}

std::string to_string(ConnectorKind k) {
  switch (k) {
    case ConnectorKind::kNone: return "";
    case ConnectorKind::kMirror: return "mirror";
    case ConnectorKind::kDistantProjection: return "distant-projection";
    case ConnectorKind::kOrthoProjection: return "ortho-projection";
    case ConnectorKind::kManifold: return "manifold";
  }
  return "";
}

std::optional<ConnectorKind> connector_from_string(const std::string& s) {
  for (ConnectorKind k : kCatalogue)
    if (to_string(k) == s) return k;
  return std::nullopt;
}

std::string connector_summary(ConnectorKind k) {
  switch (k) {
    case ConnectorKind::kNone: return "plain join (shadow ray or hit): the chain DD";
    case ConnectorKind::kMirror: return "planar mirror by the image method: an interior DSD";
    case ConnectorKind::kDistantProjection: return "projection against a distant light's direction: c0..c2 = DSD";
    case ConnectorKind::kOrthoProjection: return "projection onto an orthographic sensor's direction: ck..c(k+2) = DSD";
    case ConnectorKind::kManifold: return "manifold walk through smooth specular surfaces: an interior DS+D";
  }
  return "";
}

bool connector_handles(ConnectorKind k, const std::string& chain, int from, int to, int k_edges) {
  const bool dsd = chain == "DSD";
  bool ds_plus_d = chain.size() >= 3 && chain.front() == 'D' && chain.back() == 'D';
  for (std::size_t i = 1; ds_plus_d && i + 1 < chain.size(); ++i) ds_plus_d = chain[i] == 'S';
  // Interior vertices x1 … x(k-1) are the letters c2 … ck.
  const bool s_interior = from + 1 >= 2 && to - 1 <= k_edges;
  switch (k) {
    case ConnectorKind::kNone: return chain == "DD";
    case ConnectorKind::kMirror: return dsd && s_interior;
    case ConnectorKind::kDistantProjection: return dsd && from == 0;
    case ConnectorKind::kOrthoProjection: return dsd && to == k_edges + 2;
    case ConnectorKind::kManifold: return ds_plus_d && s_interior;
  }
  return false;
}

std::string Strategy::describe() const {
  std::string d = "(" + s.to_string() + ", " + chain + ", " + t.to_string() + ")";
  if (connector != ConnectorKind::kNone) d += " via " + to_string(connector);
  return d;
}

namespace {

Result<bool> check_strategy_unbudgeted(Strategy* st, const Limits& limits, const std::string& pointer) {
  Result<Dfa> chain = compile_text(st->chain, limits);
  if (!chain) {
    Error e = chain.error();
    e.where = pointer + "/chain";
    return e;
  }
  static const Dfa ds_star_d = constant_language("DS*D");
  if (!is_subset(*chain, ds_star_d))
    return pointer_error(pointer + "/chain", "chain '" + st->chain + "' is not within DS*D (a chain runs from one D separator to the next; " +
                                                 "it contains " + *shortest_member(dfa_difference(*chain, ds_star_d)) + ")");
  if (is_empty(*chain)) return pointer_error(pointer + "/chain", "chain '" + st->chain + "' is empty");
  static const Dfa dd = dfa_word("DD");
  static const Dfa dsd = dfa_word("DSD");
  static const Dfa ds_plus_d = constant_language("DS+D");
  switch (st->connector) {
    case ConnectorKind::kNone:
      if (!is_equivalent(*chain, dd))
        return pointer_error(pointer + "/chain", "chain '" + st->chain +
                                                     "' has specular letters, so it needs a connector (mirror, "
                                                     "distant-projection, ortho-projection or manifold); a plain join is DD");
      break;
    case ConnectorKind::kMirror:
    case ConnectorKind::kDistantProjection:
    case ConnectorKind::kOrthoProjection:
      if (!is_equivalent(*chain, dsd))
        return pointer_error(pointer + "/chain", "the " + to_string(st->connector) + " connector joins the chain DSD, not '" + st->chain + "'");
      break;
    case ConnectorKind::kManifold:
      if (!is_subset(*chain, ds_plus_d))
        return pointer_error(pointer + "/chain", "the manifold connector joins chains within DS+D, not '" + st->chain + "'");
      break;
  }
  if (st->connector == ConnectorKind::kDistantProjection && !(st->s.lo == 0 && st->s.hi == 0))
    return pointer_error(pointer + "/s", "the distant-projection connector joins at c0..c2, so s must be 0");
  if (st->connector == ConnectorKind::kOrthoProjection && !(st->t.lo == 0 && st->t.hi == 0))
    return pointer_error(pointer + "/t", "the ortho-projection connector joins at ck..c(k+2), so t must be 0");
  // Where a connector may stand is stated by the strategy's s and t (DESIGN §4); the checker's
  // languages and the tracer's strategy table both read them. Mirror and manifold construct
  // interior vertices only (every S they join is one of x1 … x(k-1)), so s ≥ 1 and t ≥ 1.
  if (st->connector == ConnectorKind::kMirror || st->connector == ConnectorKind::kManifold) {
    const bool s_ok = st->s.lo >= 1;
    if (!s_ok || st->t.lo < 1)
      return pointer_error(pointer + (s_ok ? "/t" : "/s"),
                           "the " + to_string(st->connector) +
                               " connector constructs interior vertices only, so s and t must be at least 1 (found s " +
                               st->s.to_string() + ", t " + st->t.to_string() + ")");
  }
  st->chain_dfa = std::move(*chain);
  return true;
}

}  // namespace

Result<bool> check_strategy(Strategy* st, const Limits& limits, const std::string& pointer) {
  Result<bool> r = within_budget(limits, [&] { return check_strategy_unbudgeted(st, limits, pointer); });
  if (!r && r.error().where.empty()) {
    Error e = r.error();
    e.where = pointer + "/chain";
    return e;
  }
  return r;
}

Dfa bounded_universe(std::optional<int> max_bounces) {
  return max_bounces ? dfa_universe_bounded(*max_bounces) : dfa_universe();
}

Result<Dfa> strategy_language(const Strategy& st, std::optional<int> max_bounces, const Limits& limits) {
  return within_budget(limits, [&]() -> Result<Dfa> {
    Result<Dfa> prefix = compile_text("L[SD]" + range_regex(st.s), limits);
    if (!prefix) return prefix.error();
    Result<Dfa> suffix = compile_text("[SD]" + range_regex(st.t) + "E", limits);
    if (!suffix) return suffix.error();
    Result<Dfa> a = dfa_concat(*prefix, st.chain_dfa, limits);
    if (!a) return a.error();
    Result<Dfa> b = dfa_concat(*a, *suffix, limits);
    if (!b) return b.error();
    return dfa_intersect(*b, bounded_universe(max_bounces));
  });
}

Result<Dfa> reachable_language(const Profile& p, std::optional<int> max_bounces, const Limits& limits) {
  return within_budget(limits, [&]() -> Result<Dfa> {
    Dfa r = dfa_empty();
    for (const Strategy& st : p.strategies) {
      Result<Dfa> l = strategy_language(st, max_bounces, limits);
      if (!l) return l.error();
      r = dfa_union(r, *l);
    }
    return r;
  });
}

bool strategy_samples(const Strategy& st, const std::string& path, std::optional<int> max_bounces) {
  // path = L c0 … c(k+2) E; the scattering letters are path[1 .. n-2].
  const int letters = static_cast<int>(path.size()) - 2;
  if (max_bounces && letters - 4 > *max_bounces) return false;
  for (int s = 0; s <= letters; ++s) {
    if (!st.s.contains(s)) continue;
    for (int t = 0; s + t <= letters; ++t) {
      if (!st.t.contains(t)) continue;
      const std::string chain = path.substr(static_cast<std::size_t>(s) + 1, static_cast<std::size_t>(letters - s - t));
      if (st.chain_dfa.accepts(chain)) return true;
    }
  }
  return false;
}

}  // namespace pathex
