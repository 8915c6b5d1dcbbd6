// Mitsuba 3 scenes (.xml) imported into the scene model through pugixml. The subset and its
// mapping are in the README ("Importing pbrt-v4 and Mitsuba 3 scenes"); every other plugin,
// property or tag is refused with the file, line and column of its element and what is not
// supported, so that no light, shape or material is ever silently dropped.
#pragma once

#include <string>

#include "scene/scene.h"

namespace pathex {

Result<Scene> load_scene_mitsuba(const std::string& path, const SceneLoadOptions& options = {});

}  // namespace pathex
