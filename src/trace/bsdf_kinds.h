// The per-family BSDF pieces bsdf.cpp dispatches to, each family in its own file. Internal to the
// BSDF code (bsdf.h is the interface). Every function works in the shading frame flipped so that
// wo.z > 0 (bsdf.cpp's local_pair); wi may lie on either side. An oriented kind (the rough
// dielectric) receives the relative index `eta` of the side wo is not on, η_far / η_wo: ior when
// wo is outside, 1 / ior when inside (flipping both directions is a reflection of space, which
// keeps every dot product, so the outside formulas with eta hold as they are).
#pragma once

#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "scene/material.h"
#include "trace/bsdf.h"

namespace pathex::bsdf::kinds {

// A direction drawn by a finite lobe, before the caller values it with eval() and pdf().
struct LocalSample {
  glm::vec3 wi;
  Lobe lobe;
  float eta = 1.0f;  // η_wi / η_wo
};

// The distribution of a rough lobe, alphas clamped to [kMinGlossyRoughness, 1] (NaN or ∞: 1).
inline Microfacet clamped_microfacet(MicrofacetKind kind, float alpha_u, float alpha_v) {
  const auto clamp = [](float a) { return std::clamp(std::isfinite(a) ? a : 1.0f, kMinGlossyRoughness, 1.0f); };
  return Microfacet{clamp(alpha_u), clamp(alpha_v), kind};
}

// --- conductor (bsdf_conductor.cpp) ---
glm::vec3 conductor_eval(const Conductor& c, const glm::vec3& wo, const glm::vec3& wi);
float conductor_pdf(const Conductor& c, const glm::vec3& wo, const glm::vec3& wi);
std::optional<LocalSample> conductor_sample(const Conductor& c, const glm::vec3& wo, glm::vec2 u);
glm::vec3 conductor_reflectance(const Conductor& c, float cos_o);  // the smooth conductor's delta weight

// --- a rough dielectric interface (bsdf_dielectric.cpp): the one copy that the rough dielectric
// below and the layered coat (bsdf_layered.cpp) evaluate and sample; no tint. wo.z > 0, `eta` =
// η_far / η_wo. `lobes` restricts sampling and its density to one lobe (the coat's walk asks for
// only reflection or only transmission at times), as pbrt-v4's BxDFReflTransFlags. ---
enum class InterfaceLobes { kAll, kReflection, kTransmission };
float rough_interface_f(const Microfacet& mf, float eta, const glm::vec3& wo, const glm::vec3& wi, TransportMode mode);
float rough_interface_pdf(const Microfacet& mf, float eta, const glm::vec3& wo, const glm::vec3& wi,
                          InterfaceLobes lobes = InterfaceLobes::kAll);
struct InterfaceSample {
  glm::vec3 wi;  // not yet checked against its lobe's side (a reflection may point below z = 0)
  bool reflect;
  float eta;     // η_wi / η_wo
  float choice;  // the Fresnel share of the chosen lobe at the sampled microfacet (F or 1 − F)
};
std::optional<InterfaceSample> rough_interface_sample(const Microfacet& mf, float eta, const glm::vec3& wo, float uc,
                                                      glm::vec2 u, InterfaceLobes lobes = InterfaceLobes::kAll);

// --- rough and thin dielectrics (bsdf_dielectric.cpp) ---
glm::vec3 rough_dielectric_eval(const RoughDielectric& d, float eta, const glm::vec3& wo, const glm::vec3& wi,
                                TransportMode mode);
float rough_dielectric_pdf(const RoughDielectric& d, float eta, const glm::vec3& wo, const glm::vec3& wi);
std::optional<LocalSample> rough_dielectric_sample(const RoughDielectric& d, float eta, const glm::vec3& wo, float uc,
                                                   glm::vec2 u);
// The thin slab's reflectance R' = R + T² R / (1 − R²) at |cos_o| (its transmittance is 1 − R').
float thin_dielectric_reflectance(const ThinDielectric& d, float cos_o);

// --- diffuse transmission (bsdf_transmission.cpp) ---
glm::vec3 diffuse_transmission_eval(const DiffuseTransmission& d, const glm::vec3& wo, const glm::vec3& wi);
float diffuse_transmission_pdf(const DiffuseTransmission& d, const glm::vec3& wo, const glm::vec3& wi);
std::optional<LocalSample> diffuse_transmission_sample(const DiffuseTransmission& d, const glm::vec3& wo, float uc,
                                                       glm::vec2 u);

}  // namespace pathex::bsdf::kinds
