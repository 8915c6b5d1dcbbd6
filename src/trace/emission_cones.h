// Emission aimed at the shapes a requested path can reach first (pathex trace --only, DESIGN §11).
//
// When every requested path's first surface vertex scatters specularly (caustics, `L..S+D.*..E`),
// a light subpath whose first ray misses every shape with a specular component makes no requested
// path: under --only it is traced for one ray and stopped (trace/prune.h), and with a point light
// above a glass sphere that is 97 % of them. For a point or spot light, EmissionCones draws the
// first direction only within the cones from the light that bound those shapes (Jensen's
// projection maps for caustic photons), with density
//
//     p(w) = (number of cones holding w) / (sum of the cones' solid angles),
//
// nonzero towards every point of every such shape. So each requested path keeps a nonzero density
// and its estimate its expectation; only its variance changes. The MIS weights of a requested path
// do not depend on this density: every strategy that samples it traced the light's first ray (the
// ones that did not, s = 0 and s = 1, would join at its specular first vertex). It is still the
// light's directional density wherever the integrator asks for one, so that the emitter model and
// the walk agree on every path: aimed_ray() and aimed_pdf() below decorate the light's own ray
// sampling (trace/emitters.h), and a light the plan aims (trace/plan.h) answers through them
// (RenderLight::sample_ray, RenderLight::pdf_ray in trace/render_scene.h).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "trace/emitters.h"
#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex {

// A sphere holding a shape (RenderScene::specular_bounds).
struct BoundingSphere {
  glm::vec3 center{0.0f};
  float radius = 0.0f;
};

class EmissionCones {
 public:
  // The cones from `origin` around `targets`, each widened by 0.1 % of its radius (and 1e-6 of its
  // distance) against rounding. None (every direction stays possible) when there is no target,
  // when `origin` lies in a widened target, or when the cones' solid angles add up to the whole
  // sphere or more: aiming would not leave out any direction there.
  static std::optional<EmissionCones> make(const glm::vec3& origin, const std::vector<BoundingSphere>& targets) {
    EmissionCones out;
    for (const BoundingSphere& b : targets) {
      const glm::vec3 v = b.center - origin;
      const float d = glm::length(v);
      const float r = b.radius * 1.001f + 1e-6f * d;
      if (!(d > r)) return std::nullopt;
      const float sin2 = (r / d) * (r / d);
      const float cos_max = std::sqrt(1.0f - sin2);
      // 1 − cos θ without the cancellation: sin²θ / (1 + cos θ).
      const Cone c{v / d, cos_max, sin2 / (1.0f + cos_max)};
      out.total_ += 2.0f * kPi * c.one_minus_cos;
      out.cones_.push_back(c);
      out.cdf_.push_back(out.total_);
    }
    if (out.cones_.empty() || !(out.total_ < 4.0f * kPi)) return std::nullopt;
    return out;
  }

  // A direction drawn from p(w) by u (u.x picks a cone by its solid angle and is stretched back to
  // [0, 1)), and its density.
  glm::vec3 sample(glm::vec2 u, float* pdf) const {
    const float x = u.x * total_;
    const std::size_t i = std::min<std::size_t>(
        static_cast<std::size_t>(std::upper_bound(cdf_.begin(), cdf_.end(), x) - cdf_.begin()), cones_.size() - 1);
    const Cone& c = cones_[i];
    const float lo = i == 0 ? 0.0f : cdf_[i - 1];
    const float ux = std::clamp((x - lo) / (cdf_[i] - lo), 0.0f, kOneMinusEpsilon);
    const glm::vec3 w = glm::normalize(Frame::from_normal(c.axis).to_world(sample_uniform_cone_by_height({ux, u.y}, c.one_minus_cos)));
    // The cone drawn from counts even where rounding puts w a hair outside it.
    int count = 1;
    for (std::size_t j = 0; j < cones_.size(); ++j)
      if (j != i && glm::dot(w, cones_[j].axis) >= cones_[j].cos_max) ++count;
    *pdf = static_cast<float>(count) / total_;
    return w;
  }

  // p(w) for a unit direction.
  float pdf(const glm::vec3& w) const {
    int count = 0;
    for (const Cone& c : cones_)
      if (glm::dot(w, c.axis) >= c.cos_max) ++count;
    return static_cast<float>(count) / total_;
  }

  // The share of the sphere of directions the cones cover at most (their solid angles' sum / 4π).
  float share() const { return total_ / (4.0f * kPi); }
  std::size_t size() const { return cones_.size(); }

 private:
  struct Cone {
    glm::vec3 axis;
    float cos_max;
    float one_minus_cos;
  };
  std::vector<Cone> cones_;
  std::vector<float> cdf_;  // running sums of the cones' solid angles
  float total_ = 0.0f;
};

// --- aimed emission: a decorator over a light's ray sampling ---
// The light's own first ray (its origin, normal and spatial emission, drawn from x and u as
// sample_ray(l, x, u) draws them) with its direction drawn from the cones by u instead: its value
// is the light's emission that way, its density the cones' (finite: the direction's delta flag
// stays clear). Nullopt where the light emits nothing that way (outside a spot light's cone).
inline std::optional<EndpointRay> aimed_ray(const EmissionCones& cones, const LightParams& l, const SurfacePoint& x, glm::vec2 u) {
  std::optional<EndpointRay> r = sample_ray(l, x, u);
  if (!r) return r;
  float pdf = 0.0f;
  r->direction = cones.sample(u, &pdf);
  r->value = spatial_emission(l) * directional_emission(l, r->normal, r->direction);
  r->pdf.dir = pdf;
  r->weight = r->value / pdf;
  if (r->value.x == 0.0f && r->value.y == 0.0f && r->value.z == 0.0f) return std::nullopt;
  return r;
}
// The densities of the light's ray from x towards w as aimed_ray() draws it.
inline RayPdf aimed_pdf(const EmissionCones& cones, const LightParams& l, const SurfacePoint& x, const glm::vec3& w) {
  RayPdf p = pdf_ray(l, x, w);
  p.dir = cones.pdf(w);
  p.delta_dir = false;
  return p;
}

}  // namespace pathex
