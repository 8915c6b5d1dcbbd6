// Bidirectional path sampling with full-path labels.
//
// For each pixel and pass: an eye subpath z0 z1 … from the sensor and a light subpath y0 y1 …
// from a light, each extended by local sampling (BSDF sampling, Russian roulette from
// RenderOptions::rr_depth vertices on, below rr_threshold (eye) or rr_light_threshold (light); at most max_bounces interior vertices
// on the full path).
// Then every (s, chain, t) the profile runs is joined (trace/joins/: s = 0 an eye vertex on an
// area light, s = 1 a fresh light sample (next-event estimation), t = 1 a fresh sensor sample (a
// splat), t = 0 a light vertex on a thin lens, otherwise a shadow ray between y(s-1) and z(t-1);
// and the connectors), each join weighed by MIS (mis_weight.cpp) and recorded by estimate():
// subpaths, joins, weight, record.
//
// Labels: each vertex keeps the letter of the scattering event sampled there (the component a
// BSDF chose; a light's and a sensor's two letters). The full-path string of a connection is
// those letters in light-to-eye order with the two join letters set to D (a join evaluates only
// finite parts): which strategies sample the path follows from them (mis_weight.cpp).
#include "trace/render.h"

#include <array>
#include <cmath>
#include <utility>

#include "trace/accel/path_ids.h"
#include "trace/media.h"
#include "trace/bsdf.h"
#include "trace/integrator.h"
#include "trace/prune.h"
#include "trace/rng.h"
#include "trace/strategy_table.h"

namespace pathex {

namespace tracer {
namespace {

// Random-number dimensions (trace/rng.h): each stage of a sample draws from its own block, so that
// adding a strategy leaves every other strategy's numbers unchanged. The eye and the light subpath
// draw at most 4 + 4 per vertex; each connection (kind, subpath length) then draws at most 4.
constexpr std::uint64_t kEyeDims = 0;
constexpr std::uint64_t kLightDims = 1024;
// The light subpath's first direction, after the light's pick (1) and point (2).
constexpr std::uint64_t kLightRayDim = kLightDims + 3;
static_assert(4 + 4 * 64 <= kLightDims - kEyeDims, "a subpath's numbers fit its block");

float max_component(const vec3& v) { return std::max(v.x, std::max(v.y, v.z)); }

}  // namespace

template <TransportMode mode>
int Integrator::random_walk(Thread& th, Sampler& rng, std::array<Vertex, kMaxVertices>& path, vec3 o, vec3 d, float pdf_dir,
                            vec3 beta, int max_vertices) const {
  int count = 1;
  // Russian roulette compares the throughput with the subpath's start, so that a light subpath
  // (whose throughput starts at the light's power) is treated like an eye subpath.
  const float beta_start = std::max(max_component(beta), 1e-30f);
  float eta2 = 1.0f;  // the product of η² over the refractions so far (radiance walks)
  SubpathPrefix live(filter_, mode == TransportMode::kImportance, path[0].pos_letter, path[0].letter);  // trace/prune.h
  while (count < max_vertices && live.alive()) {
    Vertex& prev = path[static_cast<std::size_t>(count - 1)];
    ++th.rays;
    // The direction numbers of the vertex this ray finds (dimensions 1 and 2 of its block), drawn
    // before the ray is traced: they do not depend on the hit, and so their computation overlaps
    // the intersection instead of delaying the scattering (Sampler::at2d_now).
    const glm::vec2 u_dir = rng.at2d_now(rng.dimension() + 1);
    const HitDetail detail = rs_.textured ? HitDetail::kFull : HitDetail::kNoUv;  // err: zero for points, no offset
    const std::optional<Hit> hit = mode == TransportMode::kRadiance && count == 1 && th.split.splitting()
                                       ? th.split.first_hit(th.ahead, *rs_.geometry, o, d, prev.n, prev.err, detail)  // the camera ray's
                                       : th.ahead.intersect(*rs_.geometry, o, d, prev.n, prev.err, detail);
    // --- a light subpath may end on the lens (strategy t = 0) ---
    if (mode == TransportMode::kImportance && lens_hits_) {
      const std::optional<EndpointConnection> lens = hit_lens(cam_.params, o, d);
      if (lens && (!hit || lens->distance < hit->t)) {
        Vertex& v = sensor_vertex(path[static_cast<std::size_t>(count)], lens->position, lens->normal, 'D');  // a lens's letters are DD
        v.kind = Kind::kLens;
        v.beta = beta;
        link(v, prev);
        v.pdf_fwd = v.d2_wo > 0.0f ? pdf_dir * std::fabs(glm::dot(v.n, d)) / v.d2_wo : 0.0f;
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
    v.ns = rs_.shading_normal(*hit);  // a bump or normal map's, if any
    v.shape = hit->shape;
    v.primitive = hit->primitive;
    v.uv = hit->uv;
    v.finite = finite_of_shape_[static_cast<std::size_t>(v.shape)] != 0;
    v.wo = -d;
    const vec3 e = v.p - prev.p;
    v.d2_wo = glm::dot(e, e);
    if (absorbing_) {  // Beer–Lambert along the segment (trace/media.h)
      v.sigma = segment_absorption(prev, d, rs_.absorption_of_shape);
      beta *= beer_lambert(v.sigma, std::sqrt(v.d2_wo));
    }
    v.beta = beta;
    v.rr_throughput = max_component(beta) * eta2 / beta_start;
    // Solid angle at prev to area at v, along the unit ray direction d.
    // 0 for coincident points (and a subnormal distance, whose inverse would overflow): no density.
    const float inv_d2 = v.d2_wo >= std::numeric_limits<float>::min() ? 1.0f / v.d2_wo : 0.0f;
    const float to_area_v = std::fabs(glm::dot(v.n, d)) * inv_d2;
    v.pdf_fwd = pdf_dir * to_area_v;
    ++count;
    if (count >= max_vertices) break;
    // --- scatter ---
    MaterialScratch textured;
    const Material& m = material_at(v, &textured);
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
    const bool delta = rs_.features.specular && bs->is_delta;
    pdf_dir = delta ? 0.0f : bs->pdf;
    const float pdf_rev_dir = delta ? 0.0f : bs->pdf_rev;
    prev.pdf_rev = pdf_rev_dir * abs_cos(prev, d) * inv_d2;
    // --- Russian roulette, never mislabelling: the vertices so far stay valid prefixes ---
    // From vertex rr_depth on, a walk whose throughput relative to its start (a refraction's
    // radiance scaling 1/η² undone, so that entering glass is no loss) is below rr_threshold
    // survives with probability throughput / threshold, and a survivor carries the threshold.
    if (mode == TransportMode::kRadiance && rs_.features.transmission) eta2 *= bs->eta * bs->eta;  // else η = 1
    constexpr bool kEye = mode == TransportMode::kRadiance;  // eye and light subpaths have thresholds of their own
    const float threshold = kEye ? eye_threshold_ : o_.rr_light_threshold;
    if (count >= o_.rr_depth && threshold > 0.0f) {
      const float survive = max_component(beta) * eta2 / (beta_start * threshold);
      if (kEye && th.tally) th.tally->survive[static_cast<std::size_t>(count)] = survive;  // the pilot's (trace/accel/join_plan.h)
      const float u_rr = rng.get1d_if(survive < 1.0f);  // its dimension taken at every vertex, so the dimensions stay aligned
      if (survive < 1.0f) {
        if (u_rr >= survive) break;
        beta *= 1.0f / survive;
      }
    }
    o = v.p;
    d = bs->wi;
    if (!std::isfinite(beta.x + beta.y + beta.z)) break;
    live.extend(v.letter);  // a subpath no recorded path can complete stops (the plan's filter, DESIGN §11)
  }
  return count;
}

int Integrator::eye_subpath(Thread& th, Sampler& rng, int px, int py) const {
  const std::optional<EndpointRay> r = th.split.splitting() ? th.split.primary_ray(th.ahead, cam_, rng, px, py) : th.ahead.primary_ray(cam_, rng, px, py);
  const Vertex& z0 = sensor_vertex(th.eye[0], r ? r->origin : vec3(0.0f), r ? r->normal : vec3(0.0f), cam_.letters[0]);
  if (!r) return 1;
  // Importance over the sampling density is 1 for every sensor: pixel values are radiance.
  const int n = random_walk<TransportMode::kRadiance>(th, rng, th.eye, r->origin, r->direction, r->pdf.dir, vec3(1.0f), max_eye_);
  // An orthographic sensor's rays are a parallel beam (see light_subpath()).
  if (n >= 2 && r->pdf.delta_dir && !r->pdf.delta_pos) th.eye[1].pdf_fwd = parallel_jacobian(th.eye[1], z0, r->direction);
  return n;
}

int Integrator::light_subpath(Thread& th, Sampler& rng, glm::vec2 u_ray) const {
  if (rs_.lights.empty() || max_light_ == 0) return 0;
  const std::size_t li = rs_.pick_light(rng);
  const RenderLight& l = rs_.lights[li];
  vec3 err{0.0f};
  SurfacePoint x;
  const std::optional<EndpointRay> r = rs_.emit(l, rng, u_ray, &x, &err);
  Vertex& y0 = light_vertex(th.light[0], li, r ? r->origin : x.position, r ? r->normal : vec3(0.0f), err, l.letters[1]);
  if (!r) {  // no emission from this sample: y0 alone, carrying nothing
    y0.beta = vec3(0.0f);
    return 1;
  }
  // y0 keeps the spatial part of the emission, L_e⁽⁰⁾ / p (a join at y0 evaluates the directional
  // part; a Dirac position is chosen with probability 1); the walk starts with the first ray's
  // whole throughput.
  y0.beta = spatial_emission(l.params) / (light_pick_ * (r->pdf.delta_pos ? 1.0f : r->pdf.pos));
  const vec3 beta1 = r->weight / light_pick_;
  if (is_black(beta1)) return 1;
  const int n = random_walk<TransportMode::kImportance>(th, rng, th.light, y0.p, r->direction, r->pdf.dir, beta1, max_light_);
  // A Dirac direction from a finite-area origin (a distant light's aperture) is a parallel beam:
  // its first vertex has a finite density per area, which the distant-projection connector's
  // MIS weight compares with the eye's.
  if (n >= 2 && r->pdf.delta_dir && !r->pdf.delta_pos) th.light[1].pdf_fwd = parallel_jacobian(th.light[1], y0, r->direction);
  // A light drawn towards y1 (an image infinite light, a rectangle sampled by solid angle:
  // Integrator::drawn_towards): y0's density as next-event estimation from y1 would draw it, y1's
  // the rest of the emission's joint density.
  if (n >= 2 && drawn_towards(static_cast<int>(li), th.light[1])) {
    y0.pdf_fwd = light_origin_density(static_cast<int>(li), y0.p, y0.n, th.light[1]);
    th.light[1].pdf_fwd = light_step_density(static_cast<int>(li), y0, th.light[1]);
  } else if (l.environment()) {
    y0.pdf_fwd = 0.0f;
  }
  return n;
}

void Integrator::record(Thread& th, const Pending& r) const {
  const Rgb rgb{r.c.x, r.c.y, r.c.z};
  ExactRgb e;
  if (!to_exact(rgb, &e)) {
    record_nonfinite(th, r);
    return;
  }
  if (is_zero(e)) return;
  if (th.tally) tally(*th.tally, r);
  const auto [id, row] = th.ids.get(th.hist, r.key, r.technique);
  th.hist.add_exact_at_row(id, row, r.batch, e);
  if (!o_.images) return;
  const std::uint32_t set = th.hist.class_set(id);
  if (r.splat) th.splats.add(*th.images, static_cast<int>(r.rx), static_cast<int>(r.ry), set, e);
  else th.row[static_cast<std::size_t>(r.px)].add(set, e);
}

void Integrator::tally(JoinTally& tally, const Pending& r) {
  const Technique k = Technique::from_code(r.technique);
  if (k.s + k.t == 2) return;  // the emission seen directly
  if (r.splat) {
    tally.splats += double(r.c.x) * r.c.x + double(r.c.y) * r.c.y + double(r.c.z) * r.c.z;
    return;
  }
  tally.camera += r.c;
  tally.by_t[static_cast<std::size_t>(k.t)] += r.c;
  if (!k.connector && k.s >= 2 && k.t >= 2) tally.deep[static_cast<std::size_t>(k.t)] += r.c;
}

void Integrator::record_nonfinite(Thread& th, const Pending& r) const {
  th.hist.add_nonfinite();
  // The earliest by (pass, row, column) of the sample that made it, not the first recorded: the
  // order a thread meets its rows and flushes its shadow rays depends on the thread count.
  NonfiniteSample here{strategies_.strategies[static_cast<std::size_t>(r.strategy)].name, unpack(r.key), r.pass, r.px, th.py};
  if (!th.first_nonfinite || here.order() < th.first_nonfinite->order()) th.first_nonfinite = std::move(here);
}

Integrator::PathView Integrator::path_of(const Thread& th, const JoinResult& jr) {
  PathView x;
  x.light = th.light.data();
  x.light0 = jr.has_light0 ? &jr.light0 : nullptr;
  x.chain = jr.chain_vertices.data();
  x.eye = th.eye.data();
  x.eye0 = jr.has_eye0 ? &jr.eye0 : nullptr;
  x.s = jr.s;
  x.m = jr.chain_length;
  x.t = jr.t;
  return x;
}

void Integrator::estimate(Thread& th, int batch) const {
  const JoinResult& jr = th.join;
  if (!filter_.records(jr.letters)) return;  // not recorded by the plan: no weight, no shadow ray
  const JoinDensity* density = jr.has_density ? &jr.density : nullptr;
  const float weight = nee_pair_ && jr.chain == ConnectorKind::kNone && jr.t >= 2 ? nee_pair_weight(path_of(th, jr), jr.letters, density)
                                                                                : mis_weight(th, path_of(th, jr), jr.letters, jr.chain, density);
  // The technique, as the histogram names it: a projection's chain starts at c0 (distant: s = 0)
  // or ends at c(k+2) (ortho: t = 0).
  const bool connector = jr.chain != ConnectorKind::kNone;
  const int technique = Technique{jr.strategy, jr.chain == ConnectorKind::kDistantProjection ? 0 : jr.s,
                                  jr.chain == ConnectorKind::kOrthoProjection ? 0 : jr.t, connector}
                            .code();
  const Pending r{jr.letters, jr.contribution * (weight * th.split.weight()), jr.strategy, batch, technique, jr.splat, connector,
                  jr.rx, jr.ry, th.px, jr.num_segments, th.pass};
  if (th.tally) {  // the pilot of the roulette thresholds' auto (trace/accel/join_plan.h)
    ++th.tally->joins;
    ++th.tally->joins_at[static_cast<std::size_t>(jr.t)];
    if (!connector && jr.s >= 2 && jr.t >= 2) ++th.tally->deep_joins[static_cast<std::size_t>(jr.t)];
  }
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

// 1 / q with probability q = min(1, z's throughput / --rr-join-threshold), else 0: whether eye
// vertex z = z(t-1) makes its joins with the light subpath (s >= 2), and their weight if it does.
float Integrator::join_roulette(Sampler& rng, const Vertex& z, int t) const {
  const float q = o_.rr_join_threshold > 0.0f ? z.rr_throughput / o_.rr_join_threshold : 1.0f;
  if (!(q < 1.0f)) return 1.0f;
  join_numbers(rng, JoinBlock::kJoinRoulette, t);
  return rng.get1d() < q ? 1.0f / q : 0.0f;
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

// --splits: the sample's camera rays and runs after each (trace/accel/first_vertex_split.h).
void Integrator::sample(Thread& th, int px, int py, std::uint64_t pass) const {
  th.split.runs(px, py, pass, static_cast<std::uint64_t>(o_.replicates), [&] { sample_run(th, px, py, pass); });
}

void Integrator::sample_run(Thread& th, int px, int py, std::uint64_t pass) const {
  const std::uint64_t pixel = static_cast<std::uint64_t>(py) * static_cast<std::uint64_t>(cam_.width) + static_cast<std::uint64_t>(px);
  Sampler rng(o_.seed, pixel, pass, o_.sampler, static_cast<std::uint64_t>(o_.replicates));
  rng.set_dimension(kEyeDims);
  // The light's first direction, computed before the eye subpath is traced: a Sobol point's chain
  // of dependent multiplies then overlaps the eye subpath's work instead of delaying the light
  // subpath's first ray (Sampler::at2d_now). A split sample's runs take it after the camera's
  // numbers, from their own point.
  const bool light_walk = !rs_.lights.empty() && max_light_ > 0;  // as light_subpath() tests
  const glm::vec2 u_light_ray_ahead = light_walk && !th.split.splitting() ? rng.at2d_now(kLightRayDim) : glm::vec2(0.0f);
  const int batch = batch_of(pixel, pass, o_.batches, o_.replicates);
  th.px = px;
  th.py = py;
  th.pass = pass;
  const int nt = eye_subpath(th, rng, px, py);
  const glm::vec2 u_light_ray = light_walk && th.split.splitting() ? rng.at2d(kLightRayDim) : u_light_ray_ahead;
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
  // --- joins (trace/joins/): each makes th.join from the subpaths; estimate() weighs and records it ---
  // A plain join whose path has a length no recorded path has is not made (its numbers are its
  // own dimensions, so no other join's change). Connectors count their attempts: they go on.
  const auto wanted = [&](int s, int t) { return filter_.has_length(s + t + 2); };
  const auto made = [&](bool joined) {
    if (joined) estimate(th, batch);
  };
  if (lens_end && lens_hits_ && ns - 2 <= max_bounces_ && strategy(ns, 0) >= 0 && wanted(ns, 0)) made(join_lens(th, ns));
  // s = 1 takes a fresh light sample, so it runs even when no light subpath was traced.
  const int s_max = (rs_.lights.empty() ? ns : std::max(ns, 1)) - (lens_end ? 1 : 0);
  if (nt >= 1)
    for (int s = 1; s <= std::min(s_max, max_bounces_ + 1); ++s)
      if (strategy(s, 1) >= 0 && wanted(s, 1)) made(join_sensor(th, rng, s, ConnectorKind::kNone));
  for (int t = 2; t <= nt; ++t) {
    const int s_hi = std::min(s_max, max_bounces_ + 2 - t);
    if (s_hi >= 0 && strategy(0, t) >= 0 && wanted(0, t)) made(join_emitter(th, t));
    if (s_hi >= 1 && strategy(1, t) >= 0 && wanted(1, t)) made(join_light(th, rng, t, ConnectorKind::kNone));
    if (s_hi >= 1 && distant_of(t) >= 0) made(join_light(th, rng, t, ConnectorKind::kDistantProjection));
    // z(t-1)'s joins with the light subpath's vertices, by a roulette of their own (--rr-join-threshold).
    const float inv_q = s_hi >= 2 ? join_roulette(rng, th.eye[static_cast<std::size_t>(t - 1)], t) : 0.0f;
    if (inv_q > 0.0f)
      for (int s = 2; s <= s_hi; ++s)
        if (strategy(s, t) >= 0 && wanted(s, t) && join_shadow(th, s, t)) {
          th.join.contribution *= inv_q;
          estimate(th, batch);
        }
  }
  if (has_connectors_ && nt >= 1)
    for (int s = 1; s <= std::min(ns - (lens_end ? 1 : 0), max_bounces_ + 1); ++s)
      if (ortho_of(s) >= 0) made(join_sensor(th, rng, s, ConnectorKind::kOrthoProjection));
  // The mirror connector's path has s + t + 1 vertices: s + t - 1 interior ones.
  if (has_mirror_)
    for (int t = 1; t <= nt; ++t)
      for (int s = 1; s <= std::min(s_max, max_bounces_ + 1 - t); ++s)
        if (mirror_of(s, t) >= 0) connect_mirror(th, rng, s, t, batch);
  // The manifold connector's eye end: a surface vertex z(t-1), or (t = 1) a fresh sensor point.
  if (has_manifold_)
    for (int t = 1; t <= nt; ++t)
      for (int s = 1; s <= std::min(s_max, max_bounces_ + 1 - t); ++s)
        if (manifold_of(s, t) >= 0) connect_manifold(th, rng, s, t, batch);
}

}  // namespace tracer

}  // namespace pathex
