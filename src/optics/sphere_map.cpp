#include "optics/sphere_map.h"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace pathex {
namespace {

constexpr float kPi = std::numbers::pi_v<float>;
constexpr float kInvPi = std::numbers::inv_pi_v<float>;
float sqrt_nonnegative(float x) { return std::sqrt(std::max(x, 0.0f)); }

}  // namespace

glm::vec3 equal_area_square_to_sphere(glm::vec2 p) {
  // The square to [-1,1]², folded into the first quadrant; r is 1 − the distance from the
  // diamond |u| + |v| = 1 (the equator), z's sign says inside (+z) or outside (−z).
  const float u = 2.0f * p.x - 1.0f, v = 2.0f * p.y - 1.0f;
  const float up = std::abs(u), vp = std::abs(v);
  const float signed_distance = 1.0f - (up + vp);
  const float r = 1.0f - std::abs(signed_distance);
  const float phi = (r == 0.0f ? 1.0f : (vp - up) / r + 1.0f) * kPi / 4.0f;
  const float z = std::copysign(1.0f - r * r, signed_distance);
  const float s = r * sqrt_nonnegative(2.0f - r * r);
  return {std::copysign(std::cos(phi), u) * s, std::copysign(std::sin(phi), v) * s, z};
}

glm::vec2 equal_area_sphere_to_square(const glm::vec3& d) {
  const float x = std::abs(d.x), y = std::abs(d.y), z = std::abs(d.z);
  const float r = sqrt_nonnegative(1.0f - z);
  const float a = std::max(x, y);
  const float b = a == 0.0f ? 0.0f : std::min(x, y) / a;
  float phi = std::atan(b) * (2.0f / kPi);  // in [0, 1]: the angle from the nearer axis
  if (x < y) phi = 1.0f - phi;
  float v = phi * r;
  float u = r - v;
  if (d.z < 0.0f) {  // the lower hemisphere maps outside the diamond
    std::swap(u, v);
    u = 1.0f - u;
    v = 1.0f - v;
  }
  u = std::copysign(u, d.x);
  v = std::copysign(v, d.y);
  return {0.5f * (u + 1.0f), 0.5f * (v + 1.0f)};
}

glm::vec3 latlong_to_direction(glm::vec2 uv) {
  const float phi = 2.0f * kPi * uv.x, theta = kPi * uv.y;
  const float st = std::sin(theta);
  return {std::sin(phi) * st, std::cos(theta), -std::cos(phi) * st};
}

glm::vec2 direction_to_latlong(const glm::vec3& d) {
  float u = std::atan2(d.x, -d.z) * (0.5f / kPi);
  if (u < 0.0f) u += 1.0f;
  const float v = std::acos(std::clamp(d.y, -1.0f, 1.0f)) * kInvPi;
  return {std::min(u, 0x1.fffffep-1f), v};
}

}  // namespace pathex
