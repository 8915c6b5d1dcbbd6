// Materials: a closed set of kinds behind one value (std::variant), as pbrt dispatches through a
// tagged handle. These are parameters only; sampling and evaluation live in trace/bsdf.h.
//
// Each kind contributes letters to full-path strings (DESIGN §1): a finite BSDF is D, a Dirac
// delta is S. A mixture carries the letters of its components; a sampled vertex gets the letter
// of the component that carried the transport.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

#include "alphabet/alphabet.h"

namespace pathex {

struct Diffuse {
  glm::vec3 albedo{0.8f};  // Lambertian reflectance in [0, 1]
};

struct Mirror {
  glm::vec3 reflectance{1.0f};  // perfect specular reflection, constant in angle
};

struct Dielectric {
  float ior = 1.5f;          // index of refraction inside / outside; Fresnel and total internal reflection
  glm::vec3 tint{1.0f};      // multiplies transmission and reflection
};

// The indices a dielectric may have, in every scene format: within [0.1, 10] and not 1. Below 1 the
// inside is the less dense medium (an air bubble in water, pbrt-v4's eta < 1); 1 is no surface.
inline bool valid_ior(double eta) { return eta >= 0.1 && eta <= 10.0 && std::fabs(eta - 1.0) >= 1e-4; }
inline constexpr const char* kValidIor = "within [0.1, 10] and not 1 (1 is no surface)";

// The microfacet distribution of a rough lobe (trace/microfacet.h): GGX (pbrt-v4's only one, the
// JSON default) or Beckmann (Mitsuba 3's default). Either is a finite lobe, letter D. Four bytes
// like the floats beside it: scene_hash.cpp hashes a material's bytes, which must hold no padding.
enum class MicrofacetKind : std::uint32_t { kGgx, kBeckmann };

struct Glossy {
  glm::vec3 reflectance{0.8f};  // microfacet reflection with Schlick Fresnel from this colour
  float roughness = 0.2f;       // the microfacet alpha; > 0 (finite BSDF, letter D)
  MicrofacetKind distribution = MicrofacetKind::kGgx;
};

// pbrt-v4's EffectivelySmooth(): a GGX alpha below this (in both tangent directions) is sampled as
// a Dirac delta (letter S); the importers and the JSON reader make such a conductor smooth and such
// a dielectric the smooth Dielectric.
inline constexpr float kSmoothAlpha = 1e-3f;

// A metal: exact Fresnel reflectance of the complex index eta + i k per RGB channel (pbrt-v4's
// conductor). GGX alpha per tangent direction; alpha_u and alpha_v both below 1e-3 make it smooth,
// a Dirac delta (letter S, pbrt-v4's EffectivelySmooth), else a finite lobe (letter D). The
// tangents are those of the shading frame (trace/frame.h), not the surface's u direction.
struct Conductor {
  glm::vec3 eta{0.104494f, 0.978171f, 1.204672f};  // default: pbrt-v4's copper (scene/metal_spectra.h)
  glm::vec3 k{2.721234f, 2.622372f, 2.358023f};
  float alpha_u = 0.0f;
  float alpha_v = 0.0f;
  glm::vec3 tint{1.0f};  // multiplies the Fresnel reflectance (Mitsuba's specular_reflectance; 1 in pbrt)
  MicrofacetKind distribution = MicrofacetKind::kGgx;
  bool smooth() const { return std::max(alpha_u, alpha_v) < kSmoothAlpha; }
};

// A rough dielectric interface (pbrt-v4's DielectricBxDF with a rough distribution, Walter et al.
// 2007): GGX reflection and transmission, Fresnel between them, single scattering (the energy the
// microfacets scatter more than once is lost, as in pbrt-v4). Always a finite lobe (letter D):
// alpha below 1e-3 is imported as the smooth Dielectric instead. Oriented as Dielectric.
struct RoughDielectric {
  float ior = 1.5f;      // η_inside / η_outside, valid_ior()
  glm::vec3 tint{1.0f};  // multiplies reflection and transmission
  float alpha_u = 0.1f;
  float alpha_v = 0.1f;
  MicrofacetKind distribution = MicrofacetKind::kGgx;
};

// A thin dielectric slab (pbrt-v4's ThinDielectricBxDF): the reflection R' = R + T² R / (1 − R²)
// of the slab's infinitely many internal bounces, a Dirac delta (S), and the rest passing straight
// through (wi = −wo), another Dirac delta (S). No refraction: the ray keeps its direction.
struct ThinDielectric {
  float ior = 1.5f;  // of the slab against the outside, valid_ior()
  glm::vec3 tint{1.0f};
};

// Lambertian reflection and Lambertian transmission on both sides (pbrt-v4's
// DiffuseTransmissionBxDF): f = reflectance / π on wo's side, transmittance / π on the other.
// Finite, letter D. reflectance + transmittance ≤ 1 per channel.
struct DiffuseTransmission {
  glm::vec3 reflectance{0.25f};
  glm::vec3 transmittance{0.25f};
};


// The base under a layered coat: pbrt-v4's coateddiffuse (Lambertian) or coatedconductor.
enum class CoatBase : std::uint32_t { kDiffuse, kConductor };

// pbrt-v4's coateddiffuse and coatedconductor (trace/bsdf_layered.h): a dielectric coat over a
// Lambertian or a conductor base with a homogeneous layer between (σ_t = 1 per unit thickness),
// evaluated and sampled by pbrt-v4's stochastic random walk between the two interfaces.
// Letters (per sampled component):
// - a smooth coat (roughness < 1e-3) reflects as a Dirac delta, S; what passes it reaches a
//   Lambertian or rough conductor base and leaves with a finite density, D;
// - a rough coat: its reflection and what passes it are D (also over a smooth conductor: the rough
//   coat spreads what the mirror returns);
// - a smooth coat over a smooth conductor with a layer that does not scatter (albedo 0): every
//   path through it leaves in the mirror direction, so the whole BSDF is one Dirac delta, S, whose
//   weight is the series of the coat's and the conductor's Fresnel terms
//   (layered::specular_reflectance). Such a coat with a scattering layer is refused at import.
struct CoatedDiffuse {
  glm::vec3 reflectance{0.5f};  // the base's Lambertian reflectance in [0, 1]
  glm::vec3 albedo{0.0f};       // the layer medium's single-scattering albedo in [0, 1]
  float roughness = 0.0f;       // the coat's alpha (pbrt's roughness after remapping); < 1e-3 is smooth
  float eta = 1.5f;             // the coat's index (inside / outside), valid_ior()
  float thickness = 0.01f;      // the layer's optical thickness (σ_t = 1), >= 0
  float g = 0.0f;               // Henyey–Greenstein asymmetry of the medium in (-1, 1)
  int max_depth = 10;           // scattering events of one walk, at least 1
  int samples = 1;              // walks per eval() and pdf() estimate, at least 1
  MicrofacetKind distribution = MicrofacetKind::kGgx;  // of a rough coat
  CoatBase base = CoatBase::kDiffuse;
  // The base of a coatedconductor (`base` kConductor; `reflectance` unused): eta and k relative to
  // the coat (pbrt-v4 divides the metal's by the coat's eta), GGX alphas, tint 1.
  Conductor conductor;
  bool smooth() const { return roughness < 1e-3f; }
  // The whole BSDF is one Dirac delta (see above).
  bool all_specular() const {
    return base == CoatBase::kConductor && smooth() && conductor.smooth() && albedo == glm::vec3(0.0f);
  }
};

// The largest walk length and walk count a coat may ask for (every format): each eval() and pdf()
// costs up to samples × max_depth steps.
inline constexpr int kMaxCoatDepth = 10000;
inline constexpr int kMaxCoatSamples = 1024;

using BasicMaterial = std::variant<Diffuse, Mirror, Dielectric, Glossy, Conductor, RoughDielectric, ThinDielectric,
                                   DiffuseTransmission, CoatedDiffuse>;

// A weighted sum of basic components: 0.5 diffuse + 0.1 mirror, the remaining 0.4 absorbed.
// Weights are non-negative and sum to at most 1.
struct Mixture {
  struct Component {
    float weight = 0.0f;
    BasicMaterial material;
  };
  std::vector<Component> components;
};

using Material = std::variant<Diffuse, Mirror, Dielectric, Glossy, Mixture, Conductor, RoughDielectric, ThinDielectric,
                              DiffuseTransmission, CoatedDiffuse>;

// The letters a basic material can give to a vertex (bit per letter): D for finite BSDFs, S for
// Dirac deltas, both for a smooth coat (its reflection is S, what passes it D). A sampled vertex
// gets the letter of the sampled event (BsdfSample::letter).
// Diffuse, Glossy, RoughDielectric, DiffuseTransmission: D. Mirror, Dielectric, ThinDielectric: S.
// Conductor: S when smooth, else D. CoatedDiffuse: S and D when smooth, else D; S alone when all_specular().
inline LetterMask letters_of(const BasicMaterial& m) {
  constexpr auto kOnlyS = static_cast<LetterMask>(1u << kS), kOnlyD = static_cast<LetterMask>(1u << kD);
  if (const auto* coat = std::get_if<CoatedDiffuse>(&m))
    return coat->all_specular() ? kOnlyS : coat->smooth() ? static_cast<LetterMask>(kOnlyS | kOnlyD) : kOnlyD;
  if (const auto* c = std::get_if<Conductor>(&m)) return c->smooth() ? kOnlyS : kOnlyD;
  return std::holds_alternative<Mirror>(m) || std::holds_alternative<Dielectric>(m) || std::holds_alternative<ThinDielectric>(m)
             ? kOnlyS
             : kOnlyD;
}

// One kind on its own (a Conductor, …): as that basic material.
template <class Kind>
  requires(!std::is_same_v<Kind, BasicMaterial> && !std::is_same_v<Kind, Material> && !std::is_same_v<Kind, Mixture>)
inline LetterMask letters_of(const Kind& k) {
  return letters_of(BasicMaterial{k});
}

// The letters a material can give (bit per letter), the union over a mixture's components.
inline LetterMask letters_of(const Material& m) {
  return std::visit(
      [](const auto& k) -> LetterMask {
        if constexpr (std::is_same_v<std::decay_t<decltype(k)>, Mixture>) {
          LetterMask out = 0;
          for (const auto& c : k.components)
            if (c.weight > 0.0f) out = static_cast<LetterMask>(out | letters_of(c.material));
          return out;
        } else {
          return letters_of(BasicMaterial{k});
        }
      },
      m);
}

}  // namespace pathex
