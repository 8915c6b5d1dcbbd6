// The manifold walk's seed (trace/specular_seed.h).
#include "trace/specular_seed.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "optics/fresnel.h"
#include "trace/bsdf.h"
#include "trace/frame.h"
#include "trace/joins/join.h"
#include "trace/rng.h"

namespace pathex::tracer {

ManifoldFailure seed_chain(const RenderScene& rs, const Vertex& from, bool from_light, std::uint64_t stream, std::uint64_t* drawn,
                           std::vector<ChainVertex>& chain) {
  const auto u = [&] { return bits_to_unit_float(stream_bits(stream, (*drawn)++)); };
  chain.clear();
  const float u_shape = u();
  const glm::vec2 u_point(u(), u());
  const std::size_t pick = static_cast<std::size_t>(std::upper_bound(rs.specular.seed_cdf.begin(), rs.specular.seed_cdf.end() - 1, u_shape) - rs.specular.seed_cdf.begin());
  const int shape = rs.specular.shapes[pick];
  vec3 o = from.p, no = from.n, eo = from.err;
  vec3 d;
  const auto* sphere = std::get_if<SphereShape>(&rs.geometry->shape_geometry(shape));
  const vec3 to_centre = sphere ? sphere->center - from.p : vec3(0.0f);
  const float d2 = glm::dot(to_centre, to_centre);
  if (sphere && d2 > sphere->radius * sphere->radius) {
    // A sphere seen from outside: a direction uniform in the cone it subtends, so every seed meets it.
    const float cos_max = std::sqrt(std::max(0.0f, 1.0f - sphere->radius * sphere->radius / d2));
    d = Frame::from_normal(to_centre / std::sqrt(d2)).to_world(sample_uniform_cone(u_point, cos_max));
  } else {  // otherwise towards a point uniform on the shape's area
    d = rs.geometry->sample_shape(shape, u_point).position - from.p;
    if (!(glm::dot(d, d) > 0.0f)) return ManifoldFailure::kNoSolution;
  }
  d = glm::normalize(d);
  // The sphere the ray meets next without a ray traced: the cone's, entered at the near root (what
  // lies before it the chain's shadow rays see), then a hollow one it runs inside
  // (SpecularSurfaces::hollow), left at t = -2 (o - c)·d.
  int within = sphere && d2 > sphere->radius * sphere->radius ? shape : -1;
  bool entering = within >= 0;
  for (;;) {
    std::optional<Hit> hit;
    if (within >= 0) {
      const SphereShape& ball = std::get<SphereShape>(rs.geometry->shape_geometry(within));
      const vec3 f = o - ball.center, across = f - glm::dot(f, d) * d;
      const float t = entering ? -glm::dot(f, d) - std::sqrt(std::max(0.0f, ball.radius * ball.radius - glm::dot(across, across))) : -2.0f * glm::dot(f, d);
      hit = Hit{.position = vec3(0.0f), .normal = glm::normalize(f + t * d), .shape = within, .primitive = 0};
      hit->position = ball.center + ball.radius * hit->normal;
      entering = false;
      hit->error = error_gamma(8) * (glm::abs(ball.center) + ball.radius * glm::abs(hit->normal));  // EmbreeScene's sphere hit's
    } else {
      hit = rs.geometry->intersect(o, d, no, eo, HitDetail::kNoUv);
    }
    if (!hit) break;
    const float ior = rs.specular.glass_ior[static_cast<std::size_t>(hit->shape)];
    const bool mirror = !is_black(rs.specular.mirror_reflectance[static_cast<std::size_t>(hit->shape)]);
    if (ior == 0.0f && !mirror) {
      if (chain.empty()) return ManifoldFailure::kOccluded;  // something opaque between the end and the specular surfaces
      break;
    }
    if (static_cast<int>(chain.size()) == kMaxChain) return ManifoldFailure::kNoSolution;
    // Follow the surface as light would: a mirror reflects; glass reflects with the Fresnel
    // probability (always under total internal reflection), else refracts.
    const float cos_o = -glm::dot(d, hit->normal);
    const bool reflect = mirror || u() < bsdf::fresnel_dielectric(cos_o, ior);
    const double outside = 1.0, inside = ior > 0.0f ? static_cast<double>(ior) : 1.0;
    const double came = cos_o > 0.0f ? outside : inside;                    // the index where the ray came from
    const double goes = reflect ? came : (cos_o > 0.0f ? inside : outside);  // and where it goes on
    const int came_side = cos_o > 0.0f ? 1 : -1, goes_side = reflect ? came_side : -came_side;
    chain.push_back({&rs.geometry->shape_geometry(hit->shape), hit->shape, hit->primitive, inside, from_light ? came : goes,
                     from_light ? goes : came, reflect, glm::dvec3(hit->position), from_light ? came_side : goes_side});
    const vec3 n_side = cos_o > 0.0f ? hit->normal : -hit->normal;  // towards where d came from
    if (reflect) {
      d = glm::normalize(d + 2.0f * std::fabs(cos_o) * n_side);
    } else {
      const float eta = cos_o > 0.0f ? 1.0f / ior : ior;  // η_from / η_to
      const float sin2_t = eta * eta * std::max(0.0f, 1.0f - cos_o * cos_o);
      if (sin2_t >= 1.0f) return ManifoldFailure::kNoSolution;  // (Fresnel gave 1: not reached)
      d = glm::normalize(eta * d + (eta * std::fabs(cos_o) - std::sqrt(1.0f - sin2_t)) * n_side);
    }
    o = hit->position;
    no = hit->normal;
    eo = hit->error;
    within = rs.specular.hollow[static_cast<std::size_t>(hit->shape)] && glm::dot(d, hit->normal) < 0.0f ? hit->shape : -1;
    // The chain ends where the ray meets no more specular surfaces: when it passes every specular
    // shape's bounding sphere by (a sphere it leaves outwards it cannot meet again), the ray that
    // would find the opaque surface or nothing beyond is not traced.
    if (!rs.specular.meets(*rs.geometry, o, d, glm::dot(d, hit->normal) > 0.0f ? hit->shape : -1)) break;
  }
  if (chain.empty()) return ManifoldFailure::kNoSolution;
  if (!from_light) std::reverse(chain.begin(), chain.end());  // light side first
  return ManifoldFailure::kNone;
}

}  // namespace pathex::tracer
