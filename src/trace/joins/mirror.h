// The `mirror` connector's geometry (DESIGN §4): a chain D S D across one planar mirror, joined by
// the image method. The two ends a (the light side's vertex) and b (the eye side's) are given;
// reflecting b through the mirror's plane gives its image b', and the mirror vertex is where the
// segment from a to b' crosses the plane. The join exists when a and b lie strictly on the same
// side of the plane and that crossing lies on the mirror. The path a → m → b then has the length
// |a − b'| of the straight segment to the image (the "unfolded" distance), which is why the
// caustic of a planar mirror is the floor lit by the light's image (DESIGN §9).
//
// Planar mirrors are quad shapes whose material is a pure `mirror`: one parallelogram each.
#pragma once

#include <cmath>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace pathex {

struct PlanarMirror {
  int shape = -1;                 // the quad's index in the scene
  glm::vec3 corner{0.0f}, edge1{0.0f}, edge2{0.0f};
  glm::vec3 normal{0.0f};         // unit, normalize(edge1 × edge2)
  glm::vec3 reflectance{1.0f};    // R of the mirror material: f = R δ / |cos|
  glm::vec3 error{0.0f};          // rounding-error bound of points on it (as a quad hit's)
};

struct MirrorJoin {
  glm::vec3 point{0.0f};  // m, on the mirror
  glm::vec3 w_a{0.0f};    // unit, from a towards m
  glm::vec3 w_b{0.0f};    // unit, from b towards m
  float unfolded = 0.0f;  // |a − m| + |m − b| = |a − b'|
};

// The reflection of p through the mirror's plane.
inline glm::vec3 mirror_image(const PlanarMirror& m, const glm::vec3& p) {
  return p - 2.0f * glm::dot(p - m.corner, m.normal) * m.normal;
}

// The join of a and b across mirror `m`, or none: a and b are not strictly on one side of the
// plane, or the crossing misses the parallelogram.
inline std::optional<MirrorJoin> mirror_join(const PlanarMirror& m, const glm::vec3& a, const glm::vec3& b) {
  const float da = glm::dot(a - m.corner, m.normal), db = glm::dot(b - m.corner, m.normal);
  if (!(da * db > 0.0f)) return std::nullopt;
  // Along a → b' the signed distance to the plane falls linearly from da to −db.
  const float frac = da / (da + db);
  const glm::vec3 b_image = b - 2.0f * db * m.normal;
  glm::vec3 p = a + frac * (b_image - a);
  p -= glm::dot(p - m.corner, m.normal) * m.normal;  // onto the plane exactly (up to rounding)
  // Parallelogram coordinates of p.
  const glm::vec3 d = p - m.corner;
  const float e11 = glm::dot(m.edge1, m.edge1), e12 = glm::dot(m.edge1, m.edge2), e22 = glm::dot(m.edge2, m.edge2);
  const float d1 = glm::dot(d, m.edge1), d2 = glm::dot(d, m.edge2);
  const float det = e11 * e22 - e12 * e12;
  const float u = (d1 * e22 - d2 * e12) / det, v = (d2 * e11 - d1 * e12) / det;
  if (!(u >= 0.0f && u < 1.0f && v >= 0.0f && v < 1.0f)) return std::nullopt;
  MirrorJoin j;
  j.point = p;
  const glm::vec3 ea = p - a, eb = p - b;
  const float la = glm::length(ea), lb = glm::length(eb);
  if (!(la > 0.0f) || !(lb > 0.0f) || !std::isfinite(la + lb)) return std::nullopt;
  j.w_a = ea / la;
  j.w_b = eb / lb;
  j.unfolded = la + lb;
  return j;
}

}  // namespace pathex
