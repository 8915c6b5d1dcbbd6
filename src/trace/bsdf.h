// BSDF sampling and evaluation for every Material kind (scene/material.h): pure functions of the
// material, the two directions and the normals, so that the integrator, the tests and any MIS
// weight computation all see the same numbers.
//
// Conventions (pbrt's). `wo` and `wi` are unit vectors pointing *away* from the surface point:
// `wo` back along the path already built, `wi` the new direction. `ns` is the unit shading
// normal and `ng` the unit geometric normal. Everything is computed in the shading frame; `ng`
// only rejects directions that would leak through the real surface (a reflection must leave on
// wo's side of ng, a refraction on the other side): sample() returns nullopt for them and eval()
// and pdf() return 0, consistently.
//
// Sidedness. Diffuse, mirror, glossy, conductor, thin dielectric and diffuse transmission are
// two-sided: the normal is flipped to wo's side. A dielectric, smooth or rough, is oriented: `ns`
// points to the outside (index 1), the inside has index `ior`. Finite lobes may transmit (rough
// dielectric, diffuse transmission): eval() and pdf() take wo and wi on opposite sides of both
// normals as a transmission and on one side of both as a reflection; a pair that ns and ng
// disagree about carries nothing.
//
// Each kind's sampling and evaluation lives in its own file: bsdf.cpp (diffuse, mirror, smooth
// dielectric, glossy, mixtures, and the dispatch), bsdf_conductor.cpp, bsdf_dielectric.cpp (rough
// and thin dielectrics), bsdf_transmission.cpp (diffuse transmission); optics/fresnel.h and
// trace/microfacet.h are the Fresnel and GGX they share.
//
// Dirac deltas (mirror, smooth dielectric, smooth conductor, thin dielectric; DESIGN §7 "MIS": handled symbolically). For a delta
// the BSDF is f · δ_σ(wi − w_delta), a Dirac in solid angle with weight f = R / |cos θi|, so the
// throughput update f · |cos θi| / pdf is one formula for both kinds; `pdf` is then the discrete
// probability of having chosen that delta, never a huge number. eval() and pdf() see only the
// finite components: a generic wi never lies on a delta direction.
//
// Mixtures (material.h: weights w_j ≥ 0, Σ w_j = W ≤ 1, the rest absorbed). sample() picks
// component j with probability w_j / W, so it never returns nullopt for the absorbed share; the
// absorption is carried by the weights in `f` instead (Σ w_j f_j), which keeps the estimator
// unbiased and avoids the variance of killing paths. For a finite component the returned f and
// pdf are those of *all* finite components together (one-sample balance heuristic over the lobes,
// as pbrt's BSDF does), so sample().f == eval() and sample().pdf == pdf() exactly; the letter is
// D either way, since every finite kind is D. For a delta component f = w_j f_j and pdf =
// (w_j / W) · p_j. The sampled vertex's letter is the chosen component's (DESIGN §7 "Labelling").
//
// Layered coats (CoatedDiffuse, trace/bsdf_layered.h): eval() and pdf() are Monte Carlo estimates
// from walks keyed by a hash of the directions, so still pure functions of material and
// directions, reciprocal in expectation rather than bit for bit; a smooth coat's reflection is a
// delta like a mirror's (letter S), the rest is D. A finite coated sample carries f == eval() and
// pdf == pdf() as above, but its weight is the walk's own unbiased product, not f·|cos θi|/pdf.
//
// Radiance and importance (Veach §5.2). Refraction compresses radiance by (η_wo / η_wi)^2 but not
// importance: in TransportMode::kRadiance (eye subpaths: wo towards the camera) the transmitted f
// carries 1/η'^2 with η' = η_wi / η_wo; in kImportance (light subpaths) it does not. So eval() of
// a rough dielectric depends on the mode: a join evaluates a light subpath's vertex with
// kImportance, an eye subpath's with kRadiance (the default). Every other kind is symmetric. The extra factor that shading normals cause for importance transport is
// shading_normal_correction(), applied by the integrator.
//
// Robustness (DESIGN §10). GGX is evaluated in forms that stay finite as roughness → 1e-4 (D from
// the half-vector's tangent components, not 1 − cos²) and at grazing angles (Λ without
// cancellation); roughness is clamped below at kMinGlossyRoughness. A direction exactly in the
// tangent plane (cos θ == 0 to float precision) carries nothing: sample() returns nullopt.
#pragma once

#include <cmath>
#include <cstdint>
#include <numbers>
#include <optional>
#include <variant>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "alphabet/alphabet.h"
#include "scene/material.h"
#include "trace/frame.h"
#include "optics/fresnel.h"
#include "trace/microfacet.h"
#include "trace/rng.h"

namespace pathex {

enum class TransportMode : std::uint8_t {
  kRadiance,    // eye subpaths: the path carries radiance towards the camera
  kImportance,  // light subpaths: the path carries importance towards the light
};

// The kind of lobe a sample came from (pbrt's BxDFFlags, reduced to what occurs here).
enum class Lobe : std::uint8_t {
  kDiffuseReflection,
  kGlossyReflection,
  kSpecularReflection,
  kSpecularTransmission,
  kGlossyTransmission,   // rough dielectric (D)
  kDiffuseTransmission,  // diffuse transmission (D)
};

inline constexpr float kMinGlossyRoughness = 1e-6f;

struct BsdfSample {
  glm::vec3 wi{0.0f};      // unit, away from the surface
  glm::vec3 f{0.0f};       // finite: eval(wo, wi); delta: the Dirac's weight R / |cos θi|
  float pdf = 0.0f;        // finite: pdf(wo, wi) (solid angle); delta: discrete probability
  float pdf_rev = 0.0f;    // the same for sampling wo from wi (BDPT's reverse density)
  glm::vec3 weight{0.0f};  // f · |cos θi| / pdf, computed without dividing by tiny cosines
  float eta = 1.0f;        // η_wi / η_wo across a refraction, 1 for reflection
  Letter letter = kD;      // kD for finite lobes, kS for deltas
  bool is_delta = false;
  Lobe lobe = Lobe::kDiffuseReflection;
  int component = 0;       // index into Mixture::components; 0 for a basic material
};

namespace bsdf {

// Sample wi given wo. `u_component` picks the mixture component (and then, rescaled, the
// reflection/refraction choice of a dielectric); `u` drives the direction within the lobe.
// nullopt when the sampled direction carries nothing (below the surface, leaking through ng,
// grazing exactly, zero-weight material).
inline std::optional<BsdfSample> sample(const Material& m, const glm::vec3& wo, const glm::vec3& ns,
                                        const glm::vec3& ng, float u_component, glm::vec2 u,
                                        TransportMode mode);

// Which of sample()'s numbers a material reads: the component number (a mixture's pick, a
// dielectric's choice between reflection and refraction) and the direction pair (every finite
// lobe). sample() returns the same, bit for bit, whatever the unread numbers are
// (Bsdf.SampleIgnoresTheNumbersItDoesNotRead), so a tracer need not compute them
// (Sampler::get1d_if, trace/rng.h).
struct NumbersRead {
  bool component = true;
  bool direction = true;
};
inline NumbersRead numbers_read(const Material& m) {
  if (std::holds_alternative<Diffuse>(m) || std::holds_alternative<Glossy>(m)) return {false, true};
  if (std::holds_alternative<Mirror>(m)) return {false, false};
  if (std::holds_alternative<Dielectric>(m) || std::holds_alternative<ThinDielectric>(m)) return {true, false};
  if (const auto* c = std::get_if<Conductor>(&m)) return {false, !c->smooth()};
  return {true, true};  // a mixture, a rough dielectric, diffuse transmission
}

namespace detail {
// Lambert needs no local frame: only the sides of the two directions (the tests reflection
// in bsdf.cpp makes, on the same dot products, so both paths agree bit for bit) and |cos θi|.
// Inline, because diffuse is the common case of every connection and MIS density.
inline bool same_side(const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns, const glm::vec3& ng,
                      float* cos_i) {
  if (!(glm::dot(wo, ng) * glm::dot(wi, ng) > 0.0f)) return false;
  *cos_i = glm::dot(wi, ns);
  return glm::dot(wo, ns) * *cos_i > 0.0f;
}
glm::vec3 eval_general(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                       const glm::vec3& ng, TransportMode mode);
float pdf_general(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                  const glm::vec3& ng);
}  // namespace detail

// The BSDF summed over the finite components, weighted by the mixture weights. Reflection is
// reciprocal: eval(wo, wi) == eval(wi, wo) bit for bit (a layered coat's: in expectation, see
// above). `mode` matters only for a rough dielectric's transmission (see "Radiance and importance").
inline glm::vec3 eval(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                      const glm::vec3& ng, TransportMode mode = TransportMode::kRadiance) {
  if (const auto* lambert = std::get_if<Diffuse>(&m)) {
    float cos_i;
    return detail::same_side(wo, wi, ns, ng, &cos_i) ? lambert->albedo * std::numbers::inv_pi_v<float> : glm::vec3(0.0f);
  }
  return detail::eval_general(m, wo, wi, ns, ng, mode);
}
inline glm::vec3 eval(const Material& m, const glm::vec3& wo, const glm::vec3& wi,
                      const glm::vec3& n) {
  return eval(m, wo, wi, n, n);
}

// Solid-angle density with which sample() produces wi through a finite component, including the
// probability of picking that component. Deltas contribute nothing here (see component_probability).
inline float pdf(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                 const glm::vec3& ng) {
  if (std::holds_alternative<Diffuse>(m)) {  // cosine-weighted: |cos θi| / π
    float cos_i;
    return detail::same_side(wo, wi, ns, ng, &cos_i) ? std::abs(cos_i) * std::numbers::inv_pi_v<float> : 0.0f;
  }
  return detail::pdf_general(m, wo, wi, ns, ng);
}
inline float pdf(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& n) {
  return pdf(m, wo, wi, n, n);
}

namespace detail {
std::optional<BsdfSample> sample_general(const Material& m, const glm::vec3& wo, const glm::vec3& ns,
                                         const glm::vec3& ng, float u_component, glm::vec2 u, TransportMode mode);
inline bool all_finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
// sample() for a plain Lambertian material (the common case), with the same numbers as the
// general path: the direction drawn in ns's frame on wo's side, then f, pdf and pdf_rev exactly
// as eval() and pdf() give them (same_side() is their test). Inline, like eval(): it is the step
// of almost every bounce.
inline std::optional<BsdfSample> sample_lambert(const Diffuse& lambert, const glm::vec3& wo, const glm::vec3& ns,
                                                const glm::vec3& ng, float cos_o, glm::vec2 u) {
  // The sample is built in the returned object itself (every return names `out`, so it is
  // elided): returning a local BsdfSample made GCC copy it into the optional with a `rep movs`,
  // whose start-up cost showed in the tracer's random walks.
  std::optional<BsdfSample> out(std::in_place);
  BsdfSample& s = *out;
  glm::vec3 wi_l = sample_cosine_hemisphere(u);
  float cos_i = 0.0f;
  if (wi_l.z > 0.0f) {
    if (cos_o < 0.0f) wi_l.z = -wi_l.z;
    s.wi = glm::normalize(Frame::from_normal(ns).to_world(wi_l));
    if (same_side(wo, s.wi, ns, ng, &cos_i)) {
      s.f = lambert.albedo * kInvPi;
      s.pdf = cosine_hemisphere_pdf(std::abs(cos_i));
      if (s.pdf > 0.0f && !(s.f.x == 0.0f && s.f.y == 0.0f && s.f.z == 0.0f) && all_finite(s.f)) {
        s.pdf_rev = cosine_hemisphere_pdf(std::abs(cos_o));
        s.weight = s.f * (std::abs(cos_i) / s.pdf);
        s.letter = kD;
        s.is_delta = false;
        s.lobe = Lobe::kDiffuseReflection;
        if (all_finite(s.weight)) return out;
      }
    }
  }
  out.reset();
  return out;
}
}  // namespace detail

inline std::optional<BsdfSample> sample(const Material& m, const glm::vec3& wo, const glm::vec3& ns,
                                        const glm::vec3& ng, float u_component, glm::vec2 u,
                                        TransportMode mode) {
  if (const auto* lambert = std::get_if<Diffuse>(&m)) {
    // The same entry tests as the general path's.
    const float cos_o = glm::dot(wo, ns);
    const float cos_og = glm::dot(wo, ng);
    if (!(cos_o != 0.0f) || !(cos_og != 0.0f) || !std::isfinite(cos_o) || !std::isfinite(cos_og))
      return std::nullopt;
    return detail::sample_lambert(*lambert, wo, ns, ng, cos_o, u);
  }
  return detail::sample_general(m, wo, ns, ng, u_component, u, mode);
}

// Both directions' densities at a join, for BDPT's MIS: pdf(wo, wi) and pdf(wi, wo).
struct JoinPdfs {
  float to_wi = 0.0f;  // pdf(wo, wi): sampling wi having arrived along wo
  float to_wo = 0.0f;  // pdf(wi, wo): sampling wo having arrived along wi
  bool known = false;  // false: not computed here (a material other than Lambert)
};
// eval(), and for a Lambertian material both densities of `pdfs` from the same side test (two
// more products), bit for bit what pdf() gives: same_side() is symmetric in wo and wi. Other
// materials leave `pdfs` unknown, for the caller to compute only if it needs them.
inline glm::vec3 eval(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                      const glm::vec3& ng, JoinPdfs* pdfs, TransportMode mode = TransportMode::kRadiance) {
  if (const auto* lambert = std::get_if<Diffuse>(&m)) {
    float cos_i;
    pdfs->known = true;
    if (!detail::same_side(wo, wi, ns, ng, &cos_i)) {
      pdfs->to_wi = pdfs->to_wo = 0.0f;
      return glm::vec3(0.0f);
    }
    pdfs->to_wi = std::abs(cos_i) * std::numbers::inv_pi_v<float>;
    pdfs->to_wo = std::abs(glm::dot(wo, ns)) * std::numbers::inv_pi_v<float>;
    return lambert->albedo * std::numbers::inv_pi_v<float>;
  }
  pdfs->known = false;
  return detail::eval_general(m, wo, wi, ns, ng, mode);
}

// The discrete probability that sample() picks the delta lobe `lobe` of component `component`
// given wo (what BsdfSample::pdf holds for that delta); 0 if that lobe is not a delta of that
// component. For BDPT, which recomputes a specular vertex's densities in the reverse direction.
float component_probability(const Material& m, const glm::vec3& wo, const glm::vec3& ns,
                            int component, Lobe lobe);

// Σ over the components of the lobe `lobe`'s component_probability(): the probability that
// sample() picks that delta lobe given wo, whichever component holds it.
double lobe_probability(const Material& m, const glm::vec3& wo, const glm::vec3& ns, Lobe lobe);

// The reflectance of a mixture's mirror components, each weighed by its weight (the share of flux
// a mirror-like mixture reflects specularly).
glm::vec3 mirror_reflectance(const Mixture& mix);

// True if the material has at least one finite (D) component with non-zero weight: only then can
// a join (shadow ray, connection) at a vertex on it carry energy.
bool has_finite_component(const Material& m);

// The dielectric Fresnel reflectance (optics/fresnel.h), under its old name.
using pathex::fresnel_dielectric;

// Veach's correction for shading normals in importance transport (thesis §5.3, pbrt-v3's
// CorrectShadingNormal): multiply a light subpath's throughput f · |wi·ns| / pdf by
// |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|). 1 for radiance transport and whenever ns == ng.
float shading_normal_correction(const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                                const glm::vec3& ng, TransportMode mode);

}  // namespace bsdf
}  // namespace pathex
