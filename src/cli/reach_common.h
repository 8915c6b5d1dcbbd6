// The set-up of `query`: its renderers and scene through the cache of check/reach_cache.h.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "classify/pathclass.h"
#include "check/reach_cache.h"
#include "reach/query.h"

namespace pathex::cli {

struct ReachSetup {
  std::vector<CompiledProfile> compiled;
  std::optional<Dfa> universe;
  std::optional<EndTypes> scene_ends;
};

// Resolves and compiles the renderers and the scene; on error reports it and returns the exit
// code, else returns 0. `cache` must outlive `setup`.
int prepare_reach(ReachCache& cache, const std::vector<std::string>& renderers, const std::string& scene,
                  std::optional<int> max_bounces, ReachSetup* setup);

}  // namespace pathex::cli
