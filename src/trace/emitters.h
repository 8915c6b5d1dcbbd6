// The one light and sensor model of the tracer: emission (lights) and importance (sensors) as plain
// functions over plain parameter structs, and the handles LightParams / SensorParams (a variant of
// those structs) that every strategy of the integrator calls. render_scene.cpp maps scene objects
// to these structs, so this file depends on no scene type.
//
// Every endpoint has a spatial and a directional part (Veach §8.3.2: L_e = L_e⁽⁰⁾ L_e⁽¹⁾,
// W_e = W_e⁽⁰⁾ W_e⁽¹⁾), each either a finite density (letter D) or a Dirac delta (letter S); the
// letters are the kPosLetter / kDirLetter of each struct and match alphabet.h's light_letters()
// and sensor_letters() (DESIGN §1):
//
//   area light  D D   cosine-weighted emission from a point the integrator chose on the surface
//   point light S D   isotropic intensity I [W/sr]
//   spot light  S D   intensity I times a cone falloff (smoothstep, or a hard edge)
//   distant     D S   irradiance E [W/m²] in one direction, entering through an aperture
//   laser       S S   power Φ [W] along one ray
//   environment D D   an image infinite light: a box around the scene emitting L(−ω) inwards
//   thin lens   D D   pinhole  D S   orthographic  S D   spot meter  S S   (sensors: dir, pos)
//
// Each kind offers
//   sample_ray(...)  -> EndpointRay: the first ray of a light or eye subpath, with the densities
//                      of its origin and direction and its starting throughput `weight`;
//   pdf_ray(...)     -> RayPdf: the same densities for a given ray (BDPT's reverse densities);
//   connect(...)     -> EndpointConnection: a point on the endpoint joined to a reference point
//                      (next-event estimation for lights; the t = 1 splat for sensors), or
//                      nullopt where no join exists (a laser or a spot meter has probability 0
//                      of passing through a given point);
//   and the value: emitted_radiance(), intensity(), importance().
//
// Deltas are symbolic (DESIGN §7), with one convention for the whole tracer: a Dirac part has
// density 0 and its flag set (RayPdf::delta_pos, delta_dir; EndpointConnection::delta; the letter
// S), and its value is the delta's weight. The walks store a Dirac's density as 0 too, and the MIS
// weight alone counts a stored 0 as 1 (tracer::remap_density, pbrt-v4's remap0), its strategies
// already excluded by letter. Hence `weight = value · |cos| / (the finite parts' densities)` for
// every kind, where cos is taken between the ray and `normal` (1 when the endpoint has no surface:
// point, spot, laser, spot meter; a pinhole uses its viewing axis, as pbrt does): a Dirac part is
// chosen with probability 1. Code must test the flags, never a density, to tell a Dirac part.
//
// Sensors measure the mean over the image: W_e is normalised so that ∫ W_e cos dσ dA = 1 over the
// whole film (pbrt's convention, W_e = 1 / (A_img cos⁴θ) for a pinhole with A_img the image area
// at unit distance), and the film position `raster` ∈ [0,1)² (x right, y down) is chosen by the
// integrator, uniformly over the image; densities are for that choice. A pixel's measurement is
// the image's times the number of pixels, restricted to the pixel; that factor cancels in every
// weight and every MIS ratio.
//
// Units: radiance Le, intensity I, irradiance E and power Φ as RGB; lengths in scene units.
// Directions are unit vectors and frames orthonormal (preconditions, not checked here: the scene
// loader validates them).
#pragma once

#include <cstdint>
#include <memory>
#include <numbers>
#include <optional>
#include <variant>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "alphabet/alphabet.h"
#include "trace/environment.h"

namespace pathex {

// Densities of an emission or importance ray, with the Dirac parts flagged.
struct RayPdf {
  float pos = 0.0f;        // area density of the origin [1/area]; 0 if delta_pos
  float dir = 0.0f;        // solid-angle density of the direction [1/sr]; 0 if delta_dir
  bool delta_pos = false;
  bool delta_dir = false;
};

// The first ray of a light subpath (from a light) or an eye subpath (from a sensor).
struct EndpointRay {
  glm::vec3 origin{0.0f};
  glm::vec3 direction{0.0f};  // unit
  glm::vec3 normal{0.0f};     // surface normal at the origin; zero when there is no surface
  glm::vec3 value{0.0f};      // Le or We along the ray (for Dirac parts: their weight)
  RayPdf pdf;
  glm::vec3 weight{0.0f};     // value · |cos| / (pdf.pos · pdf.dir, a Dirac's factor 1): the starting throughput
  Letter pos_letter = kD;     // c0 for a light, c(k+2) for a sensor
  Letter dir_letter = kD;     // c1 for a light, c(k+1) for a sensor
  glm::vec2 raster{0.0f};     // sensors: the film position of the ray, [0,1)^2
};

// A point on a light or sensor joined to a reference point `ref` in the scene.
struct EndpointConnection {
  glm::vec3 position{0.0f};   // on the light / sensor
  glm::vec3 normal{0.0f};     // its surface normal, zero when there is none
  glm::vec3 wi{0.0f};         // unit, from ref towards position
  float distance = 0.0f;      // |position − ref|: the shadow ray's length
  glm::vec3 value{0.0f};      // Le(position → ref) or We(position → ref)
  // The contribution is f(ref) · |cos θ_ref| · weight (times visibility): value · G / p with the
  // geometry term G lacking ref's cosine, or for a Dirac join value times the delta's Jacobian.
  glm::vec3 weight{0.0f};
  float pdf_dir = 0.0f;       // solid-angle density of wi at ref for this join; 0 when `delta`
  bool delta = false;         // wi was fixed (point-like position or single direction), not sampled
  glm::vec2 raster{0.0f};     // sensors: where the join lands on the film
};

// A point on an emitting surface chosen by the integrator (e.g. uniformly by area over the
// emissive triangles), with the area density of that choice.
struct SurfacePoint {
  glm::vec3 position{0.0f};
  glm::vec3 normal{0.0f, 0.0f, 1.0f};  // unit; the emitting side of a one-sided light
  float pdf_area = 0.0f;
};

// Solid-angle density at a point `distance` away, seen at `abs_cos` on the far side, of a point
// chosen with area density `pdf_area`: pdf_area · d² / |cos|. 0 when abs_cos is 0.
float area_to_solid_angle(float pdf_area, float distance, float abs_cos);

// ---------------------------------------------------------------------------------------------
// Lights
// ---------------------------------------------------------------------------------------------

// Diffuse (Lambertian) emitter, LDD. Shapes are the integrator's: it picks the SurfacePoint.
struct AreaLightParams {
  glm::vec3 radiance{1.0f};  // Le, constant over the surface and the emitting hemisphere
  bool two_sided = false;    // emit on both sides of the normal
  // Next-event points drawn by the solid angle the light subtends at the point they join, not by
  // area (`pathex trace --light-sampling solid-angle`): a rectangle corner + a·edge1 + b·edge2,
  // a, b ∈ [0, 1], edges perpendicular, unit normal edge1 × edge2 normalised, uniformly in its
  // solid angle (trace/spherical_rect.h), where that is neither tiny nor nearly a hemisphere; a
  // sphere (center, radius) uniformly in the cone it subtends (pbrt-v4's Sphere::Sample), from
  // outside it. Elsewhere by area after all, pdf_area = 1 / the light's area. kNone (the
  // default): the integrator's points, by area.
  enum class Towards : std::uint8_t { kNone, kRectangle, kSphere };
  Towards towards = Towards::kNone;
  glm::vec3 corner{0.0f}, edge1{0.0f}, edge2{0.0f}, normal{0.0f};
  glm::vec3 center{0.0f};
  float radius = 0.0f;
  float pdf_area = 0.0f;
  static constexpr Letter kPosLetter = kD;
  static constexpr Letter kDirLetter = kD;
};
// Le(x, w) for a direction w leaving the surface with normal n.
glm::vec3 emitted_radiance(const AreaLightParams& p, const glm::vec3& n, const glm::vec3& w);
// Cosine-weighted direction (two-sided: a side with probability 1/2, chosen by u.x).
std::optional<EndpointRay> sample_ray(const AreaLightParams& p, const SurfacePoint& x, glm::vec2 u);
RayPdf pdf_ray(const AreaLightParams& p, const SurfacePoint& x, const glm::vec3& direction);
// Next-event estimation towards x (also the MIS density of a BSDF-sampled ray that hits x).
std::optional<EndpointConnection> connect(const AreaLightParams& p, const SurfacePoint& x,
                                          const glm::vec3& ref);
// Power of a light of total surface area `area`: π Le area, doubled when two-sided.
glm::vec3 power(const AreaLightParams& p, float area);
// A light sampled by solid angle (p.towards set): next-event estimation from ref, its point drawn
// by u uniformly in the solid angle Ω the light subtends at ref (pdf_dir 1 / Ω, weight Le Ω), or
// by area where Ω is not usable.
std::optional<EndpointConnection> connect(const AreaLightParams& p, glm::vec2 u, const glm::vec3& ref);
// The area density with which that connect() from ref draws the point x (normal n):
// |n · w| / (Ω d²), or pdf_area where it samples by area.
float towards_area_density(const AreaLightParams& p, const glm::vec3& x, const glm::vec3& n, const glm::vec3& ref);
// The density of x1 that completes the emission's joint density (pdf_area times the cosine
// emission's) after towards_area_density(x0 from x1): pdf_area |cos θ_1| Ω / (π · sides), or the
// emission's own pdf_dir |cos θ_1| / d² where Ω is not usable; 0 where x0 does not emit towards x1.
float towards_step_density(const AreaLightParams& p, const glm::vec3& x0, const glm::vec3& n0, const glm::vec3& x1,
                           float abs_cos1);

// Isotropic point light, LSD.
struct PointLightParams {
  glm::vec3 position{0.0f};
  glm::vec3 intensity{1.0f};  // I [W/sr]
  static constexpr Letter kPosLetter = kS;
  static constexpr Letter kDirLetter = kD;
};
std::optional<EndpointRay> sample_ray(const PointLightParams& p, glm::vec2 u);
RayPdf pdf_ray(const PointLightParams& p, const glm::vec3& direction);
std::optional<EndpointConnection> connect(const PointLightParams& p, const glm::vec3& ref);
glm::vec3 power(const PointLightParams& p);  // 4π I

// Spot light, LSD: I(w) = intensity · falloff(θ), θ from the axis. falloff is 1 inside the
// falloff's start, 0 outside the cone, and in between either smoothstep in cos θ (pbrt-v4's
// SpotLight) or linear in θ (`linear_in_angle`, Mitsuba 3's spot); with cos_falloff_start ==
// cos_total the edge is hard. The edge itself (cos θ == cos_total) emits nothing. Directions are
// sampled uniformly in the cone.
struct SpotLightParams {
  glm::vec3 position{0.0f};
  glm::vec3 axis{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 intensity{1.0f};          // on the axis [W/sr]
  float cos_total = 0.5f;             // cosine of the cone's half-angle, in (−1, 1)
  float cos_falloff_start = 0.5f;     // in [cos_total, 1]
  bool linear_in_angle = false;       // Mitsuba 3's ramp; false: pbrt-v4's smoothstep in cos θ
  static constexpr Letter kPosLetter = kS;
  static constexpr Letter kDirLetter = kD;
};
float spot_falloff(const SpotLightParams& p, float cos_theta);
glm::vec3 intensity(const SpotLightParams& p, const glm::vec3& direction);
std::optional<EndpointRay> sample_ray(const SpotLightParams& p, glm::vec2 u);
RayPdf pdf_ray(const SpotLightParams& p, const glm::vec3& direction);
std::optional<EndpointConnection> connect(const SpotLightParams& p, const glm::vec3& ref);
// 2π I (1 − (cs + ct) / 2) for the smoothstep (cs, ct: the cosines of the falloff's start and the
// cone), 2π I ((1 − cs) + ((θt − θs) cs − sin θt + sin θs) / (θt − θs)) for the linear ramp.
glm::vec3 power(const SpotLightParams& p);

// Distant light through an aperture, LDS: parallel light of irradiance E (measured perpendicular
// to `direction`) entering the scene through the parallelogram corner + a·edge1 + b·edge2,
// a, b ∈ [0, 1) (the sun through a window). The origin is uniform over the aperture.
struct DistantLightParams {
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit, the way the light travels
  glm::vec3 irradiance{1.0f};              // E [W/m²]
  glm::vec3 corner{0.0f};
  glm::vec3 edge1{1.0f, 0.0f, 0.0f};
  glm::vec3 edge2{0.0f, 1.0f, 0.0f};
  static constexpr Letter kPosLetter = kD;
  static constexpr Letter kDirLetter = kS;
};
std::optional<EndpointRay> sample_ray(const DistantLightParams& p, glm::vec2 u);
RayPdf pdf_ray(const DistantLightParams& p, const glm::vec3& origin);  // 0 outside the aperture
// The projection join (the `distant-projection` connector, DESIGN §4): wi = −direction and the
// aperture point on the line through ref; nullopt when that line misses the aperture or the
// aperture is behind ref.
std::optional<EndpointConnection> connect(const DistantLightParams& p, const glm::vec3& ref);
glm::vec3 power(const DistantLightParams& p);
float aperture_area(const DistantLightParams& p);  // |edge1 × edge2|  // E · A · |cos(direction, aperture normal)|

// Laser, LSS: power Φ along one ray. Nothing can be joined to it (connect() is always nullopt).
struct LaserParams {
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};  // unit
  glm::vec3 power{1.0f};                   // Φ [W]
  static constexpr Letter kPosLetter = kS;
  static constexpr Letter kDirLetter = kS;
};
std::optional<EndpointRay> sample_ray(const LaserParams& p);
RayPdf pdf_ray(const LaserParams& p);
std::optional<EndpointConnection> connect(const LaserParams& p, const glm::vec3& ref);
glm::vec3 power(const LaserParams& p);

// Image infinite light, LDD (trace/environment.h): the box around the scene, each point emitting
// the image's radiance L(−ω) towards every direction ω into the box. Its points are not chosen by
// area: next-event estimation draws a direction from the image (connect), emission a direction
// and a point of the disk covering the box (sample_ray); the handles below do not serve it (the
// integrator calls these, with its own random numbers).
struct EnvironmentLightParams {
  std::shared_ptr<const EnvironmentMap> map;
  static constexpr Letter kPosLetter = kD;
  static constexpr Letter kDirLetter = kD;
};
// A direction ω drawn from the image by u_dir (travelling into the scene: the image's −ω), a point
// of the disk by u_disk, and the box point where that line enters: pdf.pos = |cos θ_x| / (π R²),
// pdf.dir = p(−ω), weight = L π R² / p(−ω). nullopt when the line misses the box.
std::optional<EndpointRay> sample_ray(const EnvironmentLightParams& p, glm::vec2 u_dir, glm::vec2 u_disk);
// Next-event estimation from ref: a direction drawn from the image by u, the box point where it
// leaves; value L, pdf_dir its solid-angle density, weight L / pdf_dir.
std::optional<EndpointConnection> connect(const EnvironmentLightParams& p, glm::vec2 u, const glm::vec3& ref);
// The area density of the box point x (inward normal n) as connect() from `ref` draws it:
// p(x − ref) |n · w| / d². It is the light density the integrator keeps for x0.
float connect_area_density(const EnvironmentLightParams& p, const glm::vec3& x, const glm::vec3& n, const glm::vec3& ref);
// The density of x1 that completes the emission's joint density: |cos θ_1| / (π R²).
inline float emission_step_density(const EnvironmentLightParams& p, float abs_cos_next) {
  return abs_cos_next / (std::numbers::pi_v<float> * p.map->radius * p.map->radius);
}

// ---------------------------------------------------------------------------------------------
// Sensors. raster (x, y) ∈ [0,1)^2 maps to the film point (2x − 1, 1 − 2y) in units of the half
// extents along (right, up): x grows to the right, y grows downwards.
// ---------------------------------------------------------------------------------------------

// Pinhole, DSE: all rays leave `position`; the image spans ±tan_half_x, ±tan_half_y at unit
// distance along forward. We = 1 / (A cos⁴θ), A = 4 tan_half_x tan_half_y.
struct PinholeParams {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};  // orthonormal frame: forward, right, up
  glm::vec3 right{1.0f, 0.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float tan_half_x = 1.0f;
  float tan_half_y = 1.0f;
  static constexpr Letter kPosLetter = kS;
  static constexpr Letter kDirLetter = kD;
};
std::optional<EndpointRay> sample_ray(const PinholeParams& p, glm::vec2 raster);
// We for a ray leaving the pinhole in `direction`, and its raster position; 0 outside the image.
glm::vec3 importance(const PinholeParams& p, const glm::vec3& direction, glm::vec2* raster);
RayPdf pdf_ray(const PinholeParams& p, const glm::vec3& direction);
std::optional<EndpointConnection> connect(const PinholeParams& p, const glm::vec3& ref);

// Thin lens, DDE: a lens disk of radius lens_radius > 0 centred on `position`, perpendicular to
// forward, focused at focus_distance; the image (same extents as a pinhole's) is mapped onto the
// plane of focus. We = 1 / (A A_lens cos⁴θ); the origin is uniform on the lens.
struct ThinLensParams {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  glm::vec3 right{1.0f, 0.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float tan_half_x = 1.0f;
  float tan_half_y = 1.0f;
  float lens_radius = 0.01f;
  float focus_distance = 1.0f;
  static constexpr Letter kPosLetter = kD;
  static constexpr Letter kDirLetter = kD;
};
glm::vec3 lens_point(const ThinLensParams& p, glm::vec2 u_lens);  // uniform on the lens disk
std::optional<EndpointRay> sample_ray(const ThinLensParams& p, glm::vec2 raster, glm::vec2 u_lens);
// We for a ray leaving the lens at `origin` in `direction`, and its raster position.
glm::vec3 importance(const ThinLensParams& p, const glm::vec3& origin, const glm::vec3& direction,
                     glm::vec2* raster);
RayPdf pdf_ray(const ThinLensParams& p, const glm::vec3& origin, const glm::vec3& direction);
// Splat join through a lens point drawn from u_lens.
std::optional<EndpointConnection> connect(const ThinLensParams& p, glm::vec2 u_lens,
                                          const glm::vec3& ref);
// A light subpath ray from `origin` along `direction` that crosses the lens disk (strategy t = 0):
// the crossing as a join from origin (its pdf_dir is what connect() would have had).
std::optional<EndpointConnection> hit_lens(const ThinLensParams& p, const glm::vec3& origin,
                                           const glm::vec3& direction);

// Orthographic, SDE: rays along forward from a film of half extents (half_width, half_height)
// centred on `position`; origin uniform on the film, We = 1 / A_film.
struct OrthographicParams {
  glm::vec3 position{0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  glm::vec3 right{1.0f, 0.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float half_width = 1.0f;
  float half_height = 1.0f;
  static constexpr Letter kPosLetter = kD;
  static constexpr Letter kDirLetter = kS;
};
std::optional<EndpointRay> sample_ray(const OrthographicParams& p, glm::vec2 raster);
RayPdf pdf_ray(const OrthographicParams& p, const glm::vec3& origin);  // 0 off the film
// The projection join (the `ortho-projection` connector): the film point whose ray passes through
// ref, wi = −forward; nullopt when ref is behind the film or projects outside it.
std::optional<EndpointConnection> connect(const OrthographicParams& p, const glm::vec3& ref);

// Spot meter, SSE: measures the radiance along one ray (We = 1 for that ray). Nothing can be
// joined to it (connect() is always nullopt).
struct SpotMeterParams {
  glm::vec3 position{0.0f};
  glm::vec3 direction{0.0f, 0.0f, -1.0f};
  static constexpr Letter kPosLetter = kS;
  static constexpr Letter kDirLetter = kS;
};
std::optional<EndpointRay> sample_ray(const SpotMeterParams& p);
RayPdf pdf_ray(const SpotMeterParams& p);
std::optional<EndpointConnection> connect(const SpotMeterParams& p, const glm::vec3& ref);

// ---------------------------------------------------------------------------------------------
// The handles: a light or a sensor of a render as one value over the closed set of kinds above.
// Each operation dispatches to the kind's function; kinds without the operation (a join to a
// laser, the importance of a Dirac direction) answer nullopt or zero.
// ---------------------------------------------------------------------------------------------

using LightParams = std::variant<AreaLightParams, PointLightParams, SpotLightParams, DistantLightParams, LaserParams,
                                 EnvironmentLightParams>;
using SensorParams = std::variant<PinholeParams, ThinLensParams, OrthographicParams, SpotMeterParams>;

Letter pos_letter(const LightParams& l);   // c0
Letter dir_letter(const LightParams& l);   // c1
Letter pos_letter(const SensorParams& s);  // c(k+2)
Letter dir_letter(const SensorParams& s);  // c(k+1)

// Lights. `x` is the point the integrator chose on an area light's surface (with its density);
// the other kinds ignore it, except pdf_ray of a distant light, which reads x.position as the
// ray's origin.
std::optional<EndpointRay> sample_ray(const LightParams& l, const SurfacePoint& x, glm::vec2 u);
RayPdf pdf_ray(const LightParams& l, const SurfacePoint& x, const glm::vec3& direction);
std::optional<EndpointConnection> connect(const LightParams& l, const SurfacePoint& x,
                                          const glm::vec3& ref);
// Veach's split L_e = L_e⁽⁰⁾ L_e⁽¹⁾ for the finite directional part: the spatial factor (Le for an
// area light, I for point and spot lights, E, Φ) and the directional factor towards w from a
// point with normal n (area: 1 on an emitting side, else 0; point: 1; spot: the falloff). A Dirac
// direction (distant, laser) has no finite directional part: 0. An image infinite light's
// radiance is all directional: spatial 1, directional 1 into the box (its value is looked up by
// environment_radiance() where a path meets it, or carried by the vertex's throughput).
// emitted(): the product, with an image light's radiance looked up (towards −w).
glm::vec3 spatial_emission(const LightParams& l);
float directional_emission(const LightParams& l, const glm::vec3& n, const glm::vec3& w);
glm::vec3 emitted(const LightParams& l, const glm::vec3& n, const glm::vec3& w);
// Where a light with a Dirac position (point, spot, laser) is; zero for the others, whose points
// are drawn (SurfacePoint).
glm::vec3 fixed_origin(const LightParams& l);
// The projection join of a Dirac direction from a finite-area origin, letters D S (the
// `distant-projection` connector): the aperture point on the line through ref against the light's
// direction. Nullopt for every other kind.
std::optional<EndpointConnection> connect_projection(const LightParams& l, const glm::vec3& ref);

// Lights whose next-event points are drawn towards the point x1 they join, not by area: an image
// infinite light, a rectangle sampled by solid angle. For them x0's light density in every
// strategy is next-event estimation's from x1 (towards_area_density()), and x1's the rest of the
// emission's joint density (towards_step_density(), |cos θ_1| the cosine at x1): their product is
// the emission's, so every strategy keeps its own density (Integrator::drawn_towards says where).
bool draws_towards(const LightParams& l);
// Next-event estimation from ref, the point drawn by u (a light that draws_towards()).
std::optional<EndpointConnection> connect_towards(const LightParams& l, glm::vec2 u, const glm::vec3& ref);
float towards_area_density(const LightParams& l, const glm::vec3& x, const glm::vec3& n, const glm::vec3& ref);
float towards_step_density(const LightParams& l, const glm::vec3& x0, const glm::vec3& n0, const glm::vec3& x1, float abs_cos1);
// The area density of a connect_towards() point: its solid-angle density to area,
// towards_area_density() without computing the solid angle again.
inline float towards_area_density(const EndpointConnection& c) {
  return c.distance > 0.0f ? c.pdf_dir * std::fabs(glm::dot(c.normal, c.wi)) / (c.distance * c.distance) : 0.0f;
}

// Sensors. `raster` ∈ [0,1)² as above; u_lens is read by the thin lens only.
inline bool reads_lens_numbers(const SensorParams& s) { return std::holds_alternative<ThinLensParams>(s); }
std::optional<EndpointRay> sample_ray(const SensorParams& s, glm::vec2 raster, glm::vec2 u_lens);
// Densities of the ray leaving `origin` (a point of the sensor) in `direction`.
RayPdf pdf_ray(const SensorParams& s, const glm::vec3& origin, const glm::vec3& direction);
// The t = 1 join of a finite direction (pinhole, thin lens); nullopt for the others.
std::optional<EndpointConnection> connect_finite(const SensorParams& s, glm::vec2 u_lens,
                                                 const glm::vec3& ref);
// We of the ray leaving `origin` in `direction` with its raster position (pinhole, thin lens);
// 0 for Dirac directions and outside the image.
glm::vec3 importance(const SensorParams& s, const glm::vec3& origin, const glm::vec3& direction,
                     glm::vec2* raster);
// The projection join of a sensor with a Dirac direction from a finite film, letters S D (the
// `ortho-projection` connector): the film point whose ray passes through ref. Nullopt for every
// other kind.
std::optional<EndpointConnection> connect_projection(const SensorParams& s, const glm::vec3& ref);
// The point a sensor's ray leaves from: a thin lens's point drawn from u_lens, else its position.
glm::vec3 sensor_point(const SensorParams& s, glm::vec2 u_lens);
// A ray crossing a thin lens (strategy t = 0); nullopt for every other sensor.
std::optional<EndpointConnection> hit_lens(const SensorParams& s, const glm::vec3& origin,
                                           const glm::vec3& direction);

}  // namespace pathex

// The definitions, inline: the integrator calls them on every vertex (see emitters_impl.h).
#include "trace/emitters_impl.h"  // IWYU pragma: export
