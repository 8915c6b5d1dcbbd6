#include "scene/import_common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <sstream>
#include <utility>
#include <variant>

#include <assimp/cimport.h>
#include <assimp/mesh.h>
#include <assimp/scene.h>
#include <dlfcn.h>

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

SceneFiles::SceneFiles(const std::string& main_file) {
  const std::string dir = std::filesystem::path(main_file).parent_path().string();
  base_dir_ = dir.empty() ? "." : dir;
}

std::string SceneFiles::resolve(const std::string& file) const {
  const std::filesystem::path p(file);
  return p.is_absolute() ? file : (std::filesystem::path(base_dir_) / p).string();
}

Result<std::string> SceneFiles::read(const std::string& path, const Location& from, int depth, const std::string& directive) const {
  if (depth > 32) return located(from, directive + " nested more than 32 deep (a file including itself?)");
  std::ifstream in(path, std::ios::binary);
  if (!in) return located(from, depth == 0 ? "cannot open the scene file" : "cannot open the included file '" + path + "'");
  std::ostringstream ss;
  ss << in.rdbuf();
  return std::move(ss).str();
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

void flatten(const Material& m, float w, std::vector<Mixture::Component>* out) {
  if (const auto* mix = std::get_if<Mixture>(&m)) {
    for (const Mixture::Component& c : mix->components) out->push_back({w * c.weight, c.material});
    return;
  }
  std::visit(
      [&](const auto& k) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(k)>, Mixture>) out->push_back({w, BasicMaterial{k}});
      },
      m);
}

}  // namespace

Material blend(const Material& a, const Material& b, float w) {
  Mixture mix;
  flatten(a, 1.0f - w, &mix.components);
  flatten(b, w, &mix.components);
  return mix;
}

glm::vec3 conductor_reflectance(glm::vec3 eta, glm::vec3 k) {
  const glm::vec3 k2 = k * k;
  return ((eta - 1.0f) * (eta - 1.0f) + k2) / ((eta + 1.0f) * (eta + 1.0f) + k2);
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

// --- PLY meshes through assimp ---

namespace {

// libassimp is loaded when a PLY mesh is read, not linked: with the libraries it pulls in (draco,
// minizip) its mapping and relocation took about 40 % of every pathex process's start-up page
// faults (`pathex --version` 25 -> 15 ms CPU, bench/README.md), and only imported scenes with PLY
// meshes use it. Its C interface is looked up by name (PATHEX_ASSIMP_SONAME: the build's library).
struct AssimpApi {
  decltype(&::aiImportFile) import_file;
  decltype(&::aiReleaseImport) release_import;
  decltype(&::aiGetErrorString) error_string;
};

// The loaded library's functions, or the reason it could not be loaded.
const std::variant<AssimpApi, std::string>& assimp_library() {
  static const std::variant<AssimpApi, std::string> api = []() -> std::variant<AssimpApi, std::string> {
    void* lib = ::dlopen(PATHEX_ASSIMP_SONAME, RTLD_NOW | RTLD_LOCAL);  // never closed: the process keeps it
    if (lib == nullptr) return std::string("cannot load " PATHEX_ASSIMP_SONAME " (") + ::dlerror() + ")";
    AssimpApi a{};
    a.import_file = reinterpret_cast<decltype(a.import_file)>(::dlsym(lib, "aiImportFile"));
    a.release_import = reinterpret_cast<decltype(a.release_import)>(::dlsym(lib, "aiReleaseImport"));
    a.error_string = reinterpret_cast<decltype(a.error_string)>(::dlsym(lib, "aiGetErrorString"));
    if (a.import_file == nullptr || a.release_import == nullptr || a.error_string == nullptr)
      return std::string(PATHEX_ASSIMP_SONAME " lacks a function of assimp's C interface");
    return a;
  }();
  return api;
}

}  // namespace

Result<MeshShape> load_ply_mesh(const std::string& path, const Location& at, bool discard_normals) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext != ".ply") return located(at, "the mesh '" + path + "' is not a .ply file");
  const std::variant<AssimpApi, std::string>& loaded = assimp_library();
  if (const std::string* why = std::get_if<std::string>(&loaded))
    return located(at, "cannot read the PLY mesh '" + path + "': " + *why);
  const AssimpApi& assimp = std::get<AssimpApi>(loaded);
  // No post-processing: the faces arrive as written, so quads can be checked before splitting.
  const std::unique_ptr<const aiScene, decltype(assimp.release_import)> imported(assimp.import_file(path.c_str(), 0),
                                                                                assimp.release_import);
  const aiScene* scene = imported.get();
  if (scene == nullptr) return located(at, "cannot read the PLY mesh '" + path + "': " + assimp.error_string());
  MeshShape mesh;
  mesh.file = path;
  for (unsigned mi = 0; mi < scene->mNumMeshes; ++mi) {
    const aiMesh* m = scene->mMeshes[mi];
    if (m == nullptr) continue;
    if (m->HasNormals() && !discard_normals)
      return located(at, "the PLY mesh '" + path +
                             "' has per-vertex normals, which are not supported: pathex shades meshes with their face normals");
    const auto base = static_cast<unsigned>(mesh.positions.size());
    for (unsigned v = 0; v < m->mNumVertices; ++v) {
      const aiVector3D& p = m->mVertices[v];
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        return located(at, "the PLY mesh '" + path + "' has a vertex that is not finite");
      mesh.positions.emplace_back(p.x, p.y, p.z);
    }
    for (unsigned f = 0; f < m->mNumFaces; ++f) {
      const aiFace& face = m->mFaces[f];
      const unsigned n = face.mNumIndices;
      for (unsigned i = 0; i < n; ++i)
        if (face.mIndices[i] >= m->mNumVertices)
          return located(at, "the PLY mesh '" + path + "' has face " + std::to_string(f) + " with an out-of-range vertex index");
      if (n < 3)
        return located(at, "the PLY mesh '" + path + "' has points or lines (face " + std::to_string(f) + "), expected triangles or quads");
      if (n > 4)
        return located(at, "the PLY mesh '" + path + "' has a polygon of " + std::to_string(n) + " vertices (face " +
                               std::to_string(f) + "), expected triangles or quads");
      const unsigned a = base + face.mIndices[0], b = base + face.mIndices[1], c = base + face.mIndices[2];
      mesh.triangles.emplace_back(a, b, c);
      if (n == 4) {
        const unsigned d = base + face.mIndices[3];
        const glm::vec3 pa = mesh.positions[a], pb = mesh.positions[b], pc = mesh.positions[c], pd = mesh.positions[d];
        const glm::vec3 normal = glm::cross(pb - pa, pc - pa);
        const float size = std::max({glm::length(pb - pa), glm::length(pc - pa), glm::length(pd - pa)});
        if (glm::length(normal) > 0.0f && std::fabs(glm::dot(pd - pa, glm::normalize(normal))) > 1e-5f * size)
          return located(at, "the PLY mesh '" + path + "' has a non-planar quad (face " + std::to_string(f) +
                                 "), which pbrt renders as a curved bilinear patch; pathex supports planar quads only");
        mesh.triangles.emplace_back(a, c, d);
      }
    }
  }
  if (mesh.triangles.empty()) return located(at, "the PLY mesh '" + path + "' has no faces");
  return mesh;
}

// --- the builder ---

int SceneBuilder::add_material(std::string name, Material m) {
  scene_.material_names.push_back(std::move(name));
  scene_.materials.push_back(std::move(m));
  return static_cast<int>(scene_.materials.size()) - 1;
}

void SceneBuilder::add_distant(glm::vec3 direction, glm::vec3 irradiance) {
  distant_.push_back({glm::normalize(direction), irradiance});
}

void SceneBuilder::set_camera(const Camera& camera, glm::vec3 image_right) {
  scene_.camera = camera;
  image_right_ = image_right;
  has_camera_ = true;
}

namespace {

// The reflection through the plane through `c` with unit normal `n`.
struct Mirror3 {
  glm::vec3 c, n;
  glm::vec3 point(glm::vec3 p) const { return p - 2.0f * glm::dot(p - c, n) * n; }
  glm::vec3 vector(glm::vec3 v) const { return v - 2.0f * glm::dot(v, n) * n; }
};

void mirror_scene(Scene* s, const Mirror3& r) {
  for (Shape& shape : s->shapes) {
    std::visit(
        [&](auto& g) {
          using T = std::decay_t<decltype(g)>;
          if constexpr (std::is_same_v<T, MeshShape>) {
            for (glm::vec3& p : g.positions) p = r.point(p);
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
  for (const Shape& shape : s.shapes) {
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

Result<Scene> SceneBuilder::finish(const std::string& file) {
  Scene s = std::move(scene_);
  s.name = file;
  auto fail = [&](const std::string& message) { return located(Location{file}, message); };
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
  if (glm::dot(right_handed, image_right_) < 0.0f) mirror_scene(&s, Mirror3{s.camera.position, glm::normalize(right_handed)});
  // --- uniform infinite lights: the box around the finished scene (apertures and camera included) ---
  for (const auto& [radiance, where] : environment_) add_uniform_environment(&s, radiance, where);
  if (std::optional<SceneRuleViolation> v = check_scene_rules(s)) {
    std::string message = v->message;
    if (v->pointer == "/lights") message = "the scene has no light: expected a light source or an emitting shape";
    return fail(message);
  }
  return s;
}

}  // namespace pathex::import
