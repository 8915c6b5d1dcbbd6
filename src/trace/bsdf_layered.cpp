// The layered coateddiffuse BSDF (see bsdf_layered.h). Layout: the walk's random numbers, the
// three scatterers it meets (the coat, the Lambertian base, the slab's Henyey–Greenstein medium),
// then the three estimators, which share one step structure: at depth d the walk (Russian roulette,
// then) crosses the slab or scatters inside it, then scatters at the interface it reached.
#include "trace/bsdf_layered.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "trace/bsdf.h"
#include "trace/bsdf_kinds.h"
#include "trace/frame.h"
#include "optics/fresnel.h"
#include "trace/microfacet.h"
#include "trace/rng.h"

namespace pathex::bsdf::layered {
namespace {

using glm::vec2;
using glm::vec3;

// --- the walk's random numbers: a counter-based stream (trace/rng.h) keyed by the arguments ---

class WalkRng {
 public:
  explicit WalkRng(std::uint64_t key) : key_(key) {}
  float next() { return std::min(bits_to_unit_float(stream_bits(key_, dim_++)), kOneMinusEpsilon); }
  vec2 next2() {
    const float a = next();
    return {a, next()};
  }

 private:
  std::uint64_t key_;
  std::uint64_t dim_ = 0;
};

std::uint64_t hash_floats(std::uint64_t h, std::initializer_list<float> values) {
  for (float v : values) h = mix64(h ^ (std::bit_cast<std::uint32_t>(v) + 0x452821e638d01377ULL));
  return h;
}

float max_component(const vec3& v) { return std::max({v.x, v.y, v.z}); }
bool is_black(const vec3& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

// pbrt's Russian roulette inside the walk: from depth 4 on, a walk whose weight is below 0.25
// survives with probability equal to its weight (q = 1 − max β). Returns the survival probability.
float survival(int depth, const vec3& beta) {
  const float b = max_component(beta);
  if (depth > 3 && b < 0.25f) return std::max(0.0f, b);
  return 1.0f;
}

// Transmittance of the slab (extinction 1) along w over a height dz.
float transmittance(float dz, const vec3& w) {
  if (std::abs(dz) <= std::numeric_limits<float>::min()) return 1.0f;
  return std::exp(-std::abs(dz / w.z));
}

float power_heuristic(float f, float g) {
  const float f2 = f * f, g2 = g * g;
  return f2 + g2 > 0.0f && std::isfinite(f2 + g2) ? f2 / (f2 + g2) : (std::isinf(f) ? 1.0f : 0.0f);
}

// --- the coat: a dielectric interface of index eta (inside / outside), smooth, or rough with
// either microfacet distribution ---
//
// A rough coat is bsdf_dielectric.cpp's interface (pbrt-v4's DielectricBxDF, Walter et al. 2007,
// visible-normal sampling), the one copy RoughDielectric uses too, with its lobes restricted as the
// walk asks: both, or only reflection, or only transmission. That interface wants wo above it; a
// direction below the coat (inside the slab) is handled by mirroring both directions through the
// coat's plane, with the index inverted (a reflection of space keeps every dot product).

using Lobes = kinds::InterfaceLobes;

struct Coat {
  float eta;
  Microfacet mf;  // of a rough coat
  bool smooth;
};

Coat coat_of(const CoatedDiffuse& m) {
  const bool smooth = m.smooth() || !std::isfinite(m.roughness);
  return {m.eta, kinds::clamped_microfacet(m.distribution, m.roughness, m.roughness), smooth};
}

vec3 mirrored(const vec3& w) { return {w.x, w.y, -w.z}; }

struct CoatSample {
  vec3 wi;
  float f;       // the BSDF value (a delta's weight R / |cos| or T / |cos|)
  float pdf;     // density (or a delta's probability) under the requested lobes
  float choice;  // the probability that sampling both lobes picks this one, at the same microfacet
  bool reflect;
};

std::optional<CoatSample> coat_sample(const Coat& c, const vec3& wo, float uc, vec2 u, Lobes lobes,
                                      TransportMode mode) {
  if (wo.z == 0.0f) return std::nullopt;
  if (c.smooth) {
    const float r = fresnel_dielectric(wo.z, c.eta);
    const float pr = lobes == Lobes::kTransmission ? 0.0f : r;
    const float pt = lobes == Lobes::kReflection ? 0.0f : 1.0f - r;
    if (!(pr + pt > 0.0f)) return std::nullopt;
    if (uc < pr / (pr + pt)) {
      const vec3 wi(-wo.x, -wo.y, wo.z);
      return CoatSample{wi, r / std::abs(wi.z), pr / (pr + pt), r, true};
    }
    vec3 wi;
    float etap;
    if (!refract(wo, vec3(0.0f, 0.0f, 1.0f), c.eta, &etap, &wi) || wi.z == 0.0f) return std::nullopt;
    float ft = (1.0f - r) / std::abs(wi.z);
    if (mode == TransportMode::kRadiance) ft /= etap * etap;
    return CoatSample{wi, ft, pt / (pr + pt), 1.0f - r, false};
  }
  const bool below = wo.z < 0.0f;
  const vec3 wo_up = below ? mirrored(wo) : wo;
  const float eta = below ? 1.0f / c.eta : c.eta;
  const std::optional<kinds::InterfaceSample> s = kinds::rough_interface_sample(c.mf, eta, wo_up, uc, u, lobes);
  if (!s || (s->reflect ? !(s->wi.z > 0.0f) : !(s->wi.z < 0.0f))) return std::nullopt;  // below the microsurface
  const float f = kinds::rough_interface_f(c.mf, eta, wo_up, s->wi, mode);
  const float pdf = kinds::rough_interface_pdf(c.mf, eta, wo_up, s->wi, lobes);
  return CoatSample{below ? mirrored(s->wi) : s->wi, f, pdf, s->choice, s->reflect};
}

float coat_f(const Coat& c, const vec3& wo, const vec3& wi, TransportMode mode) {
  if (c.smooth || wo.z == 0.0f) return 0.0f;
  if (wo.z < 0.0f) return kinds::rough_interface_f(c.mf, 1.0f / c.eta, mirrored(wo), mirrored(wi), mode);
  return kinds::rough_interface_f(c.mf, c.eta, wo, wi, mode);
}

float coat_pdf(const Coat& c, const vec3& wo, const vec3& wi, Lobes lobes) {
  if (c.smooth || wo.z == 0.0f) return 0.0f;
  if (wo.z < 0.0f) return kinds::rough_interface_pdf(c.mf, 1.0f / c.eta, mirrored(wo), mirrored(wi), lobes);
  return kinds::rough_interface_pdf(c.mf, c.eta, wo, wi, lobes);
}

// --- the slab's medium: Henyey–Greenstein, pbrt's convention p(wo, wi) = HG(wo·wi) with wo
// pointing back along the path, so that g > 0 scatters forwards ---

float hg(float cos_wo_wi, float g) {
  const float denom = 1.0f + g * g + 2.0f * g * cos_wo_wi;
  return (1.0f - g * g) / (4.0f * kPi * denom * safe_sqrt(denom));
}

// A direction with density hg(wo·wi, g) (which is also its value).
vec3 hg_sample(const vec3& wo, float g, vec2 u) {
  float cos_t;  // cosine between the propagation direction −wo and wi
  if (std::abs(g) < 1e-3f) {
    cos_t = 1.0f - 2.0f * u.x;
  } else {
    const float s = (1.0f - g * g) / (1.0f - g + 2.0f * g * u.x);
    cos_t = std::clamp((1.0f + g * g - s * s) / (2.0f * g), -1.0f, 1.0f);
  }
  const float sin_t = safe_sqrt(1.0f - cos_t * cos_t);
  const float phi = 2.0f * kPi * u.y;
  const Frame frame = Frame::from_normal(-wo);
  return glm::normalize(frame.to_world(vec3(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t)));
}

// --- the base: pbrt-v4's DiffuseBxDF (coateddiffuse) or ConductorBxDF (coatedconductor), met
// from above (wo.z > 0), reflection only ---

bool base_specular(const CoatedDiffuse& m) { return m.base == CoatBase::kConductor && m.conductor.smooth(); }

vec3 base_f(const CoatedDiffuse& m, const vec3& wo, const vec3& wi) {
  if (m.base == CoatBase::kConductor) return kinds::conductor_eval(m.conductor, wo, wi);
  return wi.z > 0.0f ? m.reflectance * kInvPi : vec3(0.0f);
}

float base_pdf(const CoatedDiffuse& m, const vec3& wo, const vec3& wi) {
  if (m.base == CoatBase::kConductor) return kinds::conductor_pdf(m.conductor, wo, wi);
  return cosine_hemisphere_pdf(wi.z);
}

struct BaseSample {
  vec3 wi;
  vec3 weight;  // f·cos/pdf (a smooth conductor's: its Fresnel reflectance)
  float pdf;    // 0 for the smooth conductor's delta
};

std::optional<BaseSample> base_sample(const CoatedDiffuse& m, const vec3& wo, vec2 u) {
  if (m.base == CoatBase::kDiffuse) {
    if (is_black(m.reflectance)) return std::nullopt;
    const vec3 wi = sample_cosine_hemisphere(u);
    if (!(wi.z > 0.0f)) return std::nullopt;
    return BaseSample{wi, m.reflectance, cosine_hemisphere_pdf(wi.z)};
  }
  if (m.conductor.smooth()) {
    const vec3 weight = kinds::conductor_reflectance(m.conductor, wo.z);
    if (is_black(weight)) return std::nullopt;
    return BaseSample{vec3(-wo.x, -wo.y, wo.z), weight, 0.0f};
  }
  const std::optional<kinds::LocalSample> ls = kinds::conductor_sample(m.conductor, wo, u);
  if (!ls || !(ls->wi.z > 0.0f)) return std::nullopt;
  const float pdf = kinds::conductor_pdf(m.conductor, wo, ls->wi);
  const vec3 weight = kinds::conductor_eval(m.conductor, wo, ls->wi) * (ls->wi.z / pdf);
  if (!(pdf > 0.0f) || is_black(weight) || !std::isfinite(weight.x + weight.y + weight.z)) return std::nullopt;
  return BaseSample{ls->wi, weight, pdf};
}

// --- the walk's state between steps ---

struct Slab {
  explicit Slab(const CoatedDiffuse& m)
      : coat(coat_of(m)),
        // pbrt keeps the slab at least the smallest normal float thick.
        thickness(std::max(m.thickness, std::numeric_limits<float>::min())),
        scatters(!is_black(m.albedo)) {}
  Coat coat;
  float thickness;
  bool scatters;  // a medium that scatters (albedo > 0); otherwise the slab only attenuates
};

// One crossing or medium event of the walk at depth d, from height z along w. Returns false when
// the walk stops (pbrt's zp == z). Sets *inside for a scattering event at *z_next.
bool advance(const Slab& slab, float z, const vec3& w, WalkRng& rng, float* z_next, bool* inside) {
  *inside = false;
  if (!slab.scatters) {
    *z_next = z == slab.thickness ? 0.0f : slab.thickness;
    return true;
  }
  const float dz = -std::log1p(-rng.next()) * std::abs(w.z);  // exponential, rate 1 / |cos θ|
  const float zp = w.z > 0.0f ? z + dz : z - dz;
  if (zp == z) return false;
  if (0.0f < zp && zp < slab.thickness) {
    *z_next = zp;
    *inside = true;
    return true;
  }
  *z_next = std::clamp(zp, 0.0f, slab.thickness);
  return true;
}

}  // namespace

std::uint64_t key_of(const vec3& wo, const vec3& wi, std::uint64_t salt) {
  return hash_floats(mix64(salt + 0x3c6ef372fe94f82bULL), {wo.x, wo.y, wo.z, wi.x, wi.y, wi.z});
}

float specular_probability(const CoatedDiffuse& m, float cos_o) {
  if (m.all_specular()) return 1.0f;
  return m.smooth() ? fresnel_dielectric(std::abs(cos_o), m.eta) : 0.0f;
}

// What sample()'s walk returns in expectation for a smooth coat over a smooth conductor in a
// layer that does not scatter: the coat reflects R; the rest enters (weight 1/η² in radiance),
// crosses the layer (τ = e^(−thickness/μt) each way) to the conductor (Fc at the refracted
// cosine μt), and at the coat from inside leaves with 1 − R (weight η²) or returns with R
// (no total internal reflection: the angle came from outside). The k-th way out costs 2k steps,
// so at most K = ⌊max_depth / 2⌋ are taken:
//   A = R + (1 − R)² τ² Fc Σ_{j<K} (R τ² Fc)^j.
vec3 specular_reflectance(const CoatedDiffuse& m, float cos_o) {
  const float mu = std::abs(cos_o);
  const float r = fresnel_dielectric(mu, m.eta);
  const float sin2_t = (1.0f - mu * mu) / (m.eta * m.eta);
  const float mu_t = safe_sqrt(1.0f - sin2_t);
  const float tau = transmittance(std::max(m.thickness, std::numeric_limits<float>::min()), vec3(0.0f, 0.0f, mu_t));
  const vec3 trip = tau * tau * kinds::conductor_reflectance(m.conductor, mu_t);
  const int k = m.max_depth / 2;
  vec3 sum(0.0f), term(1.0f);
  for (int j = 0; j < k; ++j) {  // Σ_{j<K} q^j, stopped once the terms no longer change it
    sum += term;
    term *= r * trip;
    if (std::max({term.x, term.y, term.z}) < 1e-9f) break;
  }
  return r + (1.0f - r) * (1.0f - r) * trip * sum;
}

// --- sample(): pbrt's LayeredBxDF::Sample_f, the walk's weight as one product ---

std::optional<Sample> sample(const CoatedDiffuse& m, const vec3& wo, float uc, vec2 u) {
  const Slab slab(m);
  const std::optional<CoatSample> entry = coat_sample(slab.coat, wo, uc, u, Lobes::kAll, TransportMode::kRadiance);
  if (!entry || !(entry->f > 0.0f) || !(entry->pdf > 0.0f) || entry->wi.z == 0.0f) return std::nullopt;
  if (entry->reflect) return Sample{entry->wi, vec3(entry->f * std::abs(entry->wi.z) / entry->pdf), slab.coat.smooth, true};

  WalkRng rng(hash_floats(mix64(0x13198a2e03707344ULL), {wo.x, wo.y, wo.z, uc, u.x, u.y}));
  vec3 beta(entry->f * std::abs(entry->wi.z) / entry->pdf);
  vec3 w = entry->wi;
  float z = slab.thickness;
  for (int depth = 0; depth < m.max_depth; ++depth) {
    // --- Russian roulette, then cross the slab or scatter in it ---
    if (const float s = survival(depth, beta); s < 1.0f) {
      if (!(rng.next() < s)) return std::nullopt;
      beta /= s;
    }
    if (w.z == 0.0f) return std::nullopt;
    bool inside;
    float zp;
    if (!advance(slab, z, w, rng, &zp, &inside)) return std::nullopt;
    if (!slab.scatters) beta *= transmittance(slab.thickness, w);
    z = zp;
    if (inside) {
      const vec3 wn = hg_sample(-w, m.g, rng.next2());
      if (wn.z == 0.0f) return std::nullopt;
      beta *= m.albedo;  // phase value / density = 1
      w = wn;
      continue;
    }
    // --- scatter at the interface reached ---
    if (z == 0.0f) {  // the base, seen from above (w going down)
      const std::optional<BaseSample> b = base_sample(m, -w, rng.next2());
      if (!b) return std::nullopt;
      beta *= b->weight;
      w = b->wi;
      continue;
    }
    const float uc2 = rng.next();
    const std::optional<CoatSample> bs = coat_sample(slab.coat, -w, uc2, rng.next2(), Lobes::kAll, TransportMode::kRadiance);
    if (!bs || !(bs->f > 0.0f) || !(bs->pdf > 0.0f) || bs->wi.z == 0.0f) return std::nullopt;
    beta *= bs->f * std::abs(bs->wi.z) / bs->pdf;
    w = bs->wi;
    if (!bs->reflect) {  // out through the coat
      if (!(w.z > 0.0f)) return std::nullopt;
      return Sample{w, beta, false, false};
    }
  }
  return std::nullopt;
}

// --- eval(): pbrt's LayeredBxDF::f for a reflection (the exit is the coat) ---

vec3 eval_estimate(const CoatedDiffuse& m, const vec3& wo, const vec3& wi, std::uint64_t key) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f) || m.all_specular()) return vec3(0.0f);
  const Slab slab(m);
  const Coat& coat = slab.coat;
  const int samples = std::max(m.samples, 1);
  vec3 f(static_cast<float>(samples) * coat_f(coat, wo, wi, TransportMode::kRadiance));  // the coat's own reflection
  WalkRng rng(key);
  for (int s = 0; s < samples; ++s) {
    const float uo = rng.next();
    const std::optional<CoatSample> wos = coat_sample(coat, wo, uo, rng.next2(), Lobes::kTransmission, TransportMode::kRadiance);
    if (!wos || !(wos->f > 0.0f) || !(wos->pdf > 0.0f) || wos->wi.z == 0.0f) continue;
    // The "light" direction: wi carried into the slab by the coat (the adjoint transport).
    const float ui = rng.next();
    const std::optional<CoatSample> wis = coat_sample(coat, wi, ui, rng.next2(), Lobes::kTransmission, TransportMode::kImportance);
    if (!wis || !(wis->f > 0.0f) || !(wis->pdf > 0.0f) || wis->wi.z == 0.0f) continue;
    const float wis_weight = wis->f / wis->pdf;

    vec3 beta(wos->f * std::abs(wos->wi.z) / wos->pdf);
    float z = slab.thickness;
    vec3 w = wos->wi;
    for (int depth = 0; depth < m.max_depth; ++depth) {
      if (const float q = 1.0f - survival(depth, beta); q > 0.0f) {
        if (rng.next() < q) break;
        beta /= 1.0f - q;
      }
      bool inside;
      float zp;
      if (w.z == 0.0f || !advance(slab, z, w, rng, &zp, &inside)) break;
      if (!slab.scatters) beta *= transmittance(slab.thickness, w);
      if (inside) {
        // --- medium scattering: connect to wis, then continue the walk ---
        float wt = 1.0f;
        if (!coat.smooth) wt = power_heuristic(wis->pdf, hg(glm::dot(-w, -wis->wi), m.g));
        f += beta * m.albedo * hg(glm::dot(-w, -wis->wi), m.g) * wt * transmittance(zp - slab.thickness, wis->wi) * wis_weight;
        const vec3 wn = hg_sample(-w, m.g, rng.next2());
        if (wn.z == 0.0f) break;
        const float p_phase = hg(glm::dot(-w, wn), m.g);
        beta *= m.albedo;
        w = wn;
        z = zp;
        if (!coat.smooth && w.z > 0.0f) {  // the walk's own way out through the rough coat
          const float f_exit = coat_f(coat, -w, wi, TransportMode::kRadiance);
          if (f_exit > 0.0f) {
            const float wt2 = power_heuristic(p_phase, coat_pdf(coat, wi, -w, Lobes::kTransmission));
            f += beta * transmittance(z - slab.thickness, w) * f_exit * wt2;
          }
        }
        continue;
      }
      z = zp;
      if (z == slab.thickness) {
        // --- the coat from inside: reflect back into the slab ---
        const float uc = rng.next();
        const std::optional<CoatSample> bs = coat_sample(coat, -w, uc, rng.next2(), Lobes::kReflection, TransportMode::kRadiance);
        if (!bs || !(bs->f > 0.0f) || !(bs->pdf > 0.0f) || bs->wi.z == 0.0f) break;
        beta *= bs->f * std::abs(bs->wi.z) / bs->pdf;
        w = bs->wi;
        continue;
      }
      // --- the base: connect to wis (next-event; not to a smooth conductor's delta), then sample it ---
      if (!base_specular(m)) {
        const vec3 to_light = -wis->wi;  // z > 0
        float wt = 1.0f;
        if (!coat.smooth) wt = power_heuristic(wis->pdf, base_pdf(m, -w, to_light));
        // (A Lambertian base's value in the order of operations it always had: its renders stay bit for bit.)
        const vec3 beta_f = m.base == CoatBase::kDiffuse ? beta * m.reflectance * kInvPi : beta * base_f(m, -w, to_light);
        f += beta_f * std::abs(wis->wi.z) * wt * transmittance(slab.thickness, wis->wi) * wis_weight;
      }
      const std::optional<BaseSample> b = base_sample(m, -w, rng.next2());
      if (!b) break;
      beta *= b->weight;
      w = b->wi;
      if (!coat.smooth) {  // the walk's own way out through the rough coat
        const float f_exit = coat_f(coat, -w, wi, TransportMode::kRadiance);
        if (f_exit > 0.0f) {
          const float wt2 = base_specular(m) ? 1.0f : power_heuristic(b->pdf, coat_pdf(coat, wi, -w, Lobes::kTransmission));
          f += beta * transmittance(slab.thickness, w) * f_exit * wt2;
        }
      }
    }
  }
  return f / static_cast<float>(samples);
}

// --- pdf(): the density of sample()'s walk, estimated along that walk ---
//
// The walk below draws what sample() draws, with two changes that keep the estimate unbiased and
// lower its variance: wherever sample() would choose between leaving through the coat and staying
// (the first crossing of the coat, each later hit of the coat from inside), it always stays and
// multiplies the walk's probability `alive` by the probability of that choice; and Russian
// roulette multiplies `alive` by the survival probability instead of drawing. At every step from
// which sample() could leave towards wi, the density of doing so is added, times `alive`:
// - a rough coat: at each hit of the coat from inside along w, the coat's density of refracting
//   -w into wi (both lobes: the choice of refraction included);
// - a smooth coat: the only way out towards wi is the upward direction u that the coat refracts
//   into wi. At each scattering event (the base, or the medium) that could send the walk up along
//   u, add that event's density of u, the probability that the next step reaches the coat (no
//   collision on the way, Russian roulette at the next depth, which has to be below max_depth) and
//   the coat's transmittance, times the Jacobian dω_u/dω_wi = |cos θi| / (η² |cos θu|).

float pdf_estimate(const CoatedDiffuse& m, const vec3& wo, const vec3& wi, std::uint64_t key) {
  if (!(wo.z > 0.0f) || !(wi.z > 0.0f) || m.all_specular()) return 0.0f;
  const Slab slab(m);
  const Coat& coat = slab.coat;
  const int samples = std::max(m.samples, 1);
  // The smooth coat's way out towards wi.
  vec3 up(0.0f);
  float exit_factor = 0.0f;  // transmittance times the Jacobian
  if (coat.smooth) {
    vec3 down;
    float etap;
    if (refract(wi, vec3(0.0f, 0.0f, 1.0f), coat.eta, &etap, &down) && down.z < 0.0f) {
      up = glm::normalize(-down);
      exit_factor = (1.0f - fresnel_dielectric(wi.z, coat.eta)) * wi.z / (etap * etap * up.z);
    }
  }
  // Adds the density of leaving along `up` from an event at height z whose density of `up` is p_up,
  // the walk's weight becoming beta_next, at depth `depth`.
  double sum = 0.0;
  const auto leave_smooth = [&](int depth, float alive, float p_up, float z, const vec3& beta_next) {
    if (exit_factor == 0.0f || depth + 1 >= m.max_depth || !(p_up > 0.0f)) return;
    const float reach = slab.scatters ? transmittance(slab.thickness - z, up) : 1.0f;
    sum += static_cast<double>(alive) * p_up * reach * survival(depth + 1, beta_next) * exit_factor;
  };

  WalkRng rng(key);
  for (int s = 0; s < samples; ++s) {
    const float uo = rng.next();
    const std::optional<CoatSample> entry = coat_sample(coat, wo, uo, rng.next2(), Lobes::kTransmission, TransportMode::kRadiance);
    if (!entry || !(entry->f > 0.0f) || !(entry->pdf > 0.0f) || entry->wi.z == 0.0f || !(entry->choice > 0.0f)) continue;
    float alive = entry->choice;
    vec3 beta(entry->f * std::abs(entry->wi.z) / (entry->pdf * entry->choice));  // sample()'s weight
    vec3 w = entry->wi;
    float z = slab.thickness;
    for (int depth = 0; depth < m.max_depth; ++depth) {
      if (const float surv = survival(depth, beta); surv < 1.0f) {
        alive *= surv;
        if (!(alive > 0.0f)) break;
        beta /= surv;
      }
      bool inside;
      float zp;
      if (w.z == 0.0f || !advance(slab, z, w, rng, &zp, &inside)) break;
      if (!slab.scatters) beta *= transmittance(slab.thickness, w);
      z = zp;
      if (inside) {
        leave_smooth(depth, alive, hg(glm::dot(-w, up), m.g), z, beta * m.albedo);
        const vec3 wn = hg_sample(-w, m.g, rng.next2());
        if (wn.z == 0.0f) break;
        beta *= m.albedo;
        w = wn;
        continue;
      }
      if (z == 0.0f) {  // the base
        if (m.base == CoatBase::kDiffuse && is_black(m.reflectance)) break;
        if (exit_factor > 0.0f && !base_specular(m)) {  // its density of `up`, and the weight it would carry there
          const float p_up = base_pdf(m, -w, up);
          if (p_up > 0.0f)
            leave_smooth(depth, alive, p_up, z, m.base == CoatBase::kDiffuse ? beta * m.reflectance : beta * base_f(m, -w, up) * (up.z / p_up));
        }
        const std::optional<BaseSample> b = base_sample(m, -w, rng.next2());
        if (!b) break;
        beta *= b->weight;
        w = b->wi;
        continue;
      }
      // The coat from inside: leave towards wi (a rough coat), or stay.
      if (!coat.smooth) sum += static_cast<double>(alive) * coat_pdf(coat, -w, wi, Lobes::kAll);
      const float uc = rng.next();
      const std::optional<CoatSample> bs = coat_sample(coat, -w, uc, rng.next2(), Lobes::kReflection, TransportMode::kRadiance);
      if (!bs || !(bs->f > 0.0f) || !(bs->pdf > 0.0f) || bs->wi.z == 0.0f || !(bs->choice > 0.0f)) break;
      alive *= bs->choice;
      beta *= bs->f * std::abs(bs->wi.z) / (bs->pdf * bs->choice);
      w = bs->wi;
    }
  }
  const float walk = static_cast<float>(sum / samples);
  const float p = coat_pdf(coat, wo, wi, Lobes::kAll) + walk;  // the coat's own reflection, then the walk
  return std::isfinite(p) ? std::max(p, kPdfFloor) : kPdfFloor;
}

// --- sample() in world space, as bsdf::sample() returns it ---

std::optional<BsdfSample> sample_world(const Material& whole, const CoatedDiffuse& m, int component,
                                       float probability, float weight, const vec3& wo, const vec3& ns,
                                       const vec3& ng, float uc, vec2 u) {
  const Frame frame = Frame::from_normal(ns);
  vec3 wo_l = frame.to_local(wo);
  const bool flip = wo_l.z < 0.0f;  // two-sided: the walk runs on wo's side
  if (flip) wo_l.z = -wo_l.z;
  if (!(wo_l.z > 0.0f)) return std::nullopt;
  const std::optional<Sample> ls = sample(m, wo_l, uc, u);
  if (!ls) return std::nullopt;
  vec3 wi_l = ls->wi;
  if (flip) wi_l.z = -wi_l.z;
  BsdfSample s;
  s.component = component;
  s.wi = glm::normalize(frame.to_world(wi_l));
  if (!(glm::dot(s.wi, ng) * glm::dot(wo, ng) > 0.0f)) return std::nullopt;  // leaks through ng
  const float abs_cos_i = std::abs(glm::dot(s.wi, ns));
  if (!(abs_cos_i > 0.0f)) return std::nullopt;
  if (ls->specular) {
    const float prob = specular_probability(m, wo_l.z);
    if (!(prob > 0.0f)) return std::nullopt;
    s.pdf = probability * prob;
    s.pdf_rev = probability * specular_probability(m, abs_cos_i);
    s.f = vec3(weight * prob / abs_cos_i);  // the Dirac's weight R / |cos θi|
    s.weight = vec3(weight / probability);  // R / R = 1 for the coat alone
    s.letter = kS;
    s.is_delta = true;
    s.lobe = Lobe::kSpecularReflection;
    return s;
  }
  s.f = bsdf::eval(whole, wo, s.wi, ns, ng);
  s.pdf = bsdf::pdf(whole, wo, s.wi, ns, ng);
  s.pdf_rev = bsdf::pdf(whole, s.wi, wo, ns, ng);
  s.weight = ls->weight * (weight / probability);
  s.letter = kD;
  s.is_delta = false;
  s.lobe = ls->coat ? Lobe::kGlossyReflection : Lobe::kDiffuseReflection;
  const bool finite = std::isfinite(s.weight.x + s.weight.y + s.weight.z) && std::isfinite(s.f.x + s.f.y + s.f.z);
  if (!(s.pdf > 0.0f) || is_black(s.weight) || !finite) return std::nullopt;
  return s;
}

}  // namespace pathex::bsdf::layered
