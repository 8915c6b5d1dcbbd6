// What the pbrt-v4 and Mitsuba 3 importers (pbrt_import.*, mitsuba_import.*) share: located
// errors, the mapping of their materials onto pathex's, PLY meshes (scene/ply.h), and the
// builder that completes a scene the same way for both formats.
//
// The builder's last step (finish) does three things neither format needs to repeat:
// - Handedness. pathex's image right is forward × up. pbrt's camera space is left-handed (image
//   right is up × forward in world coordinates), so a pbrt LookAt without a mirroring Scale, or a
//   Mitsuba to_world with a negative determinant, shows the world mirrored left-right. pathex's
//   camera cannot mirror, so the builder mirrors the world instead, through the camera's vertical
//   plane: positions, directions and normals are reflected and triangle windings and quad edges
//   swapped so that every surface keeps its front side. Every pixel then sees what it saw in the
//   source renderer, and no radiometric quantity changes.
// - Distant lights. Both formats' distant lights cover the whole scene; pathex's enters through an
//   aperture, so the builder places a square aperture perpendicular to the light, upstream of the
//   scene's bounding sphere and covering it.
// - The scene rules of scene.h (a shape, a light, a camera that sees a shape), reported at the file.
#pragma once

#include <map>
#include <optional>
#include <tuple>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "core/error.h"
#include "scene/scene.h"

namespace pathex::import {

// "file:line:column" (column 0: "file:line").
struct Location {
  std::string file;
  int line = 0;
  int column = 0;
  std::string str() const;
};

// A kBadFile error whose `where` is the location.
Error located(const Location& at, std::string message);

// The files of one scene: relative names (includes, meshes) resolve against the main file's folder,
// as pbrt-v4 and Mitsuba 3 resolve them, and includes nest at most 32 deep. Each file is read with
// a cap (never whole first: `/dev/zero` stops there): at most options.max_file_bytes, and the main
// file with everything it includes at most options.max_scene_bytes together.
class SceneFiles {
 public:
  SceneFiles(const std::string& main_file, const SceneLoadOptions& options);
  // A relative name: the first of the search paths (the latest added first) and the main file's
  // folder where the file exists, else the main file's folder.
  std::string resolve(const std::string& file) const;
  // Mitsuba's <path value="dir"/>: `dir` (relative to the main file's folder unless absolute) is
  // searched before the folders added earlier.
  void add_search_path(const std::string& dir);
  // The path an include names, resolved; refused at `from` when the name is empty.
  Result<std::string> include(const std::string& name, const Location& from, const std::string& directive) const;
  // The text of `path`, included from `from` at nesting `depth` (0: the main file); `directive`
  // names the including directive in messages. A directory is refused.
  Result<std::string> read(const std::string& path, const Location& from, int depth, const std::string& directive);
  // The included files read so far, in order.
  const std::vector<std::string>& included() const { return included_; }

 private:
  std::string base_dir_;
  std::vector<std::string> search_paths_;  // resolved, in the order added
  std::size_t max_file_bytes_, max_scene_bytes_;
  std::size_t read_ = 0;  // bytes of the scene's text so far
  std::vector<std::string> included_;
};

// The components a scene's materials expand to (a basic material is one, a mixture its
// components), counted as each material is made: mixtures of mixtures are flattened, so a graph of
// named materials that share parts could expand to exponentially many. Past the limit
// (--max-material-nodes) the material at `at` is refused.
class MaterialBudget {
 public:
  explicit MaterialBudget(std::size_t limit) : limit_(limit) {}
  std::optional<Error> charge(const Material& m, const Location& at);

 private:
  std::size_t limit_, used_ = 0;
};

// Why a transform given as a whole matrix (pbrt's Transform and ConcatTransform, Mitsuba's
// <matrix>) cannot be applied: it is projective (its last row is not 0 0 0 1) or singular (it
// flattens space): "is projective (…)", "is singular: …"; std::nullopt when it is an invertible
// affine transform.
std::optional<std::string> matrix_problem(const glm::mat4& m);

// A light's emission (radiance, intensity or irradiance, after any scale) must be non-negative and
// at most kMaxLightValue (scene.h), as in JSON scenes; the error names `at`.
std::optional<Error> check_light_value(glm::vec3 v, const Location& at);

// A mixture of `a` (weight 1 - w) and `b` (weight w), flattened: mixtures of mixtures become one
// mixture whose weights are the products along the way (both formats' mix and blend choose one
// material per shading point with these probabilities, which is the same linear combination).
// Equal components are merged (their weights added: the same choice), so a mixture has at most
// one component per distinct basic material however often the graph reaches it.
Material blend(const Material& a, const Material& b, float w);

// A sampled spectrum (wavelengths in nm, strictly increasing, at least two) as linear sRGB, as
// Mitsuba 3's RGB variants convert one (spectrum_list_to_srgb): linear between the samples, zero
// outside them, against the CIE 1931 matching functions every 5 nm (scene/cie_tables.h). A
// reflectance (`emission` false) is weighted by D65 and normalised by D65's luminance, so 1 is
// (1, 1, 1), and clamped to [0, 1]; an emission spectrum is integrated alone and normalised by the
// integral of y-bar (a constant 1 is the equal-energy white, luminance 1), negative channels 0.
glm::vec3 spectrum_to_rgb(const std::vector<double>& wavelengths, const std::vector<double>& values, bool emission);
// Mitsuba's uniform emission spectrum of value 1 in sRGB: the equal-energy white XYZ (1, 1, 1).
glm::vec3 equal_energy_rgb();

// A PLY mesh (scene/ply.h; `.ply` or `.ply.gz`): triangles and planar quads (split in two along
// v0-v2, the surface pbrt-v4's bilinear patch has when the quad is planar), with the file's uv and
// per-vertex normals (empty when the file has none). Errors in the file are located in it; refused
// at `at`: a file that cannot be opened, non-planar quads, a mesh without faces.
Result<MeshShape> load_ply_mesh(const std::string& path, const Location& at, const SceneLoadOptions& options);

// --- per-vertex (shading) normals ---
// A mesh with per-vertex normals is shaded with their interpolation (EmbreeScene::intersect); its
// geometric normal only says where the real surface is. Both formats take the vertex normals'
// side as the front: pbrt-v4 turns the geometric normal to the shading normal's side
// (FaceForward), Mitsuba decides inside and outside in the shading frame. pathex does it once, at
// load: place_mesh() winds every triangle so that its geometric normal faces the side of its
// three vertex normals' sum, so emitters, the offsets of rays and the checker see the same front.
//
// The mesh placed by `m`: positions by m, normals by its inverse transpose; `flip_normals` negates
// the normals (pbrt's ReverseOrientation, Mitsuba's flip_normals) and `flip_winding` reverses the
// winding of a mesh without normals (its front side then comes from the winding alone). The
// normals are checked (one per vertex, finite, not zero; refused at `at` otherwise) and normalised.
std::optional<Error> place_mesh(MeshShape* mesh, const glm::mat4& m, bool flip_normals, bool flip_winding, const Location& at);

// Mitsuba's vertex normals for a mesh that has none and is not face_normals: each vertex the sum
// of its faces' unit normals weighted by the face's angle at the vertex (Thürmer and Wüthrich
// 1998, as Mitsuba 3's Mesh::recompute_vertex_normals). A vertex no face gives a direction keeps
// the normal of its first face (or +z when it has none).
void angle_weighted_normals(MeshShape* mesh);

// Mitsuba's cube: [-1, 1]^3 as 24 vertices (four per face, with that face's uv from (0, 0) to
// (1, 1)) and 12 triangles whose front sides face outwards.
MeshShape cube_mesh();

// An open tube around the z axis (pbrt's and Mitsuba's cylinder, without caps as theirs are), of
// radius `radius` from z0 to z1 > z0, its front side facing outwards, as a mesh of
// kCylinderSegments quads (two triangles each) whose vertices lie on the surface, with the
// surface's normals (so it shades as the analytic tube); uv is (angle / 2 pi, (z - z0) / (z1 - z0)). The mesh stands in for the analytic surface: its points are
// within radius * (1 - cos(pi / 256)) (7.5e-5 radius) of it, and its area is 2.5e-5 smaller.
inline constexpr int kCylinderSegments = 256;
MeshShape tube_mesh(float radius, float z0, float z1);

// --- instancing (Scene::groups, Scene::instances) ---
// Makes `s` a member of group `group`: a quad becomes its two triangles (corner, +edge1, +edge1+edge2
// and corner, +edge1+edge2, +edge2: the same surface and front side), a mesh stays. Why it cannot
// be one, for the caller to locate: an emitting shape (pbrt-v4: "area lights not supported with
// object instancing"), a sphere or a disk (an instance's transform may not keep one a sphere or a
// disk; tessellate it).
std::optional<std::string> make_group_member(Shape* s, int group);

// Affine transform helpers.
glm::vec3 apply_point(const glm::mat4& m, glm::vec3 p);
glm::vec3 apply_vector(const glm::mat4& m, glm::vec3 v);
glm::vec3 apply_normal(const glm::mat4& m, glm::vec3 n);  // by the inverse transpose, normalised
bool swaps_handedness(const glm::mat4& m);
// True when the linear part is a rotation (or reflection) times a uniform scale, stored in *scale.
bool is_similarity(const glm::mat4& m, float* scale);

class SceneBuilder {
 public:
  // Materials are referenced by index in Shape::material.
  int add_material(std::string name, Material m, MaterialTextures textures = {});
  // Textures (scene/texture.h): a node, returning its index in Scene::textures; an image file
  // (resolved) read through io/image_read.h with `options` (the builder counts the scene's
  // texels), once per scene for each path and decoding; refused at `at` (kBadFile, kLimit).
  int add_texture(const Texture& t);
  int constant_texture(glm::vec3 value) { return add_texture(constant(value)); }
  Result<int> add_image(const std::string& path, ImageReadOptions options, const Location& at);
  const Texture& texture(int index) const { return scene_.textures[static_cast<std::size_t>(index)]; }
  void add_shape(Shape s) { scene_.shapes.push_back(std::move(s)); }
  // Instancing: a group (its index, for Shape::group and ShapeInstance::group) and an instance of one.
  int add_group(std::string name, std::string pointer) {
    scene_.groups.push_back({std::move(name), std::move(pointer)});
    return static_cast<int>(scene_.groups.size()) - 1;
  }
  void add_instance(ShapeInstance i) { scene_.instances.push_back(std::move(i)); }
  void add_light(Light l) { scene_.lights.push_back(std::move(l)); }
  // A uniform infinite light (add_uniform_environment in scene.h, called by finish() once the
  // scene is complete); `where` names it in messages.
  void add_environment(glm::vec3 radiance, std::string where) { environment_.push_back({radiance, std::move(where)}); }
  // An image infinite light (add_image_environment in scene.h, by finish(); at most one).
  void add_environment_image(EnvironmentImage image, std::string where) { environment_image_.emplace(std::move(image), std::move(where)); }
  bool has_environment_image() const { return environment_image_.has_value(); }
  // The texels of the scene's images read so far (--max-texels).
  std::size_t* texels() { return &texels_; }
  // A distant light covering the whole scene (its aperture is placed by finish()).
  void add_distant(glm::vec3 direction, glm::vec3 irradiance);
  // `camera` holds position, look_at (position + forward), up (the image's up) and the optics;
  // `image_right` is the world direction of the image's +x.
  void set_camera(const Camera& camera, glm::vec3 image_right);
  bool has_camera() const { return has_camera_; }
  // `included`: the files the main file included (named in errors about the whole scene).
  Result<Scene> finish(const std::string& file, const std::vector<std::string>& included = {});

 private:
  Scene scene_;
  struct Distant {
    glm::vec3 direction, irradiance;
  };
  std::vector<Distant> distant_;
  std::vector<std::pair<glm::vec3, std::string>> environment_;
  std::optional<std::pair<EnvironmentImage, std::string>> environment_image_;
  std::size_t texels_ = 0;  // of every image the scene reads: textures (add_image) and its environment
  glm::vec3 image_right_{1.0f, 0.0f, 0.0f};
  bool has_camera_ = false;
  std::map<std::tuple<std::string, int, float>, int> images_;  // (path, encoding, gamma) -> Scene::images index
};

// A mix of two materials, each with its textured parameters (blend() when none has any):
// (1 − w) a + w b, or with `amount` >= 0 a float texture's lerp (MaterialTextures::amount). A mix
// of a part that is itself a mix by a texture is refused by the callers.
std::pair<Material, MaterialTextures> blend_textured(const Material& a, const MaterialTextures& ta, const Material& b,
                                                     const MaterialTextures& tb, float w, int amount);

}  // namespace pathex::import
