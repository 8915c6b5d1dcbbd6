// The image infinite light's mappings, lookup and sampling (trace/environment.h).
#include "trace/environment.h"

#include <limits>
#include <numbers>

#include "trace/emitters.h"
#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex {

namespace {

// The image coordinates of a light-space direction, and the solid angle per unit (u, v) area there.
glm::vec2 to_uv(const EnvironmentMap& m, const glm::vec3& local) {
  return m.equal_area ? equal_area_sphere_to_square(local) : direction_to_latlong(local);
}
glm::vec3 from_uv(const EnvironmentMap& m, glm::vec2 uv) {
  return m.equal_area ? equal_area_square_to_sphere(uv) : latlong_to_direction(uv);
}
// dω / d(u, v): 4π for the equal-area square, 2π² sin θ for latitude-longitude (0 at the poles).
float jacobian(const EnvironmentMap& m, const glm::vec3& local) {
  if (m.equal_area) return 4.0f * kPi;
  return 2.0f * kPi * kPi * safe_sqrt(1.0f - local.y * local.y);
}
glm::vec3 to_local(const EnvironmentMap& m, const glm::vec3& w) { return glm::normalize(glm::transpose(m.to_world) * w); }

}  // namespace

void EnvironmentMap::build_distribution(bool uniform) {
  std::vector<float> weights(texels.size(), 1.0f);
  for (int y = 0; y < height; ++y) {
    const float sin_theta =
        !equal_area ? std::sin(kPi * (static_cast<float>(y) + 0.5f) / static_cast<float>(height)) : 1.0f;
    for (int x = 0; x < width; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * static_cast<std::size_t>(width) + static_cast<std::size_t>(x);
      const glm::vec3& t = texels[i];
      weights[i] = (uniform ? 1.0f : std::max((t.x + t.y + t.z) / 3.0f, 0.0f)) * sin_theta;
    }
  }
  distribution = Piecewise2D(weights, width, height);
}

glm::vec3 environment_radiance(const EnvironmentMap& m, const glm::vec3& w) {
  const glm::vec2 uv = to_uv(m, to_local(m, w));
  const int x = std::clamp(static_cast<int>(uv.x * static_cast<float>(m.width)), 0, m.width - 1);
  const int y = std::clamp(static_cast<int>(uv.y * static_cast<float>(m.height)), 0, m.height - 1);
  return m.texels[static_cast<std::size_t>(y) * static_cast<std::size_t>(m.width) + static_cast<std::size_t>(x)];
}

float environment_pdf(const EnvironmentMap& m, const glm::vec3& w) {
  const glm::vec3 local = to_local(m, w);
  const float j = jacobian(m, local);
  return j > 0.0f ? m.distribution.pdf(to_uv(m, local)) / j : 0.0f;
}

glm::vec3 sample_environment(const EnvironmentMap& m, glm::vec2 u, float* pdf) {
  float pdf_uv = 0.0f;
  const glm::vec2 uv = m.distribution.sample(u, &pdf_uv);
  const glm::vec3 local = from_uv(m, uv);
  const float j = jacobian(m, local);
  *pdf = j > 0.0f ? pdf_uv / j : 0.0f;
  return glm::normalize(m.to_world * local);
}

bool box_exit(const EnvironmentMap& m, const glm::vec3& o, const glm::vec3& d, glm::vec3* x, glm::vec3* n, float* t) {
  float best = std::numeric_limits<float>::infinity();
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0.0f) continue;
    const float ta = ((d[a] > 0.0f ? m.box_hi[a] : m.box_lo[a]) - o[a]) / d[a];
    if (ta < best) {
      best = ta;
      axis = a;
    }
  }
  if (axis < 0 || !(best > 0.0f) || !std::isfinite(best)) return false;
  *t = best;
  *x = o + best * d;
  (*x)[axis] = d[axis] > 0.0f ? m.box_hi[axis] : m.box_lo[axis];  // exactly on the face
  *n = glm::vec3(0.0f);
  (*n)[axis] = d[axis] > 0.0f ? -1.0f : 1.0f;
  return true;
}

glm::vec3 box_point_error(const glm::vec3& x) {
  // A few ulps of the coordinates' magnitude (the box's corners are exact; its faces' points are
  // computed with a handful of roundings).
  const float mag = std::max(std::abs(x.x), std::max(std::abs(x.y), std::abs(x.z)));
  return glm::vec3(8.0f * std::numeric_limits<float>::epsilon() * mag);
}

// --- the light's handles (trace/emitters.h) ---

std::optional<EndpointRay> sample_ray(const EnvironmentLightParams& p, glm::vec2 u_dir, glm::vec2 u_disk) {
  const EnvironmentMap& m = *p.map;
  float pdf = 0.0f;
  const glm::vec3 to_env = sample_environment(m, u_dir, &pdf);
  if (!(pdf > 0.0f)) return std::nullopt;
  const glm::vec3 w = -to_env;  // the way the light travels
  // A point of the disk through the centre perpendicular to w, and where its line along w enters the box.
  const Frame f = Frame::from_normal(w);
  const glm::vec2 d = sample_concentric_disk(u_disk) * m.radius;
  const glm::vec3 q = m.center + f.s * d.x + f.t * d.y;
  float t_in = -std::numeric_limits<float>::infinity(), t_out = std::numeric_limits<float>::infinity();
  int axis = -1;
  for (int a = 0; a < 3; ++a) {
    if (w[a] == 0.0f) {
      if (q[a] < m.box_lo[a] || q[a] > m.box_hi[a]) return std::nullopt;
      continue;
    }
    const float t0 = (m.box_lo[a] - q[a]) / w[a], t1 = (m.box_hi[a] - q[a]) / w[a];
    const float near = std::min(t0, t1), far = std::max(t0, t1);
    if (near > t_in) {
      t_in = near;
      axis = a;
    }
    t_out = std::min(t_out, far);
  }
  if (axis < 0 || !(t_in < t_out)) return std::nullopt;
  EndpointRay r;
  r.origin = q + t_in * w;
  r.origin[axis] = w[axis] > 0.0f ? m.box_lo[axis] : m.box_hi[axis];  // exactly on the face it enters
  r.normal = glm::vec3(0.0f);
  r.normal[axis] = w[axis] > 0.0f ? 1.0f : -1.0f;  // inwards
  r.direction = w;
  r.value = environment_radiance(m, to_env);
  const float disk = kPi * m.radius * m.radius;
  r.pdf = {std::abs(w[axis]) / disk, pdf, false, false};
  r.weight = r.value * (disk / pdf);  // L |cos| / (|cos| / (π R²) · p)
  r.pos_letter = EnvironmentLightParams::kPosLetter;
  r.dir_letter = EnvironmentLightParams::kDirLetter;
  return r;
}

std::optional<EndpointConnection> connect(const EnvironmentLightParams& p, glm::vec2 u, const glm::vec3& ref) {
  const EnvironmentMap& m = *p.map;
  float pdf = 0.0f;
  const glm::vec3 wi = sample_environment(m, u, &pdf);
  if (!(pdf > 0.0f)) return std::nullopt;
  EndpointConnection c;
  if (!box_exit(m, ref, wi, &c.position, &c.normal, &c.distance)) return std::nullopt;
  c.wi = wi;
  c.value = environment_radiance(m, wi);
  c.weight = c.value / pdf;  // L |cos θ_x| / d² over p |cos θ_x| / d²
  c.pdf_dir = pdf;
  return c;
}

float connect_area_density(const EnvironmentLightParams& p, const glm::vec3& x, const glm::vec3& n, const glm::vec3& ref) {
  const glm::vec3 e = x - ref;
  const float d2 = glm::dot(e, e);
  if (!(d2 > 0.0f)) return 0.0f;
  const glm::vec3 w = e / std::sqrt(d2);
  return environment_pdf(*p.map, w) * std::abs(glm::dot(n, w)) / d2;
}

}  // namespace pathex
