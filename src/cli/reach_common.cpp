#include "cli/reach_common.h"

#include "cli/common.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "scene/universe.h"

namespace pathex::cli {

int prepare_reach(ReachCache& cache, const std::vector<std::string>& renderers, const std::string& scene,
                  std::optional<int> max_bounces, ReachSetup* setup) {
  for (const std::string& r : renderers) {
    Result<const CompiledProfile*> c = cache.compiled(r, max_bounces);
    if (!c) return report(c.error());
    setup->compiled.push_back(**c);
  }
  if (!scene.empty()) {
    Result<const SceneUniverse*> s = cache.scene(scene);
    if (!s) return report(s.error());
    setup->universe = (*s)->universe;
    setup->scene_ends = (*s)->ends;
  }
  return 0;
}

}  // namespace pathex::cli
