// Pruning (DESIGN §11), in one module: what a render can leave out without changing any estimate
// of what it records.
//
// First, before the render, which strategies of a profile run (prune_profile, select_cover): the
// checker decides which can sample a path at all, given the scene's universe U_s and the classes
// the user asked for (pathex trace --only). A strategy whose language meets neither is not run; a
// strategy that can sample only some of its subpath lengths is narrowed to them. The tracer is
// handed the reduced profile, so MIS is computed over the strategies that run: for every path that
// can be sampled and is requested, the strategies left are exactly those whose language holds it,
// as before, so its weights, and the estimate, are unchanged.
//
// Then, during the render, which sampled paths are recorded (PathFilter) and when a subpath stops
// growing because no requested class can be completed from it any more (SubpathPrefix: a dead
// state of the classifier's forward automaton for light subpaths, of its backward automaton for
// eye subpaths). Separate from Russian roulette: a dead subpath's extensions belong to no
// requested class, so stopping it changes no requested estimate; it only saves their rays.
//
// trace/plan.h makes both decisions once per render (plan_render); nothing else calls them.
#pragma once

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "core/error.h"
#include "core/limits.h"
#include "reach/profile.h"
#include "trace/accel/path_ids.h"

namespace pathex {

// --- strategy pruning, before the render ---

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
// samples is sampled by K wherever a join samples it (the profile's connectors are kept whole,
// beside the joins, not instead of them).
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


// --- the path filter, during the render ---

// Which sampled paths a render records: every path (the default), or the union of requested
// classes. The estimator asks it about every join and every subpath vertex; for every path the
// answers are one test of a pointer.
class PathFilter {
 public:
  PathFilter() = default;  // every path
  // The union of `classes` (at least one) is what is recorded.
  static Result<PathFilter> make(const std::vector<const PathClass*>& classes, const Limits& limits);

  // Whether every path is recorded (no class was requested).
  bool everything() const { return classifier_ == nullptr; }

  // Whether a sampled path (packed full-path string) is recorded.
  bool records(accel::PathKey key) const {
    if (everything()) return true;
    const Classifier::Direction& d = classifier_->forward();
    Classifier::State s = Classifier::step(d, d.start, 'L');
    const int n = accel::packed_length(key);
    for (int i = 0; i < n; ++i) s = Classifier::step(d, s, accel::packed_is_d(key, i) ? 'D' : 'S');
    s = Classifier::step(d, s, 'E');
    return !classifier_->members(classifier_->set_of(d, s)).empty();
  }

  // Whether every recorded path that starts at a light with letters c0 c1 = `pos` `dir` has a
  // specular first vertex: after L c0 c1 the letter D (a diffuse first vertex, or the first letter
  // of a pinhole or a lens, the light seen directly) leaves no requested class to complete. Then a
  // light subpath's first ray matters only where it meets a shape with a specular component
  // (trace/emission_cones.h). False for every path.
  bool first_vertex_specular(char pos, char dir) const;

  // Whether some recorded path has `n` letters between L and E (c0 … c(k+2)): a join whose path
  // would have another length is not made. Lengths past the table, and every path: true.
  bool has_length(int n) const {
    return n < 0 || static_cast<std::size_t>(n) >= lengths_.size() || lengths_[static_cast<std::size_t>(n)] != 0;
  }

  // The requested classes' classifier; only when !everything().
  const Classifier& classifier() const { return *classifier_; }

 private:
  std::shared_ptr<const Classifier> classifier_;  // null: every path
  std::vector<std::uint8_t> lengths_;  // lengths_[n]: has_length(n), for n up to a packed key's longest
};

// A subpath's letters so far, read from its end vertex (a light subpath forward from L c0 c1, an
// eye subpath backward from E c(k+2) c(k+1)), for the dead-state test. Under a filter of every
// path every subpath is alive.
class SubpathPrefix {
 public:
  // `pos` and `dir`: the end vertex's two letters (c0 c1 of a light; c(k+2) c(k+1) of a sensor).
  // Inline, the walk pays a test of the filter here and one per vertex; the stepping is out of
  // line, so that the walk's own code (and what the compiler inlines into it) is as without one.
  SubpathPrefix(const PathFilter& filter, bool light, char pos, char dir) {
    if (!filter.everything()) [[unlikely]] start(filter, light, pos, dir);
  }
  // Whether some recorded path can still be completed from the letters read.
  bool alive() const { return alive_; }
  // Reads the letter of the subpath's newest vertex (the scattering event sampled there).
  void extend(char letter) {
    if (d_ != nullptr) [[unlikely]] step(letter);
  }

 private:
  void start(const PathFilter& filter, bool light, char pos, char dir);
  void step(char letter);
  const Classifier::Direction* d_ = nullptr;
  Classifier::State s_ = 0;
  bool alive_ = true;
};

}  // namespace pathex
