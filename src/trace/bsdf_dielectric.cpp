// The rough dielectric (pbrt-v4's DielectricBxDF with a rough distribution; Walter et al. 2007,
// "Microfacet Models for Refraction through Rough Surfaces"): GGX or Beckmann microfacets
// (trace/microfacet.h), as one interface the layered coat shares, that reflect with
// the dielectric Fresnel F and transmit with 1 − F, single scattering. And the thin dielectric's
// slab reflectance (pbrt-v4's ThinDielectricBxDF), whose two Dirac lobes bsdf.cpp samples.
//
// In the flipped frame of bsdf_kinds.h: wo.z > 0, `eta` = η_far / η_wo. For a pair (wo, wi) the
// generalised half vector is wm = ±normalize(η' wi + wo) with η' = 1 for reflection and eta for
// transmission, turned to +z; microfacets that face away from either direction carry nothing.
//   reflection:   f = D(wm) G2 F / (4 |z_o z_i|)
//   transmission: f = D(wm) G2 (1 − F) |wi·wm| |wo·wm| / (|z_o z_i| (wi·wm + wo·wm / η')²),
//                 divided by η'² in radiance transport (bsdf.h, "Radiance and importance")
// Sampling draws wm from the normals visible from wo (D_wo), reflects with probability F, else
// refracts; the densities are D_wo / (4 |wo·wm|) · F and D_wo |wi·wm| / (wi·wm + wo·wm / η')² ·
// (1 − F).
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "trace/bsdf_kinds.h"
#include "optics/fresnel.h"
#include "trace/microfacet.h"

namespace pathex::bsdf::kinds {
namespace {

// The generalised half vector of (wo, wi) on +z and η', or false when it is undefined or a
// microfacet facing it would be back-facing to wo or wi.
bool half_vector(float eta, const glm::vec3& wo, const glm::vec3& wi, glm::vec3* wm, float* etap) {
  if (wi.z == 0.0f || !(eta > 0.0f)) return false;
  const bool reflect = wi.z > 0.0f;
  *etap = reflect ? 1.0f : eta;
  const glm::vec3 h = reflect ? wo + wi : wi * *etap + wo;
  const float len2 = glm::dot(h, h);
  if (!(len2 > 0.0f)) return false;
  *wm = h / std::sqrt(len2);
  if (wm->z < 0.0f) *wm = -*wm;
  if (!(wm->z > 0.0f)) return false;
  return !(glm::dot(*wm, wi) * wi.z < 0.0f || glm::dot(*wm, wo) * wo.z < 0.0f);
}

// The probability of reflecting given the Fresnel reflectance f at the microfacet, under `lobes`;
// NaN when neither allowed lobe can happen.
float reflect_probability(float f, InterfaceLobes lobes) {
  if (lobes == InterfaceLobes::kAll) return f;
  const float pr = lobes == InterfaceLobes::kTransmission ? 0.0f : f;
  const float pt = lobes == InterfaceLobes::kReflection ? 0.0f : 1.0f - f;
  return pr + pt > 0.0f ? pr / (pr + pt) : std::numeric_limits<float>::quiet_NaN();
}

Microfacet dielectric_microfacet(const RoughDielectric& d) { return clamped_microfacet(d.distribution, d.alpha_u, d.alpha_v); }

}  // namespace

float rough_interface_f(const Microfacet& mf, float eta, const glm::vec3& wo, const glm::vec3& wi, TransportMode mode) {
  glm::vec3 wm;
  float etap;
  if (!half_vector(eta, wo, wi, &wm, &etap)) return 0.0f;
  if (wi.z > 0.0f) {
    // Reflection, written symmetric in (wo, wi) bit for bit, as the glossy lobe.
    const float cos_h = 0.5f * (glm::dot(wo, wm) + glm::dot(wi, wm));
    const float denom = mf.reflection_denominator(wo, wi);
    if (!(denom > 0.0f)) return 0.0f;
    return fresnel_dielectric(cos_h, eta) * mf.d(wm) / denom;
  }
  const float wi_m = glm::dot(wi, wm), wo_m = glm::dot(wo, wm);
  const float s = wi_m + wo_m / etap;
  const float denom = s * s * std::abs(wi.z * wo.z);
  if (!(denom > 0.0f)) return 0.0f;
  float ft = mf.d(wm) * mf.g2(wo, wi) * (1.0f - fresnel_dielectric(wo_m, eta)) * std::abs(wi_m * wo_m / denom);
  if (mode == TransportMode::kRadiance) ft /= etap * etap;
  return ft;
}

float rough_interface_pdf(const Microfacet& mf, float eta, const glm::vec3& wo, const glm::vec3& wi,
                          InterfaceLobes lobes) {
  glm::vec3 wm;
  float etap;
  if (!half_vector(eta, wo, wi, &wm, &etap)) return 0.0f;
  const float wo_m = glm::dot(wo, wm);
  const float pr = reflect_probability(fresnel_dielectric(wo_m, eta), lobes);
  if (!(pr >= 0.0f)) return 0.0f;
  if (wi.z > 0.0f) return mf.d_visible(wo, wm) / (4.0f * std::abs(wo_m)) * pr;
  const float wi_m = glm::dot(wi, wm);
  const float s = wi_m + wo_m / etap;
  if (!(s * s > 0.0f)) return 0.0f;
  return mf.d_visible(wo, wm) * (std::abs(wi_m) / (s * s)) * (1.0f - pr);
}

std::optional<InterfaceSample> rough_interface_sample(const Microfacet& mf, float eta, const glm::vec3& wo, float uc,
                                                      glm::vec2 u, InterfaceLobes lobes) {
  const glm::vec3 wm = mf.sample_visible_normal(wo, u);
  const float cos_m = glm::dot(wo, wm);
  const float f = fresnel_dielectric(cos_m, eta);
  const float pr = reflect_probability(f, lobes);
  if (!(pr >= 0.0f)) return std::nullopt;
  if (uc < pr) return InterfaceSample{2.0f * cos_m * wm - wo, true, 1.0f, f};
  // Refraction through the microfacet (cos_m > 0: wm is visible from wo).
  glm::vec3 wt;
  float etap;
  if (!refract(wo, wm, eta, &etap, &wt)) return std::nullopt;  // unreachable: F = 1 there
  return InterfaceSample{glm::normalize(wt), false, etap, 1.0f - f};
}

glm::vec3 rough_dielectric_eval(const RoughDielectric& d, float eta, const glm::vec3& wo, const glm::vec3& wi,
                                TransportMode mode) {
  return d.tint * rough_interface_f(dielectric_microfacet(d), eta, wo, wi, mode);
}

float rough_dielectric_pdf(const RoughDielectric& d, float eta, const glm::vec3& wo, const glm::vec3& wi) {
  return rough_interface_pdf(dielectric_microfacet(d), eta, wo, wi);
}

std::optional<LocalSample> rough_dielectric_sample(const RoughDielectric& d, float eta, const glm::vec3& wo, float uc,
                                                   glm::vec2 u) {
  const std::optional<InterfaceSample> s = rough_interface_sample(dielectric_microfacet(d), eta, wo, uc, u);
  if (!s) return std::nullopt;
  return LocalSample{s->wi, s->reflect ? Lobe::kGlossyReflection : Lobe::kGlossyTransmission, s->eta};
}

float thin_dielectric_reflectance(const ThinDielectric& d, float cos_o) {
  float r = fresnel_dielectric(std::abs(cos_o), d.ior);
  const float t = 1.0f - r;
  if (r < 1.0f) r += t * t * r / (1.0f - r * r);
  return r;
}

}  // namespace pathex::bsdf::kinds
