// Image infinite lights in every format (docs/lights.md): pbrt-v4's `infinite` with a filename
// (an equal-area square; scale, illuminance, the light's transform), Mitsuba 3's `envmap`
// (latitude-longitude; scale, to_world) and the JSON environment with an image: exact values, the
// orientation (which world direction a texel lights, seen from the camera), and the refusals,
// located.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <glm/glm.hpp>

#include "scene/scene.h"
#include "support/env_images.h"
#include "support/load_scene.h"
#include "support/scratch_files.h"
#include "trace/environment.h"

namespace pathex {
namespace {

using test::relative;
using test::scratch;
using test::write;

using test::load;

// The texel of the scene's image that world direction `w` (towards the environment) reads.
glm::vec3 radiance_towards(const Scene& s, const glm::vec3& w) {
  EnvironmentMap m;
  m.equal_area = s.environment_image->equal_area;
  m.width = s.environment_image->width;
  m.height = s.environment_image->height;
  m.texels = s.environment_image->texels;
  m.to_world = s.environment_image->to_world;
  return environment_radiance(m, glm::normalize(w));
}

// The camera's right, as the image shows it (trace/render_scene.cpp's frame).
glm::vec3 camera_right(const Scene& s) {
  return glm::normalize(glm::cross(glm::normalize(s.camera.look_at - s.camera.position), s.camera.up));
}

const std::string kPbrtHead = "LookAt 0 0 -5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n";

TEST(ImportPbrtImageLight, ScaleAndTheBoxAndTheSquare) {
  test::write_constant_exr("sky8.exr", 8, 8, 0.5f);
  const Scene s = load(write("image.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"sky8.exr\" \"float scale\" 3\nShape \"sphere\"\n"));
  ASSERT_TRUE(s.environment_image.has_value());
  const EnvironmentImage& e = *s.environment_image;
  EXPECT_TRUE(e.equal_area);
  EXPECT_EQ(e.width, 8);
  EXPECT_EQ(e.height, 8);
  for (const glm::vec3& t : e.texels) EXPECT_EQ(t, glm::vec3(1.5f));  // 0.5 × scale 3, exactly
  ASSERT_GE(e.shape, 0);
  EXPECT_TRUE(s.shapes[static_cast<std::size_t>(e.shape)].emissive());  // the box: an area light, LDD
  EXPECT_EQ(describe(scene_types(s)).substr(0, 11), "lights area");
}

// pbrt-v4's illuminance: the texels scaled so that Σ over the upper hemisphere's texels of
// luminance × cos θ × 2π / N² is the value given (its normalisation; docs/lights.md). For a
// constant red image (luminance 0.2126 r) the sum is 0.2126 r Σ cos θ 2π / N², which tends to
// 0.2126 r π / 2 (the mean of cos θ over the hemisphere is 1/2, half the texels are in it).
TEST(ImportPbrtImageLight, IlluminanceIsPbrtsNormalisation) {
  test::write_rgb_exr("red.exr", 64, 64, [] {
    std::vector<float> v(64 * 64 * 3, 0.0f);
    for (std::size_t i = 0; i < v.size(); i += 3) v[i] = 2.0f;
    return v;
  }());
  const Scene s = load(write("lux.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"red.exr\" \"float illuminance\" 10\nShape \"sphere\"\n"));
  ASSERT_TRUE(s.environment_image.has_value());
  double cos_sum = 0.0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const glm::vec3 w = equal_area_square_to_sphere({(static_cast<float>(x) + 0.5f) / 64.0f, (static_cast<float>(y) + 0.5f) / 64.0f});
      if (w.z > 0.0f) cos_sum += w.z;
    }
  const double k = 0.2126 * 2.0 * cos_sum * 2.0 * std::numbers::pi / (64.0 * 64.0);
  EXPECT_NEAR(k, 0.2126 * 2.0 * std::numbers::pi / 2.0, 0.01);
  EXPECT_NEAR(s.environment_image->texels[0].x, 2.0 * 10.0 / k, 1e-4);
  EXPECT_EQ(s.environment_image->texels[0].y, 0.0f);
  // The uniform light's illuminance is π L (luminance): L = E / (π Y).
  const Scene u = load(write("lux-uniform.pbrt", kPbrtHead + "LightSource \"infinite\" \"rgb L\" [1 1 1] \"float illuminance\" 5\nShape \"sphere\"\n"));
  EXPECT_NEAR(u.environment->x, 5.0 / std::numbers::pi, 1e-6);
}

// The square's centre is +z in light space. pbrt-v4's camera here looks along +z with +x on the
// image's right and +y up (a left-handed world, which the importer mirrors): the texel pbrt shows
// at light direction d must be the one pathex reads at right d.x + up d.y + forward d.z, whatever
// the mirroring did; the light's transform (the CTM at LightSource) turns it.
TEST(ImportPbrtImageLight, ATexelLightsTheSideThatPbrtShows) {
  test::write_one_texel_exr("plusx.exr", 8, 8, 7, 4, 0.0f, 9.0f);  // near +x: u ∈ [7/8, 1), v ∈ [1/2, 5/8)
  const glm::vec3 d = equal_area_square_to_sphere({7.5f / 8.0f, 4.5f / 8.0f});
  ASSERT_GT(d.x, 0.9f);
  const auto seen = [](const Scene& s, const glm::vec3& pbrt_dir) {  // the world direction pbrt shows there
    const glm::vec3 forward = glm::normalize(s.camera.look_at - s.camera.position);
    return camera_right(s) * pbrt_dir.x + glm::normalize(s.camera.up) * pbrt_dir.y + forward * pbrt_dir.z;
  };
  const Scene s = load(write("plusx.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"plusx.exr\"\nShape \"sphere\"\n"));
  ASSERT_TRUE(s.environment_image.has_value());
  EXPECT_EQ(radiance_towards(s, seen(s, d)), glm::vec3(9.0f));  // on the image's right
  EXPECT_EQ(radiance_towards(s, seen(s, -d)), glm::vec3(0.0f));
  // Rotate 90 about y takes pbrt's +x to −z (towards the camera): (x, y, z) → (z, y, −x).
  const Scene r = load(write("plusx-rot.pbrt", kPbrtHead + "AttributeBegin\nRotate 90 0 1 0\nLightSource \"infinite\" \"string filename\" \"plusx.exr\"\n"
                                                           "AttributeEnd\nShape \"sphere\"\n"));
  EXPECT_EQ(radiance_towards(r, seen(r, {d.z, d.y, -d.x})), glm::vec3(9.0f));
  EXPECT_EQ(radiance_towards(r, seen(r, d)), glm::vec3(0.0f));
}

const std::string kXmlHead =
    "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>"
    "<transform name=\"to_world\"><lookat origin=\"0, 0, -5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>";

TEST(ImportMitsubaImageLight, EnvmapScaleAndYUp) {
  // 16 x 8, one texel in the top row (v < 1/8: near +Y) of value 4, the rest 1.
  test::write_one_texel_exr("top.exr", 16, 8, 3, 0, 1.0f, 4.0f);
  const Scene s = load(write("envmap.xml", kXmlHead + "<emitter type=\"envmap\"><string name=\"filename\" value=\"top.exr\"/>"
                                                      "<float name=\"scale\" value=\"0.5\"/></emitter><shape type=\"sphere\"/></scene>"));
  ASSERT_TRUE(s.environment_image.has_value());
  EXPECT_FALSE(s.environment_image->equal_area);
  EXPECT_EQ(s.environment_image->texels[3], glm::vec3(2.0f));  // 4 × 0.5
  EXPECT_EQ(s.environment_image->texels[4], glm::vec3(0.5f));
  // Straight up reads the top row; the texel at u ∈ [3/16, 4/16) is φ ≈ 78°: towards +X, above.
  const float phi = 2.0f * std::numbers::pi_v<float> * 3.5f / 16.0f, theta = std::numbers::pi_v<float> * 0.5f / 8.0f;
  EXPECT_EQ(radiance_towards(s, {std::sin(phi) * std::sin(theta), std::cos(theta), -std::cos(phi) * std::sin(theta)}), glm::vec3(2.0f));
  EXPECT_EQ(radiance_towards(s, {0.0f, -1.0f, 0.0f}), glm::vec3(0.5f));
  // to_world turns it: rotated 180° about x, the top row is down.
  const Scene r = load(write("envmap-rot.xml", kXmlHead + "<emitter type=\"envmap\"><string name=\"filename\" value=\"top.exr\"/>"
                                                          "<transform name=\"to_world\"><rotate x=\"1\" angle=\"180\"/></transform></emitter>"
                                                          "<shape type=\"sphere\"/></scene>"));
  EXPECT_EQ(radiance_towards(r, {std::sin(phi) * std::sin(theta), -std::cos(theta), std::cos(phi) * std::sin(theta)}), glm::vec3(4.0f));
}

TEST(ImportJsonImageLight, ImageRelativeToTheSceneAndAUniformLightAdded) {
  test::write_constant_exr("json-sky.exr", 4, 2, 0.25f);
  const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0]},
    "materials": {"m": {"type": "diffuse"}}, "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    "lights": [{"type": "environment", "image": "json-sky.exr", "scale": [2, 2, 2]}, {"type": "environment", "radiance": [1, 1, 1]}]})";
  const Scene s = load(write("json-sky.json", scene));
  ASSERT_TRUE(s.environment_image.has_value());
  for (const glm::vec3& t : s.environment_image->texels) EXPECT_EQ(t, glm::vec3(1.5f));  // 0.25 × 2 + 1: one box
  int boxes = 0;
  for (const Shape& shape : s.shapes) boxes += shape.emissive();
  EXPECT_EQ(boxes, 1);
}

struct Refusal {
  std::string file, text, where, message;
};

TEST(ImageLightRefusals, LocatedWithWhatWasExpected) {
  test::write_constant_exr("wide.exr", 8, 4, 1.0f);
  test::write_constant_exr("ok8.exr", 8, 8, 1.0f);
  const std::vector<Refusal> refusals = {
      {"square.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"wide.exr\"\n", "square.pbrt:4:24",
       "the image 'wide.exr': it is 8 x 4: pbrt-v4's infinite light needs a square image (its equal-area mapping)"},
      {"missing.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"nowhere.exr\"\n", "missing.pbrt:4:24",
       "the image 'nowhere.exr': cannot read the image: No such file or directory"},
      {"portal.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"ok8.exr\" \"point3 portal\" [0 0 0 1 0 0 1 1 0 0 1 0]\n",
       "portal.pbrt:4:52", "portals are not supported: render the light without its portal (pbrt-v4 uses the portal only to sample it)"},
      {"both.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"ok8.exr\" \"rgb L\" [1 1 1]\n", "both.pbrt:4:52",
       "give \"L\" or \"filename\", not both (as pbrt-v4)"},
      {"two.pbrt", kPbrtHead + "LightSource \"infinite\" \"string filename\" \"ok8.exr\"\nLightSource \"infinite\" \"string filename\" \"ok8.exr\"\n",
       "two.pbrt:5:1", "a second image infinite light is not supported: a scene has at most one"},
      {"missing.xml", kXmlHead + "\n<emitter type=\"envmap\"><string name=\"filename\" value=\"nowhere.exr\"/></emitter></scene>", "missing.xml:2:1",
       "the image 'nowhere.exr': cannot read the image: No such file or directory"},
      {"missing.json",
       R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0]}, "materials": {"m": {"type": "diffuse"}},
           "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
           "lights": [{"type": "environment", "image": "nowhere.exr"}]})",
       "missing.json:/lights/0/image", "the image 'nowhere.exr': cannot read the image: No such file or directory"},
  };
  for (const Refusal& r : refusals) {
    const Result<Scene> s = load_scene_file(write(r.file, r.text));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
}

}  // namespace
}  // namespace pathex

namespace pathex {
namespace {

// Mitsuba 3's perspective sensor without a fov: focal_length, "50mm" by default, on a 36 x 24 mm
// film, its fov along the diagonal (Mitsuba's parse_fov). On a 3:2 image that is a vertical half
// angle of atan(12 / f).
TEST(ImportMitsubaSensor, FocalLengthAndItsFiftyMillimetreDefault) {
  const auto sensor = [](const std::string& inner) {
    return "<scene version=\"3.0.0\"><sensor type=\"perspective\">" + inner +
           "<transform name=\"to_world\"><lookat origin=\"0, 0, -5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>"
           "<film type=\"hdrfilm\"><integer name=\"width\" value=\"300\"/><integer name=\"height\" value=\"200\"/></film></sensor>"
           "<emitter type=\"constant\"/><shape type=\"sphere\"/></scene>";
  };
  const Scene fifty = load(write("focal-default.xml", sensor("")));
  EXPECT_NEAR(fifty.camera.fov_degrees, glm::degrees(2.0 * std::atan(12.0 / 50.0)), 1e-4);
  const Scene wide = load(write("focal-35.xml", sensor("<string name=\"focal_length\" value=\"35mm\"/>")));
  EXPECT_NEAR(wide.camera.fov_degrees, glm::degrees(2.0 * std::atan(12.0 / 35.0)), 1e-4);
  const Result<Scene> both = load_scene_file(write("focal-both.xml", sensor("<float name=\"fov\" value=\"30\"/><string name=\"focal_length\" value=\"35mm\"/>")));
  ASSERT_FALSE(both.ok());
  EXPECT_EQ(relative(both.error().message), "give fov or focal_length, not both (as Mitsuba 3)");
  const Result<Scene> bad = load_scene_file(write("focal-bad.xml", sensor("<string name=\"focal_length\" value=\"wide\"/>")));
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(relative(bad.error().message), "focal_length \"wide\" must be of the form <x>mm with x > 0");
}

}  // namespace
}  // namespace pathex
