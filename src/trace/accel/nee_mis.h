// pt-nee's MIS weights: a speed-up of Integrator::mis_weight(), the one MIS routine (DESIGN §7),
// kept out of render.cpp.
//
// When the profile's plain joins at every path length n are at most the emitter hit (0, n) and
// next-event estimation (1, n - 1) (pt-nee, pt; pbrt-v4-path and mitsuba3-path where no connector
// runs), a path is weighed against one other strategy at most, and the two differ in one vertex's
// density: the point on the light (y0 for next-event estimation, z(t-1) for the emitter hit), drawn from the light (the light's pick times its point's
// area density) by next-event estimation, or by the BSDF at the eye vertex before it (solid angle,
// to area at y0) by the emitter hit. The general recurrence reaches the same two numbers through
// its masks and loops; these compute them directly, with the same operations in the same order, so
// the weights are equal bit for bit. tests/trace/mis_test.cpp (Mis.NeeFastPathEqualsTheGeneralRoutine)
// pins them equal on random paths of every sample scene.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "trace/vertex.h"

namespace pathex::accel {

// Whether the weights below apply to a profile: runs_mask[n] has bit s set when the profile runs
// the plain join (s, n - s) (Integrator::runs_mask_), and no bit other than 0 and 1 is set. (The
// caller adds: no connector runs, and t >= 2, so that the other strategy's eye vertex is a surface.)
template <std::size_t N>
bool nee_mis_applies(const std::array<std::uint64_t, N>& runs_mask) {
  for (const std::uint64_t m : runs_mask)
    if ((m & ~std::uint64_t{3}) != 0) return false;
  return true;
}

// The power heuristic of the strategy that drew a vertex with area density `own` against the one
// other strategy that would have drawn it with `other` (Dirac densities, stored as 0, count as 1:
// tracer::remap_density()). As the general recurrence forms it: the ratio, its square, 1 / (1 + sum).
inline float two_strategy_weight(float other, float own) {
  const double r = tracer::remap_density(other) / tracer::remap_density(own);
  const double sum = r * r;
  return static_cast<float>(1.0 / (1.0 + sum));
}

// Next-event estimation (1, t), t >= 2: light point `y0` (its pdf_fwd: as the light drew it),
// joined along unit w (from y0 to the eye vertex) over squared distance d2 to the eye vertex, whose
// BSDF samples the direction towards y0 with solid-angle density `pdf_dir`. The emitter hit
// (0, t + 1) would have drawn y0 with that density converted to area at y0.
inline float nee_weight(const tracer::Vertex& y0, float pdf_dir, const tracer::vec3& w, float d2) {
  const float hit = d2 > 0.0f ? pdf_dir * tracer::abs_cos(y0, w) / d2 : 0.0f;
  return two_strategy_weight(hit, y0.pdf_fwd);
}

// The emitter hit (0, t), t >= 2: eye vertex `on_light` on an area light (its pdf_fwd: as the BSDF
// drew it); next-event estimation (1, t - 1) would have drawn that point with area density
// `pdf_origin` (the light's pick times its point's density).
inline float emitter_hit_weight(const tracer::Vertex& on_light, float pdf_origin) {
  return two_strategy_weight(pdf_origin, on_light.pdf_fwd);
}

}  // namespace pathex::accel
