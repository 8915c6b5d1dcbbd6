// Loop subdivision of a triangle mesh, as pbrt-v4's `loopsubdiv` shape makes it at load
// (pbrt-v4 src/pbrt/util/loopsubdiv.cpp; Loop 1987): `levels` times, every triangle is split in
// four at new edge ("odd") vertices and every old ("even") vertex moves by Loop's weights; then
// every vertex is pushed to its limit position on the subdivision surface, and its normal is the
// cross product of the limit surface's two tangents there. The result is an ordinary mesh with
// per-vertex (shading) normals, which the importer places like a `trianglemesh` with "N".
//
// The rules, with n the valence (the number of neighbours) and ring the neighbours in order:
// - even interior vertex: (1 - n b) p + b sum(ring), b = 3/16 for n = 3, else 3 / (8 n);
// - even boundary vertex: 3/4 p + 1/8 (the two boundary neighbours);
// - odd vertex of an interior edge ab with opposite vertices c, d: 3/8 (a + b) + 1/8 (c + d);
//   of a boundary edge: (a + b) / 2;
// - limit, interior: (1 - n g) p + g sum(ring), g = 1 / (n + 3 / (8 b)); boundary: 3/5 p +
//   1/5 (the two boundary neighbours);
// - tangents, interior: S = sum cos(2 pi j / n) ring_j, T = sum sin(2 pi j / n) ring_j; boundary:
//   pbrt's (S from the last to the first neighbour, T by the valence's rule). The normal is
//   S x T with the ring in pbrt's order, so its side is pbrt's (it faces against the winding of
//   an interior fan), and pbrt then turns each triangle to face its vertex normals, as
//   import::place_mesh does.
// Counts, exactly: one level takes V vertices, E edges and F triangles to V + E vertices,
// 2 E + 3 F edges and 4 F triangles (vertices: the even ones first in their order, then one per
// edge in the order the triangles first meet them; triangles: each parent's four children in
// order), as pbrt-v4's output.
//
// The control mesh must be what pbrt's half-edge structure assumes (pbrt fails or crashes
// otherwise); loop_check says why one is not.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "scene/scene.h"

namespace pathex::import {

// Why `control` (positions and triangles with indices in range; normals and uv ignored) cannot be
// subdivided, or std::nullopt; `*edges` is then its number of edges. Refused: a triangle that
// repeats a vertex, an edge used twice in the same direction (the triangles are not consistently
// wound, or more than two share it), a point no triangle uses, a point where separate fans of
// triangles meet (a non-manifold vertex).
std::optional<std::string> loop_check(const MeshShape& control, std::size_t* edges);

// The number of vertices and triangles after `levels` levels of a mesh of `vertices`, `edges` and
// `triangles` (the recurrence above), saturated at UINT64_MAX.
struct LoopCounts {
  std::uint64_t vertices = 0, triangles = 0;
};
LoopCounts loop_counts(std::uint64_t vertices, std::uint64_t edges, std::uint64_t triangles, int levels);

// `control` subdivided `levels` >= 0 times and pushed to the limit surface, with per-vertex
// normals (not normalised; zero where the limit tangents are parallel, as at a degenerate fan:
// there the sum of the adjacent triangles' normals, on pbrt's side, stands in). `control` must
// pass loop_check.
MeshShape loop_subdivide(const MeshShape& control, int levels);

}  // namespace pathex::import
