// pt-nee's MIS weight: a speed-up of the one MIS routine (trace/mis.h), kept out of the estimator.
//
// When the profile's plain joins at every path length n are at most the emitter hit (0, n) and
// next-event estimation (1, n - 1), and no connector runs (pt-nee, pt; pbrt-v4-path and
// mitsuba3-path where their distant connector cannot), a join with t >= 2 is weighed against one
// other strategy at most, and the two differ in one vertex's density: the point on the light (y0
// for next-event estimation, z(t-1) for the emitter hit), drawn from the light (its pick times its
// point's density) by next-event estimation, or by the BSDF at the eye vertex before it (solid
// angle, to area at the point) by the emitter hit. The general routine reaches the same two numbers
// through the strategy list, a window of densities and its loops (~400 instructions a weight,
// bench/README.md "Issue 37, tenth session"); Integrator::nee_pair_weight() computes them directly
// with the same operations in the same order, so the weights are equal bit for bit.
// tests/trace/mis_test.cpp (Mis.PathTracerWeightsAreTheTwoStrategyPowerHeuristic) pins them to
// Integrator::mis_weight() on random paths of every sample scene.
#pragma once

#include <cmath>
#include <cstdint>

#include "trace/strategy_table.h"
#include "trace/vertex.h"

namespace pathex::accel {

// Whether the weights below apply to a profile: no connector runs, and no plain join (s, n - s)
// with s >= 2 (the caller adds: t >= 2, so that the other strategy's eye vertex is a surface).
inline bool nee_pair_only(const StrategyTable& table, bool connectors) {
  bool only = !connectors;
  for (int n = 0; n < StrategyTable::kMaxSplits; ++n) only = only && (table.plain_splits(n) & ~std::uint64_t{3}) == 0;
  return only;
}

// The power heuristic of the strategy that drew a vertex with area density `own` against the one
// other strategy that would have drawn it with `other` (Dirac densities, stored as 0, count as 1),
// as mis::weight() forms it for two adjacent splits: the ratio, 1 + its square (the plain sum
// 0 + r² is r², never -0; the scale is 1), 1 / that, and no weight when it is not finite.
inline float two_strategy_weight(float own, float other) {
  const double r = tracer::remap_density(other) / tracer::remap_density(own);
  const double sum = 1.0 + r * r;
  return std::isfinite(sum) ? static_cast<float>(1.0 / sum) : 0.0f;
}

}  // namespace pathex::accel
