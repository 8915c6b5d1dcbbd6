// PLY meshes (scene/ply.h): the bytes are parsed as a PLY file (inflated first when they start with
// the gzip magic, as a `.ply.gz` is) under a small element limit. A mesh that reads must hold what
// the reader promises: one normal and one uv per vertex or none, every corner index within the
// vertices, w marking a triangle or a fourth corner, every value finite.
#include "fuzz_support.h"

#include <cmath>

#include "io/input_file.h"
#include "scene/ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace pathex;
  std::string bytes(fuzz::as_text(data, size));
  if (is_gzip(bytes)) {
    Result<std::string> inflated = gunzip(bytes, fuzz::small_limits().max_file_bytes, "fuzz.ply.gz");
    if (!inflated) {
      if (inflated.error().message.empty()) fuzz::finding("an error without a message");
      return 0;
    }
    bytes = std::move(*inflated);
  }
  Result<PlyMesh> mesh = parse_ply(bytes, "fuzz.ply", /*max_elements=*/100000);
  if (!mesh) {
    if (mesh.error().message.empty() || mesh.error().where.empty()) fuzz::finding("an error without a message or a location");
    return 0;
  }
  const std::size_t n = mesh->positions.size();
  if (!mesh->normals.empty() && mesh->normals.size() != n) fuzz::finding("normals for some vertices only");
  if (!mesh->uvs.empty() && mesh->uvs.size() != n) fuzz::finding("uvs for some vertices only");
  for (const glm::vec3& p : mesh->positions)
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) fuzz::finding("a vertex that is not finite");
  for (const glm::uvec4& f : mesh->faces) {
    for (int k = 0; k < 3; ++k)
      if (f[k] >= n) fuzz::finding("a corner index out of range");
    if (f[3] != kPlyTriangle && f[3] >= n) fuzz::finding("a fourth corner out of range");
  }
  return 0;
}
