// What the integrator needs from a scene, flattened for the hot loop: the Embree geometry, each
// shape's material and emission, the lights as sampling-ready records, and the sensor model.
// Built once per render from scene/scene.h by make_render_scene().
//
// Conventions (DESIGN §1): every light and sensor contributes two letters. Area lights are
// "DD" (a density over area, a finite directional emission), point and spot lights "SD", distant
// lights through an aperture "DS", lasers "SS". Sensors: thin lens "DD", pinhole "DS",
// orthographic "SD", spot meter "SS" (directional letter first, c(k+1), then spatial, c(k+2)).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "trace/embree_scene.h"

namespace pathex {

// The emitters the tracer samples; spot lights share the point light's letters (SD).
enum class EmitterKind : std::uint8_t { kArea, kPoint, kSpot, kDistant, kLaser };
LightType letter_type(EmitterKind k);

struct RenderLight {
  EmitterKind type = EmitterKind::kPoint;
  glm::vec3 power{0.0f};      // area: radiance Le; point/spot: intensity I; distant: irradiance E; laser: power
  glm::vec3 position{0.0f};   // point, spot, laser
  glm::vec3 direction{0.0f};  // spot axis, distant travel direction, laser direction (unit)
  float cos_cone = -1.0f;     // spot: cosine of the cone's half angle
  int shape = -1;             // area: the emissive shape
  bool two_sided = false;     // area
  // distant: the aperture quad the light passes through
  glm::vec3 ap_corner{0.0f}, ap_edge1{0.0f}, ap_edge2{0.0f}, ap_normal{0.0f};
  float ap_area = 0.0f;
};

struct RenderCamera {
  SensorType type = SensorType::kPinhole;
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f}, right{1.0f, 0.0f, 0.0f}, up{0.0f, 1.0f, 0.0f};
  int width = 1, height = 1;
  float tan_x = 1.0f, tan_y = 1.0f;     // pinhole, lens: half extent of the image plane at distance 1
  float lens_radius = 0.0f;             // lens
  float focus_distance = 1.0f;          // lens
  float film_width = 1.0f, film_height = 1.0f;  // orthographic, world units
  float image_area() const { return 4.0f * tan_x * tan_y; }
};

struct RenderScene {
  std::unique_ptr<EmbreeScene> geometry;
  std::vector<const Material*> material_of_shape;
  std::vector<glm::vec3> emission_of_shape;  // Le, zero for non-emitters
  std::vector<int> light_of_shape;           // index into lights, -1 for non-emitters
  std::vector<RenderLight> lights;
  RenderCamera camera;
};

Result<RenderScene> make_render_scene(const Scene& scene);

}  // namespace pathex
