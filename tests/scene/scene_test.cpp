// Scenes: the bad-scene corpus through the CLI (exact message, exit 2), every sample scene's
// types and universe, and the Embree layer (the two-ray smoke test, exact analytic
// intersections, area sampling).
#include <gtest/gtest.h>

#include <cstdio>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "automata/ops.h"
#include "classify/pathclass.h"
#include "scene/scene.h"
#include "scene/universe.h"
#include "trace/embree_scene.h"
#include "trace/rng.h"

namespace pathex {
namespace {

const std::string kDir = PATHEX_SOURCE_DIR;

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// --- the corpus: tests/scene/bad/*.json, expected stderr in expected.json ---
TEST(BadScenes, EachGivesItsMessageAndExitCode2) {
  const nlohmann::json expected = nlohmann::json::parse(slurp(kDir + "/tests/scene/bad/expected.json"));
  ASSERT_GE(expected.size(), 20u);
  for (const auto& [file, message] : expected.items()) {
    const std::string cmd = "cd '" + kDir + "' && '" + PATHEX_BINARY + "' trace tests/scene/bad/" + file +
                            " --quiet --out /tmp/pathex-bad-scene-out 2>&1 >/dev/null";
    FILE* p = popen(cmd.c_str(), "r");
    std::string out;
    char buf[4096];
    std::size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) out.append(buf, n);
    const int status = pclose(p);
    EXPECT_EQ(WEXITSTATUS(status), 2) << file;
    EXPECT_EQ(out, message.get<std::string>()) << file;
  }
}

// --- sample scenes ---
struct Expect {
  const char* file;
  std::set<LightType> lights;
  SensorType sensor;
  LetterMask interior;
  const char* universe;  // U_s as an expression
};

TEST(SampleScenes, TypesAndUniverses) {
  const LetterMask d = 1u << kD, sd = (1u << kS) | (1u << kD);
  const Expect cases[] = {
      {"cornell.json", {LightType::kArea}, SensorType::kPinhole, sd, "LDD.*DSE"},
      {"point-mirror-caustic.json", {LightType::kPoint}, SensorType::kPinhole, sd, "LSD[SD]*DSE"},
      {"mirror-ortho.json", {LightType::kPoint}, SensorType::kOrthographic, sd, "LSD[SD]*SDE"},
      {"spotmeter-caustic.json", {LightType::kPoint}, SensorType::kSpotmeter, sd, "LSD[SD]*SSE"},
      {"point-glass.json", {LightType::kPoint}, SensorType::kPinhole, sd, "LSD[SD]*DSE"},
      {"sun-window.json", {LightType::kDistant}, SensorType::kPinhole, d, "LDSD*DSE"},
      {"laser.json", {LightType::kLaser}, SensorType::kPinhole, sd, "LSS[SD]*DSE"},
      {"closed-sphere-point.json", {LightType::kPoint}, SensorType::kPinhole, d, "LSDD*DSE"},
      {"closed-sphere-emitting.json", {LightType::kArea}, SensorType::kPinhole, d, "LDDD*DSE"},
      {"point-plane.json", {LightType::kPoint}, SensorType::kPinhole, d, "LSDD*DSE"},
  };
  for (const Expect& e : cases) {
    Result<Scene> s = load_scene_file(kDir + "/samples/scenes/" + e.file);
    ASSERT_TRUE(s.ok()) << s.error().render();
    const SceneTypes t = scene_types(*s);
    EXPECT_EQ(t.lights, e.lights) << e.file;
    EXPECT_EQ(t.sensor, e.sensor) << e.file;
    EXPECT_EQ(t.interior, e.interior) << e.file;
    EXPECT_TRUE(is_equivalent(scene_universe(t), compile_class(e.universe, ClassOptions{})->dfa)) << e.file;
  }
}

TEST(SampleScenes, DefaultSceneIsTheCornellBox) {
  Result<Scene> s = load_scene_json(default_scene_json(), ".", "default");
  ASSERT_TRUE(s.ok()) << s.error().render();
  EXPECT_EQ(slurp(kDir + "/samples/scenes/cornell.json"), default_scene_json());
  EXPECT_EQ(s->shapes.size(), 8u);
}

// --- Embree ---
Scene one_shape(const std::string& shape_json) {
  const std::string text = R"({"camera": {"type": "pinhole", "position": [0, 0, 5], "look_at": [0, 0, 0]},
    "materials": {"m": {"type": "diffuse"}}, "shapes": [)" + shape_json +
                           R"(], "lights": [{"type": "point", "position": [0, 0, 3], "intensity": [1, 1, 1]}]})";
  Result<Scene> s = load_scene_json(text, ".", "inline");
  EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().render());
  return *s;
}

TEST(Embree, TwoRaySmokeTest) {
  // A triangle in the plane z = 0; one ray hits it at t = 1, one misses.
  std::ofstream("/tmp/pathex-smoke.obj") << "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n";
  const Scene s = one_shape(R"({"type": "mesh", "file": "/tmp/pathex-smoke.obj", "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  const std::optional<Hit> hit = (*es)->intersect({0, 0, 1}, {0, 0, -1}, {0, 0, 0});
  ASSERT_TRUE(hit.has_value());
  EXPECT_FLOAT_EQ(hit->t, 1.0f);
  EXPECT_EQ(hit->shape, 0);
  EXPECT_FLOAT_EQ(hit->normal.z, 1.0f);
  EXPECT_FALSE((*es)->intersect({5, 5, 1}, {0, 0, -1}, {0, 0, 0}).has_value());
}

TEST(Embree, ExactAnalyticIntersections) {
  const Scene s = one_shape(R"({"type": "sphere", "center": [0, 0, 0], "radius": 0.5, "material": "m"},
                              {"type": "disk", "center": [0, 0, -2], "normal": [0, 0, 1], "radius": 1, "material": "m"},
                              {"type": "quad", "corner": [-1, -1, -3], "edge1": [2, 0, 0], "edge2": [0, 2, 0], "material": "m"})");
  auto es = EmbreeScene::build(s);
  ASSERT_TRUE(es.ok());
  const auto sphere = (*es)->intersect({0, 0, 3}, {0, 0, -1}, {0, 0, 0});
  ASSERT_TRUE(sphere);
  EXPECT_NEAR(sphere->t, 2.5f, 2.5e-6f);
  EXPECT_EQ(sphere->shape, 0);
  // Off-centre: the chord at height 0.3 enters at z = sqrt(0.25 - 0.09) = 0.4.
  const auto chord = (*es)->intersect({0.3f, 0, 3}, {0, 0, -1}, {0, 0, 0});
  ASSERT_TRUE(chord);
  EXPECT_NEAR(chord->t, 2.6f, 2.6e-6f);
  // From inside the sphere outwards (the closed-sphere scenes).
  const auto inside = (*es)->intersect({0, 0, 0}, {0, 1, 0}, {0, 0, 0});
  ASSERT_TRUE(inside);
  EXPECT_NEAR(inside->t, 0.5f, 1e-6f);
  const auto disk = (*es)->intersect({0.7f, 0, 3}, {0, 0, -1}, {0, 0, 0});
  ASSERT_TRUE(disk);
  EXPECT_EQ(disk->shape, 1);
  EXPECT_NEAR(disk->t, 5.0f, 5e-6f);
  const auto quad = (*es)->intersect({0.95f, 0.95f, 3}, {0, 0, -1}, {0, 0, 0});
  ASSERT_TRUE(quad);
  EXPECT_EQ(quad->shape, 2);
  EXPECT_NEAR(quad->t, 6.0f, 6e-6f);
  // Visibility between the sphere's top and a point above it, and through it.
  EXPECT_TRUE((*es)->visible({0, 0.5f, 0}, {0, 1, 0}, {0, 2, 0}, {0, 0, 0}));
  EXPECT_FALSE((*es)->visible({0, 0, 2}, {0, 0, 0}, {0, 0, -1.5f}, {0, 0, 0}));
}

TEST(Embree, AreaSamplingIsUniformAndOnTheSurface) {
  std::ofstream("/tmp/pathex-two.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 10 0 0\nv 13 0 0\nv 10 1 0\nf 1 2 3\nf 4 5 6\n";
  const Scene s2 = one_shape(R"({"type": "sphere", "center": [1, 2, 3], "radius": 2, "material": "m"},
                               {"type": "disk", "center": [0, 0, 0], "normal": [0, 1, 0], "radius": 1.5, "material": "m"},
                               {"type": "mesh", "file": "/tmp/pathex-two.obj", "material": "m"})");
  auto es = EmbreeScene::build(s2);
  ASSERT_TRUE(es.ok());
  EXPECT_NEAR((*es)->shape_area(0), 4 * kPi * 4, 1e-4);
  EXPECT_NEAR((*es)->shape_area(1), kPi * 2.25, 1e-5);
  EXPECT_NEAR((*es)->shape_area(2), 0.5 + 1.5, 1e-6);
  // The second triangle has 3/4 of the mesh's area: 3/4 of the samples, within 4 sigma.
  const int n = 40000;
  int second = 0;
  for (int i = 0; i < n; ++i) {
    Sampler rng(5, static_cast<std::uint64_t>(i), 0);
    const SurfaceSample a = (*es)->sample_shape(0, rng.get2d());
    EXPECT_NEAR(glm::length(a.position - glm::vec3(1, 2, 3)), 2.0f, 1e-5f);
    const SurfaceSample b = (*es)->sample_shape(1, rng.get2d());
    EXPECT_NEAR(b.position.y, 0.0f, 1e-6f);
    EXPECT_LE(glm::length(b.position), 1.5f + 1e-5f);
    if ((*es)->sample_shape(2, rng.get2d()).position.x >= 10.0f) ++second;
  }
  const double sigma = std::sqrt(n * 0.75 * 0.25);
  EXPECT_NEAR(second, 0.75 * n, 4 * sigma);
}

}  // namespace
}  // namespace pathex
