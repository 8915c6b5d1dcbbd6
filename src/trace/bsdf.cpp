// BSDF sampling and evaluation (see bsdf.h for the conventions). Layout: the per-kind pieces in
// the shading frame (Lambert, GGX, Fresnel), then the public functions, which handle sidedness,
// the geometric-normal test and mixtures once for all kinds.
#include "trace/bsdf.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

#include <glm/geometric.hpp>

#include "trace/bsdf_layered.h"
#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex::bsdf {
namespace {

template <class T, class V>
constexpr bool is = std::is_same_v<std::decay_t<V>, T>;

bool is_delta_kind(const BasicMaterial& m) {
  return std::holds_alternative<Mirror>(m) || std::holds_alternative<Dielectric>(m);
}

bool finite_vec(const glm::vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

bool is_black(const glm::vec3& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

// The positive, finite weight of a mixture component, 0 otherwise.
float usable_weight(float w) { return std::isfinite(w) && w > 0.0f ? w : 0.0f; }

float total_weight(const Mixture& mix) {
  float total = 0.0f;
  for (const auto& c : mix.components) total += usable_weight(c.weight);
  return total;
}

// --- GGX (Trowbridge–Reitz) with height-correlated Smith masking, in the shading frame ---
//
// Directions are local with z > 0 (the caller flipped them to wo's side). The forms avoid both
// 1 − cos² (which loses the whole distribution near its peak when alpha ~ 1e-4) and divisions by
// cos θ (which overflow at grazing angles): with r² = x² + y²,
//   D(h)       = α² / (π (h_x² + h_y² + α² h_z²)²)               for unit h
//   z·Λ(w)     = α² r² / (2 (z + sqrt(z² + α² r²)))             (Λ = Smith's lambda)
//   G1(w)      = z / (z + zΛ(w))
//   G2(o, i)   = z_o z_i / (z_o z_i + z_i·zΛ(o) + z_o·zΛ(i))

float ggx_alpha(const Glossy& g) {
  return std::clamp(std::isfinite(g.roughness) ? g.roughness : 1.0f, kMinGlossyRoughness, 1.0f);
}

float ggx_d(const glm::vec3& h, float alpha) {
  const float a2 = alpha * alpha;
  const float t = h.x * h.x + h.y * h.y + a2 * h.z * h.z;
  return a2 / (kPi * t * t);
}

float ggx_z_lambda(const glm::vec3& w, float alpha) {
  const float a2r2 = alpha * alpha * (w.x * w.x + w.y * w.y);
  const float z = std::abs(w.z);
  return a2r2 / (2.0f * (z + std::sqrt(z * z + a2r2)));
}

glm::vec3 schlick(const glm::vec3& r0, float cos_h) {
  const float m = std::clamp(1.0f - cos_h, 0.0f, 1.0f);
  const float m2 = m * m;
  return r0 + (glm::vec3(1.0f) - r0) * (m2 * m2 * m);
}

// f(wo, wi) for z_o, z_i > 0. Every step is symmetric in (wo, wi), so the result is bit-identical
// under exchange (IEEE + and * commute; the sums are grouped so that exchange only reorders
// commuting operands).
glm::vec3 ggx_eval(const Glossy& g, const glm::vec3& wo, const glm::vec3& wi) {
  const float alpha = ggx_alpha(g);
  const glm::vec3 hs = wo + wi;
  const float len2 = glm::dot(hs, hs);
  if (!(len2 > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 h = hs / std::sqrt(len2);
  const float d = ggx_d(h, alpha);
  const float cos_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  const float zo = wo.z, zi = wi.z;
  // 4 z_o z_i (1 + Λo + Λi), without dividing by either cosine.
  const float denom =
      4.0f * (zo * zi + (zi * ggx_z_lambda(wo, alpha) + zo * ggx_z_lambda(wi, alpha)));
  if (!(denom > 0.0f)) return glm::vec3(0.0f);
  return schlick(g.reflectance, cos_h) * (d / denom);
}

// Density of visible-normal sampling: G1(wo) D(h) / (4 z_o) = D(h) / (4 (z_o + zΛ(wo))).
float ggx_pdf(const Glossy& g, const glm::vec3& wo, const glm::vec3& wi) {
  const float alpha = ggx_alpha(g);
  const glm::vec3 hs = wo + wi;
  const float len2 = glm::dot(hs, hs);
  if (!(len2 > 0.0f)) return 0.0f;
  const glm::vec3 h = hs / std::sqrt(len2);
  const float denom = 4.0f * (wo.z + ggx_z_lambda(wo, alpha));
  if (!(denom > 0.0f)) return 0.0f;
  return ggx_d(h, alpha) / denom;
}

// Heitz 2018, "Sampling the GGX Distribution of Visible Normals": a microfacet normal with density
// D_wo(m) = G1(wo) max(0, wo·m) D(m) / z_o. wo.z > 0.
glm::vec3 ggx_sample_visible_normal(const glm::vec3& wo, float alpha, glm::vec2 u) {
  const glm::vec3 vh = glm::normalize(glm::vec3(alpha * wo.x, alpha * wo.y, wo.z));
  const float lensq = vh.x * vh.x + vh.y * vh.y;
  const glm::vec3 t1 = lensq > 0.0f ? glm::vec3(-vh.y, vh.x, 0.0f) / std::sqrt(lensq)
                                    : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 t2 = glm::cross(vh, t1);
  const float r = std::sqrt(u.x);
  const float phi = 2.0f * kPi * u.y;
  const float p1 = r * std::cos(phi);
  float p2 = r * std::sin(phi);
  const float s = 0.5f * (1.0f + vh.z);
  p2 = (1.0f - s) * safe_sqrt(1.0f - p1 * p1) + s * p2;
  const glm::vec3 nh = p1 * t1 + p2 * t2 + safe_sqrt(1.0f - p1 * p1 - p2 * p2) * vh;
  return glm::normalize(glm::vec3(alpha * nh.x, alpha * nh.y, std::max(0.0f, nh.z)));
}

// --- finite components, local frame, directions as given (either side) ---

// The finite BSDF of one basic component; both directions already flipped to z > 0.
glm::vec3 eval_basic(const BasicMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  return std::visit(
      [&](const auto& k) -> glm::vec3 {
        if constexpr (is<Diffuse, decltype(k)>) {
          return k.albedo * kInvPi;
        } else if constexpr (is<Glossy, decltype(k)>) {
          return ggx_eval(k, wo, wi);
        } else if constexpr (is<CoatedDiffuse, decltype(k)>) {
          return layered::eval(k, wo, wi);
        } else {
          return glm::vec3(0.0f);  // deltas: nothing for a generic wi
        }
      },
      m);
}

float pdf_basic(const BasicMaterial& m, const glm::vec3& wo, const glm::vec3& wi) {
  return std::visit(
      [&](const auto& k) -> float {
        if constexpr (is<Diffuse, decltype(k)>) {
          return cosine_hemisphere_pdf(wi.z);
        } else if constexpr (is<Glossy, decltype(k)>) {
          return ggx_pdf(k, wo, wi);
        } else if constexpr (is<CoatedDiffuse, decltype(k)>) {
          return layered::pdf(k, wo, wi);
        } else {
          return 0.0f;
        }
      },
      m);
}

// Local wo/wi of a reflection configuration flipped so that both have z > 0, or false if wo and
// wi are not strictly on one side of both the shading and the geometric normal.
bool reflection_local(const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                      const glm::vec3& ng, glm::vec3* wo_l, glm::vec3* wi_l) {
  if (!(glm::dot(wo, ng) * glm::dot(wi, ng) > 0.0f)) return false;
  const Frame frame = Frame::from_normal(ns);
  *wo_l = frame.to_local(wo);
  *wi_l = frame.to_local(wi);
  if (!(wo_l->z * wi_l->z > 0.0f)) return false;
  if (wo_l->z < 0.0f) {
    wo_l->z = -wo_l->z;
    wi_l->z = -wi_l->z;
  }
  return true;
}

using detail::same_side;

// --- delta components ---

struct DeltaSample {
  glm::vec3 wi;
  glm::vec3 weight;  // f |cos θi| / p (before mixture scaling)
  float abs_cos_i;
  float prob;        // discrete probability of this lobe
  float prob_rev;
  float eta;
  Lobe lobe;
};

std::optional<DeltaSample> sample_delta(const BasicMaterial& m, const glm::vec3& wo,
                                        const glm::vec3& ns, float uc, TransportMode mode) {
  const float cos_o = glm::dot(wo, ns);
  if (!(cos_o != 0.0f) || !std::isfinite(cos_o)) return std::nullopt;
  const glm::vec3 reflected = (2.0f * cos_o) * ns - wo;
  if (const auto* mirror = std::get_if<Mirror>(&m)) {
    return DeltaSample{reflected, mirror->reflectance, std::abs(cos_o), 1.0f, 1.0f, 1.0f,
                       Lobe::kSpecularReflection};
  }
  const auto& d = std::get<Dielectric>(m);
  if (!(d.ior > 0.0f) || !std::isfinite(d.ior)) return std::nullopt;
  const float f_refl = fresnel_dielectric(cos_o, d.ior);
  if (uc < f_refl) {
    return DeltaSample{reflected, d.tint, std::abs(cos_o), f_refl, f_refl, 1.0f,
                       Lobe::kSpecularReflection};
  }
  // Refraction. eta_rel = η_wi / η_wo; the normal on wo's side is ns · sign(cos_o).
  const bool outside = cos_o > 0.0f;
  const float eta_rel = outside ? d.ior : 1.0f / d.ior;
  const float cos_i = std::abs(cos_o);
  const float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta_rel * eta_rel);
  if (sin2_t >= 1.0f) return std::nullopt;  // unreachable: fresnel_dielectric returned 1
  const float cos_t = std::sqrt(1.0f - sin2_t);
  const glm::vec3 n_side = outside ? ns : -ns;
  const glm::vec3 wt = glm::normalize(-wo / eta_rel + (cos_i / eta_rel - cos_t) * n_side);
  glm::vec3 weight = d.tint;
  if (mode == TransportMode::kRadiance) weight /= eta_rel * eta_rel;
  const float f_rev = fresnel_dielectric(glm::dot(wt, ns), d.ior);
  return DeltaSample{wt, weight, std::abs(glm::dot(wt, ns)), 1.0f - f_refl, 1.0f - f_rev, eta_rel,
                     Lobe::kSpecularTransmission};
}

float delta_probability(const BasicMaterial& m, const glm::vec3& wo, const glm::vec3& ns,
                        Lobe lobe) {
  if (const auto* d = std::get_if<Dielectric>(&m)) {
    const float f_refl = fresnel_dielectric(glm::dot(wo, ns), d->ior);
    if (lobe == Lobe::kSpecularReflection) return f_refl;
    if (lobe == Lobe::kSpecularTransmission) return 1.0f - f_refl;
    return 0.0f;
  }
  if (std::holds_alternative<Mirror>(m)) return lobe == Lobe::kSpecularReflection ? 1.0f : 0.0f;
  if (const auto* coat = std::get_if<CoatedDiffuse>(&m))
    return lobe == Lobe::kSpecularReflection ? layered::specular_probability(*coat, glm::dot(wo, ns)) : 0.0f;
  return 0.0f;
}

// The component `m` selects and the remapped uniform, or nullopt for a material with no weight.
struct Pick {
  const BasicMaterial* material;
  int index;
  float probability;  // w_j / W (1 for a basic material)
  float weight;       // w_j (1 for a basic material)
  float u;            // u_component rescaled to [0, 1) within the chosen interval
};

std::optional<Pick> pick_component(const Mixture& mix, float u) {
  const float total = total_weight(mix);
  if (!(total > 0.0f)) return std::nullopt;
  // Walk the cumulative weights; rounding can leave target past the last interval, in which case
  // the last positive component is taken.
  const float target = u * total;
  float lo = 0.0f, last_lo = 0.0f;
  int last = -1;
  for (std::size_t j = 0; j < mix.components.size(); ++j) {
    const float w = usable_weight(mix.components[j].weight);
    if (w == 0.0f) continue;
    last = static_cast<int>(j);
    last_lo = lo;
    if (target < lo + w) break;
    lo += w;
  }
  if (last < 0) return std::nullopt;
  const auto& c = mix.components[static_cast<std::size_t>(last)];
  const float w = usable_weight(c.weight);
  const float ur = std::clamp((target - last_lo) / w, 0.0f, kOneMinusEpsilon);
  return Pick{&c.material, last, w / total, w, ur};
}

// The component to sample: a mixture's is referenced in place, a basic material (a few floats) is
// copied into `storage` so that both cases continue as a BasicMaterial.
std::optional<Pick> pick(const Material& m, float u, BasicMaterial* storage) {
  if (const auto* mix = std::get_if<Mixture>(&m)) return pick_component(*mix, u);
  std::visit(
      [&](const auto& k) {
        if constexpr (!is<Mixture, decltype(k)>) *storage = k;
      },
      m);
  return Pick{storage, 0, 1.0f, 1.0f, u};
}

}  // namespace

// --- public functions ---

float fresnel_dielectric(float cos_i, float eta) {
  cos_i = std::clamp(cos_i, -1.0f, 1.0f);
  if (cos_i < 0.0f) {  // incidence from inside: swap the media
    eta = 1.0f / eta;
    cos_i = -cos_i;
  }
  const float sin2_t = (1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;  // total internal reflection
  const float cos_t = safe_sqrt(1.0f - sin2_t);
  const float r_parl = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  const float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_parl * r_parl + r_perp * r_perp);
}

glm::vec3 detail::eval_general(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                               const glm::vec3& ng) {
  glm::vec3 wo_l, wi_l;
  if (!reflection_local(wo, wi, ns, ng, &wo_l, &wi_l)) return glm::vec3(0.0f);
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    glm::vec3 sum(0.0f);
    for (const auto& c : mix->components) {
      const float w = usable_weight(c.weight);
      if (w > 0.0f && !is_delta_kind(c.material)) sum += w * eval_basic(c.material, wo_l, wi_l);
    }
    return sum;
  }
  return std::visit(
      [&](const auto& k) -> glm::vec3 {
        if constexpr (is<Mixture, decltype(k)>) {
          return glm::vec3(0.0f);
        } else {
          return eval_basic(BasicMaterial{k}, wo_l, wi_l);
        }
      },
      m);
}

float detail::pdf_general(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                          const glm::vec3& ng) {
  glm::vec3 wo_l, wi_l;
  if (!reflection_local(wo, wi, ns, ng, &wo_l, &wi_l)) return 0.0f;
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    const float total = total_weight(*mix);
    if (!(total > 0.0f)) return 0.0f;
    float sum = 0.0f;
    for (const auto& c : mix->components) {
      const float w = usable_weight(c.weight);
      if (w > 0.0f && !is_delta_kind(c.material))
        sum += (w / total) * pdf_basic(c.material, wo_l, wi_l);
    }
    return sum;
  }
  return std::visit(
      [&](const auto& k) -> float {
        if constexpr (is<Mixture, decltype(k)>) {
          return 0.0f;
        } else {
          return pdf_basic(BasicMaterial{k}, wo_l, wi_l);
        }
      },
      m);
}

std::optional<BsdfSample> detail::sample_general(const Material& m, const glm::vec3& wo, const glm::vec3& ns,
                                                const glm::vec3& ng, float u_component, glm::vec2 u,
                                                TransportMode mode) {
  const float cos_o = glm::dot(wo, ns);
  const float cos_og = glm::dot(wo, ng);
  if (!(cos_o != 0.0f) || !(cos_og != 0.0f) || !std::isfinite(cos_o) || !std::isfinite(cos_og))
    return std::nullopt;
  // Lambert never gets here: sample() (bsdf.h) takes it inline.
  BasicMaterial storage;
  const std::optional<Pick> chosen = pick(m, u_component, &storage);
  if (!chosen) return std::nullopt;
  const BasicMaterial& c = *chosen->material;
  if (const auto* coat = std::get_if<CoatedDiffuse>(&c))  // its own walk (trace/bsdf_layered.h)
    return layered::sample_world(m, *coat, chosen->index, chosen->probability, chosen->weight, wo, ns, ng, chosen->u, u);

  BsdfSample s;
  s.component = chosen->index;
  if (is_delta_kind(c)) {
    // --- Dirac delta: mirror, or the reflection / refraction of a smooth dielectric ---
    const std::optional<DeltaSample> d = sample_delta(c, wo, ns, chosen->u, mode);
    if (!d || !(d->abs_cos_i > 0.0f) || !(d->prob > 0.0f)) return std::nullopt;
    const bool transmits = d->lobe == Lobe::kSpecularTransmission;
    const float side = glm::dot(d->wi, ng) * cos_og;
    if (transmits ? !(side < 0.0f) : !(side > 0.0f)) return std::nullopt;  // leaks through ng
    s.wi = d->wi;
    s.pdf = chosen->probability * d->prob;
    s.pdf_rev = chosen->probability * d->prob_rev;
    // f = w_j · (weight_j · p_j / |cos θi|); weight = f |cos θi| / pdf = W · weight_j.
    s.f = chosen->weight * d->weight * (d->prob / d->abs_cos_i);
    s.weight = d->weight * (chosen->weight / chosen->probability);
    s.eta = d->eta;
    s.letter = kS;
    s.is_delta = true;
    s.lobe = d->lobe;
  } else {
    // --- finite lobe: draw a direction from the chosen lobe, value it with all finite lobes ---
    const Frame frame = Frame::from_normal(ns);
    glm::vec3 wo_l = frame.to_local(wo);
    const bool flip = wo_l.z < 0.0f;
    if (flip) wo_l.z = -wo_l.z;
    glm::vec3 wi_l;
    if (const auto* g = std::get_if<Glossy>(&c)) {
      const glm::vec3 wm = ggx_sample_visible_normal(wo_l, ggx_alpha(*g), u);
      wi_l = 2.0f * glm::dot(wo_l, wm) * wm - wo_l;
      s.lobe = Lobe::kGlossyReflection;
    } else {
      wi_l = sample_cosine_hemisphere(u);
      s.lobe = Lobe::kDiffuseReflection;
    }
    if (!(wi_l.z > 0.0f)) return std::nullopt;  // below the (micro)surface: energy not reflected
    if (flip) wi_l.z = -wi_l.z;
    s.wi = glm::normalize(frame.to_world(wi_l));
    s.f = eval(m, wo, s.wi, ns, ng);
    s.pdf = pdf(m, wo, s.wi, ns, ng);
    if (!(s.pdf > 0.0f) || is_black(s.f) || !finite_vec(s.f)) return std::nullopt;
    s.pdf_rev = pdf(m, s.wi, wo, ns, ng);
    s.weight = s.f * (std::abs(glm::dot(s.wi, ns)) / s.pdf);
    if (const auto* mix = std::get_if<Mixture>(&m)) {
      // A coat's samples carry their walk's weight without MIS (trace/bsdf_layered.h), so the
      // other finite lobes of a mixture holding one share only their own part, by one-sample MIS
      // among themselves; s.f and s.pdf stay those of the whole material.
      glm::vec3 f_own(0.0f), wo_l2, wi_l2;
      float p_own = 0.0f;
      bool coat = false;
      if (reflection_local(wo, s.wi, ns, ng, &wo_l2, &wi_l2)) {
        const float total = total_weight(*mix);
        for (const auto& k : mix->components) {
          const float w = usable_weight(k.weight);
          if (w == 0.0f || is_delta_kind(k.material)) continue;
          if (std::holds_alternative<CoatedDiffuse>(k.material)) {
            coat = true;
            continue;
          }
          f_own += w * eval_basic(k.material, wo_l2, wi_l2);
          p_own += (w / total) * pdf_basic(k.material, wo_l2, wi_l2);
        }
      }
      if (coat) {
        if (!(p_own > 0.0f)) return std::nullopt;
        s.weight = f_own * (std::abs(glm::dot(s.wi, ns)) / p_own);
      }
    }
    s.letter = kD;
    s.is_delta = false;
  }
  if (!finite_vec(s.weight) || !finite_vec(s.f)) return std::nullopt;
  return s;
}

float component_probability(const Material& m, const glm::vec3& wo, const glm::vec3& ns,
                            int component, Lobe lobe) {
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    if (component < 0 || static_cast<std::size_t>(component) >= mix->components.size()) return 0.0f;
    const float total = total_weight(*mix);
    const auto& c = mix->components[static_cast<std::size_t>(component)];
    const float w = usable_weight(c.weight);
    if (!(total > 0.0f) || w == 0.0f) return 0.0f;
    return (w / total) * delta_probability(c.material, wo, ns, lobe);
  }
  if (component != 0) return 0.0f;
  return std::visit(
      [&](const auto& k) -> float {
        if constexpr (is<Mixture, decltype(k)>) {
          return 0.0f;
        } else {
          return delta_probability(BasicMaterial{k}, wo, ns, lobe);
        }
      },
      m);
}

bool has_finite_component(const Material& m) {
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    for (const auto& c : mix->components)
      if (usable_weight(c.weight) > 0.0f && !is_delta_kind(c.material)) return true;
    return false;
  }
  return std::holds_alternative<Diffuse>(m) || std::holds_alternative<Glossy>(m) || std::holds_alternative<CoatedDiffuse>(m);
}

float shading_normal_correction(const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                                const glm::vec3& ng, TransportMode mode) {
  if (mode == TransportMode::kRadiance) return 1.0f;
  const float num = std::abs(glm::dot(wo, ns) * glm::dot(wi, ng));
  const float den = std::abs(glm::dot(wo, ng) * glm::dot(wi, ns));
  if (!(den > 0.0f)) return 0.0f;
  return num / den;
}

}  // namespace pathex::bsdf
