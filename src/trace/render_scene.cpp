// make_render_scene() (trace/render_scene.h): a Scene flattened once per render into what the
// integrator's hot loop reads (the Embree geometry, each shape's material and emitter, the lights
// and the sensor as handles of the one emitter model), with the scene's refusals located.
#include "trace/render_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>

#include "optics/fresnel.h"
#include "trace/bsdf.h"
#include "trace/rng.h"

namespace pathex {

namespace {

// A sphere holding the shape: exact for spheres and disks, around the corners' centre for quads,
// around the bounding box's centre for meshes.
BoundingSphere bounding_sphere(const ShapeGeometry& g) {
  if (const auto* s = std::get_if<SphereShape>(&g)) return {s->center, s->radius};
  if (const auto* d = std::get_if<DiskShape>(&g)) return {d->center, d->radius};
  if (const auto* q = std::get_if<QuadShape>(&g)) {
    const glm::vec3 c = q->corner + 0.5f * (q->edge1 + q->edge2);
    return {c, 0.5f * std::max(glm::length(q->edge1 + q->edge2), glm::length(q->edge1 - q->edge2))};
  }
  const std::vector<glm::vec3>& p = std::get<MeshShape>(g).positions;
  if (p.empty()) return {};
  glm::vec3 lo = p[0], hi = p[0];
  for (const glm::vec3& v : p) {
    lo = glm::min(lo, v);
    hi = glm::max(hi, v);
  }
  const glm::vec3 c = 0.5f * (lo + hi);
  float r2 = 0.0f;
  for (const glm::vec3& v : p) r2 = std::max(r2, glm::dot(v - c, v - c));
  return {c, std::sqrt(r2)};
}

// A sphere (centre, radius) holding the shape, padded by a relative 1e-4 (the manifold's: the
// emission cones' bounding_sphere() above is tighter for quads and meshes).
glm::vec4 padded_sphere(const ShapeGeometry& g) {
  if (const auto* s = std::get_if<SphereShape>(&g)) return {s->center, s->radius * 1.0001f};
  if (const auto* d = std::get_if<DiskShape>(&g)) return {d->center, d->radius * 1.0001f};
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  const auto add = [&](const glm::vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); };
  if (const auto* q = std::get_if<QuadShape>(&g)) {
    for (const glm::vec3& p : {q->corner, q->corner + q->edge1, q->corner + q->edge2, q->corner + q->edge1 + q->edge2}) add(p);
  } else {
    for (const glm::vec3& p : std::get<MeshShape>(g).positions) add(p);
  }
  const glm::vec3 c = 0.5f * (lo + hi);
  return {c, 0.5f * glm::length(hi - lo) * 1.0001f + 1e-6f * glm::length(c)};
}

// The specular surfaces of rs (its shapes, lights and geometry made).
SpecularSurfaces specular_surfaces(const RenderScene& rs) {
  SpecularSurfaces sp;
  sp.glass_ior.assign(rs.material_of_shape.size(), 0.0f);
  sp.mirror_reflectance.assign(rs.material_of_shape.size(), glm::vec3(0.0f));
  for (std::size_t i = 0; i < rs.material_of_shape.size(); ++i) {
    if (rs.light_of_shape[i] >= 0 || rs.in_group[i]) continue;  // instanced members: opaque to the walks (RenderScene::in_group)
    // A bump or normal map turns the shading normal the walk's constraint does not see: opaque too.
    if (rs.textures_of_shape[i] && rs.textures_of_shape[i]->perturb != NormalPerturbation::kNone) continue;
    const Material& m = *rs.material_of_shape[i];
    if (const auto* d = std::get_if<Dielectric>(&m); d && d->ior > 0.0f && d->ior != 1.0f) sp.glass_ior[i] = d->ior;
    if (const auto* r = std::get_if<Mirror>(&m)) sp.mirror_reflectance[i] = r->reflectance;
    // A smooth conductor reflects like a mirror, by its Fresnel (here at normal incidence; the
    // chain's throughput takes it at the chain's angle).
    if (const auto* c = std::get_if<Conductor>(&m); c && c->smooth()) sp.mirror_reflectance[i] = c->tint * fresnel_complex(1.0f, c->eta, c->k);
    if (const auto* mix = std::get_if<Mixture>(&m)) sp.mirror_reflectance[i] = bsdf::mirror_reflectance(*mix);
    const glm::vec3& r = sp.mirror_reflectance[i];
    if (sp.glass_ior[i] > 0.0f || r.x != 0.0f || r.y != 0.0f || r.z != 0.0f) sp.shapes.push_back(static_cast<int>(i));
  }
  // Seeds pick a shape by the share of flux it passes on: 1 for glass (reflected plus
  // transmitted), a mirror's (or a mixture's mirror parts') mean reflectance, at most 1.
  float total = 0.0f;
  for (const int shape : sp.shapes) {
    const glm::vec3 r = sp.mirror_reflectance[static_cast<std::size_t>(shape)];
    total += sp.glass_ior[static_cast<std::size_t>(shape)] > 0.0f ? 1.0f : std::clamp((r.x + r.y + r.z) / 3.0f, 1e-3f, 1.0f);
    sp.seed_cdf.push_back(total);
  }
  for (float& c : sp.seed_cdf) c /= total;
  for (const int shape : sp.shapes) sp.bounds.push_back(padded_sphere(rs.geometry->shape_geometry(shape)));
  // A sphere is hollow when every other shape's surface stays outside it (touching allowed): a
  // sphere's nearest point, a flat piece's plane or its box at least the radius from the centre.
  // Instanced shapes are not looked at: with any, no sphere is hollow; nor is one with a cut-out.
  sp.hollow.assign(rs.material_of_shape.size(), 0);
  for (const int shape : sp.shapes) {
    const auto* ball = std::get_if<SphereShape>(&rs.geometry->shape_geometry(shape));
    bool hollow = ball && rs.scene->instances.empty() && rs.scene->shapes[static_cast<std::size_t>(shape)].alpha < 0;
    const float r = ball ? ball->radius * (1.0f - 1e-4f) : 0.0f;
    const auto outside = [&](const glm::vec3& lo, const glm::vec3& hi, const glm::vec3& on, const glm::vec3& n) {
      const glm::vec3 q = glm::clamp(ball->center, lo, hi);  // the box's point nearest the centre
      return glm::length(q - ball->center) >= r || std::fabs(glm::dot(ball->center - on, glm::normalize(n))) >= r;
    };
    for (std::size_t j = 0; j < rs.scene->shapes.size() && hollow; ++j) {
      const ShapeGeometry& g = rs.scene->shapes[j].geometry;
      if (static_cast<int>(j) == shape) continue;
      if (const auto* o = std::get_if<SphereShape>(&g)) {
        hollow = std::fabs(glm::length(o->center - ball->center) - o->radius) >= r;
      } else if (const auto* k = std::get_if<DiskShape>(&g)) {
        hollow = outside(k->center - k->radius, k->center + k->radius, k->center, k->normal);
      } else if (const auto* q = std::get_if<QuadShape>(&g)) {
        const glm::vec3 far = q->corner + q->edge1 + q->edge2;
        hollow = outside(glm::min(glm::min(q->corner, far), glm::min(q->corner + q->edge1, q->corner + q->edge2)),
                         glm::max(glm::max(q->corner, far), glm::max(q->corner + q->edge1, q->corner + q->edge2)), q->corner,
                         glm::cross(q->edge1, q->edge2));
      } else {
        const MeshShape& m = std::get<MeshShape>(g);
        for (const glm::uvec3& t : m.triangles) {
          const glm::vec3 &a = m.positions[t.x], &b = m.positions[t.y], &c = m.positions[t.z];
          hollow = hollow && outside(glm::min(a, glm::min(b, c)), glm::max(a, glm::max(b, c)), a, glm::cross(b - a, c - a));
        }
      }
    }
    sp.hollow[static_cast<std::size_t>(shape)] = hollow ? 1 : 0;
  }
  RTCBounds b;
  rtcGetSceneBounds(rs.geometry->handle(), &b);
  const double dx = static_cast<double>(b.upper_x) - b.lower_x, dy = static_cast<double>(b.upper_y) - b.lower_y,
               dz = static_cast<double>(b.upper_z) - b.lower_z;
  const double size = std::sqrt(dx * dx + dy * dy + dz * dz);
  sp.scene_size = std::isfinite(size) && size > 0.0 ? size : 1.0;
  return sp;
}

// The image infinite light of `image`, whose box is `box` (trace/environment.h).
EnvironmentLightParams environment_light(const EnvironmentImage& image, const Shape& box) {
  auto m = std::make_shared<EnvironmentMap>();
  m->equal_area = image.equal_area;
  m->width = image.width;
  m->height = image.height;
  m->texels = image.texels;
  m->to_world = image.to_world;
  m->build_distribution(image.uniform_sampling);
  const std::vector<glm::vec3>& p = std::get<MeshShape>(box.geometry).positions;
  m->box_lo = m->box_hi = p[0];
  for (const glm::vec3& v : p) {
    m->box_lo = glm::min(m->box_lo, v);
    m->box_hi = glm::max(m->box_hi, v);
  }
  m->center = 0.5f * (m->box_lo + m->box_hi);
  m->radius = 0.5f * glm::length(m->box_hi - m->box_lo) * 1.0001f;  // the disk covers the box
  return EnvironmentLightParams{std::move(m)};
}

}  // namespace

bool SpecularSurfaces::meets(const EmbreeScene& geometry, const glm::vec3& o, const glm::vec3& d, int leaving) const {
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    if (shapes[k] == leaving && std::holds_alternative<SphereShape>(geometry.shape_geometry(leaving))) continue;
    const glm::vec4& bs = bounds[k];
    const glm::vec3 oc = glm::vec3(bs) - o;
    const float along = glm::dot(oc, d), r2 = bs.w * bs.w, oc2 = glm::dot(oc, oc);
    // (in float: the bounds are padded by 1e-4 of the radius, far above this test's rounding)
    if (oc2 <= r2 || (along > 0.0f && oc2 - along * along <= r2)) return true;
  }
  return false;
}

Result<RenderScene> make_render_scene(const Scene& scene) {
  RenderScene rs;
  Result<std::unique_ptr<EmbreeScene>> geometry = EmbreeScene::build(scene);
  if (!geometry) return geometry.error();
  rs.geometry = std::move(*geometry);
  rs.scene = &scene;
  rs.light_of_shape.assign(scene.shapes.size(), -1);
  for (std::size_t i = 0; i < scene.shapes.size(); ++i) {
    const Shape& s = scene.shapes[i];
    rs.material_of_shape.push_back(&scene.materials[static_cast<std::size_t>(s.material)]);
    const MaterialTextures* tex = static_cast<std::size_t>(s.material) < scene.material_textures.size()
                                      ? &scene.material_textures[static_cast<std::size_t>(s.material)]
                                      : nullptr;
    rs.textures_of_shape.push_back(tex && !tex->empty() ? tex : nullptr);
    rs.textured = rs.textured || rs.textures_of_shape.back() != nullptr;
    rs.in_group.push_back(s.group >= 0 ? 1 : 0);
    rs.emission_of_shape.push_back(s.emission);
    rs.absorption_of_shape.push_back(s.absorption);
    rs.absorbing = rs.absorbing || s.absorption != glm::vec3(0.0f);
    // Planar mirrors, for the mirror connector: quads of a pure mirror material (without a bump or
    // normal map, whose normal the connector's plane does not have).
    const bool perturbed = tex && tex->perturb != NormalPerturbation::kNone;
    const auto* quad = s.group < 0 && !perturbed ? std::get_if<QuadShape>(&s.geometry) : nullptr;
    const auto* mirror = std::get_if<Mirror>(rs.material_of_shape.back());
    const glm::vec3 n = quad ? glm::cross(quad->edge1, quad->edge2) : glm::vec3(0.0f);
    rs.planar_mirror.push_back(quad && mirror && !s.emissive() && glm::length(n) > 0.0f ? 1 : 0);
    if (rs.planar_mirror.back())
      rs.mirrors.push_back({static_cast<int>(i), quad->corner, quad->edge1, quad->edge2, glm::normalize(n),
                            mirror->reflectance, parallelogram_error(quad->corner, quad->edge1, quad->edge2)});
    // A zero-area emitter emits nothing; it is not a light (and would have an infinite density).
    if (!s.emissive() || !(rs.geometry->shape_area(static_cast<int>(i)) > 0.0f)) continue;
    RenderLight l;
    l.params = AreaLightParams{s.emission, s.two_sided};
    if (scene.environment_image && scene.environment_image->shape == static_cast<int>(i)) l.params = environment_light(*scene.environment_image, s);
    l.shape = static_cast<int>(i);
    l.pdf_pos = 1.0f / rs.geometry->shape_area(l.shape);
    rs.light_of_shape[i] = static_cast<int>(rs.lights.size());
    rs.lights.push_back(l);
  }
  rs.features = scene_features(rs.material_of_shape);
  for (std::size_t i = 0; i < scene.shapes.size(); ++i)
    if (scene.shapes[i].group < 0 && scene_features({rs.material_of_shape[i]}).specular)
      rs.specular_bounds.push_back(bounding_sphere(scene.shapes[i].geometry));
  // An instance's specular members: their spheres moved by its transform, the radius scaled by
  // the transform's largest stretch (bounded by the Frobenius norm of its linear part).
  std::vector<std::vector<BoundingSphere>> specular_members(scene.groups.size());
  for (std::size_t i = 0; i < scene.shapes.size(); ++i)
    if (scene.shapes[i].group >= 0 && scene_features({rs.material_of_shape[i]}).specular)
      specular_members[static_cast<std::size_t>(scene.shapes[i].group)].push_back(bounding_sphere(scene.shapes[i].geometry));
  for (const ShapeInstance& inst : scene.instances) {
    const glm::mat3 l(inst.to_world);
    const float stretch = std::sqrt(glm::dot(l[0], l[0]) + glm::dot(l[1], l[1]) + glm::dot(l[2], l[2]));
    for (const BoundingSphere& b : specular_members[static_cast<std::size_t>(inst.group)])
      rs.specular_bounds.push_back({glm::vec3(inst.to_world * glm::vec4(b.center, 1.0f)), b.radius * stretch * 1.0001f});
  }
  for (const Light& light : scene.lights) {
    RenderLight l;
    if (const auto* p = std::get_if<PointLight>(&light)) {
      l.params = PointLightParams{p->position, p->intensity};
    } else if (const auto* s = std::get_if<SpotLight>(&light)) {
      const float cos_cone = std::cos(glm::radians(s->cone_degrees));
      const float cos_start = s->falloff_start_degrees < 0.0f ? cos_cone : std::cos(glm::radians(s->falloff_start_degrees));
      l.params = SpotLightParams{s->position, s->direction, s->intensity, cos_cone, std::max(cos_start, cos_cone),
                                 s->falloff == SpotFalloff::kLinear};
    } else if (const auto* d = std::get_if<DistantLight>(&light)) {
      const DistantLightParams params{d->direction, d->irradiance, d->aperture_corner, d->aperture_edge1, d->aperture_edge2};
      l.params = params;
      l.pdf_pos = 1.0f / aperture_area(params);
      l.origin_error = parallelogram_error(params.corner, params.edge1, params.edge2);
    } else {
      const LaserLight& z = std::get<LaserLight>(light);
      l.params = LaserParams{z.position, z.direction, z.power};
    }
    rs.lights.push_back(l);
  }
  rs.specular = specular_surfaces(rs);
  for (RenderLight& l : rs.lights) l.letters = {letter_char(pos_letter(l.params)), letter_char(dir_letter(l.params))};
  // --- the sensor ---
  const Camera& c = scene.camera;
  RenderSensor& cam = rs.camera;
  cam.type = c.type;
  cam.width = c.width;
  cam.height = c.height;
  const glm::vec3 forward = glm::normalize(c.look_at - c.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, c.up));
  const glm::vec3 up = glm::cross(right, forward);
  const float tan_y = std::tan(glm::radians(c.fov_degrees) * 0.5f);
  const float tan_x = tan_y * static_cast<float>(c.width) / static_cast<float>(c.height);
  switch (c.type) {
    case SensorType::kPinhole: cam.params = PinholeParams{c.position, forward, right, up, tan_x, tan_y}; break;
    case SensorType::kLens:
      cam.params = ThinLensParams{c.position, forward, right, up, tan_x, tan_y, c.aperture_radius, c.focus_distance};
      cam.pdf_pos = 1.0f / (kPi * c.aperture_radius * c.aperture_radius);
      break;
    case SensorType::kOrthographic:
      cam.params = OrthographicParams{c.position, forward, right, up, 0.5f * c.film_width, 0.5f * c.film_height};
      cam.pdf_pos = 1.0f / (c.film_width * c.film_height);
      break;
    case SensorType::kSpotmeter: cam.params = SpotMeterParams{c.position, forward}; break;
  }
  cam.letters = {letter_char(dir_letter(cam.params)), letter_char(pos_letter(cam.params))};
  return rs;
}

void sample_lights_by_solid_angle(RenderScene& rs, const Scene& scene, bool rectangles) {
  for (RenderLight& l : rs.lights) {
    auto* area = std::get_if<AreaLightParams>(&l.params);
    if (!area || !l.is_area()) continue;
    const Shape& s = scene.shapes[static_cast<std::size_t>(l.shape)];
    if (s.group >= 0) continue;
    if (const auto* q = std::get_if<QuadShape>(&s.geometry); rectangles && q && is_rectangle(q->edge1, q->edge2)) {
      area->towards = AreaLightParams::Towards::kRectangle;
      area->corner = q->corner;
      area->edge1 = q->edge1;
      area->edge2 = q->edge2;
      area->normal = glm::normalize(glm::cross(q->edge1, q->edge2));  // as the shape's (EmbreeScene::sample_shape)
      l.origin_error = parallelogram_error(q->corner, q->edge1, q->edge2);
    } else if (const auto* sp = std::get_if<SphereShape>(&s.geometry)) {
      area->towards = AreaLightParams::Towards::kSphere;
      area->center = sp->center;
      area->radius = sp->radius;
      // EmbreeScene's bound for a point of the sphere at any normal (its |n| at most 1 a component).
      l.origin_error = error_gamma(8) * (glm::abs(sp->center) + glm::vec3(sp->radius));
    } else {
      continue;
    }
    area->pdf_area = l.pdf_pos;
  }
}

void aim_emission(RenderScene& rs, const Scene& scene, const std::vector<int>& lights) {
  const std::size_t area_lights = rs.lights.size() - scene.lights.size();  // the emissive shapes come first
  for (const int i : lights) {
    const Light& light = scene.lights[static_cast<std::size_t>(i)];
    const glm::vec3 origin = std::holds_alternative<PointLight>(light) ? std::get<PointLight>(light).position
                                                                       : std::get<SpotLight>(light).position;
    rs.lights[area_lights + static_cast<std::size_t>(i)].aim = EmissionCones::make(origin, rs.specular_bounds);
  }
}

}  // namespace pathex
