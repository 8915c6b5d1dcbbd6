// The scene model: plain values, loaded from JSON (schema: grammar/scene.schema.json) with OBJ
// meshes through tinyobjloader. Every validation error names the file and the JSON pointer of
// the offending value (or the OBJ file and line) and says what was expected (DESIGN §12).
//
// Kinds are closed sets behind one value: shapes, lights and materials are std::variants. Area
// lights are shapes with an emission; the other lights are points, spots, distant lights
// through an aperture and lasers. Exactly one sensor. Transforms are applied at load time
// (scale, then rotate, then translate), so the model holds world-space geometry only.
//
// Scene-level rules: at least one shape; at least one light (an entry in "lights" or a shape with
// an emission; zero power is allowed); and the camera must see some geometry, meaning some
// shape's axis-aligned bounding box meets the camera's viewing region (the field-of-view pyramid
// of a pinhole, widened by the aperture for a lens, the prism over an orthographic film, or a
// spot meter's ray). The test is exact for those boxes, so it never refuses a visible object.
#pragma once

#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

#include <glm/glm.hpp>
#include <glm/mat3x3.hpp>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "core/limits.h"
#include "scene/material.h"
#include "scene/texture.h"

namespace pathex {

struct MeshShape {
  std::string file;                      // as given, relative to the scene file
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  // Per vertex, or empty. `normals` (unit): the mesh is smooth-shaded with their interpolation,
  // and each triangle is wound to face their side (import::place_mesh). `uvs`: read for the
  // textures (scene/texture.h).
  std::vector<glm::vec3> normals;
  std::vector<glm::vec2> uvs;
};
struct SphereShape {
  glm::vec3 center{0.0f};
  float radius = 1.0f;
};
struct QuadShape {  // corner, corner + edge1, corner + edge1 + edge2, corner + edge2
  glm::vec3 corner{0.0f}, edge1{1.0f, 0.0f, 0.0f}, edge2{0.0f, 1.0f, 0.0f};
};
struct DiskShape {
  glm::vec3 center{0.0f}, normal{0.0f, 1.0f, 0.0f};
  float radius = 1.0f;
};
using ShapeGeometry = std::variant<MeshShape, SphereShape, QuadShape, DiskShape>;

struct Shape {
  ShapeGeometry geometry;
  int material = 0;             // index into Scene::materials
  glm::vec3 emission{0.0f};     // radiance Le; nonzero makes the shape an area light (LDD)
  bool two_sided = false;       // emits from both sides
  // σa (per unit length, per channel) of the shape's interior: an absorbing medium that light
  // entering the shape through a transmissive surface crosses (trace/media.h); zero: vacuum.
  glm::vec3 absorption{0.0f};
  std::string pointer;          // "/shapes/3", for messages
  // A float texture (Scene::textures) giving the surface's coverage in [0, 1] (an alpha cut-out,
  // trace/texture_eval.h): rays pass where it is 0, and a fraction 1 − alpha of them where it is
  // between; -1: opaque. A passed-through surface is no vertex (no letter).
  int alpha = -1;
  // -1: placed in the world (the model's world-space geometry). >= 0: a member of
  // Scene::groups[group], in the group's own space, drawn only where Scene::instances place it.
  int group = -1;
  bool emissive() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
};

// Instancing (pbrt-v4 ObjectBegin/ObjectInstance, Mitsuba 3 shapegroup/instance, JSON "groups"):
// a group's member shapes (Shape::group) are stored once, in the group's space, and each instance
// draws them all through its transform (an Embree instance: memory grows with the unique geometry,
// not with the instances). Members are meshes without emission (area lights in instances are
// refused, as pbrt-v4 refuses them).
struct ShapeGroup {
  std::string name;
  std::string pointer;  // where it is defined, for messages
};
struct ShapeInstance {
  int group = 0;              // index into Scene::groups
  glm::mat4 to_world{1.0f};   // affine, invertible: world = to_world * group space
  std::string pointer;        // where it is placed, for messages
};

struct PointLight {   // LSD
  glm::vec3 position{0.0f}, intensity{1.0f};  // W/sr
};
// How a soft-edged spot light's intensity falls between falloff_start_degrees and cone_degrees.
enum class SpotFalloff : std::uint32_t {  // 32 bits: SpotLight has no padding (scene_hash.cpp hashes its bytes)
  kSmoothstep,  // smoothstep in cos θ (pbrt-v4's spot, conedeltaangle)
  kLinear,      // linear in θ (Mitsuba 3's spot, beam_width)
};
struct SpotLight {    // LSD: a point light restricted to a cone
  glm::vec3 position{0.0f}, direction{0.0f, -1.0f, 0.0f}, intensity{1.0f};
  float cone_degrees = 30.0f;            // half angle: nothing is emitted at or beyond it
  float falloff_start_degrees = -1.0f;   // where the falloff starts, ≤ cone_degrees; < 0: a hard edge
  SpotFalloff falloff = SpotFalloff::kSmoothstep;
};
struct DistantLight { // LDS: parallel light of irradiance E entering through a finite aperture
  glm::vec3 direction{0.0f, -1.0f, 0.0f}, irradiance{1.0f};  // W/m² perpendicular to direction
  glm::vec3 aperture_corner{0.0f}, aperture_edge1{1.0f, 0.0f, 0.0f}, aperture_edge2{0.0f, 0.0f, 1.0f};
};
struct LaserLight {   // LSS: one ray
  glm::vec3 position{0.0f}, direction{0.0f, -1.0f, 0.0f}, power{1.0f};  // W
};
using Light = std::variant<PointLight, SpotLight, DistantLight, LaserLight>;

struct Camera {
  SensorType type = SensorType::kPinhole;
  glm::vec3 position{0.0f}, look_at{0.0f, 0.0f, -1.0f}, up{0.0f, 1.0f, 0.0f};
  float fov_degrees = 45.0f;        // pinhole, lens: vertical field of view
  float aperture_radius = 0.0f;     // lens
  float focus_distance = 1.0f;      // lens
  float film_width = 1.0f, film_height = 1.0f;  // orthographic, world units
  int width = 64, height = 64;      // spot meter: 1 x 1
};

// A closed-form reference a scene declares (DESIGN §9), which `pathex converge` measures renderers
// against: the exact image mean (mean pixel luminance) of some path classes. JSON:
//   "reference": {"source": "why these values are exact", "uniform": true,
//                 "classes": [{"name": "1 bounce", "class": "LSDDDSE", "luminance": 0.159155}, …]}
// `uniform` says that every pixel of each class has that value (inside a closed sphere), so
// per-pixel errors can be measured too. A class named "total" is the whole image (class $all).
struct ReferenceClass {
  std::string name;
  std::string expr;        // full notation
  double luminance = 0.0;  // exact image mean
};
struct ClosedFormReference {
  std::string source;
  bool uniform = false;
  std::vector<ReferenceClass> classes;
};

// An image infinite light (docs/lights.md): radiance from every direction, read from an image.
// pbrt-v4's `infinite` with a filename (an equal-area octahedral square), Mitsuba 3's `envmap` and
// the JSON {"type": "environment", "image": …} (latitude-longitude, +Y up; or "equal-area").
struct EnvironmentImage {
  std::string file;         // as given, for messages
  bool equal_area = false;  // pbrt-v4's square; else latitude-longitude (Mitsuba 3)
  int width = 0, height = 0;
  std::vector<glm::vec3> texels;  // linear radiance ≥ 0, row-major from the top row, scale applied
  glm::mat3 to_world{1.0f};       // light space → world: orthogonal (a rotation, or with a mirror)
  int shape = -1;                 // the emitting box (add_image_environment())
  // Directions drawn uniformly over the image instead of by its values (JSON "sampling":
  // "uniform"): the same light, sampled worse; the tests compare the two.
  bool uniform_sampling = false;
};

struct Scene {
  std::string name;
  std::vector<std::string> material_names;
  std::vector<Material> materials;
  std::vector<Shape> shapes;
  std::vector<ShapeGroup> groups;          // instancing: see ShapeGroup
  std::vector<ShapeInstance> instances;
  std::vector<Light> lights;
  Camera camera;
  std::optional<ClosedFormReference> reference;  // "reference", when the scene declares one
  // A uniform infinite light's radiance (pbrt-v4 `infinite` with `L`, Mitsuba 3 `constant`, JSON
  // {"type": "environment"}), when the scene has one; add_uniform_environment() has made it a shape.
  std::optional<glm::vec3> environment;
  // An image infinite light, when the scene has one; add_image_environment() has made its box. A
  // uniform infinite light in the same scene is added to its texels (one box).
  std::optional<EnvironmentImage> environment_image;
  // Textures (scene/texture.h): their nodes, the images they read (each file once per scene), and
  // beside each material the parameters textures give it (empty when no material has any).
  std::vector<Texture> textures;
  std::vector<LinearImage> images;
  std::vector<MaterialTextures> material_textures;
};

// A uniform infinite light of radiance L (DESIGN §1: an area light, letters LDD): light of the same
// radiance L arriving at every point from every direction not blocked by the scene. It is rendered
// exactly as a closed box around everything the scene holds (its shapes, the camera with its lens
// or film, the point-like lights and the distant lights' apertures), padded by a tenth of its
// diagonal, whose six faces emit L inwards and absorb whatever reaches them (a material with no
// components, which gives no letter). Every ray that leaves the scene meets the box and carries L
// back, whatever its origin and direction, which is the infinite light's definition; nothing is
// approximated. Emitter hits, next-event estimation (uniform by area over the box) and light
// subpaths (cosine-weighted from the box) then need no kind of their own. Call it once the scene's
// shapes, lights and camera are complete; several calls add their radiances into one box.
// `pointer` names the light in messages ("/lights/2", "scene.pbrt:14:1").
void add_uniform_environment(Scene* scene, glm::vec3 radiance, const std::string& pointer);
// An image infinite light, rendered as the same box (its faces emit the image's radiance of each
// direction; trace/environment.h samples it). Call it as add_uniform_environment(); a scene holds
// at most one image light (the importers refuse a second, located).
void add_image_environment(Scene* scene, EnvironmentImage image, const std::string& pointer);

struct SceneLoadOptions;
// An image infinite light's image at `path` (as given: `file`), read by read_image (io/image_read.h:
// linear RGB; integer data decoded as sRGB) with its texels counted in *texels_so_far against
// options.max_texels, negative values clamped to 0 (pbrt-v4's ClampZero), times `scale`. An
// equal-area image must be square. Errors name the file; the caller says where it was asked for.
Result<EnvironmentImage> load_environment_image(const std::string& path, const std::string& file, bool equal_area, glm::vec3 scale,
                                                const SceneLoadOptions& options, std::size_t* texels_so_far);
// pbrt-v4's `illuminance` of an equal-area image: the sum over the texels of the upper hemisphere
// (+z in light space) of luminance × cos θ, times 2π / texels — pbrt-v4's own normalisation (which is
// half the hemisphere's illuminance, the texels subtending 4π / texels each; docs/lights.md).
double pbrt_image_illuminance(const EnvironmentImage& image);
// The light-value rule (kMaxLightValue, kMinLightValue below) for an image's texels: components
// below kMinLightValue become 0 (a dark texel, not a refusal), one above kMaxLightValue is refused
// with the message returned.
std::optional<std::string> settle_environment_values(EnvironmentImage* image);

// How much of a scene to load.
struct SceneLoadOptions {
  std::size_t max_file_bytes = Limits{}.max_file_bytes;  // the scene file and each mesh (--max-file-size)
  // false: meshes keep their vertex positions but are not triangulated (enough for the scene's
  // universe and the camera check; what `query --scene` and `check` need).
  bool triangles = true;
  // An imported scene's resources (pbrt-v4, Mitsuba 3; README "Limits"): its text with every
  // included file (--max-scene-size), the nesting of its materials (--max-scene-depth), the
  // components its materials expand to (--max-material-nodes), and, in every format, the
  // vertices plus triangles of all its meshes (--max-mesh-elements).
  std::size_t max_scene_bytes = Limits{}.max_scene_bytes;
  int max_scene_depth = Limits{}.max_scene_depth;
  std::size_t max_material_nodes = Limits{}.max_material_nodes;
  std::size_t max_mesh_elements = Limits{}.max_mesh_elements;
  std::size_t max_texels = Limits{}.max_texels;  // pixels of all its images (--max-texels)
};
// The options of a command's limits (every command that reads a scene passes them through here).
SceneLoadOptions scene_load_options(const Limits& limits, bool triangles = true);
// The world-space axis-aligned box of each instance of a non-empty group: its group's
// members' boxes, their corners moved by the instance's transform. For the scene-level code that
// needs world extents (the camera rule, the environment box, distant lights' apertures).
std::vector<std::pair<glm::vec3, glm::vec3>> instance_boxes(const Scene& scene);

// An OBJ face may have at most this many corners (tinyobjloader's triangulation of one polygon
// is quadratic in its corners; a modeller's n-gons are far smaller).
inline constexpr std::size_t kMaxFaceCorners = 1024;

// The largest emission, intensity, irradiance or power component a scene may give. The tracer sums
// contributions exactly in fixed point and counts one of 2^50 (about 1.1e15) or more as non-finite
// (stats/histogram.h); 1e9 leaves a factor of 1e6 for what geometry and sampling multiply a
// light's value by. Physical values stay far below it (the sun's radiance is about 2e7 W/(m^2 sr)).
inline constexpr float kMaxLightValue = 1e9f;
// The smallest nonzero one (0 is allowed: a light of zero power). Contributions are summed on a
// fixed-point grid of 2^-64 (about 5.4e-20): with a margin of 1e-6 for geometry, a contribution of
// 1e-12 still has 2^24 grid steps, single precision; a light of 1e-20 would round to a black image.
inline constexpr float kMinLightValue = 1e-6f;

// `base_dir` resolves relative mesh paths; `name` prefixes error locations.
Result<Scene> load_scene_json(std::string_view text, const std::string& base_dir, const std::string& name,
                              const SceneLoadOptions& options = {});
// The entry point of every command: dispatches on the extension. `.pbrt` is a pbrt-v4 scene
// (scene/pbrt_import.h), `.xml` a Mitsuba 3 scene (scene/mitsuba_import.h), anything else JSON.
Result<Scene> load_scene_file(const std::string& path, const SceneLoadOptions& options = {});

// An OBJ file's triangles (polygons fan-triangulated); errors name the OBJ file and line. The
// result may have no triangles: callers say where the mesh was asked for.
// `mesh_elements`, when given: the vertices and triangles of the scene's meshes read before, on
// entry, with this mesh's on return (checked against options.max_mesh_elements as they are read).
Result<MeshShape> load_obj_mesh(const std::string& path, const SceneLoadOptions& options = {}, std::size_t* mesh_elements = nullptr);
// A kLimit error at `where` when `elements` (the vertices plus triangles of a scene's meshes so
// far) exceed options.max_mesh_elements.
std::optional<Error> check_mesh_elements(std::size_t elements, const SceneLoadOptions& options, const std::string& where);

// The scene-level rules above (a shape, a light, a camera that sees a shape), which every loader
// checks once the scene is complete: the first one violated, with the JSON pointer it concerns.
struct SceneRuleViolation {
  std::string pointer;
  std::string message;
};
std::optional<SceneRuleViolation> check_scene_rules(const Scene& scene);

// The scene embedded in the binary: a Cornell box with an area light, a mirror and a glass sphere.
const char* default_scene_json();

// What fixes the scene's universe (DESIGN §6): its light types, its sensor, the letters its
// materials can produce.
struct SceneTypes {
  std::set<LightType> lights;
  SensorType sensor = SensorType::kPinhole;
  LetterMask interior = 0;
};
SceneTypes scene_types(const Scene& scene);
// "lights area, point; sensor pinhole; materials D S"
std::string describe(const SceneTypes& t);

}  // namespace pathex
