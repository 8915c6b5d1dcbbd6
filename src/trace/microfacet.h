// The GGX (Trowbridge–Reitz) microfacet distribution with height-correlated Smith masking, the one
// copy the glossy, conductor and rough dielectric BSDFs use. Anisotropic: alpha_x along the local
// frame's first tangent, alpha_y along the second (pbrt-v4's TrowbridgeReitzDistribution).
//
// Directions are local (shading normal = +z). The forms avoid both 1 − cos² (which loses the whole
// distribution near its peak when alpha ~ 1e-4) and divisions by cos θ (which overflow at grazing
// angles): with a² r² = α_x² x² + α_y² y²,
//   D(h)       = α_x α_y / (π t²),  t = (α_y/α_x) h_x² + (α_x/α_y) h_y² + α_x α_y h_z²   (unit h)
//   z·Λ(w)     = a² r² / (2 (|z| + sqrt(z² + a² r²)))           (Λ = Smith's lambda)
//   G1(w)      = |z| / (|z| + zΛ(w))
//   G2(o, i)   = |z_o z_i| / (|z_o z_i| + |z_i|·zΛ(o) + |z_o|·zΛ(i))
// For α_x == α_y every expression is, operation for operation, the isotropic one.
#pragma once

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "trace/rng.h"

namespace pathex {

struct Ggx {
  float ax = 0.1f;
  float ay = 0.1f;

  // pbrt-v4's TrowbridgeReitzDistribution::RoughnessToAlpha (remaproughness true): α = sqrt(r).
  static float roughness_to_alpha(float roughness) { return std::sqrt(roughness); }

  float d(const glm::vec3& h) const {
    const float a2 = ax * ay;
    const float t = (ay / ax) * h.x * h.x + (ax / ay) * h.y * h.y + a2 * h.z * h.z;
    return a2 / (kPi * t * t);
  }
  float z_lambda(const glm::vec3& w) const {
    const float a2r2 = ax == ay ? ax * ax * (w.x * w.x + w.y * w.y) : (ax * w.x) * (ax * w.x) + (ay * w.y) * (ay * w.y);
    const float z = std::abs(w.z);
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

  // Heitz 2018, "Sampling the GGX Distribution of Visible Normals": a microfacet normal (z ≥ 0)
  // with density D_wo(m). wo.z > 0.
  glm::vec3 sample_visible_normal(const glm::vec3& wo, glm::vec2 u) const {
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
