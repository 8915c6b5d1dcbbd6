#include "scene/resolution.h"

namespace pathex {

Result<bool> apply_resolution(const std::string& text, Camera* camera) {
  Error e = make_error(ErrorCode::kUsage, "--resolution: expected WIDTHxHEIGHT with each from 1 to 16384, such as "
                                          "640x480; got '" + text + "'");
  const std::size_t x = text.find('x');
  if (x == std::string::npos || x == 0 || x + 1 == text.size() || x > 5 || text.size() - x - 1 > 5 ||
      text.find_first_not_of("0123456789x") != std::string::npos || text.find('x', x + 1) != std::string::npos)
    return e;
  const int w = std::stoi(text.substr(0, x)), h = std::stoi(text.substr(x + 1));
  if (w < 1 || h < 1 || w > 16384 || h > 16384) return e;
  if (camera->type == SensorType::kSpotmeter && (w != 1 || h != 1))
    return make_error(ErrorCode::kUsage, "--resolution: the scene's sensor is a spot meter, which measures one pixel "
                                         "(1x1); got '" + text + "'");
  camera->width = w;
  camera->height = h;
  return true;
}

}  // namespace pathex
