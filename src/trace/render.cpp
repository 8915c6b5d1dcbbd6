// Bidirectional path sampling with full-path labels.
//
// For each pixel and pass: an eye subpath z0 z1 … from the sensor and a light subpath y0 y1 …
// from a light, each extended by local sampling (BSDF sampling, Russian roulette from
// RenderOptions::rr_depth vertices on, below rr_threshold; at most max_bounces interior vertices
// on the full path).
// Then every (s, t) pair the profile runs is evaluated: s = 0 an eye vertex on an area light,
// s = 1 a fresh light sample (next-event estimation), t = 1 a fresh sensor sample (a splat), t = 0
// a light vertex on a thin lens, otherwise a shadow ray between y(s-1) and z(t-1).
//
// Labels: each vertex keeps the letter of the scattering event sampled there (the component a
// BSDF chose; a light's and a sensor's two letters). The full-path string of a connection is
// those letters in light-to-eye order with the two join letters set to D (a join evaluates only
// finite parts). A strategy (s', t') has nonzero density for that string exactly when the
// profile runs it and the string's letters c(s') and c(s'+1) are both D; the power heuristic
// sums over those strategies only, using the pdf-ratio recurrence of pbrt's BDPT with Dirac
// densities kept symbolic (stored as 0, remapped to 1, and their strategies excluded by letter).
#include "trace/render.h"

#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <array>
#include <bit>
#include <chrono>
#include <cmath>

#include "trace/accel/path_ids.h"
#include "trace/bsdf.h"
#include "trace/frame.h"
#include "trace/integrator.h"
#include "trace/prune.h"
#include "trace/render_scene.h"
#include "trace/rng.h"
#include "trace/strategy_table.h"

namespace pathex {

// --- strategies the tracer runs ---

Result<StrategySet> runnable_strategies(const Profile& profile) {
  StrategySet set;
  for (const Strategy& st : profile.strategies) {
    // The manifold connector's seed leaves a surface vertex of the eye subpath (trace/joins/manifold.h).
    if (st.connector == ConnectorKind::kManifold && st.t.contains(1))
      return make_error(ErrorCode::kUsage, "renderer '" + profile.name + "' runs the manifold connector with t = 1 (strategy '" +
                                               st.name + "'), which the tracer does not run: its eye end must be a surface "
                                               "vertex of the eye subpath, t >= 2");
    set.strategies.push_back(st);
  }
  return set;
}

namespace tracer {
namespace {
// Passes go to batches round-robin: every batch covers the whole image, and an interrupted render
// still spreads what it has over all batches (so its error is defined). Batches are independent:
// under `sobol` each is a sequence scrambled on its own (trace/rng.h, sobol_stream()).
// Paths a thread's histogram has room for before it first regrows (address space only).
constexpr std::size_t kReservedPaths = std::size_t{1} << 14;

int batch_of(std::uint64_t pass, int batches) { return static_cast<int>(pass % static_cast<std::uint64_t>(batches)); }

// Random-number dimensions (trace/rng.h): each stage of a sample draws from its own block, so that
// adding a strategy leaves every other strategy's numbers unchanged. The eye and the light subpath
// draw at most 4 + 4 per vertex; each connection (kind, subpath length) then draws at most 4.
constexpr std::uint64_t kEyeDims = 0;
constexpr std::uint64_t kLightDims = 1024;
constexpr std::uint64_t kJoinDims = 2048;
// The light subpath's first direction, after the light's pick (1) and point (2).
constexpr std::uint64_t kLightRayDim = kLightDims + 3;
constexpr std::uint64_t kDimsPerJoin = 4;
static_assert(4 + 4 * 64 <= kLightDims - kEyeDims, "a subpath's numbers fit its block");

float max_component(const vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }
bool is_black(const vec3& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

}  // namespace

template <TransportMode mode>
int Integrator::random_walk(Thread& th, Sampler& rng, std::array<Vertex, kMaxVertices>& path, int count, vec3 o, vec3 d,
                            float pdf_dir, int max_vertices) const {
  vec3 beta = path[static_cast<std::size_t>(count - 1)].beta;
  // Russian roulette compares the throughput with the subpath's start, so that a light subpath
  // (whose throughput starts at the light's power) is treated like an eye subpath.
  const float beta_start = std::max(max_component(beta), 1e-30f);
  float eta2 = 1.0f;  // the product of η² over the refractions so far (radiance walks)
  // `beta` passed in the first vertex already includes the first direction's weight: the caller
  // stores it in path[count - 1].beta and we continue from there.
  SubpathPrefix live(o_.only, mode == TransportMode::kImportance, path[0].pos_letter, path[0].letter);  // trace/prune.h
  while (count < max_vertices && live.alive()) {
    Vertex& prev = path[static_cast<std::size_t>(count - 1)];
    ++th.rays;
    // The direction numbers of the vertex this ray finds (dimensions 1 and 2 of its block), drawn
    // before the ray is traced: they do not depend on the hit, and so their computation overlaps
    // the intersection instead of delaying the scattering (Sampler::at2d_now).
    const glm::vec2 u_dir = rng.at2d_now(rng.dimension() + 1);
    const std::optional<Hit> hit = rs_.geometry->intersect(o, d, prev.n, prev.err, HitDetail::kNoUv);  // zero for points: no offset
    // --- a light subpath may end on the lens (strategy t = 0) ---
    if (mode == TransportMode::kImportance && lens_hits_) {
      const std::optional<EndpointConnection> lens = hit_lens(cam_.params, o, d);
      if (lens && (!hit || lens->distance < hit->t)) {
        Vertex& v = path[static_cast<std::size_t>(count)];
        v = Vertex{};
        v.kind = Kind::kLens;
        v.p = lens->position;
        v.n = lens->normal;
        v.ns = lens->normal;
        v.beta = beta;
        link(v, prev);
        v.pdf_fwd = v.d2_wo > 0.0f ? pdf_dir * std::fabs(glm::dot(v.n, d)) / v.d2_wo : 0.0f;
        v.letter = 'D';
        v.pos_letter = 'D';
        return count + 1;
      }
    }
    if (!hit) break;
    Vertex& v = path[static_cast<std::size_t>(count)];
    v = Vertex{};
    v.kind = Kind::kSurface;
    v.p = hit->position;
    v.n = hit->normal;
    v.err = hit->error;
    v.ns = hit->shading_normal;
    v.shape = hit->shape;
    v.finite = finite_of_shape_[static_cast<std::size_t>(v.shape)] != 0;
    v.wo = -d;
    const vec3 e = v.p - prev.p;
    v.d2_wo = glm::dot(e, e);
    v.beta = beta;
    // Solid angle at prev to area at v, along the unit ray direction d.
    // 0 for coincident points (and a subnormal distance, whose inverse would overflow): no density.
    const float inv_d2 = v.d2_wo >= std::numeric_limits<float>::min() ? 1.0f / v.d2_wo : 0.0f;
    const float to_area_v = std::fabs(glm::dot(v.n, d)) * inv_d2;
    v.pdf_fwd = pdf_dir * to_area_v;
    ++count;
    if (count >= max_vertices) break;
    // --- scatter ---
    const Material& m = *rs_.material_of_shape[static_cast<std::size_t>(v.shape)];
    const vec3 wo = -d;
    const bsdf::NumbersRead reads = bsdf::numbers_read(m);  // the others are not computed
    const float u_comp = rng.get1d_if(reads.component);
    const glm::vec2 u = reads.direction ? u_dir : glm::vec2(0.0f);
    rng.skip(2);
    const std::optional<BsdfSample> bs = bsdf::sample(m, wo, v.ns, v.n, u_comp, u, mode);
    if (!bs || is_black(bs->weight) || bs->pdf <= 0.0f) break;
    v.letter = letter_char(bs->letter);
    beta *= bs->weight * bsdf::shading_normal_correction(wo, bs->wi, v.ns, v.n, mode);
    // A Dirac's densities stay symbolic: 0 here, remapped to 1 in the MIS ratios, and every
    // strategy that would join at this vertex is excluded by its letter S.
    // (Without a specular material no lobe is a Dirac: the test is skipped.)
    const bool delta = features_.specular && bs->is_delta;
    pdf_dir = delta ? 0.0f : bs->pdf;
    const float pdf_rev_dir = delta ? 0.0f : bs->pdf_rev;
    prev.pdf_rev = pdf_rev_dir * abs_cos(prev, d) * inv_d2;
    // --- Russian roulette, never mislabelling: the vertices so far stay valid prefixes ---
    // From vertex rr_depth on, a walk whose throughput relative to its start (a refraction's
    // radiance scaling 1/η² undone, so that entering glass is no loss) is below rr_threshold
    // survives with probability throughput / threshold, and a survivor carries the threshold.
    if (mode == TransportMode::kRadiance && features_.transmission) eta2 *= bs->eta * bs->eta;  // else η = 1
    if (count >= o_.rr_depth && o_.rr_threshold > 0.0f) {
      const float survive = max_component(beta) * eta2 / (beta_start * o_.rr_threshold);
      const float u_rr = rng.get1d_if(survive < 1.0f);  // its dimension taken at every vertex, so the dimensions stay aligned
      if (survive < 1.0f) {
        if (u_rr >= survive) break;
        beta *= 1.0f / survive;
      }
    }
    o = v.p;
    d = bs->wi;
    if (!std::isfinite(beta.x + beta.y + beta.z)) break;
    live.extend(v.letter);  // --only: a subpath no requested class can complete stops (DESIGN §11)
  }
  return count;
}

int Integrator::eye_subpath(Thread& th, Sampler& rng, int px, int py) const {
  Vertex& z0 = th.eye[0];
  z0 = Vertex{};
  z0.kind = Kind::kCamera;
  z0.beta = vec3(1.0f);
  z0.letter = sensor_pair_[0];
  z0.pos_letter = sensor_pair_[1];
  const glm::vec2 uf = rng.get2d();
  const glm::vec2 ul = rng.get2d_if(reads_lens_numbers(cam_.params));
  const glm::vec2 raster{(static_cast<float>(px) + uf.x) / static_cast<float>(cam_.width),
                         (static_cast<float>(py) + uf.y) / static_cast<float>(cam_.height)};
  const std::optional<EndpointRay> r = sample_ray(cam_.params, raster, ul);
  z0.pdf_fwd = cam_.pdf_pos;
  if (!r) return 1;
  z0.p = r->origin;
  z0.n = r->pdf.delta_pos ? vec3(0.0f) : r->normal;  // a point sensor has no surface
  z0.ns = z0.n;
  // Importance over the sampling density is 1 for every sensor: pixel values are radiance.
  const int n = random_walk<TransportMode::kRadiance>(th, rng, th.eye, 1, r->origin, r->direction,
                                                      finite_part(r->pdf.dir, r->pdf.delta_dir), max_eye_);
  // An orthographic sensor's rays are a parallel beam (see light_subpath()).
  if (n >= 2 && r->pdf.delta_dir && !r->pdf.delta_pos) th.eye[1].pdf_fwd = parallel_jacobian(th.eye[1], z0, r->direction);
  return n;
}

int Integrator::light_subpath(Thread& th, Sampler& rng, glm::vec2 u_ray) const {
  if (rs_.lights.empty() || max_light_ == 0) return 0;
  const std::size_t li = pick_light(rng);
  const RenderLight& l = rs_.lights[li];
  Vertex& y0 = th.light[0];
  y0 = Vertex{};
  y0.kind = Kind::kLight;
  y0.light = static_cast<int>(li);
  y0.pos_letter = light_pairs_[li][0];
  y0.letter = light_pairs_[li][1];
  const SurfacePoint x = sample_point(l, rng, &y0.err);
  rng.skip(2);  // u_ray, drawn in advance
  std::optional<EndpointRay> r = sample_ray(l.params, x, u_ray);
  if (const std::optional<EmissionCones>& cones = aimed_[li]; cones && r) {
    // --only: the first direction drawn within the cones instead (trace/emission_cones.h).
    float pdf = 0.0f;
    r->direction = cones->sample(u_ray, &pdf);
    r->value = spatial_emission(l.params) * directional_emission(l.params, r->normal, r->direction);
    r->pdf.dir = pdf;
    r->weight = r->value / pdf;
    if (is_black(r->value)) r.reset();
  }
  y0.pdf_fwd = light_pick_ * l.pdf_pos;  // 0 for Dirac positions
  if (!r) {  // no emission from this sample: y0 alone, carrying nothing
    y0.p = x.position;
    y0.beta = vec3(0.0f);
    return 1;
  }
  y0.p = r->origin;
  y0.n = r->normal;
  y0.ns = y0.n;
  // y0 keeps the spatial part of the emission, L_e⁽⁰⁾ / p (a join at y0 evaluates the directional
  // part); the walk continues with the first ray's whole throughput.
  y0.beta = spatial_emission(l.params) / (light_pick_ * (r->pdf.delta_pos ? 1.0f : r->pdf.pos));
  const vec3 beta1 = r->weight / light_pick_;
  if (is_black(beta1)) return 1;
  const vec3 saved = y0.beta;
  th.light[0].beta = beta1;
  const int n = random_walk<TransportMode::kImportance>(th, rng, th.light, 1, y0.p, r->direction,
                                                        finite_part(r->pdf.dir, r->pdf.delta_dir), max_light_);
  th.light[0].beta = saved;
  // A Dirac direction from a finite-area origin (a distant light's aperture) is a parallel beam:
  // its first vertex has a finite density per area, which the distant-projection connector's
  // MIS weight compares with the eye's.
  if (n >= 2 && r->pdf.delta_dir && !r->pdf.delta_pos) th.light[1].pdf_fwd = parallel_jacobian(th.light[1], y0, r->direction);
  return n;
}

void Integrator::full_path(const Thread& th, int s, int t, const Vertex* sampled, std::string& out) const {
  const int k = s + t - 1;
  out.clear();
  if (k < 1) return;
  out.assign(static_cast<std::size_t>(k) + 5, 'D');  // L c0 … c(k+2) E: c_i is out[i + 1]
  out.front() = 'L';
  out.back() = 'E';
  auto vertex = [&](int i) -> const Vertex& {  // x_i in light-to-eye order
    // A fresh sensor sample replaces z0 when t = 1; otherwise a fresh light sample replaces y0 when s = 1.
    if (i < s) return (s == 1 && t != 1 && i == 0 && sampled) ? *sampled : th.light[static_cast<std::size_t>(i)];
    const int j = k - i;
    return (t == 1 && j == 0 && sampled) ? *sampled : th.eye[static_cast<std::size_t>(j)];
  };
  auto c = [&](int i) -> char& { return out[static_cast<std::size_t>(i) + 1]; };
  // Light end: for s = 0 the eye path hit an area light, DD.
  if (s > 0) {
    c(0) = vertex(0).pos_letter;
    c(1) = vertex(0).letter;
  }
  for (int i = 1; i <= k - 1; ++i) c(i + 1) = vertex(i).letter;
  if (t > 0) {
    c(k + 1) = vertex(k).letter;
    c(k + 2) = vertex(k).pos_letter;
  }
  c(s) = 'D';
  c(s + 1) = 'D';
}

float Integrator::mis_weight(const Thread& th, int s, int t, const Vertex* sampled, PathKey key, const JoinDensity* join,
                             ConnectorKind self) const {
  // Strategy (s2, t2) samples this string when the profile runs it and its join letters c(s2),
  // c(s2+1) are both D: one mask for all of them, bit s2 (runs_mask_ holds the profile's part).
  // When no other strategy can sample this string (pt, lt, and many strings of every profile),
  // the weight is 1 and no density needs recomputing.
  const int n = s + t;
  const std::uint64_t d_pairs = ~static_cast<std::uint64_t>(key | (key >> 1));  // bit i: c_i and c_(i+1) are D
  std::uint64_t others = runs_mask_[static_cast<std::size_t>(n)] & d_pairs;
  if (self == ConnectorKind::kNone) others &= ~(std::uint64_t{1} << s);
  // The projection connectors sample the split (1, n - 1) of strings beginning DSD (a distant
  // light) and the split (n - 1, 1) of strings ending DSD (an orthographic sensor). Their density
  // is the plain split's with the projected endpoint's area density (light choice aside) replaced
  // by 1, so their ratios to the plain recurrence's carry a factor 1 / pdf_pos (`conn_w2`, squared).
  double conn_w2_first = 0.0, conn_w2_last = 0.0, self_w2 = 1.0;
  if (has_connectors_) {
    const auto dsd_at = [&](int i) { return ((key >> i) & 7) == 2; };  // c_i c_(i+1) c_(i+2) = DSD
    if (n - 1 >= 1 && distant_of(n - 1) >= 0 && dsd_at(0) && !(self == ConnectorKind::kDistantProjection)) {
      const Vertex& x0 = s == 1 && t != 1 && sampled ? *sampled : th.light[0];
      const double pos = rs_.lights[static_cast<std::size_t>(x0.light)].pdf_pos;
      conn_w2_first = 1.0 / (pos * pos);
      others |= std::uint64_t{1} << 1;
    }
    if (n - 1 >= 1 && ortho_of(n - 1) >= 0 && dsd_at(n - 1) && !(self == ConnectorKind::kOrthoProjection)) {
      conn_w2_last = 1.0 / (static_cast<double>(cam_.pdf_pos) * cam_.pdf_pos);
      others |= std::uint64_t{1} << (n - 1);
    }
    if (self == ConnectorKind::kDistantProjection) {
      const double pos = rs_.lights[static_cast<std::size_t>((sampled ? *sampled : th.light[0]).light)].pdf_pos;
      self_w2 = pos * pos;
    }
    if (self == ConnectorKind::kOrthoProjection) self_w2 = static_cast<double>(cam_.pdf_pos) * cam_.pdf_pos;
  }
  if (others == 0) return 1.0f;
  // The loops below reach only as far as the farthest strategy that can: the light side down to
  // s2 = light_lo, the eye side up to s2 = eye_hi; densities beyond are not needed.
  const std::uint64_t below = others & ((std::uint64_t{1} << s) - 1), above = others & ~below;
  const int light_lo = below != 0 ? std::countr_zero(below) : s;
  const int eye_hi = above != 0 ? 63 - std::countl_zero(above) : s;
  const int eye_lo = n - eye_hi;  // the eye loop's last index: t when it does not run
  const std::array<Vertex, kMaxVertices>& L = th.light;
  const std::array<Vertex, kMaxVertices>& E = th.eye;
  // The join's vertices; a fresh sample stands for z0 when t = 1, else for y0 when s = 1.
  const Vertex* qs = s > 0 ? (s == 1 && t != 1 && sampled ? sampled : &L[static_cast<std::size_t>(s - 1)]) : nullptr;
  const Vertex* pt = t > 0 ? (t == 1 && sampled ? sampled : &E[static_cast<std::size_t>(t - 1)]) : nullptr;
  const Vertex* qsm = s > 1 ? &L[static_cast<std::size_t>(s - 2)] : nullptr;
  const Vertex* ptm = t > 1 ? &E[static_cast<std::size_t>(t - 2)] : nullptr;
  // --- the four reverse densities the join changes (the subpaths themselves stay untouched) ---
  // Every direction is at hand: the join's (w, from qs to pt, at squared distance d2) and each
  // vertex's unit direction to its predecessor (wo, at d2_wo); no normalisation is needed.
  // Area density at `next` from solid-angle density `pdf_w` along unit `w` over squared distance `dist2`.
  const auto area = [](float pdf_w, const Vertex& next, const vec3& w, float dist2) {
    return dist2 > 0.0f ? pdf_w * abs_cos(next, w) / dist2 : 0.0f;
  };
  float rev_qs = 0.0f, rev_pt = 0.0f, rev_qsm = 0.0f, rev_ptm = 0.0f;
  const bool need_pt = eye_lo <= t - 1, need_ptm = ptm && eye_lo <= t - 2;
  const bool need_qs = light_lo <= s - 1, need_qsm = qsm && light_lo <= s - 2;
  if (qs && pt) {
    JoinDensity own;
    if (join == nullptr) {
      const vec3 e = pt->p - qs->p;
      own.d2 = glm::dot(e, e);
      own.w = own.d2 > 0.0f ? e * (1.0f / std::sqrt(own.d2)) : vec3(0.0f);  // as connect() forms it
      join = &own;
    }
    const vec3 w = join->w, back = -w;
    const float d2 = join->d2;
    const bsdf::JoinPdfs& at_qs = join->at_qs;
    const bsdf::JoinPdfs& at_pt = join->at_pt;
    if (need_pt) rev_pt = area(at_qs.known ? at_qs.to_wi : pdf_dir(*qs, qsm ? &qs->wo : nullptr, w), *pt, w, d2);
    if (need_qs) rev_qs = area(at_pt.known ? at_pt.to_wi : pdf_dir(*pt, ptm ? &pt->wo : nullptr, back), *qs, w, d2);
    // A connector's endpoint sends a parallel beam: the density at the other end is per area.
    if (self == ConnectorKind::kDistantProjection) rev_pt = parallel_jacobian(*pt, *qs, w);
    if (self == ConnectorKind::kOrthoProjection) rev_qs = parallel_jacobian(*qs, *pt, w);
    if (need_ptm) rev_ptm = area(at_pt.known ? at_pt.to_wo : pdf_dir(*pt, &back, pt->wo), *ptm, pt->wo, pt->d2_wo);
    if (need_qsm) rev_qsm = area(at_qs.known ? at_qs.to_wo : pdf_dir(*qs, &w, qs->wo), *qsm, qs->wo, qs->d2_wo);
  } else if (pt) {  // s = 0: pt lies on an area light
    rev_pt = pdf_light_origin(*pt);
    if (need_ptm) {
      const RenderLight& l = rs_.lights[static_cast<std::size_t>(rs_.light_of_shape[static_cast<std::size_t>(pt->shape)])];
      rev_ptm = area(light_pdf_dir(l, *pt, pt->wo), *ptm, pt->wo, pt->d2_wo);
    }
  } else if (qs) {  // t = 0: qs is the lens point
    rev_qs = cam_.pdf_pos;
    if (need_qsm) rev_qsm = area(sensor_pdf_dir(*qs, qs->wo), *qsm, qs->wo, qs->d2_wo);
  }
  // --- hypothetical strategies: shorter eye subpaths, then shorter light subpaths ---
  // Ratios in double: long paths multiply many of them. Dirac densities are stored as 0 and
  // count as 1 here; their strategies are excluded by letter.
  double sum = 0.0;
  const auto runs = [&](int s2) { return static_cast<double>((others >> s2) & 1); };
  // The term of strategy s2 for density ratio ri (a connector's carries its factor; profiles
  // without connectors never take the branch).
  const auto term = [&](int s2, double ri) {
    double r2 = ri * ri;
    if (has_connectors_) [[unlikely]]
      r2 *= s2 == 1 && conn_w2_first != 0.0 ? conn_w2_first : s2 == n - 1 && conn_w2_last != 0.0 ? conn_w2_last : 1.0;
    return r2;
  };
  if (all_runs_) {
    // Each side: the join's two ratios, then the subpath's fixed part from prepare_joins().
    if (eye_lo <= t - 1) {
      const double a = remap(rev_pt) * (t == 1 && sampled ? inv_fwd(*pt) : th.eye_inv_fwd[static_cast<std::size_t>(t - 1)]);
      const double a2 = a * a;
      sum += a2 * runs(n - (t - 1));
      if (need_ptm) {
        const double b = remap(rev_ptm) * th.eye_inv_fwd[static_cast<std::size_t>(t - 2)];
        sum += a2 * b * b * (runs(n - (t - 2)) + (t >= 3 ? th.eye_acc[static_cast<std::size_t>(t - 3)] : 0.0));
      }
    }
    if (light_lo <= s - 1) {
      const double a = remap(rev_qs) * (qs != &L[static_cast<std::size_t>(s - 1)] ? inv_fwd(*qs) : th.light_inv_fwd[static_cast<std::size_t>(s - 1)]);
      const double a2 = a * a;
      sum += a2 * runs(s - 1);
      if (need_qsm) {
        const double b = remap(rev_qsm) * th.light_inv_fwd[static_cast<std::size_t>(s - 2)];
        sum += a2 * b * b * (runs(s - 2) + (s >= 3 ? th.light_acc[static_cast<std::size_t>(s - 3)] : 0.0));
      }
    }
    return static_cast<float>(1.0 / (1.0 + sum));
  }
  double ri = 1.0;
  for (int i = t - 1; i >= eye_lo; --i) {
    ri *= i == t - 1   ? remap(rev_pt) / remap(pt->pdf_fwd)
          : i == t - 2 ? remap(rev_ptm) / remap(E[static_cast<std::size_t>(i)].pdf_fwd)
                       : th.eye_ratio[static_cast<std::size_t>(i)];
    if ((others >> (n - i)) & 1) sum += term(n - i, ri);
  }
  ri = 1.0;
  for (int i = s - 1; i >= light_lo; --i) {
    ri *= i == s - 1   ? remap(rev_qs) / remap(qs->pdf_fwd)
          : i == s - 2 ? remap(rev_qsm) / remap(L[static_cast<std::size_t>(i)].pdf_fwd)
                       : th.light_ratio[static_cast<std::size_t>(i)];
    if ((others >> i) & 1) sum += term(i, ri);
  }
  return static_cast<float>(1.0 / (1.0 + sum * self_w2));
}

void Integrator::record(Thread& th, const Pending& r) const {
  const Rgb rgb{r.c.x, r.c.y, r.c.z};
  ExactRgb e;
  if (!to_exact(rgb, &e)) {
    record_nonfinite(th, r);
    return;
  }
  if (is_zero(e)) return;
  const auto [id, row] = th.ids.get(th.hist, r.key, r.technique);
  th.hist.add_exact_at_row(id, row, r.batch, e);
  if (!o_.images) return;
  const std::uint32_t set = th.hist.class_set(id);
  if (r.splat) th.splats.add(*th.images, static_cast<int>(r.rx), static_cast<int>(r.ry), set, e);
  else th.row[static_cast<std::size_t>(r.px)].add(set, e);
}

void Integrator::record_nonfinite(Thread& th, const Pending& r) const {
  th.hist.add_nonfinite();
  if (!th.first_nonfinite)
    th.first_nonfinite = NonfiniteSample{strategies_.strategies[static_cast<std::size_t>(r.strategy)].name, unpack(r.key),
                                         th.pass, r.px, th.py};
}

template <Integrator::Connection C>
void Integrator::connect(Thread& th, Sampler& rng, int s, int t, int batch) const {
  constexpr bool by_light = C == Connection::kSplat || C == Connection::kOrtho || C == Connection::kLens;
  // --only: a plain join whose path has a length no requested path has is not made (its numbers
  // are its own dimensions, so no other join's change). Connectors count their attempts: they go on.
  if constexpr (C != Connection::kDistant && C != Connection::kOrtho)
    if (o_.only != nullptr && !o_.only->has_length(s + t + 2)) return;
  rng.set_dimension(kJoinDims + (static_cast<std::uint64_t>(C) * kMaxRuns + static_cast<std::uint64_t>(by_light ? s : t)) * kDimsPerJoin);
  // s = 0: the eye subpath's last vertex must lie on an area light, which most do not; tested
  // before the join is set up.
  [[maybe_unused]] int hit_light = -1;
  if constexpr (C == Connection::kEmitter) {
    const Vertex& z = th.eye[static_cast<std::size_t>(t - 1)];
    if (z.kind != Kind::kSurface) return;
    hit_light = rs_.light_of_shape[static_cast<std::size_t>(z.shape)];
    if (hit_light < 0) return;
  }
  constexpr ConnectorKind kind = C == Connection::kDistant ? ConnectorKind::kDistantProjection : C == Connection::kOrtho ? ConnectorKind::kOrthoProjection : ConnectorKind::kNone;
  const int strategy_index = C == Connection::kDistant ? distant_of(t) : C == Connection::kOrtho ? ortho_of(s) : strategy(s, t);
  ConnectorStats* stats = kind != ConnectorKind::kNone ? &th.connectors[static_cast<std::size_t>(strategy_index)] : nullptr;
  PathKey chain_s = 0;  // a connector's S letter
  vec3 contrib{0.0f};
  // The join builds into th.join (its fresh endpoint stands for z0 for a splat or a film point,
  // for y0 otherwise); estimate() weighs and records it.
  JoinResult& jr = th.join;
  jr.chain = kind;
  jr.s = s;
  jr.t = t;
  jr.strategy = strategy_index;
  jr.density = JoinDensity{};
  constexpr bool fresh_eye = C == Connection::kSplat || C == Connection::kOrtho;
  Vertex& sampled = fresh_eye ? jr.eye0 : jr.light0;
  bool splat = false;
  float rx = 0.0f, ry = 0.0f;
  const Vertex* qs = s > 0 ? &th.light[static_cast<std::size_t>(s - 1)] : nullptr;
  const Vertex* pt = t > 0 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
  JoinDensity& join = jr.density;
  bool joined = false;  // `join` describes this connection (every case but s = 0 and t = 0)
  std::array<const Vertex*, 2> ends{};  // the shadow ray's ends, in the order visible() takes them
  if constexpr (C == Connection::kEmitter) {
    // --- eye path hits an area light (hit_light, above) ---
    const LightParams& l = rs_.lights[static_cast<std::size_t>(hit_light)].params;
    contrib = pt->beta * spatial_emission(l) * directional_emission(l, pt->n, pt->wo);
  } else if constexpr (C == Connection::kLens) {
    // --- light path hits the lens ---
    if (qs->kind != Kind::kLens) return;
    glm::vec2 raster;
    const vec3 we = importance(cam_.params, qs->p, qs->wo, &raster);
    if (is_black(we)) return;
    to_pixels(raster, &rx, &ry);
    contrib = qs->beta * we;
    splat = true;
  } else if constexpr (C == Connection::kSplat || C == Connection::kOrtho) {
    // --- a light vertex joined to a sensor point: a fresh one (the splat, t = 1) or, for
    //     ortho-projection, the film point on the line of sight through qs ---
    if (qs->kind == Kind::kLens || !qs->finite) return;
    std::optional<EndpointConnection> c;
    if constexpr (C == Connection::kSplat) {
      if (sensor_pair_[0] != 'D') return;  // a Dirac direction (orthographic, spot meter): no DD join
      c = connect_finite(cam_.params, rng.get2d_if(reads_lens_numbers(cam_.params)), qs->p);
      if (!c) return;
    } else {
      const auto* film = std::get_if<OrthographicParams>(&cam_.params);
      if (film == nullptr) return;
      ++stats->attempts;
      c = pathex::connect(*film, qs->p);
      if (!c) {
        ++stats->outside;
        return;
      }
      chain_s = bit(s + 1);  // c(k+1), the sensor's direction
    }
    sampled = Vertex{};
    sampled.kind = Kind::kCamera;
    sampled.p = c->position;
    sampled.n = cam_.pdf_pos == 0.0f ? vec3(0.0f) : c->normal;  // a pinhole is a point
    sampled.ns = sampled.n;
    sampled.letter = C == Connection::kSplat ? 'D' : sensor_pair_[0];
    sampled.pos_letter = sensor_pair_[1];
    sampled.pdf_fwd = cam_.pdf_pos;
    const vec3 w = c->wi;  // from qs to the sensor
    to_pixels(c->raster, &rx, &ry);
    vec3 fq;
    // A light vertex's beta already holds its spatial emission; only the directional part is left.
    if (qs->kind == Kind::kLight) fq = vec3(directional_emission(rs_.lights[static_cast<std::size_t>(qs->light)].params, qs->n, w));
    else fq = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(qs->shape)],
                        qs->wo, w, qs->ns, qs->n, &join.at_qs, TransportMode::kImportance);
    join.w = w;
    join.d2 = c->distance * c->distance;
    joined = true;
    contrib = qs->beta * fq * (abs_cos(*qs, w) * c->weight);  // weight: We cos / d² (splat), We (film)
    ends = {qs, &sampled};
    splat = true;
  } else if constexpr (C == Connection::kNee || C == Connection::kDistant) {
    // --- an eye vertex joined to a light point: a fresh light sample (next-event estimation) or,
    //     for distant-projection, the aperture point on the line through pt against the light ---
    if (pt->kind != Kind::kSurface || !pt->finite || rs_.lights.empty()) return;
    const std::size_t li = pick_light(rng);
    const RenderLight& l = rs_.lights[li];
    std::optional<EndpointConnection> c;
    vec3 err{0.0f};  // the light point's rounding-error bound, which offsets the shadow ray
    if constexpr (C == Connection::kNee) {
      if (light_pairs_[li][1] != 'D') return;  // Dirac directions (distant, laser): no DD join
      c = pathex::connect(l.params, sample_point(l, rng, &err), pt->p);
      if (!c) return;
    } else {
      if (!std::holds_alternative<DistantLightParams>(l.params)) return;  // the light picked is not distant
      ++stats->attempts;
      c = pathex::connect(l.params, SurfacePoint{}, pt->p);
      if (!c) {
        ++stats->outside;
        return;
      }
      err = aperture_error(l);
      chain_s = bit(1);  // c1, the light's direction
    }
    sampled = Vertex{};
    sampled.kind = Kind::kLight;
    sampled.light = static_cast<int>(li);
    sampled.pos_letter = light_pairs_[li][0];
    sampled.letter = C == Connection::kNee ? 'D' : light_pairs_[li][1];
    sampled.p = c->position;
    sampled.n = c->normal;
    sampled.err = err;
    sampled.ns = sampled.n;
    sampled.pdf_fwd = light_pick_ * l.pdf_pos;
    const vec3 w = c->wi;  // from pt to the light
    const vec3 f = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(pt->shape)],
                             pt->wo, w, pt->ns, pt->n, &join.at_pt);
    join.w = -w;  // w runs from pt to the light, the join's from the light to pt
    join.d2 = c->distance * c->distance;
    joined = true;
    contrib = pt->beta * f * (abs_cos(*pt, w) / light_pick_) * c->weight;  // weight: Le cos / (p d²), I / d², E
    ends = {pt, &sampled};
  } else {
    // --- a shadow ray between y(s-1) and z(t-1) ---
    if (qs->kind == Kind::kLens || pt->kind != Kind::kSurface || qs->kind != Kind::kSurface) return;
    if (!qs->finite || !pt->finite) return;
    const vec3 d = pt->p - qs->p;
    const float d2 = glm::dot(d, d);
    if (d2 <= 0.0f) return;
    const vec3 w = d * (1.0f / std::sqrt(d2));  // one division, not three
    const vec3 fq = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(qs->shape)],
                              qs->wo, w, qs->ns, qs->n, &join.at_qs, TransportMode::kImportance);
    const vec3 fp = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(pt->shape)],
                              pt->wo, -w, pt->ns, pt->n, &join.at_pt);
    join.w = w;
    join.d2 = d2;
    joined = true;
    const float g = abs_cos(*qs, w) * abs_cos(*pt, w) / d2;
    contrib = qs->beta * fq * fp * pt->beta * g;
    ends = {qs, pt};
  }
  if (is_black(contrib)) {
    if (stats) ++stats->no_transport;
    return;
  }
  const bool fresh = C == Connection::kSplat || C == Connection::kNee || kind != ConnectorKind::kNone;
  jr.has_eye0 = fresh && fresh_eye;
  jr.has_light0 = fresh && !fresh_eye;
  jr.chain_length = 0;
  if (!th.joins_ready) prepare_joins(th, th.ns, th.nt);
  jr.letters = path_key(th, s, t, fresh ? &sampled : nullptr) | chain_s;
  jr.contribution = contrib;
  jr.has_density = joined;
  jr.splat = splat;
  jr.rx = rx;
  jr.ry = ry;
  // No segment to test when the path's last edge was traced (an eye path on a light, a light
  // path on the lens); else the shadow ray between the join's two ends.
  jr.num_segments = C == Connection::kEmitter || C == Connection::kLens ? 0 : 1;
  jr.segments[0] = {ends[0], ends[1]};
  estimate(th, batch);
}

void Integrator::estimate(Thread& th, int batch) const {
  const JoinResult& jr = th.join;
  // The MIS weight over every strategy of the profile that samples this path: over whole-path
  // densities when the mirror connector is one of them, else by the join-local recurrence.
  if (o_.only != nullptr && !o_.only->records(jr.letters)) return;  // --only: not requested, no weight, no shadow ray
  float weight = 0.0f;
  // With the manifold connector every path is weighed over whole paths (which chains it could
  // build depends on the path's vertices, not on the join's).
  if (has_manifold_ || jr.chain == ConnectorKind::kMirror || (has_mirror_ && mirror_can_sample(th, jr.s, jr.t, jr.letters))) {
    gather(th, jr.s, jr.t, jr.has_light0 ? &jr.light0 : nullptr, jr.chain_length > 0 ? jr.chain_vertices.data() : nullptr, jr.chain_length,
           jr.has_eye0 ? &jr.eye0 : nullptr);
    weight = path_weight(th, jr.letters, jr.chain, jr.s);
  } else if (nee_mis_ && jr.t >= 2) {  // pt-nee's two strategies (trace/accel/nee_mis.h)
    weight = nee_mis_weight(th, jr.s, jr.t, jr.fresh(), jr.letters, jr.has_density ? &jr.density : nullptr);
  } else {
    weight = mis_weight(th, jr.s, jr.t, jr.fresh(), jr.letters, jr.has_density ? &jr.density : nullptr, jr.chain);
  }
  // The technique, as the histogram names it: a projection's chain starts at c0 (distant: s = 0)
  // or ends at c(k+2) (ortho: t = 0).
  const bool connector = jr.chain != ConnectorKind::kNone;
  const int technique = Technique{jr.strategy, jr.chain == ConnectorKind::kDistantProjection ? 0 : jr.s,
                                  jr.chain == ConnectorKind::kOrthoProjection ? 0 : jr.t, connector}
                            .code();
  const Pending r{jr.letters, jr.contribution * weight, jr.strategy, batch, technique, jr.splat, connector,
                  jr.rx, jr.ry, th.px, jr.num_segments};
  if (jr.num_segments == 0) {
    record(th, r);
    return;
  }
  // The weight is known before the segments' visibility is: they join the thread's batch (all in
  // one), and the contribution is recorded once the batch finds all of them clear; it waits on
  // the last one's lane.
  if (th.shadow.size() + jr.num_segments > OcclusionBatch::kCapacity) trace_shadows(th);
  th.rays += static_cast<std::uint64_t>(jr.num_segments);
  for (int i = 0; i < jr.num_segments; ++i) {
    const Segment& g = jr.segments[static_cast<std::size_t>(i)];
    Pending& lane = th.pending[static_cast<std::size_t>(th.shadow.add(*rs_.geometry, g.from->p, g.from->n, g.from->err, g.to->p, g.to->n, g.to->err))];
    lane = r;
    if (i + 1 < jr.num_segments) lane.segments = 0;
  }
  if (th.shadow.full()) trace_shadows(th);
}

// --- the mirror connector ---

void Integrator::connect_mirror(Thread& th, Sampler& rng, int s, int t, int batch) const {
  const int strategy_index = mirror_of(s, t);
  ConnectorStats& stats = th.connectors[static_cast<std::size_t>(strategy_index)];
  // Random numbers: a fresh light sample's from one block per t, a fresh sensor sample's from one
  // block per s, after the seven blocks of connect()'s kinds.
  constexpr std::uint64_t kLightBlock = 7, kEyeBlock = 8;
  // --- the light end a: y(s-1), or a fresh light sample ---
  const Vertex* a = s >= 2 ? &th.light[static_cast<std::size_t>(s - 1)] : fresh_light_end(th, rng, t, kLightBlock);
  if (!a || (s >= 2 && (a->kind != Kind::kSurface || !a->finite))) return;
  const RenderLight* light = s == 1 ? &rs_.lights[static_cast<std::size_t>(a->light)] : nullptr;
  // --- the eye end b: z(t-1), or (t = 1) a fresh sensor sample drawn per mirror ---
  const Vertex* b = t >= 2 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
  glm::vec2 u_lens{0.0f};
  if (b) {
    if (b->kind != Kind::kSurface || !b->finite) return;
  } else {
    if (sensor_pair_[0] != 'D') return;  // a Dirac direction (orthographic, spot meter): no D end
    rng.set_dimension(kJoinDims + (kEyeBlock * kMaxRuns + static_cast<std::uint64_t>(s)) * kDimsPerJoin);
    u_lens = rng.get2d_if(reads_lens_numbers(cam_.params));
  }
  if (!th.joins_ready) prepare_joins(th, th.ns, th.nt);
  // The letters: y(s-1)'s c(s) = D, the mirror's c(s+1) = S, z(t-1)'s c(s+2) = D.
  const PathKey light_part = s == 1 ? letter_bit(a->pos_letter, 0) : th.light_mask & (bit(s) - 1);
  const PathKey key = light_part | bit(s + 1) | ((th.eye_masks[static_cast<std::size_t>(t)] << (s + 2)) & ~bit(s + 2)) |
                      static_cast<PathKey>(s + t + 3) << kLengthShift;
  for (const PlanarMirror& mirror : rs_.mirrors) {
    ++stats.attempts;
    float rx = 0.0f, ry = 0.0f;
    std::optional<EndpointConnection> c;  // t = 1: the sensor's join to a's image
    if (t == 1) {
      c = connect_finite(cam_.params, u_lens, mirror_image(mirror, a->p));
      if (!c) {
        ++stats.outside;
        continue;
      }
      Vertex& z0 = th.join.eye0;
      z0 = Vertex{};
      z0.kind = Kind::kCamera;
      z0.p = c->position;
      z0.n = cam_.pdf_pos == 0.0f ? vec3(0.0f) : c->normal;
      z0.ns = z0.n;
      z0.letter = 'D';
      z0.pos_letter = sensor_pair_[1];
      z0.pdf_fwd = cam_.pdf_pos;
      to_pixels(c->raster, &rx, &ry);
      b = &z0;
    }
    MirrorMiss miss = MirrorMiss::kNone;
    const std::optional<MirrorJoin> j = mirror_join(mirror, a->p, b->p, &miss);
    if (!j) {
      ++stats.outside;  // off the mirror, or the ends on different sides of its plane
      continue;
    }
    // f at a towards the mirror: the light's directional emission, or the BSDF.
    const vec3 fa = light ? vec3(directional_emission(light->params, a->n, j->w_a))
                          : bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(a->shape)], a->wo, j->w_a, a->ns, a->n,
                                       TransportMode::kImportance);
    // Across the mirror the geometry term is the straight one to the image: |cos_a| |cos_b| / D².
    vec3 contrib = a->beta * fa * mirror.reflectance * abs_cos(*a, j->w_a);
    if (t == 1) {
      contrib *= c->weight;  // We cos / (p D²), D = |a' − sensor point|
    } else {
      const vec3 fb = bsdf::eval(*rs_.material_of_shape[static_cast<std::size_t>(b->shape)], b->wo, j->w_b, b->ns, b->n);
      contrib *= fb * b->beta * (abs_cos(*b, j->w_b) / (j->unfolded * j->unfolded));
    }
    if (is_black(contrib)) {
      ++stats.no_transport;
      continue;
    }
    JoinResult& jr = th.join;
    Vertex& m = jr.chain_vertices[0];
    m = Vertex{};
    m.kind = Kind::kSurface;
    m.letter = 'S';
    m.p = j->point;
    m.n = mirror.normal;
    m.ns = mirror.normal;
    m.err = mirror.error;
    m.shape = mirror.shape;
    jr.set_connector(ConnectorKind::kMirror, s, t, strategy_index, key, contrib, 1);
    jr.segments = {Segment{a, &m}, Segment{&m, b}};  // both must be clear
    jr.num_segments = 2;
    jr.has_density = false;  // MIS over whole paths recomputes every density
    jr.splat = t == 1;
    jr.rx = rx;
    jr.ry = ry;
    estimate(th, batch);
  }
}

const Vertex* Integrator::fresh_light_end(Thread& th, Sampler& rng, int t, std::uint64_t block) const {
  if (rs_.lights.empty()) return nullptr;
  rng.set_dimension(kJoinDims + (block * kMaxRuns + static_cast<std::uint64_t>(t)) * kDimsPerJoin);
  const std::size_t li = pick_light(rng);
  const RenderLight& light = rs_.lights[li];
  if (light_pairs_[li][1] != 'D') return nullptr;  // a Dirac direction (distant, laser): no D end
  Vertex& y0 = th.join.light0;
  y0 = Vertex{};
  y0.kind = Kind::kLight;
  y0.light = static_cast<int>(li);
  y0.pos_letter = light_pairs_[li][0];
  y0.letter = 'D';
  const SurfacePoint x = sample_point(light, rng, &y0.err);
  y0.p = light.is_area() ? x.position : light_position(light.params);
  y0.n = light.is_area() ? x.normal : vec3(0.0f);
  y0.ns = y0.n;
  y0.pdf_fwd = light_pick_ * light.pdf_pos;
  y0.beta = spatial_emission(light.params) / (light_pick_ * (light.pdf_pos > 0.0f ? light.pdf_pos : 1.0f));
  return &y0;
}

void Integrator::gather(Thread& th, int s, int t, const Vertex* fresh_light, const Vertex* chain, int chain_length,
                        const Vertex* fresh_eye) const {
  th.path.clear();
  for (int i = 0; i < s; ++i) th.path.push_back(i == 0 && fresh_light ? *fresh_light : th.light[static_cast<std::size_t>(i)]);
  for (int i = 0; i < chain_length; ++i) th.path.push_back(chain[i]);
  for (int j = t - 1; j >= 0; --j) th.path.push_back(j == 0 && fresh_eye ? *fresh_eye : th.eye[static_cast<std::size_t>(j)]);
  Vertex& x0 = th.path.front();
  if (s == 0) {  // an eye vertex on an area light starts the path
    x0.kind = Kind::kLight;
    x0.light = rs_.light_of_shape[static_cast<std::size_t>(x0.shape)];
  }
  if (t == 0) th.path.back().kind = Kind::kCamera;  // a light vertex on the lens ends it
}

bool Integrator::mirror_can_sample(const Thread& th, int s, int t, PathKey key) const {
  const int k = packed_length(key) - 3;
  for (int m = 1; m <= k - 1; ++m) {
    if (((key >> m) & 7) != 2 || mirror_of(m, k - m) < 0) continue;  // c(m) c(m+1) c(m+2) = DSD
    const Vertex& x = m < s ? th.light[static_cast<std::size_t>(m)] : th.eye[static_cast<std::size_t>(s + t - 1 - m)];
    if (x.kind == Kind::kSurface && mirror_shape_[static_cast<std::size_t>(x.shape)]) return true;
  }
  return false;
}

float Integrator::path_weight(Thread& th, PathKey key, ConnectorKind self, int s) const {
  // Every vertex's area density as the light walk (lf) and as the eye walk (ef) would sample it,
  // Dirac ones stored as 0 and counted as 1 (remap()), as the subpaths store them. The density of
  // plain split i (light vertices x0 … x(i-1)) is Π_{v<i} lf(v) Π_{v>=i} ef(v); the mirror
  // connector's with its vertex at x_m lacks x_m's factor, Π_{v<m} lf(v) Π_{v>m} ef(v); the
  // projections' are split 1's and split k's with the projected endpoint's area density replaced
  // by 1 (as in mis_weight()). All are kept relative to split 0's: rel[i] = P_i / P_0.
  const std::vector<Vertex>& x = th.path;
  const int k = static_cast<int>(x.size()) - 1, n = k + 1;
  const auto letter_s = [&](int i) { return !packed_is_d(key, i); };  // c_i is S
  const auto lf = [&](int v) -> double {
    if (v == 0) return light_pick_ * rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
    if (v == 1 && letter_s(1) && rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos > 0.0f)
      return parallel_jacobian(x[1], x[0], glm::normalize(x[1].p - x[0].p));  // a distant light's parallel beam
    if (letter_s(v)) return 0.0;  // x(v-1) is a Dirac
    return pdf(v >= 2 ? &x[static_cast<std::size_t>(v - 2)] : nullptr, x[static_cast<std::size_t>(v - 1)], x[static_cast<std::size_t>(v)]);
  };
  const auto ef = [&](int v) -> double {
    if (v == k) return cam_.pdf_pos;
    if (v == k - 1 && letter_s(k + 1) && cam_.pdf_pos > 0.0f)
      return parallel_jacobian(x[static_cast<std::size_t>(k - 1)], x[static_cast<std::size_t>(k)],
                               glm::normalize(x[static_cast<std::size_t>(k - 1)].p - x[static_cast<std::size_t>(k)].p));
    if (letter_s(v + 2)) return 0.0;  // x(v+1) is a Dirac
    return pdf(v + 2 <= k ? &x[static_cast<std::size_t>(v + 2)] : nullptr, x[static_cast<std::size_t>(v + 1)], x[static_cast<std::size_t>(v)]);
  };
  std::vector<double>& rel = th.rel;
  std::vector<double>& e = th.eye_density;
  rel.assign(static_cast<std::size_t>(n) + 1, 1.0);
  e.assign(static_cast<std::size_t>(n), 1.0);
  for (int v = 0; v <= k; ++v) {
    e[static_cast<std::size_t>(v)] = remap(static_cast<float>(ef(v)));
    rel[static_cast<std::size_t>(v) + 1] = rel[static_cast<std::size_t>(v)] * remap(static_cast<float>(lf(v))) / e[static_cast<std::size_t>(v)];
  }
  const double light_pos = rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos;
  const auto dsd_at = [&](int i) { return ((key >> i) & 7) == 2; };
  // The number of S vertices from x_i on (letters c(i+1) …), and the density of a chain
  // connector whose chain is x_i … x(i+m-1): the light walk's up to x(i-1), the eye walk's from
  // x(i+m) on, the chain's own vertices omitted (they are constructed, as the mirror's vertex).
  const auto s_run = [&](int i) {
    int m = 0;
    while (i + m <= k - 1 && letter_s(i + m + 1)) ++m;
    return m;
  };
  const auto chain_density = [&](int i, int m) {
    double r = rel[static_cast<std::size_t>(i)];
    for (int v = i; v < i + m; ++v) r /= e[static_cast<std::size_t>(v)];
    return r;
  };
  const auto mirror_at = [&](int m) {
    return m >= 1 && m <= k - 1 && dsd_at(m) && mirror_of(m, k - m) >= 0 && x[static_cast<std::size_t>(m)].kind == Kind::kSurface &&
           mirror_shape_[static_cast<std::size_t>(x[static_cast<std::size_t>(m)].shape)];
  };
  double own = 0.0;
  switch (self) {
    case ConnectorKind::kNone: own = rel[static_cast<std::size_t>(s)]; break;
    case ConnectorKind::kDistantProjection: own = rel[1] / light_pos; break;
    case ConnectorKind::kOrthoProjection: own = rel[static_cast<std::size_t>(n - 1)] / cam_.pdf_pos; break;
    case ConnectorKind::kMirror: own = rel[static_cast<std::size_t>(s)] / e[static_cast<std::size_t>(s)]; break;
    case ConnectorKind::kManifold: own = chain_density(s, s_run(s)); break;
  }
  double sum = 0.0;
  const auto add = [&](double p) {
    const double r = p / own;
    sum += r * r;
  };
  const std::uint64_t d_pairs = ~static_cast<std::uint64_t>(key | (key >> 1));
  const std::uint64_t plain = runs_mask_[static_cast<std::size_t>(n)] & d_pairs;
  for (int i = 0; i <= n; ++i)
    if ((plain >> i) & 1) add(rel[static_cast<std::size_t>(i)]);
  if (n - 1 >= 1 && distant_of(n - 1) >= 0 && dsd_at(0) && light_pos > 0.0) add(rel[1] / light_pos);
  if (n - 1 >= 1 && ortho_of(n - 1) >= 0 && dsd_at(n - 1) && cam_.pdf_pos > 0.0f) add(rel[static_cast<std::size_t>(n - 1)] / cam_.pdf_pos);
  for (int m = 1; m <= k - 1; ++m)
    if (mirror_at(m)) add(rel[static_cast<std::size_t>(m)] / e[static_cast<std::size_t>(m)]);
  // The manifold's chains: every maximal run of S vertices x_i … x(i+m-1) between two D vertices.
  if (has_manifold_)
    for (int i = 1; i <= k - 1; ++i) {
      const int m = s_run(i);
      if (m > 0 && !letter_s(i) && manifold_at(th, key, i, m)) add(chain_density(i, m));
    }
  return sum > 0.0 && std::isfinite(sum) ? static_cast<float>(1.0 / sum) : 0.0f;
}

void Integrator::trace_shadows(Thread& th) const {
  th.shadow.trace(*rs_.geometry);
  for (int lane = 0; lane < th.shadow.size(); ++lane) {
    const Pending& r = th.pending[static_cast<std::size_t>(lane)];
    if (r.segments == 0) continue;  // its contribution waits on a later lane
    bool visible = true;
    for (int i = lane - r.segments + 1; i <= lane; ++i) visible = visible && th.shadow.visible(i);
    if (r.connector) ++(visible ? th.connectors[static_cast<std::size_t>(r.strategy)].successes
                                : th.connectors[static_cast<std::size_t>(r.strategy)].occluded);
    if (visible) record(th, r);
  }
  th.shadow.clear();
}

void Integrator::sample(Thread& th, int px, int py, std::uint64_t pass) const {
  const std::uint64_t pixel = static_cast<std::uint64_t>(py) * static_cast<std::uint64_t>(cam_.width) + static_cast<std::uint64_t>(px);
  Sampler rng(o_.seed, pixel, pass, o_.sampler, static_cast<std::uint64_t>(o_.batches));
  rng.set_dimension(kEyeDims);
  // The light's first direction, computed before the eye subpath is traced: a Sobol point's chain
  // of dependent multiplies then overlaps the eye subpath's work instead of delaying the light
  // subpath's first ray (Sampler::at2d_now).
  const bool light_walk = !rs_.lights.empty() && max_light_ > 0;  // as light_subpath() tests
  const glm::vec2 u_light_ray = light_walk ? rng.at2d_now(kLightRayDim) : glm::vec2(0.0f);
  const int batch = batch_of(pass, o_.batches);
  th.px = px;
  th.py = py;
  th.pass = pass;
  const int nt = eye_subpath(th, rng, px, py);
  rng.set_dimension(kLightDims);
  const int ns = light_subpath(th, rng, u_light_ray);
  th.ns = ns;
  th.nt = nt;
  th.joins_ready = false;
  // The connections (s, t) in order of t, then s, over the ranges where they form a path of k =
  // s + t - 1 >= 1 edges and at most max_bounces_ + 1 (k - 1 <= max_bounces_): loops with exact
  // bounds rather than one loop whose tests the branch predictor keeps missing.
  // A light subpath that reached the lens ends there (random_walk stops), so only its last vertex
  // can be a lens vertex; it forms the t = 0 connection and no other.
  const bool lens_end = ns >= 2 && th.light[static_cast<std::size_t>(ns - 1)].kind == Kind::kLens;
  if (lens_end && lens_hits_ && ns - 2 <= max_bounces_ && strategy(ns, 0) >= 0)
    connect<Connection::kLens>(th, rng, ns, 0, batch);
  // s = 1 takes a fresh light sample, so it runs even when no light subpath was traced.
  const int s_max = (rs_.lights.empty() ? ns : std::max(ns, 1)) - (lens_end ? 1 : 0);
  if (nt >= 1)
    for (int s = 1; s <= std::min(s_max, max_bounces_ + 1); ++s)
      if (strategy(s, 1) >= 0) connect<Connection::kSplat>(th, rng, s, 1, batch);
  for (int t = 2; t <= nt; ++t) {
    const int s_hi = std::min(s_max, max_bounces_ + 2 - t);
    if (s_hi >= 0 && strategy(0, t) >= 0) connect<Connection::kEmitter>(th, rng, 0, t, batch);
    if (s_hi >= 1 && strategy(1, t) >= 0) connect<Connection::kNee>(th, rng, 1, t, batch);
    if (s_hi >= 1 && distant_of(t) >= 0) connect<Connection::kDistant>(th, rng, 1, t, batch);
    for (int s = 2; s <= s_hi; ++s)
      if (strategy(s, t) >= 0) connect<Connection::kJoin>(th, rng, s, t, batch);
  }
  if (has_connectors_ && nt >= 1)
    for (int s = 1; s <= std::min(ns - (lens_end ? 1 : 0), max_bounces_ + 1); ++s)
      if (ortho_of(s) >= 0) connect<Connection::kOrtho>(th, rng, s, 1, batch);
  // The mirror connector's path has s + t + 1 vertices: s + t - 1 interior ones.
  if (has_mirror_)
    for (int t = 1; t <= nt; ++t)
      for (int s = 1; s <= std::min(s_max, max_bounces_ + 1 - t); ++s)
        if (mirror_of(s, t) >= 0) connect_mirror(th, rng, s, t, batch);
  // The manifold connector's eye end is a surface vertex z(t-1), t >= 2.
  if (has_manifold_)
    for (int t = 2; t <= nt; ++t)
      for (int s = 1; s <= std::min(s_max, max_bounces_ + 1 - t); ++s)
        if (manifold_of(s, t) >= 0) connect_manifold(th, rng, s, t, batch);
}


}  // namespace tracer

using tracer::Integrator;

Result<RenderOutput> render(const Scene& scene, const Profile& profile, const Classifier* classifier,
                            const RenderOptions& options) {
  Result<StrategySet> strategies = runnable_strategies(profile);
  if (!strategies) return strategies.error();
  Result<RenderScene> rs = make_render_scene(scene);
  if (!rs) return rs.error();
  RenderOptions o = options;
  // The same rule as the checker's: an explicit bound overrides the profile's own.
  if (!o.max_bounces) o.max_bounces = profile.max_bounces.value_or(16);
  HistogramLayout layout;
  layout.num_batches = o.batches;
  for (const Strategy& st : strategies->strategies) layout.strategies.push_back(st.name);

  RenderOutput out{Histogram(layout, classifier),
                   o.images ? ClassImages(rs->camera.width, rs->camera.height, classifier, o.layer_classes)
                            : ClassImages(0, 0, nullptr, {}),
                   layout.strategies};
  Integrator integrator(*rs, *strategies, o);
  const std::size_t area_lights = rs->lights.size() - scene.lights.size();  // the emissive shapes come first
  for (std::size_t i = area_lights; i < rs->lights.size(); ++i)
    if (const std::optional<EmissionCones>& c = integrator.aimed(i))
      out.aimed.push_back({static_cast<int>(i - area_lights), std::holds_alternative<PointLightParams>(rs->lights[i].params) ? "point" : "spot",
                           c->size(), c->share()});
  const int threads = o.threads > 0 ? o.threads : static_cast<int>(tbb::this_task_arena::max_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  tbb::enumerable_thread_specific<Integrator::Thread> locals(
      [&] {
        Integrator::Thread th{Histogram(layout, classifier),
                              std::vector<ClassImages::PixelSum>(static_cast<std::size_t>(out.images.width()), ClassImages::PixelSum(out.images)),
                              {}, {}, 0, {}, {}, {}};
        // Room for many paths and technique rows at once: the histogram keeps each of its batches'
        // cells and row sums in a row of its own, and a render finds new paths to the end (the
        // rare long ones), so regrowing moved every row into fresh pages, again and again (a
        // quarter of pt-nee's CPU time on the embedded Cornell box at 128 spp went to the copies
        // and their page faults). Address space only: pages are touched as paths arrive.
        th.hist.reserve_paths(tracer::kReservedPaths);
        th.hist.reserve_rows(2 * tracer::kReservedPaths);
        th.images = &out.images;
        th.splats = ClassImages::SplatBuffer(out.images.splat_entries(), out.images.splat_keys());
        th.connectors.resize(strategies->strategies.size());
        return th;
      });
  const int w = rs->camera.width, h = rs->camera.height;
  const std::uint64_t pixels = static_cast<std::uint64_t>(w) * static_cast<std::uint64_t>(h);
  const auto start = std::chrono::steady_clock::now();
  // Passes run in chunks: a pixel takes a chunk's passes back to back, so that its camera
  // contributions reach the shared image once per chunk (and its part of the scene stays in
  // cache); cancelling stops on a whole chunk, so every finished pass covers the whole image. The
  // chunks come from a deal (core/pass_deal.h): this render's passes in order, or an MPI job's.
  ChunkDeal own(o.passes.value_or(PassSet::range(0, o.spp)), kPassesPerChunk);
  PassDealer& deal = o.dealer != nullptr ? *o.dealer : own;
  bool dealt_all = false;
  while (!(o.cancel && o.cancel->load())) {
    const std::optional<PassRange> chunk = deal.next();
    if (!chunk) {
      dealt_all = true;
      break;
    }
    const std::uint64_t first = chunk->first, end = chunk->last;
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 1), [&](const tbb::blocked_range<int>& rows) {
      Integrator::Thread& th = locals.local();
      for (int y = rows.begin(); y < rows.end(); ++y) {
        for (int x = 0; x < w; ++x)
          for (std::uint64_t p = first; p < end; ++p) integrator.sample(th, x, y, p);
        integrator.finish_row(th, out.images, y);
      }
    });
    for (std::uint64_t p = first; p < end; ++p) out.histogram.add_samples(tracer::batch_of(p, o.batches), pixels);
    out.passes_done.add(first, end);
    if (o.progress) o.progress(deal.dealt() * pixels, deal.total() * pixels);
  }
  out.spp_done = out.passes_done.count();
  out.complete = dealt_all;
  // The threads' histograms are summed into the first of them, which then takes the place of
  // the output's (holding only the sample counts so far): one fewer copy of every path, and of
  // its classification. Ids are local to a histogram, so which thread comes first does not show.
  std::optional<Histogram> summed;
  for (Integrator::Thread& th : locals) {
    th.splats.flush(out.images);
    th.ids.flush(th.hist);
    if (!summed) {
      summed.emplace(std::move(th.hist));
    } else {
      Result<bool> m = summed->merge(th.hist);
      if (!m) return m.error();
    }
    out.rays += th.rays;
    if (th.first_nonfinite && (!out.first_nonfinite || th.first_nonfinite->order() < out.first_nonfinite->order()))
      out.first_nonfinite = th.first_nonfinite;
  }
  if (summed) {
    Result<bool> m = summed->merge(out.histogram);  // the sample counts of every batch
    if (!m) return m.error();
    out.histogram = std::move(*summed);
  }
  // Connector statistics, in the profile's order (integer sums: the same for every thread count).
  for (std::size_t i = 0; i < strategies->strategies.size(); ++i) {
    const Strategy& st = strategies->strategies[i];
    if (st.connector == ConnectorKind::kNone) continue;
    ConnectorStats total{st.name, to_string(st.connector)};
    for (const Integrator::Thread& th : locals) total += th.connectors[i];
    out.connectors.push_back(total);
  }
  out.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace pathex
