// Loop subdivision (loop_subdivision.h). Each level works on plain arrays: the mesh's edges (in
// the order the triangles first meet them, with the vertices opposite them) and every vertex's
// one-ring in pbrt's order, from which the even and odd rules, the limit and the tangents read.
#include "scene/loop_subdivision.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

namespace pathex::import {
namespace {

using glm::vec3;

std::uint64_t key(std::uint32_t a, std::uint32_t b) { return (static_cast<std::uint64_t>(a) << 32) | b; }

struct Edge {
  std::uint32_t a = 0, b = 0;               // a < b
  std::int64_t c = -1, d = -1;              // the opposite vertex in the first and the second triangle (-1: boundary)
};

// The edges of `tris`, numbered in the order the triangles first meet them; `edge_of[3 f + k]` is
// the number of triangle f's edge from corner k to corner k + 1.
struct Edges {
  std::vector<Edge> list;
  std::vector<std::uint32_t> edge_of;
};

Edges edges_of(const std::vector<glm::uvec3>& tris) {
  Edges e;
  std::unordered_map<std::uint64_t, std::uint32_t> id;
  id.reserve(tris.size() * 2);
  e.edge_of.resize(tris.size() * 3);
  for (std::size_t f = 0; f < tris.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = tris[f][k], b = tris[f][(k + 1) % 3], c = tris[f][(k + 2) % 3];
      auto [it, fresh] = id.try_emplace(key(std::min(a, b), std::max(a, b)), static_cast<std::uint32_t>(e.list.size()));
      if (fresh) e.list.push_back({std::min(a, b), std::max(a, b), c, -1});
      else e.list[it->second].d = c;
      e.edge_of[3 * f + k] = it->second;
    }
  return e;
}

// Every vertex's one-ring in pbrt's order (SDVertex::oneRing): around an interior vertex, each
// triangle's next vertex after it, stepping to the triangle across the edge to that vertex; around
// a boundary vertex, from the last boundary neighbour back to the first. `ok` is false when a
// vertex has no triangle or several fans.
struct Rings {
  std::vector<std::uint32_t> offset;  // vertex v's ring is ring[offset[v] .. offset[v + 1])
  std::vector<std::uint32_t> ring;
  std::vector<char> boundary;
  std::int64_t bad_vertex = -1, lonely_vertex = -1;
};

Rings rings_of(std::size_t vertices, const std::vector<glm::uvec3>& tris) {
  // Corners per vertex: (previous, next) around each triangle, sorted by the previous vertex.
  std::vector<std::uint32_t> count(vertices + 1, 0);
  for (const glm::uvec3& t : tris)
    for (int k = 0; k < 3; ++k) ++count[t[k] + 1];
  for (std::size_t v = 0; v < vertices; ++v) count[v + 1] += count[v];
  std::vector<std::pair<std::uint32_t, std::uint32_t>> corner(tris.size() * 3);
  std::vector<std::uint32_t> fill(count.begin(), count.end() - 1);
  for (const glm::uvec3& t : tris)
    for (int k = 0; k < 3; ++k) corner[fill[t[k]]++] = {t[(k + 2) % 3], t[(k + 1) % 3]};
  Rings r;
  r.offset.assign(vertices + 1, 0);
  r.boundary.assign(vertices, 0);
  r.ring.reserve(tris.size() * 3 + vertices);
  std::vector<std::uint32_t> walk;
  for (std::size_t v = 0; v < vertices; ++v) {
    r.offset[v] = static_cast<std::uint32_t>(r.ring.size());
    auto first = corner.begin() + count[v], last = corner.begin() + count[v + 1];
    const std::size_t n = static_cast<std::size_t>(last - first);
    if (n == 0) {
      if (r.lonely_vertex < 0) r.lonely_vertex = static_cast<std::int64_t>(v);
      continue;
    }
    std::sort(first, last);
    std::vector<std::uint32_t> nexts;
    nexts.reserve(n);
    for (auto it = first; it != last; ++it) nexts.push_back(it->second);
    std::sort(nexts.begin(), nexts.end());
    // A boundary fan starts at a corner whose previous vertex is no corner's next.
    std::size_t starts = 0;
    std::uint32_t start = first->first;
    for (auto it = first; it != last; ++it)
      if (!std::binary_search(nexts.begin(), nexts.end(), it->first)) {
        if (starts++ == 0) start = it->first;
      }
    const bool boundary = starts > 0;
    // s_0 = start, s_{j+1} = the next vertex of the corner whose previous vertex is s_j.
    walk.assign(1, start);
    for (std::size_t j = 0; j < n; ++j) {
      auto it = std::lower_bound(first, last, std::make_pair(walk.back(), std::uint32_t{0}));
      if (it == last || it->first != walk.back()) break;
      walk.push_back(it->second);
      if (!boundary && it->second == start) break;
    }
    const std::size_t visited = walk.size() - 1;
    if (starts > 1 || visited != n || (!boundary && walk.back() != start)) {
      if (r.bad_vertex < 0) r.bad_vertex = static_cast<std::int64_t>(v);
      continue;
    }
    r.boundary[v] = boundary;
    if (boundary) r.ring.insert(r.ring.end(), walk.rbegin(), walk.rend());  // s_m … s_0
    else r.ring.insert(r.ring.end(), walk.begin() + 1, walk.end());       // s_1 … s_m = s_0
  }
  r.offset[vertices] = static_cast<std::uint32_t>(r.ring.size());
  return r;
}

float beta(std::size_t n) { return n == 3 ? 3.0f / 16.0f : 3.0f / (8.0f * static_cast<float>(n)); }
float gamma(std::size_t n) { return 1.0f / (static_cast<float>(n) + 3.0f / (8.0f * beta(n))); }

// (1 - n w) p + w sum(ring), or for a boundary vertex (1 - 2 w) p + w (first + last).
vec3 weigh(const std::vector<vec3>& p, const Rings& r, std::size_t v, float w) {
  const std::uint32_t* ring = r.ring.data() + r.offset[v];
  const std::size_t n = r.offset[v + 1] - r.offset[v];
  if (r.boundary[v]) return (1.0f - 2.0f * w) * p[v] + w * p[ring[0]] + w * p[ring[n - 1]];
  vec3 sum(0.0f);
  for (std::size_t j = 0; j < n; ++j) sum += p[ring[j]];
  return (1.0f - static_cast<float>(n) * w) * p[v] + w * sum;
}

// The limit surface's tangents at v (positions already at the limit), as pbrt-v4 computes them.
vec3 limit_normal(const std::vector<vec3>& p, const Rings& r, std::size_t v) {
  const std::uint32_t* ring = r.ring.data() + r.offset[v];
  const std::size_t n = r.offset[v + 1] - r.offset[v];
  auto q = [&](std::size_t j) { return p[ring[j]] - p[v]; };  // every rule's weights sum to 0
  vec3 s(0.0f), t(0.0f);
  const float pi = std::numbers::pi_v<float>;
  if (!r.boundary[v]) {
    for (std::size_t j = 0; j < n; ++j) {
      const float angle = 2.0f * pi * static_cast<float>(j) / static_cast<float>(n);
      s += std::cos(angle) * q(j);
      t += std::sin(angle) * q(j);
    }
  } else {
    s = q(n - 1) - q(0);
    if (n == 2) t = q(0) + q(1);
    else if (n == 3) t = q(1);
    else if (n == 4) t = -q(0) + 2.0f * q(1) + 2.0f * q(2) - q(3);
    else {
      const float theta = pi / static_cast<float>(n - 1);
      t = std::sin(theta) * (q(0) + q(n - 1));
      for (std::size_t k = 1; k + 1 < n; ++k) t += (2.0f * std::cos(theta) - 2.0f) * std::sin(static_cast<float>(k) * theta) * q(k);
      t = -t;
    }
  }
  return glm::cross(s, t);
}

}  // namespace

std::optional<std::string> loop_check(const MeshShape& control, std::size_t* edges) {
  const std::vector<glm::uvec3>& tris = control.triangles;
  std::unordered_set<std::uint64_t> directed;
  directed.reserve(tris.size() * 3);
  for (std::size_t f = 0; f < tris.size(); ++f) {
    const glm::uvec3& t = tris[f];
    if (t.x == t.y || t.y == t.z || t.z == t.x)
      return "triangle " + std::to_string(f) + " repeats a point (" + std::to_string(t.x) + " " + std::to_string(t.y) + " " +
             std::to_string(t.z) + "): Loop subdivision needs three distinct points per triangle";
    for (int k = 0; k < 3; ++k)
      if (!directed.insert(key(t[k], t[(k + 1) % 3])).second)
        return "the edge from point " + std::to_string(t[k]) + " to point " + std::to_string(t[(k + 1) % 3]) +
               " is used twice in the same direction (by triangle " + std::to_string(f) +
               " and an earlier one): Loop subdivision needs consistently wound triangles, at most two per edge";
  }
  const Rings r = rings_of(control.positions.size(), tris);
  if (r.lonely_vertex >= 0)
    return "point " + std::to_string(r.lonely_vertex) + " is used by no triangle: Loop subdivision needs every point on the surface";
  if (r.bad_vertex >= 0)
    return "point " + std::to_string(r.bad_vertex) +
           " is where separate fans of triangles meet (a non-manifold vertex): Loop subdivision needs one fan around each point";
  *edges = edges_of(tris).list.size();
  return std::nullopt;
}

LoopCounts loop_counts(std::uint64_t vertices, std::uint64_t edges, std::uint64_t triangles, int levels) {
  constexpr std::uint64_t kMax = std::numeric_limits<std::uint64_t>::max();
  auto add = [](std::uint64_t a, std::uint64_t b) { return a > kMax - b ? kMax : a + b; };
  auto mul = [](std::uint64_t a, std::uint64_t k) { return a > kMax / k ? kMax : a * k; };
  for (int l = 0; l < levels && triangles != kMax; ++l) {  // saturated: no need to go on (levels may be 1e9)
    vertices = add(vertices, edges);
    edges = add(mul(edges, 2), mul(triangles, 3));
    triangles = mul(triangles, 4);
  }
  return {vertices, triangles};
}

MeshShape loop_subdivide(const MeshShape& control, int levels) {
  std::vector<vec3> p = control.positions;
  std::vector<glm::uvec3> tris = control.triangles;
  for (int level = 0; level < levels; ++level) {
    const Edges e = edges_of(tris);
    const Rings r = rings_of(p.size(), tris);
    const std::uint32_t v0 = static_cast<std::uint32_t>(p.size());
    std::vector<vec3> next(p.size() + e.list.size());
    // --- even vertices ---
    for (std::size_t v = 0; v < p.size(); ++v) {
      const std::size_t n = r.offset[v + 1] - r.offset[v];
      next[v] = weigh(p, r, v, r.boundary[v] ? 1.0f / 8.0f : beta(n));
    }
    // --- odd vertices, one per edge ---
    for (std::size_t i = 0; i < e.list.size(); ++i) {
      const Edge& edge = e.list[i];
      if (edge.d < 0) next[v0 + i] = 0.5f * p[edge.a] + 0.5f * p[edge.b];
      else
        next[v0 + i] = 3.0f / 8.0f * p[edge.a] + 3.0f / 8.0f * p[edge.b] + 1.0f / 8.0f * p[static_cast<std::size_t>(edge.c)] +
                       1.0f / 8.0f * p[static_cast<std::size_t>(edge.d)];
    }
    // --- four children per triangle: one at each corner, one in the middle ---
    std::vector<glm::uvec3> children;
    children.reserve(tris.size() * 4);
    for (std::size_t f = 0; f < tris.size(); ++f) {
      const glm::uvec3& t = tris[f];
      const std::uint32_t m01 = v0 + e.edge_of[3 * f], m12 = v0 + e.edge_of[3 * f + 1], m20 = v0 + e.edge_of[3 * f + 2];
      children.emplace_back(t.x, m01, m20);
      children.emplace_back(m01, t.y, m12);
      children.emplace_back(m20, m12, t.z);
      children.emplace_back(m01, m12, m20);
    }
    p = std::move(next);
    tris = std::move(children);
  }
  // --- the limit surface: positions, then normals from the limit positions ---
  const Rings r = rings_of(p.size(), tris);
  std::vector<vec3> limit(p.size());
  for (std::size_t v = 0; v < p.size(); ++v) {
    const std::size_t n = r.offset[v + 1] - r.offset[v];
    limit[v] = weigh(p, r, v, r.boundary[v] ? 1.0f / 5.0f : gamma(n));
  }
  MeshShape out;
  out.normals.resize(p.size());
  for (std::size_t v = 0; v < p.size(); ++v) out.normals[v] = limit_normal(limit, r, v);
  // Where the tangents are parallel, the triangles' own normals on pbrt's side (against the
  // winding, as an interior fan's S x T is).
  std::vector<vec3> faces(p.size(), vec3(0.0f));
  bool degenerate = false;
  for (const vec3& n : out.normals) degenerate = degenerate || !(glm::dot(n, n) > 0.0f) || !std::isfinite(glm::dot(n, n));
  if (degenerate) {
    for (const glm::uvec3& t : tris) {
      const vec3 n = glm::cross(limit[t.y] - limit[t.x], limit[t.z] - limit[t.x]);
      for (int k = 0; k < 3; ++k) faces[t[k]] -= n;
    }
    for (std::size_t v = 0; v < p.size(); ++v)
      if (!(glm::dot(out.normals[v], out.normals[v]) > 0.0f) || !std::isfinite(glm::dot(out.normals[v], out.normals[v]))) out.normals[v] = faces[v];
  }
  out.positions = std::move(limit);
  out.triangles = std::move(tris);
  return out;
}

}  // namespace pathex::import
