// Pruning (trace/prune.h): which strategies of a profile run, decided by the checker's languages
// before the render; and the tracer's side of --only, whether a sampled path is recorded and
// whether a growing subpath can still complete to a requested class, read off the classifier's
// automata so that what is pruned is exactly what no requested class contains (DESIGN §11).
#include "trace/prune.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

#include "automata/ops.h"

namespace pathex {
namespace {

// Whether `st` with its s (or t) range set to exactly `v` samples a path of `target`. With s
// fixed the language reads deterministically from L; with only t fixed its determinisation would
// remember the last t letters (2^t states), so then each s of the range is tried with it, except
// for a small t, whose one language over the whole s range is cheap (the language of an s range
// is the union of its values' languages, so the answer is the same).
constexpr int kWholeRangeMaxT = 4;

Result<bool> samples_at(const Strategy& st, bool on_s, int v, int top, std::optional<int> max_bounces, const Dfa& target,
                        const Limits& limits) {
  Strategy one = st;
  (on_s ? one.s : one.t) = Range{v, v};
  const int s_last = st.s.hi == Range::kOpen ? top : std::min(st.s.hi, top);
  if (!on_s && v <= kWholeRangeMaxT) {
    if (st.s.lo > s_last) return false;
    one.s = Range{st.s.lo, s_last};
    Result<Dfa> l = strategy_language(one, max_bounces, limits);
    if (!l) return l.error();
    return !is_empty(dfa_intersect(*l, target));
  }
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

// Rays to extend a subpath from its first vertex to `vertices` vertices (cover_cost()).
double subpath_rays(int vertices) {
  double r = 0.0;
  for (int d = 1; d < vertices; ++d) r += std::pow(kGoOn, d - 1);
  return r;
}

// A hit (s = 0 or t = 0) is found by the subpath's own ray.
double join_rays(Join j) {
  return j.s == 0 || j.t == 0 ? 0.0 : std::pow(kGoOn, std::max(j.s - 2, 0) + std::max(j.t - 2, 0));
}

}  // namespace

double cover_cost(const std::vector<Join>& joins) {
  int s_max = 0, t_max = 0;
  double c = 0.0;
  for (const Join& j : joins) {
    s_max = std::max(s_max, j.s);
    t_max = std::max(t_max, j.t);
    c += join_rays(j);
  }
  // s = 1 and t = 1 take fresh samples: as in the tracer, a light subpath is traced only for some
  // s >= 2, an eye subpath beyond the sensor's vertex only for some t >= 2.
  return c + (s_max >= 2 ? subpath_rays(s_max) : 0.0) + subpath_rays(t_max);
}

Result<CoverSelection> select_cover(const Profile& pruned, int max_bounces, const Dfa& universe, const Dfa& requested,
                                    const Limits& limits) {
  const Dfa target = dfa_intersect(dfa_intersect(universe, requested), bounded_universe(max_bounces));
  CoverSelection out;
  out.profile = pruned;
  out.profile.strategies.clear();
  out.per_strategy.resize(pruned.strategies.size());
  // Connectors are kept whole, and a path a connector samples still wants the joins that sample it
  // too: a connector is an expensive and heavy-tailed sampler that MIS needs beside the joins, not
  // instead of them (with the connector's paths left to it alone, bdpt+manifold's --only render of
  // lamp-glass's directly seen caustic lost light tracing and was 50× less efficient than the full
  // render: bench/README.md, issue 40, eighth session).
  const Dfa& wanted = target;
  // X: the joins that sample a wanted path, each with the strategy that runs it (the first whose
  // ranges hold it, as in the tracer's table) and the wanted paths it samples.
  const int letters = max_bounces + 4;  // the most letters between L and E: s + t + 2 <= letters
  std::vector<Join> x;
  std::vector<std::size_t> owner;
  std::vector<Dfa> lang;
  std::map<std::pair<int, int>, bool> seen;
  // A join's wanted paths are the wanted paths of its length whose join sits after s letters: one
  // language per length and one per (strategy, s), rather than one per join.
  std::vector<Dfa> wanted_of_length(static_cast<std::size_t>(letters) + 1, dfa_empty());
  for (int n = 4; n <= letters; ++n)
    wanted_of_length[static_cast<std::size_t>(n)] = dfa_intersect(
        wanted, n == 4 ? dfa_universe_bounded(0) : dfa_difference(dfa_universe_bounded(n - 4), dfa_universe_bounded(n - 5)));
  for (std::size_t i = 0; i < pruned.strategies.size(); ++i) {
    const Strategy& st = pruned.strategies[i];
    if (st.connector != ConnectorKind::kNone) continue;
    for (int s = 0; s + 2 <= letters; ++s) {
      if (!st.s.contains(s)) continue;
      std::optional<Dfa> after_s;  // the strategy's language with s letters before its join
      for (int t = 0; s + t + 2 <= letters; ++t) {
        if (!st.t.contains(t) || seen[{s, t}]) continue;
        seen[{s, t}] = true;
        const Dfa& w = wanted_of_length[static_cast<std::size_t>(s + t + 2)];
        if (is_empty(w)) continue;
        if (!after_s) {
          Strategy one = st;
          one.s = Range{s, s};
          Result<Dfa> l = strategy_language(one, max_bounces, limits);
          if (!l) return l.error();
          after_s = std::move(*l);
        }
        Dfa mine = dfa_intersect(*after_s, w);
        if (is_empty(mine)) continue;
        x.push_back(Join{s, t});
        owner.push_back(i);
        lang.push_back(std::move(mine));
      }
    }
  }
  // Hits (s = 0: an eye subpath that happens to reach an area light; t = 0: a light subpath that
  // reaches the lens) cost no ray, but sample by chance: for a small light or lens they are the
  // worst sampler of their paths, which the ray count does not see. So a hit is kept only for
  // the paths no other join samples, and the search below covers the rest with joins s, t >= 1.
  const auto is_hit = [&](std::size_t m) { return x[m].s == 0 || x[m].t == 0; };
  Dfa by_joins = dfa_empty();
  for (std::size_t m = 0; m < x.size(); ++m)
    if (!is_hit(m)) by_joins = dfa_union(by_joins, lang[m]);
  std::vector<int> hits;
  const Dfa hits_only = dfa_difference(wanted, by_joins);
  for (std::size_t m = 0; m < x.size(); ++m)
    if (is_hit(m) && !is_empty(dfa_intersect(lang[m], hits_only))) hits.push_back(static_cast<int>(m));
  const Dfa need = by_joins;
  const auto union_of = [&](const std::vector<int>& members) {
    Dfa u = dfa_empty();
    for (int m : members) u = dfa_union(u, lang[static_cast<std::size_t>(m)]);
    return u;
  };
  const auto joins_of = [&](const std::vector<int>& members) {
    std::vector<Join> j;
    for (int m : members) j.push_back(x[static_cast<std::size_t>(m)]);
    return j;
  };
  // The candidates: every row and column, completed where it misses something; pairs that cover.
  std::vector<std::vector<int>> families;
  std::map<int, std::vector<int>> rows, columns;
  for (std::size_t m = 0; m < x.size(); ++m) {
    if (is_hit(m)) continue;
    rows[x[m].s].push_back(static_cast<int>(m));
    columns[x[m].t].push_back(static_cast<int>(m));
  }
  for (const auto& [s, members] : rows) families.push_back(members);
  for (const auto& [t, members] : columns) families.push_back(members);
  std::vector<Dfa> family_lang;
  for (const std::vector<int>& f : families) family_lang.push_back(union_of(f));
  out.full_cost = cover_cost(x);
  // Only a candidate under the budget is worth it; adding joins never lowers the cost, so a family
  // over it is skipped before any language operation.
  const double budget = kCoverAt * out.full_cost;
  const auto within = [&](const std::vector<int>& c) { return cover_cost(joins_of(c)) <= budget; };
  std::vector<std::vector<int>> candidates;
  // What each family misses, and its shortest missed path: a pair covers only if each family
  // samples the other's, a test on one string before the language operation.
  std::vector<Dfa> missed;
  std::vector<std::string> missed_one;
  for (std::size_t f = 0; f < families.size(); ++f) {
    missed.push_back(dfa_difference(need, family_lang[f]));
    missed_one.push_back(shortest_member(missed.back()).value_or(""));
    if (missed_one.back().empty() && within(families[f])) candidates.push_back(families[f]);
  }
  for (std::size_t f = 0; f < families.size(); ++f)
    for (std::size_t g = f + 1; g < families.size(); ++g) {
      if (missed_one[f].empty() || missed_one[g].empty()) continue;  // one alone covers: the pair costs more
      if (!family_lang[g].accepts(missed_one[f]) || !family_lang[f].accepts(missed_one[g])) continue;
      std::vector<int> pair = families[f];
      for (int m : families[g])
        if (std::find(pair.begin(), pair.end(), m) == pair.end()) pair.push_back(m);
      if (within(pair) && is_empty(dfa_intersect(missed[f], missed[g]))) candidates.push_back(std::move(pair));
    }
  // Completions, the cheapest families first, each only while it can still beat the best so far.
  double bound = budget;
  for (const std::vector<int>& c : candidates) bound = std::min(bound, cover_cost(joins_of(c)));
  std::vector<std::size_t> by_cost(families.size());
  for (std::size_t f = 0; f < families.size(); ++f) by_cost[f] = f;
  std::stable_sort(by_cost.begin(), by_cost.end(), [&](std::size_t a, std::size_t b) {
    return cover_cost(joins_of(families[a])) < cover_cost(joins_of(families[b]));
  });
  for (std::size_t f : by_cost) {
    if (missed_one[f].empty()) continue;
    std::vector<int> c = families[f];
    const auto cheap = [&] { return cover_cost(joins_of(c)) <= bound; };
    for (std::size_t m = 0; m < x.size() && cheap(); ++m)
      if (!is_hit(m) && std::find(c.begin(), c.end(), static_cast<int>(m)) == c.end() &&
          !is_empty(dfa_intersect(lang[m], missed[f])))
        c.push_back(static_cast<int>(m));
    if (!cheap()) continue;
    bound = cover_cost(joins_of(c));
    candidates.push_back(std::move(c));
  }
  // None under the budget: every join runs (the exact pruning).
  std::vector<int> best;
  if (candidates.empty())
    for (std::size_t m = 0; m < x.size(); ++m) best.push_back(static_cast<int>(m));
  double best_cost = 0.0;
  for (const std::vector<int>& c : candidates) {
    if (c.empty()) continue;
    const double cost = cover_cost(joins_of(c));
    if (best.empty() || cost < best_cost || (cost == best_cost && c.size() < best.size())) {
      best = c;
      best_cost = cost;
    }
  }
  // Drop what the rest covers, the most expensive first.
  std::vector<int> order = best;
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return join_rays(x[static_cast<std::size_t>(a)]) > join_rays(x[static_cast<std::size_t>(b)]);
  });
  for (int m : candidates.empty() ? std::vector<int>{} : order) {
    std::vector<int> rest;
    for (int k : best)
      if (k != m) rest.push_back(k);
    if (!rest.empty() && is_subset(need, union_of(rest)) && cover_cost(joins_of(rest)) <= cover_cost(joins_of(best)))
      best = std::move(rest);
  }
  if (!candidates.empty()) best.insert(best.end(), hits.begin(), hits.end());
  std::sort(best.begin(), best.end(), [&](int a, int b) {
    const Join& ja = x[static_cast<std::size_t>(a)];
    const Join& jb = x[static_cast<std::size_t>(b)];
    return owner[static_cast<std::size_t>(a)] != owner[static_cast<std::size_t>(b)]
               ? owner[static_cast<std::size_t>(a)] < owner[static_cast<std::size_t>(b)]
               : (ja.s != jb.s ? ja.s < jb.s : ja.t < jb.t);
  });
  out.kept = joins_of(best);
  out.cost = cover_cost(out.kept);
  // Group each strategy's kept joins into (s, DD, t range)s: one per s and run of consecutive t.
  for (std::size_t k = 0; k < best.size();) {
    const std::size_t m = static_cast<std::size_t>(best[k]);
    Strategy g = pruned.strategies[owner[m]];
    g.s = Range{x[m].s, x[m].s};
    int hi = x[m].t;
    std::size_t next = k + 1;
    for (; next < best.size(); ++next) {
      const std::size_t n = static_cast<std::size_t>(best[next]);
      if (owner[n] != owner[m] || x[n].s != x[m].s || x[n].t != hi + 1) break;
      hi = x[n].t;
    }
    g.t = Range{x[m].t, hi};
    // Consecutive s with the same t range make one strategy (light tracing: (4..17, DD, 1)).
    std::vector<Strategy>& mine = out.per_strategy[owner[m]];
    if (!mine.empty() && mine.back().t.lo == g.t.lo && mine.back().t.hi == g.t.hi && mine.back().s.hi + 1 == g.s.lo)
      mine.back().s.hi = g.s.hi;
    else
      mine.push_back(g);
    k = next;
  }
  for (std::size_t i = 0; i < pruned.strategies.size(); ++i) {
    if (pruned.strategies[i].connector != ConnectorKind::kNone) out.per_strategy[i].push_back(pruned.strategies[i]);
    for (const Strategy& st : out.per_strategy[i]) out.profile.strategies.push_back(st);
  }
  return out;
}

Result<bool> covers(const Profile& kept, const Profile& pruned, int max_bounces, const Dfa& universe, const Dfa& requested,
                    const Limits& limits) {
  const Dfa target = dfa_intersect(dfa_intersect(universe, requested), bounded_universe(max_bounces));
  Result<Dfa> all = reachable_language(pruned, max_bounces, limits);
  if (!all) return all.error();
  Result<Dfa> some = reachable_language(kept, max_bounces, limits);
  if (!some) return some.error();
  return is_subset(dfa_intersect(target, *all), *some);
}

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
  if (!requested || !max_bounces || out.samples_nothing()) return out;
  // --- the cheapest cover of the requested paths ---
  Result<CoverSelection> cover = select_cover(out.profile, *max_bounces, universe, *requested, limits);
  if (!cover) return cover.error();
  if (cover->cost > kCoverAt * cover->full_cost) return out;
  char figures[160];
  std::snprintf(figures, sizeof figures, "%zu joins, %.2f rays a sample against %.2f (cost model: trace/prune.h)",
                cover->kept.size(), cover->cost, cover->full_cost);
  for (std::size_t i = 0; i < out.profile.strategies.size(); ++i) {
    const Strategy& st = out.profile.strategies[i];
    if (st.connector != ConnectorKind::kNone) continue;
    std::string now;
    for (const Strategy& g : cover->per_strategy[i]) now += (now.empty() ? "" : " ") + g.describe();
    // One change per strategy: a narrowing already listed is replaced by what now runs.
    std::string was = st.describe();
    for (const PrunedStrategy& c : out.changes)
      if (c.strategy == st.name && !c.now.empty()) was = c.was;
    std::erase_if(out.changes, [&](const PrunedStrategy& c) { return c.strategy == st.name && !c.now.empty(); });
    out.changes.push_back({st.name, was, now,
                           "the requested paths are all sampled by the cheapest cover of the profile's joins: " +
                               std::string(figures)});
  }
  out.profile = std::move(cover->profile);
  return out;
}


// --- the path filter ---

Result<PathFilter> PathFilter::make(const std::vector<const PathClass*>& classes, const Limits& limits) {
  if (classes.empty()) return make_error(ErrorCode::kUsage, "no requested class");
  Result<Classifier> c = Classifier::build(classes, limits);
  if (!c) return c.error();
  PathFilter out;
  out.classifier_ = std::make_shared<const Classifier>(std::move(*c));
  // The lengths of the requested paths: the live states after L and n letters, breadth first.
  const Classifier& cl = *out.classifier_;
  const Classifier::Direction& d = cl.forward();
  std::vector<Classifier::State> now = {Classifier::step(d, d.start, 'L')}, next;
  std::vector<std::uint8_t> seen(static_cast<std::size_t>(d.num_states()));
  for (int n = 0; n <= accel::kMaxPackedLetters; ++n) {
    bool any = false;
    for (const Classifier::State s : now) any = any || !cl.members(cl.set_of(d, Classifier::step(d, s, 'E'))).empty();
    out.lengths_.push_back(any ? 1 : 0);
    std::fill(seen.begin(), seen.end(), 0);
    next.clear();
    for (const Classifier::State s : now)
      for (const char letter : {'S', 'D'}) {
        const Classifier::State t = Classifier::step(d, s, letter);
        if (cl.alive(d, t) && seen[t / Classifier::kStride] == 0) {
          seen[t / Classifier::kStride] = 1;
          next.push_back(t);
        }
      }
    now.swap(next);
  }
  return out;
}

bool PathFilter::first_vertex_specular(char pos, char dir) const {
  if (everything()) return false;
  const Classifier::Direction& d = classifier_->forward();
  Classifier::State s = Classifier::step(d, d.start, 'L');
  s = Classifier::step(d, s, pos);
  s = Classifier::step(d, s, dir);
  return !classifier_->alive(d, Classifier::step(d, s, 'D'));
}

void SubpathPrefix::start(const PathFilter& filter, bool light, char pos, char dir) {
  const Classifier& c = filter.classifier();
  d_ = light ? &c.forward() : &c.backward();
  s_ = Classifier::step(*d_, d_->start, light ? 'L' : 'E');
  s_ = Classifier::step(*d_, s_, pos);
  step(dir);
}

void SubpathPrefix::step(char letter) {
  s_ = Classifier::step(*d_, s_, letter);
  alive_ = d_->alive[s_ / Classifier::kStride] != 0;
}

}  // namespace pathex
