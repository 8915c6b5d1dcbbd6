// An image infinite light's image (scene.h: load_environment_image, pbrt_image_illuminance).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "io/image_read.h"
#include "scene/scene.h"
#include "optics/sphere_map.h"

namespace pathex {

Result<EnvironmentImage> load_environment_image(const std::string& path, const std::string& file, bool equal_area, glm::vec3 scale,
                                                const SceneLoadOptions& options, std::size_t* texels_so_far) {
  ImageReadOptions ro;
  ro.max_file_bytes = options.max_file_bytes;
  ro.max_texels = options.max_texels;
  ro.texels_so_far = texels_so_far;
  Result<LinearImage> img = read_image(path, ro);
  if (!img) return img.error();
  if (equal_area && img->width != img->height)
    return make_error(ErrorCode::kBadValue, "it is " + std::to_string(img->width) + " x " +
                                                std::to_string(img->height) +
                                                ": pbrt-v4's infinite light needs a square image (its equal-area mapping)");
  EnvironmentImage e;
  e.file = file;
  e.equal_area = equal_area;
  e.width = img->width;
  e.height = img->height;
  e.texels.resize(static_cast<std::size_t>(e.width) * static_cast<std::size_t>(e.height));
  for (std::size_t i = 0; i < e.texels.size(); ++i) {
    const glm::vec3 v(img->rgb[3 * i], img->rgb[3 * i + 1], img->rgb[3 * i + 2]);
    e.texels[i] = glm::max(v, glm::vec3(0.0f)) * scale;
  }
  return e;
}

double pbrt_image_illuminance(const EnvironmentImage& image) {
  double sum = 0.0;
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const glm::vec2 uv((static_cast<float>(x) + 0.5f) / static_cast<float>(image.width),
                         (static_cast<float>(y) + 0.5f) / static_cast<float>(image.height));
      const glm::vec3 w = equal_area_square_to_sphere(uv);
      if (w.z <= 0.0f) continue;
      const glm::vec3& t = image.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width) + static_cast<std::size_t>(x)];
      sum += (0.2126 * t.x + 0.7152 * t.y + 0.0722 * t.z) * static_cast<double>(w.z);
    }
  return sum * 2.0 * std::numbers::pi / (static_cast<double>(image.width) * static_cast<double>(image.height));
}

std::optional<std::string> settle_environment_values(EnvironmentImage* image) {
  for (std::size_t i = 0; i < image->texels.size(); ++i)
    for (int c = 0; c < 3; ++c) {
      float& v = image->texels[i][c];
      if (v > kMaxLightValue)
        return "the image '" + excerpt(image->file, kMaxPathBytes) + "' has a radiance of " + std::to_string(v) + " at texel (" +
               std::to_string(i % static_cast<std::size_t>(image->width)) + ", " + std::to_string(i / static_cast<std::size_t>(image->width)) +
               ") after its scale: expected at most 1e9 (the tracer sums contributions exactly below 2^50); scale the scene's lights down";
      if (v < kMinLightValue) v = 0.0f;
    }
  return std::nullopt;
}

}  // namespace pathex
