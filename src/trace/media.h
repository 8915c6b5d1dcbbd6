// Absorbing media (issue 34): the interior of a shape may absorb light, as coloured glass, tea or
// wine do (pbrt-v4's homogeneous medium with sigma_s = 0 behind a MediumInterface, Mitsuba 3's
// homogeneous medium of albedo 0 as a shape's interior). Light that travels a distance d through
// it keeps exp(-σa d) of itself per channel (Beer–Lambert). Nothing scatters in it, so no vertex
// is created and no letter changes (DESIGN §1): the attenuation is a factor of the throughput of
// the segment, in every strategy, and no density changes (every strategy that samples a path
// carries the same factor, so the MIS weights stay as they are).
//
// Which medium a segment crosses is decided at its start vertex v, leaving along d:
// - v on a shape with an absorbing interior: the interior when d points into the shape (against
//   its geometric normal), else the outside, which is vacuum (media do not nest: an absorbing
//   shape inside another absorbing shape is not supported, and the importers refuse an exterior
//   medium);
// - any other vertex (a surface without an interior, a light, the sensor): the medium of the
//   segment that reached v (Vertex::sigma), so a diffuse object in a tank of tea is in the tea.
// Emitters and sensors start in vacuum.
#pragma once

#include <cmath>
#include <vector>

#include <glm/vec3.hpp>

#include "trace/vertex.h"

namespace pathex::tracer {

// σa of the medium the segment leaving v along d crosses (zero: vacuum). `absorption_of_shape`:
// RenderScene's, σa of each shape's interior.
inline vec3 segment_absorption(const Vertex& v, const vec3& d, const std::vector<vec3>& absorption_of_shape) {
  if (v.kind == Kind::kSurface) {
    const vec3& inside = absorption_of_shape[static_cast<std::size_t>(v.shape)];
    if (inside.x != 0.0f || inside.y != 0.0f || inside.z != 0.0f) return glm::dot(d, v.n) < 0.0f ? inside : vec3(0.0f);
  }
  return v.sigma;
}

// exp(-σa d) per channel.
inline vec3 beer_lambert(const vec3& sigma, float distance) {
  return {std::exp(-sigma.x * distance), std::exp(-sigma.y * distance), std::exp(-sigma.z * distance)};
}

// The share of light that the straight segment from v to the point p keeps: exp(-σa d) of the
// medium it crosses (1 for a segment of no length).
inline vec3 segment_transmittance(const Vertex& v, const vec3& p, const std::vector<vec3>& absorption_of_shape) {
  const vec3 e = p - v.p;
  const float length = std::sqrt(glm::dot(e, e));
  return length > 0.0f ? beer_lambert(segment_absorption(v, e / length, absorption_of_shape), length) : vec3(1.0f);
}

}  // namespace pathex::tracer
