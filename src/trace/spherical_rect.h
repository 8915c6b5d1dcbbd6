// Uniform sampling of the solid angle a rectangle subtends at a point: Ureña, Fajardo and King
// 2013, "An Area-Preserving Parametrization for Spherical Rectangles" (the algorithm of their §3,
// as pbrt-v4's SampleSphericalRectangle writes it). The rectangle is corner + a·edge1 + b·edge2,
// a, b ∈ [0, 1], with edge1 ⟂ edge2; seen from `ref` it covers a spherical rectangle of solid
// angle Ω = γ0 + γ1 + γ2 + γ3 − 2π (its four interior angles), and the map from the unit square
// to it preserves area: every direction in it has density 1 / Ω.
//
// The setup and the map run in double precision: Ω is a difference of angles near 2π, which in
// float would lose three digits at the solid angles where area sampling takes over (1e-3 sr), and
// an error in Ω is an error in every sample's weight. Callers fall back to area sampling where the
// solid angle is tiny or close to a hemisphere (usable()): the same test, on the same numbers,
// where the density is evaluated and where the sample is drawn.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace pathex {

struct SphericalRect {
  // The rectangle in a frame at ref: x along edge1, y along edge2, z towards the rectangle's
  // plane's far side from ref negated (so z0 ≤ 0), and its extent there.
  glm::dvec3 o{0.0}, ex{0.0}, ey{0.0}, ez{0.0};  // ref and the frame's axes (world)
  double x0 = 0.0, y0 = 0.0, z0 = 0.0, x1 = 0.0, y1 = 0.0;
  double b0 = 0.0, b1 = 0.0, k = 0.0;  // the map's constants: the paper's b0, b1, and γ2 + γ3
  double solid_angle = 0.0;            // Ω [sr]; 0 when ref lies in the rectangle's plane

  // Solid angles below this are sampled by area (the rectangle is far or seen edge on: area
  // sampling is then nearly as good, and Ω's rounding matters); above the upper bound (ref almost
  // on the rectangle) too. pbrt-v4 uses 3e-4 and 6.22 for its spherical samplers.
  static constexpr double kMinSolidAngle = 1e-4;
  static constexpr double kMaxSolidAngle = 6.22;
  bool usable() const { return solid_angle >= kMinSolidAngle && solid_angle <= kMaxSolidAngle; }

  // The spherical rectangle of the rectangle at `ref`. edge1 and edge2 must be orthogonal and
  // nonzero (the caller's rectangle test).
  static SphericalRect at(const glm::vec3& corner, const glm::vec3& edge1, const glm::vec3& edge2, const glm::vec3& ref) {
    SphericalRect r;
    const glm::dvec3 e1(edge1), e2(edge2);
    const double l1 = glm::length(e1), l2 = glm::length(e2);
    r.o = glm::dvec3(ref);
    r.ex = e1 / l1;
    r.ey = e2 / l2;
    r.ez = glm::cross(r.ex, r.ey);
    const glm::dvec3 d = glm::dvec3(corner) - r.o;
    r.z0 = glm::dot(d, r.ez);
    if (r.z0 > 0.0) {  // the frame's z points away from the rectangle
      r.ez = -r.ez;
      r.z0 = -r.z0;
    }
    r.x0 = glm::dot(d, r.ex);
    r.y0 = glm::dot(d, r.ey);
    r.x1 = r.x0 + l1;
    r.y1 = r.y0 + l2;
    if (!(r.z0 < 0.0) || !std::isfinite(r.z0 + r.x0 + r.y0)) return r;  // in the plane: Ω = 0
    const glm::dvec3 v00(r.x0, r.y0, r.z0), v01(r.x0, r.y1, r.z0), v10(r.x1, r.y0, r.z0), v11(r.x1, r.y1, r.z0);
    const glm::dvec3 n0 = glm::normalize(glm::cross(v00, v10));
    const glm::dvec3 n1 = glm::normalize(glm::cross(v10, v11));
    const glm::dvec3 n2 = glm::normalize(glm::cross(v11, v01));
    const glm::dvec3 n3 = glm::normalize(glm::cross(v01, v00));
    const double g0 = angle_between(-n0, n1), g1 = angle_between(-n1, n2);
    const double g2 = angle_between(-n2, n3), g3 = angle_between(-n3, n0);
    r.b0 = n0.z;
    r.b1 = n2.z;
    r.k = g2 + g3;
    const double omega = g0 + g1 + g2 + g3 - 2.0 * std::numbers::pi;
    r.solid_angle = std::isfinite(omega) ? std::max(omega, 0.0) : 0.0;
    return r;
  }

  // The point of the rectangle in the direction u maps to (usable() must hold).
  glm::vec3 sample(glm::vec2 u) const {
    const double ux = u.x, uy = u.y;
    const double au = ux * solid_angle - k;  // the paper's u S + k, k = 2π − γ2 − γ3, less 2π
    const double fu = (std::cos(au) * b0 - b1) / std::sin(au);
    double cu = std::copysign(1.0, fu) / std::sqrt(fu * fu + b0 * b0);
    cu = std::clamp(cu, -1.0 + 1e-15, 1.0 - 1e-15);
    const double xu = std::clamp(-(cu * z0) / std::sqrt(std::max(0.0, 1.0 - cu * cu)), x0, x1);
    const double dd = std::sqrt(xu * xu + z0 * z0);
    const double h0 = y0 / std::sqrt(dd * dd + y0 * y0), h1 = y1 / std::sqrt(dd * dd + y1 * y1);
    const double hv = h0 + uy * (h1 - h0), hv2 = hv * hv;
    const double yv = hv2 < 1.0 - 1e-12 ? std::clamp(hv * dd / std::sqrt(1.0 - hv2), y0, y1) : y1;
    return glm::vec3(o + xu * ex + yv * ey + z0 * ez);
  }

  // The angle between unit vectors, accurate near 0 and π (pbrt-v4's AngleBetween).
  static double angle_between(const glm::dvec3& a, const glm::dvec3& b) {
    if (glm::dot(a, b) < 0.0) return std::numbers::pi - 2.0 * std::asin(std::min(1.0, glm::length(a + b) / 2.0));
    return 2.0 * std::asin(std::min(1.0, glm::length(b - a) / 2.0));
  }
};

// Whether a parallelogram is a rectangle the sampler serves: nonzero, perpendicular edges (to a
// relative 1e-4 of their lengths' product).
inline bool is_rectangle(const glm::vec3& edge1, const glm::vec3& edge2) {
  const double l1 = glm::length(glm::dvec3(edge1)), l2 = glm::length(glm::dvec3(edge2));
  return l1 > 0.0 && l2 > 0.0 && std::isfinite(l1 * l2) && std::abs(glm::dot(glm::dvec3(edge1), glm::dvec3(edge2))) <= 1e-4 * l1 * l2;
}

}  // namespace pathex
