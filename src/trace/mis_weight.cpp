// The estimator's MIS weight (DESIGN §7): which strategies of the profile sample a join's path, and
// the two densities of each vertex they differ in, handed to the one weight routine (trace/mis.h).
//
// Which strategies sample a path follows from its letters: a plain join (s', DD, t') when the
// profile runs it and its join letters c(s') c(s'+1) are D; a projection where the path starts
// (distant) or ends (orthographic) with DSD; the mirror connector where a DSD has its S on a planar
// mirror; the manifold connector at every maximal run of S vertices it could solve.
//
// The densities come from where they are: a plain join's path is made of the two subpaths, which
// keep each vertex's densities as their walks sampled them (Vertex::pdf_fwd, pdf_rev); the join
// changes only the reverse densities of the two vertices nearest each end. The weight reads a copy
// of the vertices between the two strategies farthest apart, those four computed into it (from the
// BSDF densities the join's evaluation gave, when it gave them): no subpath density is written. A
// connector that constructs vertices (the mirror's, the manifold's chain) makes a path no walk
// sampled: every density is computed from the vertices. Across a run of S vertices that the
// manifold connector could build, every strategy's densities are the chain's (chain_densities(),
// trace/joins/manifold_join.cpp): a walk that crosses it draws the far end with the generalized
// geometry term |dω/dA| of the chain, as the manifold's own density leaves the chain out.
#include <algorithm>
#include <array>
#include <cmath>

#include "trace/integrator.h"
#include "trace/mis.h"

namespace pathex::tracer {

// The manifold connector runs for this share of the samples (--manifold-rate), the factor of its
// density in the weight (n_i p_i): where the camera sees its eye end x_b directly or past a diffuse
// vertex, and, without a light subpath (pt-nee+manifold), also where it sees x_b through specular
// vertices only; with one (bdpt+manifold), those joins run in every sample (docs/manifold.md).
double Integrator::manifold_rate(PathKey key, int b, int k) const {
  bool through = max_light_ >= 2 && b + 1 <= k - 1;  // the camera sees x_b through S vertices only (x_v's letter is c(v+1))
  for (int v = b + 1; v <= k - 1 && through; ++v) through = !packed_is_d(key, v + 1);
  // Nor where x0 is a point (c0 = S) and no light subpath's join shares the path (pt-nee+manifold: the connector's alone).
  return through || (max_light_ < 2 && !packed_is_d(key, 0)) ? 1.0 : o_.manifold.rate.value_or(1.0);
}

void Integrator::store_densities(Thread& th, int ns, int nt) const {
  for (int i = 0; i < ns; ++i) {
    const Vertex& y = th.light[static_cast<std::size_t>(i)];
    th.light_densities[static_cast<std::size_t>(i)] = {remap_density(y.pdf_fwd), remap_density(y.pdf_rev)};
  }
  for (int j = 0; j < nt; ++j) {
    const Vertex& z = th.eye[static_cast<std::size_t>(j)];
    th.eye_densities[static_cast<std::size_t>(j)] = {remap_density(z.pdf_rev), remap_density(z.pdf_fwd)};
  }
}

float Integrator::sensor_pdf_dir(const Vertex& v, const vec3& w) const { return pdf_ray(cam_.params, v.p, w).dir; }

float Integrator::light_pdf_dir(const RenderLight& l, const Vertex& v, const vec3& w) const {
  return l.pdf_ray(SurfacePoint{v.p, v.n, l.pdf_pos}, w).dir;
}

bool Integrator::origin_drawn_towards(const Vertex& v, const Vertex& x1) const {
  const int li = v.kind == Kind::kLight ? v.light : v.kind == Kind::kSurface ? rs_.light_of_shape[static_cast<std::size_t>(v.shape)] : -1;
  return li >= 0 && drawn_towards(li, x1);
}

float Integrator::pdf_dir(const Vertex& v, const vec3* wp, const vec3& wn) const {
  switch (v.kind) {
    case Kind::kCamera: return sensor_pdf_dir(v, wn);
    case Kind::kLight: return light_pdf_dir(rs_.lights[static_cast<std::size_t>(v.light)], v, wn);
    case Kind::kSurface: {
      if (!wp) return 0.0f;
      MaterialScratch textured;
      return bsdf::pdf(material_at(v, &textured), *wp, wn, v.ns, v.n);
    }
    case Kind::kLens: return 0.0f;
  }
  return 0.0f;
}

float Integrator::pdf(const Vertex* prev, const Vertex& v, const Vertex& next) const {
  const vec3 d = next.p - v.p;
  const float d2 = glm::dot(d, d);
  if (d2 == 0.0f) return 0.0f;
  const vec3 wn = d / std::sqrt(d2);
  if (v.kind == Kind::kLight && drawn_towards(v.light, next)) return light_step_density(v.light, v, next);
  const vec3 wp = prev ? glm::normalize(prev->p - v.p) : vec3(0.0f);
  return pdf_dir(v, prev ? &wp : nullptr, wn) * abs_cos(next, wn) / d2;  // solid angle at v to area at next
}

mis::Strategies Integrator::techniques(Thread& th, const PathView& x, PathKey key, ConnectorKind self) const {
  const int n = x.size(), s = x.s;
  mis::Strategies st;
  st.own = {s, 0, 1.0};  // the strategy that sampled the path: a plain join's (a connector's: below)
  // --- the plain joins whose two join letters are D ---
  const std::uint64_t d_pairs = ~static_cast<std::uint64_t>(key | (key >> 1));  // bit i: c_i and c(i+1) are D
  // (The split s = n, t = 0, only when light paths can hit the lens.)
  st.plain = table_.plain_splits(n) & d_pairs & ~(lens_hits_ ? 0 : std::uint64_t{1} << n);
  if (self == ConnectorKind::kNone) st.plain &= ~(std::uint64_t{1} << s);
  if (has_connectors_ || self != ConnectorKind::kNone) connector_techniques(th, x, key, self, st);
  return st;
}

void Integrator::connector_techniques(Thread& th, const PathView& x, PathKey key, ConnectorKind self, mis::Strategies& st) const {
  const int n = x.size(), k = n - 1, s = x.s;
  const auto letter_s = [&](int i) { return !packed_is_d(key, i); };  // c_i is S
  const auto dsd_at = [&](int i) { return ((key >> i) & 7) == 2; };   // c_i c(i+1) c(i+2) = DSD
  const auto light_pos = [&] { return static_cast<double>(rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos); };
  // The number of S vertices from x_i on (letters c(i+1) …).
  const auto s_run = [&](int i) {
    int m = 0;
    while (i + m <= k - 1 && letter_s(i + m + 1)) ++m;
    return m;
  };
  // --- the connector that sampled the path ---
  switch (self) {
    case ConnectorKind::kNone: break;
    case ConnectorKind::kDistantProjection: st.own = {1, 0, 1.0 / light_pos()}; break;
    case ConnectorKind::kOrthoProjection: st.own = {n - 1, 0, 1.0 / cam_.pdf_pos}; break;
    case ConnectorKind::kMirror: st.own = {s, x.m, 1.0}; break;
    case ConnectorKind::kManifold: st.own = {s, x.m, manifold_rate(key, s + x.m, k)}; break;  // run for that share of the samples
  }
  if (!has_connectors_) return;
  // --- the connectors: one term each, the plain density with their constructed vertices left out ---
  mis::Technique* out = th.techniques.data();
  int& count = st.count;
  st.connectors = out;
  if (self != ConnectorKind::kDistantProjection && n - 1 >= 1 && distant_of(n - 1) >= 0 && dsd_at(0) && light_pos() > 0.0)
    out[count++] = {1, 0, 1.0 / light_pos()};
  // An x0 drawn towards x1 (an image infinite light's, a rectangle's sampled by solid angle where x1
  // could be joined) is never projected (join_sensor()), nor a connector's fresh light end, split 1
  // (fresh_light_end(), emit_manifold()): those draw light points by area.
  const bool drawn = origin_drawn_towards(x[0], x[1]);
  if (self != ConnectorKind::kOrthoProjection && n - 1 >= 1 + drawn && ortho_of(n - 1) >= 0 && dsd_at(n - 1) && cam_.pdf_pos > 0.0f)
    out[count++] = {n - 1, 0, 1.0 / cam_.pdf_pos};
  if (has_mirror_)
    for (int m = 1 + drawn; m <= k - 1; ++m)
      if (!(self == ConnectorKind::kMirror && m == s) && dsd_at(m) && mirror_of(m, k - m) >= 0 && x[m].kind == Kind::kSurface &&
          rs_.planar_mirror[static_cast<std::size_t>(x[m].shape)])
        out[count++] = {m, 1, 1.0};
  if (has_manifold_)
    for (int i = 1 + drawn; i <= k - 1; ++i) {
      const int m = s_run(i);
      if (m > 0 && !letter_s(i) && !(self == ConnectorKind::kManifold && i == s) && manifold_at(x, key, i, m)) out[count++] = {i, m, manifold_rate(key, i + m, k)};
    }
}

void Integrator::join_densities(Thread& th, const PathView& x, ConnectorKind self, const JoinDensity* join, int lo, int hi) const {
  const int s = x.s, t = x.t, n = x.size();
  // The window x[lo … hi) the weight reads, copied from the subpaths' densities as
  // store_densities() kept them once per sample (they are never changed: each join's path is its
  // own), then the ones the join changes recomputed in the copy. A fresh endpoint's: its forward
  // density, the reverse one set below.
  mis::Densities* d = th.densities.data();
  for (int v = lo; v < std::min(hi, s); ++v) d[v] = th.light_densities[static_cast<std::size_t>(v)];
  for (int v = std::max(lo, s); v < hi; ++v) d[v] = th.eye_densities[static_cast<std::size_t>(n - 1 - v)];
  if (x.light0) d[0] = {remap_density(x.light0->pdf_fwd), 1.0};
  if (x.eye0) d[n - 1] = {1.0, remap_density(x.eye0->pdf_fwd)};
  const auto needed = [&](int v) { return v >= lo && v < hi; };
  const auto set_light = [&](int v, float f) { d[v].light = remap_density(f); };  // an eye-side vertex's light density
  const auto set_eye = [&](int v, float f) { d[v].eye = remap_density(f); };      // a light-side vertex's eye density
  // --- the four reverse densities the join changes: qs = x(s-1), its predecessor qsm, pt = x_s, ptm ---
  // Every direction is at hand: the join's (w, from qs to pt, at squared distance d2) and each
  // vertex's unit direction to its predecessor (wo, at d2_wo); no normalisation is needed.
  const auto area = [](float pdf_w, const Vertex& next, const vec3& w, float dist2) {
    return dist2 > 0.0f ? pdf_w * abs_cos(next, w) / dist2 : 0.0f;
  };
  const bool has_qsm = s > 1, has_ptm = t > 1;
  if (s > 0 && t > 0) {
    const Vertex& qs = x.light_at(s - 1);  // (a plain or projection join's path has no chain)
    const Vertex& pt = x.eye_at(t - 1);
    JoinDensity own;
    if (join == nullptr) {
      const vec3 e = pt.p - qs.p;
      own.d2 = glm::dot(e, e);
      own.w = own.d2 > 0.0f ? e * (1.0f / std::sqrt(own.d2)) : vec3(0.0f);  // as the join forms it
      join = &own;
    }
    const vec3 w = join->w, back = -w;
    const float d2 = join->d2;
    const bsdf::JoinPdfs& at_qs = join->at_qs;
    const bsdf::JoinPdfs& at_pt = join->at_pt;
    // x_s as qs samples it (a projected endpoint sends a parallel beam: its density at the other
    // end is per area; an image infinite light's step has a density of its own).
    if (self == ConnectorKind::kDistantProjection) set_light(s, parallel_jacobian(pt, qs, w));
    else if (needed(s)) {
      const bool towards = qs.kind == Kind::kLight && drawn_towards(qs.light, pt);
      set_light(s, towards ? light_step_density(qs.light, qs, pt)
                           : area(at_qs.known ? at_qs.to_wi : pdf_dir(qs, has_qsm ? &qs.wo : nullptr, w), pt, w, d2));
    }
    // x(s-1) as pt samples it.
    if (self == ConnectorKind::kOrthoProjection) set_eye(s - 1, parallel_jacobian(qs, pt, w));
    else if (needed(s - 1)) set_eye(s - 1, area(at_pt.known ? at_pt.to_wi : pdf_dir(pt, has_ptm ? &pt.wo : nullptr, back), qs, w, d2));
    // x(s+1) as pt samples it, having come from qs; x(s-2) as qs does, having come from pt.
    if (has_ptm && needed(s + 1)) set_light(s + 1, area(at_pt.known ? at_pt.to_wo : pdf_dir(pt, &back, pt.wo), x.eye_at(t - 2), pt.wo, pt.d2_wo));
    if (has_qsm && needed(s - 2)) set_eye(s - 2, area(at_qs.known ? at_qs.to_wo : pdf_dir(qs, &w, qs.wo), x.light_at(s - 2), qs.wo, qs.d2_wo));
  } else if (t > 0) {  // s = 0: pt lies on an area light
    const Vertex& pt = x[0];
    const int li = rs_.light_of_shape[static_cast<std::size_t>(pt.shape)];
    set_light(0, light_origin_density(li, pt.p, pt.n, x[1]));
    if (has_ptm && needed(1)) {
      if (drawn_towards(li, x[1])) set_light(1, light_step_density(li, pt, x[1]));
      else set_light(1, area(light_pdf_dir(rs_.lights[static_cast<std::size_t>(li)], pt, pt.wo), x[1], pt.wo, pt.d2_wo));
    }
  } else if (s > 0) {  // t = 0: qs is the lens point
    const Vertex& qs = x[n - 1];
    set_eye(n - 1, cam_.pdf_pos);
    if (has_qsm && needed(n - 2)) set_eye(n - 2, area(sensor_pdf_dir(qs, qs.wo), x[n - 2], qs.wo, qs.d2_wo));
  }
}

void Integrator::path_densities(Thread& th, const PathView& x, PathKey key, int lo, int hi) const {
  // Every vertex's area density as the light walk (lf) and as the eye walk (ef) would sample it,
  // Dirac ones stored as 0 (remapped to 1), as the subpaths store them.
  const int k = x.size() - 1;
  const auto letter_s = [&](int i) { return !packed_is_d(key, i); };  // c_i is S
  const auto lf = [&](int v) -> float {
    if (v == 0) return light_origin_density(x[0].light, x[0].p, x[0].n, x[1]);
    if (v == 1 && letter_s(1) && rs_.lights[static_cast<std::size_t>(x[0].light)].pdf_pos > 0.0f)
      return parallel_jacobian(x[1], x[0], glm::normalize(x[1].p - x[0].p));  // a distant light's parallel beam
    if (letter_s(v)) return 0.0f;  // x(v-1) is a Dirac
    return pdf(v >= 2 ? &x[v - 2] : nullptr, x[v - 1], x[v]);
  };
  const auto ef = [&](int v) -> float {
    if (v == k) return cam_.pdf_pos;
    if (v == k - 1 && letter_s(k + 1) && cam_.pdf_pos > 0.0f) return parallel_jacobian(x[k - 1], x[k], glm::normalize(x[k - 1].p - x[k].p));
    if (letter_s(v + 2)) return 0.0f;  // x(v+1) is a Dirac
    return pdf(v + 2 <= k ? &x[v + 2] : nullptr, x[v + 1], x[v]);
  };
  for (int v = lo; v < hi; ++v) th.densities[static_cast<std::size_t>(v)] = mis::Densities{remap_density(lf(v)), remap_density(ef(v))};
}

float Integrator::nee_pair_weight(const PathView& x, PathKey key, const JoinDensity* join) const {
  // The other strategy, (0, t + 1) for next-event estimation, (1, t - 1) for the emitter hit, as
  // techniques() finds it: the profile runs it and its join letters are D.
  const int s = x.s;
  const std::uint64_t d_pairs = ~static_cast<std::uint64_t>(key | (key >> 1));
  if (((table_.plain_splits(x.size()) & d_pairs) >> (1 - s) & 1) == 0) return 1.0f;
  const Vertex& pt = x[s];
  if (s == 0) return accel::two_strategy_weight(pt.pdf_fwd, light_origin_density(rs_.light_of_shape[static_cast<std::size_t>(pt.shape)], pt.p, pt.n, x[1]));
  // y0 as the emitter hit would draw it: pt's BSDF density towards it, to area at y0 (as join_densities() sets it).
  const Vertex& y0 = x[0];
  const vec3 e = pt.p - y0.p;
  const float d2 = join ? join->d2 : glm::dot(e, e);
  const vec3 w = join ? join->w : d2 > 0.0f ? e * (1.0f / std::sqrt(d2)) : vec3(0.0f);
  const float dir = join && join->at_pt.known ? join->at_pt.to_wi : pdf_dir(pt, &pt.wo, -w);
  return accel::two_strategy_weight(y0.pdf_fwd, d2 > 0.0f ? dir * abs_cos(y0, w) / d2 : 0.0f);
}

float Integrator::mis_weight(Thread& th, const PathView& x, PathKey key, ConnectorKind self, const JoinDensity* join) const {
  const mis::Strategies st = techniques(th, x, key, self);
  if (st.alone()) return 1.0f;  // no other strategy samples the path: no density is needed
  int lo = 0, hi = 0;
  st.read_range(&lo, &hi);
  // th.densities[lo … hi): a plain join's from the subpaths' stored ones, a constructed path's
  // from its vertices; a chain the manifold could build changes them across it.
  const bool constructed = x.m > 0;
  if (constructed) path_densities(th, x, key, lo, hi);
  else join_densities(th, x, self, join, lo, hi);
  if (has_manifold_ && (constructed || st.count > 0)) chain_densities(th, x, key, self, lo, hi);
  return mis::weight(th.densities.data(), st, lo, hi);
}

}  // namespace pathex::tracer
