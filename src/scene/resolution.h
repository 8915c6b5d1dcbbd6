// --resolution WxH (trace, bias, converge): the image size asked for on the command line, applied
// to a loaded scene's camera.
#pragma once

#include <string>

#include "core/error.h"
#include "scene/scene.h"

namespace pathex {

// "640x480", each from 1 to 16384, into the camera; a spot meter measures one pixel. Errors (kUsage)
// name --resolution.
Result<bool> apply_resolution(const std::string& text, Camera* camera);

}  // namespace pathex
