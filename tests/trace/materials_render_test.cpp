// The materials of issue 35 rendered (scene JSON → tracer): the white furnace for the materials
// that lose nothing (thin dielectric, diffuse transmission 0.5 + 0.5: exactly the sky's radiance),
// pbrt-v4's own furnace figures for the models that lose energy by design (a rough dielectric,
// a rough gold conductor from pbrt-v4's measured spectra), and pt-nee, lt and bdpt agreeing on a
// sphere of each new material (they reach it through different densities, so a pdf that
// disagrees with its sampler shows here).
//
// pbrt-v4's figures (issue 35: pbrt-v4 5f7a606, CPU, 1,024 spp, RGB means of the image) are of a
// unit sphere under a uniform sky of radiance 1 seen from distance 5 with a 30° field of view, so
// that the sky fills 54.5 % of the image: that framing reproduces the rough-dielectric figure to
// 0.2 % (0.8167 against 0.815) and the three gold channels with one background share; the issue
// does not state it. Tolerance: 1.5 % (pbrt-v4 renders spectrally, pathex in RGB), as the issue
// asks. Statistical tolerances are in standard errors (batch means, fixed seeds):
// test::family_sigmas over each test's comparisons, family-wise false-failure rate 0.1 %.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/stat_seed.h"
#include "trace/render.h"

namespace pathex {
namespace {

Estimate render_total(const std::string& scene_json, const std::string& renderer, std::uint64_t spp, int max_bounces,
                      std::uint64_t* nonfinite) {
  Result<Scene> scene = load_scene_json(scene_json, ".", "test");
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().render());
  Result<Profile> profile = resolve_profile(renderer, Limits{});
  EXPECT_TRUE(profile.ok());
  RenderOptions o;
  o.spp = spp;
  o.seed = test::stat_seed(11);
  o.max_bounces = max_bounces;
  Result<RenderOutput> out = render(*scene, *profile, nullptr, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  RunInfo info;
  info.spp = spp;
  const HistogramReport r = make_report(out->histogram, info, nullptr, {}).expect("a test input");
  *nonfinite = r.nonfinite_samples;
  return r.total;
}

// A unit sphere of `material` under a uniform sky of radiance 1, from distance `distance` with
// field of view `fov` (degrees).
std::string furnace(const std::string& material, double distance, double fov, int pixels) {
  const std::string d = std::to_string(distance), f = std::to_string(fov), n = std::to_string(pixels);
  return R"({"camera": {"type": "pinhole", "position": [0, 0, -)" + d + R"(], "look_at": [0, 0, 0], "up": [0, 1, 0],
              "fov": )" + f + R"(, "width": )" + n + R"(, "height": )" + n + R"(},
    "materials": {"m": )" + material + R"(},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "m"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})";
}

// Materials that neither absorb nor lose energy: the camera sees only the sphere, and every pixel
// is the sky's radiance 1. Max depth 64, as the issue's furnace. lt cannot end a path on the
// pinhole through a Dirac vertex, so the thin dielectric (S only) is rendered by pt-nee and bdpt.
TEST(MaterialsFurnace, LosslessMaterialsReturnTheSky) {
  struct Case {
    const char* material;
    std::vector<const char*> renderers;
  };
  const std::vector<Case> cases = {
      {R"({"type": "thin_dielectric", "ior": 1.5})", {"pt-nee", "bdpt"}},
      {R"({"type": "diffuse_transmission", "reflectance": [0.5, 0.5, 0.5], "transmittance": [0.5, 0.5, 0.5]})",
       {"pt-nee", "lt", "bdpt"}},
  };
  const double z = test::family_sigmas(5);
  for (const Case& c : cases) {
    for (const char* renderer : c.renderers) {
      std::uint64_t nonfinite = 0;
      const Estimate e = render_total(furnace(c.material, 3.0, 20.0, 6), renderer, 256, 64, &nonfinite);
      EXPECT_EQ(nonfinite, 0u);
      const double dev = std::fabs(e.luminance - 1.0);
      test::stat_log(std::string("furnace ") + renderer, dev / e.std_error, z);
      EXPECT_LE(dev, z * e.std_error + 1e-4) << c.material << " " << renderer << ": " << e.luminance << " ± " << e.std_error;
    }
  }
}

// pbrt-v4's figures for the models that lose energy by design (single-scattering microfacets).
// The JSON roughness is GGX alpha: pbrt's roughness r with remaproughness true is alpha = sqrt(r).
TEST(MaterialsFurnace, LossyModelsLoseWhatPbrtV4Loses) {
  struct Case {
    std::string material;
    double rgb[3];
  };
  const std::vector<Case> cases = {
      {R"({"type": "dielectric", "ior": 1.5, "roughness": 0.4472136})", {0.815, 0.815, 0.815}},  // roughness 0.2
      {R"({"type": "conductor", "metal": "Au", "roughness": 0.31622777})", {0.930, 0.843, 0.682}},  // roughness 0.1
  };
  for (const Case& c : cases) {
    std::uint64_t nonfinite = 0;
    const Estimate e = render_total(furnace(c.material, 5.0, 30.0, 24), "pt", 64, 64, &nonfinite);
    EXPECT_EQ(nonfinite, 0u);
    EXPECT_LT(e.std_error, 0.002);  // well inside the 1.5 %
    for (int ch = 0; ch < 3; ++ch)
      EXPECT_NEAR(e.rgb[ch], c.rgb[ch], 0.015 * c.rgb[ch]) << c.material << " channel " << ch;
  }
}

// pt-nee, lt and bdpt agree on a sphere of each new finite material over a diffuse floor, lit by
// a small spherical lamp (so that next-event estimation, light tracing and every BDPT join run
// through the material's eval() and pdf()). The smooth kinds (S only) cannot be joined at, and lt
// cannot see them through a pinhole: pt-nee and bdpt are compared there, and for a smooth coat
// (its S reflection is seen through the pinhole; pbrt-v4's coatedconductor as JSON's coateddiffuse
// with a conductor "base").
TEST(MaterialsAgreement, EstimatorsAgreeOnASphereOfEachMaterial) {
  struct Case {
    const char* name;
    const char* material;
    bool finite;
  };
  const std::vector<Case> cases = {
      {"rough gold", R"({"type": "conductor", "metal": "Au", "roughness": 0.3})", true},
      {"anisotropic copper", R"({"type": "conductor", "roughness_u": 0.1, "roughness_v": 0.5})", true},
      {"rough glass", R"({"type": "dielectric", "ior": 1.5, "roughness": 0.3})", true},
      {"rough bubble", R"({"type": "dielectric", "ior": 0.6666667, "roughness": 0.4})", true},
      {"diffuse transmission", R"({"type": "diffuse_transmission", "reflectance": [0.3, 0.4, 0.5], "transmittance": [0.5, 0.4, 0.3]})", true},
      {"mixture", R"({"type": "mixture", "components": [
          {"weight": 0.5, "material": {"type": "dielectric", "ior": 1.5, "roughness": 0.3}},
          {"weight": 0.5, "material": {"type": "diffuse_transmission", "reflectance": [0.4, 0.4, 0.4], "transmittance": [0.4, 0.4, 0.4]}}]})", true},
      {"beckmann gold", R"({"type": "conductor", "metal": "Au", "roughness": 0.3, "distribution": "beckmann"})", true},
      {"beckmann glass", R"({"type": "dielectric", "ior": 1.5, "roughness": 0.3, "distribution": "beckmann"})", true},
      {"beckmann coat", R"({"type": "coateddiffuse", "reflectance": [0.6, 0.5, 0.4], "roughness": 0.3, "distribution": "beckmann"})", true},
      {"rough gold under a rough coat", R"({"type": "coateddiffuse", "roughness": 0.3, "base": {"type": "conductor", "metal": "Au", "roughness": 0.2}})", true},
      {"smooth copper under a rough coat", R"({"type": "coateddiffuse", "roughness": 0.3, "base": {"type": "conductor"}})", true},
      {"rough gold under a smooth coat", R"({"type": "coateddiffuse", "base": {"type": "conductor", "metal": "Au", "roughness": 0.3}})", false},
      {"smooth gold under a smooth coat", R"({"type": "coateddiffuse", "base": {"type": "conductor", "metal": "Au"}})", false},
      {"smooth silver", R"({"type": "conductor", "metal": "Ag"})", false},
      {"thin glass", R"({"type": "thin_dielectric", "ior": 1.5})", false},
  };
  int comparisons = 0;
  for (const Case& c : cases) comparisons += c.finite ? 3 : 1;
  const double z = test::family_sigmas(comparisons);
  for (const Case& c : cases) {
    const std::string scene = std::string(R"({"camera": {"type": "pinhole", "position": [0, 1.2, -3.5], "look_at": [0, 0.5, 0],
                                  "up": [0, 1, 0], "fov": 40, "width": 12, "height": 12},
      "materials": {"m": )") + c.material + R"(, "floor": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
      "shapes": [{"type": "sphere", "center": [0, 0.6, 0], "radius": 0.6, "material": "m"},
                 {"type": "quad", "corner": [-3, 0, 3], "edge1": [6, 0, 0], "edge2": [0, 0, -6], "material": "floor"},
                 {"type": "sphere", "center": [1.2, 2.5, -0.8], "radius": 0.25, "material": "floor", "emission": [20, 20, 20]}]})";
    std::vector<std::pair<std::string, Estimate>> results;
    for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
      if (!c.finite && std::string(renderer) == "lt") continue;
      std::uint64_t nonfinite = 0;
      results.emplace_back(renderer, render_total(scene, renderer, 1024, 8, &nonfinite));
      EXPECT_EQ(nonfinite, 0u) << c.name << " " << renderer;
    }
    for (std::size_t i = 0; i < results.size(); ++i) {
      for (std::size_t j = i + 1; j < results.size(); ++j) {
        if (!c.finite && j != i + 1) continue;
        const Estimate& a = results[i].second;
        const Estimate& b = results[j].second;
        const double sigma = std::sqrt(a.std_error * a.std_error + b.std_error * b.std_error);
        const double dev = std::fabs(a.luminance - b.luminance);
        test::stat_log(std::string("agreement ") + c.name + " " + results[i].first + " " + results[j].first, dev / sigma, z);
        EXPECT_LE(dev, z * sigma) << c.name << ": " << results[i].first << " " << a.luminance << " ± " << a.std_error << ", "
                                  << results[j].first << " " << b.luminance << " ± " << b.std_error;
      }
    }
  }
}

}  // namespace
}  // namespace pathex
