// Scenes: the bad-scene corpus (exact pointer and message from the library, exit code 2 and the
// same line from the CLI), the camera-sees-geometry rule, transforms, OBJ features, every sample
// scene's types and universe, synthetic scene universes, and the embedded default scene.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <nlohmann/json.hpp>

#include "automata/ops.h"
#include "support/cli_run.h"
#include "classify/pathclass.h"
#include "scene/scene.h"
#include "scene/universe.h"

namespace pathex {
namespace {

const std::string kDir = PATHEX_SOURCE_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Paths in errors are as the loader saw them; make them relative to the source tree.
std::string relative(std::string s) {
  for (std::size_t at; (at = s.find(kDir + "/")) != std::string::npos;) s.erase(at, kDir.size() + 1);
  return s;
}

// --- the corpus: tests/scene/bad/*.json, each with its pointer (or OBJ line) and message ---
// tests/scene/bad/expected.json is the table: {"file.json": {"where": ..., "message": ...}}.
nlohmann::json expected_table() { return nlohmann::json::parse(slurp(kDir + "/tests/scene/bad/expected.json")); }

TEST(BadScenes, EveryFileIsInTheTable) {
  const nlohmann::json table = expected_table();
  EXPECT_GE(table.size(), 40u);
  for (const auto& entry : std::filesystem::directory_iterator(kDir + "/tests/scene/bad")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() == ".json" && name != "expected.json") {
      EXPECT_TRUE(table.contains(name)) << name;
    }
  }
}

TEST(BadScenes, LibraryNamesWhereAndWhat) {
  const nlohmann::json table = expected_table();
  for (const auto& [file, want] : table.items()) {
    const Result<Scene> s = load_scene_file(kDir + "/tests/scene/bad/" + file);
    ASSERT_FALSE(s.ok()) << file;
    EXPECT_EQ(relative(s.error().where), want.at("where").get<std::string>()) << file;
    EXPECT_EQ(relative(s.error().message), want.at("message").get<std::string>()) << file;
  }
}

TEST(BadScenes, CliPrintsTheSameLineAndExits2) {
  const nlohmann::json table = expected_table();
  for (const auto& [file, want] : table.items()) {
    const pathex::test::CliRun r =
        pathex::test::run_pathex("trace tests/scene/bad/" + file + " --quiet --out /tmp/pathex-bad-scene-out");
    EXPECT_EQ(r.code, 2) << file;
    EXPECT_EQ(r.err, "pathex: error: " + want.at("where").get<std::string>() + ": " + want.at("message").get<std::string>() + "\n")
        << file;
  }
}

// --- mutations of the sample scenes never crash and always name a place ---
// Each case replaces one value anywhere in a sample scene (by a value of another kind, a
// negative or huge number, an empty array) or deletes one key; the loader must answer with a
// scene or an Error whose `where` is a JSON pointer into the file or an OBJ location.
TEST(BadScenes, RandomMutationsGiveErrorsNotCrashes) {
  std::vector<nlohmann::json> scenes;
  for (const auto& entry : std::filesystem::directory_iterator(kDir + "/samples/scenes")) {
    if (entry.path().extension() == ".json") scenes.push_back(nlohmann::json::parse(slurp(entry.path().string())));
  }
  ASSERT_FALSE(scenes.empty());
  const nlohmann::json replacements[] = {nullptr, true, -1, 0, 1e300, -1e-300, 2.5, "text", nlohmann::json::array(),
                                         nlohmann::json::array({1, 2}), nlohmann::json::object(), nlohmann::json{{"type", "sphere"}}};
  std::mt19937 rng(7);
  int errors = 0;
  for (int trial = 0; trial < 3000; ++trial) {
    nlohmann::json doc = scenes[rng() % scenes.size()];
    // Walk down to a random value, remembering its parent.
    nlohmann::json* parent = nullptr;
    nlohmann::json* node = &doc;
    std::string key;
    std::size_t index = 0;
    for (int depth = 0; depth < 6 && (node->is_object() || node->is_array()) && !node->empty(); ++depth) {
      if (depth > 0 && rng() % 3 == 0) break;
      parent = node;
      if (node->is_object()) {
        auto it = node->begin();
        std::advance(it, static_cast<long>(rng() % node->size()));
        key = it.key();
        node = &(*node)[key];
      } else {
        index = rng() % node->size();
        node = &(*node)[index];
      }
    }
    if (parent && parent->is_object() && rng() % 4 == 0) {
      parent->erase(key);
    } else {
      *node = replacements[rng() % std::size(replacements)];
    }
    const Result<Scene> s = load_scene_json(doc.dump(), kDir + "/samples/scenes", "m.json");
    if (s.ok()) continue;
    ++errors;
    const std::string& where = s.error().where;
    EXPECT_TRUE(where.rfind("m.json:/", 0) == 0 || where.find(".obj") != std::string::npos) << where << " " << doc.dump();
    EXPECT_FALSE(s.error().message.empty());
  }
  EXPECT_GT(errors, 1500);  // most mutations break something
}

// --- scenes written inline ---
std::string scene_with(const std::string& camera, const std::string& shapes) {
  return R"({"camera": )" + camera + R"(, "materials": {"m": {"type": "diffuse"}}, "shapes": [)" + shapes +
         R"(], "lights": [{"type": "point", "position": [0, 5, 0], "intensity": [1, 1, 1]}]})";
}
Result<Scene> load_inline(const std::string& text) { return load_scene_json(text, "/tmp", "inline"); }

// A sphere of radius r at `c`.
std::string ball(const std::string& c, double r) {
  return R"({"type": "sphere", "center": )" + c + R"(, "radius": )" + std::to_string(r) + R"(, "material": "m"})";
}

constexpr const char* kSeesNothing = "the camera sees no geometry: no shape's bounding box meets its field of view";

TEST(CameraSees, PinholeSeesASmallSphereAnywhereInItsField) {
  // The old rule cast a 9 x 9 grid of rays; a 1 cm ball between two of them was refused. The
  // field of view at distance 10 spans +-10 tan(22.5 deg) = +-4.14.
  const std::string cam = R"({"type": "pinhole", "position": [0, 0, 0], "look_at": [0, 0, -1], "fov": 45})";
  for (const char* c : {"[0.517, 0.517, -10]", "[4.13, 0, -10]", "[-4.1, 4.1, -10]", "[0, 0, -1e6]"})
    EXPECT_TRUE(load_inline(scene_with(cam, ball(c, 0.01))).ok()) << c;
  // Just outside the field (the ball's box reaches 4.14 + 0.01 < 4.2), or behind the camera.
  for (const char* c : {"[4.2, 0, -10]", "[0, -4.2, -10]", "[0, 0, 10]"}) {
    const Result<Scene> s = load_inline(scene_with(cam, ball(c, 0.01)));
    ASSERT_FALSE(s.ok()) << c;
    EXPECT_EQ(s.error().message, kSeesNothing);
    EXPECT_EQ(s.error().where, "inline:/camera");
  }
  // A camera inside a closed sphere sees it.
  EXPECT_TRUE(load_inline(scene_with(cam, ball("[0, 0, 0]", 1.0))).ok());
}

TEST(CameraSees, ApertureWidensTheLensField) {
  // A lens of aperture radius A focused at F sees, at distance z = 2F, out to |x| = A + 2 F tan
  // (the ray from one lens edge through the opposite image edge): 1 + 8.28 = 9.28 for A = 1,
  // F = 10, against 8.28 for the pinhole. The loader's region is the pyramid |x| <= A + z (tan +
  // A / F), a superset, which ends at 11.28 there.
  const std::string pinhole = R"({"type": "pinhole", "position": [0, 0, 0], "look_at": [0, 0, -1], "fov": 45})";
  const std::string lens = R"({"type": "lens", "position": [0, 0, 0], "look_at": [0, 0, -1], "fov": 45,
                                "aperture_radius": 1, "focus_distance": 10})";
  EXPECT_FALSE(load_inline(scene_with(pinhole, ball("[9, 0, -20]", 0.01))).ok());
  EXPECT_TRUE(load_inline(scene_with(lens, ball("[9, 0, -20]", 0.01))).ok());
  EXPECT_FALSE(load_inline(scene_with(lens, ball("[11.5, 0, -20]", 0.01))).ok());
}

TEST(CameraSees, OrthographicFilmAndSpotMeterRay) {
  const std::string ortho = R"({"type": "orthographic", "position": [0, 0, 0], "look_at": [0, 0, -1],
                                 "film_width": 2, "film_height": 1})";
  EXPECT_TRUE(load_inline(scene_with(ortho, ball("[0.99, 0, -100]", 0.001))).ok());
  EXPECT_FALSE(load_inline(scene_with(ortho, ball("[1.01, 0, -100]", 0.001))).ok());
  EXPECT_FALSE(load_inline(scene_with(ortho, ball("[0, 0.51, -100]", 0.001))).ok());
  const std::string meter = R"({"type": "spotmeter", "position": [0, 0, 0], "look_at": [1, 1, -1]})";
  EXPECT_TRUE(load_inline(scene_with(meter, ball("[10, 10, -10]", 0.001))).ok());
  EXPECT_FALSE(load_inline(scene_with(meter, ball("[10, 10.01, -10]", 0.001))).ok());
  // A quad in the plane x = 0, seen edge-on by a ray in that plane, is met (its box is flat).
  const std::string along_z = R"({"type": "spotmeter", "position": [0, 0, 0], "look_at": [0, 0, -1]})";
  EXPECT_TRUE(load_inline(scene_with(along_z, R"({"type": "quad", "corner": [0, -1, -5], "edge1": [0, 2, 0],
                                                   "edge2": [0, 0, -2], "material": "m"})"))
                  .ok());
}

// --- transforms are applied at load: scale, then rotate, then translate ---
TEST(Transforms, AppliedToEveryShapeKind) {
  const std::string cam = R"({"type": "pinhole", "position": [0, 0, 20], "look_at": [0, 0, 0], "fov": 90})";
  const Result<Scene> s = load_inline(scene_with(cam, R"(
    {"type": "quad", "corner": [1, 0, 0], "edge1": [1, 0, 0], "edge2": [0, 1, 0], "material": "m",
     "transform": {"scale": [2, 3, 1], "rotate": {"axis": [0, 0, 1], "degrees": 90}, "translate": [10, 0, 0]}},
    {"type": "sphere", "center": [1, 0, 0], "radius": 0.5, "material": "m",
     "transform": {"scale": 4, "rotate": {"axis": [0, 1, 0], "degrees": 90}}},
    {"type": "disk", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 1, "material": "m",
     "transform": {"rotate": {"axis": [1, 0, 0], "degrees": 90}, "scale": 2}})"));
  ASSERT_TRUE(s.ok()) << s.error().render();
  // Quad: corner (1,0,0) -> scaled (2,0,0) -> rotated (0,2,0) -> translated (10,2,0); edge1 (1,0,0)
  // -> (2,0,0) -> (0,2,0); edge2 (0,1,0) -> (0,3,0) -> (-3,0,0).
  const auto& q = std::get<QuadShape>(s->shapes[0].geometry);
  EXPECT_NEAR(glm::distance(q.corner, glm::vec3(10, 2, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::distance(q.edge1, glm::vec3(0, 2, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::distance(q.edge2, glm::vec3(-3, 0, 0)), 0.0f, 1e-5f);
  // Sphere: centre (1,0,0) -> (4,0,0) -> rotated 90 deg about y -> (0,0,-4); radius 0.5 * 4.
  const auto& b = std::get<SphereShape>(s->shapes[1].geometry);
  EXPECT_NEAR(glm::distance(b.center, glm::vec3(0, 0, -4)), 0.0f, 1e-5f);
  EXPECT_FLOAT_EQ(b.radius, 2.0f);
  // Disk: normal +y rotated 90 deg about x -> +z, unit; radius doubled.
  const auto& d = std::get<DiskShape>(s->shapes[2].geometry);
  EXPECT_NEAR(glm::distance(d.normal, glm::vec3(0, 0, 1)), 0.0f, 1e-6f);
  EXPECT_FLOAT_EQ(d.radius, 2.0f);
}

// --- OBJ features tinyobjloader handles and our checks accept ---
TEST(Obj, RelativeIndicesPolygonsAndCornerForms) {
  std::ofstream("/tmp/pathex-scene-test.obj") << "# a unit square as one polygon, then a triangle with negative indices\n"
                                                 "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                                 "vt 0 0\nvn 0 0 1\n"
                                                 "f 1/1/1 2/1/1 3//1 4\n"
                                                 "v 5 0 0\nv 6 0 0\nv +5 1.0e0 0 1\n"
                                                 "f -3 -2 -1\n";
  const std::string cam = R"({"type": "pinhole", "position": [0.5, 0.5, 5], "look_at": [0.5, 0.5, 0]})";
  const Result<Scene> s = load_inline(scene_with(cam, R"({"type": "mesh", "file": "pathex-scene-test.obj", "material": "m"})"));
  ASSERT_TRUE(s.ok()) << s.error().render();
  const auto& m = std::get<MeshShape>(s->shapes[0].geometry);
  ASSERT_EQ(m.positions.size(), 7u);
  ASSERT_EQ(m.triangles.size(), 3u);  // the square in two triangles, and one more
  EXPECT_EQ(m.triangles[2], glm::uvec3(4, 5, 6));
  EXPECT_EQ(m.positions[6], glm::vec3(5, 1, 0));
  EXPECT_EQ(m.file, "pathex-scene-test.obj");
}

// --- sample scenes: every file in samples/scenes is in this table ---
struct Expect {
  const char* file;
  std::set<LightType> lights;
  SensorType sensor;
  LetterMask interior;
  const char* universe;  // U_s as a full-path expression
};

TEST(SampleScenes, TypesAndUniverses) {
  const LetterMask d = 1u << kD, sd = (1u << kS) | (1u << kD);
  const Expect cases[] = {
      {"cornell.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD[SD]*DSE"},
      {"point-mirror-caustic.json", {LightType::kPoint}, SensorType::kPinhole, sd, "LSD[SD]*DSE"},
      {"mirror-ortho.json", {LightType::kPoint}, SensorType::kOrthographic, sd, "LSD[SD]*SDE"},
      {"spotmeter-caustic.json", {LightType::kPoint}, SensorType::kSpotmeter, sd, "LSD[SD]*SSE"},
      {"point-glass.json", {LightType::kPoint}, SensorType::kPinhole, sd, "LSD[SD]*DSE"},
      {"sun-window.json", {LightType::kDistant}, SensorType::kPinhole, d, "LDSD*DSE"},
      {"sky-glass.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD[SD]*DSE"},  // the sky is an area light
      {"sky-image.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD[SD]*DSE"},  // an image sky too (docs/lights.md)
      {"materials.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD[SD]*DSE"},  // issue 35's materials
      {"small-light-caustic.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD[SD]*DSE"},  // issue 36
      {"lamp-glass.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD[SD]*DSE"},  // issue 40
      {"laser.json", {LightType::kLaser}, SensorType::kPinhole, sd, "LSS[SD]*DSE"},
      {"closed-sphere-point.json", {LightType::kPoint}, SensorType::kPinhole, d, "LSDD*DSE"},
      {"closed-sphere-emitting.json", {LightType::kArea}, SensorType::kPinhole, d, "LDDD*DSE"},
      {"point-plane.json", {LightType::kPoint}, SensorType::kPinhole, d, "LSDD*DSE"},
  };
  std::set<std::string> covered;
  for (const Expect& e : cases) {
    covered.insert(e.file);
    Result<Scene> s = load_scene_file(kDir + "/samples/scenes/" + e.file);
    ASSERT_TRUE(s.ok()) << s.error().render();
    const SceneTypes t = scene_types(*s);
    EXPECT_EQ(t.lights, e.lights) << e.file;
    EXPECT_EQ(t.sensor, e.sensor) << e.file;
    EXPECT_EQ(t.interior, e.interior) << e.file;
    Result<PathClass> want = compile_class(e.universe, ClassOptions{});
    ASSERT_TRUE(want.ok());
    EXPECT_TRUE(is_equivalent(scene_universe(t), want->dfa)) << e.file;
  }
  for (const auto& entry : std::filesystem::directory_iterator(kDir + "/samples/scenes")) {
    if (entry.path().extension() == ".json") {
      EXPECT_TRUE(covered.count(entry.path().filename().string())) << entry.path();
    }
  }
}

TEST(SceneUniverse, UnionOfLightPairsTimesInteriorTimesSensorPair) {
  struct Case {
    SceneTypes types;
    const char* universe;
  };
  const LetterMask d = 1u << kD, s = 1u << kS;
  const Case cases[] = {
      {{{LightType::kPoint}, SensorType::kPinhole, static_cast<LetterMask>(s | d)}, "LSD[SD]*DSE"},
      {{{LightType::kArea, LightType::kLaser}, SensorType::kOrthographic, d}, "(LDD|LSS)D*SDE"},
      {{{LightType::kDistant}, SensorType::kLens, s}, "LDSS*DDE"},
      {{{LightType::kArea, LightType::kDistant, LightType::kPoint, LightType::kLaser}, SensorType::kSpotmeter,
        static_cast<LetterMask>(s | d)},
       "L..[SD]*SSE"},
      // A mixture whose weights are all zero gives no interior letter: only direct paths (k = 1).
      {{{LightType::kArea}, SensorType::kPinhole, 0}, "LDDDSE"},
  };
  for (const Case& c : cases) {
    Result<PathClass> want = compile_class(c.universe, ClassOptions{});
    ASSERT_TRUE(want.ok()) << c.universe;
    EXPECT_TRUE(is_equivalent(scene_universe(c.types), want->dfa)) << c.universe;
  }
}

TEST(SampleScenes, DescribeNamesTypesAndLetters) {
  Result<Scene> s = load_scene_file(kDir + "/samples/scenes/point-mirror-caustic.json");
  ASSERT_TRUE(s.ok());
  EXPECT_EQ(describe(scene_types(*s)), "lights point; sensor pinhole; materials D S");
}

TEST(SampleScenes, DefaultSceneIsTheCornellBox) {
  Result<Scene> s = load_scene_json(default_scene_json(), ".", "default");
  ASSERT_TRUE(s.ok()) << s.error().render();
  EXPECT_EQ(slurp(kDir + "/samples/scenes/cornell.json"), default_scene_json());
  EXPECT_EQ(s->shapes.size(), 8u);
  const SceneTypes t = scene_types(*s);
  EXPECT_EQ(t.lights, std::set<LightType>{LightType::kArea});
  EXPECT_EQ(t.sensor, SensorType::kPinhole);
}

}  // namespace
}  // namespace pathex
