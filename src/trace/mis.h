// The one MIS weight of the tracer (DESIGN §7): the power heuristic of the strategy that sampled a
// full path against every strategy of the profile that could have sampled the same path, computed
// from each vertex's two area densities, as pbrt-v4's MISWeight (bdpt.cpp) computes it.
//
// A full path x0 … xk has, at every vertex, the density with which the light walk samples it (from
// x(i-1), or the light's own for x0) and the density with which the eye walk samples it (from
// x(i+1), or the sensor's own for xk). A plain join at split i (light vertices x0 … x(i-1), eye
// vertices xi … xk) samples the path with density P_i = Π_{v<i} light(v) · Π_{v>=i} eye(v). A
// connector is the same product with the vertices it constructs left out (the mirror's vertex, the
// manifold's specular chain) and, for a projection, the projected endpoint's position density
// divided out: one more term of the same sum, not a routine of its own. Dirac densities are kept
// symbolic (stored as 0 by the walks, counted as 1 here); the strategies they rule out are not in
// the list, which the caller builds from the path's letters.
//
// The weight reads only the densities between the two strategies farthest apart, so that a path
// only two strategies sample (pt-nee's) reads the one vertex where they differ.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>

namespace pathex::tracer::mis {

// Vertex x_i's area densities: as the light walk samples it (`light`) and as the eye walk does
// (`eye`), Dirac densities counted as 1 (tracer::remap_density()).
struct Densities {
  double light = 1.0;
  double eye = 1.0;
};

// A strategy that samples the path: the light walk up to x(split-1), the eye walk from
// x(split + constructed) on, the `constructed` vertices between them built by a connector (0 for
// a plain join), times `factor` (a projection's 1 / the projected endpoint's position density).
struct Technique {
  int split = 0;
  int constructed = 0;
  double factor = 1.0;
};

// The longest full path (vertices): 2 * kMaxVertices (trace/vertex.h) bounds every join's.
inline constexpr int kMaxPath = 128;

// The power-heuristic weight of techniques[0] among techniques[0 … count) (every strategy that
// samples the path, each once), from the densities x[v] of the path's vertices. Reads x only
// between the smallest split and the largest split + constructed (the caller fills that range:
// read_range()). 0 when the sum is not finite (a density overflowed: no weight rather than NaN).
inline void read_range(const Technique* techniques, int count, int* lo, int* hi) {
  *lo = techniques[0].split;
  *hi = techniques[0].split + techniques[0].constructed;
  for (int i = 1; i < count; ++i) {
    *lo = std::min(*lo, techniques[i].split);
    *hi = std::max(*hi, techniques[i].split + techniques[i].constructed);
  }
}

inline float weight(const Densities* x, const Technique* techniques, int count) {
  if (count == 1) return 1.0f;
  int lo = 0, hi = 0;
  read_range(techniques, count, &lo, &hi);
  // rel[i - lo] = P_i / P_b for the own split b: outwards from b, one vertex's ratio at a time.
  const int b = techniques[0].split;
  double rel[kMaxPath + 1];
  rel[b - lo] = 1.0;
  for (int i = b + 1; i <= hi; ++i) rel[i - lo] = rel[i - 1 - lo] * x[i - 1].light / x[i - 1].eye;
  for (int i = b - 1; i >= lo; --i) rel[i - lo] = rel[i + 1 - lo] * x[i].eye / x[i].light;
  const auto density = [&](const Technique& c) {  // relative to P_b
    double d = rel[c.split - lo] * c.factor;
    for (int v = c.split; v < c.split + c.constructed; ++v) d /= x[v].eye;
    return d;
  };
  const double own = density(techniques[0]);
  double sum = 1.0;
  for (int i = 1; i < count; ++i) {
    const double r = density(techniques[i]) / own;
    sum += r * r;
  }
  return std::isfinite(sum) ? static_cast<float>(1.0 / sum) : 0.0f;
}

}  // namespace pathex::tracer::mis
