// What `pathex trace` checks before it renders, beyond the scene's own validation: the image
// size asked for on the command line, and lights that the renderer cannot sample at all (their
// light would be missing from the image without a word).
#pragma once

#include <string>

#include "core/error.h"
#include "core/limits.h"
#include "reach/query.h"
#include "scene/scene.h"

namespace pathex::cli {

// --resolution WxH, each from 1 to 16384, into the camera; a spot meter measures one pixel.
Result<bool> apply_resolution(const std::string& text, Camera* camera);

// Prints one warning per light from which `profile` (compiled as `compiled`, under `bound`, in
// the scene's `universe`) samples no path at all, naming the built-in renderers that do.
void warn_unreachable_lights(const Scene& scene, const Profile& profile, const CompiledProfile& compiled,
                             const Dfa& universe, int bound, const Limits& limits);

}  // namespace pathex::cli
