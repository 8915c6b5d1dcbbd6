#include "scene/serialized.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <optional>
#include <type_traits>
#include <utility>

#include "io/input_file.h"

namespace pathex {

namespace {

constexpr std::uint16_t kIdentifier = 0x041C;
constexpr std::uint32_t kVertexNormals = 0x0001, kUvs = 0x0002, kColours = 0x0008, kFaceNormals = 0x0010;
constexpr std::uint32_t kSingle = 0x1000, kDouble = 0x2000;
constexpr std::uint32_t kKnownFlags = kVertexNormals | kUvs | kColours | kFaceNormals | kSingle | kDouble;

// Little-endian reads from a byte string at a position the caller has checked.
template <typename T>
T read_le(std::string_view b, std::size_t at) {
  T v{};
  unsigned char raw[sizeof(T)];
  std::memcpy(raw, b.data() + at, sizeof(T));
  if constexpr (std::is_integral_v<T>) {
    using U = std::make_unsigned_t<T>;
    U u = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) u = static_cast<U>(u | (static_cast<U>(raw[i]) << (8 * i)));
    v = static_cast<T>(u);
  } else {
    using U = std::conditional_t<sizeof(T) == 4, std::uint32_t, std::uint64_t>;
    U u = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) u = static_cast<U>(u | (static_cast<U>(raw[i]) << (8 * i)));
    std::memcpy(&v, &u, sizeof(T));
  }
  return v;
}

Error fail(const std::string& name, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = name;
  return e;
}

// The shape's [begin, end) within the file, from the table at its end.
Result<std::pair<std::size_t, std::size_t>> shape_span(std::string_view b, std::size_t index, const std::string& name) {
  if (b.size() < 8) return fail(name, "the file is " + std::to_string(b.size()) + " bytes, too short for a serialized mesh (expected a shape and the table of shapes)");
  if (read_le<std::uint16_t>(b, 0) != kIdentifier) return fail(name, "not a serialized mesh: the file does not start with the identifier 0x041C");
  const std::uint16_t version = read_le<std::uint16_t>(b, 2);
  if (version != 3 && version != 4) return fail(name, "serialized mesh version " + std::to_string(version) + " is not supported, expected 3 or 4");
  const std::uint64_t count = read_le<std::uint32_t>(b, b.size() - 4);
  const std::size_t entry = version == 4 ? 8 : 4;
  if (count == 0 || count > (b.size() - 4) / entry)
    return fail(name, "the table of shapes at the end of the file lists " + std::to_string(count) + " shapes, which the file's " +
                          std::to_string(b.size()) + " bytes cannot hold");
  if (index >= count)
    return fail(name, "shape_index " + std::to_string(index) + " is beyond the file's " + std::to_string(count) + " shape" + (count == 1 ? "" : "s"));
  const std::size_t table = b.size() - 4 - static_cast<std::size_t>(count) * entry;
  const auto offset = [&](std::size_t i) -> std::uint64_t {
    const std::size_t at = table + i * entry;
    return version == 4 ? read_le<std::uint64_t>(b, at) : read_le<std::uint32_t>(b, at);
  };
  const std::uint64_t begin = offset(index), end = index + 1 < count ? offset(index + 1) : table;
  if (!(begin < end && end <= table) || end - begin < 5)
    return fail(name, "shape " + std::to_string(index) + "'s offsets in the table (" + std::to_string(begin) + " to " + std::to_string(end) +
                          ") do not lie in order within the file's " + std::to_string(table) + " bytes of shapes");
  if (read_le<std::uint16_t>(b, static_cast<std::size_t>(begin)) != kIdentifier || read_le<std::uint16_t>(b, static_cast<std::size_t>(begin) + 2) != version)
    return fail(name, "shape " + std::to_string(index) + " at byte " + std::to_string(begin) + " does not start with the identifier 0x041C and version " +
                          std::to_string(version));
  return std::pair<std::size_t, std::size_t>{static_cast<std::size_t>(begin) + 4, static_cast<std::size_t>(end)};
}

}  // namespace

Result<SerializedMesh> parse_serialized(std::string_view bytes, std::size_t index, const std::string& name, const SerializedReadOptions& options) {
  Result<std::pair<std::size_t, std::size_t>> span = shape_span(bytes, index, name);
  if (!span) return span.error();
  const bool v4 = read_le<std::uint16_t>(bytes, 2) == 4;
  Result<std::string> inflated = inflate_zlib(bytes.substr(span->first, span->second - span->first), options.max_file_bytes, name);
  if (!inflated) return inflated.error();
  const std::string_view d = *inflated;
  const std::string shape = "shape " + std::to_string(index);
  std::size_t at = 0;
  if (d.size() < 4) return fail(name, shape + " inflates to " + std::to_string(d.size()) + " bytes, too few for its flags");
  const std::uint32_t flags = read_le<std::uint32_t>(d, 0);
  at = 4;
  if ((flags & ~kKnownFlags) != 0) return fail(name, shape + " has unknown flags 0x" + [&] {
    char hex[16];
    std::snprintf(hex, sizeof hex, "%x", flags & ~kKnownFlags);
    return std::string(hex);
  }());
  if (((flags & kSingle) != 0) == ((flags & kDouble) != 0))
    return fail(name, shape + "'s flags give " + ((flags & kSingle) != 0 ? "both" : "neither") + " single (0x1000) and double (0x2000) precision, expected one");
  SerializedMesh mesh;
  mesh.face_normals = (flags & kFaceNormals) != 0;
  if (v4) {
    const std::size_t nul = d.find('\0', at);
    if (nul == std::string_view::npos) return fail(name, shape + "'s name has no terminating NUL byte");
    mesh.name = std::string(d.substr(at, nul - at));
    at = nul + 1;
  }
  if (d.size() - at < 16) return fail(name, shape + " ends before its vertex and triangle counts");
  const std::uint64_t vertices = read_le<std::uint64_t>(d, at), triangles = read_le<std::uint64_t>(d, at + 8);
  at += 16;
  const std::uint64_t limit = options.max_elements;
  if (vertices > limit || triangles > limit - vertices) {
    Error e = make_error(ErrorCode::kLimit, limit_message("the mesh's size", options.max_elements, "vertices and triangles", "--max-mesh-elements"));
    e.where = name;
    return e;
  }
  // Counts now within --max-mesh-elements (at most 4e9), so these products do not overflow.
  const std::uint64_t value = (flags & kDouble) != 0 ? 8 : 4;
  const std::uint64_t per_vertex = 3 + ((flags & kVertexNormals) != 0 ? 3 : 0) + ((flags & kUvs) != 0 ? 2 : 0) + ((flags & kColours) != 0 ? 3 : 0);
  const std::uint64_t index_bytes = vertices > std::numeric_limits<std::uint32_t>::max() ? 8 : 4;
  const std::uint64_t need = vertices * per_vertex * value + triangles * 3 * index_bytes;
  if (need != d.size() - at)
    return fail(name, shape + " declares " + std::to_string(vertices) + " vertices and " + std::to_string(triangles) + " triangles (" +
                          std::to_string(need) + " bytes of data), but holds " + std::to_string(d.size() - at) + " bytes after its counts");
  const auto number = [&](std::size_t& p) -> double {
    const double x = value == 8 ? read_le<double>(d, p) : static_cast<double>(read_le<float>(d, p));
    p += static_cast<std::size_t>(value);
    return x;
  };
  const auto finite = [](double x) { return std::isfinite(x) && std::fabs(x) <= std::numeric_limits<float>::max(); };
  const auto vectors = [&](std::vector<glm::vec3>* out, const char* what) -> std::optional<Error> {
    out->reserve(static_cast<std::size_t>(vertices));
    for (std::uint64_t i = 0; i < vertices; ++i) {
      const double x = number(at), y = number(at), z = number(at);
      if (!finite(x) || !finite(y) || !finite(z))
        return fail(name, shape + ": " + what + " " + std::to_string(i) + " is not finite in single precision");
      out->emplace_back(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
    }
    return std::nullopt;
  };
  if (auto e = vectors(&mesh.positions, "vertex")) return *e;
  if ((flags & kVertexNormals) != 0)
    if (auto e = vectors(&mesh.normals, "normal")) return *e;
  if ((flags & kUvs) != 0) {
    mesh.uvs.reserve(static_cast<std::size_t>(vertices));
    for (std::uint64_t i = 0; i < vertices; ++i) {
      const double u = number(at), v = number(at);
      if (!finite(u) || !finite(v)) return fail(name, shape + ": uv " + std::to_string(i) + " is not finite in single precision");
      mesh.uvs.emplace_back(static_cast<float>(u), static_cast<float>(v));
    }
  }
  if ((flags & kColours) != 0) at += static_cast<std::size_t>(vertices * 3 * value);
  mesh.triangles.reserve(static_cast<std::size_t>(triangles));
  for (std::uint64_t t = 0; t < triangles; ++t) {
    std::uint64_t c[3];
    for (std::uint64_t& k : c) {
      k = index_bytes == 8 ? read_le<std::uint64_t>(d, at) : read_le<std::uint32_t>(d, at);
      at += static_cast<std::size_t>(index_bytes);
      if (k >= vertices)
        return fail(name, shape + ": triangle " + std::to_string(t) + " refers to vertex " + std::to_string(k) +
                              (vertices == 0 ? ", but the shape has no vertices" : ", expected 0.." + std::to_string(vertices - 1)));
    }
    mesh.triangles.emplace_back(static_cast<unsigned>(c[0]), static_cast<unsigned>(c[1]), static_cast<unsigned>(c[2]));
  }
  return mesh;
}

Result<SerializedMesh> read_serialized_file(const std::string& path, std::size_t index, const SerializedReadOptions& options) {
  Result<std::string> bytes = read_input_file(path, options.max_file_bytes);
  if (!bytes) return bytes.error();
  return parse_serialized(*bytes, index, path, options);
}

}  // namespace pathex
