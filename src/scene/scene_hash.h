// The content hash of a scene: a 64-bit FNV-1a over everything a render reads from the model
// (geometry after transforms, materials, emission, lights, camera), not over file names or
// formatting. Two scene files that load to the same model have the same hash, wherever they
// live; editing a mesh changes it. Sharded renders and resumed renders compare it to refuse
// merging renders of different scenes.
#pragma once

#include <string>

#include "scene/scene.h"

namespace pathex {

std::string scene_content_hash(const Scene& scene);  // 16 hexadecimal digits

}  // namespace pathex
