// The manifold connector in the integrator (trace/joins/manifold.h for the walk, trace/specular_seed.h
// for its seeds): the batches of seeds, the contribution through the solved chain, and which paths
// it could build (for MIS).
#include <algorithm>
#include <cmath>
#include <vector>

#include "trace/media.h"
#include "optics/fresnel.h"
#include "trace/integrator.h"
#include "trace/joins/manifold.h"
#include "trace/specular_seed.h"

namespace pathex::tracer {

bool Integrator::manifold_at(const PathView& x, PathKey key, int i, int m) const {
  const int k = x.size() - 1;
  const int t = k + 1 - i - m;  // letters after the chain
  if (i < 1 || m < 1 || m > kMaxChain || t < 1 || manifold_of(i, t) < 0) return false;
  // (At t = 1, c(i+m+1) is the sensor's direction letter: D for a pinhole's and a thin lens's.)
  if (!packed_is_d(key, i) || !packed_is_d(key, i + m + 1)) return false;
  const Vertex& a = x[i - 1];
  const Vertex& b = x[i + m];
  if (t >= 2 && (b.kind != Kind::kSurface || !finite_of_shape_[static_cast<std::size_t>(b.shape)])) return false;
  if (i >= 2 && (a.kind != Kind::kSurface || !finite_of_shape_[static_cast<std::size_t>(a.shape)])) return false;
  for (int v = i; v < i + m; ++v) {
    const Vertex& c = x[v];
    if (c.kind != Kind::kSurface) return false;
    const std::size_t shape = static_cast<std::size_t>(c.shape);
    const float before = glm::dot(x[v - 1].p - c.p, c.n);
    const float after = glm::dot(x[v + 1].p - c.p, c.n);
    // Glass reflects or refracts; a mirror (or a mixture's mirror part) reflects.
    if (rs_.specular.glass_ior[shape] == 0.0f && (is_black(rs_.specular.mirror_reflectance[shape]) || !(before * after > 0.0f))) return false;
  }
  return true;
}

void Integrator::chain_densities(Thread& th, const PathView& x, PathKey key, ConnectorKind self, int lo, int hi) const {
  const int k = x.size() - 1;
  const auto letter_s = [&](int i) { return !packed_is_d(key, i); };  // c_i is S: x(i-1) is a Dirac vertex
  const auto read = [&](int v) { return v >= lo && v < hi; };
  // The probability that a walk leaving towards `wo`'s opposite picks the Dirac lobe the chain took there.
  const auto picks = [&](const Vertex& c, const vec3& wo, bool reflect) {
    MaterialScratch textured;
    return bsdf::lobe_probability(material_at(c, &textured), wo, c.ns, reflect ? Lobe::kSpecularReflection : Lobe::kSpecularTransmission);
  };
  // Every maximal run x_i … x(i+m-1) of S vertices that the manifold connector could build, as
  // techniques() lists them (an x0 drawn towards x1 joins no chain).
  for (int i = 1 + (origin_drawn_towards(x[0], x[1]) ? 1 : 0); i <= k - 1; ++i) {
    if (letter_s(i) || !letter_s(i + 1)) continue;
    int m = 0;
    while (i + m <= k - 1 && letter_s(i + m + 1)) ++m;
    const bool own = self == ConnectorKind::kManifold && i == x.s;
    if (i + m < lo || i - 1 >= hi) continue;  // none of x(i-1) … x(i+m) is read
    if (!own && !manifold_at(x, key, i, m)) continue;
    const Vertex& a = x[i - 1];
    const Vertex& b = x[i + m];
    std::vector<ChainVertex>& chain = th.mis_chain;
    chain.clear();
    double light_picks = 1.0, eye_picks = 1.0;  // the walks' choices of the chain's lobes, from either end
    for (int v = i; v < i + m; ++v) {
      const Vertex& c = x[v];
      const vec3 to_light = glm::normalize(x[v - 1].p - c.p), to_eye = glm::normalize(x[v + 1].p - c.p);
      const float before = glm::dot(to_light, c.n), after = glm::dot(to_eye, c.n);
      const bool reflect = before * after > 0.0f;
      const double ior = rs_.specular.glass_ior[static_cast<std::size_t>(c.shape)] > 0.0f ? rs_.specular.glass_ior[static_cast<std::size_t>(c.shape)] : 1.0;
      // The index on each neighbour's side (the normal points out of the glass).
      chain.push_back({&rs_.geometry->shape_geometry(c.shape), c.shape, c.primitive, ior, before > 0.0f ? 1.0 : ior,
                       after > 0.0f ? 1.0 : ior, reflect, glm::dvec3(c.p), 0});
      light_picks *= picks(c, to_light, reflect);
      eye_picks *= picks(c, to_eye, reflect);
    }
    const vec3 wa = glm::normalize(x[i].p - a.p), wb = glm::normalize(x[i + m - 1].p - b.p);
    const vec3 nb = b.has_normal() ? b.n : cam_.axis();  // a pinhole's area across its axis, as the connector's (t = 1)
    const double cos_a = abs_cos(a, wa), cos_b = std::fabs(glm::dot(nb, wb));
    const double ab = chain_dw_db(chain, glm::dvec3(a.p), glm::dvec3(b.p), glm::dvec3(nb), 0.0);  // |dω_a / dA_b|
    // |dω_b / dA_a| by reciprocity: the étendue η² cos dA dω is the same at both ends of the chain.
    const double eta_a = chain.front().eta_light, eta_b = chain.back().eta_eye;
    const double ba = ab * (eta_a * eta_a * cos_a) / (eta_b * eta_b * cos_b);
    // The direction densities at either end: a's light (x0's, the light's emission) or BSDF, b's BSDF.
    float pa = 0.0f;
    if (i == 1) {
      const int li = a.kind == Kind::kLight ? a.light : rs_.light_of_shape[static_cast<std::size_t>(a.shape)];
      pa = light_pdf_dir(rs_.lights[static_cast<std::size_t>(li)], a, wa);
    } else {
      const vec3 wp = glm::normalize(x[i - 2].p - a.p);
      pa = pdf_dir(a, &wp, wa);
    }
    // b's BSDF's, or (b = xk, a sensor point) the sensor's direction density.
    const vec3 wn = b.kind == Kind::kCamera ? vec3(0.0f) : glm::normalize(x[i + m + 1].p - b.p);
    const float pb = pdf_dir(b, &wn, wb);
    const double light_b = pa * light_picks * ab, eye_a = pb * eye_picks * ba;
    // Where the chain's term is undefined, the walks' densities stay (a function of the path
    // alone, as every density here: the weights still sum to 1).
    if (!(ab > 0.0) || !(cos_b > 0.0) || !std::isfinite(light_b) || !std::isfinite(eye_a)) continue;
    for (int v = i; v < i + m; ++v)
      if (read(v)) th.densities[static_cast<std::size_t>(v)] = mis::Densities{1.0, 1.0};
    if (read(i + m)) th.densities[static_cast<std::size_t>(i + m)].light = light_b;
    if (read(i - 1)) th.densities[static_cast<std::size_t>(i - 1)].eye = eye_a;
  }
}

void Integrator::connect_manifold(Thread& th, Sampler& rng, int s, int t, int batch) const {
  const int strategy_index = manifold_of(s, t);
  ConnectorStats& stats = th.connectors[static_cast<std::size_t>(strategy_index)];
  // manifold_rate() from the eye subpath and the light; below 1, one coin per sample (from a stream of its own).
  bool through = max_light_ >= 2 && t >= 3;
  for (int j = 1; j <= t - 2 && through; ++j) through = th.eye[static_cast<std::size_t>(j)].letter == 'S';
  double rate = through ? 1.0 : o_.manifold.rate.value_or(1.0);
  const bool skip = rate < 1.0 && static_cast<double>(stream_bits(stream_key(rng.key(), th.pass, 0x6d616e6966726174ULL), 0) >> 11) * 0x1p-53 >= rate;
  if (skip && max_light_ >= 2) return;  // light subpaths' joins share every such path: the rate applies whatever the light
  const Vertex* b = &th.eye[static_cast<std::size_t>(t - 1)];
  if (t == 1) {  // a fresh point of a sensor with a finite direction (a pinhole's, one drawn on a thin lens)
    if (cam_.letters[0] != 'D') return;
    join_numbers(rng, JoinBlock::kManifoldEye, s);
    b = &sensor_vertex(th.join.eye0, sensor_point(cam_.params, rng.get2d_if(reads_lens_numbers(cam_.params))), cam_.axis(), 'D');
  } else if (b->kind != Kind::kSurface || !b->finite) {
    return;
  }
  const Vertex* a = s >= 2 ? &th.light[static_cast<std::size_t>(s - 1)] : fresh_light_end(th, rng, t, JoinBlock::kManifoldLight);
  if (!a || (s >= 2 && (a->kind != Kind::kSurface || !a->finite))) return;
  if (max_light_ < 2 && (s >= 2 ? th.light[0] : *a).pos_letter == 'S') rate = 1.0;  // from a point: the connector's alone
  else if (skip) return;
  // A one-sided emitter at a (a fresh light point) whose every specular shape lies behind it sends no
  // chain any light: the chain's first vertex would leave a at a negative cosine (no transport).
  if (s == 1 && !is_black(vec3(a->n)) && is_black(end_f(*a, -a->n, TransportMode::kImportance))) {
    bool behind = true;
    for (const glm::vec4& bs : rs_.specular.bounds)
      behind = behind && glm::dot(vec3(bs) - a->p, a->n) < -bs.w;
    if (behind) return;
  }
  // The seeds draw from their own counter-based stream (an unbounded count of numbers per join).
  const std::uint64_t stream = stream_key(rng.key(), th.pass, 0x6d616e69666f6c64ULL + static_cast<std::uint64_t>(s) * kMaxRuns +
                                                               static_cast<std::uint64_t>(t));
  std::uint64_t drawn = 0;
  const glm::dvec3 pa(a->p), pb(b->p), nb(b->has_normal() ? b->n : cam_.axis());  // a pinhole's area across its axis
  std::vector<ManifoldSolution>& found = th.manifold_found;
  // A seed keeps its vertices' shapes and types (reflection or refraction) through Newton's
  // method, so a seed of another signature than every chain still sought cannot find one again:
  // the batches that seek (`seeking`) skip its solve, and it still counts in its batch.
  const auto sought = [&](const std::vector<ChainVertex>& x) {
    for (const ManifoldSolution& f : found) {
      if (f.batches > 0 || f.chain.size() != x.size()) continue;
      bool same = true;
      for (std::size_t i = 0; i < x.size() && same; ++i) same = x[i].id == f.chain[i].id && x[i].reflect == f.chain[i].reflect;
      if (same) return true;
    }
    return false;
  };
  // The signatures (shapes and types, Newton's method keeps them) a seed of this batch solved to
  // the wrong type: a batch solves no other seed of those (below). Flat: length, then shape * 2 +
  // reflect per vertex; one per thread, reused.
  static thread_local std::vector<int> wrong;
  const auto signature_at = [&](const std::vector<ChainVertex>& x) -> bool {
    for (std::size_t k = 0; k < wrong.size(); k += 1 + static_cast<std::size_t>(wrong[k])) {
      bool same = static_cast<std::size_t>(wrong[k]) == x.size();
      for (std::size_t i = 0; i < x.size() && same; ++i) same = wrong[k + 1 + i] == x[i].id * 2 + (x[i].reflect ? 1 : 0);
      if (same) return true;
    }
    return false;
  };
  // One seed, from either end with probability 1/2, solved.
  const auto trial = [&](std::vector<ChainVertex>& chain, bool seeking) -> ManifoldWalk {
    ManifoldWalk w;
    const bool from_light = bits_to_unit_float(stream_bits(stream, drawn++)) < 0.5f;
    w.failure = seed_chain(rs_, from_light ? *a : *b, from_light, stream, &drawn, chain);
    if (w.failure != ManifoldFailure::kNone) return w;
    if (s + static_cast<int>(chain.size()) + t - 2 > max_bounces_) {  // longer than the render's bound on interior vertices
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
    // A chain whose path the plan's filter does not record is not solved (its seed still counts
    // in the batches, so the recorded chains' inverse probabilities are unchanged).
    if (!filter_.records(chain_key(th, *a, s, t, static_cast<int>(chain.size())))) {
      w.failure = ManifoldFailure::kUnrequested;
      return w;
    }
    if (seeking && !sought(chain)) {
      w.failure = ManifoldFailure::kUnrequested;
      return w;
    }
    // A signature this batch already saw solve to the wrong type (at most points a type no chain
    // to b has: 96 % of the wrong types on lamp-glass.json and point-glass.json fall in batches
    // where no seed of that signature finds a chain) is not solved again. Every batch follows the
    // same rule, so the chance that a batch finds a chain is the same for the first batch and the
    // ones that seek it again, and K stays its inverse probability: unbiased, as long as a chain
    // can still be found (by its signature's first seed of a batch).
    if (signature_at(chain)) {
      w.failure = ManifoldFailure::kWrongType;
      return w;
    }
    ++stats.walks;
    // Its generalized geometry term only for a chain that is new to the join (the first batch's),
    // not for one found again: the same chain, the same term.
    w = solve_chain(chain, pa, pb, nb, rs_.specular.scene_size, o_.manifold, false);
    stats.iterations += static_cast<std::uint64_t>(w.iterations);
    if (w.failure == ManifoldFailure::kWrongType) {
      wrong.push_back(static_cast<int>(chain.size()));
      for (const ChainVertex& c : chain) wrong.push_back(c.id * 2 + (c.reflect ? 1 : 0));
    }
    return w;
  };
  std::vector<ChainVertex>& seed = th.manifold_seed;
  const double same = 1e-5 * rs_.specular.scene_size;  // solutions are polished (solve_chain), so one found twice compares equal
  const auto index_of = [&](const std::vector<ChainVertex>& x) -> int {
    for (std::size_t k = 0; k < found.size(); ++k) {
      const std::vector<ChainVertex>& y = found[k].chain;
      bool equal = y.size() == x.size();
      for (std::size_t i = 0; i < x.size() && equal; ++i)
        equal = x[i].id == y[i].id && x[i].reflect == y[i].reflect && glm::length(x[i].p - y[i].p) < same;
      if (equal) return static_cast<int>(k);
    }
    return -1;
  };
  // --- the first batch: `seeds` seeds, each an attempt; the distinct chains they solve to (the
  //     biased variant: `biased_trials` seeds, and no batches after it) ---
  const bool biased = o_.manifold.biased_trials > 0;
  const int per_batch = biased ? o_.manifold.biased_trials : std::max(1, o_.manifold.seeds.value_or(kManifoldSeeds));
  found.clear();
  wrong.clear();
  for (int j = 0; j < per_batch; ++j) {
    ++stats.attempts;
    const ManifoldWalk w = trial(seed, false);
    switch (w.failure) {
      case ManifoldFailure::kNone: break;
      case ManifoldFailure::kNoSolution: ++stats.no_solution; continue;
      case ManifoldFailure::kOccluded: ++stats.occluded; continue;
      case ManifoldFailure::kSingular: ++stats.singular; continue;
      case ManifoldFailure::kWrongType: ++stats.wrong_type; continue;
      case ManifoldFailure::kTooShort: ++stats.too_short; continue;
      case ManifoldFailure::kIterationLimit: ++stats.iteration_limit; continue;
      case ManifoldFailure::kUnrequested: ++stats.no_transport; continue;  // no light to the classes rendered
    }
    if (index_of(seed) >= 0) {
      ++stats.repeats;
      continue;
    }
    const double dw_db = chain_dw_db(seed, pa, pb, nb, o_.manifold.singular);
    if (!(dw_db > 0.0)) {
      ++stats.singular;
      continue;
    }
    found.push_back({seed, dw_db, 0});
  }
  // --- each chain's inverse probability of being found by a batch: the number of fresh batches
  //     until one finds it again (geometric, E[K] = 1 / P(a batch finds it)); the batches are
  //     shared, and run until every chain is found again or max_trials seeds are spent ---
  if (biased) {  // every distinct chain once
    for (const ManifoldSolution& x : found) emit_manifold(th, s, t, batch, strategy_index, *a, *b, x.chain, x.dw_db / rate);
    return;
  }
  std::size_t left = found.size();
  int batches = 0;
  while (left > 0 && (batches + 1) * per_batch <= o_.manifold.max_trials) {
    ++batches;
    wrong.clear();
    // A batch ends early once every chain is found again: its other seeds could change no count.
    for (int j = 0; j < per_batch && left > 0; ++j) {
      if (trial(seed, true).failure != ManifoldFailure::kNone) continue;
      const int k = index_of(seed);
      if (k >= 0 && found[static_cast<std::size_t>(k)].batches == 0) {
        found[static_cast<std::size_t>(k)].batches = batches;
        --left;
      }
    }
  }
  stats.truncated += left;  // weighed by the batches run, an underestimate of their inverse probability
  for (const ManifoldSolution& x : found)
    emit_manifold(th, s, t, batch, strategy_index, *a, *b, x.chain, x.dw_db * static_cast<double>(x.batches > 0 ? x.batches : std::max(batches, 1)) / rate);
}

void Integrator::emit_manifold(Thread& th, int s, int t, int batch, int strategy_index, const Vertex& a_end, const Vertex& b_end,
                               const std::vector<ChainVertex>& chain, double weight) const {
  const Vertex* a = &a_end;
  const Vertex* b = &b_end;
  ConnectorStats& stats = th.connectors[static_cast<std::size_t>(strategy_index)];
  const int m = static_cast<int>(chain.size());
  // A fresh light point where x0's density is drawn towards x1 (a rectangle sampled by solid
  // angle, x1 on a shape with a finite part): not this connector's to sample (techniques()).
  if (s == 1 && rs_.lights[static_cast<std::size_t>(a->light)].drawn_towards(finite_of_shape_[static_cast<std::size_t>(chain[0].id)] != 0)) return;
  // --- the chain's vertices and its contribution ---
  JoinResult& jr = th.join;
  vec3 transmit(1.0f);  // the share of flux the chain passes: tint (1 - F) or tint F for glass, R for a mirror
  for (int i = 0; i < m; ++i) {
    const ChainVertex& c = chain[static_cast<std::size_t>(i)];
    Vertex& v = jr.chain_vertices[static_cast<std::size_t>(i)];
    v = Vertex{};
    v.kind = Kind::kSurface;
    v.letter = 'S';
    v.p = vec3(c.p);
    const SurfaceDerivatives geometry = surface_derivatives(*c.shape, c.primitive, c.p);
    v.n = vec3(geometry.n);
    v.ns = vec3(geometry.ns);
    v.finite = false;
    // Rounding of the solved point: its float position and the surface's own test, as a hit's bound.
    v.err = error_gamma(16) * (glm::abs(v.p) + vec3(static_cast<float>(rs_.specular.scene_size)));
    v.shape = c.id;
    v.primitive = c.primitive;
    const glm::dvec3 prev = i == 0 ? glm::dvec3(a->p) : chain[static_cast<std::size_t>(i - 1)].p;
    const float cos_prev = static_cast<float>(glm::dot(glm::normalize(prev - c.p), geometry.ns));
    // A textured material's values at the solved point (its uv as a hit there has it), as every
    // other strategy sees them through material_at().
    MaterialScratch textured;
    const bool has_textures = rs_.textures_of_shape[static_cast<std::size_t>(c.id)] != nullptr;
    if (has_textures) v.uv = rs_.geometry->uv_at(c.id, c.primitive, v.p);
    const Material& mat = material_at(v, &textured);
    if (const auto* glass = std::get_if<Dielectric>(&mat)) {
      const float f = bsdf::fresnel_dielectric(cos_prev, glass->ior);
      transmit *= glass->tint * (c.reflect ? f : 1.0f - f);
    } else if (const auto* metal = std::get_if<Conductor>(&mat)) {
      transmit *= metal->tint * fresnel_complex(cos_prev, metal->eta, metal->k);
    } else if (const auto* mix = std::get_if<Mixture>(&mat); mix && has_textures) {  // a mix by a texture amount: its weights here
      transmit *= bsdf::mirror_reflectance(*mix);
    } else {
      transmit *= rs_.specular.mirror_reflectance[static_cast<std::size_t>(c.id)];
    }
  }
  if (absorbing_) {  // Beer–Lambert along the chain's m + 1 segments, a to b (trace/media.h)
    const Vertex* from = a;
    for (int i = 0; i <= m; ++i) {
      Vertex* to = i < m ? &jr.chain_vertices[static_cast<std::size_t>(i)] : nullptr;
      const vec3 e = (to ? to->p : b->p) - from->p;
      const float length = glm::length(e);
      const vec3 sigma = length > 0.0f ? segment_absorption(*from, e / length, rs_.absorption_of_shape) : from->sigma;
      transmit *= beer_lambert(sigma, length);
      if (to) to->sigma = sigma;
      from = to;
    }
  }
  const vec3 w_a = glm::normalize(jr.chain_vertices[0].p - a->p);
  const vec3 w_b = glm::normalize(jr.chain_vertices[static_cast<std::size_t>(m - 1)].p - b->p);
  // f at a towards the chain: the light's directional emission (a's beta holds the spatial part), or the BSDF.
  const vec3 fa = end_f(*a, w_a, TransportMode::kImportance);
  // Flux leaving a into dω lands on dA_b = dω / |dω_a/dA_b|: the generalized geometry term, here
  // times the chain's estimated inverse probability (`weight`). Its cosine at b is the area
  // measure's (geometric); b's shading cosine replaces it (shading_cos, vertex.h). At a sensor
  // point (t = 1) dA_b lies across the sensor's axis, as connect_finite()'s weight We cos / (p d²)
  // has it: b's factor is We towards the chain over the point's density (a pinhole's 1), splatted.
  vec3 fb(1.0f), beta_b(1.0f);
  float shade_b = 1.0f;
  glm::vec2 raster{0.0f};
  if (t == 1) {
    fb = importance(cam_.params, b->p, w_b, &raster) / (cam_.pdf_pos > 0.0f ? cam_.pdf_pos : 1.0f);
  } else {
    fb = end_f(*b, w_b, TransportMode::kRadiance);
    beta_b = b->beta;
    const float cos_b = abs_cos(*b, w_b);
    shade_b = cos_b > 0.0f ? shading_cos(*b, w_b) / cos_b : 0.0f;
  }
  const vec3 contrib = a->beta * fa * shading_cos(*a, w_a) * transmit * fb * beta_b *
                       (static_cast<float>(weight) * shade_b);
  if (is_black(contrib)) {
    ++stats.no_transport;
    return;
  }
  // b is a surface vertex (t >= 2), or the sensor point eye0.
  jr.set_connector(ConnectorKind::kManifold, s, t, strategy_index, chain_key(th, *a, s, t, m), contrib, m, a, b);
  jr.splat = t == 1;
  if (jr.splat) cam_.to_pixels(raster, &jr.rx, &jr.ry);
  estimate(th, batch);
}

}  // namespace pathex::tracer
