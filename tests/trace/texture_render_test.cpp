// Textures and alpha cut-outs rendered (pbrt-v4 scene → tracer): a constant image texture renders
// the same numbers as the plain colour at the same seed, a checkerboard-textured diffuse wall in a
// white furnace averages its two albedos, a fully cut-out quad is invisible (the same numbers as
// the scene without it), and a checkerboard cut-out and a constant alpha ½ let through the
// closed-form fraction of the sky — each by pt-nee, lt and bdpt (statistical tolerances in
// standard errors, test::family_sigmas, fixed seeds).
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/scratch_files.h"
#include "support/stat_seed.h"
#include "support/test_images.h"
#include "trace/render.h"

namespace pathex {
namespace {

using test::write;

Estimate render_total(const std::string& path, const std::string& renderer, std::uint64_t spp) {
  Result<Scene> scene = load_scene_file(path);
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().render());
  if (!scene.ok()) return {};
  Result<Profile> profile = resolve_profile(renderer, Limits{});
  EXPECT_TRUE(profile.ok());
  RenderOptions o;
  o.spp = spp;
  o.seed = test::stat_seed(35);
  o.max_bounces = 8;
  Result<RenderOutput> out = render(*scene, *profile, nullptr, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  RunInfo info;
  info.spp = spp;
  const HistogramReport r = make_report(out->histogram, info, nullptr, {}).expect("a test input");
  EXPECT_EQ(r.nonfinite_samples, 0u);
  return r.total;
}

// A camera at z = −3 looking at the origin (fov 30: it sees [−0.80, 0.80]² of the plane z = 0).
const std::string kHead =
    "LookAt 0 0 -3  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\nFilm \"rgb\" \"integer xresolution\" 8 \"integer yresolution\" 8\n"
    "WorldBegin\n";
// The square [−2, 2]² of the plane z = 0 with uv from 0 to 1 across it: with uscale = vscale = 8
// its cells are 0.5 wide and a cell corner is at the origin, so the square the camera sees is
// exactly half even cells and half odd ones (a mirror in x swaps the parity).
const std::string kWall =
    "Shape \"trianglemesh\" \"point3 P\" [-2 -2 0  2 -2 0  2 2 0  -2 2 0] \"integer indices\" [0 1 2  0 2 3] "
    "\"point2 uv\" [0 0  1 0  1 1  0 1]";

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
