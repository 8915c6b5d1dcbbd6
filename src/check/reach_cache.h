// Resolving renderer profiles (built-in names or files), compiling them under a bound, and turning
// a scene into its universe U_s (DESIGN §6), each once: a check file with a hundred cases compiles
// each (profile, bound) and scene once. `pathex query` and `pathex check` use it.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>

#include "classify/pathclass.h"
#include "core/limits.h"
#include "reach/query.h"

namespace pathex {

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

}  // namespace pathex
