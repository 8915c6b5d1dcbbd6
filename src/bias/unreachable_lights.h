// Lights that a renderer cannot sample at all (their light would be missing from the image without
// a word: pt and a point light make a black image), found by the checker before `pathex trace`
// renders, with the built-in renderers that do reach them.
#pragma once

#include <string>
#include <vector>

#include "alphabet/alphabet.h"
#include "core/limits.h"
#include "reach/query.h"
#include "scene/scene.h"

namespace pathex {

struct UnreachableLight {
  std::string description;  // "the point light at (0, 1.9, 0)", "the emissive shape /shapes/3"
  LightType type;
  std::string reached_by;   // "bdpt, lt", or "none of the built-in renderers"
};

// One entry per light of `scene` from which `profile` (compiled as `compiled`, under `bound`, in the
// scene's `universe`) samples no path at all, in the scene's order (emissive shapes, then lights).
std::vector<UnreachableLight> unreachable_lights(const Scene& scene, const Profile& profile, const CompiledProfile& compiled,
                                                 const Dfa& universe, int bound, const Limits& limits);

}  // namespace pathex
