// The microfacet distributions, the one copy the glossy, conductor, rough dielectric and coated
// BSDFs use: GGX (Trowbridge–Reitz, pbrt-v4's TrowbridgeReitzDistribution) and Beckmann (Mitsuba 3's
// default for its rough materials), both with height-correlated Smith masking. Anisotropic: alpha_x
// along the local frame's first tangent, alpha_y along the second. One struct, the kind a field:
// every caller asks D, Λ, G and visible-normal sampling of it and never names the distribution.
//
// Directions are local (shading normal = +z). The forms avoid both 1 − cos² (which loses the whole
// distribution near its peak when alpha ~ 1e-4) and divisions by cos θ (which overflow at grazing
// angles): with a² r² = α_x² x² + α_y² y²,
//   GGX       D(h)   = α_x α_y / (π t²),  t = (α_y/α_x) h_x² + (α_x/α_y) h_y² + α_x α_y h_z²   (unit h)
//             z·Λ(w) = a² r² / (2 (|z| + sqrt(z² + a² r²)))           (Λ = Smith's lambda)
//   Beckmann  D(h)   = exp(−((h_x/α_x)² + (h_y/α_y)²) / h_z²) / (π α_x α_y h_z⁴)
//             z·Λ(w) = (a r) e^(−a²) / (2 √π) − |z| erfc(a) / 2,  a = |z| / (a r)   (in double)
//                      (Λ = (erf(a) − 1) / 2 + e^(−a²) / (2 a √π), Walter et al. 2007, times |z|)
//   G1(w)      = |z| / (|z| + zΛ(w))
//   G2(o, i)   = |z_o z_i| / (|z_o z_i| + |z_i|·zΛ(o) + |z_o|·zΛ(i))
// For α_x == α_y every GGX expression is, operation for operation, the isotropic one.
// Sampling is of the visible normals D_wo(m) = G1(wo) |wo·m| D(m) / |z_o| for both kinds: Heitz
// 2018 for GGX, Heitz and d'Eon 2014 (the slope inversion as pbrt-v3's BeckmannSample11, which is
// what Mitsuba 3's sample_visible does) for Beckmann; so pdfs are d_visible() for both.
#pragma once

#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "scene/material.h"
#include "trace/rng.h"

namespace pathex {

namespace microfacet_detail {

// erf⁻¹ on (−1, 1): Giles' single-precision approximation (2010), then two Newton steps on std::erf
// in double (the result is exact to double rounding where the slope matters).
inline double erf_inv(double y) {
  y = std::clamp(y, -1.0 + 1e-15, 1.0 - 1e-15);
  double w = -std::log((1.0 - y) * (1.0 + y)), p;
  if (w < 5.0) {
    w -= 2.5;
    p = 2.81022636e-08;
    for (double c : {3.43273939e-07, -3.5233877e-06, -4.39150654e-06, 0.00021858087, -0.00125372503, -0.00417768164,
                     0.246640727, 1.50140941})
      p = c + p * w;
  } else {
    w = std::sqrt(w) - 3.0;
    p = -0.000200214257;
    for (double c : {0.000100950558, 0.00134934322, -0.00367342844, 0.00573950773, -0.0076224613, 0.00943887047,
                     1.00167406, 2.83297682})
      p = c + p * w;
  }
  double x = p * y;
  for (int i = 0; i < 2; ++i) {
    const double d = 2.0 / std::sqrt(std::numbers::pi) * std::exp(-x * x);
    if (!(d > 0.0)) break;
    x -= (std::erf(x) - y) / d;
  }
  return x;
}

// Heitz and d'Eon 2014 for the Beckmann slopes of unit roughness seen from a direction of cosine
// cos_i (> 0) in the x–z plane: slope_x by inverting its CDF (bisection-safeguarded Newton in erf
// space, pbrt-v3's BeckmannSample11), slope_y Gaussian.
inline glm::dvec2 beckmann_sample11(double cos_i, double u1, double u2) {
  if (cos_i > 0.9999) {  // normal incidence: the plain slope distribution exp(−x² − y²) / π
    const double r = std::sqrt(-std::log(std::max(1.0 - u1, 1e-300)));
    return {r * std::cos(2.0 * std::numbers::pi * u2), r * std::sin(2.0 * std::numbers::pi * u2)};
  }
  const double sin_i = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
  const double tan_i = sin_i / cos_i, cot_i = cos_i / sin_i;
  const double inv_sqrt_pi = 1.0 / std::sqrt(std::numbers::pi);
  double a = -1.0, c = std::erf(cot_i);
  const double x = std::clamp(u1, 1e-9, 1.0 - 1e-9);
  const double theta = std::acos(cos_i);
  const double fit = 1.0 + theta * (-0.876 + theta * (0.4265 - 0.0594 * theta));
  double b = c - (1.0 + c) * std::pow(1.0 - x, fit);
  const double norm = 1.0 / (1.0 + c + inv_sqrt_pi * tan_i * std::exp(-cot_i * cot_i));
  for (int it = 0; it < 40; ++it) {
    if (!(b >= a && b <= c)) b = 0.5 * (a + c);
    const double e = erf_inv(b);
    const double value = norm * (1.0 + b + inv_sqrt_pi * tan_i * std::exp(-e * e)) - x;
    const double derivative = norm * (1.0 - e * tan_i);
    if (std::abs(value) < 1e-9) break;
    if (value > 0.0) c = b; else a = b;
    b -= value / derivative;
  }
  return {erf_inv(b), erf_inv(2.0 * std::clamp(u2, 1e-9, 1.0 - 1e-9) - 1.0)};
}

}  // namespace microfacet_detail

struct Microfacet {
  float ax = 0.1f;
  float ay = 0.1f;
  MicrofacetKind kind = MicrofacetKind::kGgx;

  // pbrt-v4's TrowbridgeReitzDistribution::RoughnessToAlpha (remaproughness true): α = sqrt(r).
  // (Mitsuba 3's alpha is the alpha of either kind, unmapped.)
  static float roughness_to_alpha(float roughness) { return std::sqrt(roughness); }

  float d(const glm::vec3& h) const {
    if (kind == MicrofacetKind::kBeckmann) {
      const double z2 = double(h.z) * h.z;
      if (!(z2 > 0.0)) return 0.0f;
      const double sx = h.x / double(ax), sy = h.y / double(ay);
      return static_cast<float>(std::exp(-(sx * sx + sy * sy) / z2) / (std::numbers::pi * ax * ay * z2 * z2));
    }
    const float a2 = ax * ay;
    const float t = (ay / ax) * h.x * h.x + (ax / ay) * h.y * h.y + a2 * h.z * h.z;
    return a2 / (kPi * t * t);
  }
  float z_lambda(const glm::vec3& w) const {
    const float a2r2 = ax == ay ? ax * ax * (w.x * w.x + w.y * w.y) : (ax * w.x) * (ax * w.x) + (ay * w.y) * (ay * w.y);
    const float z = std::abs(w.z);
    if (kind == MicrofacetKind::kBeckmann) {
      const double ar = std::sqrt(double(a2r2));
      if (!(ar > 0.0)) return 0.0f;
      const double a = z / ar;
      const double zl = ar * std::exp(-a * a) / (2.0 * std::sqrt(std::numbers::pi)) - 0.5 * z * std::erfc(a);
      return static_cast<float>(std::max(zl, 0.0));
    }
    return a2r2 / (2.0f * (z + std::sqrt(z * z + a2r2)));
  }
  // G2 · 4 |z_o z_i| written as its denominator: 4 (|z_o z_i| + |z_i| zΛ(o) + |z_o| zΛ(i)); the
  // microfacet BRDF is D F / this. Symmetric in (wo, wi) bit for bit.
  float reflection_denominator(const glm::vec3& wo, const glm::vec3& wi) const {
    const float zo = std::abs(wo.z), zi = std::abs(wi.z);
    return 4.0f * (zo * zi + (zi * z_lambda(wo) + zo * z_lambda(wi)));
  }
  float g1(const glm::vec3& w) const {
    const float z = std::abs(w.z);
    return z / (z + z_lambda(w));
  }
  float g2(const glm::vec3& wo, const glm::vec3& wi) const {
    const float zo = std::abs(wo.z), zi = std::abs(wi.z);
    return zo * zi / (zo * zi + (zi * z_lambda(wo) + zo * z_lambda(wi)));
  }
  // Density of the visible normals from wo: D_wo(m) = G1(wo) |wo·m| D(m) / |z_o|, m on +z.
  float d_visible(const glm::vec3& wo, const glm::vec3& m) const {
    const float z = std::abs(wo.z);
    return d(m) * std::abs(glm::dot(wo, m)) / (z + z_lambda(wo));
  }

  // A microfacet normal (z ≥ 0) with density D_wo(m), wo.z > 0. GGX: Heitz 2018, "Sampling the GGX
  // Distribution of Visible Normals". Beckmann: Heitz and d'Eon 2014 (stretch, sample the unit
  // slopes, rotate, unstretch).
  glm::vec3 sample_visible_normal(const glm::vec3& wo, glm::vec2 u) const {
    if (kind == MicrofacetKind::kBeckmann) {
      const glm::dvec3 ws = glm::normalize(glm::dvec3(double(ax) * wo.x, double(ay) * wo.y, wo.z));
      const double sin_s = std::sqrt(ws.x * ws.x + ws.y * ws.y);
      const double cos_phi = sin_s > 0.0 ? ws.x / sin_s : 1.0, sin_phi = sin_s > 0.0 ? ws.y / sin_s : 0.0;
      const glm::dvec2 s = microfacet_detail::beckmann_sample11(ws.z, u.x, u.y);
      const double sx = ax * (cos_phi * s.x - sin_phi * s.y), sy = ay * (sin_phi * s.x + cos_phi * s.y);
      return glm::vec3(glm::normalize(glm::dvec3(-sx, -sy, 1.0)));
    }
    const glm::vec3 vh = glm::normalize(glm::vec3(ax * wo.x, ay * wo.y, wo.z));
    const float lensq = vh.x * vh.x + vh.y * vh.y;
    const glm::vec3 t1 = lensq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 t2 = glm::cross(vh, t1);
    const float r = std::sqrt(u.x);
    const float phi = 2.0f * kPi * u.y;
    const float p1 = r * std::cos(phi);
    float p2 = r * std::sin(phi);
    const float s = 0.5f * (1.0f + vh.z);
    p2 = (1.0f - s) * safe_sqrt(1.0f - p1 * p1) + s * p2;
    const glm::vec3 nh = p1 * t1 + p2 * t2 + safe_sqrt(1.0f - p1 * p1 - p2 * p2) * vh;
    return glm::normalize(glm::vec3(ax * nh.x, ay * nh.y, std::max(0.0f, nh.z)));
  }
};

}  // namespace pathex
