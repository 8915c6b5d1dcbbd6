// Mitsuba's serialized meshes (`<shape type="serialized">`), read by a small reader of our own
// from the format Mitsuba documents (Mitsuba 3's "serialized" plugin; the same files as Mitsuba
// 0.5 and 0.6 write). All integers and values are little-endian.
//
// A file holds one or more shapes, one after another, then a table: for each shape the byte
// offset of its start (uint64 in version 4, uint32 in version 3), then the number of shapes
// (uint32) as the file's last 4 bytes. A shape is
//   uint16 0x041C (the format's identifier), uint16 version (3 or 4),
//   one zlib stream (RFC 1950) which inflates to:
//     uint32 flags: 0x0001 vertex normals, 0x0002 uv, 0x0008 vertex colours, 0x0010 face normals
//                   (the mesh asks to be shaded flat), 0x1000 single / 0x2000 double precision;
//     version 4 only: the shape's name, UTF-8, ending in a NUL byte;
//     uint64 vertex count, uint64 triangle count;
//     positions (3 values per vertex), normals if 0x0001 (3), uv if 0x0002 (2), colours if 0x0008
//     (3, skipped), then the triangles' indices: 3 uint32 per triangle (uint64 when there are
//     more than 2^32 vertices, which --max-mesh-elements never allows).
//
// Strict as the PLY reader (scene/ply.h): refused, each with one message naming the file (and the
// shape and byte where it helps), exit 2: a table that does not fit the file or offsets out of
// order, a shape index beyond the table, a wrong identifier or version, a stream zlib refuses or
// that inflates beyond --max-file-size, flags with neither or both precisions or unknown bits,
// counts whose data the inflated bytes do not hold exactly (checked before anything is allocated),
// more vertices or triangles than --max-mesh-elements, values that are not finite in single
// precision, indices out of range.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "core/limits.h"

namespace pathex {

struct SerializedMesh {
  std::string name;                // version 4's shape name (empty in version 3)
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // one per vertex, or empty
  std::vector<glm::vec2> uvs;      // one per vertex, or empty
  std::vector<glm::uvec3> triangles;
  bool face_normals = false;       // flag 0x0010
};

struct SerializedReadOptions {
  std::size_t max_file_bytes = Limits{}.max_file_bytes;   // the file, and the shape's inflated bytes
  std::size_t max_elements = Limits{}.max_mesh_elements;  // vertices plus triangles
};

// Shape `index` of the serialized file at `path`. Errors name `path`.
Result<SerializedMesh> read_serialized_file(const std::string& path, std::size_t index, const SerializedReadOptions& options = {});

// The same from the file's bytes; `name` is the file name errors carry.
Result<SerializedMesh> parse_serialized(std::string_view bytes, std::size_t index, const std::string& name,
                                        const SerializedReadOptions& options = {});

}  // namespace pathex
