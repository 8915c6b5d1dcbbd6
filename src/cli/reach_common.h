// Shared set-up of `query` and `check`: resolving renderer profiles (built-in names or files),
// compiling them under a bound, and turning a scene into its universe U_s (DESIGN §6). Both are
// cached, so a check file with a hundred cases compiles each (profile, bound) and scene once.
#pragma once

#include <deque>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "classify/pathclass.h"
#include "reach/query.h"

namespace pathex::cli {

struct SceneUniverse {
  Dfa universe;    // U_s
  EndTypes ends;   // the scene's light types and sensor type (for Heckbert notation)
  std::string summary;  // e.g. "lights point; sensor pinhole; materials D S"
};

class ReachCache {
 public:
  explicit ReachCache(const Limits& limits) : limits_(limits) {}
  Result<const Profile*> profile(const std::string& name_or_path);
  Result<const CompiledProfile*> compiled(const std::string& name_or_path, std::optional<int> max_bounces);
  Result<const SceneUniverse*> scene(const std::string& path);

 private:
  Limits limits_;
  std::map<std::string, Profile> profiles_;
  std::map<std::pair<std::string, int>, CompiledProfile> compiled_;
  std::map<std::string, SceneUniverse> scenes_;
};

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
