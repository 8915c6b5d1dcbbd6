// Materials: a closed set of kinds behind one value (std::variant), as pbrt dispatches through a
// tagged handle. These are parameters only; sampling and evaluation live in trace/bsdf.h.
//
// Each kind contributes letters to full-path strings (DESIGN §1): a finite BSDF is D, a Dirac
// delta is S. A mixture carries the letters of its components; a sampled vertex gets the letter
// of the component that carried the transport.
#pragma once

#include <cmath>
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

struct Glossy {
  glm::vec3 reflectance{0.8f};  // GGX microfacet reflection with Schlick Fresnel from this colour
  float roughness = 0.2f;       // GGX alpha; > 0 (finite BSDF, letter D)
};

// pbrt-v4's coateddiffuse (trace/bsdf_layered.h): a dielectric coat over a Lambertian base with a
// homogeneous layer between (σ_t = 1 per unit thickness), evaluated and sampled by pbrt-v4's
// stochastic random walk between the two interfaces. Letters: a smooth coat (roughness < 1e-3)
// reflects as a Dirac delta, S, and everything that passes it is D; a rough coat is D only.
struct CoatedDiffuse {
  glm::vec3 reflectance{0.5f};  // the base's Lambertian reflectance in [0, 1]
  glm::vec3 albedo{0.0f};       // the layer medium's single-scattering albedo in [0, 1]
  float roughness = 0.0f;       // the coat's GGX alpha (pbrt's roughness after remapping); < 1e-3 is smooth
  float eta = 1.5f;             // the coat's index (inside / outside), valid_ior()
  float thickness = 0.01f;      // the layer's optical thickness (σ_t = 1), >= 0
  float g = 0.0f;               // Henyey–Greenstein asymmetry of the medium in (-1, 1)
  int max_depth = 10;           // scattering events of one walk, at least 1
  int samples = 1;              // walks per eval() and pdf() estimate, at least 1
  bool smooth() const { return roughness < 1e-3f; }
};

// The largest walk length and walk count a coat may ask for (every format): each eval() and pdf()
// costs up to samples × max_depth steps.
inline constexpr int kMaxCoatDepth = 10000;
inline constexpr int kMaxCoatSamples = 1024;

using BasicMaterial = std::variant<Diffuse, Mirror, Dielectric, Glossy, CoatedDiffuse>;

// A weighted sum of basic components: 0.5 diffuse + 0.1 mirror, the remaining 0.4 absorbed.
// Weights are non-negative and sum to at most 1.
struct Mixture {
  struct Component {
    float weight = 0.0f;
    BasicMaterial material;
  };
  std::vector<Component> components;
};

using Material = std::variant<Diffuse, Mirror, Dielectric, Glossy, CoatedDiffuse, Mixture>;

// The letters a basic material can give to a vertex (bit per letter): D for finite BSDFs, S for
// Dirac deltas, both for a smooth coat (its reflection is S, what passes it D). A sampled vertex
// gets the letter of the sampled event (BsdfSample::letter).
inline LetterMask letters_of(const BasicMaterial& m) {
  if (const auto* coat = std::get_if<CoatedDiffuse>(&m))
    return static_cast<LetterMask>(coat->smooth() ? (1u << kS) | (1u << kD) : 1u << kD);
  return static_cast<LetterMask>(1u << (std::holds_alternative<Mirror>(m) || std::holds_alternative<Dielectric>(m) ? kS : kD));
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
