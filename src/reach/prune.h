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
// values for which that intersection is not empty. `requested` unset: every path.
Result<ProfilePruning> prune_profile(const Profile& p, std::optional<int> max_bounces, const Dfa& universe,
                                     const std::optional<Dfa>& requested, const Limits& limits);

}  // namespace pathex
