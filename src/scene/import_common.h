// What the pbrt-v4 and Mitsuba 3 importers (pbrt_import.*, mitsuba_import.*) share: located
// errors, the mapping of their materials onto pathex's, PLY meshes through assimp, and the
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

#include <optional>
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
// as pbrt-v4 and Mitsuba 3 resolve them, and includes nest at most 32 deep.
class SceneFiles {
 public:
  explicit SceneFiles(const std::string& main_file);
  std::string resolve(const std::string& file) const;
  // The text of `path`, included from `from` at nesting `depth` (0: the main file); `directive`
  // names the including directive in messages.
  Result<std::string> read(const std::string& path, const Location& from, int depth, const std::string& directive) const;

 private:
  std::string base_dir_;
};

// A light's emission (radiance, intensity or irradiance, after any scale) must be non-negative and
// at most kMaxLightValue (scene.h), as in JSON scenes; the error names `at`.
std::optional<Error> check_light_value(glm::vec3 v, const Location& at);

// A mixture of `a` (weight 1 - w) and `b` (weight w), flattened: mixtures of mixtures become one
// mixture whose weights are the products along the way (both formats' mix and blend choose one
// material per shading point with these probabilities, which is the same linear combination).
Material blend(const Material& a, const Material& b, float w);

// Normal-incidence reflectance of a conductor with complex index eta + i k, per channel.
glm::vec3 conductor_reflectance(glm::vec3 eta, glm::vec3 k);

// A PLY file read by assimp: triangles and planar quads (split in two along v0-v2, the surface
// pbrt-v4's bilinear patch has when the quad is planar). Refused, at `at`: a file assimp cannot
// read, polygons of more than four vertices, non-planar quads, points and lines, and per-vertex
// normals (pathex shades meshes with their face normals; a smooth-shaded mesh would look
// different) unless `discard_normals` (Mitsuba's face_normals). The result has a triangle.
Result<MeshShape> load_ply_mesh(const std::string& path, const Location& at, bool discard_normals);

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
  int add_material(std::string name, Material m);
  void add_shape(Shape s) { scene_.shapes.push_back(std::move(s)); }
  void add_light(Light l) { scene_.lights.push_back(std::move(l)); }
  // A uniform infinite light (add_uniform_environment in scene.h, called by finish() once the
  // scene is complete); `where` names it in messages.
  void add_environment(glm::vec3 radiance, std::string where) { environment_.push_back({radiance, std::move(where)}); }
  // A distant light covering the whole scene (its aperture is placed by finish()).
  void add_distant(glm::vec3 direction, glm::vec3 irradiance);
  // `camera` holds position, look_at (position + forward), up (the image's up) and the optics;
  // `image_right` is the world direction of the image's +x.
  void set_camera(const Camera& camera, glm::vec3 image_right);
  bool has_camera() const { return has_camera_; }
  Result<Scene> finish(const std::string& file);

 private:
  Scene scene_;
  struct Distant {
    glm::vec3 direction, irradiance;
  };
  std::vector<Distant> distant_;
  std::vector<std::pair<glm::vec3, std::string>> environment_;
  glm::vec3 image_right_{1.0f, 0.0f, 0.0f};
  bool has_camera_ = false;
};

}  // namespace pathex::import
