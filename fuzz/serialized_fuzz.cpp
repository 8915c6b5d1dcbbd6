// Mitsuba's serialized meshes (scene/serialized.h): the bytes are parsed as a serialized file, its
// first and second shape, under small limits. A mesh that reads must hold what the reader
// promises: one normal and one uv per vertex or none, every index within the vertices, every
// value finite.
#include "fuzz_support.h"

#include <cmath>

#include "scene/serialized.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  const std::string bytes(fuzz::as_text(data, size));
  for (std::size_t index : {0, 1}) {
    Result<SerializedMesh> mesh =
        parse_serialized(bytes, index, "fuzz.serialized", SerializedReadOptions{fuzz::small_limits().max_file_bytes, 100000});
    if (!mesh) {
      if (mesh.error().message.empty() || mesh.error().where.empty()) fuzz::finding("an error without a message or a location");
      continue;
    }
    const std::size_t n = mesh->positions.size();
    if (!mesh->normals.empty() && mesh->normals.size() != n) fuzz::finding("normals for some vertices only");
    if (!mesh->uvs.empty() && mesh->uvs.size() != n) fuzz::finding("uvs for some vertices only");
    for (const glm::vec3& p : mesh->positions)
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) fuzz::finding("a vertex that is not finite");
    for (const glm::uvec3& t : mesh->triangles)
      if (t.x >= n || t.y >= n || t.z >= n) fuzz::finding("an index out of range");
  }
  return 0;
}
