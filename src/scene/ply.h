// PLY meshes (Greg Turk's polygon file format), read by a small reader of our own, as pbrt-v4's
// `plymesh` and Mitsuba 3's `ply` read them. It is strict about everything that could make it read
// something other than what the file says, and it allocates nothing that the file's bytes do not
// hold.
//
// Read:
// - `format ascii 1.0`, `binary_little_endian 1.0` and `binary_big_endian 1.0`. A file that starts
//   with the gzip magic (a `.ply.gz`, which pbrt-v4 reads) is inflated first, the inflated size
//   bounded like a file's (--max-file-size).
// - `element vertex`: `x`, `y`, `z` (required); `nx`, `ny`, `nz` (all or none); uv as `u v`, `s t`,
//   `texture_u texture_v` or `texture_s texture_t` (both or none). Any numeric type (char … double);
//   every other property is skipped by its declared type.
// - `element face`: a list `vertex_indices` (or `vertex_index`) of integer count and index types,
//   3 or 4 entries (triangles and quads); every other property is skipped.
// - Any other element, skipped by its declared types. `comment` and `obj_info` lines.
//
// Refused, each with one located message ("file:line:column" in the header and in ASCII data,
// "file: byte N: …" in binary data):
// - a header without `end_header` (also every truncation inside the header), an unknown line,
//   type or format, an element or property declared twice;
// - counts the file cannot hold. Counts are parsed as 64-bit integers. Before anything is
//   allocated, each element's count times the least an entry takes (binary: bytes; ASCII:
//   numbers, a list at least its count) is checked against what follows the header, without
//   overflow; each list's count against the bytes or numbers left before it is skipped;
// - more vertices or faces than `max_elements` (kLimit, naming --max-mesh-elements);
// - vertex values that are not finite in single precision; ASCII values that are not numbers of
//   their declared type (an index `nan`, `1e38` or `1.5` is not an integer); indices out of range;
//   faces of other than 3 or 4 vertices;
// - data after the last element (the header then declares less than the file holds).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "core/limits.h"

namespace pathex {

// faces[i].w of a triangle (a vertex index never reaches it: kMaxMeshElementsCeiling).
inline constexpr std::uint32_t kPlyTriangle = 0xffffffffu;

struct PlyMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // one per vertex, or empty when the file has none
  std::vector<glm::vec2> uvs;      // one per vertex, or empty when the file has none
  std::vector<glm::uvec4> faces;   // corners in file order; w is kPlyTriangle for a triangle
};

struct PlyReadOptions {
  std::size_t max_file_bytes = Limits{}.max_file_bytes;       // the file, and its inflated bytes
  std::size_t max_elements = Limits{}.max_mesh_elements;      // vertices, and faces
};

// The PLY file at `path` (gzipped or not). Errors name `path`.
Result<PlyMesh> read_ply_file(const std::string& path, const PlyReadOptions& options = {});

// The PLY bytes themselves (not gzipped); `name` is the file name errors carry.
Result<PlyMesh> parse_ply(std::string_view bytes, const std::string& name, std::size_t max_elements = Limits{}.max_mesh_elements);

}  // namespace pathex
