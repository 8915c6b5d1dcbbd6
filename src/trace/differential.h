// Local differential geometry of a shape at a point, in double precision: what a walk that moves
// points along surfaces needs (the manifold connector, trace/joins/manifold.h). Computed only when
// asked (EmbreeScene::derivatives()), never for the hot loop's hits.
//
// u and v run along an orthonormal tangent frame (s, t) at the point, chosen from the normal
// alone (Duff et al. 2017), so that the parametrisation has no pole: p(u, v) moves along s and t,
// and n(u, v) turns with the surface's curvature. Spheres: dn/du = s / r (outward normal).
// Quads, disks and the triangles of meshes without vertex normals: dn = 0. A mesh with vertex
// normals is smooth-shaded: its shading normal ns is their interpolation (mesh_shading_normal(),
// the tracer's too), and dn/du, dn/dv are ns's derivatives along the triangle's plane, so that a
// specular constraint (the manifold walk) sees the surface the tracer shades.
#pragma once

#include <cmath>
#include <optional>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "scene/scene.h"

namespace pathex {

struct SurfaceDerivatives {
  glm::dvec3 n{0.0};                  // the unit outward (geometric) normal
  glm::dvec3 ns{0.0};                 // the unit shading normal (n but on smooth-shaded meshes)
  glm::dvec3 dpdu{0.0}, dpdv{0.0};    // unit, orthogonal, tangent (to n)
  glm::dvec3 dndu{0.0}, dndv{0.0};    // of ns
};

// The shading normal of triangle `t` of `m` (which has vertex normals) at Embree's barycentrics
// (u, v) (the weights of its second and third vertex): the vertex normals interpolated and
// normalised; `fallback` (the geometric normal) where they cancel.
inline glm::vec3 mesh_shading_normal(const MeshShape& m, const glm::uvec3& t, float u, float v, const glm::vec3& fallback) {
  const glm::vec3 n = (1.0f - u - v) * m.normals[t.x] + u * m.normals[t.y] + v * m.normals[t.z];
  const float len = glm::length(n);
  return len > 0.0f ? n / len : fallback;
}

// An orthonormal tangent pair for unit n (Duff et al., "Building an Orthonormal Basis, Revisited").
inline void tangent_frame(const glm::dvec3& n, glm::dvec3* s, glm::dvec3* t) {
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double b = n.x * n.y * a;
  *s = {1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x};
  *t = {b, sign + n.y * n.y * a, -n.y};
}

namespace differential_detail {
inline glm::dvec3 d(const glm::vec3& v) { return glm::dvec3(v); }
inline glm::dvec3 mesh_normal(const MeshShape& m, int primitive) {
  const glm::uvec3 t = m.triangles[static_cast<std::size_t>(primitive)];
  const glm::dvec3 n = glm::cross(d(m.positions[t.y]) - d(m.positions[t.x]), d(m.positions[t.z]) - d(m.positions[t.x]));
  const double len = glm::length(n);
  return len > 0.0 ? n / len : glm::dvec3(0.0, 0.0, 1.0);
}
// A smooth-shaded triangle at p: r.n set. With the raw normal N = w0 n0 + w1 n1 + w2 n2 (the
// barycentrics w linear in p) and ns = N / |N|, a tangent step a changes N by
// dw1(a) (n1 - n0) + dw2(a) (n2 - n0), and ns by that change's part perpendicular to ns, / |N|.
inline SurfaceDerivatives smooth_triangle(const MeshShape& m, int primitive, const glm::dvec3& p, SurfaceDerivatives r) {
  const glm::uvec3 t = m.triangles[static_cast<std::size_t>(primitive)];
  const glm::dvec3 o = d(m.positions[t.x]), e1 = d(m.positions[t.y]) - o, e2 = d(m.positions[t.z]) - o;
  const glm::dvec3 n0 = d(m.normals[t.x]), n1 = d(m.normals[t.y]), n2 = d(m.normals[t.z]);
  const glm::dvec3 c = glm::cross(e1, e2);
  const double c2 = glm::dot(c, c);
  tangent_frame(r.n, &r.dpdu, &r.dpdv);
  if (!(c2 > 0.0)) {  // degenerate: flat
    r.ns = r.n;
    return r;
  }
  // Barycentric weights of the second and third vertex for a point (or, without o, a step) in the plane.
  const auto w12 = [&](const glm::dvec3& a) { return glm::dvec2(glm::dot(glm::cross(a, e2), c) / c2, glm::dot(glm::cross(e1, a), c) / c2); };
  const glm::dvec2 w = w12(p - o);
  const glm::dvec3 raw = (1.0 - w.x - w.y) * n0 + w.x * n1 + w.y * n2;
  const double len = glm::length(raw);
  if (!(len > 0.0)) {
    r.ns = r.n;
    return r;
  }
  r.ns = raw / len;
  const auto turn = [&](const glm::dvec3& a) {
    const glm::dvec2 dw = w12(a);
    const glm::dvec3 dn = dw.x * (n1 - n0) + dw.y * (n2 - n0);
    return (dn - glm::dot(dn, r.ns) * r.ns) / len;
  };
  r.dndu = turn(r.dpdu);
  r.dndv = turn(r.dpdv);
  return r;
}
}  // namespace differential_detail

// The derivatives of `shape` at p (a point on it; `primitive`: the triangle of a mesh).
inline SurfaceDerivatives surface_derivatives(const ShapeGeometry& shape, int primitive, const glm::dvec3& p) {
  using differential_detail::d;
  SurfaceDerivatives r;
  double curvature = 0.0;  // 1 / r for spheres
  if (const auto* s = std::get_if<SphereShape>(&shape)) {
    r.n = glm::normalize(p - d(s->center));
    curvature = 1.0 / static_cast<double>(s->radius);
  } else if (const auto* q = std::get_if<QuadShape>(&shape)) {
    r.n = glm::normalize(glm::cross(d(q->edge1), d(q->edge2)));
  } else if (const auto* k = std::get_if<DiskShape>(&shape)) {
    r.n = glm::normalize(d(k->normal));
  } else {
    const MeshShape& m = std::get<MeshShape>(shape);
    r.n = differential_detail::mesh_normal(m, primitive);
    if (!m.normals.empty()) return differential_detail::smooth_triangle(m, primitive, p, r);
  }
  r.ns = r.n;
  tangent_frame(r.n, &r.dpdu, &r.dpdv);
  r.dndu = curvature * r.dpdu;
  r.dndv = curvature * r.dpdv;
  return r;
}

// p (on `shape`) moved by the tangent step `step` and put back onto the surface: onto the sphere
// through its centre, within the plane of a quad, disk or triangle. Empty when the point leaves
// the shape (off the quad, the disk or the triangle).
inline std::optional<glm::dvec3> move_on_surface(const ShapeGeometry& shape, int primitive, const glm::dvec3& p,
                                                 const glm::dvec3& step) {
  using differential_detail::d;
  const glm::dvec3 q = p + step;
  if (const auto* s = std::get_if<SphereShape>(&shape)) {
    const glm::dvec3 c = d(s->center);
    const double len = glm::length(q - c);
    if (!(len > 0.0)) return std::nullopt;
    return c + (static_cast<double>(s->radius) / len) * (q - c);
  }
  if (const auto* k = std::get_if<DiskShape>(&shape)) {
    const glm::dvec3 n = glm::normalize(d(k->normal));
    const glm::dvec3 r = q - glm::dot(q - d(k->center), n) * n;  // back into the plane
    if (!(glm::length(r - d(k->center)) <= static_cast<double>(k->radius))) return std::nullopt;
    return r;
  }
  // Planar parallelograms and triangles: coordinates in the plane of two edges from a corner.
  glm::dvec3 o, e1, e2;
  bool triangle = false;
  if (const auto* qd = std::get_if<QuadShape>(&shape)) {
    o = d(qd->corner), e1 = d(qd->edge1), e2 = d(qd->edge2);
  } else {
    const MeshShape& m = std::get<MeshShape>(shape);
    const glm::uvec3 t = m.triangles[static_cast<std::size_t>(primitive)];
    o = d(m.positions[t.x]), e1 = d(m.positions[t.y]) - o, e2 = d(m.positions[t.z]) - o;
    triangle = true;
  }
  const glm::dvec3 n = glm::cross(e1, e2);
  const double n2 = glm::dot(n, n);
  if (!(n2 > 0.0)) return std::nullopt;
  const glm::dvec3 r = q - (glm::dot(q - o, n) / n2) * n;
  const glm::dvec3 w = r - o;
  const double u = glm::dot(glm::cross(w, e2), n) / n2, v = glm::dot(glm::cross(e1, w), n) / n2;
  const bool inside = triangle ? (u >= 0.0 && v >= 0.0 && u + v <= 1.0) : (u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0);
  if (!inside) return std::nullopt;
  return r;
}

}  // namespace pathex
