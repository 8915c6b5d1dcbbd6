// The conductor (pbrt-v4's ConductorBxDF): the exact Fresnel reflectance of a complex index
// eta + i k per RGB channel (optics/fresnel.h), on a smooth surface (a Dirac delta, letter S) or on
// GGX or Beckmann microfacets (letter D, trace/microfacet.h) with alpha_u, alpha_v along the shading frame's tangents. Smooth when
// both alphas are below 1e-3, as pbrt-v4's EffectivelySmooth(). Two-sided, reflection only.
#include <cmath>

#include <glm/geometric.hpp>

#include "trace/bsdf_kinds.h"
#include "optics/fresnel.h"
#include "trace/microfacet.h"

namespace pathex::bsdf::kinds {

namespace {
Microfacet conductor_microfacet(const Conductor& c) { return clamped_microfacet(c.distribution, c.alpha_u, c.alpha_v); }
}  // namespace

// D(h) F(wo·h) / (4 |z_o z_i| (1 + Λo + Λi)); symmetric in (wo, wi) bit for bit (the cosine with
// the half vector is the mean of the two equal dot products).
glm::vec3 conductor_eval(const Conductor& c, const glm::vec3& wo, const glm::vec3& wi) {
  if (!(wi.z > 0.0f) || c.smooth()) return glm::vec3(0.0f);
  const Microfacet mf = conductor_microfacet(c);
  const glm::vec3 hs = wo + wi;
  const float len2 = glm::dot(hs, hs);
  if (!(len2 > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 h = hs / std::sqrt(len2);
  const float denom = mf.reflection_denominator(wo, wi);
  if (!(denom > 0.0f)) return glm::vec3(0.0f);
  const float cos_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  return c.tint * fresnel_complex(cos_h, c.eta, c.k) * (mf.d(h) / denom);
}

// Visible-normal sampling: D_wo(h) / (4 wo·h) = D(h) / (4 (z_o + zΛ(wo))).
float conductor_pdf(const Conductor& c, const glm::vec3& wo, const glm::vec3& wi) {
  if (!(wi.z > 0.0f) || c.smooth()) return 0.0f;
  const Microfacet mf = conductor_microfacet(c);
  const glm::vec3 hs = wo + wi;
  const float len2 = glm::dot(hs, hs);
  if (!(len2 > 0.0f)) return 0.0f;
  const float denom = 4.0f * (wo.z + mf.z_lambda(wo));
  if (!(denom > 0.0f)) return 0.0f;
  return mf.d(hs / std::sqrt(len2)) / denom;
}

std::optional<LocalSample> conductor_sample(const Conductor& c, const glm::vec3& wo, glm::vec2 u) {
  const glm::vec3 m = conductor_microfacet(c).sample_visible_normal(wo, u);
  return LocalSample{2.0f * glm::dot(wo, m) * m - wo, Lobe::kGlossyReflection};
}

glm::vec3 conductor_reflectance(const Conductor& c, float cos_o) { return c.tint * fresnel_complex(cos_o, c.eta, c.k); }

}  // namespace pathex::bsdf::kinds
