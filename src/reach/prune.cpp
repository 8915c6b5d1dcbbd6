#include "reach/prune.h"

#include "automata/ops.h"

namespace pathex {
namespace {

// Whether `st` with its s (or t) range set to exactly `v` samples a path of `target`. With s
// fixed the language reads deterministically from L; with only t fixed its determinisation would
// remember the last t letters (2^t states), so then each s of the range is tried with it.
Result<bool> samples_at(const Strategy& st, bool on_s, int v, int top, std::optional<int> max_bounces, const Dfa& target,
                        const Limits& limits) {
  Strategy one = st;
  (on_s ? one.s : one.t) = Range{v, v};
  const int s_last = st.s.hi == Range::kOpen ? top : std::min(st.s.hi, top);
  for (int s = on_s ? v : st.s.lo; s <= (on_s ? v : s_last); ++s) {
    one.s = Range{s, s};
    Result<Dfa> l = strategy_language(one, max_bounces, limits);
    if (!l) return l.error();
    if (!is_empty(dfa_intersect(*l, target))) return true;
  }
  return false;
}

// The hull of the values of `range` at which `st` samples a path of `target` (one is known to
// exist). Without a bound an open range keeps its open end.
Result<Range> narrowed(const Strategy& st, bool on_s, std::optional<int> max_bounces, const Dfa& target,
                       const Limits& limits) {
  const Range r = on_s ? st.s : st.t;
  // A full path has s + t + 2 letters between L and E, at most max_bounces + 4.
  const int top = max_bounces ? *max_bounces + 2 : r.lo + 64;
  const int last = r.hi == Range::kOpen ? top : std::min(r.hi, top);
  // The first value from below and the first from above at which it samples (the hull's ends).
  int lo = -1, hi = -1;
  for (int v = r.lo; v <= last && lo < 0; ++v) {
    Result<bool> yes = samples_at(st, on_s, v, top, max_bounces, target, limits);
    if (!yes) return yes.error();
    if (*yes) lo = v;
  }
  if (lo < 0) return r;  // only past `top` (no bound): keep the range
  for (int v = last; v >= lo && hi < 0; --v) {
    Result<bool> yes = samples_at(st, on_s, v, top, max_bounces, target, limits);
    if (!yes) return yes.error();
    if (*yes) hi = v;
  }
  // Sampling at (or next to) the last value checked keeps the range's own end: under the bound it is
  // the same strategy (the tracer clamps its subpaths to max_bounces + 2 vertices).
  return Range{lo, hi >= last - 1 ? r.hi : hi};
}

}  // namespace

Result<ProfilePruning> prune_profile(const Profile& p, std::optional<int> max_bounces, const Dfa& universe,
                                     const std::optional<Dfa>& requested, const Limits& limits) {
  const Dfa target = requested ? dfa_intersect(universe, *requested) : universe;
  ProfilePruning out;
  out.profile = p;
  out.profile.strategies.clear();
  for (const Strategy& st : p.strategies) {
    Result<Dfa> lang = strategy_language(st, max_bounces, limits);
    if (!lang) return lang.error();
    PrunedStrategy change{st.name, st.describe(), "", ""};
    if (is_empty(dfa_intersect(*lang, target))) {
      if (is_empty(dfa_intersect(*lang, universe))) {
        const std::optional<std::string> example = shortest_member(*lang);
        change.reason = "it samples no path this scene can have" +
                        (example ? " (its shortest, " + *example + ", needs end or material types the scene lacks)" : std::string());
      } else {
        change.reason = "it samples no path of the requested classes in this scene";
      }
      out.changes.push_back(std::move(change));
      continue;
    }
    Strategy kept = st;
    Result<Range> s = narrowed(kept, true, max_bounces, target, limits);
    if (!s) return s.error();
    kept.s = *s;
    Result<Range> t = narrowed(kept, false, max_bounces, target, limits);
    if (!t) return t.error();
    kept.t = *t;
    if (kept.s.lo != st.s.lo || kept.s.hi != st.s.hi || kept.t.lo != st.t.lo || kept.t.hi != st.t.hi) {
      change.now = kept.describe();
      change.reason = "only these subpath lengths sample a path of this scene" +
                      std::string(requested ? " in the requested classes" : "");
      out.changes.push_back(std::move(change));
    }
    out.profile.strategies.push_back(std::move(kept));
  }
  return out;
}

}  // namespace pathex
