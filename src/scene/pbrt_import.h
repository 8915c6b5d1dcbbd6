// pbrt-v4 scenes (.pbrt) imported into the scene model. The subset and its mapping are in the
// README ("Importing pbrt-v4 and Mitsuba 3 scenes"); everything outside it is refused with the
// file, line and column of the directive or parameter and what is not supported, so that no
// light, shape or material is ever silently dropped.
#pragma once

#include <string>

#include "scene/scene.h"

namespace pathex {

Result<Scene> load_scene_pbrt(const std::string& path, const SceneLoadOptions& options = {});

}  // namespace pathex
