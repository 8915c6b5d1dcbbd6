// Fresnel reflectance and Snell's refraction, the one copy every BSDF uses: a dielectric interface (real relative index)
// and a conductor (complex index eta + i k, per RGB channel), both exact and unpolarised, as
// pbrt-v4's FrDielectric and FrComplex (pbrt-v4 book §9.3).
#pragma once

#include <algorithm>
#include <cmath>
#include <complex>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

namespace pathex {

// Reflectance of a smooth dielectric interface. `cos_i` is the cosine between the incident
// direction and the normal on the outside; negative means incidence from inside. `eta` is
// η_inside / η_outside. Returns exactly 1 beyond the critical angle.
inline float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, -1.0f, 1.0f);
  if (cos_i < 0.0f) {  // incidence from inside: swap the media
    eta = 1.0f / eta;
    cos_i = -cos_i;
  }
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;  // total internal reflection
  const float cos_t = std::sqrt(std::max(1.0f - sin2_t, 0.0f));
  const float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_parl * r_parl + r_perp * r_perp);
}

// Snell's law, the one copy (pbrt-v4's Refract): the direction *wt refracted from w (pointing away
// from the surface) across a surface of unit normal n with relative index eta = η_other / η_n's side;
// the normal and the index are flipped when w is on n's back side (*etap gets the index used,
// η_wt / η_w). False for total internal reflection.
inline bool refract(const glm::vec3& w, glm::vec3 n, float eta, float* etap, glm::vec3* wt) {
  float cos_i = glm::dot(n, w);
  if (cos_i < 0.0f) {
    eta = 1.0f / eta;
    cos_i = -cos_i;
    n = -n;
  }
  const float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return false;
  const float cos_t = std::sqrt(1.0f - sin2_t);
  *wt = -w / eta + (cos_i / eta - cos_t) * n;
  *etap = eta;
  return true;
}

// Reflectance of a conductor of complex relative index eta + i k, light arriving from the
// dielectric side at |cos_i| (the sign is ignored: pbrt-v4's conductors are two-sided). Computed in
// complex arithmetic as pbrt-v4's FrComplex: Snell's law with a complex index, then the two
// polarisations' amplitude ratios. k = 0 gives fresnel_dielectric().
inline float fresnel_complex(float cos_i, float eta, float k) {
  using C = std::complex<float>;
  cos_i = std::clamp(std::abs(cos_i), 0.0f, 1.0f);
  const C n(eta, k);
  const float sin2_i = 1.0f - cos_i * cos_i;
  const C sin2_t = sin2_i / (n * n);
  const C cos_t = std::sqrt(C(1.0f) - sin2_t);
  const C r_parl = (n * cos_i - cos_t) / (n * cos_i + cos_t);
  const C r_perp = (cos_i - n * cos_t) / (cos_i + n * cos_t);
  return 0.5f * (std::norm(r_parl) + std::norm(r_perp));
}

inline glm::vec3 fresnel_complex(float cos_i, const glm::vec3& eta, const glm::vec3& k) {
  return {fresnel_complex(cos_i, eta.x, k.x), fresnel_complex(cos_i, eta.y, k.y), fresnel_complex(cos_i, eta.z, k.z)};
}

}  // namespace pathex
