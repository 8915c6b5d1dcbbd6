// Strategy pruning (DESIGN §11): before a render, the checker decides which strategies of a
// profile can sample a path at all, given the scene's universe U_s and the classes the user asked
// for (pathex trace --only). A strategy whose language meets neither is not run; a strategy that
// can sample only some of its subpath lengths is narrowed to them. The tracer is handed the
// reduced profile, so MIS is computed over the strategies that run: for every path that can be
// sampled and is requested, the strategies left are exactly those whose language holds it, as
// before, so its weights, and the estimate, are unchanged.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "core/error.h"
#include "core/limits.h"
#include "reach/profile.h"

namespace pathex {

struct PrunedStrategy {
  std::string strategy;  // the profile's name for it
  std::string was;       // its (s, chain, t) in the profile
  std::string now;       // what runs: "" when it does not run at all, else the narrowed (s, chain, t)
  std::string reason;    // one line: why
};

struct ProfilePruning {
  Profile profile;                      // the strategies that run, narrowed; MIS is over these
  std::vector<PrunedStrategy> changes;  // each strategy not run or narrowed, in the profile's order
  bool samples_nothing() const { return profile.strategies.empty(); }
};

// For each strategy of `p` with language S (bounded by `max_bounces`): not run when
// S ∩ universe ∩ requested is empty; otherwise its s and t ranges are narrowed to the hull of the
// values for which that intersection is not empty. `requested` unset: every path. With requested
// classes and a bound, the plain joins left are then reduced to the cheapest cover
// (select_cover() below), which changes the sampling of the requested paths but not their
// expectation: it is reported as one more change.
Result<ProfilePruning> prune_profile(const Profile& p, std::optional<int> max_bounces, const Dfa& universe,
                                     const std::optional<Dfa>& requested, const Limits& limits);

// --- cover selection: the cheapest subset of strategies that still samples every requested path ---
//
// Exact pruning keeps every strategy that samples some requested path, so the requested paths are
// sampled as in the full render and only time is saved. Most of a render's work, though, is spent
// on strategies whose every requested path is also sampled by another strategy. MIS stays unbiased
// over any set of strategies that samples each path at least once (the weights over the strategies
// that run sum to 1 on each path they sample), so a render of some classes needs only a cover:
// a set K of plain joins (s, DD, t) such that every path of universe ∩ requested that the profile
// samples is sampled by K or by one of the profile's connectors (which are kept whole).
//
// The cost model counts expected rays per sample, with a subpath going on past each vertex with
// probability q = kGoOn: extending the light subpath to the largest s of K and the eye subpath to
// the largest t (vertex d, counted from the first ray, is reached with probability q^(d-1)), and
// one shadow ray per join (s, t) of K with s, t >= 1, made when both of its vertices exist
// (q^(max(s-2, 0) + max(t-2, 0))). Variance is not modelled, with one exception: hits (s = 0, an
// eye subpath reaching an area light; t = 0, a light subpath reaching the lens) cost no ray but
// sample by chance, the worst sampler of their paths for a small light or lens, so a hit is kept
// only for the paths that no join with s, t >= 1 samples.
//
// The search, over the joins X with s, t >= 1 that sample a requested path: as candidates, each
// row (one s, e.g. s = 1 is next-event estimation) and each column (one t: t = 1 is light
// tracing), each pair of them that covers, each row or column completed with every join of X that
// samples a requested path it misses (which always covers), and X itself; the cheapest candidate
// (ties: fewer joins, then rows before columns, smaller s first: camera-side sampling, whose
// contributions stay in their pixel), with joins the rest covers dropped, the most expensive
// first. Takes well under a second for max_bounces 16.
//
// A cover is used only when it costs at most kCoverAt of every join's rays: a subset that is not
// full BDPT takes the tracer's general MIS routine (dearer per join than full BDPT's per-sample
// sums), and the variance per sample may rise; below a 4/3 saving the exact pruning, which samples
// the requested paths exactly as the full render does, is kept. Candidates over that budget are
// skipped before any language operation (adding joins never lowers the cost).
inline constexpr double kGoOn = 0.8;
inline constexpr double kCoverAt = 0.75;

struct Join {
  int s = 0, t = 0;
  friend bool operator==(const Join&, const Join&) = default;
};
// The cost model above for a set of plain joins.
double cover_cost(const std::vector<Join>& joins);

struct CoverSelection {
  Profile profile;           // the connector strategies and the kept joins, grouped into (s, DD, t range) strategies
  std::vector<std::vector<Strategy>> per_strategy;  // [i]: what runs of the pruned profile's strategy i
  std::vector<Join> kept;    // the kept joins
  double cost = 0.0;         // cover_cost(kept); every join (the fallback) when no candidate is within kCoverAt
  double full_cost = 0.0;    // cover_cost of every join the pruned profile runs that samples a requested path
};

// The cheapest cover found for `pruned` (a result of prune_profile(); its plain strategies are
// taken as they are, first match per (s, t) as the tracer's table does), or an error.
Result<CoverSelection> select_cover(const Profile& pruned, int max_bounces, const Dfa& universe, const Dfa& requested,
                                    const Limits& limits);

// Whether `kept` samples every path of universe ∩ requested that `pruned` samples (paths with at
// most max_bounces interior vertices): the exact check select_cover() makes.
Result<bool> covers(const Profile& kept, const Profile& pruned, int max_bounces, const Dfa& universe, const Dfa& requested,
                    const Limits& limits);

}  // namespace pathex
