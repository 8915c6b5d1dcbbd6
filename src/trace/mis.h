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
#include <bit>
#include <cstdint>
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

// Every strategy that samples a path: the one that sampled it (`own`), the other plain joins (bit
// i of `plain`: the join at split i; the own split's bit clear when own is a plain join), and the
// connectors (the first `count` of `connectors`, own not among them).
struct Strategies {
  Technique own;
  std::uint64_t plain = 0;
  const Technique* connectors = nullptr;
  int count = 0;
  bool alone() const { return plain == 0 && count == 0; }
  // The vertices the weight reads: x[lo … hi), from the smallest split to the largest split +
  // constructed (the caller fills that range of x).
  void read_range(int* lo, int* hi) const {
    *lo = own.split;
    *hi = own.split + own.constructed;
    if (plain != 0) {
      *lo = std::min(*lo, std::countr_zero(plain));
      *hi = std::max(*hi, 63 - std::countl_zero(plain));
    }
    for (int i = 0; i < count; ++i) {
      *lo = std::min(*lo, connectors[i].split);
      *hi = std::max(*hi, connectors[i].split + connectors[i].constructed);
    }
  }
};

// The power-heuristic weight of st.own among the strategies `st`, from the densities x[v] of the
// path's vertices x0 … xk, of which only [lo, hi) are read (read_range()). 0 when the sum is not
// finite (a density overflowed: no weight rather than NaN).
inline float weight(const Densities* x, const Strategies& st, int lo, int hi) {
  if (st.alone()) return 1.0f;
  // rel(i) = P_i / P_b for the own split b, outwards from b one vertex's ratio at a time; the
  // plain joins' terms are summed on the way, and rel kept for the connectors when there are any.
  const Technique& own = st.own;
  const int b = own.split;
  double rel[kMaxPath + 1];
  const bool keep = st.count > 0;
  if (keep) rel[b - lo] = 1.0;
  // A technique's density relative to P_b: a connector's constructed vertices are not sampled by
  // the eye walk, and a projection carries its factor.
  const auto density = [&](const Technique& c, double r) {
    double d = r * c.factor;
    for (int v = c.split; v < c.split + c.constructed; ++v) d /= x[v].eye;
    return d;
  };
  const double scale = own.constructed == 0 && own.factor == 1.0 ? 1.0 : 1.0 / density(own, 1.0);
  const double scale2 = scale * scale;
  double plain_sum = 0.0;
  double r = 1.0;
  for (int i = b + 1; i <= hi; ++i) {
    r *= x[i - 1].light / x[i - 1].eye;
    if (keep) rel[i - lo] = r;
    if ((st.plain >> i) & 1) plain_sum += r * r;
  }
  r = 1.0;
  for (int i = b - 1; i >= lo; --i) {
    r *= x[i].eye / x[i].light;
    if (keep) rel[i - lo] = r;
    if ((st.plain >> i) & 1) plain_sum += r * r;
  }
  double sum = 1.0 + plain_sum * scale2;
  for (int i = 0; i < st.count; ++i) {
    const Technique& c = st.connectors[i];
    const double d = density(c, rel[c.split - lo]) * scale;
    sum += d * d;
  }
  return std::isfinite(sum) ? static_cast<float>(1.0 / sum) : 0.0f;
}

}  // namespace pathex::tracer::mis
