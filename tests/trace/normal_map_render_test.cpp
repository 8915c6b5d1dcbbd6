// Bump and normal maps rendered (pbrt-v4 scene → tracer; docs/textures.md "Bump and normal maps"):
// a flat normal map and a constant bump map render as no map, a constant tilted normal map and a
// linear ramp bump map give a diffuse wall under a distant light the closed form of a Lambertian
// with the tilted shading normal (and the same as tilted per-vertex normals), by pt-nee, lt and
// bdpt (lt through the adjoint's shading-normal correction); and perturbed_normal's closed forms
// for pbrt-v4's and Mitsuba 3's bump maps. Statistical tolerances in standard errors
// (test::family_sigmas), fixed seeds.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/scene_snippets.h"
#include "support/scratch_files.h"
#include "support/stat_seed.h"
#include "support/test_images.h"
#include "support/test_render.h"
#include "trace/render.h"
#include "trace/texture_eval.h"

namespace pathex {
namespace {

using glm::vec2;
using glm::vec3;
using test::write;

Estimate render_total(const std::string& path, const std::string& renderer, std::uint64_t spp) {
  return test::render_total(path, renderer, spp, test::stat_seed(3535));
}

// A camera at z = −3 looking at the origin (fov 30: it sees [−0.80, 0.80]² of the plane z = 0,
// u and v within [0.3, 0.7] on the wall below).
// The square [−2, 2]² of z = 0, uv 0 to 1 across it: dp/du = (4, 0, 0), dp/dv = (0, 4, 0), normal +z.
using test::kWall;
const std::string& kHead = test::kRenderHead;
// A distant light of irradiance π from the unit direction (x, 0, −√3/2) on the camera's side: a
// diffuse wall of albedo ½ with shading normal n shows ½ |n · l| (pbrt-v4's L is the irradiance).
std::string distant(float x) {
  return "LightSource \"distant\" \"point3 from\" [" + std::to_string(x) + " 0 -0.8660254] \"point3 to\" [0 0 0] \"rgb L\" [3.14159265 3.14159265 3.14159265]\n";
}
const std::string kMaterial = "Material \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]";

TEST(NormalMapRender, AFlatNormalMapAndAConstantBumpRenderAsNoMap) {
  test::write_image<float>("flat.exr", 1, 1, 3, {0.5f, 0.5f, 1.0f});
  const std::string scene = kHead + "LightSource \"point\" \"point3 from\" [1 2 -2] \"rgb I\" [5 5 5]\n";
  // The wall: ns = (0, 0, 1) exactly, which both maps give back exactly: the same numbers.
  const std::string plain = write("plain.pbrt", scene + kMaterial + "\n" + kWall + "\n");
  const std::string flat = write("flat.pbrt", scene + kMaterial + " \"string normalmap\" \"flat.exr\"\n" + kWall + "\n");
  const std::string bump = write("bump.pbrt", scene + kMaterial + " \"float displacement\" 0.3\n" + kWall + "\n");
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    const Estimate a = render_total(plain, renderer, 16);
    EXPECT_GT(a.luminance, 0.0);
    for (const std::string& path : {flat, bump}) {
      const Estimate b = render_total(path, renderer, 16);
      EXPECT_EQ(a.luminance, b.luminance) << renderer << " " << path;
      EXPECT_EQ(a.std_error, b.std_error) << renderer << " " << path;
    }
  }
  // A sphere: the flat map's normal is ns up to its last bits (the frame's rounding), so the
  // renders agree within 3σ (they are nearly the same samples).
  const std::string sphere_plain = write("sphere-plain.pbrt", scene + kMaterial + "\nShape \"sphere\" \"float radius\" 0.5\n");
  const std::string sphere_flat =
      write("sphere-flat.pbrt", scene + kMaterial + " \"string normalmap\" \"flat.exr\"\nShape \"sphere\" \"float radius\" 0.5\n");
  for (const char* renderer : {"pt-nee", "bdpt"}) {
    const Estimate a = render_total(sphere_plain, renderer, 64), b = render_total(sphere_flat, renderer, 64);
    EXPECT_GT(a.luminance, 0.0);
    EXPECT_LE(std::fabs(a.luminance - b.luminance), 3.0 * a.std_error) << renderer;
  }
}

TEST(NormalMapRender, TiltedNormalsGiveTheClosedFormOfALambertian) {
  // Normal map: the texel (sin 30°, 0, cos 30°) in (dp/du, n × dp/du, n): n' = (½, 0, √3/2); light
  // from (½, 0, −√3/2): |n' · l| = ½, pixel ¼ (untilted: √3/4 = 0.433). Tilted per-vertex normals
  // n' give the same. Bump: displacement k (2u − ½) (a 2 x 1 ramp 0, 1 clamped, scale k) tilts n
  // towards −x by atan(2k / 4) = 30° for k = 2 tan 30°: n' = (−½, 0, √3/2); light from (−½, 0,
  // −√3/2): ¼ again.
  test::write_image<float>("tilt.exr", 1, 1, 3, {0.75f, 0.5f, 0.9330127f});
  test::write_image<float>("ramp.exr", 2, 1, 1, {0.0f, 1.0f});
  const std::string normal_map = write("tilt.pbrt", kHead + distant(0.5f) + kMaterial + " \"string normalmap\" \"tilt.exr\"\n" + kWall + "\n");
  const std::string vertex = write("vertex.pbrt", kHead + distant(0.5f) + kMaterial + "\n" + kWall +
                                                      " \"normal N\" [0.5 0 0.8660254  0.5 0 0.8660254  0.5 0 0.8660254  0.5 0 0.8660254]\n");
  const std::string bump = write("ramp.pbrt", kHead + distant(-0.5f) +
                                                  "Texture \"ramp\" \"float\" \"imagemap\" \"string filename\" \"ramp.exr\" \"string wrap\" \"clamp\" "
                                                  "\"float scale\" 1.1547005\n" +
                                                  kMaterial + " \"texture displacement\" \"ramp\"\n" + kWall + "\n");
  const std::string untilted = write("untilted.pbrt", kHead + distant(0.5f) + kMaterial + "\n" + kWall + "\n");
  // A distant light's direction is a Dirac (its letters L D S): pt-nee cannot join it; lt and bdpt
  // reach the wall by light paths joined to the camera, through the adjoint's correction.
  const double z = test::family_sigmas(8);
  for (const char* renderer : {"lt", "bdpt"}) {
    for (const auto& [path, expected] : std::vector<std::pair<std::string, double>>{
             {normal_map, 0.25}, {vertex, 0.25}, {bump, 0.25}, {untilted, std::sqrt(3.0) / 4.0}}) {
      const Estimate e = render_total(path, renderer, 256);
      test::stat_log(std::string("tilt ") + renderer, std::fabs(e.luminance - expected) / std::max(e.std_error, 1e-12), z);
      EXPECT_LE(std::fabs(e.luminance - expected), z * e.std_error + 2e-4) << path << " " << renderer << ": " << e.luminance << " ± " << e.std_error;
    }
  }
}

TEST(NormalMapRender, MitsubaNormalmapAndBumpmapGiveTheClosedForm) {
  // The same wall as a Mitsuba rectangle (scaled by 2: dp/du = (4, 0, 0), Mitsuba's uv) under a
  // directional emitter of irradiance π: a normalmap tilted towards +x by 30° lit from (½, 0, −√3/2),
  // and a bumpmap of the ramp with scale 2 tan 30° (Mitsuba: dp/du's normal part = scale ∂d/∂u,
  // ∂d/∂u = 2) tilted towards −x lit from (−½, 0, −√3/2): ¼ each, by lt and bdpt.
  test::write_image<float>("tilt.exr", 1, 1, 3, {0.75f, 0.5f, 0.9330127f});
  test::write_image<float>("ramp.exr", 2, 1, 1, {0.0f, 1.0f});
  const auto scene = [](const std::string& light_x, const std::string& bsdf) {
    return "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/><transform name=\"to_world\">"
           "<lookat origin=\"0, 0, -3\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform><film type=\"hdrfilm\"><integer name=\"width\" "
           "value=\"8\"/><integer name=\"height\" value=\"8\"/></film></sensor>\n<emitter type=\"directional\"><vector name=\"direction\" "
           "x=\"" + light_x + "\" y=\"0\" z=\"0.8660254\"/><rgb name=\"irradiance\" value=\"3.14159265\"/></emitter>\n"
           "<shape type=\"rectangle\"><transform name=\"to_world\"><scale value=\"2\"/></transform>" + bsdf + "</shape>\n</scene>\n";
  };
  const std::string diffuse = "<bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"0.5\"/></bsdf>";
  const std::string normal_map = write("tilt.xml", scene("-0.5", "<bsdf type=\"normalmap\"><texture type=\"bitmap\" name=\"normalmap\">"
                                                                 "<string name=\"filename\" value=\"tilt.exr\"/></texture>" + diffuse + "</bsdf>"));
  const std::string bump = write("ramp.xml", scene("0.5", "<bsdf type=\"bumpmap\"><float name=\"scale\" value=\"1.1547005\"/><texture "
                                                           "type=\"bitmap\"><string name=\"filename\" value=\"ramp.exr\"/><string name=\"wrap_mode\" "
                                                           "value=\"clamp\"/></texture>" + diffuse + "</bsdf>"));
  const double z = test::family_sigmas(4);
  for (const char* renderer : {"lt", "bdpt"}) {
    for (const std::string& path : {normal_map, bump}) {
      const Estimate e = render_total(path, renderer, 256);
      test::stat_log(std::string("mitsuba tilt ") + renderer, std::fabs(e.luminance - 0.25) / std::max(e.std_error, 1e-12), z);
      EXPECT_LE(std::fabs(e.luminance - 0.25), z * e.std_error + 2e-4) << path << " " << renderer << ": " << e.luminance << " ± " << e.std_error;
    }
  }
}

TEST(NormalMapRender, ATiltedNormalMapEqualsTiltedVertexNormals) {
  // The same tilt by a normal map and by per-vertex normals, under a point light: every estimator
  // (pt-nee included) renders the two within 3σ (nearly the same samples: the normals differ in
  // their last bits at most).
  test::write_image<float>("tilt.exr", 1, 1, 3, {0.75f, 0.5f, 0.9330127f});
  const std::string light = "LightSource \"point\" \"point3 from\" [1 1 -2] \"rgb I\" [5 5 5]\n";
  const std::string normal_map = write("tilt-point.pbrt", kHead + light + kMaterial + " \"string normalmap\" \"tilt.exr\"\n" + kWall + "\n");
  const std::string vertex = write("vertex-point.pbrt", kHead + light + kMaterial + "\n" + kWall +
                                                            " \"normal N\" [0.5 0 0.8660254  0.5 0 0.8660254  0.5 0 0.8660254  0.5 0 0.8660254]\n");
  const std::string untilted = write("untilted-point.pbrt", kHead + light + kMaterial + "\n" + kWall + "\n");
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    const Estimate a = render_total(normal_map, renderer, 256), b = render_total(vertex, renderer, 256), c = render_total(untilted, renderer, 256);
    EXPECT_GT(a.luminance, 0.0);
    EXPECT_LE(std::fabs(a.luminance - b.luminance), 3.0 * a.std_error) << renderer << ": " << a.luminance << " vs " << b.luminance;
    EXPECT_GT(std::fabs(a.luminance - c.luminance), 5.0 * std::hypot(a.std_error, c.std_error))
        << renderer << ": the tilt shows, " << a.luminance << " vs " << c.luminance;
  }
}

TEST(NormalMapRender, EstimatorsAgreeOnANormalMappedSphere) {
  // A sphere with a varying normal map over a floor, lit by a point light: pt-nee, lt and bdpt
  // reach it through different densities and lt through the adjoint's correction.
  test::write_image<unsigned char>("nm.png", 2, 2, 3, {255, 128, 200, 0, 128, 255, 128, 255, 200, 128, 0, 255});
  const std::string path = write("sphere-nm.pbrt", kHead + "LightSource \"point\" \"point3 from\" [1 2 -2] \"rgb I\" [5 5 5]\n" + kMaterial +
                                                       " \"string normalmap\" \"nm.png\"\nShape \"sphere\" \"float radius\" 0.5\n"
                                                       "Material \"diffuse\"\nTranslate 0 0 1\n" + kWall + "\n");
  const Estimate ref = render_total(path, "pt-nee", 1024);
  const double z = test::family_sigmas(2);
  for (const char* renderer : {"lt", "bdpt"}) {
    const Estimate e = render_total(path, renderer, 1024);
    const double sigma = std::sqrt(ref.std_error * ref.std_error + e.std_error * e.std_error);
    test::stat_log(std::string("nm sphere ") + renderer, std::fabs(e.luminance - ref.luminance) / sigma, z);
    EXPECT_LE(std::fabs(e.luminance - ref.luminance), z * sigma) << renderer << ": " << e.luminance << " vs " << ref.luminance;
  }
}

// perturbed_normal's closed forms, on a scene holding a 2 x 1 linear ramp (0, 1) clamped: with
// dp/du = (4, 0, 0), dp/dv = (0, 4, 0) and n = +z, a bump of gradient g per unit u gives
// n' ∝ (−g / 4, 0, 1) (pbrt-v4, and Mitsuba 3 with its scale s: g × s).
TEST(PerturbedNormal, BumpAndNormalMapClosedForms) {
  Scene scene;
  scene.images.push_back(LinearImage{2, 1, {0, 0, 0, 1, 1, 1}, {}});
  Texture ramp;
  ramp.kind = TextureKind::kImage;
  ramp.image = 0;
  ramp.wrap = TextureWrap::kClamp;
  scene.textures.push_back(ramp);                                 // 0: u ↦ 2u − ½ within [¼, ¾]
  scene.textures.push_back(constant(vec3(0.5f, 0.5f, 1.0f)));     // 1: the flat normal map
  scene.textures.push_back(constant(vec3(1.0f, 0.5f, 0.5f)));     // 2: the normal along +s
  const vec3 n(0.0f, 0.0f, 1.0f), dpdu(4.0f, 0.0f, 0.0f), dpdv(0.0f, 4.0f, 0.0f);
  MaterialTextures m;
  m.perturb = NormalPerturbation::kBumpPbrt;
  m.perturb_texture = 0;
  const auto near = [](vec3 a, vec3 b) { return glm::length(a - b) < 1e-3f; };
  const vec3 pbrt = perturbed_normal(scene, m, vec2(0.5f, 0.5f), n, n, dpdu, dpdv);
  EXPECT_TRUE(near(pbrt, glm::normalize(vec3(-0.5f, 0.0f, 1.0f)))) << pbrt.x << " " << pbrt.y << " " << pbrt.z;
  m.perturb = NormalPerturbation::kBumpMitsuba;
  m.bump_scale = 3.0f;
  const vec3 mitsuba = perturbed_normal(scene, m, vec2(0.5f, 0.5f), n, n, dpdu, dpdv);
  EXPECT_TRUE(near(mitsuba, glm::normalize(vec3(-1.5f, 0.0f, 1.0f)))) << mitsuba.x << " " << mitsuba.y << " " << mitsuba.z;
  // Degenerate uv (dp/du = dp/dv = 0): an arbitrary frame; a constant bump still gives n.
  m.perturb_texture = 1;
  EXPECT_EQ(perturbed_normal(scene, m, vec2(0.5f), n, n, vec3(0.0f), vec3(0.0f)), n);
  m.perturb = NormalPerturbation::kNormalMap;
  EXPECT_EQ(perturbed_normal(scene, m, vec2(0.5f), n, n, dpdu, dpdv), n);
  m.perturb_texture = 2;
  EXPECT_EQ(perturbed_normal(scene, m, vec2(0.5f), n, n, dpdu, dpdv), vec3(1.0f, 0.0f, 0.0f));  // along dp/du's direction
  EXPECT_EQ(perturbed_normal(scene, m, vec2(0.5f), n, n, dpdv, dpdu), vec3(0.0f, 1.0f, 0.0f));
  // None: n itself.
  m.perturb = NormalPerturbation::kNone;
  EXPECT_EQ(perturbed_normal(scene, m, vec2(0.5f), n, n, dpdu, dpdv), n);
}

}  // namespace
}  // namespace pathex
