// The plain joins (s, DD, t) of DESIGN §4 and the two projection connectors (distant (0, DSD, t),
// orthographic (s, DSD, 0)), each a function from the two subpaths to the JoinResult in th.join
// (trace/joins/join.h; true when it made one), which the estimator (render.cpp) weighs and records.
#include <cmath>

#include "trace/bsdf.h"
#include "trace/integrator.h"
#include "trace/media.h"

namespace pathex::tracer {
vec3 Integrator::end_f(const Vertex& v, const vec3& w, TransportMode mode, bsdf::JoinPdfs* pdfs) const {
  // A light vertex's beta already holds its spatial emission; only the directional part is left.
  if (v.kind == Kind::kLight) return vec3(directional_emission(rs_.lights[static_cast<std::size_t>(v.light)].params, v.n, w));
  MaterialScratch textured;
  const Material& m = material_at(v, &textured);
  const vec3 f = pdfs ? bsdf::eval(m, v.wo, w, v.ns, v.n, pdfs, mode) : bsdf::eval(m, v.wo, w, v.ns, v.n, mode);
  // The light end carries importance: shading normals make its transport asymmetric (Veach §5.3).
  // (1 where the shading normal is the geometric one; the test saves the call.)
  return mode == TransportMode::kImportance && v.ns != v.n ? f * bsdf::shading_normal_correction(v.wo, w, v.ns, v.n, mode) : f;
}

bool Integrator::end_join(Thread& th, vec3 contrib, PathKey chain_s, const Vertex* from, const Vertex* to) const {
  JoinResult& jr = th.join;
  // Beer–Lambert along the joining segment (trace/media.h).
  if (absorbing_ && from != nullptr) contrib *= segment_transmittance(*from, to->p, rs_.absorption_of_shape);
  if (is_black(contrib)) {
    if (jr.chain != ConnectorKind::kNone) ++th.connectors[static_cast<std::size_t>(jr.strategy)].no_transport;
    return false;
  }
  if (!th.joins_ready) set_masks(th, th.ns, th.nt);
  jr.letters = path_key(th, jr.s, jr.t, jr.fresh()) | chain_s;
  jr.contribution = contrib;
  // No segment to test when the path's last edge was traced (an eye path on a light, a light
  // path on the lens); else the shadow ray between the join's two ends.
  jr.num_segments = from ? 1 : 0;
  jr.segments[0] = {from, to};
  return true;
}

Vertex& Integrator::sensor_vertex(Vertex& z, const vec3& p, const vec3& n, char letter) const {
  z = Vertex{};
  z.kind = Kind::kCamera;
  z.p = p;
  z.n = cam_.pdf_pos == 0.0f ? vec3(0.0f) : n;  // a pinhole is a point
  z.ns = z.n;
  z.letter = letter;
  z.pos_letter = cam_.letters[1];
  z.pdf_fwd = cam_.pdf_pos;
  return z;
}

Vertex& Integrator::light_vertex(Vertex& y, std::size_t li, const vec3& p, const vec3& n, const vec3& err, char letter) const {
  y = Vertex{};
  y.kind = Kind::kLight;
  y.light = static_cast<int>(li);
  y.pos_letter = rs_.lights[li].letters[0];
  y.letter = letter;
  y.p = p;
  y.n = n;
  y.ns = n;
  y.err = err;
  y.pdf_fwd = light_pick_ * rs_.lights[li].pdf_pos;  // 0 for Dirac positions
  return y;
}

bool Integrator::join_emitter(Thread& th, int t) const {
  const Vertex& pt = th.eye[static_cast<std::size_t>(t - 1)];
  if (pt.kind != Kind::kSurface) return false;
  const int hit_light = rs_.light_of_shape[static_cast<std::size_t>(pt.shape)];
  if (hit_light < 0) return false;
  th.join.begin(ConnectorKind::kNone, 0, t, strategy(0, t));
  return end_join(th, pt.beta * emitted(rs_.lights[static_cast<std::size_t>(hit_light)].params, pt.n, pt.wo), 0, nullptr, nullptr);
}

bool Integrator::join_lens(Thread& th, int s) const {
  const Vertex& qs = th.light[static_cast<std::size_t>(s - 1)];
  if (qs.kind != Kind::kLens) return false;
  glm::vec2 raster;
  const vec3 we = importance(cam_.params, qs.p, qs.wo, &raster);
  if (is_black(we)) return false;
  th.join.begin(ConnectorKind::kNone, s, 0, strategy(s, 0));
  JoinResult& jr = th.join;
  cam_.to_pixels(raster, &jr.rx, &jr.ry);
  jr.splat = true;
  return end_join(th, qs.beta * we, 0, nullptr, nullptr);
}

bool Integrator::join_sensor(Thread& th, Sampler& rng, int s, ConnectorKind kind) const {
  const Vertex* q = &th.light[static_cast<std::size_t>(s - 1)];
  if (q->kind == Kind::kLens || !q->finite) return false;
  const bool ortho = kind == ConnectorKind::kOrthoProjection;
  join_numbers(rng, ortho ? JoinBlock::kOrtho : JoinBlock::kSplat, s);
  const bool env = q->kind == Kind::kLight && rs_.lights[static_cast<std::size_t>(q->light)].environment() != nullptr;
  // A Dirac direction (orthographic, spot meter) has no DD join; the connector's c(k+1) c(k+2) are
  // a Dirac direction from a film. (No projection of an image light: mis_weight.cpp.)
  if (ortho ? env || cam_.letters != "SD" : cam_.letters[0] != 'D') return false;
  // (The splat's sensor point has a finite direction: a light drawn towards points draws y0 towards it.)
  const bool towards = !ortho && q->kind == Kind::kLight && rs_.lights[static_cast<std::size_t>(q->light)].drawn_towards(true);
  th.join.begin(kind, s, 1, ortho ? ortho_of(s) : strategy(s, 1));
  if (ortho) ++th.connectors[static_cast<std::size_t>(th.join.strategy)].attempts;
  const glm::vec2 ul = ortho ? glm::vec2(0.0f) : rng.get2d_if(reads_lens_numbers(cam_.params));
  if (towards) {
    // A light seen directly whose points are drawn towards the point they join (an image infinite
    // light, a rectangle sampled by solid angle): its point is drawn towards the sensor point, as
    // next-event estimation draws it (the light density its x0 has), not the light subpath's y0.
    const std::size_t li = static_cast<std::size_t>(q->light);
    const std::optional<EndpointConnection> e = connect_towards(rs_.lights[li].params, rng.get2d(), sensor_point(cam_.params, ul));
    if (!e) return false;
    Vertex& y0 = fresh_light_vertex(th, li, e->position, e->normal, rs_.lights[li].towards_point_error(e->position), 'D');
    y0.pdf_fwd = light_pick_ * towards_area_density(*e);
    // L / (pick p |cos θ_x| / d²): the join's |cos θ_x| and We cos / d² complete L We cos / (pick p).
    y0.beta = y0.pdf_fwd > 0.0f ? e->value / y0.pdf_fwd : vec3(0.0f);
    q = &y0;
  }
  // The sensor point: a fresh one, or the film point on the line of sight (made in place: an
  // optional assigned later would be zero-filled first).
  const std::optional<EndpointConnection> c = ortho ? connect_projection(cam_.params, q->p) : connect_finite(cam_.params, ul, q->p);
  if (!c) {
    if (ortho) ++th.connectors[static_cast<std::size_t>(th.join.strategy)].outside;
    return false;
  }
  JoinResult& jr = th.join;
  const Vertex& qs = *q;
  const Vertex& z0 = fresh_sensor_vertex(th, *c, ortho ? cam_.letters[0] : 'D');
  const vec3 w = c->wi;  // from qs to the sensor
  cam_.to_pixels(c->raster, &jr.rx, &jr.ry);
  jr.splat = true;
  const vec3 fq = end_f(qs, w, TransportMode::kImportance, &jr.density.at_qs);
  jr.density.w = w;
  jr.density.d2 = c->distance * c->distance;
  jr.has_density = true;
  // weight: We cos / d² (splat), We (film); an ortho path's S letter is c(k+1), the sensor's direction.
  return end_join(th, qs.beta * fq * (shading_cos(qs, w) * c->weight), ortho ? bit(s + 1) : 0, &qs, &z0);
}

bool Integrator::join_light(Thread& th, Sampler& rng, int t, ConnectorKind kind) const {
  const Vertex& pt = th.eye[static_cast<std::size_t>(t - 1)];
  if (pt.kind != Kind::kSurface || !pt.finite || rs_.lights.empty()) return false;
  const bool distant = kind == ConnectorKind::kDistantProjection;
  join_numbers(rng, distant ? JoinBlock::kDistant : JoinBlock::kNee, t);
  const std::size_t li = rs_.pick_light(rng);
  const RenderLight& l = rs_.lights[li];
  // The eye end pt can be joined: a light drawn towards points draws its point towards pt.
  const bool towards = !distant && l.drawn_towards(true);
  // Dirac directions (distant, laser) have no DD join; the connector's c0 c1 are a Dirac direction
  // from an aperture.
  if (distant ? l.letters != "DS" : !towards && l.letters[1] != 'D') return false;
  th.join.begin(kind, 1, t, distant ? distant_of(t) : strategy(1, t));
  if (distant) ++th.connectors[static_cast<std::size_t>(th.join.strategy)].attempts;
  vec3 err{0.0f};  // the light point's rounding-error bound, which offsets the shadow ray
  // The light point: the aperture point on the line (distant), a point drawn towards pt (a
  // direction from an image infinite light's image, a rectangle's by solid angle), or a point of
  // the light. (Made in place: an optional assigned later would be zero-filled first.)
  const std::optional<EndpointConnection> c = distant   ? connect_projection(l.params, pt.p)
                                              : towards ? connect_towards(l.params, rng.get2d(), pt.p)
                                                        : pathex::connect(l.params, rs_.sample_point(l, rng, &err), pt.p);
  if (!c) {
    if (distant) ++th.connectors[static_cast<std::size_t>(th.join.strategy)].outside;
    return false;
  }
  if (distant) err = l.origin_error;
  else if (towards) err = l.towards_point_error(c->position);
  JoinResult& jr = th.join;
  Vertex& y0 = fresh_light_vertex(th, li, c->position, c->normal, err, distant ? l.letters[1] : 'D');
  if (towards) y0.pdf_fwd = light_pick_ * towards_area_density(*c);
  const vec3 w = c->wi;  // from pt to the light
  const vec3 f = end_f(pt, w, TransportMode::kRadiance, &jr.density.at_pt);
  jr.density.w = -w;  // w runs from pt to the light, the join's from the light to pt
  jr.density.d2 = c->distance * c->distance;
  jr.has_density = true;
  // weight: Le cos / (p d²), I / d², E; a distant path's S letter is c1, the light's direction.
  return end_join(th, pt.beta * f * (shading_cos(pt, w) / light_pick_) * c->weight, distant ? bit(1) : 0, &pt, &y0);
}

bool Integrator::join_shadow(Thread& th, int s, int t) const {
  const Vertex& qs = th.light[static_cast<std::size_t>(s - 1)];
  const Vertex& pt = th.eye[static_cast<std::size_t>(t - 1)];
  if (qs.kind != Kind::kSurface || pt.kind != Kind::kSurface || !qs.finite || !pt.finite) return false;
  const vec3 d = pt.p - qs.p;
  const float d2 = glm::dot(d, d);
  if (d2 <= 0.0f) return false;
  th.join.begin(ConnectorKind::kNone, s, t, strategy(s, t));
  JoinResult& jr = th.join;
  const vec3 w = d * (1.0f / std::sqrt(d2));  // one division, not three
  const vec3 fq = end_f(qs, w, TransportMode::kImportance, &jr.density.at_qs);
  const vec3 fp = end_f(pt, -w, TransportMode::kRadiance, &jr.density.at_pt);
  jr.density.w = w;
  jr.density.d2 = d2;
  jr.has_density = true;
  const float g = shading_cos(qs, w) * shading_cos(pt, w) / d2;
  return end_join(th, qs.beta * fq * fp * pt.beta * g, 0, &qs, &pt);
}

}  // namespace pathex::tracer
