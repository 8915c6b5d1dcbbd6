#include "trace/render_scene.h"

#include <cmath>

namespace pathex {

LightType letter_type(EmitterKind k) {
  switch (k) {
    case EmitterKind::kArea: return LightType::kArea;
    case EmitterKind::kPoint:
    case EmitterKind::kSpot: return LightType::kPoint;
    case EmitterKind::kDistant: return LightType::kDistant;
    case EmitterKind::kLaser: return LightType::kLaser;
  }
  return LightType::kPoint;
}

Result<RenderScene> make_render_scene(const Scene& scene) {
  RenderScene rs;
  Result<std::unique_ptr<EmbreeScene>> geometry = EmbreeScene::build(scene);
  if (!geometry) return geometry.error();
  rs.geometry = std::move(*geometry);
  rs.light_of_shape.assign(scene.shapes.size(), -1);
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const Shape& s = scene.shapes[i];
    rs.material_of_shape.push_back(&scene.materials[static_cast<std::size_t>(s.material)]);
    rs.emission_of_shape.push_back(s.emission);
    // A zero-area emitter emits nothing; it is not a light (and would have an infinite density).
    if (!s.emissive() || !(rs.geometry->shape_area(static_cast<int>(i)) > 0.0f)) continue;
    RenderLight l;
    l.type = EmitterKind::kArea;
    l.power = s.emission;
    l.shape = static_cast<int>(i);
    l.two_sided = s.two_sided;
    rs.light_of_shape[i] = static_cast<int>(rs.lights.size());
    rs.lights.push_back(l);
  }
  for (const Light& light : scene.lights) {
    RenderLight l;
    if (const auto* p = std::get_if<PointLight>(&light)) {
      l.type = EmitterKind::kPoint;
      l.position = p->position;
      l.power = p->intensity;
    } else if (const auto* s = std::get_if<SpotLight>(&light)) {
      l.type = EmitterKind::kSpot;
      l.position = s->position;
      l.direction = s->direction;
      l.power = s->intensity;
      l.cos_cone = std::cos(glm::radians(s->cone_degrees));
    } else if (const auto* d = std::get_if<DistantLight>(&light)) {
      l.type = EmitterKind::kDistant;
      l.direction = d->direction;
      l.power = d->irradiance;
      l.ap_corner = d->aperture_corner;
      l.ap_edge1 = d->aperture_edge1;
      l.ap_edge2 = d->aperture_edge2;
      const glm::vec3 n = glm::cross(d->aperture_edge1, d->aperture_edge2);
      l.ap_area = glm::length(n);
      l.ap_normal = n / l.ap_area;
    } else {
      const LaserLight& z = std::get<LaserLight>(light);
      l.type = EmitterKind::kLaser;
      l.position = z.position;
      l.direction = z.direction;
      l.power = z.power;
    }
    rs.lights.push_back(l);
  }
  // --- the sensor ---
  const Camera& c = scene.camera;
  RenderCamera& cam = rs.camera;
  cam.type = c.type;
  cam.position = c.position;
  cam.forward = glm::normalize(c.look_at - c.position);
  cam.right = glm::normalize(glm::cross(cam.forward, c.up));
  cam.up = glm::cross(cam.right, cam.forward);
  cam.width = c.width;
  cam.height = c.height;
  cam.tan_y = std::tan(glm::radians(c.fov_degrees) * 0.5f);
  cam.tan_x = cam.tan_y * static_cast<float>(c.width) / static_cast<float>(c.height);
  cam.lens_radius = c.aperture_radius;
  cam.focus_distance = c.focus_distance;
  cam.film_width = c.film_width;
  cam.film_height = c.film_height;
  return rs;
}

}  // namespace pathex
