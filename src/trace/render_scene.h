// What the integrator needs from a scene, flattened for the hot loop: the Embree geometry, each
// shape's material and emission, the lights and the sensor as handles of the one emitter model
// (trace/emitters.h).
// Built once per render from scene/scene.h by make_render_scene().
//
// Conventions (DESIGN §1): every light and sensor contributes two letters. Area lights are
// "DD" (a density over area, a finite directional emission), point and spot lights "SD", distant
// lights through an aperture "DS", lasers "SS". Sensors: thin lens "DD", pinhole "DS",
// orthographic "SD", spot meter "SS" (directional letter first, c(k+1), then spatial, c(k+2)).
#pragma once

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "scene/material.h"
#include "scene/scene.h"
#include "trace/embree_scene.h"
#include "trace/emission_cones.h"
#include "trace/emitters.h"
#include "trace/joins/mirror.h"
#include "trace/rng.h"
#include "trace/scene_features.h"
#include "trace/texture_eval.h"

namespace pathex {

// A light of the render: its emission model (trace/emitters.h) and where the integrator finds
// its points.
struct RenderLight {
  LightParams params;
  int shape = -1;       // area lights: the emissive shape, whose points are sampled by area
  // Area density of the emitting point as the MIS ratios keep it: 1 / area for an area light and
  // for a distant light's aperture, 0 for a Dirac position (point, spot, laser).
  float pdf_pos = 0.0f;
  // The plan's emission narrowing (trace/plan.h): the cones a point or spot light draws its first
  // direction in (trace/emission_cones.h); none: the light's own emission sampling.
  std::optional<EmissionCones> aim;
  // The rounding-error bound of the points rays leave from when they are not a shape's (a distant
  // light's aperture may coincide with one, a window pane); zero for the others.
  glm::vec3 origin_error{0.0f};
  std::string letters;  // c0 c1: its position's letter, then its direction's (the header's conventions)
  bool is_area() const { return shape >= 0; }
  // Whether x0's light density in a path is next-event estimation's from x1 (trace/emitters.h
  // draws_towards()): always for an image infinite light, which has no other; for a rectangle
  // sampled by solid angle where next-event estimation could join x0 to x1 (`x1_joinable`: a
  // surface with a finite part, a sensor with a finite direction), elsewhere (x1 a Dirac vertex,
  // which the connectors' fresh light ends reach by area) its area density.
  bool drawn_towards(bool x1_joinable) const { return draws_towards(params) && (x1_joinable || environment() != nullptr); }
  // The image infinite light this is (trace/environment.h), or null.
  const EnvironmentLightParams* environment() const { return std::get_if<EnvironmentLightParams>(&params); }
  // x0's light density in a path whose x1 is at `x1` (without the light's pick): next-event
  // estimation's from x1 where drawn towards it, else its area density (0 for a Dirac position).
  float origin_density(const glm::vec3& x0, const glm::vec3& n0, const glm::vec3& x1, bool x1_joinable) const {
    return drawn_towards(x1_joinable) ? towards_area_density(params, x0, n0, x1) : pdf_pos;
  }
  // The rounding-error bound of a point drawn towards a point (an image light's box, a rectangle).
  glm::vec3 towards_point_error(const glm::vec3& p) const { return environment() ? box_point_error(p) : origin_error; }
  // The light's first ray from point x (an area light's; the others ignore it) by u, and the
  // densities of its ray from x towards w: the emitter model's, through the aiming decorator when
  // the light is aimed. Every strategy samples and weighs a light's emission through these.
  std::optional<EndpointRay> sample_ray(const SurfacePoint& x, glm::vec2 u) const {
    return aim ? aimed_ray(*aim, params, x, u) : pathex::sample_ray(params, x, u);
  }
  RayPdf pdf_ray(const SurfacePoint& x, const glm::vec3& w) const {
    return aim ? aimed_pdf(*aim, params, x, w) : pathex::pdf_ray(params, x, w);
  }
};

// The sensor: its importance model and the image it measures.
struct RenderSensor {
  SensorParams params;
  SensorType type = SensorType::kPinhole;
  int width = 1, height = 1;  // pixels
  // Area density of the ray's origin as the MIS ratios keep it: 1 / lens area, 1 / film area,
  // 0 for a point (pinhole, spot meter).
  float pdf_pos = 0.0f;
  std::string letters;  // c(k+1) c(k+2): its direction's letter, then its position's
  // Pixel coordinates of a raster position in [0,1)² (the product may round up to the width).
  void to_pixels(glm::vec2 raster, float* rx, float* ry) const {
    const float w = static_cast<float>(width), h = static_cast<float>(height);
    *rx = std::min(raster.x * w, below(w));
    *ry = std::min(raster.y * h, below(h));
  }
  // std::nextafter(x, 0) for a finite x >= 1 (a pixel count): the float one step towards zero is
  // the one whose bits are one less. On the bits, not libm's call: every splat takes two (bdpt
  // made 1.6 M such calls at 4 spp on Tungsten's box, ~1 % of its instructions).
  static float below(float x) { return std::bit_cast<float>(std::bit_cast<std::uint32_t>(x) - 1u); }
  // The eye subpath's first ray through pixel (px, py), from the sample's numbers at rng's
  // dimension (film, then lens), and its origin's normal as the sensor vertex keeps it (none for
  // a point).
  std::optional<EndpointRay> primary_ray(Sampler& rng, int px, int py) const {
    const glm::vec2 uf = rng.get2d();
    const glm::vec2 ul = rng.get2d_if(reads_lens_numbers(params));
    const glm::vec2 raster{(static_cast<float>(px) + uf.x) / static_cast<float>(width),
                           (static_cast<float>(py) + uf.y) / static_cast<float>(height)};
    return sample_ray(params, raster, ul);
  }
  glm::vec3 origin_normal(const EndpointRay& r) const { return pdf_pos == 0.0f ? glm::vec3(0.0f) : r.normal; }
  // The axis of a sensor with a finite direction (a pinhole's, a thin lens's `forward`; 0 for the
  // others): the normal of the plane over which a join that ends on its point measures area there,
  // as connect_finite()'s cosine does (the manifold connector at t = 1, whose direction at the point
  // the walk finds).
  glm::vec3 axis() const {
    if (const auto* p = std::get_if<PinholeParams>(&params)) return p->forward;
    if (const auto* l = std::get_if<ThinLensParams>(&params)) return l->forward;
    return glm::vec3(0.0f);
  }
};

// Room for a material with its textured parameters evaluated (RenderScene::material_at): a
// Material is made in it only at a textured shape, so that a scene without textures makes none.
// (Not std::optional<Material>, whose construction zero-fills the storage: 120 bytes at every
// surface vertex.)
class MaterialScratch {
 public:
  MaterialScratch() {}  // NOLINT: the storage stays unmade
  MaterialScratch(const MaterialScratch&) = delete;
  MaterialScratch& operator=(const MaterialScratch&) = delete;
  ~MaterialScratch() {
    if (made_) material_.~Material();
  }
  // The material in it, default-made the first time.
  Material& get() {
    if (!made_) {
      new (&material_) Material();
      made_ = true;
    }
    return material_;
  }

 private:
  union {
    Material material_;
  };
  bool made_ = false;
};

// The manifold connector's specular surfaces (trace/joins/manifold.h), found once per scene as the
// planar mirrors are: per shape, the index of a pure smooth dielectric, else 0; the reflectance of
// a mirror (a smooth conductor's at normal incidence, a mixture's mirror components weighed), else
// 0. Group members and shapes with a bump or normal map are left out (opaque to the walks).
struct SpecularSurfaces {
  std::vector<float> glass_ior;
  std::vector<glm::vec3> mirror_reflectance;
  std::vector<int> shapes;             // the shapes with either (the manifold's seeds aim at points on them)
  std::vector<float> seed_cdf;         // the seeds' choice among them (cumulative, last 1)
  std::vector<glm::vec4> bounds;       // a bounding sphere of each (centre, radius): joins no chain can leave skip
  std::vector<std::uint8_t> hollow;    // of every shape: 1 for a sphere of these that no other surface enters (trace/joins/manifold_join.cpp)
  double scene_size = 1.0;             // the scene's bounding-box diagonal (the manifold's shortest segment scales with it)
  // Whether the ray (o, d) can meet one of the shapes: it passes through one's bounding sphere, but
  // for shape `leaving` when that is a sphere (the ray leaves it outwards).
  bool meets(const EmbreeScene& geometry, const glm::vec3& o, const glm::vec3& d, int leaving) const;
};

struct RenderScene {
  std::unique_ptr<EmbreeScene> geometry;
  std::vector<const Material*> material_of_shape;
  // The textured parameters of each shape's material (scene/texture.h), null for none; `scene`
  // holds the textures. `textured`: some shape has them, so hits carry uv (trace/texture_eval.h).
  std::vector<const MaterialTextures*> textures_of_shape;
  const Scene* scene = nullptr;
  bool textured = false;
  std::vector<glm::vec3> emission_of_shape;  // Le, zero for non-emitters
  std::vector<int> light_of_shape;           // index into lights, -1 for non-emitters
  std::vector<glm::vec3> absorption_of_shape;  // σa of the shape's interior (trace/media.h), zero for none
  bool absorbing = false;                    // some shape has an absorbing interior
  std::vector<RenderLight> lights;
  std::vector<PlanarMirror> mirrors;         // quads of a pure mirror material (the mirror connector's)
  std::vector<std::uint8_t> planar_mirror;   // per shape: 1 for one of `mirrors`
  RenderSensor camera;
  SceneFeatures features;                    // what the shapes' materials can do (trace/scene_features.h)
  // A sphere around each shape whose material has a specular (Dirac) component: where a path whose
  // first surface vertex scatters specularly can start (trace/emission_cones.h).
  std::vector<BoundingSphere> specular_bounds;
  // 1 for a shape that is a group member, drawn by instances (scene.h ShapeInstance); the manifold
  // connector's walks know world-space shapes only and treat these as opaque.
  std::vector<std::uint8_t> in_group;
  SpecularSurfaces specular;  // the manifold connector's

  // --- what every strategy asks of the scene ---
  // A light chosen uniformly by u. (u n lies in [0, n), far below 2^63: the signed conversion is
  // exact and, unlike the unsigned one, a single instruction. A lone light's pick reads no number.)
  std::size_t pick_light(Sampler& rng) const {
    const float u = rng.get1d_if(lights.size() > 1);
    const auto i = static_cast<std::int64_t>(u * static_cast<float>(lights.size()));
    return std::min(lights.size() - 1, static_cast<std::size_t>(i));
  }
  // A point on light l drawn from u2 (area lights; the others ignore the point and read no number),
  // with its rounding-error bound (SurfaceSample::error) in *error, which offsets rays leaving it.
  SurfacePoint sample_point(const RenderLight& l, Sampler& rng, glm::vec3* error) const {
    const glm::vec2 u2 = rng.get2d_if(l.is_area());
    *error = l.origin_error;
    if (!l.is_area()) return {};
    const SurfaceSample ss = geometry->sample_shape(l.shape, u2);
    *error = ss.error;
    return {ss.position, ss.normal, l.pdf_pos};
  }
  // Light l's first ray, its direction from u_ray (drawn in advance, its dimensions skipped) and its
  // point from the next numbers: an area light's point (*x, with its rounding-error bound in
  // *error), or an image infinite light's disk point, drawn from the numbers an area light's point
  // takes. (An aimed light draws its direction within its cones: RenderLight::sample_ray.)
  std::optional<EndpointRay> emit(const RenderLight& l, Sampler& rng, glm::vec2 u_ray, SurfacePoint* x, glm::vec3* error) const {
    const EnvironmentLightParams* env = l.environment();
    const glm::vec2 u_disk = env ? rng.get2d() : glm::vec2(0.0f);
    if (!env) *x = sample_point(l, rng, error);
    rng.skip(2);
    if (!env) return l.sample_ray(*x, u_ray);
    const std::optional<EndpointRay> r = sample_ray(*env, u_ray, u_disk);
    if (r) *error = box_point_error(r->origin);
    return r;
  }
  // The material of `shape` at `uv`: its own, or, when it has textured parameters, the material
  // with them evaluated, made in `*scratch` (trace/texture_eval.h).
  const Material& material_at(int shape, glm::vec2 uv, MaterialScratch* scratch) const {
    const Material& base = *material_of_shape[static_cast<std::size_t>(shape)];
    const MaterialTextures* tex = textures_of_shape[static_cast<std::size_t>(shape)];
    if (!tex) return base;
    Material& made = scratch->get();
    textured_material(*scene, base, *tex, uv, &made);
    return made;
  }
  // A hit's shading normal as every strategy sees it (pt, pt-nee, lt, bdpt's joins and the MIS
  // densities all read the vertex's ns): the geometry's (Hit::shading_normal) turned by its
  // material's bump or normal map (trace/texture_eval.h perturbed_normal). The letter stays.
  glm::vec3 shading_normal(const Hit& h) const {
    const MaterialTextures* tex = textures_of_shape[static_cast<std::size_t>(h.shape)];
    if (!tex || tex->perturb == NormalPerturbation::kNone) return h.shading_normal;
    glm::vec3 dpdu, dpdv;
    geometry->uv_tangents(h, &dpdu, &dpdv);
    return perturbed_normal(*scene, *tex, h.uv, h.normal, h.shading_normal, dpdu, dpdv);
  }
};

Result<RenderScene> make_render_scene(const Scene& scene);

// `pathex trace --light-sampling sphere-cone` (and solid-angle, with `rectangles`): every area
// light that is one sphere (and one rectangle: a quad with perpendicular edges), not an instance's,
// draws its next-event points by the solid angle it subtends (AreaLightParams::towards,
// trace/spherical_rect.h); the others (meshes, disks, parallelograms) keep area sampling.
void sample_lights_by_solid_angle(RenderScene& rs, const Scene& scene, bool rectangles);

// The plan's emission narrowing (trace/plan.h RenderPlan::aimed_lights, indices into scene.lights,
// each a point or spot light): each aims at the shapes with a specular component
// (rs.specular_bounds) where that leaves some direction out (EmissionCones::make).
void aim_emission(RenderScene& rs, const Scene& scene, const std::vector<int>& lights);

}  // namespace pathex
