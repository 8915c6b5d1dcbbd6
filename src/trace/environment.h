// The image infinite light (docs/lights.md): radiance arriving from every direction, read from an
// image, as pbrt-v4's ImageInfiniteLight (an equal-area octahedral square) or Mitsuba 3's envmap
// (a latitude-longitude image with +Y up). DESIGN §1: letters LDD, like an area light.
//
// Like the uniform infinite light (scene.h, add_uniform_environment) it is rendered as the closed
// box around the scene whose faces absorb and emit inwards; here a face point x emits, towards a
// direction ω into the box, the image's radiance L(−ω): the radiance depends on the direction only,
// which is what an infinite light is, and every ray leaving the scene meets the box. What differs is
// how its points are sampled:
//   - next-event estimation from a point r draws a direction ω from the image's distribution
//     (trace/piecewise2d.h, converted to solid angle) and takes the box point where the ray from r
//     along ω leaves the box: area density p(ω) |cos θ_x| / d²;
//   - emission (lt, bdpt) draws ω likewise, then a point on a disk of radius R perpendicular to ω
//     covering the box, and follows the line back to where it enters the box (pbrt's way): joint
//     density p(ω) |cos θ_x| / (π R²) of the box point and the direction.
// The integrator keeps, as the light density of x0, the first one (given the vertex x1 it joins),
// and as that of x1 the ratio |cos θ_1| / (π R²): their product is the emission's joint density, so
// the one MIS routine (trace/mis.h) weighs every strategy with the densities it sampled with.
#pragma once

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "alphabet/alphabet.h"
#include "optics/sphere_map.h"
#include "trace/piecewise2d.h"

namespace pathex {


// Everything the light needs, shared (immutable) by the render's handles.
struct EnvironmentMap {
  bool equal_area = false;  // pbrt-v4's square; else latitude-longitude
  int width = 1, height = 1;
  std::vector<glm::vec3> texels;  // linear radiance, row-major from the top row, scale applied
  glm::mat3 to_world{1.0f};       // light space → world: a rotation
  Piecewise2D distribution;       // over the image's (u, v)
  glm::vec3 box_lo{0.0f}, box_hi{0.0f};  // the emitting box (scene.h)
  glm::vec3 center{0.0f};                // the emission disk: centred on the box, covering it
  float radius = 1.0f;

  // The image's distribution: each texel's mean of R, G and B, times sin θ at its centre for a
  // latitude-longitude image. `uniform`: every texel alike (the tests compare the two).
  void build_distribution(bool uniform = false);
};

// Radiance arriving from world direction `w` (unit, pointing away from the scene): the texel w
// falls in (nearest, as pbrt-v4's lookup).
glm::vec3 environment_radiance(const EnvironmentMap& m, const glm::vec3& w);
// Solid-angle density of drawing the world direction `w`, and a direction drawn from u.
float environment_pdf(const EnvironmentMap& m, const glm::vec3& w);
glm::vec3 sample_environment(const EnvironmentMap& m, glm::vec2 u, float* pdf);
// Where the ray from `o` (inside the box) along unit `d` leaves the box: the point, the face's
// inward normal and the distance. False when o is not inside.
bool box_exit(const EnvironmentMap& m, const glm::vec3& o, const glm::vec3& d, glm::vec3* x, glm::vec3* n, float* t);
// Rounding-error bound of a box point (the ray offset of a vertex there).
glm::vec3 box_point_error(const glm::vec3& x);

}  // namespace pathex
