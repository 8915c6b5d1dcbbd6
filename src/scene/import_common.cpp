#include "scene/import_common.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <cstring>
#include <map>
#include <memory>
#include <sstream>
#include <utility>
#include <variant>

#include "scene/cie_tables.h"
#include "scene/ply.h"

#include "core/limits.h"
#include "io/input_file.h"

namespace pathex::import {

std::string Location::str() const {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  if (line > 0 && column > 0) s += ":" + std::to_string(column);
  return s;
}

Error located(const Location& at, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = at.str();
  return e;
}

// --- files ---

SceneFiles::SceneFiles(const std::string& main_file, const SceneLoadOptions& options)
    : max_file_bytes_(options.max_file_bytes), max_scene_bytes_(options.max_scene_bytes) {
  const std::string dir = std::filesystem::path(main_file).parent_path().string();
  base_dir_ = dir.empty() ? "." : dir;
}

std::string SceneFiles::resolve(const std::string& file) const {
  const std::filesystem::path p(file);
  if (p.is_absolute()) return file;
  for (auto dir = search_paths_.rbegin(); dir != search_paths_.rend(); ++dir) {
    const std::filesystem::path candidate = std::filesystem::path(*dir) / p;
    std::error_code ec;
    if (std::filesystem::exists(candidate, ec)) return candidate.string();
  }
  return (std::filesystem::path(base_dir_) / p).string();
}

void SceneFiles::add_search_path(const std::string& dir) {
  const std::filesystem::path p(dir);
  search_paths_.push_back(p.is_absolute() ? dir : (std::filesystem::path(base_dir_) / p).string());
}

Result<std::string> SceneFiles::include(const std::string& name, const Location& from, const std::string& directive) const {
  if (name.empty()) return located(from, directive + " needs a file name, found \"\"");
  return resolve(name);
}

Result<std::string> SceneFiles::read(const std::string& path, const Location& from, int depth, const std::string& directive) {
  if (depth > 32) return located(from, directive + " nested more than 32 deep (a file including itself?)");
  const std::string what = depth == 0 ? "the scene file" : "the included file '" + excerpt(path, kMaxPathBytes) + "'";
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return located(from, what + " is a directory, expected a file");
  const std::size_t left = max_scene_bytes_ - read_;
  Result<std::string> text = read_input_file(path, std::min(max_file_bytes_, left));
  if (!text) {
    if (text.error().code != ErrorCode::kLimit) return located(from, "cannot open " + what);
    Error e = left < max_file_bytes_ ? located(from, limit_message("the scene's text with its included files", max_scene_bytes_, "bytes",
                                                                   "--max-scene-size"))
                                     : located(from, limit_message(what, max_file_bytes_, "bytes", "--max-file-size"));
    e.code = ErrorCode::kLimit;
    return e;
  }
  read_ += text->size();
  if (depth > 0) included_.push_back(path);
  return text;
}

std::optional<Error> MaterialBudget::charge(const Material& m, const Location& at) {
  const Mixture* mix = std::get_if<Mixture>(&m);
  used_ += mix != nullptr ? mix->components.size() : 1;
  if (used_ <= limit_) return std::nullopt;
  Error e = located(at, limit_message("the expansion of the scene's materials", limit_, "components", "--max-material-nodes"));
  e.code = ErrorCode::kLimit;
  return e;
}

std::optional<std::string> matrix_problem(const glm::mat4& m) {
  // glm is column-major: m[column][row].
  const glm::vec4 last(m[0][3], m[1][3], m[2][3], m[3][3]);
  if (!(std::fabs(last.x) <= 1e-6f && std::fabs(last.y) <= 1e-6f && std::fabs(last.z) <= 1e-6f && std::fabs(last.w - 1.0f) <= 1e-6f)) {
    std::ostringstream row;
    row << last.x << " " << last.y << " " << last.z << " " << last.w;
    return "is projective (its last row is " + row.str() + ", expected 0 0 0 1): pathex applies affine transforms only";
  }
  // Singular when the determinant of the linear part vanishes against the product of its column
  // lengths (its largest possible value, by Hadamard's inequality), computed in double.
  const glm::dmat3 a(m);
  const double bound = glm::length(a[0]) * glm::length(a[1]) * glm::length(a[2]);
  if (!(std::fabs(glm::determinant(a)) > 1e-12 * bound)) return "is singular: it flattens space onto a plane, a line or a point";
  return std::nullopt;
}

std::optional<Error> check_light_value(glm::vec3 v, const Location& at) {
  for (int i = 0; i < 3; ++i) {
    if (!(v[i] >= 0.0f)) return located(at, "a light's emission must be non-negative");
    if (v[i] > kMaxLightValue) {
      std::ostringstream found;
      found << v[i];
      return located(at, "a light's emission (" + found.str() +
                             " after scale) exceeds 1e9: the tracer sums contributions exactly below 2^50 and drops larger ones; "
                             "scale the scene's lights down (the image scales with them)");
    }
    if (v[i] > 0.0f && v[i] < kMinLightValue) {
      std::ostringstream found;
      found << v[i];
      return located(at, "a light's emission (" + found.str() +
                             " after scale) is below 1e-6: the tracer sums contributions exactly on a grid of 2^-64 and "
                             "dimmer lights would round to nothing; scale the scene's lights up (the image scales with them)");
    }
  }
  return std::nullopt;
}

// --- materials ---

namespace {

// A basic material's kind and parameters, as a key: equal keys are the same material. Every kind
// is a plain struct of floats, so its bytes are its parameters.
using MaterialKey = std::vector<std::uint32_t>;
MaterialKey material_key(const BasicMaterial& m) {
  return std::visit(
      [&](const auto& k) -> MaterialKey {
        using T = std::decay_t<decltype(k)>;
        static_assert(std::is_trivially_copyable_v<T> && sizeof(T) % sizeof(std::uint32_t) == 0);
        MaterialKey key(1 + sizeof(T) / sizeof(std::uint32_t));
        key[0] = static_cast<std::uint32_t>(m.index());
        std::memcpy(key.data() + 1, &k, sizeof(T));
        return key;
      },
      m);
}

// Adds `m` with weight `w` to `out`, merging components equal to one already there (`index`).
void flatten(const Material& m, float w, std::vector<Mixture::Component>* out, std::map<MaterialKey, std::size_t>* index) {
  auto add = [&](float weight, const BasicMaterial& basic) {
    const auto [it, fresh] = index->emplace(material_key(basic), out->size());
    if (fresh) out->push_back({weight, basic});
    else (*out)[it->second].weight += weight;
  };
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    for (const Mixture::Component& c : mix->components) add(w * c.weight, c.material);
    return;
  }
  std::visit(
      [&](const auto& k) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(k)>, Mixture>) add(w, BasicMaterial{k});
      },
      m);
}

}  // namespace

Material blend(const Material& a, const Material& b, float w) {
  Mixture mix;
  std::map<MaterialKey, std::size_t> index;
  flatten(a, 1.0f - w, &mix.components, &index);
  flatten(b, w, &mix.components, &index);
  return mix;
}

// --- transforms ---

glm::vec3 apply_point(const glm::mat4& m, glm::vec3 p) { return glm::vec3(m * glm::vec4(p, 1.0f)); }
glm::vec3 apply_vector(const glm::mat4& m, glm::vec3 v) { return glm::vec3(m * glm::vec4(v, 0.0f)); }
glm::vec3 apply_normal(const glm::mat4& m, glm::vec3 n) {
  return glm::normalize(glm::transpose(glm::inverse(glm::mat3(m))) * n);
}
bool swaps_handedness(const glm::mat4& m) { return glm::determinant(glm::mat3(m)) < 0.0f; }

bool is_similarity(const glm::mat4& m, float* scale) {
  const glm::mat3 a(m);
  const float l0 = glm::length(a[0]), l1 = glm::length(a[1]), l2 = glm::length(a[2]);
  const float hi = std::max({l0, l1, l2});
  if (!(hi > 0.0f) || !std::isfinite(hi)) return false;
  const float tol = 1e-4f * hi;
  if (std::fabs(l0 - l1) > tol || std::fabs(l1 - l2) > tol || std::fabs(l0 - l2) > tol) return false;
  if (std::fabs(glm::dot(a[0], a[1])) > tol * hi || std::fabs(glm::dot(a[1], a[2])) > tol * hi ||
      std::fabs(glm::dot(a[0], a[2])) > tol * hi)
    return false;
  *scale = (l0 + l1 + l2) / 3.0f;
  return true;
}

// --- PLY meshes ---

namespace {

bool ends_with(std::string s, const std::string& suffix) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

}  // namespace

Result<MeshShape> load_ply_mesh(const std::string& path, const Location& at, const SceneLoadOptions& options) {
  if (!ends_with(path, ".ply") && !ends_with(path, ".ply.gz")) return located(at, "the mesh '" + path + "' is not a .ply or .ply.gz file");
  if (!std::ifstream(path, std::ios::binary)) return located(at, "cannot open the PLY mesh '" + path + "'");
  Result<PlyMesh> read = read_ply_file(path, PlyReadOptions{options.max_file_bytes, options.max_mesh_elements});
  if (!read) return read.error();  // located in the PLY file
  PlyMesh& ply = *read;
  MeshShape mesh;
  mesh.file = path;
  mesh.positions = std::move(ply.positions);
  mesh.normals = std::move(ply.normals);
  mesh.uvs = std::move(ply.uvs);
  mesh.triangles.reserve(ply.faces.size());
  for (std::size_t f = 0; f < ply.faces.size(); ++f) {
    const glm::uvec4& face = ply.faces[f];
    const unsigned a = face[0], b = face[1], c = face[2];
    mesh.triangles.emplace_back(a, b, c);
    if (face[3] == kPlyTriangle) continue;
    const unsigned d = face[3];
    const glm::vec3 pa = mesh.positions[a], pb = mesh.positions[b], pc = mesh.positions[c], pd = mesh.positions[d];
    const glm::vec3 normal = glm::cross(pb - pa, pc - pa);
    const float size = std::max({glm::length(pb - pa), glm::length(pc - pa), glm::length(pd - pa)});
    if (glm::length(normal) > 0.0f && std::fabs(glm::dot(pd - pa, glm::normalize(normal))) > 1e-5f * size)
      return located(at, "the PLY mesh '" + path + "' has a non-planar quad (face " + std::to_string(f) +
                             "), which pbrt renders as a curved bilinear patch; pathex supports planar quads only");
    mesh.triangles.emplace_back(a, c, d);  // split along v0-v2
  }
  if (mesh.triangles.empty()) return located(at, "the PLY mesh '" + path + "' has no faces");
  return mesh;
}

// --- sampled spectra ---

namespace {
glm::vec3 xyz_to_srgb(const glm::dvec3& xyz) {
  glm::dvec3 rgb(0.0);
  for (int r = 0; r < 3; ++r) rgb[r] = cie::kXyzToSrgb[r][0] * xyz.x + cie::kXyzToSrgb[r][1] * xyz.y + cie::kXyzToSrgb[r][2] * xyz.z;
  return glm::vec3(rgb);
}
}  // namespace

glm::vec3 spectrum_to_rgb(const std::vector<double>& wavelengths, const std::vector<double>& values, bool emission) {
  glm::dvec3 xyz(0.0);
  double norm = 0.0;
  std::size_t k = 0;
  for (int i = 0; i < cie::kCieSamples; ++i) {
    const double w = cie::kCieFirst + cie::kCieStep * i;
    const double weight = emission ? 1.0 : cie::kD65[i];
    norm += weight * cie::kY[i];
    if (w < wavelengths.front() || w > wavelengths.back()) continue;
    while (k + 2 < wavelengths.size() && wavelengths[k + 1] < w) ++k;
    const double t = (w - wavelengths[k]) / (wavelengths[k + 1] - wavelengths[k]);
    const double v = values[k] + std::clamp(t, 0.0, 1.0) * (values[k + 1] - values[k]);
    xyz += v * weight * glm::dvec3(cie::kX[i], cie::kY[i], cie::kZ[i]);
  }
  const glm::vec3 rgb = glm::max(xyz_to_srgb(xyz / norm), glm::vec3(0.0f));
  return emission ? rgb : glm::min(rgb, glm::vec3(1.0f));
}

glm::vec3 equal_energy_rgb() { return xyz_to_srgb(glm::dvec3(1.0)); }

// --- per-vertex (shading) normals ---

std::optional<Error> place_mesh(MeshShape* mesh, const glm::mat4& m, bool flip_normals, bool flip_winding, const Location& at) {
  for (glm::vec3& p : mesh->positions) p = apply_point(m, p);
  if (mesh->normals.empty()) {
    if (flip_winding)
      for (glm::uvec3& t : mesh->triangles) std::swap(t.y, t.z);
    return std::nullopt;
  }
  if (mesh->normals.size() != mesh->positions.size())
    return located(at, "the mesh has " + std::to_string(mesh->normals.size()) + " normals for " + std::to_string(mesh->positions.size()) +
                           " vertices, expected one normal per vertex");
  for (std::size_t i = 0; i < mesh->normals.size(); ++i) {
    const glm::vec3 n = mesh->normals[i];
    if (!std::isfinite(n.x) || !std::isfinite(n.y) || !std::isfinite(n.z) || !(glm::length(n) > 0.0f))
      return located(at, "normal " + std::to_string(i) + " of the mesh is " + (glm::length(n) > 0.0f ? "not finite" : "zero") +
                             ", expected a direction");
    mesh->normals[i] = (flip_normals ? -1.0f : 1.0f) * apply_normal(m, n);
  }
  for (glm::uvec3& t : mesh->triangles) {
    const glm::vec3 p0 = mesh->positions[t.x], p1 = mesh->positions[t.y], p2 = mesh->positions[t.z];
    const glm::vec3 sum = mesh->normals[t.x] + mesh->normals[t.y] + mesh->normals[t.z];
    if (glm::dot(glm::cross(p1 - p0, p2 - p0), sum) < 0.0f) std::swap(t.y, t.z);
  }
  return std::nullopt;
}

void angle_weighted_normals(MeshShape* mesh) {
  std::vector<glm::dvec3> sum(mesh->positions.size(), glm::dvec3(0.0));
  std::vector<glm::vec3> first(mesh->positions.size(), glm::vec3(0.0f));
  for (const glm::uvec3& t : mesh->triangles) {
    const unsigned idx[3] = {t.x, t.y, t.z};
    const glm::dvec3 p[3] = {glm::dvec3(mesh->positions[t.x]), glm::dvec3(mesh->positions[t.y]), glm::dvec3(mesh->positions[t.z])};
    const glm::dvec3 n = glm::cross(p[1] - p[0], p[2] - p[0]);
    const double len = glm::length(n);
    if (!(len > 0.0)) continue;  // a degenerate face has no direction to give
    for (int i = 0; i < 3; ++i) {
      const glm::dvec3 a = p[(i + 1) % 3] - p[i], b = p[(i + 2) % 3] - p[i];
      const double la = glm::length(a), lb = glm::length(b);
      if (!(la > 0.0 && lb > 0.0)) continue;
      const double angle = std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0, 1.0));
      sum[idx[i]] += (angle / len) * n;
      if (first[idx[i]] == glm::vec3(0.0f)) first[idx[i]] = glm::vec3(n / len);
    }
  }
  mesh->normals.resize(mesh->positions.size());
  for (std::size_t i = 0; i < sum.size(); ++i) {
    const double len = glm::length(sum[i]);
    mesh->normals[i] = len > 0.0 ? glm::vec3(sum[i] / len) : first[i] != glm::vec3(0.0f) ? first[i] : glm::vec3(0.0f, 0.0f, 1.0f);
  }
}

// --- generated meshes ---

MeshShape cube_mesh() {
  MeshShape m;
  const glm::vec3 e[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int axis = 0; axis < 3; ++axis)
    for (float sign : {1.0f, -1.0f}) {
      // u × v = the outward normal, so the corners below run counter-clockwise seen from outside.
      glm::vec3 u = e[(axis + 1) % 3], v = e[(axis + 2) % 3];
      if (sign < 0.0f) std::swap(u, v);
      const glm::vec3 c = sign * e[axis];
      const auto base = static_cast<unsigned>(m.positions.size());
      m.positions.insert(m.positions.end(), {c - u - v, c + u - v, c + u + v, c - u + v});
      m.uvs.insert(m.uvs.end(), {{0, 0}, {1, 0}, {1, 1}, {0, 1}});
      m.triangles.emplace_back(base, base + 1, base + 2);
      m.triangles.emplace_back(base, base + 2, base + 3);
    }
  return m;
}

MeshShape tube_mesh(float radius, float z0, float z1) {
  MeshShape m;
  constexpr int n = kCylinderSegments;
  for (int i = 0; i <= n; ++i) {  // the seam's column twice, for its two u values
    const double phi = 2.0 * 3.14159265358979323846 * (i % n) / n;
    const float x = radius * static_cast<float>(std::cos(phi)), y = radius * static_cast<float>(std::sin(phi));
    m.positions.insert(m.positions.end(), {{x, y, z0}, {x, y, z1}});
    const float u = static_cast<float>(i) / n;
    m.uvs.insert(m.uvs.end(), {{u, 0.0f}, {u, 1.0f}});
    const glm::vec3 radial(static_cast<float>(std::cos(phi)), static_cast<float>(std::sin(phi)), 0.0f);
    m.normals.insert(m.normals.end(), {radial, radial});  // the analytic surface's, so it shades as one
  }
  for (unsigned i = 0; i < static_cast<unsigned>(n); ++i) {
    const unsigned a = 2 * i, d = 2 * i + 1, b = 2 * i + 2, c = 2 * i + 3;  // (i, z0), (i, z1), (i + 1, z0), (i + 1, z1)
    m.triangles.emplace_back(a, b, c);  // (b - a) × (c - a) points away from the axis
    m.triangles.emplace_back(a, c, d);
  }
  return m;
}

// --- the builder ---

int SceneBuilder::add_material(std::string name, Material m, MaterialTextures textures) {
  scene_.material_names.push_back(std::move(name));
  scene_.materials.push_back(std::move(m));
  if (!textures.empty() || !scene_.material_textures.empty()) scene_.material_textures.resize(scene_.materials.size());
  if (!textures.empty()) scene_.material_textures.back() = std::move(textures);
  return static_cast<int>(scene_.materials.size()) - 1;
}

int SceneBuilder::add_texture(const Texture& t) {
  scene_.textures.push_back(t);
  return static_cast<int>(scene_.textures.size()) - 1;
}

Result<int> SceneBuilder::add_image(const std::string& path, ImageReadOptions options, const Location& at) {
  const auto key = std::make_tuple(path, static_cast<int>(options.encoding), options.encoding == ImageEncoding::kGamma ? options.gamma : 0.0f);
  if (auto it = images_.find(key); it != images_.end()) return it->second;
  options.texels_so_far = &texels_;
  Result<LinearImage> image = read_image(path, options);
  if (!image) {
    Error e = located(at, "image \"" + path + "\" " + image.error().message);
    e.code = image.error().code;
    return e;
  }
  scene_.images.push_back(std::move(*image));
  const int index = static_cast<int>(scene_.images.size()) - 1;
  images_[key] = index;
  return index;
}

std::pair<Material, MaterialTextures> blend_textured(const Material& a, const MaterialTextures& ta, const Material& b,
                                                     const MaterialTextures& tb, float w, int amount) {
  if (ta.empty() && tb.empty() && amount < 0) return {blend(a, b, w), {}};
  // No merging of equal components here: a texture binds one component by its index.
  Mixture mix;
  MaterialTextures out;
  out.amount = amount;
  auto add = [&](const Material& m, const MaterialTextures& t, bool second) {
    const int offset = static_cast<int>(mix.components.size());
    auto push = [&](float weight, const BasicMaterial& basic) {
      const float w0 = second ? 0.0f : weight, w1 = second ? weight : 0.0f;
      out.weight0.push_back(w0);
      out.weight1.push_back(w1);
      mix.components.push_back({amount >= 0 ? 0.5f * (w0 + w1) : (second ? w : 1.0f - w) * weight, basic});
    };
    if (const auto* inner = std::get_if<Mixture>(&m)) {
      for (const Mixture::Component& c : inner->components) push(c.weight, c.material);
    } else {
      std::visit([&](const auto& k) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(k)>, Mixture>) push(1.0f, BasicMaterial{k});
      }, m);
    }
    for (TextureBinding binding : t.bindings) {
      binding.component = offset + std::max(binding.component, 0);
      out.bindings.push_back(binding);
    }
  };
  add(a, ta, false);
  add(b, tb, true);
  if (amount < 0) {
    out.weight0.clear();
    out.weight1.clear();
  }
  return {Material{std::move(mix)}, std::move(out)};
}

void SceneBuilder::add_distant(glm::vec3 direction, glm::vec3 irradiance) {
  distant_.push_back({glm::normalize(direction), irradiance});
}

void SceneBuilder::set_camera(const Camera& camera, glm::vec3 image_right) {
  scene_.camera = camera;
  image_right_ = image_right;
  has_camera_ = true;
}

std::optional<std::string> make_group_member(Shape* s, int group) {
  if (s->emissive()) return std::string("an area light in an instanced object is not supported (pbrt-v4 refuses them too): place the emitting shape in the world");
  if (s->alpha >= 0) return std::string("an alpha cut-out in an instanced object is not supported: place the cut-out shape in the world");
  if (const auto* q = std::get_if<QuadShape>(&s->geometry)) {
    MeshShape m;
    m.positions = {q->corner, q->corner + q->edge1, q->corner + q->edge1 + q->edge2, q->corner + q->edge2};
    m.triangles = {{0u, 1u, 2u}, {0u, 2u, 3u}};
    s->geometry = std::move(m);
  } else if (!std::holds_alternative<MeshShape>(s->geometry)) {
    return std::string(std::holds_alternative<SphereShape>(s->geometry) ? "a sphere" : "a disk") +
           " in an instanced object is not supported (an instance's transform need not keep it one): instanced objects hold meshes";
  }
  s->group = group;
  return std::nullopt;
}

namespace {

// The reflection through the plane through `c` with unit normal `n`.
struct Mirror3 {
  glm::vec3 c, n;
  glm::vec3 point(glm::vec3 p) const { return p - 2.0f * glm::dot(p - c, n) * n; }
  glm::vec3 vector(glm::vec3 v) const { return v - 2.0f * glm::dot(v, n) * n; }
};

void mirror_scene(Scene* s, const Mirror3& r) {
  // An instance's members stay in their group's space; the reflection joins its transform (whose
  // determinant then changes sign, which turns the members' front sides as the swaps below do).
  const glm::mat4 reflect(glm::vec4(r.vector({1, 0, 0}), 0), glm::vec4(r.vector({0, 1, 0}), 0), glm::vec4(r.vector({0, 0, 1}), 0),
                          glm::vec4(r.point(glm::vec3(0.0f)), 1));
  for (ShapeInstance& inst : s->instances) inst.to_world = reflect * inst.to_world;
  for (Shape& shape : s->shapes) {
    if (shape.group >= 0) continue;
    std::visit(
        [&](auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, MeshShape>) {
            for (glm::vec3& p : g.positions) p = r.point(p);
            for (glm::vec3& n : g.normals) n = r.vector(n);
            for (glm::uvec3& t : g.triangles) std::swap(t.y, t.z);  // keeps each face's front side
          } else if constexpr (std::is_same_v<T, SphereShape>) {
            g.center = r.point(g.center);
          } else if constexpr (std::is_same_v<T, QuadShape>) {
            g.corner = r.point(g.corner);
            const glm::vec3 e1 = r.vector(g.edge1), e2 = r.vector(g.edge2);
            g.edge1 = e2;  // swapped: the normal edge1 × edge2 stays the reflected front
            g.edge2 = e1;
          } else {
            g.center = r.point(g.center);
            g.normal = r.vector(g.normal);
          }
        },
        shape.geometry);
  }
  for (Light& light : s->lights) {
    std::visit(
        [&](auto& l) {
          using T = std::decay_t<decltype(l)>;
          if constexpr (std::is_same_v<T, PointLight>) {
            l.position = r.point(l.position);
          } else if constexpr (std::is_same_v<T, SpotLight> || std::is_same_v<T, LaserLight>) {
            l.position = r.point(l.position);
            l.direction = r.vector(l.direction);
          } else {
            l.direction = r.vector(l.direction);
            l.aperture_corner = r.point(l.aperture_corner);
            l.aperture_edge1 = r.vector(l.aperture_edge1);
            l.aperture_edge2 = r.vector(l.aperture_edge2);
          }
        },
        light);
  }
  s->camera.position = r.point(s->camera.position);
  s->camera.look_at = r.point(s->camera.look_at);
  s->camera.up = r.vector(s->camera.up);
}

// Bounding sphere of the shapes (centre of the box, half its diagonal).
std::pair<glm::vec3, float> bounding_sphere(const Scene& s) {
  glm::vec3 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  auto add = [&](glm::vec3 p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  };
  for (const auto& [blo, bhi] : instance_boxes(s)) {
    add(blo);
    add(bhi);
  }
  for (const Shape& shape : s.shapes) {
    if (shape.group >= 0) continue;  // the instances' boxes above
    std::visit(
        [&](const auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, MeshShape>) {
            for (const glm::vec3& p : g.positions) add(p);
          } else if constexpr (std::is_same_v<T, SphereShape>) {
            add(g.center - glm::vec3(g.radius));
            add(g.center + glm::vec3(g.radius));
          } else if constexpr (std::is_same_v<T, QuadShape>) {
            add(g.corner);
            add(g.corner + g.edge1 + g.edge2);
            add(g.corner + g.edge1);
            add(g.corner + g.edge2);
          } else {
            add(g.center - glm::vec3(g.radius));
            add(g.center + glm::vec3(g.radius));
          }
        },
        shape.geometry);
  }
  const glm::vec3 c = 0.5f * (lo + hi);
  return {c, std::max(0.5f * glm::length(hi - lo), 1e-6f)};
}

}  // namespace

Result<Scene> SceneBuilder::finish(const std::string& file, const std::vector<std::string>& included) {
  Scene s = std::move(scene_);
  s.name = file;
  // Errors about the scene as a whole are located at the main file and say which files it was read from.
  std::string from;
  for (std::size_t i = 0; i < included.size() && i < 3; ++i) from += (i == 0 ? "" : ", ") + included[i];
  if (included.size() > 3) from += " and " + std::to_string(included.size() - 3) + " more";
  if (!from.empty()) from = " (read from " + file + " and the files it includes: " + from + ")";
  auto fail = [&](const std::string& message) { return located(Location{file}, message + from); };
  if (!has_camera_) return fail("the scene has no camera");
  if (s.shapes.empty()) return fail("the scene is empty: expected at least one shape");
  // --- every coordinate finite and within 1e30, as the JSON loader requires ---
  auto bad = [](glm::vec3 v) { return !(std::fabs(v.x) <= 1e30f && std::fabs(v.y) <= 1e30f && std::fabs(v.z) <= 1e30f); };
  for (const Shape& shape : s.shapes) {
    bool out_of_range = false;
    std::visit(
        [&](const auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, MeshShape>) {
            for (const glm::vec3& p : g.positions) out_of_range = out_of_range || bad(p);
          } else if constexpr (std::is_same_v<T, QuadShape>) {
            out_of_range = bad(g.corner) || bad(g.edge1) || bad(g.edge2);
          } else if constexpr (std::is_same_v<T, SphereShape>) {
            out_of_range = bad(g.center) || bad(glm::vec3(g.radius));
          } else {
            out_of_range = bad(g.center) || bad(g.normal) || bad(glm::vec3(g.radius));
          }
        },
        shape.geometry);
    if (out_of_range) return located(Location{shape.pointer}, "the shape's transformed coordinates are not finite (or beyond 1e30)");
  }
  for (std::size_t i = 0; i < s.instances.size(); ++i) {  // the instance's transform too (Embree needs finite ones)
    const glm::mat4& m = s.instances[i].to_world;
    if (bad(glm::vec3(m[0])) || bad(glm::vec3(m[1])) || bad(glm::vec3(m[2])) || bad(glm::vec3(m[3])))
      return located(Location{s.instances[i].pointer}, "the instance's transform is not finite (or beyond 1e30)");
  }
  for (const auto& [lo, hi] : instance_boxes(s))
    if (bad(lo) || bad(hi)) return fail("an instance's transformed coordinates are not finite (or beyond 1e30)");
  for (const Light& light : s.lights) {
    const bool out_of_range = std::visit([&](const auto& l) {
      using T = std::decay_t<decltype(l)>;
      if constexpr (std::is_same_v<T, DistantLight>) return bad(l.direction) || bad(l.irradiance);
      else if constexpr (std::is_same_v<T, PointLight>) return bad(l.position) || bad(l.intensity);
      else if constexpr (std::is_same_v<T, SpotLight>) return bad(l.position) || bad(l.direction) || bad(l.intensity);
      else return bad(l.position) || bad(l.direction) || bad(l.power);
    }, light);
    if (out_of_range) return fail("a light's transformed position, direction or emission is not finite (or beyond 1e30)");
  }
  // --- distant lights: an aperture upstream of the bounding sphere, covering it ---
  if (!distant_.empty()) {
    const auto [centre, radius] = bounding_sphere(s);
    const float r = 1.01f * radius;
    for (const Distant& d : distant_) {
      const glm::vec3 a = std::fabs(d.direction.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
      const glm::vec3 u = glm::normalize(glm::cross(d.direction, a)), v = glm::cross(d.direction, u);
      DistantLight l;
      l.direction = d.direction;
      l.irradiance = d.irradiance;
      l.aperture_corner = centre - 1.01f * r * d.direction - r * (u + v);
      l.aperture_edge1 = 2.0f * r * u;
      l.aperture_edge2 = 2.0f * r * v;
      s.lights.push_back(l);
    }
  }
  // --- handedness: mirror a left-handed camera's world through its vertical plane ---
  const glm::vec3 fwd = glm::normalize(s.camera.look_at - s.camera.position);
  const glm::vec3 right_handed = glm::cross(fwd, glm::normalize(s.camera.up));
  if (glm::dot(right_handed, image_right_) < 0.0f) {
    mirror_scene(&s, Mirror3{s.camera.position, glm::normalize(right_handed)});
    if (environment_image_) {  // the image's directions are mirrored with the world
      const glm::vec3 n = glm::normalize(right_handed);
      environment_image_->first.to_world = (glm::mat3(1.0f) - 2.0f * glm::outerProduct(n, n)) * environment_image_->first.to_world;
    }
  }
  // --- uniform infinite lights: the box around the finished scene (apertures and camera included) ---
  if (environment_image_) add_image_environment(&s, std::move(environment_image_->first), environment_image_->second);
  for (const auto& [radiance, where] : environment_) add_uniform_environment(&s, radiance, where);
  if (std::optional<SceneRuleViolation> v = check_scene_rules(s)) {
    std::string message = v->message;
    if (v->pointer == "/lights") message = "the scene has no light: expected a light source or an emitting shape";
    return fail(message);
  }
  return s;
}

}  // namespace pathex::import
