#include "check/reach_cache.h"

#include "io/profile_json.h"
#include "scene/scene.h"
#include "scene/universe.h"

namespace pathex {

Result<const Profile*> ReachCache::profile(const std::string& name_or_path) {
  auto it = profiles_.find(name_or_path);
  if (it != profiles_.end()) return static_cast<const Profile*>(&it->second);
  Result<Profile> p = resolve_profile(name_or_path, limits_);
  if (!p) return p.error();
  return static_cast<const Profile*>(&profiles_.emplace(name_or_path, std::move(*p)).first->second);
}

Result<const CompiledProfile*> ReachCache::compiled(const std::string& name_or_path, std::optional<int> max_bounces) {
  const auto key = std::make_pair(name_or_path, max_bounces ? *max_bounces : -1);
  auto it = compiled_.find(key);
  if (it != compiled_.end()) return static_cast<const CompiledProfile*>(&it->second);
  Result<const Profile*> p = profile(name_or_path);
  if (!p) return p.error();
  Result<CompiledProfile> c = compile_profile(**p, max_bounces, limits_);
  if (!c) return c.error();
  return static_cast<const CompiledProfile*>(&compiled_.emplace(key, std::move(*c)).first->second);
}

Result<const SceneUniverse*> ReachCache::scene(const std::string& path) {
  auto it = scenes_.find(path);
  if (it != scenes_.end()) return static_cast<const SceneUniverse*>(&it->second);
  // The universe needs the scene's light, sensor and material types, never its triangles.
  Result<Scene> s = load_scene_file(path, scene_load_options(limits_, /*triangles=*/false));
  if (!s) return s.error();
  const SceneTypes types = scene_types(*s);
  SceneUniverse u;
  u.universe = scene_universe(types);
  u.ends.lights.assign(types.lights.begin(), types.lights.end());
  u.ends.sensors = {types.sensor};
  u.summary = describe(types);
  return static_cast<const SceneUniverse*>(&scenes_.emplace(path, std::move(u)).first->second);
}

}  // namespace pathex
