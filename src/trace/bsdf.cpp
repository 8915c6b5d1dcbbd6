// BSDF sampling and evaluation (see bsdf.h for the conventions). Layout: the per-kind pieces in
// the shading frame (Lambert, the glossy lobe, the Dirac deltas; the conductor, rough and thin
// dielectrics and diffuse transmission in their own files, bsdf_kinds.h), then the public
// functions, which handle sidedness, the geometric-normal test and mixtures once for all kinds.
#include "trace/bsdf.h"

#include <algorithm>
#include <cmath>
#include <type_traits>
#include <variant>

#include <glm/geometric.hpp>

#include "trace/bsdf_kinds.h"
#include "trace/bsdf_layered.h"
#include "trace/frame.h"
#include "trace/rng.h"

namespace pathex::bsdf {
namespace {

template <class T, class V>
constexpr bool is = std::is_same_v<std::decay_t<V>, T>;

// A kind that is only Dirac deltas (a smooth coat is not: what passes it is finite).
bool is_delta_kind(const BasicMaterial& m) { return letters_of(m) == static_cast<LetterMask>(1u << kS); }

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

// --- the glossy lobe: GGX (trace/microfacet.h) with Schlick's Fresnel, in the shading frame ---

Microfacet glossy_ggx(const Glossy& g) { return kinds::clamped_microfacet(g.distribution, g.roughness, g.roughness); }

glm::vec3 schlick(const glm::vec3& r0, float cos_h) {
  const float m = std::clamp(1.0f - cos_h, 0.0f, 1.0f);
  const float m2 = m * m;
  return r0 + (glm::vec3(1.0f) - r0) * (m2 * m2 * m);
}

// f(wo, wi) for z_o, z_i > 0. Every step is symmetric in (wo, wi), so the result is bit-identical
// under exchange (IEEE + and * commute; the sums are grouped so that exchange only reorders
// commuting operands).
glm::vec3 ggx_eval(const Glossy& g, const glm::vec3& wo, const glm::vec3& wi) {
  const Microfacet ggx = glossy_ggx(g);
  const glm::vec3 hs = wo + wi;
  const float len2 = glm::dot(hs, hs);
  if (!(len2 > 0.0f)) return glm::vec3(0.0f);
  const glm::vec3 h = hs / std::sqrt(len2);
  const float d = ggx.d(h);
  const float cos_h = 0.5f * (glm::dot(wo, h) + glm::dot(wi, h));
  // 4 z_o z_i (1 + Λo + Λi), without dividing by either cosine.
  const float denom = ggx.reflection_denominator(wo, wi);
  if (!(denom > 0.0f)) return glm::vec3(0.0f);
  return schlick(g.reflectance, cos_h) * (d / denom);
}

// Density of visible-normal sampling: G1(wo) D(h) / (4 z_o) = D(h) / (4 (z_o + zΛ(wo))).
float ggx_pdf(const Glossy& g, const glm::vec3& wo, const glm::vec3& wi) {
  const Microfacet ggx = glossy_ggx(g);
  const glm::vec3 hs = wo + wi;
  const float len2 = glm::dot(hs, hs);
  if (!(len2 > 0.0f)) return 0.0f;
  const glm::vec3 h = hs / std::sqrt(len2);
  const float denom = 4.0f * (wo.z + ggx.z_lambda(wo));
  if (!(denom > 0.0f)) return 0.0f;
  return ggx.d(h) / denom;
}

// --- finite components, local frame flipped so that wo.z > 0 (wi on either side) ---

// The relative index of the side wo is not on, for an oriented kind (bsdf_kinds.h).
float far_eta(float ior, bool inside) { return inside ? 1.0f / ior : ior; }

// The finite BSDF of one basic component. `inside`: wo was on −ns's side before the flip.
glm::vec3 eval_basic(const BasicMaterial& m, const glm::vec3& wo, const glm::vec3& wi, bool inside,
                     TransportMode mode) {
  return std::visit(
      [&](const auto& k) -> glm::vec3 {
        if constexpr (is<Diffuse, decltype(k)>) {
          return wi.z > 0.0f ? k.albedo * kInvPi : glm::vec3(0.0f);
        } else if constexpr (is<Glossy, decltype(k)>) {
          return wi.z > 0.0f ? ggx_eval(k, wo, wi) : glm::vec3(0.0f);
        } else if constexpr (is<Conductor, decltype(k)>) {
          return kinds::conductor_eval(k, wo, wi);
        } else if constexpr (is<RoughDielectric, decltype(k)>) {
          return kinds::rough_dielectric_eval(k, far_eta(k.ior, inside), wo, wi, mode);
        } else if constexpr (is<DiffuseTransmission, decltype(k)>) {
          return kinds::diffuse_transmission_eval(k, wo, wi);
        } else if constexpr (is<CoatedDiffuse, decltype(k)>) {
          return wi.z > 0.0f ? layered::eval(k, wo, wi) : glm::vec3(0.0f);  // a coat over an opaque base reflects only
        } else {
          return glm::vec3(0.0f);  // deltas: nothing for a generic wi
        }
      },
      m);
}

float pdf_basic(const BasicMaterial& m, const glm::vec3& wo, const glm::vec3& wi, bool inside) {
  return std::visit(
      [&](const auto& k) -> float {
        if constexpr (is<Diffuse, decltype(k)>) {
          return cosine_hemisphere_pdf(wi.z);
        } else if constexpr (is<Glossy, decltype(k)>) {
          return wi.z > 0.0f ? ggx_pdf(k, wo, wi) : 0.0f;
        } else if constexpr (is<Conductor, decltype(k)>) {
          return kinds::conductor_pdf(k, wo, wi);
        } else if constexpr (is<RoughDielectric, decltype(k)>) {
          return kinds::rough_dielectric_pdf(k, far_eta(k.ior, inside), wo, wi);
        } else if constexpr (is<DiffuseTransmission, decltype(k)>) {
          return kinds::diffuse_transmission_pdf(k, wo, wi);
        } else if constexpr (is<CoatedDiffuse, decltype(k)>) {
          return wi.z > 0.0f ? layered::pdf(k, wo, wi) : 0.0f;
        } else {
          return 0.0f;
        }
      },
      m);
}

// Local wo/wi flipped so that wo.z > 0, or false if the pair is neither a reflection (wo and wi
// strictly on one side of both the shading and the geometric normal) nor a transmission
// (strictly on opposite sides of both). *inside: wo was on −ns's side.
bool local_pair(const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns, const glm::vec3& ng,
                glm::vec3* wo_l, glm::vec3* wi_l, bool* inside) {
  const float sides_g = glm::dot(wo, ng) * glm::dot(wi, ng);
  if (!(sides_g > 0.0f) && !(sides_g < 0.0f)) return false;
  const Frame frame = Frame::from_normal(ns);
  *wo_l = frame.to_local(wo);
  *wi_l = frame.to_local(wi);
  const float sides_s = wo_l->z * wi_l->z;
  if (sides_g > 0.0f ? !(sides_s > 0.0f) : !(sides_s < 0.0f)) return false;
  *inside = wo_l->z < 0.0f;
  if (*inside) {
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
  if (const auto* c = std::get_if<Conductor>(&m)) {
    return DeltaSample{reflected, kinds::conductor_reflectance(*c, cos_o), std::abs(cos_o), 1.0f, 1.0f, 1.0f,
                       Lobe::kSpecularReflection};
  }
  if (const auto* coat = std::get_if<CoatedDiffuse>(&m)) {  // all_specular(): a mirror of the walk's expected reflectance
    return DeltaSample{reflected, layered::specular_reflectance(*coat, cos_o), std::abs(cos_o), 1.0f, 1.0f, 1.0f,
                       Lobe::kSpecularReflection};
  }
  if (const auto* t = std::get_if<ThinDielectric>(&m)) {  // reflect with R', else pass straight through
    const float r = kinds::thin_dielectric_reflectance(*t, cos_o);
    if (uc < r) return DeltaSample{reflected, t->tint, std::abs(cos_o), r, r, 1.0f, Lobe::kSpecularReflection};
    return DeltaSample{-wo, t->tint, std::abs(cos_o), 1.0f - r, 1.0f - r, 1.0f, Lobe::kSpecularTransmission};
  }
  const auto& d = std::get<Dielectric>(m);
  if (!(d.ior > 0.0f) || !std::isfinite(d.ior)) return std::nullopt;
  const float f_refl = fresnel_dielectric(cos_o, d.ior);
  if (uc < f_refl) {
    return DeltaSample{reflected, d.tint, std::abs(cos_o), f_refl, f_refl, 1.0f,
                       Lobe::kSpecularReflection};
  }
  // Refraction. eta_rel = η_wi / η_wo; the normal on wo's side is ns · sign(cos_o).
  float eta_rel;
  glm::vec3 wt;
  if (!refract(wo, ns, d.ior, &eta_rel, &wt)) return std::nullopt;  // unreachable: fresnel_dielectric returned 1
  wt = glm::normalize(wt);
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
  if (const auto* t = std::get_if<ThinDielectric>(&m)) {
    const float r = kinds::thin_dielectric_reflectance(*t, glm::dot(wo, ns));
    if (lobe == Lobe::kSpecularReflection) return r;
    if (lobe == Lobe::kSpecularTransmission) return 1.0f - r;
    return 0.0f;
  }
  if (std::holds_alternative<Mirror>(m) || is_delta_kind(m)) return lobe == Lobe::kSpecularReflection ? 1.0f : 0.0f;
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

glm::vec3 detail::eval_general(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                               const glm::vec3& ng, TransportMode mode) {
  glm::vec3 wo_l, wi_l;
  bool inside;
  if (!local_pair(wo, wi, ns, ng, &wo_l, &wi_l, &inside)) return glm::vec3(0.0f);
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    glm::vec3 sum(0.0f);
    for (const auto& c : mix->components) {
      const float w = usable_weight(c.weight);
      if (w > 0.0f && !is_delta_kind(c.material)) sum += w * eval_basic(c.material, wo_l, wi_l, inside, mode);
    }
    return sum;
  }
  return std::visit(
      [&](const auto& k) -> glm::vec3 {
        if constexpr (is<Mixture, decltype(k)>) {
          return glm::vec3(0.0f);
        } else {
          return eval_basic(BasicMaterial{k}, wo_l, wi_l, inside, mode);
        }
      },
      m);
}

float detail::pdf_general(const Material& m, const glm::vec3& wo, const glm::vec3& wi, const glm::vec3& ns,
                          const glm::vec3& ng) {
  glm::vec3 wo_l, wi_l;
  bool inside;
  if (!local_pair(wo, wi, ns, ng, &wo_l, &wi_l, &inside)) return 0.0f;
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    const float total = total_weight(*mix);
    if (!(total > 0.0f)) return 0.0f;
    float sum = 0.0f;
    for (const auto& c : mix->components) {
      const float w = usable_weight(c.weight);
      if (w > 0.0f && !is_delta_kind(c.material))
        sum += (w / total) * pdf_basic(c.material, wo_l, wi_l, inside);
    }
    return sum;
  }
  return std::visit(
      [&](const auto& k) -> float {
        if constexpr (is<Mixture, decltype(k)>) {
          return 0.0f;
        } else {
          return pdf_basic(BasicMaterial{k}, wo_l, wi_l, inside);
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
  if (const auto* coat = std::get_if<CoatedDiffuse>(&c); coat && !coat->all_specular())  // its own walk (trace/bsdf_layered.h)
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
    std::optional<kinds::LocalSample> other;  // the kinds in their own files
    if (const auto* g = std::get_if<Glossy>(&c)) {
      const glm::vec3 wm = glossy_ggx(*g).sample_visible_normal(wo_l, u);
      wi_l = 2.0f * glm::dot(wo_l, wm) * wm - wo_l;
      s.lobe = Lobe::kGlossyReflection;
    } else if (const auto* k = std::get_if<Conductor>(&c)) {
      other = kinds::conductor_sample(*k, wo_l, u);
    } else if (const auto* r = std::get_if<RoughDielectric>(&c)) {
      other = kinds::rough_dielectric_sample(*r, far_eta(r->ior, flip), wo_l, chosen->u, u);
      if (!other) return std::nullopt;
    } else if (const auto* t = std::get_if<DiffuseTransmission>(&c)) {
      other = kinds::diffuse_transmission_sample(*t, wo_l, chosen->u, u);
    } else {
      wi_l = sample_cosine_hemisphere(u);
      s.lobe = Lobe::kDiffuseReflection;
    }
    if (other) {
      wi_l = other->wi;
      s.lobe = other->lobe;
      s.eta = other->eta;
    }
    const bool transmits = s.lobe == Lobe::kGlossyTransmission || s.lobe == Lobe::kDiffuseTransmission;
    // Below the (micro)surface for a reflection, above it for a transmission: nothing passes.
    if (transmits ? !(wi_l.z < 0.0f) : !(wi_l.z > 0.0f)) return std::nullopt;
    if (flip) wi_l.z = -wi_l.z;
    s.wi = glm::normalize(frame.to_world(wi_l));
    s.f = eval(m, wo, s.wi, ns, ng, mode);
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
      bool inside = false;
      if (local_pair(wo, s.wi, ns, ng, &wo_l2, &wi_l2, &inside)) {
        const float total = total_weight(*mix);
        for (const auto& k : mix->components) {
          const float w = usable_weight(k.weight);
          if (w == 0.0f || is_delta_kind(k.material)) continue;
          if (std::holds_alternative<CoatedDiffuse>(k.material)) {
            coat = true;
            continue;
          }
          f_own += w * eval_basic(k.material, wo_l2, wi_l2, inside, mode);
          p_own += (w / total) * pdf_basic(k.material, wo_l2, wi_l2, inside);
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

double lobe_probability(const Material& m, const glm::vec3& wo, const glm::vec3& ns, Lobe lobe) {
  const auto* mix = std::get_if<Mixture>(&m);
  const int components = mix ? static_cast<int>(mix->components.size()) : 1;
  double p = 0.0;
  for (int i = 0; i < components; ++i) p += component_probability(m, wo, ns, i, lobe);
  return p;
}

glm::vec3 mirror_reflectance(const Mixture& mix) {
  glm::vec3 r(0.0f);
  for (const Mixture::Component& c : mix.components)
    if (const auto* mirror = std::get_if<Mirror>(&c.material); mirror && std::isfinite(c.weight) && c.weight > 0.0f)
      r += c.weight * mirror->reflectance;
  return r;
}

bool has_finite_component(const Material& m) {
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    for (const auto& c : mix->components)
      if (usable_weight(c.weight) > 0.0f && !is_delta_kind(c.material)) return true;
    return false;
  }
  return (letters_of(m) & (1u << kD)) != 0;
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
