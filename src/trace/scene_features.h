// What a scene's materials can do, computed once when the render scene is built
// (make_render_scene()), so that the integrator runs only the transport code the scene can need
// (issue 14, "effects the scene cannot have are not simulated"; DESIGN §11).
//
// The subpath walk (Integrator::random_walk) skips what the features rule out: without a specular
// material it keeps no Dirac densities (every sampled lobe has a density, none is stored as the
// symbolic 0), and without a dielectric it tracks no η² for Russian roulette (no refraction scales
// radiance). The BSDF code that runs at a vertex is always the hit material's own (bsdf::sample()
// dispatches on it), so a scene without a dielectric never reaches transmission sampling either.
// The walk tests the features at run time (one branch that always goes the same way): compiled
// once per feature set, the three walks made the tracer's code too large for GCC to inline
// bsdf::sample() into them, which cost more than the branches. tests/trace/scene_features_test.cpp
// checks the features of the sample scenes and that the walk traces the same subpaths, bit for
// bit, as with every feature on.
#pragma once

#include <variant>
#include <vector>

#include "scene/material.h"

namespace pathex {

struct SceneFeatures {
  bool specular = true;      // some material has a Dirac lobe (mirror, dielectric, smooth coat) of nonzero weight
  bool transmission = true;  // some material has a dielectric (refracting) lobe, smooth or rough, of nonzero weight
  bool operator==(const SceneFeatures&) const = default;
};

// The features of a scene whose shapes use `materials` (each shape's; repeats are harmless).
inline SceneFeatures scene_features(const std::vector<const Material*>& materials) {
  SceneFeatures f{false, false};
  const auto add = [&f](const BasicMaterial& m, float weight) {
    if (!(weight > 0.0f)) return;
    f.specular = f.specular || (letters_of(m) & (1u << kS)) != 0;
    f.transmission = f.transmission || std::holds_alternative<Dielectric>(m) || std::holds_alternative<RoughDielectric>(m);
  };
  for (const Material* m : materials) {
    if (const auto* mix = std::get_if<Mixture>(m)) {
      for (const Mixture::Component& c : mix->components) add(c.material, c.weight);
    } else {
      std::visit([&](const auto& k) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(k)>, Mixture>) add(BasicMaterial{k}, 1.0f);
      }, *m);
    }
  }
  return f;
}

}  // namespace pathex
