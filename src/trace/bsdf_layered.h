// pbrt-v4's layered BSDF for `coateddiffuse` and `coatedconductor` (scene/material.h
// CoatedDiffuse): a dielectric coat (smooth, or rough with GGX or Beckmann microfacets:
// bsdf_dielectric.cpp's interface) over a Lambertian base or a conductor base (bsdf_conductor.cpp's,
// smooth or rough), with a homogeneous slab between them (extinction 1 per unit thickness,
// single-scattering `albedo`, Henyey–Greenstein `g`). Light that passes the coat takes a random
// walk between the two interfaces; pbrt-v4 (Physically Based Rendering, 4th ed., §14.3) samples
// that walk and estimates the BSDF's value by Monte Carlo, and so do we.
//
// Everything here is in the coat's local frame: z along the normal, the outside at z > 0, wo.z > 0
// (bsdf.cpp flips both directions to wo's side: the material is two-sided like pbrt's). The coat's
// reflection and the walk only ever return to wo's side (the base is opaque): reflection only.
//
// Letters (DESIGN §1). A smooth coat (roughness < 1e-3) reflects as a Dirac delta: that sample is
// an S event, and pdf() and eval() exclude it (component_probability() gives its probability, the
// Fresnel reflectance at wo). Everything that passes the coat reaches the Lambertian or rough
// conductor base at least once, so it leaves with a finite density: D. A rough coat's reflection
// is D too, and so is what passes it (over a smooth conductor too: the coat spreads it on the way
// out). A smooth coat over a smooth conductor with a layer that does not scatter is one Dirac
// delta as a whole (CoatedDiffuse::all_specular(), S): bsdf.cpp samples it as a mirror of
// reflectance specular_reflectance(); eval() and pdf() are 0 for it.
//
// Three estimators, each a pure function of the material and the directions:
// - sample() runs the walk (pbrt's LayeredBxDF::Sample_f) and returns its weight f·|cos θi|/p as
//   the walk's product of interface and medium weights: unbiased for every integrand, which is
//   all a throughput needs. Its random numbers come from a stream keyed by (wo, uc, u), so the
//   same arguments give the same sample.
// - eval() is pbrt's LayeredBxDF::f: walks from wo with next-event connections towards a
//   direction drawn from the coat on wi's side (multiple importance sampling against the walk's
//   own hits when the coat is rough), averaged over `samples` walks.
// - pdf() is NOT pbrt's LayeredBxDF::PDF. pbrt's is an approximation meant only for MIS weights
//   (it omits the refraction's Jacobian, ignores Russian roulette and mixes in a uniform density).
//   Ours is an unbiased estimate of the density with which sample() produces wi: it runs
//   sample()'s own walk from wo and, at each step that could leave the layers, adds the density
//   of leaving towards wi there (times the probability that the walk is still alive), instead of
//   drawing the exit. So the histogram of sample() matches the average of pdf() over a region
//   (tests/trace/bsdf_layered_test.cpp checks this by chi-square).
// eval() and pdf() draw their walks from a stream keyed by a hash of (wo, wi), as pbrt-v4 seeds
// its RNG from Hash(wo), Hash(wi): they are deterministic functions of the directions, so every
// strategy of an estimator sees the same numbers for the same vertex, and one-sample MIS weights
// computed from them still sum to 1 (their values need not be exact for that, only consistent).
// The stream of pdf(wo, wi) differs from that of eval(wo, wi), and from that of pdf(wi, wo): the
// estimates are reciprocal in expectation, not bit for bit.
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "scene/material.h"
#include "trace/bsdf.h"

namespace pathex::bsdf::layered {

// The finite part of the BSDF (the coat's delta reflection excluded), wo.z > 0; 0 unless wi.z > 0.
// An average of m.samples walks keyed by `key`; eval() uses key_of(wo, wi, 0).
glm::vec3 eval_estimate(const CoatedDiffuse& m, const glm::vec3& wo, const glm::vec3& wi, std::uint64_t key);
// The density with which sample() produces wi through a finite event (the delta reflection
// excluded), wo.z > 0; 0 unless wi.z > 0. An average of m.samples walks keyed by `key`; pdf() uses
// key_of(wo, wi, 1). Never below kPdfFloor on wo's side (see pdf()).
float pdf_estimate(const CoatedDiffuse& m, const glm::vec3& wo, const glm::vec3& wi, std::uint64_t key);

std::uint64_t key_of(const glm::vec3& wo, const glm::vec3& wi, std::uint64_t salt);

// A density at least this large wherever the BSDF can reflect: a walk may miss a direction that
// sample() can produce (a rough coat's exit density is zero for back-facing microfacets), and a
// sample whose reported density is 0 would be dropped by the integrators. 1e-6 per steradian is
// far below anything a chi-square or a render can see.
inline constexpr float kPdfFloor = 1e-6f;

inline glm::vec3 eval(const CoatedDiffuse& m, const glm::vec3& wo, const glm::vec3& wi) {
  return eval_estimate(m, wo, wi, key_of(wo, wi, 0));
}
inline float pdf(const CoatedDiffuse& m, const glm::vec3& wo, const glm::vec3& wi) {
  return pdf_estimate(m, wo, wi, key_of(wo, wi, 1));
}

// The probability that sample() returns the coat's delta reflection at wo (the Fresnel
// reflectance of a smooth coat; 0 for a rough one; 1 for an all_specular() coat).
float specular_probability(const CoatedDiffuse& m, float cos_o);

// The reflectance of an all_specular() coat at cos θo: the expectation of its walk, a series of the
// coat's and the conductor's Fresnel terms truncated at max_depth (formula in bsdf_layered.cpp).
glm::vec3 specular_reflectance(const CoatedDiffuse& m, float cos_o);

struct Sample {
  glm::vec3 wi{0.0f};
  glm::vec3 weight{0.0f};  // f·|cos θi| / p, the walk's product (1 for the delta reflection)
  bool specular = false;   // the smooth coat's delta reflection (letter S)
  bool coat = false;       // the coat's own reflection (delta or rough), not the walk
};
// wo.z > 0. nullopt when the walk dies (absorbed by Russian roulette, past max_depth, or a sample
// that carries nothing).
std::optional<Sample> sample(const CoatedDiffuse& m, const glm::vec3& wo, float uc, glm::vec2 u);

// bsdf::sample() for a coated component of `whole` (the material itself, or the mixture holding it
// as component `component`, picked with `probability`, of weight `weight`), in world space. The
// delta reflection is returned like a mirror's (letter S, pdf its discrete probability); a finite
// sample carries f = eval(whole), pdf = pdf(whole), pdf_rev = pdf(whole) reversed, letter D, and
// the walk's weight (times weight / probability), not f·|cos θi|/pdf: the walk's is unbiased,
// while the ratio of the two estimates is not.
std::optional<BsdfSample> sample_world(const Material& whole, const CoatedDiffuse& m, int component,
                                       float probability, float weight, const glm::vec3& wo, const glm::vec3& ns,
                                       const glm::vec3& ng, float uc, glm::vec2 u);

}  // namespace pathex::bsdf::layered
