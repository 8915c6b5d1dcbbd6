// The image infinite light (trace/environment.h, docs/lights.md) against closed forms and
// equivalences, with fixed seeds; tolerances in standard errors (batch means over 32 batches).
//   - the mappings: pbrt-v4's equal-area square and Mitsuba 3's latitude-longitude, both ways;
//   - the direction density integrates to 1 and each sample reports it;
//   - a constant image over a diffuse sphere is the furnace (as the uniform light);
//   - a small bright patch (a sun) gives the same image whether its directions are importance-
//     sampled or drawn uniformly, and pt-nee, lt and bdpt agree;
//   - the patch lights the side of a sphere it faces.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>

#include <glm/glm.hpp>

#include "classify/classifier.h"
#include "stats/convergence.h"
#include "classify/pathclass.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/env_images.h"
#include "support/stat_seed.h"
#include "support/test_classes.h"
#include "support/test_render.h"
#include "trace/environment.h"
#include "trace/render.h"
#include "trace/rng.h"

namespace pathex {
namespace {

using test::scratch;

// --- the mappings ---

TEST(EnvironmentMapping, EqualAreaRoundTripsAndPutsPlusZAtTheCentre) {
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) {
      const glm::vec2 p((static_cast<float>(x) + 0.5f) / 32.0f, (static_cast<float>(y) + 0.5f) / 32.0f);
      const glm::vec3 d = equal_area_square_to_sphere(p);
      EXPECT_NEAR(glm::length(d), 1.0f, 1e-5f);
      const glm::vec2 q = equal_area_sphere_to_square(d);
      EXPECT_NEAR(q.x, p.x, 2e-5f) << x << ", " << y;
      EXPECT_NEAR(q.y, p.y, 2e-5f) << x << ", " << y;
    }
  const glm::vec3 centre = equal_area_square_to_sphere({0.5f, 0.5f});
  EXPECT_NEAR(centre.z, 1.0f, 1e-6f);
  EXPECT_NEAR(equal_area_square_to_sphere({0.0f, 0.0f}).z, -1.0f, 1e-6f);
  // +x is to the right of the centre (u > 1/2 on the v = 1/2 line), +y below it (v > 1/2).
  const glm::vec2 px = equal_area_sphere_to_square({1.0f, 0.0f, 0.0f});
  EXPECT_NEAR(px.x, 1.0f, 1e-6f);
  EXPECT_NEAR(px.y, 0.5f, 1e-6f);
  const glm::vec2 py = equal_area_sphere_to_square({0.0f, 1.0f, 0.0f});
  EXPECT_NEAR(py.x, 0.5f, 1e-6f);
  EXPECT_NEAR(py.y, 1.0f, 1e-6f);
}

TEST(EnvironmentMapping, LatLongIsMitsubasYUp) {
  const auto near = [](glm::vec3 a, glm::vec3 b) { return glm::length(a - b) < 1e-5f; };
  EXPECT_TRUE(near(latlong_to_direction({0.3f, 0.0f}), {0, 1, 0}));     // top row: +Y
  EXPECT_TRUE(near(latlong_to_direction({0.0f, 0.5f}), {0, 0, -1}));    // u = 0: −Z
  EXPECT_TRUE(near(latlong_to_direction({0.25f, 0.5f}), {1, 0, 0}));    // u = 1/4: +X
  EXPECT_TRUE(near(latlong_to_direction({0.5f, 0.5f}), {0, 0, 1}));     // u = 1/2: +Z
  EXPECT_TRUE(near(latlong_to_direction({0.75f, 1.0f}), {0, -1, 0}));   // bottom row: −Y
  for (float u : {0.1f, 0.4f, 0.6f, 0.9f})
    for (float v : {0.2f, 0.5f, 0.8f}) {
      const glm::vec2 q = direction_to_latlong(latlong_to_direction({u, v}));
      EXPECT_NEAR(q.x, u, 1e-5f);
      EXPECT_NEAR(q.y, v, 1e-5f);
    }
}

// A map of w x h texels of value 1 except a bright block, with its distribution.
EnvironmentMap test_map(bool equal_area, int w, int h) {
  EnvironmentMap m;
  m.equal_area = equal_area;
  m.width = w;
  m.height = h;
  m.texels.assign(static_cast<std::size_t>(w * h), glm::vec3(1.0f));
  for (int y = h / 4; y < h / 4 + 2; ++y)
    for (int x = w / 3; x < w / 3 + 2; ++x) m.texels[static_cast<std::size_t>(y * w + x)] = glm::vec3(200.0f, 100.0f, 50.0f);
  m.to_world = glm::mat3(glm::vec3(0, 0, 1), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0));  // a rotation
  m.build_distribution();
  return m;
}

// ∫ p(ω) dω = 1, and each sample's density is environment_pdf() of its direction.
TEST(EnvironmentMapping, DirectionDensityIntegratesToOneAndSamplesReportIt) {
  for (bool equal_area : {true, false}) {
    const EnvironmentMap m = test_map(equal_area, equal_area ? 16 : 32, 16);
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<float> uni(0.0f, 1.0f);
    // The midpoint rule over 1024² cells of the area-preserving square-to-sphere map: the density is
    // piecewise constant, so only the cells its texel edges cross err (well within 0.5 %).
    double sum = 0.0;
    const int n = 1024;
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const glm::vec2 u((static_cast<float>(x) + 0.5f) / n, (static_cast<float>(y) + 0.5f) / n);
        sum += environment_pdf(m, sample_uniform_sphere(u)) / kUniformSpherePdf;
      }
    EXPECT_NEAR(sum / (n * n), 1.0, 0.005) << (equal_area ? "equal-area" : "latlong");
    for (int i = 0; i < 1000; ++i) {
      float pdf = 0.0f;
      const glm::vec3 w = sample_environment(m, {uni(rng), uni(rng)}, &pdf);
      EXPECT_NEAR(pdf, environment_pdf(m, w), 1e-3f * pdf) << (equal_area ? "equal-area" : "latlong");
    }
  }
}

// --- renders ---

using test::Rendered;

Rendered render_json(const std::string& scene_json, const std::string& renderer, const std::vector<std::string>& classes,
                     std::uint64_t spp, std::uint64_t seed = 7) {
  Rendered r = test::render_scene(load_scene_json(scene_json, scratch(), "test"), renderer, classes, spp, /*threads=*/0,
                                  test::stat_seed_from(seed),
                                  test::Sampling{}, /*max_bounces=*/8);
  EXPECT_EQ(r.report.nonfinite_samples, 0u) << renderer;
  return r;
}

using test::expect_close;

// Two estimates of one value: their difference within `sigmas` standard errors of the difference.
void expect_agree(const Estimate& a, const Estimate& b, double sigmas, const std::string& what) {
  const double se = std::sqrt(a.std_error * a.std_error + b.std_error * b.std_error);
  EXPECT_TRUE(std::isfinite(se)) << what;
  EXPECT_LE(std::fabs(a.luminance - b.luminance), sigmas * se + 1e-3 * std::fabs(b.luminance))
      << what << ": " << a.luminance << " ± " << a.std_error << " against " << b.luminance << " ± " << b.std_error;
}

// A constant image of radiance L is the uniform infinite light: over a diffuse sphere of albedo
// rho every pixel is rho L (the furnace), whichever mapping and renderer.
TEST(ImageInfiniteLight, ConstantImageOverADiffuseSphereIsTheFurnace) {
  const double sigmas = test::family_sigmas(16);  // 2 mappings x 4 renderers x 2 classes, 0.1 % together
  const double rho = 0.7, radiance = 1.5;
  test::write_constant_exr("constant_latlong.exr", 16, 8, 1.5f);
  test::write_constant_exr("constant_square.exr", 8, 8, 1.5f);
  for (const char* image : {R"("constant_latlong.exr")", R"("constant_square.exr", "mapping": "equal-area")"}) {
    const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                                    "fov": 20, "width": 6, "height": 6},
      "materials": {"ball": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"}],
      "lights": [{"type": "environment", "image": )" + std::string(image) + "}]}";
    for (const char* renderer : {"pt", "pt-nee", "lt", "bdpt"}) {
      Rendered r = render_json(scene, renderer, {"LDDDDSE", "L.*E"}, 256);
      expect_close(r.report.classes[0].estimate, rho * radiance, sigmas, 0.005, std::string(renderer) + " furnace " + image);
      expect_close(r.report.classes[1].estimate, rho * radiance, sigmas, 0.005, std::string(renderer) + " furnace, every path " + image);
    }
  }
}

// A sun: a 4 x 2 block of texels 200 times brighter than the sky (three quarters of the light),
// over a sphere on a floor. Uniform sampling still finds it often enough at 256 spp for its batch
// means to be near normal (a 2-texel sun 1000 times brighter made its stderr lie at 8 % of seeds).
std::string sun_scene(const std::string& extra) {
  std::vector<float> v(32 * 16 * 3, 0.2f);
  for (int y = 4; y < 6; ++y)
    for (int x = 4; x < 8; ++x)
      for (int c = 0; c < 3; ++c) v[static_cast<std::size_t>((y * 32 + x) * 3 + c)] = c == 2 ? 30.0f : 40.0f;
  test::write_rgb_exr("sun.exr", 32, 16, v);
  return R"({"camera": {"type": "pinhole", "position": [0, 2, -4], "look_at": [0, 0.5, 0], "up": [0, 1, 0],
              "fov": 40, "width": 8, "height": 8},
    "materials": {"ball": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}, "floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0.8, 0], "radius": 0.8, "material": "ball"},
               {"type": "quad", "corner": [-3, 0, -3], "edge1": [0, 0, 6], "edge2": [6, 0, 0], "material": "floor"}],
    "lights": [{"type": "environment", "image": "sun.exr")" + extra + "}]}";
}

// The same light importance-sampled and sampled uniformly over its image gives one image (pt-nee),
// and pt-nee, lt and bdpt agree on it: 8 checks of the difference, 0.1 % together.
TEST(ImageInfiniteLight, ImportanceAndUniformSamplingAndEveryRendererAgree) {
  const double sigmas = test::family_sigmas(8);
  const std::vector<std::string> classes = {"L.*E", "LDD[SD]DSE", "LDD[SD]{2,}DSE"};
  Rendered importance = render_json(sun_scene(""), "pt-nee", classes, 256);
  Rendered uniform = render_json(sun_scene(R"(, "sampling": "uniform")"), "pt-nee", classes, 256, 11);
  Rendered lt = render_json(sun_scene(""), "lt", classes, 256, 13);
  Rendered bdpt = render_json(sun_scene(""), "bdpt", classes, 128, 17);
  for (std::size_t c = 0; c < classes.size(); ++c) {
    expect_agree(importance.report.classes[c].estimate, uniform.report.classes[c].estimate, sigmas, "importance vs uniform " + classes[c]);
    expect_agree(bdpt.report.classes[c].estimate, importance.report.classes[c].estimate, sigmas, "bdpt vs pt-nee " + classes[c]);
    if (c != 1) expect_agree(lt.report.classes[c].estimate, importance.report.classes[c].estimate, sigmas, "lt vs pt-nee " + classes[c]);
  }
  // Importance sampling is what makes the sun cheap: its error is well below uniform sampling's.
  EXPECT_LT(importance.report.classes[1].estimate.std_error, 0.5 * uniform.report.classes[1].estimate.std_error);
}

// One bright texel near +X (latitude-longitude, u ∈ [1/4, 5/16), the equator's row): a spot meter
// looking at the sphere's +X side sees it lit, one looking at its −X side sees nothing.
TEST(ImageInfiniteLight, ABrightTexelLightsTheSideItFaces) {
  test::write_one_texel_exr("plus_x.exr", 16, 9, 4, 4, 0.0f, 100.0f);
  const auto scene = [](const char* position) {
    return std::string(R"({"camera": {"type": "spotmeter", "position": )") + position + R"(, "look_at": [0, 0, 0]},
      "materials": {"ball": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"}],
      "lights": [{"type": "environment", "image": "plus_x.exr"}]})";
  };
  Rendered lit = render_json(scene("[3, 0, 0]"), "pt-nee", {"L.*E"}, 256);
  Rendered dark = render_json(scene("[-3, 0, 0]"), "pt-nee", {"L.*E"}, 256);
  EXPECT_GT(lit.report.classes[0].estimate.luminance, 0.1);
  EXPECT_EQ(dark.report.classes[0].estimate.luminance, 0.0);
}

}  // namespace
}  // namespace pathex
