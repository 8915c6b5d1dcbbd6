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

using BasicMaterial = std::variant<Diffuse, Mirror, Dielectric, Glossy>;

// A weighted sum of basic components: 0.5 diffuse + 0.1 mirror, the remaining 0.4 absorbed.
// Weights are non-negative and sum to at most 1.
struct Mixture {
  struct Component {
    float weight = 0.0f;
    BasicMaterial material;
  };
  std::vector<Component> components;
};

using Material = std::variant<Diffuse, Mirror, Dielectric, Glossy, Mixture>;

// The letter a basic material gives to a vertex: D for finite BSDFs, S for Dirac deltas.
inline Letter letter_of(const BasicMaterial& m) {
  return std::holds_alternative<Mirror>(m) || std::holds_alternative<Dielectric>(m) ? kS : kD;
}

// The letters a material can give (bit per letter), the union over a mixture's components.
inline LetterMask letters_of(const Material& m) {
  return std::visit(
      [](const auto& k) -> LetterMask {
        if constexpr (std::is_same_v<std::decay_t<decltype(k)>, Mixture>) {
          LetterMask out = 0;
          for (const auto& c : k.components)
            if (c.weight > 0.0f) out = static_cast<LetterMask>(out | (1u << letter_of(c.material)));
          return out;
        } else {
          return static_cast<LetterMask>(1u << letter_of(BasicMaterial{k}));
        }
      },
      m);
}

}  // namespace pathex
