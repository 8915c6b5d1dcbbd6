// An orthonormal frame around a unit normal, for moving directions between world space and the
// local space in which BSDFs and emission lobes are written (normal = +z).
//
// The tangents come from Duff et al., "Building an Orthonormal Basis, Revisited" (JCGT 2017): no
// branch on the normal's direction except the sign, no normalisation, continuous everywhere but
// across z = 0 where the sign flips, and orthonormal to float precision even for n = (0, 0, −1),
// where Frisvad's original construction breaks down.
#pragma once

#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace pathex {

struct Frame {
  glm::vec3 s{1.0f, 0.0f, 0.0f};  // first tangent  (local +x)
  glm::vec3 t{0.0f, 1.0f, 0.0f};  // second tangent (local +y)
  glm::vec3 n{0.0f, 0.0f, 1.0f};  // normal         (local +z); s × t = n

  // The frame of a unit normal `n` (Duff et al. 2017, Listing 3).
  static Frame from_normal(const glm::vec3& n) {
    const float sign = std::copysign(1.0f, n.z);
    const float a = -1.0f / (sign + n.z);
    const float b = n.x * n.y * a;
    Frame f;
    f.s = {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    f.t = {b, sign + n.y * n.y * a, -n.y};
    f.n = n;
    return f;
  }

  // A frame from a unit normal and a preferred first tangent (Gram–Schmidt); falls back to
  // from_normal() when the tangent is (nearly) parallel to the normal.
  static Frame from_normal_tangent(const glm::vec3& n, const glm::vec3& tangent) {
    const glm::vec3 s = tangent - n * glm::dot(n, tangent);
    const float len2 = glm::dot(s, s);
    if (!(len2 > 1e-12f)) return from_normal(n);
    Frame f;
    f.s = s / std::sqrt(len2);
    f.t = glm::cross(n, f.s);
    f.n = n;
    return f;
  }

  glm::vec3 to_local(const glm::vec3& v) const {
    return {glm::dot(v, s), glm::dot(v, t), glm::dot(v, n)};
  }
  glm::vec3 to_world(const glm::vec3& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace pathex
