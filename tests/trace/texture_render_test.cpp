// Textures and alpha cut-outs rendered (pbrt-v4 scene → tracer): a constant image texture renders
// the same numbers as the plain colour at the same seed, a checkerboard-textured diffuse wall in a
// white furnace averages its two albedos, a fully cut-out quad is invisible (the same numbers as
// the scene without it), and a checkerboard cut-out and a constant alpha ½ let through the
// closed-form fraction of the sky — each by pt-nee, lt and bdpt (statistical tolerances in
// standard errors, test::family_sigmas, fixed seeds).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/scene_snippets.h"
#include "support/scratch_files.h"
#include "support/stat_seed.h"
#include "support/test_images.h"
#include "support/test_render.h"
#include "trace/render.h"

namespace pathex {
namespace {

using test::write;

Estimate render_total(const std::string& path, const std::string& renderer, std::uint64_t spp) {
  return test::render_total(path, renderer, spp, test::stat_seed(35));
}

// A camera at z = −3 looking at the origin (fov 30: it sees [−0.80, 0.80]² of the plane z = 0).
// The square [−2, 2]² of the plane z = 0 with uv from 0 to 1 across it: with uscale = vscale = 8
// its cells are 0.5 wide and a cell corner is at the origin, so the square the camera sees is
// exactly half even cells and half odd ones (a mirror in x swaps the parity).
using test::kWall;
const std::string& kHead = test::kRenderHead;

TEST(TextureRender, AConstantImageRendersAsItsColour) {
  test::write_image<float>("grey.exr", 1, 1, 3, {0.25f, 0.5f, 0.75f});
  const std::string scene = kHead + "LightSource \"point\" \"point3 from\" [0 2 -2] \"rgb I\" [5 5 5]\n";
  const std::string plain = write("plain.pbrt", scene + "Material \"diffuse\" \"rgb reflectance\" [0.25 0.5 0.75]\nShape \"sphere\"\n");
  const std::string image = write("image.pbrt", scene + "Texture \"g\" \"spectrum\" \"imagemap\" \"string filename\" \"grey.exr\"\n"
                                                          "Material \"diffuse\" \"texture reflectance\" \"g\"\nShape \"sphere\"\n");
  for (const char* renderer : {"pt-nee", "bdpt"}) {
    const Estimate a = render_total(plain, renderer, 16), b = render_total(image, renderer, 16);
    EXPECT_GT(a.luminance, 0.0);
    EXPECT_EQ(a.luminance, b.luminance) << renderer;
    EXPECT_EQ(a.std_error, b.std_error) << renderer;
  }
}

TEST(TextureRender, ACheckerboardWallInAFurnaceAveragesItsAlbedos) {
  // Every pixel sees the wall, which sees only the sky (radiance 1): a pixel is its albedo, and
  // the image mean is (0.9 + 0.5) / 2 = 0.7 (the untextured default would give 0.5).
  const std::string path = write("checks.pbrt", kHead + "LightSource \"infinite\" \"rgb L\" [1 1 1]\n"
                                                        "Texture \"c\" \"spectrum\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 8 "
                                                        "\"rgb tex1\" [0.9 0.9 0.9] \"rgb tex2\" [0.5 0.5 0.5]\n"
                                                        "Material \"diffuse\" \"texture reflectance\" \"c\"\n" +
                                                        kWall + "\n");
  const double z = test::family_sigmas(3);
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    const Estimate e = render_total(path, renderer, 1024);
    test::stat_log(std::string("checker wall ") + renderer, std::fabs(e.luminance - 0.7) / e.std_error, z);
    EXPECT_LE(std::fabs(e.luminance - 0.7), z * e.std_error + 1e-4) << renderer << ": " << e.luminance << " ± " << e.std_error;
  }
}

// Issue 35: textured roughness, conductor reflectance and plastic reflectance go through the one
// texture evaluation (material_at) as the colours do: constant 1 x 1 images render the same
// numbers as the plain values at the same seed (the per-hit maps, √ of pbrt's roughness, pbrt's
// k from a reflectance and Mitsuba plastic's base, are the importers' own arithmetic).
TEST(TextureRender, ConstantRoughnessReflectanceAndPlasticTexturesRenderAsTheirValues) {
  test::write_image<float>("metal.exr", 1, 1, 3, {0.64f, 0.5f, 0.25f});
  test::write_image<float>("quarter.exr", 1, 1, 3, {0.25f, 0.25f, 0.25f});  // as a pbrt float: the mean, 0.25
  const std::string scene = kHead + "LightSource \"point\" \"point3 from\" [0 2 -2] \"rgb I\" [5 5 5]\n";
  const std::string plain = write("metal-plain.pbrt", scene + "Material \"conductor\" \"rgb reflectance\" [0.64 0.5 0.25] \"float roughness\" 0.25\n"
                                                              "Shape \"sphere\"\n");
  const std::string image = write("metal-image.pbrt", scene + "Texture \"r\" \"spectrum\" \"imagemap\" \"string filename\" \"metal.exr\"\n"
                                                              "Texture \"q\" \"float\" \"imagemap\" \"string filename\" \"quarter.exr\"\n"
                                                              "Material \"conductor\" \"texture reflectance\" \"r\" \"texture roughness\" \"q\"\n"
                                                              "Shape \"sphere\"\n");
  const std::string xml = "<scene version=\"3.0.0\">\n<sensor type=\"perspective\"><float name=\"fov\" value=\"30\"/><transform name=\"to_world\">"
                          "<lookat origin=\"0, 0, -3\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform><film type=\"hdrfilm\">"
                          "<integer name=\"width\" value=\"8\"/><integer name=\"height\" value=\"8\"/></film></sensor>\n"
                          "<emitter type=\"point\"><point name=\"position\" value=\"0, 2, -2\"/><rgb name=\"intensity\" value=\"5, 5, 5\"/></emitter>\n";
  const std::string plastic_plain = write("plastic-plain.xml", xml + "<shape type=\"sphere\"><bsdf type=\"plastic\"><rgb name=\"diffuse_reflectance\" "
                                                                     "value=\"0.64, 0.5, 0.25\"/></bsdf></shape>\n</scene>\n");
  const std::string plastic_image = write("plastic-image.xml", xml + "<shape type=\"sphere\"><bsdf type=\"plastic\"><texture type=\"bitmap\" "
                                                                     "name=\"diffuse_reflectance\"><string name=\"filename\" value=\"metal.exr\"/>"
                                                                     "</texture></bsdf></shape>\n</scene>\n");
  for (const auto& [a_path, b_path] : {std::pair{plain, image}, std::pair{plastic_plain, plastic_image}})
    for (const char* renderer : {"pt-nee", "bdpt"}) {
      const Estimate a = render_total(a_path, renderer, 16), b = render_total(b_path, renderer, 16);
      EXPECT_GT(a.luminance, 0.0);
      EXPECT_EQ(a.luminance, b.luminance) << a_path << " " << renderer;
      EXPECT_EQ(a.std_error, b.std_error) << a_path << " " << renderer;
    }
}

// The manifold connector evaluates a textured smooth conductor at its solved points (their uv
// from EmbreeScene::uv_at, tested in embree_test): a 1 x 1 reflectance image renders the plain
// value's numbers with pt-nee+manifold.
TEST(TextureRender, TheManifoldConnectorSeesATexturedSmoothConductor) {
  test::write_image<float>("metal.exr", 1, 1, 3, {0.64f, 0.5f, 0.25f});
  const std::string scene = kHead + "LightSource \"point\" \"point3 from\" [0 0.5 -0.9] \"rgb I\" [5 5 5]\n"
                                    "Material \"diffuse\"\nShape \"trianglemesh\" \"point3 P\" [-4 -0.5 -4  4 -0.5 -4  4 -0.5 4  -4 -0.5 4] "
                                    "\"integer indices\" [0 1 2  0 2 3]\n"
                                    "Texture \"r\" \"spectrum\" \"imagemap\" \"string filename\" \"metal.exr\"\n";
  const std::string plain = write("caustic-plain.pbrt", scene + "Material \"conductor\" \"rgb reflectance\" [0.64 0.5 0.25]\n"
                                                                "Shape \"sphere\" \"float radius\" 0.4\n");
  const std::string image = write("caustic-image.pbrt", scene + "Material \"conductor\" \"texture reflectance\" \"r\"\n"
                                                                "Shape \"sphere\" \"float radius\" 0.4\n");
  const Estimate a = render_total(plain, "pt-nee+manifold", 16), b = render_total(image, "pt-nee+manifold", 16);
  EXPECT_EQ(a.luminance, b.luminance);
  EXPECT_EQ(a.std_error, b.std_error);
}

TEST(TextureRender, ACheckerboardRoughnessRendersTheMeanOfItsTwoRoughnesses) {
  // A conductor wall lit by a small area light whose reflection the camera sees. The scene is
  // symmetric in x and x -> −x swaps the cells' parity, so the image mean of a checkerboard of
  // roughness 0.01 and 0.3 is the mean of the two plain walls' image means: each estimator
  // (pt-nee, lt, bdpt: their densities differ, so a pdf that saw another roughness than the
  // sampler would show here) within test::family_sigmas(3) combined standard errors.
  const std::string head = kHead + "AttributeBegin\nAreaLightSource \"diffuse\" \"rgb L\" [20 20 20] \"bool twosided\" true\n"
                                   "Shape \"trianglemesh\" \"point3 P\" [-0.2 0.9 -1.5  0.2 0.9 -1.5  0.2 1.1 -1.5  -0.2 1.1 -1.5] "
                                   "\"integer indices\" [0 1 2  0 2 3]\nAttributeEnd\n";
  const std::string checks = write("rough-checks.pbrt", head + "Texture \"r\" \"float\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 8 "
                                                               "\"float tex1\" 0.01 \"float tex2\" 0.3\n"
                                                               "Material \"conductor\" \"texture roughness\" \"r\"\n" + kWall + "\n");
  const std::string smooth = write("rough-a.pbrt", head + "Material \"conductor\" \"float roughness\" 0.01\n" + kWall + "\n");
  const std::string rough = write("rough-b.pbrt", head + "Material \"conductor\" \"float roughness\" 0.3\n" + kWall + "\n");
  const double z = test::family_sigmas(3);
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    const Estimate t = render_total(checks, renderer, 1024), a = render_total(smooth, renderer, 1024), b = render_total(rough, renderer, 1024);
    const double mean = 0.5 * (a.luminance + b.luminance);
    const double se = std::sqrt(t.std_error * t.std_error + 0.25 * (a.std_error * a.std_error + b.std_error * b.std_error));
    EXPECT_GT(std::fabs(a.luminance - b.luminance), 6.0 * se) << renderer << ": the two roughnesses must differ visibly";
    test::stat_log(std::string("roughness checks ") + renderer, std::fabs(t.luminance - mean) / se, z);
    EXPECT_LE(std::fabs(t.luminance - mean), z * se) << renderer << ": " << t.luminance << " ± " << t.std_error << " vs " << mean;
  }
}

TEST(AlphaRender, AFullyCutOutQuadIsInvisible) {
  const std::string scene = kHead + "LightSource \"point\" \"point3 from\" [0 2 -2] \"rgb I\" [5 5 5]\nShape \"sphere\" \"float radius\" 0.5\n";
  const std::string without = write("no-quad.pbrt", scene);
  const std::string with = write("cut-quad.pbrt", scene + "Translate 0 0 -1\n" + kWall + " \"float alpha\" 0\n");
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    const Estimate a = render_total(without, renderer, 16), b = render_total(with, renderer, 16);
    EXPECT_GT(a.luminance, 0.0);
    EXPECT_EQ(a.luminance, b.luminance) << renderer;
    EXPECT_EQ(a.std_error, b.std_error) << renderer;
  }
}

TEST(AlphaRender, CutOutsLetTheClosedFormFractionThrough) {
  // The wall (albedo ½) in the furnace: where it is opaque a pixel is ½, where it is cut out the
  // sky, 1. A checkerboard alpha (half the seen square cut out) and a constant alpha ½ (half the
  // rays pass) both give an image mean of 0.75.
  const std::string head = kHead + "LightSource \"infinite\" \"rgb L\" [1 1 1]\nMaterial \"diffuse\" \"rgb reflectance\" [0.5 0.5 0.5]\n";
  const std::string checker = write("alpha-checks.pbrt", head +
                                                             "Texture \"a\" \"float\" \"checkerboard\" \"float uscale\" 8 \"float vscale\" 8\n" +
                                                             kWall + " \"texture alpha\" \"a\"\n");
  const std::string half = write("alpha-half.pbrt", head + kWall + " \"float alpha\" 0.5\n");
  const double z = test::family_sigmas(6);
  for (const std::string& path : {checker, half}) {
    for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
      const Estimate e = render_total(path, renderer, 1024);
      test::stat_log(std::string("alpha ") + renderer, std::fabs(e.luminance - 0.75) / e.std_error, z);
      EXPECT_LE(std::fabs(e.luminance - 0.75), z * e.std_error + 1e-4) << path << " " << renderer << ": " << e.luminance << " ± " << e.std_error;
    }
  }
}

}  // namespace
}  // namespace pathex
