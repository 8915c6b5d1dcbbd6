// What `pathex trace` warns of before it renders: lights that the renderer cannot sample at all
// (bias/unreachable_lights.h). --resolution is scene/resolution.h.
#pragma once

#include <string>

#include "core/error.h"
#include "core/limits.h"
#include "reach/query.h"
#include "scene/resolution.h"
#include "scene/scene.h"

namespace pathex::cli {

// Prints to stderr one warning per light from which `profile` (compiled as `compiled`, under `bound`, in
// the scene's `universe`) samples no path at all, naming the built-in renderers that do.
void warn_unreachable_lights(const Scene& scene, const Profile& profile, const CompiledProfile& compiled,
                             const Dfa& universe, int bound, const Limits& limits);

}  // namespace pathex::cli
