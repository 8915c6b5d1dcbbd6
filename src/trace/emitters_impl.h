// The definitions of emitters.h (see there for the conventions: symbolic deltas, the starting
// throughput `weight`, the image-mean normalisation of W_e). They are inline, in a header that
// emitters.h includes, because the integrator calls them through the handles on every vertex: as
// calls into another translation unit (std::visit cannot be inlined across one) they cost the
// Cornell box 4-6 % of its instructions (bench/README.md, "Emitters inline").
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <utility>
#include <variant>

#include <glm/geometric.hpp>

#include "trace/emitters.h"
#include "trace/frame.h"
#include "trace/rng.h"
#include "trace/spherical_rect.h"

namespace pathex {
namespace emitter_detail {

inline bool finite_vec(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

inline bool is_black(const glm::vec3& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

inline bool in_unit_square(glm::vec2 r) { return r.x >= 0.0f && r.x < 1.0f && r.y >= 0.0f && r.y < 1.0f; }

// Unit direction and length of `v`, or false when v is zero or not finite.
inline bool unit_and_length(const glm::vec3& v, glm::vec3* dir, float* length) {
  const float len = glm::length(v);
  if (!(len > 0.0f) || !std::isfinite(len)) return false;
  *dir = v * (1.0f / len);
  *length = len;
  return true;
}

// Film coordinates (2x − 1, 1 − 2y) of a raster position, and back.
inline glm::vec2 raster_to_film(glm::vec2 r) { return {2.0f * r.x - 1.0f, 1.0f - 2.0f * r.y}; }
inline glm::vec2 film_to_raster(glm::vec2 f) { return {0.5f * (f.x + 1.0f), 0.5f * (1.0f - f.y)}; }

// --- perspective image geometry shared by the pinhole and the thin lens ---

struct Perspective {
  glm::vec3 forward, right, up;
  float tan_half_x, tan_half_y;
  float image_area() const { return 4.0f * tan_half_x * tan_half_y; }
  // The unit-distance image point of a raster position, as a direction from the centre.
  glm::vec3 direction(glm::vec2 raster) const {
    const glm::vec2 f = emitter_detail::raster_to_film(raster);
    return glm::normalize(forward + (f.x * tan_half_x) * right + (f.y * tan_half_y) * up);
  }
  // The raster position of a direction with positive cos θ = dot(w, forward).
  glm::vec2 raster(const glm::vec3& w, float cos_theta) const {
    return emitter_detail::film_to_raster({glm::dot(w, right) / (cos_theta * tan_half_x),
                           glm::dot(w, up) / (cos_theta * tan_half_y)});
  }
};

inline Perspective perspective(const PinholeParams& p) {
  return {p.forward, p.right, p.up, p.tan_half_x, p.tan_half_y};
}
inline Perspective perspective(const ThinLensParams& p) {
  return {p.forward, p.right, p.up, p.tan_half_x, p.tan_half_y};
}

// 1 / (A cos⁴θ) and 1 / (A cos³θ), the pinhole's importance and direction density.
inline float perspective_we(float area, float cos_theta) {
  const float c2 = cos_theta * cos_theta;
  return 1.0f / (area * c2 * c2);
}
inline float perspective_pdf_dir(float area, float cos_theta) {
  return 1.0f / (area * cos_theta * cos_theta * cos_theta);
}

inline float lens_area(const ThinLensParams& p) { return kPi * p.lens_radius * p.lens_radius; }

}  // namespace emitter_detail

inline float area_to_solid_angle(float pdf_area, float distance, float abs_cos) {
  if (!(abs_cos > 0.0f)) return 0.0f;
  return pdf_area * (distance * distance) / abs_cos;
}

// --- area light ---

inline glm::vec3 emitted_radiance(const AreaLightParams& p, const glm::vec3& n, const glm::vec3& w) {
  const float c = glm::dot(n, w);
  if (c > 0.0f || (p.two_sided && c < 0.0f)) return p.radiance;
  return glm::vec3(0.0f);
}

inline std::optional<EndpointRay> sample_ray(const AreaLightParams& p, const SurfacePoint& x, glm::vec2 u) {
  if (!(x.pdf_area > 0.0f) || !std::isfinite(x.pdf_area)) return std::nullopt;
  float side = 1.0f;
  if (p.two_sided) {  // pick a side with u.x and stretch it back to [0, 1)
    side = u.x < 0.5f ? 1.0f : -1.0f;
    u.x = std::min(u.x < 0.5f ? 2.0f * u.x : 2.0f * u.x - 1.0f, kOneMinusEpsilon);
  }
  const glm::vec3 local = sample_cosine_hemisphere(u);
  if (!(local.z > 0.0f)) return std::nullopt;
  const Frame frame = Frame::from_normal(x.normal * side);
  EndpointRay r;
  r.origin = x.position;
  r.direction = glm::normalize(frame.to_world(local));
  r.normal = x.normal;
  r.value = p.radiance;
  const float sides = p.two_sided ? 2.0f : 1.0f;
  r.pdf = {x.pdf_area, local.z * kInvPi / sides, false, false};
  // Le cos / (p_A cos / (π · sides)) without the cosines.
  r.weight = p.radiance * (kPi * sides / x.pdf_area);
  r.pos_letter = AreaLightParams::kPosLetter;
  r.dir_letter = AreaLightParams::kDirLetter;
  return r;
}

inline RayPdf pdf_ray(const AreaLightParams& p, const SurfacePoint& x, const glm::vec3& direction) {
  const float c = glm::dot(x.normal, direction);
  const bool emits = c > 0.0f || (p.two_sided && c < 0.0f);
  const float sides = p.two_sided ? 2.0f : 1.0f;
  return {x.pdf_area, emits ? std::abs(c) * kInvPi / sides : 0.0f, false, false};
}

inline std::optional<EndpointConnection> connect(const AreaLightParams& p, const SurfacePoint& x,
                                          const glm::vec3& ref) {
  EndpointConnection c;
  if (!emitter_detail::unit_and_length(x.position - ref, &c.wi, &c.distance)) return std::nullopt;
  const float cos_signed = -glm::dot(x.normal, c.wi);  // at the light, towards ref
  const float cos_l = std::abs(cos_signed);
  const bool emits = cos_signed > 0.0f || (p.two_sided && cos_signed < 0.0f);  // as emitted_radiance()
  if (!emits || !(x.pdf_area > 0.0f)) return std::nullopt;
  c.value = p.radiance;
  c.position = x.position;
  c.normal = x.normal;
  c.pdf_dir = area_to_solid_angle(x.pdf_area, c.distance, cos_l);
  c.weight = c.value * (cos_l / (c.distance * c.distance * x.pdf_area));
  c.delta = false;
  if (!emitter_detail::finite_vec(c.weight) || !std::isfinite(c.pdf_dir)) return std::nullopt;
  return c;
}

namespace emitter_detail {
// The solid angle a light sampled towards points subtends at ref, and its sample there: the
// spherical rectangle (trace/spherical_rect.h) or the cone of a sphere seen from outside.
struct TowardsSolidAngle {
  const AreaLightParams* p = nullptr;
  SphericalRect rect;
  // The sphere's cone: sin²θ_max and 1 − cos θ_max (without cancellation), the axis from ref.
  double sin2_max = 0.0, one_minus_cos_max = 0.0;
  glm::dvec3 axis{0.0};
  double solid_angle = 0.0;
  bool usable = false;

  TowardsSolidAngle(const AreaLightParams& light, const glm::vec3& ref) : p(&light) {
    if (light.towards == AreaLightParams::Towards::kRectangle) {
      rect = SphericalRect::at(light.corner, light.edge1, light.edge2, ref);
      solid_angle = rect.solid_angle;
      usable = rect.usable();
      return;
    }
    const glm::dvec3 v = glm::dvec3(light.center) - glm::dvec3(ref);
    const double d2 = glm::dot(v, v), r2 = static_cast<double>(light.radius) * light.radius;
    // Inside, on or within a thousandth of the sphere (a point of its own surface): by area.
    if (!(d2 > r2 * 1.002) || !std::isfinite(d2)) return;
    sin2_max = r2 / d2;
    one_minus_cos_max = sin2_max / (1.0 + std::sqrt(1.0 - sin2_max));
    axis = v / std::sqrt(d2);
    solid_angle = 2.0 * std::numbers::pi * one_minus_cos_max;
    usable = solid_angle >= SphericalRect::kMinSolidAngle;
  }
  // The light's point in the direction u maps to (usable must hold).
  glm::vec3 sample(glm::vec2 u) const {
    if (p->towards == AreaLightParams::Towards::kRectangle) return rect.sample(u);
    // pbrt-v4's Sphere::Sample: cos θ uniform in [cos θ_max, 1], then the point of the sphere whose
    // normal makes the angle α with the direction back to ref.
    const double t = static_cast<double>(u.x) * one_minus_cos_max;  // 1 − cos θ
    const double cos_t = 1.0 - t, sin2_t = t * (2.0 - t);
    const double sin_max = std::sqrt(sin2_max);
    const double cos_a = std::clamp(sin2_t / sin_max + cos_t * std::sqrt(std::max(0.0, 1.0 - sin2_t / sin2_max)), -1.0, 1.0);
    const double sin_a = std::sqrt(std::max(0.0, 1.0 - cos_a * cos_a));
    const double phi = 2.0 * std::numbers::pi * static_cast<double>(u.y);
    const Frame f = Frame::from_normal(glm::vec3(axis));
    const glm::dvec3 x(f.to_world(glm::vec3(1.0f, 0.0f, 0.0f))), y(f.to_world(glm::vec3(0.0f, 1.0f, 0.0f)));
    const glm::dvec3 n = -(sin_a * std::cos(phi) * x + sin_a * std::sin(phi) * y + cos_a * axis);
    return glm::vec3(glm::dvec3(p->center) + static_cast<double>(p->radius) * n);
  }
  // A point's area density, at |cos| and squared distance d2 from ref.
  float density(float abs_cos, float d2) const {
    if (!usable) return p->pdf_area;
    return d2 > 0.0f ? abs_cos / (static_cast<float>(solid_angle) * d2) : 0.0f;
  }
};
// The light's unit normal at its point x.
inline glm::vec3 towards_normal(const AreaLightParams& p, const glm::vec3& x) {
  return p.towards == AreaLightParams::Towards::kRectangle ? p.normal : glm::normalize(x - p.center);
}
}  // namespace emitter_detail

inline std::optional<EndpointConnection> connect(const AreaLightParams& p, glm::vec2 u, const glm::vec3& ref) {
  const emitter_detail::TowardsSolidAngle r(p, ref);
  const bool solid = r.usable;
  EndpointConnection c;
  if (solid) {
    c.position = r.sample(u);
    c.normal = emitter_detail::towards_normal(p, c.position);
  } else if (p.towards == AreaLightParams::Towards::kRectangle) {
    c.position = p.corner + u.x * p.edge1 + u.y * p.edge2;
    c.normal = p.normal;
  } else {  // as EmbreeScene::sample_shape draws a sphere's point
    c.normal = sample_uniform_sphere(u);
    c.position = p.center + p.radius * c.normal;
  }
  if (!emitter_detail::unit_and_length(c.position - ref, &c.wi, &c.distance)) return std::nullopt;
  const float cos_signed = -glm::dot(c.normal, c.wi);  // at the light, towards ref
  const float cos_l = std::abs(cos_signed);
  const bool emits = cos_signed > 0.0f || (p.two_sided && cos_signed < 0.0f);  // as emitted_radiance()
  if (!emits || !(p.pdf_area > 0.0f)) return std::nullopt;
  c.value = p.radiance;
  const auto omega = static_cast<float>(r.solid_angle);
  c.pdf_dir = solid ? 1.0f / omega : area_to_solid_angle(p.pdf_area, c.distance, cos_l);
  // Le cos / (d² p_A): Le Ω where the density is 1 / Ω per solid angle.
  c.weight = solid ? c.value * omega : c.value * (cos_l / (c.distance * c.distance * p.pdf_area));
  c.delta = false;
  if (!emitter_detail::finite_vec(c.weight) || !std::isfinite(c.pdf_dir)) return std::nullopt;
  return c;
}

inline float towards_area_density(const AreaLightParams& p, const glm::vec3& x, const glm::vec3& n, const glm::vec3& ref) {
  const emitter_detail::TowardsSolidAngle r(p, ref);
  if (!r.usable) return p.pdf_area;
  const glm::vec3 e = x - ref;
  const float d2 = glm::dot(e, e);
  if (!(d2 > 0.0f)) return 0.0f;
  const float c = glm::dot(n, e) / std::sqrt(d2);
  // A sphere's cone reaches only the cap facing ref.
  if (p.towards == AreaLightParams::Towards::kSphere && !(c < 0.0f)) return 0.0f;
  return r.density(std::abs(c), d2);
}

inline float towards_step_density(const AreaLightParams& p, const glm::vec3& x0, const glm::vec3& n0, const glm::vec3& x1,
                                  float abs_cos1) {
  const glm::vec3 e = x1 - x0;
  const float d2 = glm::dot(e, e);
  if (!(d2 > 0.0f)) return 0.0f;
  const float c0 = glm::dot(n0, e) / std::sqrt(d2);
  if (!(c0 > 0.0f || (p.two_sided && c0 < 0.0f))) return 0.0f;
  const float sides = p.two_sided ? 2.0f : 1.0f;
  const emitter_detail::TowardsSolidAngle r(p, x1);
  if (!r.usable) return std::abs(c0) * kInvPi / sides * abs_cos1 / d2;  // the emission's pdf_dir, to area at x1
  if (p.towards == AreaLightParams::Towards::kSphere && !(c0 > 0.0f)) return 0.0f;  // x0 off the cap: density 0 above
  return p.pdf_area * abs_cos1 * static_cast<float>(r.solid_angle) * kInvPi / sides;
}

inline glm::vec3 power(const AreaLightParams& p, float area) {
  return p.radiance * (kPi * std::max(area, 0.0f) * (p.two_sided ? 2.0f : 1.0f));
}

// --- point light ---

inline std::optional<EndpointRay> sample_ray(const PointLightParams& p, glm::vec2 u) {
  EndpointRay r;
  r.origin = p.position;
  r.direction = sample_uniform_sphere(u);
  r.value = p.intensity;
  r.pdf = {0.0f, kUniformSpherePdf, true, false};
  r.weight = p.intensity * (4.0f * kPi);
  r.pos_letter = PointLightParams::kPosLetter;
  r.dir_letter = PointLightParams::kDirLetter;
  return r;
}

inline RayPdf pdf_ray(const PointLightParams&, const glm::vec3&) {
  return {0.0f, kUniformSpherePdf, true, false};
}

inline std::optional<EndpointConnection> connect(const PointLightParams& p, const glm::vec3& ref) {
  EndpointConnection c;
  if (!emitter_detail::unit_and_length(p.position - ref, &c.wi, &c.distance)) return std::nullopt;
  c.position = p.position;
  c.value = p.intensity;
  c.weight = p.intensity / (c.distance * c.distance);
  c.delta = true;
  if (!emitter_detail::finite_vec(c.weight)) return std::nullopt;
  return c;
}

inline glm::vec3 power(const PointLightParams& p) { return p.intensity * (4.0f * kPi); }

// --- spot light ---

inline float spot_falloff(const SpotLightParams& p, float cos_theta) {
  if (!(cos_theta > p.cos_total)) return 0.0f;  // the cone's boundary itself emits nothing
  if (cos_theta >= p.cos_falloff_start) return 1.0f;
  if (p.linear_in_angle) {
    const float total = std::acos(p.cos_total), start = std::acos(p.cos_falloff_start);
    return std::clamp((total - std::acos(cos_theta)) / (total - start), 0.0f, 1.0f);
  }
  const float t = (cos_theta - p.cos_total) / (p.cos_falloff_start - p.cos_total);
  return t * t * (3.0f - 2.0f * t);
}

inline glm::vec3 intensity(const SpotLightParams& p, const glm::vec3& direction) {
  return p.intensity * spot_falloff(p, glm::dot(direction, p.axis));
}

inline std::optional<EndpointRay> sample_ray(const SpotLightParams& p, glm::vec2 u) {
  const glm::vec3 local = sample_uniform_cone(u, p.cos_total);
  EndpointRay r;
  r.origin = p.position;
  r.direction = glm::normalize(Frame::from_normal(p.axis).to_world(local));
  r.value = p.intensity * spot_falloff(p, local.z);
  if (emitter_detail::is_black(r.value)) return std::nullopt;  // the cone's rim, where the falloff is 0
  const float pdf_dir = uniform_cone_pdf(p.cos_total);
  r.pdf = {0.0f, pdf_dir, true, false};
  r.weight = r.value / pdf_dir;
  r.pos_letter = SpotLightParams::kPosLetter;
  r.dir_letter = SpotLightParams::kDirLetter;
  return r;
}

inline RayPdf pdf_ray(const SpotLightParams& p, const glm::vec3& direction) {
  const bool inside = glm::dot(direction, p.axis) > p.cos_total;
  return {0.0f, inside ? uniform_cone_pdf(p.cos_total) : 0.0f, true, false};
}

inline std::optional<EndpointConnection> connect(const SpotLightParams& p, const glm::vec3& ref) {
  EndpointConnection c;
  if (!emitter_detail::unit_and_length(p.position - ref, &c.wi, &c.distance)) return std::nullopt;
  c.value = intensity(p, -c.wi);
  if (emitter_detail::is_black(c.value)) return std::nullopt;
  c.position = p.position;
  c.weight = c.value / (c.distance * c.distance);
  c.delta = true;
  if (!emitter_detail::finite_vec(c.weight)) return std::nullopt;
  return c;
}

inline glm::vec3 power(const SpotLightParams& p) {
  const float cs = p.cos_falloff_start, ct = p.cos_total;
  if (p.linear_in_angle && cs > ct) {
    const float ts = std::acos(cs), tt = std::acos(ct);
    return p.intensity * (2.0f * kPi * ((1.0f - cs) + ((tt - ts) * cs - std::sin(tt) + std::sin(ts)) / (tt - ts)));
  }
  return p.intensity * (2.0f * kPi * (1.0f - 0.5f * (cs + ct)));
}

// --- distant light through an aperture ---

inline float aperture_area(const DistantLightParams& p) { return glm::length(glm::cross(p.edge1, p.edge2)); }

namespace emitter_detail {
inline glm::vec3 aperture_normal(const DistantLightParams& p) {
  return glm::normalize(glm::cross(p.edge1, p.edge2));
}
// Parallelogram coordinates (a, b) of a point in the aperture's plane.
inline glm::vec2 aperture_coords(const DistantLightParams& p, const glm::vec3& x) {
  const glm::vec3 d = x - p.corner;
  const float e11 = glm::dot(p.edge1, p.edge1), e12 = glm::dot(p.edge1, p.edge2),
              e22 = glm::dot(p.edge2, p.edge2);
  const float d1 = glm::dot(d, p.edge1), d2 = glm::dot(d, p.edge2);
  const float det = e11 * e22 - e12 * e12;
  return {(d1 * e22 - d2 * e12) / det, (d2 * e11 - d1 * e12) / det};
}
}  // namespace emitter_detail

inline std::optional<EndpointRay> sample_ray(const DistantLightParams& p, glm::vec2 u) {
  const float area = aperture_area(p);
  if (!(area > 0.0f)) return std::nullopt;
  const glm::vec3 n = emitter_detail::aperture_normal(p);
  EndpointRay r;
  r.origin = p.corner + u.x * p.edge1 + u.y * p.edge2;
  r.direction = p.direction;
  r.normal = n;
  r.value = p.irradiance;
  r.pdf = {1.0f / area, 0.0f, false, true};
  r.weight = p.irradiance * (std::abs(glm::dot(n, p.direction)) * area);
  if (emitter_detail::is_black(r.weight)) return std::nullopt;  // light parallel to the aperture
  r.pos_letter = DistantLightParams::kPosLetter;
  r.dir_letter = DistantLightParams::kDirLetter;
  return r;
}

inline RayPdf pdf_ray(const DistantLightParams& p, const glm::vec3& origin) {
  const float area = aperture_area(p);
  const glm::vec2 ab = emitter_detail::aperture_coords(p, origin);
  const bool inside = area > 0.0f && ab.x >= 0.0f && ab.x < 1.0f && ab.y >= 0.0f && ab.y < 1.0f;
  return {inside ? 1.0f / area : 0.0f, 0.0f, false, true};
}

inline std::optional<EndpointConnection> connect(const DistantLightParams& p, const glm::vec3& ref) {
  const float area = aperture_area(p);
  if (!(area > 0.0f)) return std::nullopt;
  const glm::vec3 n = emitter_detail::aperture_normal(p);
  // ref − t · direction lies in the aperture's plane: t = dot(ref − corner, n) / dot(direction, n).
  const float denom = glm::dot(p.direction, n);
  if (denom == 0.0f) return std::nullopt;
  const float t = glm::dot(ref - p.corner, n) / denom;
  if (!(t > 0.0f) || !std::isfinite(t)) return std::nullopt;
  EndpointConnection c;
  c.position = ref - t * p.direction;
  const glm::vec2 ab = emitter_detail::aperture_coords(p, c.position);
  if (!(ab.x >= 0.0f && ab.x < 1.0f && ab.y >= 0.0f && ab.y < 1.0f)) return std::nullopt;
  c.normal = n;
  c.wi = -p.direction;
  c.distance = t;
  c.value = p.irradiance;
  c.weight = p.irradiance;  // E: the irradiance on a surface facing the light
  c.delta = true;
  return c;
}

inline glm::vec3 power(const DistantLightParams& p) {
  if (!(aperture_area(p) > 0.0f)) return glm::vec3(0.0f);
  return p.irradiance * (aperture_area(p) * std::abs(glm::dot(p.direction, emitter_detail::aperture_normal(p))));
}

// --- laser ---

inline std::optional<EndpointRay> sample_ray(const LaserParams& p) {
  EndpointRay r;
  r.origin = p.position;
  r.direction = p.direction;
  r.value = p.power;
  r.pdf = pdf_ray(p);
  r.weight = p.power;
  r.pos_letter = LaserParams::kPosLetter;
  r.dir_letter = LaserParams::kDirLetter;
  return r;
}

inline RayPdf pdf_ray(const LaserParams&) { return {0.0f, 0.0f, true, true}; }

inline std::optional<EndpointConnection> connect(const LaserParams&, const glm::vec3&) {
  return std::nullopt;
}

inline glm::vec3 power(const LaserParams& p) { return p.power; }

// --- pinhole ---

inline std::optional<EndpointRay> sample_ray(const PinholeParams& p, glm::vec2 raster) {
  const emitter_detail::Perspective cam = emitter_detail::perspective(p);
  EndpointRay r;
  r.origin = p.position;
  r.direction = cam.direction(raster);
  r.normal = p.forward;
  const float cos_theta = glm::dot(r.direction, p.forward);
  if (!(cos_theta > 0.0f)) return std::nullopt;
  const float pdf_dir = emitter_detail::perspective_pdf_dir(cam.image_area(), cos_theta);
  r.value = glm::vec3(pdf_dir / cos_theta);  // We = 1 / (A cos⁴θ)
  r.pdf = {0.0f, pdf_dir, true, false};
  r.weight = glm::vec3(1.0f);  // We cos / p_dir = 1 exactly
  r.pos_letter = PinholeParams::kPosLetter;
  r.dir_letter = PinholeParams::kDirLetter;
  r.raster = raster;
  return r;
}

inline glm::vec3 importance(const PinholeParams& p, const glm::vec3& direction, glm::vec2* raster) {
  const float cos_theta = glm::dot(direction, p.forward);
  if (!(cos_theta > 0.0f)) return glm::vec3(0.0f);
  const emitter_detail::Perspective cam = emitter_detail::perspective(p);
  const glm::vec2 r = cam.raster(direction, cos_theta);
  if (!emitter_detail::in_unit_square(r)) return glm::vec3(0.0f);
  if (raster) *raster = r;
  return glm::vec3(emitter_detail::perspective_we(cam.image_area(), cos_theta));
}

inline RayPdf pdf_ray(const PinholeParams& p, const glm::vec3& direction) {
  // importance()'s test of the image, without its value (MIS asks for this density often).
  const float cos_theta = glm::dot(direction, p.forward);
  if (!(cos_theta > 0.0f)) return {0.0f, 0.0f, true, false};
  const emitter_detail::Perspective cam = emitter_detail::perspective(p);
  if (!emitter_detail::in_unit_square(cam.raster(direction, cos_theta))) return {0.0f, 0.0f, true, false};
  return {0.0f, emitter_detail::perspective_pdf_dir(cam.image_area(), cos_theta), true, false};
}

inline std::optional<EndpointConnection> connect(const PinholeParams& p, const glm::vec3& ref) {
  EndpointConnection c;
  if (!emitter_detail::unit_and_length(p.position - ref, &c.wi, &c.distance)) return std::nullopt;
  c.value = importance(p, -c.wi, &c.raster);
  if (emitter_detail::is_black(c.value)) return std::nullopt;
  const float cos_theta = glm::dot(-c.wi, p.forward);
  c.position = p.position;
  c.normal = p.forward;
  c.weight = c.value * (cos_theta / (c.distance * c.distance));
  c.delta = true;
  if (!emitter_detail::finite_vec(c.weight)) return std::nullopt;
  return c;
}

// --- thin lens ---

inline glm::vec3 lens_point(const ThinLensParams& p, glm::vec2 u_lens) {
  const glm::vec2 d = sample_concentric_disk(u_lens) * p.lens_radius;
  return p.position + d.x * p.right + d.y * p.up;
}

inline std::optional<EndpointRay> sample_ray(const ThinLensParams& p, glm::vec2 raster, glm::vec2 u_lens) {
  if (!(p.lens_radius > 0.0f) || !(p.focus_distance > 0.0f)) return std::nullopt;
  const emitter_detail::Perspective cam = emitter_detail::perspective(p);
  // The point on the plane of focus that the pinhole ray through the lens centre would reach.
  const glm::vec3 pinhole_dir = cam.direction(raster);
  const glm::vec3 focus =
      p.position + pinhole_dir * (p.focus_distance / glm::dot(pinhole_dir, p.forward));
  EndpointRay r;
  r.origin = lens_point(p, u_lens);
  float dist;
  if (!emitter_detail::unit_and_length(focus - r.origin, &r.direction, &dist)) return std::nullopt;
  r.normal = p.forward;
  const float cos_theta = glm::dot(r.direction, p.forward);
  if (!(cos_theta > 0.0f)) return std::nullopt;
  const float area = cam.image_area();
  const float a_lens = emitter_detail::lens_area(p);
  r.value = glm::vec3(emitter_detail::perspective_we(area, cos_theta) / a_lens);
  r.pdf = {1.0f / a_lens, emitter_detail::perspective_pdf_dir(area, cos_theta), false, false};
  r.weight = glm::vec3(1.0f);  // We cos / (p_pos p_dir) = 1 exactly
  r.pos_letter = ThinLensParams::kPosLetter;
  r.dir_letter = ThinLensParams::kDirLetter;
  r.raster = raster;
  return r;
}

inline glm::vec3 importance(const ThinLensParams& p, const glm::vec3& origin, const glm::vec3& direction,
                     glm::vec2* raster) {
  const float cos_theta = glm::dot(direction, p.forward);
  if (!(cos_theta > 0.0f) || !(p.lens_radius > 0.0f)) return glm::vec3(0.0f);
  // Off the lens there is no importance (the tolerance admits lens_point()'s rounding at the rim).
  const glm::vec3 off = origin - p.position;
  const float lu = glm::dot(off, p.right), lv = glm::dot(off, p.up);
  if (!(lu * lu + lv * lv <= p.lens_radius * p.lens_radius * (1.0f + 1e-5f))) return glm::vec3(0.0f);
  // Where the ray meets the plane of focus, seen from the lens centre.
  const glm::vec3 focus = origin + direction * (p.focus_distance / cos_theta);
  const glm::vec3 v = focus - p.position;
  const float depth = glm::dot(v, p.forward);
  if (!(depth > 0.0f)) return glm::vec3(0.0f);
  const emitter_detail::Perspective cam = emitter_detail::perspective(p);
  const glm::vec2 r = emitter_detail::film_to_raster({glm::dot(v, p.right) / (depth * p.tan_half_x),
                                      glm::dot(v, p.up) / (depth * p.tan_half_y)});
  if (!emitter_detail::in_unit_square(r)) return glm::vec3(0.0f);
  if (raster) *raster = r;
  return glm::vec3(emitter_detail::perspective_we(cam.image_area(), cos_theta) / emitter_detail::lens_area(p));
}

inline RayPdf pdf_ray(const ThinLensParams& p, const glm::vec3& origin, const glm::vec3& direction) {
  glm::vec2 raster;
  if (emitter_detail::is_black(importance(p, origin, direction, &raster))) return {0.0f, 0.0f, false, false};
  const float cos_theta = glm::dot(direction, p.forward);
  return {1.0f / emitter_detail::lens_area(p), emitter_detail::perspective_pdf_dir(emitter_detail::perspective(p).image_area(), cos_theta), false,
          false};
}

namespace emitter_detail {
// The join of `ref` to the lens point `x`.
inline std::optional<EndpointConnection> connect_lens_point(const ThinLensParams& p, const glm::vec3& x,
                                                     const glm::vec3& ref) {
  EndpointConnection c;
  if (!emitter_detail::unit_and_length(x - ref, &c.wi, &c.distance)) return std::nullopt;
  c.value = importance(p, x, -c.wi, &c.raster);
  if (emitter_detail::is_black(c.value)) return std::nullopt;
  const float cos_lens = glm::dot(-c.wi, p.forward);
  const float a_lens = emitter_detail::lens_area(p);
  c.position = x;
  c.normal = p.forward;
  c.pdf_dir = area_to_solid_angle(1.0f / a_lens, c.distance, cos_lens);
  c.weight = c.value * (cos_lens * a_lens / (c.distance * c.distance));
  c.delta = false;
  if (!emitter_detail::finite_vec(c.weight) || !std::isfinite(c.pdf_dir)) return std::nullopt;
  return c;
}
}  // namespace emitter_detail

inline std::optional<EndpointConnection> connect(const ThinLensParams& p, glm::vec2 u_lens,
                                          const glm::vec3& ref) {
  if (!(p.lens_radius > 0.0f)) return std::nullopt;
  return emitter_detail::connect_lens_point(p, lens_point(p, u_lens), ref);
}

inline std::optional<EndpointConnection> hit_lens(const ThinLensParams& p, const glm::vec3& origin,
                                           const glm::vec3& direction) {
  if (!(p.lens_radius > 0.0f)) return std::nullopt;
  const float denom = glm::dot(direction, p.forward);
  if (denom == 0.0f) return std::nullopt;
  const float t = glm::dot(p.position - origin, p.forward) / denom;
  if (!(t > 0.0f) || !std::isfinite(t)) return std::nullopt;
  const glm::vec3 x = origin + t * direction;
  const glm::vec3 off = x - p.position;
  const float u = glm::dot(off, p.right), v = glm::dot(off, p.up);
  if (!(u * u + v * v < p.lens_radius * p.lens_radius)) return std::nullopt;
  return emitter_detail::connect_lens_point(p, x, origin);
}

// --- orthographic ---

namespace emitter_detail {
inline float film_area(const OrthographicParams& p) { return 4.0f * p.half_width * p.half_height; }
}  // namespace emitter_detail

inline std::optional<EndpointRay> sample_ray(const OrthographicParams& p, glm::vec2 raster) {
  const float area = emitter_detail::film_area(p);
  if (!(area > 0.0f)) return std::nullopt;
  const glm::vec2 f = emitter_detail::raster_to_film(raster);
  EndpointRay r;
  r.origin = p.position + (f.x * p.half_width) * p.right + (f.y * p.half_height) * p.up;
  r.direction = p.forward;
  r.normal = p.forward;
  r.value = glm::vec3(1.0f / area);
  r.pdf = {1.0f / area, 0.0f, false, true};
  r.weight = glm::vec3(1.0f);  // We / (1/A): 1 exactly (the Dirac direction has no density)
  r.pos_letter = OrthographicParams::kPosLetter;
  r.dir_letter = OrthographicParams::kDirLetter;
  r.raster = raster;
  return r;
}

inline RayPdf pdf_ray(const OrthographicParams& p, const glm::vec3& origin) {
  const float area = emitter_detail::film_area(p);
  const glm::vec3 d = origin - p.position;
  const glm::vec2 r =
      emitter_detail::film_to_raster({glm::dot(d, p.right) / p.half_width, glm::dot(d, p.up) / p.half_height});
  const bool inside = area > 0.0f && emitter_detail::in_unit_square(r);
  return {inside ? 1.0f / area : 0.0f, 0.0f, false, true};
}

inline std::optional<EndpointConnection> connect(const OrthographicParams& p, const glm::vec3& ref) {
  const float area = emitter_detail::film_area(p);
  if (!(area > 0.0f)) return std::nullopt;
  const glm::vec3 d = ref - p.position;
  const float depth = glm::dot(d, p.forward);
  if (!(depth > 0.0f) || !std::isfinite(depth)) return std::nullopt;
  EndpointConnection c;
  c.raster =
      emitter_detail::film_to_raster({glm::dot(d, p.right) / p.half_width, glm::dot(d, p.up) / p.half_height});
  if (!emitter_detail::in_unit_square(c.raster)) return std::nullopt;
  c.position = ref - depth * p.forward;
  c.normal = p.forward;
  c.wi = -p.forward;
  c.distance = depth;
  c.value = glm::vec3(1.0f / area);
  c.weight = c.value;  // We: the film point's share of the image mean
  c.delta = true;
  return c;
}

// --- spot meter ---

inline std::optional<EndpointRay> sample_ray(const SpotMeterParams& p) {
  EndpointRay r;
  r.origin = p.position;
  r.direction = p.direction;
  r.value = glm::vec3(1.0f);
  r.pdf = pdf_ray(p);
  r.weight = glm::vec3(1.0f);
  r.pos_letter = SpotMeterParams::kPosLetter;
  r.dir_letter = SpotMeterParams::kDirLetter;
  r.raster = {0.5f, 0.5f};
  return r;
}

inline RayPdf pdf_ray(const SpotMeterParams&) { return {0.0f, 0.0f, true, true}; }

inline std::optional<EndpointConnection> connect(const SpotMeterParams&, const glm::vec3&) {
  return std::nullopt;
}

// --- the handles ---

namespace emitter_detail {
template <class... F>
struct Overloaded : F... {
  using F::operator()...;
};
template <class... F>
Overloaded(F...) -> Overloaded<F...>;

// std::visit as a chain of index tests, which the compiler inlines with the kind's function
// (GCC compiles std::visit to a table of calls that it does not inline): the integrator's calls
// through the handles then cost what a switch over the kinds would.
template <std::size_t I = 0, class F, class V>
[[gnu::always_inline]] inline decltype(auto) visit(F&& f, const V& v) {
  if constexpr (I + 1 == std::variant_size_v<V>) {
    return f(*std::get_if<I>(&v));
  } else {
    if (v.index() == I) return f(*std::get_if<I>(&v));
    return visit<I + 1>(std::forward<F>(f), v);
  }
}
}  // namespace emitter_detail

inline Letter pos_letter(const LightParams& l) {
  return emitter_detail::visit([](const auto& p) { return std::decay_t<decltype(p)>::kPosLetter; }, l);
}
inline Letter dir_letter(const LightParams& l) {
  return emitter_detail::visit([](const auto& p) { return std::decay_t<decltype(p)>::kDirLetter; }, l);
}
inline Letter pos_letter(const SensorParams& s) {
  return emitter_detail::visit([](const auto& p) { return std::decay_t<decltype(p)>::kPosLetter; }, s);
}
inline Letter dir_letter(const SensorParams& s) {
  return emitter_detail::visit([](const auto& p) { return std::decay_t<decltype(p)>::kDirLetter; }, s);
}

inline std::optional<EndpointRay> sample_ray(const LightParams& l, const SurfacePoint& x, glm::vec2 u) {
  return emitter_detail::visit(emitter_detail::Overloaded{[&](const AreaLightParams& p) { return sample_ray(p, x, u); },
                               [&](const LaserParams& p) { return sample_ray(p); },
                               [](const EnvironmentLightParams&) { return std::optional<EndpointRay>(); },
                               [&](const auto& p) { return sample_ray(p, u); }},
                    l);
}

inline RayPdf pdf_ray(const LightParams& l, const SurfacePoint& x, const glm::vec3& direction) {
  return emitter_detail::visit(emitter_detail::Overloaded{[&](const AreaLightParams& p) { return pdf_ray(p, x, direction); },
                               [&](const DistantLightParams& p) { return pdf_ray(p, x.position); },
                               [&](const LaserParams& p) { return pdf_ray(p); },
                               [&](const EnvironmentLightParams& p) { return RayPdf{0.0f, environment_pdf(*p.map, -direction), false, false}; },
                               [&](const auto& p) { return pdf_ray(p, direction); }},
                    l);
}

inline std::optional<EndpointConnection> connect(const LightParams& l, const SurfacePoint& x,
                                          const glm::vec3& ref) {
  return emitter_detail::visit(emitter_detail::Overloaded{[&](const AreaLightParams& p) { return connect(p, x, ref); },
                               [](const EnvironmentLightParams&) { return std::optional<EndpointConnection>(); },
                               [&](const auto& p) { return connect(p, ref); }},
                    l);
}

inline bool draws_towards(const LightParams& l) {
  if (const auto* a = std::get_if<AreaLightParams>(&l)) return a->towards != AreaLightParams::Towards::kNone;
  return std::holds_alternative<EnvironmentLightParams>(l);
}

inline std::optional<EndpointConnection> connect_towards(const LightParams& l, glm::vec2 u, const glm::vec3& ref) {
  if (const auto* a = std::get_if<AreaLightParams>(&l)) return connect(*a, u, ref);
  if (const auto* e = std::get_if<EnvironmentLightParams>(&l)) return connect(*e, u, ref);
  return std::nullopt;
}

inline float towards_area_density(const LightParams& l, const glm::vec3& x, const glm::vec3& n, const glm::vec3& ref) {
  if (const auto* a = std::get_if<AreaLightParams>(&l)) return towards_area_density(*a, x, n, ref);
  if (const auto* e = std::get_if<EnvironmentLightParams>(&l)) return connect_area_density(*e, x, n, ref);
  return 0.0f;
}

inline float towards_step_density(const LightParams& l, const glm::vec3& x0, const glm::vec3& n0, const glm::vec3& x1, float abs_cos1) {
  if (const auto* a = std::get_if<AreaLightParams>(&l)) return towards_step_density(*a, x0, n0, x1, abs_cos1);
  if (const auto* e = std::get_if<EnvironmentLightParams>(&l)) return emission_step_density(*e, abs_cos1);
  return 0.0f;
}

inline glm::vec3 spatial_emission(const LightParams& l) {
  return emitter_detail::visit(emitter_detail::Overloaded{[](const AreaLightParams& p) { return p.radiance; },
                               [](const PointLightParams& p) { return p.intensity; },
                               [](const SpotLightParams& p) { return p.intensity; },
                               [](const DistantLightParams& p) { return p.irradiance; },
                               [](const LaserParams& p) { return p.power; },
                               [](const EnvironmentLightParams&) { return glm::vec3(1.0f); }},
                    l);
}

inline float directional_emission(const LightParams& l, const glm::vec3& n, const glm::vec3& w) {
  return emitter_detail::visit(
      emitter_detail::Overloaded{[&](const AreaLightParams& p) { return emitter_detail::is_black(emitted_radiance(p, n, w)) ? 0.0f : 1.0f; },
                 [](const PointLightParams&) { return 1.0f; },
                 [&](const SpotLightParams& p) { return spot_falloff(p, glm::dot(w, p.axis)); },
                 [&](const EnvironmentLightParams&) { return glm::dot(n, w) > 0.0f ? 1.0f : 0.0f; },
                 [](const auto&) { return 0.0f; }},
      l);
}

inline glm::vec3 emitted(const LightParams& l, const glm::vec3& n, const glm::vec3& w) {
  if (const auto* e = std::get_if<EnvironmentLightParams>(&l)) return environment_radiance(*e->map, -w);
  return spatial_emission(l) * directional_emission(l, n, w);
}

inline glm::vec3 fixed_origin(const LightParams& l) {
  return emitter_detail::visit(emitter_detail::Overloaded{[](const PointLightParams& p) { return p.position; },
                                                          [](const SpotLightParams& p) { return p.position; },
                                                          [](const LaserParams& p) { return p.position; },
                                                          [](const auto&) { return glm::vec3(0.0f); }},
                               l);
}

inline std::optional<EndpointConnection> connect_projection(const LightParams& l, const glm::vec3& ref) {
  if (const auto* d = std::get_if<DistantLightParams>(&l)) return connect(*d, ref);
  return std::nullopt;
}

inline std::optional<EndpointRay> sample_ray(const SensorParams& s, glm::vec2 raster, glm::vec2 u_lens) {
  return emitter_detail::visit(emitter_detail::Overloaded{[&](const ThinLensParams& p) { return sample_ray(p, raster, u_lens); },
                               [&](const SpotMeterParams& p) { return sample_ray(p); },
                               [&](const auto& p) { return sample_ray(p, raster); }},
                    s);
}

inline RayPdf pdf_ray(const SensorParams& s, const glm::vec3& origin, const glm::vec3& direction) {
  return emitter_detail::visit(emitter_detail::Overloaded{[&](const PinholeParams& p) { return pdf_ray(p, direction); },
                               [&](const ThinLensParams& p) { return pdf_ray(p, origin, direction); },
                               [&](const OrthographicParams& p) { return pdf_ray(p, origin); },
                               [&](const SpotMeterParams& p) { return pdf_ray(p); }},
                    s);
}

inline std::optional<EndpointConnection> connect_finite(const SensorParams& s, glm::vec2 u_lens,
                                                 const glm::vec3& ref) {
  return emitter_detail::visit(
      emitter_detail::Overloaded{[&](const PinholeParams& p) { return connect(p, ref); },
                 [&](const ThinLensParams& p) { return connect(p, u_lens, ref); },
                 [](const auto&) { return std::optional<EndpointConnection>(); }},
      s);
}

inline glm::vec3 importance(const SensorParams& s, const glm::vec3& origin, const glm::vec3& direction,
                     glm::vec2* raster) {
  return emitter_detail::visit(
      emitter_detail::Overloaded{[&](const PinholeParams& p) { return importance(p, direction, raster); },
                 [&](const ThinLensParams& p) { return importance(p, origin, direction, raster); },
                 [](const auto&) { return glm::vec3(0.0f); }},
      s);
}

inline std::optional<EndpointConnection> connect_projection(const SensorParams& s, const glm::vec3& ref) {
  if (const auto* o = std::get_if<OrthographicParams>(&s)) return connect(*o, ref);
  return std::nullopt;
}

inline glm::vec3 sensor_point(const SensorParams& s, glm::vec2 u_lens) {
  if (const auto* lens = std::get_if<ThinLensParams>(&s)) return lens_point(*lens, u_lens);
  return emitter_detail::visit([](const auto& p) { return p.position; }, s);
}

inline std::optional<EndpointConnection> hit_lens(const SensorParams& s, const glm::vec3& origin,
                                           const glm::vec3& direction) {
  if (const auto* p = std::get_if<ThinLensParams>(&s)) return hit_lens(*p, origin, direction);
  return std::nullopt;
}

}  // namespace pathex
