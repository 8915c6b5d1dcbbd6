// The mirror connector (s, DSD, t) of DESIGN §4: y(s-1) (or a fresh light sample) joined to z(t-1)
// (or a fresh sensor sample) across each planar mirror by the image method (trace/joins/mirror.h
// for the geometry), one JoinResult per mirror that the straight line to the image meets.
#include "trace/media.h"
#include "trace/integrator.h"
#include "trace/joins/mirror.h"

namespace pathex::tracer {

void Integrator::connect_mirror(Thread& th, Sampler& rng, int s, int t, int batch) const {
  const int strategy_index = mirror_of(s, t);
  ConnectorStats& stats = th.connectors[static_cast<std::size_t>(strategy_index)];
  // Random numbers: a fresh light sample's from one block per t, a fresh sensor sample's from one
  // block per s.
  // --- the light end a: y(s-1), or a fresh light sample ---
  const Vertex* a = s >= 2 ? &th.light[static_cast<std::size_t>(s - 1)] : fresh_light_end(th, rng, t, JoinBlock::kMirrorLight);
  if (!a || (s >= 2 && (a->kind != Kind::kSurface || !a->finite))) return;
  // --- the eye end b: z(t-1), or (t = 1) a fresh sensor sample drawn per mirror ---
  const Vertex* b = t >= 2 ? &th.eye[static_cast<std::size_t>(t - 1)] : nullptr;
  glm::vec2 u_lens{0.0f};
  if (b) {
    if (b->kind != Kind::kSurface || !b->finite) return;
  } else {
    if (cam_.letters[0] != 'D') return;  // a Dirac direction (orthographic, spot meter): no D end
    join_numbers(rng, JoinBlock::kMirrorEye, s);
    u_lens = rng.get2d_if(reads_lens_numbers(cam_.params));
  }
  const PathKey key = chain_key(th, *a, s, t, 1);
  for (const PlanarMirror& mirror : rs_.mirrors) {
    ++stats.attempts;
    std::optional<EndpointConnection> c;  // t = 1: the sensor's join to a's image
    if (t == 1) {
      c = connect_finite(cam_.params, u_lens, mirror_image(mirror, a->p));
      if (!c) {
        ++stats.outside;
        continue;
      }
      b = &fresh_sensor_vertex(th, *c, 'D');
    }
    const std::optional<MirrorJoin> j = mirror_join(mirror, a->p, b->p);
    if (!j) {
      ++stats.outside;  // off the mirror, or the ends on different sides of its plane
      continue;
    }
    // f at a towards the mirror: the light's directional emission, or the BSDF.
    const vec3 fa = end_f(*a, j->w_a, TransportMode::kImportance);
    // Across the mirror the geometry term is the straight one to the image: |cos_a| |cos_b| / D².
    vec3 contrib = a->beta * fa * mirror.reflectance * shading_cos(*a, j->w_a);
    if (t == 1) {
      contrib *= c->weight;  // We cos / (p D²), D = |a' − sensor point|
    } else {
      const vec3 fb = end_f(*b, j->w_b, TransportMode::kRadiance);
      contrib *= fb * b->beta * (shading_cos(*b, j->w_b) / (j->unfolded * j->unfolded));
    }
    // Both legs lie in the medium a's leg starts in (a mirror has no interior: trace/media.h).
    if (absorbing_) contrib *= beer_lambert(segment_absorption(*a, j->w_a, rs_.absorption_of_shape), glm::length(j->point - a->p) + glm::length(j->point - b->p));
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
    jr.set_connector(ConnectorKind::kMirror, s, t, strategy_index, key, contrib, 1, a, b);
    jr.splat = t == 1;
    if (jr.splat) cam_.to_pixels(c->raster, &jr.rx, &jr.ry);
    estimate(th, batch);
  }
}

const Vertex* Integrator::fresh_light_end(Thread& th, Sampler& rng, int t, JoinBlock block) const {
  if (rs_.lights.empty()) return nullptr;
  join_numbers(rng, block, t);
  const std::size_t li = rs_.pick_light(rng);
  const RenderLight& light = rs_.lights[li];
  if (light.letters[1] != 'D') return nullptr;  // a Dirac direction (distant, laser): no D end
  if (light.environment()) return nullptr;  // an image light's points are drawn towards a point (mis_weight.cpp skips these)
  vec3 err{0.0f};
  const SurfacePoint x = rs_.sample_point(light, rng, &err);
  Vertex& y0 = fresh_light_vertex(th, li, light.is_area() ? x.position : fixed_origin(light.params),
                                  light.is_area() ? x.normal : vec3(0.0f), err, 'D');
  y0.beta = spatial_emission(light.params) / (light_pick_ * (light.pdf_pos > 0.0f ? light.pdf_pos : 1.0f));
  return &y0;
}

PathKey Integrator::chain_key(Thread& th, const Vertex& a, int s, int t, int m) const {
  if (!th.joins_ready) set_masks(th, th.ns, th.nt);
  // The letters: a's c(s) = D, the chain's c(s+1) … c(s+m) = S, b's c(s+m+1) = D.
  const PathKey light_part = s == 1 ? letter_bit(a.pos_letter, 0) : th.light_mask & (bit(s) - 1);
  PathKey key = light_part | ((th.eye_masks[static_cast<std::size_t>(t)] << (s + m + 1)) & ~bit(s + m + 1)) |
                static_cast<PathKey>(s + t + m + 2) << kLengthShift;
  for (int i = 1; i <= m; ++i) key |= bit(s + i);
  return key;
}

}  // namespace pathex::tracer
