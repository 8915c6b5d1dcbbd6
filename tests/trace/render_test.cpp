// The tracer against closed forms (DESIGN §9), per class, with fixed seeds. Tolerances are stated
// in standard errors (batch means over 32 batches) plus a small relative slack.
#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <map>
#include <optional>
#include <tuple>

#include <glm/glm.hpp>

#include "classify/classifier.h"
#include "stats/convergence.h"
#include "classify/pathclass.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "optics/fresnel.h"
#include "trace/render.h"
#include "support/compare_estimates.h"
#include "support/scratch_files.h"
#include "support/stat_seed.h"
#include "support/test_classes.h"
#include "support/test_render.h"

namespace pathex {
namespace {

constexpr double kPi = 3.14159265358979323846;

using test::Rendered;
using test::Sampling;
using test::render_scene;

// Renders `scene_json` with `renderer`, classifying by `classes` (full notation).
Rendered render_json(const std::string& scene_json, const std::string& renderer, const std::vector<std::string>& classes,
                std::uint64_t spp, int threads = 0, std::uint64_t seed = 7, const Sampling& sampling = {}) {
  return render_scene(load_scene_json(scene_json, ".", "test"), renderer, classes, spp, threads, test::stat_seed_from(seed),
                      sampling, 12);
}

using test::expect_close;

std::string closed_sphere_point(double rho, double intensity) {
  return R"({"camera": {"type": "pinhole", "position": [0.1, 0.05, 0], "look_at": [0.1, 0.05, 1], "up": [0, 1, 0],
              "fov": 70, "width": 12, "height": 12},
   "materials": {"wall": {"type": "diffuse", "albedo": [)" + std::to_string(rho) + "," + std::to_string(rho) + "," +
         std::to_string(rho) + R"(]}},
   "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "wall"}],
   "lights": [{"type": "point", "position": [0, 0, 0], "intensity": [)" +
         std::to_string(intensity) + "," + std::to_string(intensity) + "," + std::to_string(intensity) + "]}]}";
}

// DESIGN §9: inside a closed diffuse sphere of radius r and albedo rho with a point light of
// intensity I at the centre, paths with n diffuse bounces carry rho^n I / (pi r^2) at every wall
// point, so that is every pixel's value and the image mean. The class of those paths with a point
// light and a pinhole is LSD D{n} DSE.
TEST(ClosedForm, SpherePointLightPerBounce) {
  const double kSigmas = test::family_sigmas(15);  // 15 checks, 0.1 % together
  const double rho = 0.5, intensity = 2.0;
  std::vector<std::string> classes;
  for (int n = 1; n <= 5; ++n) classes.push_back("LSDD{" + std::to_string(n) + "}DSE");
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    Rendered r = render_json(closed_sphere_point(rho, intensity), renderer, classes, 256);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    for (int n = 1; n <= 5; ++n) {
      const double expected = std::pow(rho, n) * intensity / kPi;
      expect_close(r.report.classes[static_cast<std::size_t>(n - 1)].estimate, expected, kSigmas, 0.01,
                   std::string(renderer) + " n=" + std::to_string(n));
    }
  }
}

std::string closed_sphere_emitting(double rho, double le) {
  return R"({"camera": {"type": "pinhole", "position": [0.2, 0, 0.1], "look_at": [0.2, 0.3, 1], "up": [0, 1, 0],
              "fov": 70, "width": 12, "height": 12},
   "materials": {"wall": {"type": "diffuse", "albedo": [)" + std::to_string(rho) + "," + std::to_string(rho) + "," +
         std::to_string(rho) + R"(]}},
   "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "wall",
               "emission": [)" + std::to_string(le) + "," + std::to_string(le) + "," + std::to_string(le) +
         R"(], "two_sided": true}]})";
}

// With the sphere itself emitting L_e: paths with n bounces carry L_e rho^n (class LDD D{n} DSE).
TEST(ClosedForm, EmittingSpherePerBounce) {
  const double kSigmas = test::family_sigmas(24);  // 24 checks, 0.1 % together
  const double rho = 0.5, le = 1.5;
  std::vector<std::string> classes;
  for (int n = 0; n <= 5; ++n) classes.push_back("LDDD{" + std::to_string(n) + "}DSE");
  for (const char* renderer : {"pt", "pt-nee", "lt", "bdpt"}) {
    Rendered r = render_json(closed_sphere_emitting(rho, le), renderer, classes, 128);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    for (int n = 0; n <= 5; ++n)
      expect_close(r.report.classes[static_cast<std::size_t>(n)].estimate, le * std::pow(rho, n), kSigmas, 0.01,
                   std::string(renderer) + " n=" + std::to_string(n));
  }
}

// The mean over the image of radiance(p) at the point p where each pixel's ray meets the plane
// y = 0 (0 where it misses), integrated over each pixel on a 256 x 256 grid: the reference for
// scenes whose floor radiance is known in closed form. The camera is the pinhole of the scene
// JSON below: position (0, 1.5, 2.5), looking at the origin, fov 50, 8 x 8 pixels. (A 16 x 16
// grid put a sun patch's edges 0.23 % high, half the 0.5 % its test allows beside its stderr.)
template <class F>
double floor_reference(F radiance) {
  const glm::vec3 pos(0.0f, 1.5f, 2.5f);
  const glm::vec3 fwd = glm::normalize(-pos);
  const glm::vec3 right = glm::normalize(glm::cross(fwd, glm::vec3(0, 1, 0)));
  const glm::vec3 up = glm::cross(right, fwd);
  const double ty = std::tan(25.0 * kPi / 180.0), tx = ty;
  double sum = 0;
  const int n = 8, sub = 256;
  for (int py = 0; py < n; ++py)
    for (int px = 0; px < n; ++px)
      for (int j = 0; j < sub; ++j)
        for (int i = 0; i < sub; ++i) {
          const double rx = px + (i + 0.5) / sub, ry = py + (j + 0.5) / sub;
          const double sx = (2 * rx / n - 1) * tx, sy = (1 - 2 * ry / n) * ty;
          const glm::dvec3 d = glm::dvec3(fwd) + sx * glm::dvec3(right) + sy * glm::dvec3(up);
          if (d.y >= 0) continue;
          const double t = -pos.y / d.y;
          sum += radiance(glm::dvec3(pos) + t * d);
        }
  return sum / (n * n * sub * sub);
}

const char* kFloorCamera = R"("camera": {"type": "pinhole", "position": [0, 1.5, 2.5], "look_at": [0, 0, 0],
                                 "up": [0, 1, 0], "fov": 50, "width": 8, "height": 8})";

// DESIGN §9: a point light of intensity I at height h over a large diffuse plane of albedo rho:
// reflected radiance rho I cos(theta) / (pi d^2). Class LSD D DSE.
TEST(ClosedForm, PointLightOverAPlane) {
  const double kSigmas = test::family_sigmas(3);  // 3 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, h = 1.0;
  const std::string scene = std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"}],
    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [2, 2, 2]}]})";
  const double expected = floor_reference([&](const glm::dvec3& p) {
    const double d2 = p.x * p.x + h * h + p.z * p.z;
    return rho * intensity * (h / std::sqrt(d2)) / (kPi * d2);
  });
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    Rendered r = render_json(scene, renderer, {"LSDDDSE"}, 128);
    expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, std::string(renderer) + " point over plane");
  }
}

// A spot light (hard edge, half angle 30°) at height h over the plane, pointing straight down:
// inside its cone the floor's radiance is the point light's, rho I cos(theta) / (pi d^2), and
// outside it is 0. The edge is decided once, in trace/emitters.h (the cone's boundary itself emits
// nothing), and every strategy reads it there: next-event estimation, light tracing and bdpt agree
// with the closed form. Class LSD D DSE.
TEST(ClosedForm, SpotLightOverAPlaneIsThePointLightInsideItsCone) {
  const double kSigmas = test::family_sigmas(3);  // 3 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, h = 1.0, cos_cone = std::cos(30.0 * kPi / 180.0);
  const std::string scene = std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"}],
    "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "cone": 30, "intensity": [2, 2, 2]}]})";
  const double expected = floor_reference([&](const glm::dvec3& p) {
    const double d2 = p.x * p.x + h * h + p.z * p.z;
    const double cos_theta = h / std::sqrt(d2);
    return cos_theta > cos_cone ? rho * intensity * cos_theta / (kPi * d2) : 0.0;
  });
  ASSERT_GT(expected, 0.0);
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    Rendered r = render_json(scene, renderer, {"LSDDDSE"}, 256);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, std::string(renderer) + " spot over plane");
  }
}

// Soft-edged spot lights, with the falloff of each source renderer: pbrt-v4's smoothstep in cos θ
// (coneangle 60°, conedeltaangle 50°) and Mitsuba 3's ramp linear in θ (cutoff_angle 60°,
// beam_width 10°). The floor's radiance is the point light's times the falloff; the falloff is
// written here from its definition, not from emitters.h. The two falloffs differ by 20 % here
// (about 40 bdpt standard errors), so a spot that took one for the other fails. Class LSD D DSE.
TEST(ClosedForm, SoftSpotLightsFallOffAsTheirRenderersDefine) {
  const double kSigmas = test::family_sigmas(6);  // 6 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, h = 1.0, total = 60.0 * kPi / 180.0, start = 10.0 * kPi / 180.0;
  for (const char* falloff : {"smoothstep", "linear"}) {
    const std::string scene = std::string("{") + kFloorCamera + R"(,
      "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
      "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"}],
      "lights": [{"type": "spot", "position": [0.3, 1, 0], "direction": [0, -1, 0], "cone": 60, "falloff_start": 10,
                  "falloff": ")" + std::string(falloff) + R"(", "intensity": [2, 2, 2]}]})";
    const bool linear = std::string(falloff) == "linear";
    const double expected = floor_reference([&](const glm::dvec3& p) {
      const double dx = p.x - 0.3, d2 = dx * dx + h * h + p.z * p.z, cos_theta = h / std::sqrt(d2);
      const double theta = std::acos(cos_theta);
      double f = 0.0;
      if (theta < start) {
        f = 1.0;
      } else if (theta < total) {
        if (linear) {
          f = (total - theta) / (total - start);
        } else {
          const double t = (cos_theta - std::cos(total)) / (std::cos(start) - std::cos(total));
          f = t * t * (3.0 - 2.0 * t);
        }
      }
      return rho * intensity * f * cos_theta / (kPi * d2);
    });
    ASSERT_GT(expected, 0.0);
    for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
      Rendered r = render_json(scene, renderer, {"LSDDDSE"}, 256);
      EXPECT_EQ(r.report.nonfinite_samples, 0u);
      expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, std::string(renderer) + " " + falloff + " spot");
    }
  }
}

// A uniform infinite light of radiance L (DESIGN §1: letters LDD, an area light) over a diffuse
// sphere of albedo rho: the sphere is convex, so each of its points sees only the light, and its
// radiance is rho L everywhere (the furnace). The camera's whole view is on the sphere, so every
// pixel is rho L in class L DD D DS E and there is nothing else. Every renderer must agree.
TEST(ClosedForm, UniformInfiniteLightOverADiffuseSphereIsTheFurnace) {
  const double kSigmas = test::family_sigmas(8);  // 8 checks, 0.1 % together
  const double rho = 0.7, radiance = 1.5;
  const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                                  "fov": 20, "width": 6, "height": 6},
    "materials": {"ball": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"}],
    "lights": [{"type": "environment", "radiance": [1.5, 1.5, 1.5]}]})";
  for (const char* renderer : {"pt", "pt-nee", "lt", "bdpt"}) {
    Rendered r = render_json(scene, renderer, {"LDDDDSE", "L.*E"}, 256);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    expect_close(r.report.classes[0].estimate, rho * radiance, kSigmas, 0.005, std::string(renderer) + " furnace");
    expect_close(r.report.classes[1].estimate, rho * radiance, kSigmas, 0.005, std::string(renderer) + " furnace, every path");
  }
}

// The white furnace for glass: a lossless dielectric sphere in a uniform infinite light of
// radiance L reflects and transmits without loss, so every ray that meets it leaves it again and
// brings back L, whatever the index: 1.5 (glass) and 1 / 1.5 (the inside less dense, as an air
// bubble in glass; pbrt-v4's eta < 1). The camera sees only the sphere, so every pixel is L, in
// paths L DD S+ DS E that only an emitter hit samples. A wrong Fresnel weight, a lost factor of
// η² on the way in or out, or a refraction that fails below 1 would each move it.
TEST(ClosedForm, GlassInAUniformLightIsInvisibleWhateverItsIndex) {
  const double kSigmas = test::family_sigmas(12);  // 12 checks, 0.1 % together
  for (const char* ior : {"1.5", "0.6666667"}) {
    const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                                    "fov": 20, "width": 6, "height": 6},
      "materials": {"glass": {"type": "dielectric", "ior": )" + std::string(ior) + R"(}},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "glass"}],
      "lights": [{"type": "environment", "radiance": [0.8, 0.8, 0.8]}]})";
    for (const char* renderer : {"pt", "pt-nee", "bdpt"}) {
      Rendered r = render_json(scene, renderer, {"LDDS+DSE", "L.*E"}, 64);
      EXPECT_EQ(r.report.nonfinite_samples, 0u);
      expect_close(r.report.classes[0].estimate, 0.8, kSigmas, 0.005, std::string(renderer) + " glass furnace, ior " + ior);
      expect_close(r.report.classes[1].estimate, 0.8, kSigmas, 0.005, std::string(renderer) + " glass furnace, every path, ior " + ior);
    }
  }
}

// The same light seen directly: a camera that looks away from the only shape sees L in every pixel
// (class L DD DS E), and a second environment entry adds its radiance.
TEST(ClosedForm, UniformInfiniteLightSeenDirectlyIsItsRadiance) {
  const double kSigmas = test::family_sigmas(1);  // 1 checks, 0.1 % together
  const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, -6], "up": [0, 1, 0],
                                  "fov": 60, "width": 6, "height": 6},
    "materials": {"ball": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}, {"type": "environment", "radiance": [0.5, 0.5, 0.5]}]})";
  for (const char* renderer : {"pt", "pt-nee"}) {  // one strategy: the eye ray's hit, exactly L
    Rendered r = render_json(scene, renderer, {"LDDDSE"}, 16);
    expect_close(r.report.classes[0].estimate, 1.5, 0.0, 1e-5, std::string(renderer) + " environment seen directly");
  }
  Rendered r = render_json(scene, "bdpt", {"LDDDSE"}, 64);  // the hit weighed against the camera join
  expect_close(r.report.classes[0].estimate, 1.5, kSigmas, 0.005, "bdpt environment seen directly");
}

// DESIGN §9: a planar mirror of reflectance R throws a caustic that is the floor lit by the
// light's mirror image with intensity R I. Light at height 1, a large mirror facing down at
// height 2 (image light at height 3), the camera below the mirror. Class LSD S D DSE, which
// pt-nee cannot sample and lt and bdpt can.
TEST(ClosedForm, MirrorCausticIsTheImageLight) {
  const double kSigmas = test::family_sigmas(2);  // 2 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, refl = 0.8, image_h = 3.0;
  const std::string scene = std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "mirror": {"type": "mirror", "reflectance": [0.8, 0.8, 0.8]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"},
               {"type": "quad", "corner": [-100, 2, -100], "edge1": [200, 0, 0], "edge2": [0, 0, 200], "material": "mirror"}],
    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [2, 2, 2]}]})";
  const double expected = floor_reference([&](const glm::dvec3& p) {
    const double d2 = p.x * p.x + image_h * image_h + p.z * p.z;
    return rho * refl * intensity * (image_h / std::sqrt(d2)) / (kPi * d2);
  });
  for (const char* renderer : {"lt", "bdpt"}) {
    Rendered r = render_json(scene, renderer, {"LSDSDDSE"}, 256);
    expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, std::string(renderer) + " mirror caustic");
  }
  Rendered pt = render_json(scene, "pt-nee", {"LSDSDDSE"}, 16);
  EXPECT_EQ(pt.report.classes[0].estimate.luminance, 0.0);  // the checker says unreachable; so does the tracer
}

// DESIGN §9: a distant light of irradiance E (perpendicular to its direction) through a window:
// the floor's irradiance is E cos θ inside the window's projection and 0 outside, so its radiance
// there is rho E cos θ / pi. Class LDS D DSE: the distant-projection connector samples it (as a
// production path tracer samples the sun), light tracing and bdpt join it at the camera, and
// pt-nee cannot (its value stays exactly 0).
TEST(ClosedForm, SunPatchThroughAWindowIsECosTheta) {
  const double kSigmas = test::family_sigmas(3);  // 3 checks, 0.1 % together
  const double rho = 0.6, irradiance = 2.0;
  const glm::dvec3 dir = glm::normalize(glm::dvec3(0.3, -1.0, 0.2));
  const std::string scene = std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"}],
    "lights": [{"type": "distant", "direction": [0.3, -1, 0.2], "irradiance": [2, 2, 2],
                "aperture": {"corner": [-0.5, 2, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1]}}]})";
  const double expected = floor_reference([&](const glm::dvec3& p) {
    const glm::dvec3 q = p - dir * ((2.0 - p.y) / -dir.y);  // against the light, up to the window's plane
    const bool lit = q.x >= -0.5 && q.x < 0.5 && q.z >= -0.5 && q.z < 0.5;
    return lit ? rho * irradiance * -dir.y / kPi : 0.0;
  });
  ASSERT_GT(expected, 0.0);
  // pt-nee+distant at 256 spp: only the patch's edge pixels vary, by whole samples, and under sobol
  // their two replicates' counts can tie in every group, so at 64 spp 1 seed in 100 read a stderr
  // of 0 with the estimate 0.64 % off (its spread over seeds 0.79 %; at 256 spp 0.22 %).
  for (const auto& [renderer, spp] : {std::pair<const char*, std::uint64_t>{"pt-nee+distant", 256}, {"lt", 256}, {"bdpt", 256}}) {
    Rendered r = render_json(scene, renderer, {"LDSDDSE"}, spp);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, std::string(renderer) + " sun patch");
  }
  Rendered pt = render_json(scene, "pt-nee", {"LDSDDSE"}, 16);
  EXPECT_EQ(pt.report.classes[0].estimate.luminance, 0.0);
  // The connector's statistics account for every attempt: eye vertices outside the window's
  // projection miss the aperture; with nothing between floor and window nothing is occluded.
  Rendered d = render_json(scene, "pt-nee+distant", {"LDSDDSE"}, 16);
  ASSERT_EQ(d.out.connectors.size(), 1u);
  const ConnectorStats& c = d.out.connectors[0];
  EXPECT_EQ(c.strategy, "nee-distant");
  EXPECT_EQ(c.connector, "distant-projection");
  EXPECT_GT(c.successes, 0u);
  EXPECT_GT(c.outside, 0u);
  EXPECT_EQ(c.occluded, 0u);
  EXPECT_EQ(c.attempts, c.successes + c.outside + c.occluded + c.no_transport);
}

// DESIGN §9: a planar mirror of reflectance R throws a caustic on a diffuse floor: the floor lit by
// the light's mirror image, of intensity R I, wherever the line from the image to the floor point
// crosses the mirror. A point light at (0.3, 0.8, 0), a vertical mirror in the plane x = 1 (z in
// [-1.5, 1.5], y in [0, 1]); the camera sees the floor only at x < 1 (the mirror hides the rest).
// Class LSDSDDSE: light, mirror, floor, camera. The mirror connector (pt-nee+mirror: next-event
// estimation towards the image) matches the closed form; pt-nee cannot sample the class at all.
TEST(ClosedForm, MirrorCausticIsTheFloorLitByTheImageLight) {
  const double kSigmas = test::family_sigmas(2);  // 2 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, refl = 0.8;
  const glm::dvec3 image(1.7, 0.8, 0.0);  // (0.3, 0.8, 0) reflected through x = 1
  const std::string scene = std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "mirror": {"type": "mirror", "reflectance": [0.8, 0.8, 0.8]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"},
               {"type": "quad", "corner": [1, 0, 1.5], "edge1": [0, 0, -3], "edge2": [0, 1, 0], "material": "mirror"}],
    "lights": [{"type": "point", "position": [0.3, 0.8, 0], "intensity": [2, 2, 2]}]})";
  const double expected = floor_reference([&](const glm::dvec3& p) {
    if (p.x >= 1.0) return 0.0;  // behind the mirror: hidden from the camera, and no caustic there
    const double f = (1.0 - p.x) / (image.x - p.x);  // where the line to the image crosses x = 1
    const glm::dvec3 m = p + f * (image - p);
    if (!(m.y >= 0.0 && m.y < 1.0 && m.z > -1.5 && m.z <= 1.5)) return 0.0;
    const glm::dvec3 d = image - p;
    const double d2 = glm::dot(d, d);
    return rho * refl * intensity * (d.y / std::sqrt(d2)) / (kPi * d2);
  });
  ASSERT_GT(expected, 0.0);
  Rendered r = render_json(scene, "pt-nee+mirror", {"LSDSDDSE"}, 64);
  EXPECT_EQ(r.report.nonfinite_samples, 0u);
  expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, "pt-nee+mirror caustic");
  // bdpt+mirror weighs the connector against light tracing (s = 3, t = 1) by MIS: the same value.
  Rendered b = render_json(scene, "bdpt+mirror", {"LSDSDDSE"}, 64);
  expect_close(b.report.classes[0].estimate, expected, kSigmas, 0.005, "bdpt+mirror caustic");
  Rendered pt = render_json(scene, "pt-nee", {"LSDSDDSE"}, 16);
  EXPECT_EQ(pt.report.classes[0].estimate.luminance, 0.0);
  // Every attempt is accounted for: eye vertices whose line to the image misses the mirror are
  // off it; nothing stands between the mirror and the floor.
  ASSERT_EQ(r.out.connectors.size(), 1u);
  const ConnectorStats& c = r.out.connectors[0];
  EXPECT_EQ(c.strategy, "mirror-nee");
  EXPECT_EQ(c.connector, "mirror");
  EXPECT_GT(c.successes, 0u);
  EXPECT_GT(c.outside, 0u);
  EXPECT_EQ(c.occluded, 0u);
  EXPECT_EQ(c.attempts, c.successes + c.outside + c.occluded + c.no_transport);
}

// A blocker between the light and the mirror: the connector tests both of its segments, so the
// caustic vanishes and every join that reached the mirror is counted as occluded.
TEST(MirrorConnector, EitherSegmentBlockedBlocksTheJoin) {
  const std::string scene = std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "mirror": {"type": "mirror", "reflectance": [0.8, 0.8, 0.8]},
                  "black": {"type": "diffuse", "albedo": [0, 0, 0]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"},
               {"type": "quad", "corner": [1, 0, 1.5], "edge1": [0, 0, -3], "edge2": [0, 1, 0], "material": "mirror"},
               {"type": "quad", "corner": [0.6, -1, 3], "edge1": [0, 0, -6], "edge2": [0, 3, 0], "material": "black"}],
    "lights": [{"type": "point", "position": [0.3, 0.8, 0], "intensity": [2, 2, 2]}]})";
  Rendered r = render_json(scene, "pt-nee+mirror", {"LSDSDDSE"}, 8);
  EXPECT_EQ(r.report.classes[0].estimate.luminance, 0.0);
  ASSERT_EQ(r.out.connectors.size(), 1u);
  const ConnectorStats& c = r.out.connectors[0];
  EXPECT_EQ(c.successes, 0u);
  EXPECT_GT(c.occluded, 0u);
  EXPECT_EQ(c.attempts, c.successes + c.outside + c.occluded + c.no_transport);
}

// An orthographic sensor (film 2 x 2 looking straight down from height 3) over a diffuse floor,
// a point light of intensity I at height h = 1 and a vertical mirror of reflectance R at x = 2.
// Image means (the film's average radiance):
//   LSDSDE   the light seen directly: I / A_film (ortho-projection only);
//   LSDDSDE  the lit floor, rho I h / (pi d^3) averaged over the film (ortho-projection and
//            next-event estimation, combined by MIS);
//   LSDSDSDE the mirror's caustic, the same with the image light at x = 3.5 and intensity R I
//            (ortho-projection only).
TEST(ClosedForm, OrthographicSensorSeesLightFloorAndMirrorCaustic) {
  const double kSigmas = test::family_sigmas(4);  // 4 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, refl = 0.8, film_area = 4.0;
  const std::string scene = R"({"camera": {"type": "orthographic", "position": [0, 3, 0], "look_at": [0, 0, 0], "up": [0, 0, -1],
                                           "film_width": 2, "film_height": 2, "width": 8, "height": 8},
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                  "mirror": {"type": "mirror", "reflectance": [0.8, 0.8, 0.8]}},
    "shapes": [{"type": "quad", "corner": [-100, 0, 100], "edge1": [200, 0, 0], "edge2": [0, 0, -200], "material": "plane"},
               {"type": "quad", "corner": [2, 0, -10], "edge1": [0, 10, 0], "edge2": [0, 0, 20], "material": "mirror"}],
    "lights": [{"type": "point", "position": [0.5, 1, 0], "intensity": [2, 2, 2]}]})";
  // The film's mean of rho I' h / (pi d^3) for a light of intensity I' at (lx, 1, 0), by the
  // midpoint rule on a 400 x 400 grid (relative error below 1e-5).
  const auto floor_mean = [&](double lx, double light_intensity) {
    const int n = 400;
    double sum = 0;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const double x = -1.0 + 2.0 * (i + 0.5) / n, z = -1.0 + 2.0 * (j + 0.5) / n;
        const double d = std::sqrt((x - lx) * (x - lx) + 1.0 + z * z);
        sum += rho * light_intensity / (kPi * d * d * d);
      }
    return sum / (n * n);
  };
  const std::vector<std::pair<std::string, double>> expected = {
      {"LSDSDE", intensity / film_area}, {"LSDDSDE", floor_mean(0.5, intensity)}, {"LSDSDSDE", floor_mean(3.5, refl * intensity)}};
  std::vector<std::string> classes;
  for (const auto& [c, v] : expected) classes.push_back(c);
  Rendered r = render_json(scene, "bdpt+ortho", classes, 64);
  EXPECT_EQ(r.report.nonfinite_samples, 0u);
  for (std::size_t i = 0; i < expected.size(); ++i)
    expect_close(r.report.classes[i].estimate, expected[i].second, kSigmas, 0.005, "bdpt+ortho " + expected[i].first);
  // The light seen directly and the caustic come from the connector alone, one technique each
  // (s letters before its chain): it carries all of the estimate, and all of the caustic's
  // variance; the light seen directly is the same in every batch, so it has no variance to share.
  // The lit floor comes from the connector and next-event estimation together.
  for (std::size_t i : {0u, 2u}) {
    const std::vector<TechniqueEstimate>& ts = r.report.classes[i].strategies;
    ASSERT_EQ(ts.size(), 1u) << expected[i].first;
    EXPECT_EQ(ts[0].name, i == 0 ? "ortho-splat (1, DSD, 0)" : "ortho-splat (3, DSD, 0)");
    EXPECT_EQ(ts[0].share, 1.0);
    if (i == 0) EXPECT_TRUE(std::isnan(ts[0].variance_share));
    else EXPECT_EQ(ts[0].variance_share, 1.0);
  }
  double floor_share = 0;
  for (const TechniqueEstimate& t : r.report.classes[1].strategies) floor_share += t.share;
  EXPECT_EQ(r.report.classes[1].strategies.size(), 2u);
  EXPECT_NEAR(floor_share, 1.0, 1e-12);
  // Without the connector only the lit floor is reachable (next-event estimation).
  Rendered plain = render_json(scene, "bdpt", classes, 64);
  EXPECT_EQ(plain.report.classes[0].estimate.luminance, 0.0);
  expect_close(plain.report.classes[1].estimate, expected[1].second, kSigmas, 0.005, "bdpt LSDDSDE");
  EXPECT_EQ(plain.report.classes[2].estimate.luminance, 0.0);
}

// Every sensor measures radiance: inside the emitting sphere every wall point has L_e / (1 - rho),
// so a thin lens, an orthographic camera and a spot meter all read it, from every strategy that
// can reach them (the lens also through light paths hitting it, t = 0).
TEST(ClosedForm, EverySensorReadsTheEmittingSphere) {
  const double kSigmas = test::family_sigmas(9);  // 9 checks, 0.1 % together
  const std::string materials = R"("materials": {"wall": {"type": "diffuse", "albedo": [0.5, 0.5, 0.5]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "wall", "emission": [1, 1, 1], "two_sided": true}]})";
  struct Case {
    const char* camera;
    std::vector<const char*> renderers;
    std::uint64_t spp;
  };
  const Case cases[] = {
      {R"("camera": {"type": "lens", "position": [0.1, 0, 0], "look_at": [0.1, 0, 1], "fov": 60, "aperture_radius": 0.05,
                     "focus_distance": 0.8, "width": 6, "height": 6})", {"pt", "lt", "bdpt"}, 256},
      {R"("camera": {"type": "orthographic", "position": [0, 0, 0], "look_at": [0, 0, 1], "film_width": 0.8,
                     "film_height": 0.8, "width": 6, "height": 6})", {"pt", "pt-nee", "bdpt"}, 64},
      {R"("camera": {"type": "spotmeter", "position": [0.3, 0.1, 0], "look_at": [0.5, 0.2, 1]})", {"pt", "pt-nee", "bdpt"}, 8192},
  };
  for (const Case& c : cases)
    for (const char* renderer : c.renderers) {
      Rendered r = render_json(std::string("{") + c.camera + "," + materials, renderer, {"L.*E"}, c.spp);
      EXPECT_EQ(r.report.nonfinite_samples, 0u);
      // Paths up to 12 bounces carry 2 (1 - 0.5^13).
      expect_close(r.report.total, 2.0 * (1.0 - std::pow(0.5, 13)), kSigmas, 0.01, std::string(renderer) + " " + c.camera);
    }
}

// A mixture labels each vertex with the component that carried the transport (DESIGN §7). Inside
// an emitting sphere whose material is 0.5 diffuse + 0.1 mirror, a path whose interior letters are
// a word w carries L_e 0.5^{#D(w)} 0.1^{#S(w)}: LDD D DSE 0.5, LDD S DSE 0.1, LDD SD DSE 0.05, …
TEST(ClosedForm, MixtureLettersCarryTheirComponentsShare) {
  const double kSigmas = test::family_sigmas(12);  // 12 checks, 0.1 % together
  const std::string scene = R"({"camera": {"type": "pinhole", "position": [0.2, 0, 0.1], "look_at": [0.2, 0.3, 1], "fov": 70,
                                           "width": 8, "height": 8},
    "materials": {"mix": {"type": "mixture", "components": [{"weight": 0.5, "material": {"type": "diffuse", "albedo": [1, 1, 1]}},
                                                            {"weight": 0.1, "material": {"type": "mirror", "reflectance": [1, 1, 1]}}]}},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "mix", "emission": [1, 1, 1], "two_sided": true}]})";
  const std::vector<std::pair<std::string, double>> expected = {
      {"LDDDSE", 1.0}, {"LDDDDSE", 0.5}, {"LDDSDSE", 0.1}, {"LDDSDDSE", 0.05}, {"LDDDSDSE", 0.05}, {"LDDSSDSE", 0.01}};
  std::vector<std::string> classes;
  for (const auto& [c, v] : expected) classes.push_back(c);
  for (const char* renderer : {"pt", "bdpt"}) {
    Rendered r = render_json(scene, renderer, classes, 512);
    for (std::size_t i = 0; i < expected.size(); ++i)
      expect_close(r.report.classes[i].estimate, expected[i].second, kSigmas, 0.01, std::string(renderer) + " " + expected[i].first);
  }
}

// pt-nee, lt and bdpt (in that order in `runs`) agree on each class of `classes` (or, with none,
// on the total): every pair by the shared comparison rule (tests/support/compare_estimates.h:
// Student's t at the pair's Welch–Satterthwaite degrees of freedom, Šidák over all the checks,
// 0.1 % together) with `rel` of the value allowed beyond the noise; every estimate finite and,
// for a class, positive (the scene must show it).
void expect_estimators_agree(const std::vector<Rendered>& runs, std::size_t classes, double rel) {
  const char* names[] = {"pt-nee", "lt", "bdpt"};
  const std::size_t rows = std::max<std::size_t>(classes, 1);
  std::vector<test::Comparison> comparisons;
  for (std::size_t c = 0; c < rows; ++c)
    for (std::size_t i = 0; i < runs.size(); ++i) {
      EXPECT_EQ(runs[i].report.nonfinite_samples, 0u) << names[i];
      for (std::size_t j = i + 1; j < runs.size(); ++j) {
        const Estimate& x = classes == 0 ? runs[i].report.total : runs[i].report.classes[c].estimate;
        const Estimate& y = classes == 0 ? runs[j].report.total : runs[j].report.classes[c].estimate;
        ASSERT_GT(x.luminance, 0.0) << "class " << c;
        comparisons.push_back(test::compare("class " + std::to_string(c) + ", " + names[i] + " against " + names[j], x, y));
        comparisons.back().allowance = rel * x.luminance;
      }
    }
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

// A floor of two triangles (geometric normal +y) whose vertex normals all lean 25° towards +x,
// written as an ASCII PLY into the scratch folder; `extra` adds JSON shapes.
std::string smooth_floor_scene(const std::string& extra) {
  const double a = 25.0 * kPi / 180.0;
  const std::string n = std::to_string(std::sin(a)) + " " + std::to_string(std::cos(a)) + " 0\n";
  test::write("smooth-floor.ply", "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
                                  "property float nx\nproperty float ny\nproperty float nz\nelement face 2\n"
                                  "property list uchar int vertex_indices\nend_header\n"
                                  "-100 0 100 " + n + "100 0 100 " + n + "100 0 -100 " + n + "-100 0 -100 " + n +
                                  "3 0 1 2\n3 0 2 3\n");
  return std::string("{") + kFloorCamera + R"(,
    "materials": {"plane": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]}},
    "shapes": [{"type": "mesh", "file": "smooth-floor.ply", "material": "plane"})" + extra + R"(],
    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [2, 2, 2]}]})";
}

// Shading normals (Veach's thesis §5.3). A diffuse floor whose shading normal ns leans 25° off its
// geometric normal, under a point light of intensity I at height 1: its radiance is
// rho I |ns·wi| / (pi d^2), the BSDF's cosine taken with ns. Next-event estimation reads that
// directly; light tracing reaches it only through the adjoint BSDF's correction
// |wo·ns| |wi·ng| / (|wo·ng| |wi·ns|) (without it, lt would give rho I |ng·wi| / (pi d^2), 4 to 10 %
// off here, tens of standard errors); bdpt mixes both. Class LSD D DSE.
TEST(ClosedForm, SmoothShadedFloorUnderAPointLightTakesTheShadingCosine) {
  const double kSigmas = test::family_sigmas(3);  // 3 checks, 0.1 % together
  const double rho = 0.6, intensity = 2.0, a = 25.0 * kPi / 180.0;
  const glm::dvec3 ns(std::sin(a), std::cos(a), 0.0);
  const std::string scene = smooth_floor_scene("");
  const double expected = floor_reference([&](const glm::dvec3& p) {
    const glm::dvec3 to_light = glm::dvec3(0, 1, 0) - p;
    const double d2 = glm::dot(to_light, to_light);
    return rho * intensity * std::fabs(glm::dot(ns, to_light)) / std::sqrt(d2) / (kPi * d2);
  });
  const double flat = floor_reference([&](const glm::dvec3& p) {
    const double d2 = p.x * p.x + 1.0 + p.z * p.z;
    return rho * intensity / std::sqrt(d2) / (kPi * d2);
  });
  ASSERT_GT(std::fabs(expected - flat), 0.03 * expected);  // the test can tell the two apart
  for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
    Rendered r = render_scene(load_scene_json(scene, test::scratch(), "smooth"), renderer, {"LSDDDSE"}, 256, 0, test::stat_seed(7), {}, 12);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    expect_close(r.report.classes[0].estimate, expected, kSigmas, 0.005, std::string(renderer) + " smooth-shaded floor");
  }
}

// The same floor with a flat wall beside it: light that bounces floor -> wall and wall -> floor
// goes through joins with a smooth-shaded end on either side (the light subpath's end carries the
// adjoint's correction, the eye subpath's the shading cosine). pt-nee, lt and bdpt sample those
// paths through different densities and joins, so they agree only if every join and the random
// walk treat ns alike. Classes LSD D D DSE (one bounce between the surfaces) and the direct light.
TEST(Agreement, SmoothShadedFloorAndAWallAgreeAcrossEstimators) {
  const std::string scene = smooth_floor_scene(R"(,
    {"type": "quad", "corner": [-1, 0, -1], "edge1": [0, 3, 0], "edge2": [0, 0, 3], "material": "plane"})");
  const std::vector<std::string> classes = {"LSDDDSE", "LSDDDDSE"};
  std::vector<Rendered> runs;
  for (const char* renderer : {"pt-nee", "lt", "bdpt"})
    runs.push_back(render_scene(load_scene_json(scene, test::scratch(), "smooth"), renderer, classes, 256, 0, test::stat_seed(11), {}, 12));
  expect_estimators_agree(runs, classes.size(), 0.005);
}

// A sphere of radius 1 at the origin as a latitude-longitude mesh (`rings` x 2 `rings` quads, two
// triangles each, facing outwards) whose vertex normals are the sphere's, as an ASCII PLY.
std::string smooth_sphere_ply(int rings) {
  std::string v, f;
  int vertices = 0, faces = 0;
  for (int i = 0; i <= rings; ++i)
    for (int j = 0; j <= 2 * rings; ++j, ++vertices) {
      const double theta = kPi * i / rings, phi = kPi * j / rings;
      const glm::dvec3 n(std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi));
      v += std::to_string(n.x) + " " + std::to_string(n.y) + " " + std::to_string(n.z) + " " + std::to_string(n.x) + " " +
           std::to_string(n.y) + " " + std::to_string(n.z) + "\n";
    }
  const int row = 2 * rings + 1;
  for (int i = 0; i < rings; ++i)
    for (int j = 0; j < 2 * rings; ++j) {
      const int a = i * row + j, b = a + 1, c = a + row, d = c + 1;  // a, b on ring i; c, d below
      if (i > 0) f += "3 " + std::to_string(a) + " " + std::to_string(b) + " " + std::to_string(d) + "\n", ++faces;
      if (i + 1 < rings) f += "3 " + std::to_string(a) + " " + std::to_string(d) + " " + std::to_string(c) + "\n", ++faces;
    }
  return "ply\nformat ascii 1.0\nelement vertex " + std::to_string(vertices) +
         "\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\n"
         "element face " + std::to_string(faces) + "\nproperty list uchar int vertex_indices\nend_header\n" + v + f;
}

// Issue 34's test of shading normals: a smooth-shaded sphere mesh (coarse, 4 x 8 quads, so its
// shading normals stray up to 30° from its facets) on a floor, lit by a small area light, seen
// through a narrow pinhole (10°) that frames part of one facet. pt-nee, lt and bdpt agree within
// the family's tolerance on the direct light and on one bounce between sphere and floor. Without
// the adjoint's correction at the light subpath's vertices, lt reads 0.118 ± 0.007 where pt-nee
// and bdpt read 0.1785 (checked when this test was written). The frame matters: over a whole
// facet the correction's effect nearly cancels (ns leans one way on one side of the facet and the
// other way on the other), so a view of the whole sphere could not tell.
TEST(Agreement, SmoothShadedSphereMeshUnderAnAreaLightAgreesAcrossEstimators) {
  test::write("smooth-sphere.ply", smooth_sphere_ply(4));
  const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 1.2, 4], "look_at": [0.3, 0.45, 0.8], "up": [0, 1, 0],
                                           "fov": 10, "width": 8, "height": 8},
    "materials": {"white": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]}, "black": {"type": "diffuse", "albedo": [0, 0, 0]}},
    "shapes": [{"type": "mesh", "file": "smooth-sphere.ply", "material": "white"},
               {"type": "quad", "corner": [-4, -1, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "white"},
               {"type": "quad", "corner": [1, 3, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "material": "black", "emission": [20, 20, 20]}]})";
  const std::vector<std::string> classes = {"LDDDDSE", "LDDDDDSE"};
  std::vector<Rendered> runs;
  // Light tracing reaches this 8 × 8, 10° frame's LDDDDDSE rarely, through the adjoint factor of the
  // shading normals (unbounded near grazing): at 1,024 spp a few heavy splats carry its estimate,
  // and 1 seed in 72 read it 2.3× low with a stderr of 24 % (issue 36's sweep). At 8,192 spp its
  // batch means are near normal again; the other two meet the class at every sample.
  for (const char* renderer : {"pt-nee", "lt", "bdpt"})
    runs.push_back(render_scene(load_scene_json(scene, test::scratch(), "sphere"), renderer, classes,
                                std::string(renderer) == "lt" ? 8192 : 1024, 0, test::stat_seed(13), {}, 12));
  expect_estimators_agree(runs, classes.size(), 0.005);
}

// Absorbing media (trace/media.h). A glass slab (index 1.5, two parallel faces 0.5 apart, its
// interior absorbing σa = 1.2 per unit length) between a pinhole and an emitting quad of radiance
// 1, seen at normal incidence (a 1° field of view: Fresnel within 1e-6 of normal incidence). Light
// crosses the slab with k = 0, 1, 2, … pairs of internal reflections: the camera sees
//     Le Σ_k (1 − R)² R^{2k} e^{−σa d (2k + 1)} = Le (1 − R)² e^{−σa d} / (1 − R² e^{−2 σa d}),
// R = ((η − 1) / (η + 1))² (the radiance's η² going in and 1/η² coming out cancel). Only a path
// that hits the emitter can carry this light (the slab is specular), so pt and bdpt read the same
// emitter hits; without the medium the slab would pass 0.923 instead of 0.506.
TEST(ClosedForm, AbsorbingGlassSlabTransmitsBeerLambertTimesFresnel) {
  const double kSigmas = test::family_sigmas(2);  // 2 checks, 0.1 % together
  const double eta = 1.5, sigma = 1.2, d = 0.5;
  const double r = (eta - 1) * (eta - 1) / ((eta + 1) * (eta + 1));
  const double expected = (1 - r) * (1 - r) * std::exp(-sigma * d) / (1 - r * r * std::exp(-2 * sigma * d));
  const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, 3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                                           "fov": 1, "width": 4, "height": 4},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5}, "black": {"type": "diffuse", "albedo": [0, 0, 0]}},
    "shapes": [{"type": "quad", "corner": [-5, -5, 0], "edge1": [10, 0, 0], "edge2": [0, 10, 0], "material": "glass", "absorption": [1.2, 1.2, 1.2]},
               {"type": "quad", "corner": [-5, -5, -0.5], "edge1": [0, 10, 0], "edge2": [10, 0, 0], "material": "glass", "absorption": [1.2, 1.2, 1.2]},
               {"type": "quad", "corner": [-5, -5, -2], "edge1": [10, 0, 0], "edge2": [0, 10, 0], "material": "black", "emission": [1, 1, 1]}]})";
  for (const char* renderer : {"pt", "bdpt"}) {
    Rendered out = render_json(scene, renderer, {}, 256, 0, test::stat_seed(17));
    EXPECT_EQ(out.report.nonfinite_samples, 0u);
    expect_close(out.report.total, expected, kSigmas, 1e-4, std::string(renderer) + " absorbing slab");
  }
}

// Joins through a medium: a rough glass sphere (GGX α 0.3) whose interior absorbs σa = (0.3, 0.8,
// 1.5), lit by a small area light, on a diffuse floor. Light reaches the floor and the camera
// through rough (D) vertices on the sphere's inside, so bdpt and lt join across the interior and
// pt-nee and lt reach the same paths through different segments: they agree only if every segment
// inside carries exp(−σa d) in every strategy. The same scene without the medium is brighter by
// far more than the tolerance, so the test sees the medium.
TEST(Agreement, AbsorbingRoughGlassAgreesAcrossEstimators) {
  const auto scene = [](const char* absorption) {
    return std::string(R"({"camera": {"type": "pinhole", "position": [0, 1.5, 4], "look_at": [0, 0.2, 0], "up": [0, 1, 0],
                                           "fov": 40, "width": 8, "height": 8},
    "materials": {"glass": {"type": "dielectric", "ior": 1.5, "roughness": 0.3}, "white": {"type": "diffuse", "albedo": [0.7, 0.7, 0.7]},
                  "black": {"type": "diffuse", "albedo": [0, 0, 0]}},
    "shapes": [{"type": "sphere", "center": [0, 0.6, 0], "radius": 0.6, "material": "glass", "absorption": )") + absorption + R"(},
               {"type": "quad", "corner": [-4, 0, 4], "edge1": [8, 0, 0], "edge2": [0, 0, -8], "material": "white"},
               {"type": "quad", "corner": [-0.5, 3, -0.5], "edge1": [1, 0, 0], "edge2": [0, 0, 1], "material": "black", "emission": [10, 10, 10]}]})";
  };
  std::vector<Rendered> runs;
  for (const char* renderer : {"pt-nee", "lt", "bdpt"})
    runs.push_back(render_json(scene("[0.3, 0.8, 1.5]"), renderer, {}, 1024, 0, test::stat_seed(19)));
  const Rendered clear = render_json(scene("[0, 0, 0]"), "bdpt", {}, 1024, 0, test::stat_seed(19));
  expect_estimators_agree(runs, 0, 0.002);
  // The medium is seen: without it the image is brighter than twice the agreement's tolerance (a
  // fixed 10 sigma failed at 1 seed in 100, seed 28: 9.75 sigma, one run's stderr inflated by a rare
  // sample). 1,024 spp: at 256 the medium's 10 % came within 2 x (3.3 sigma + 0.2 %) at seeds 29
  // and 100 of 100 (twenty-fourth session's sweep; swept 0 of 100 on 2026-12-06's renderer).
  const Estimate& a = runs[2].report.total;
  const double tolerance = test::family_sigmas(3) * std::hypot(a.std_error, clear.report.total.std_error) + 0.002 * a.luminance;
  EXPECT_GT(clear.report.total.luminance - a.luminance, 2.0 * tolerance)
      << "absorbing " << a.luminance << ", clear " << clear.report.total.luminance;
}

TEST(Determinism, SameSeedOneAndTwoThreadsIdentical) {
  Rendered a = render_json(closed_sphere_point(0.5, 1.0), "bdpt", {"LSDDDSE"}, 16, 1);
  Rendered b = render_json(closed_sphere_point(0.5, 1.0), "bdpt", {"LSDDDSE"}, 16, 2);
  EXPECT_EQ(a.report.total.rgb, b.report.total.rgb);
  EXPECT_EQ(a.report.total.std_error, b.report.total.std_error);
  ASSERT_EQ(a.report.paths.size(), b.report.paths.size());
  for (std::size_t i = 0; i < a.report.paths.size(); ++i) {
    EXPECT_EQ(a.report.paths[i].path, b.report.paths[i].path);
    EXPECT_EQ(a.report.paths[i].estimate.rgb, b.report.paths[i].estimate.rgb);
  }
}

// Without images (pathex trace --no-images) the render keeps no per-pixel sums at all, and the
// histogram is exactly the one the render with images keeps: the images never feed it.
TEST(Images, OffLeavesTheHistogramExactlyTheSameAndTheImageEmpty) {
  Result<Scene> scene = load_scene_json(default_scene_json(), ".", "default");
  ASSERT_TRUE(scene.ok());
  Result<Profile> profile = resolve_profile("bdpt", Limits{});
  RenderOptions with;
  with.spp = 2;
  with.threads = 2;
  RenderOptions without = with;
  without.images = false;
  ASSERT_TRUE(profile.ok());
  Result<RenderOutput> a = render(*scene, *profile, nullptr, with);
  Result<RenderOutput> b = render(*scene, *profile, nullptr, without);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a->images.width(), 64);
  EXPECT_GT(a->images.memory_bytes(), 0u);
  EXPECT_EQ(b->images.width(), 0);
  EXPECT_EQ(b->images.num_layers(), 1);
  EXPECT_EQ(b->images.memory_bytes(), 0u);
  EXPECT_EQ(a->rays, b->rays);
  const Histogram& ha = a->histogram;
  const Histogram& hb = b->histogram;
  ASSERT_EQ(ha.num_paths(), hb.num_paths());
  ASSERT_GT(ha.num_paths(), 100);
  for (int id = 0; id < ha.num_paths(); ++id) {
    const std::optional<Histogram::PathId> other = hb.find(ha.path(id));
    ASSERT_TRUE(other.has_value()) << ha.path(id);
    for (int batch = 0; batch < ha.num_batches(); ++batch) {
      EXPECT_TRUE(ha.cell(id, batch).sum == hb.cell(*other, batch).sum) << ha.path(id) << " batch " << batch;
      EXPECT_EQ(ha.cell(id, batch).contributions, hb.cell(*other, batch).contributions) << ha.path(id);
    }
  }
  EXPECT_EQ(ha.total_samples(), hb.total_samples());
  EXPECT_EQ(ha.nonfinite(), 0u);
  EXPECT_EQ(hb.nonfinite(), 0u);
}

// An interrupted render keeps the passes it finished, says it is incomplete, and still has a
// standard error (passes are spread over the batches round-robin).
TEST(Interrupt, KeepsFinishedPassesAndMarksIncomplete) {
  Result<Scene> scene = load_scene_json(closed_sphere_point(0.5, 1.0), ".", "test");
  Result<Profile> profile = resolve_profile("bdpt", Limits{});
  std::atomic<bool> cancel{false};
  RenderOptions o;
  o.spp = 1000;
  o.cancel = &cancel;
  o.progress = [&](std::uint64_t done, std::uint64_t) {
    if (done >= 3 * 12 * 12) cancel.store(true);  // once the third pass is done
  };
  ASSERT_TRUE(scene.ok());
  ASSERT_TRUE(profile.ok());
  Result<RenderOutput> out = render(*scene, *profile, nullptr, o);
  ASSERT_TRUE(out.ok());
  EXPECT_FALSE(out->complete);
  // Passes run in chunks of kPassesPerChunk: the render stops after the chunk holding pass 3.
  const std::uint64_t done = (3 + kPassesPerChunk - 1) / kPassesPerChunk * kPassesPerChunk;
  EXPECT_EQ(out->spp_done, done);
  RunInfo info;
  Result<HistogramReport> rep = make_report(out->histogram, info, nullptr, {});
  ASSERT_TRUE(rep.ok());
  EXPECT_TRUE(std::isfinite(rep->total.std_error));
  EXPECT_EQ(out->histogram.total_samples(), done * 12 * 12);
}

TEST(Labels, PointLightWithPinholeOnlyProducesSDprefixAndDSsuffix) {
  Rendered r = render_json(closed_sphere_point(0.5, 1.0), "bdpt", {"LSD.*DSE"}, 8);
  ASSERT_FALSE(r.report.paths.empty());
  for (const PathEstimate& p : r.report.paths) {
    EXPECT_EQ(p.path.substr(0, 3), "LSD") << p.path;
    EXPECT_EQ(p.path.substr(p.path.size() - 3), "DSE") << p.path;
  }
  EXPECT_NEAR(r.report.classes[0].share, 1.0, 1e-12);
}

// Every connector the checker accepts the tracer runs: since issue 40's twelfth session the manifold
// connector at t = 1 too (its eye end a fresh pinhole or lens point), which a profile of its own
// runs alone, and bdpt+manifold lists.
TEST(Profiles, EveryConnectorTheCheckerAcceptsRuns) {
  Result<Profile> p = parse_profile(R"({"name": "lt+manifold", "strategies": [
      {"name": "splat-manifold", "s": "1..", "chain": "DS+D", "t": "1..", "connector": "manifold"}]})",
                                    "lt+manifold.json", Limits{});
  ASSERT_TRUE(p.ok()) << p.error().render();
  const StrategySet s = runnable_strategies(*p).expect("the manifold connector at t = 1");
  ASSERT_EQ(s.strategies.size(), 1u);
  EXPECT_TRUE(s.strategies[0].t.contains(1));
  const StrategySet bdpt = runnable_strategies(resolve_profile("bdpt+manifold", Limits{}).expect("built in")).expect("runs");
  EXPECT_TRUE(std::any_of(bdpt.strategies.begin(), bdpt.strategies.end(), [](const Strategy& st) {
    return st.connector == ConnectorKind::kManifold && st.t.contains(1) && !st.t.contains(2) && st.s.contains(1);
  }));
  for (const char* name : {"pt-nee+distant", "bdpt+ortho", "bdpt+mirror", "pt-nee+mirror", "pt-nee+manifold", "pbrt-v4-path",
                           "pbrt-v4-bdpt", "mitsuba3-path"})
    EXPECT_TRUE(runnable_strategies(resolve_profile(name, Limits{}).expect("a test input")).ok()) << name;
}

}  // namespace
}  // namespace pathex

namespace pathex {
namespace {

// --- samplers and Russian roulette (issue 19): every setting is unbiased ---

// Both samplers with the roulette settings worth having: the default (pbrt-v4's: every vertex
// from the third, survival = throughput), a low threshold (roulette only once a path carries
// less than a tenth), roulette from the second vertex, and none.
std::vector<Sampling> every_sampling() {
  std::vector<Sampling> out;
  // The default first (bdpt's eye and join thresholds `auto`: the pilot's, trace/accel/join_plan.h);
  // then the eye and light thresholds apart (issue 39) and together, and the roulette of bdpt's
  // joins at 0 (none), 1 and far above it (every join of an eye vertex past the first rouletted,
  // most of them skipped; the eye's `auto` beside it).
  const RenderOptions d;
  for (SamplerKind k : {SamplerKind::kIndependent, SamplerKind::kSobol})
    for (auto [depth, eye, light, join] : std::vector<std::tuple<int, float, float, float>>{
             {d.rr_depth, d.rr_threshold, d.rr_light_threshold, d.rr_join_threshold},
             {3, 0.1f, 0.1f, 0.0f},
             {2, 0.5f, 0.5f, 1.0f},
             {3, 0.0f, 0.0f, 0.0f},
             {3, 1.0f, 0.1f, 1.0f},
             {d.rr_depth, d.rr_threshold, d.rr_light_threshold, 8.0f}})
      out.push_back({k, depth, eye, light, join});
  return out;
}

// The closed forms of DESIGN §9 per bounce, for every sampler and roulette setting and the three
// estimators: 2 samplers x 6 roulette settings x 3 renderers x 9 classes = 324 checks (270 before
// issue 39's join roulette added the sixth), each render with a seed of its own.
//
// Each check is |z| <= kSigmas with z = (estimate - closed form) / sigma, sigma^2 = stderr^2 +
// (kRoundingFloor closed form)^2: the render's stderr, plus single-precision rounding for the
// classes a setting computes exactly (pt-nee without roulette, and its first bounces with it, by
// next-event estimation: their error is below 4e-8 of the value). The 12 x 12 sensor gets the
// default design, 16 pixel groups of two replicates, so z follows Student's t with 16 degrees of
// freedom, not the 31 of plain batch means that an earlier tolerance of 6 assumed: P(|t_16| > 6) =
// 1.9e-5, so the 270 checks failed a correct renderer at about 0.5 % of seeds, and issue 36's sweep
// of 100 seeds found 2 (seeds 76 and 80, lt's deepest class on the emitting sphere at -7.2 and
// -6.6). Over 400 seeds (108,000 checks at 64 spp) the deviates' tails are t_16's (beyond 4: 8.5e-4
// against 10.3e-4; beyond 5: 1.1e-4 against 1.3e-4; beyond 6: 1.9e-5 against 1.9e-5), except lt's
// deepest classes, whose roulette-thinned contributions are skewed: its four-bounce class on the
// emitting sphere had 8 of 2,930 below -4 where t_16 gives 1.5. Now kSigmas is family_sigmas over
// the checks made (Šidák, 0.1 % together at 16 dof: 6.88 for 270) and the renders take 256 spp,
// which halves that skew (2 of 1,987 below -4 where t_16 gives 1.0): over 197 seeds at 256 spp
// (53,000 checks) none beyond 6, the largest 5.6, no seed failed (76 and 80 among them).
// bench/README.md (issue 36, eleventh session) has the measurements and the command.
//
// What it catches: a bias every setting shares, beyond 1e-5 of the value, in the exactly computed
// classes (there is one for every bounce count); a bias of one setting alone beyond 6.9 of its best
// renderer's stderr (bdpt's, in the independent sampler at 256 spp: 0.01-0.3 % of the value up to
// two bounces, 0.2-0.6 % at three, 0.4-0.9 % at four).
//
// The settings' checks, each render at a seed of its own from `seed` on (test::stat_seed).
void expect_closed_forms(const std::vector<Sampling>& settings, std::uint64_t seed) {
  const double kSigmas = test::family_sigmas(static_cast<int>(settings.size()) * 3 * 9);
  constexpr std::uint64_t kSpp = 256;
  const double rho = 0.5, intensity = 2.0, le = 1.5;
  std::vector<std::string> point_classes, emitting_classes;
  for (int n = 1; n <= 4; ++n) point_classes.push_back("LSDD{" + std::to_string(n) + "}DSE");
  for (int n = 0; n <= 4; ++n) emitting_classes.push_back("LDDD{" + std::to_string(n) + "}DSE");
  const auto check = [&](const Estimate& e, double expected, const std::string& what) {
    const double z = (e.luminance - expected) / std::hypot(e.std_error, kRoundingFloor * expected);
    test::stat_log(what, z, kSigmas);
    EXPECT_LE(std::fabs(z), kSigmas) << what << ": estimate " << e.luminance << " ± " << e.std_error << ", expected "
                                     << expected << ", z = " << z;
  };
  for (const Sampling& sampling : settings)
    for (const char* renderer : {"pt-nee", "lt", "bdpt"}) {
      const std::string what = std::string(renderer) + ", " + sampling.name();
      Rendered p = render_json(closed_sphere_point(rho, intensity), renderer, point_classes, kSpp, 0, seed++, sampling);
      EXPECT_EQ(p.report.nonfinite_samples, 0u) << what;
      for (int n = 1; n <= 4; ++n)
        check(p.report.classes[static_cast<std::size_t>(n - 1)].estimate, std::pow(rho, n) * intensity / kPi,
              what + ", point light, n=" + std::to_string(n));
      Rendered e = render_json(closed_sphere_emitting(rho, le), renderer, emitting_classes, kSpp, 0, seed++, sampling);
      EXPECT_EQ(e.report.nonfinite_samples, 0u) << what;
      for (int n = 0; n <= 4; ++n)
        check(e.report.classes[static_cast<std::size_t>(n)].estimate, le * std::pow(rho, n),
              what + ", emitting sphere, n=" + std::to_string(n));
    }
}

TEST(Sampling, EverySamplerAndRouletteSettingMatchesTheClosedForms) {
  ASSERT_EQ(RenderOptions{}.rr_depth, every_sampling()[0].rr_depth);  // the default is the first setting
  ASSERT_EQ(RenderOptions{}.rr_threshold, every_sampling()[0].rr_threshold);
  ASSERT_EQ(RenderOptions{}.rr_light_threshold, every_sampling()[0].rr_light_threshold);
  ASSERT_EQ(RenderOptions{}.rr_join_threshold, every_sampling()[0].rr_join_threshold);
  expect_closed_forms(every_sampling(), test::stat_seed(7) * 1000);  // 7000, 7001, … one per render
}

// Issue 39: a sample split after its camera ray and first hit (--splits) is unbiased: 3 runs, and
// 4 (a power of two: each run's numbers are points i·4 + j of the pixel's sequence), both samplers,
// the three estimators, the same 9 closed forms: 108 checks, at family_sigmas(108) (6.37 at the
// default 16 dof, as above), which together fail a correct renderer at 0.1 % of seeds.
TEST(Sampling, SplitSamplesMatchTheClosedForms) {
  std::vector<Sampling> settings;
  for (SamplerKind k : {SamplerKind::kIndependent, SamplerKind::kSobol})
    for (int splits : {3, 4}) {
      Sampling s{k};
      s.splits = splits;
      settings.push_back(s);
    }
  expect_closed_forms(settings, test::stat_seed(13) * 1000);
}

// Issue 39: --splits auto (trace/accel/split_plan.h) is unbiased: its pilot's counts (on these
// uniform spheres every pixel takes the most runs per camera ray), and a map of counts that differ
// pixel by pixel, camera rays and runs (what the pilot gives a lamp's edge and the rest), both
// samplers, the three estimators, the same 9 closed forms: 108 checks at family_sigmas(108), 0.1 %
// family-wise (as above).
//
// The map's counts cycle with the pixel index p and with p / 16, so that each of the 16 pixel
// groups (pixel p's group is p mod 16: stats/histogram.h, batch_of) holds every count two or three
// times and the groups' variances are alike, which the 16 degrees of freedom of family_sigmas
// assume. An earlier map, counts[(x + 2y) mod 4] on this 12-wide sensor, aliased with p mod 16:
// half the groups held only {1, 1} and {1, 5}, half only {3, 1} and {2, 3}, whose variances differ
// 2-3 times, so the stderr had Satterthwaite's (Σ v_g)² / Σ v_g² ≈ 10 effective degrees of
// freedom, not 16, and issue 36's sweep failed at seed 70 (pt-nee, sobol, the emitting sphere's
// n = 4 at -6.56 against 6.37). Measured over 550 renders of that setting (bench/README.md, issue
// 36, fifteenth session): the relative spread of the squared stderr gave 9.8-12.4 dof with the
// old map and 14.7-17.4 with this one, the deviates' sd 1.10-1.15 and 1.04-1.07 (t16: 1.069).
TEST(Sampling, AutoSplitSamplesMatchTheClosedForms) {
  auto map = std::make_shared<tracer::SplitMap>(tracer::SplitMap{12, 12, {}});  // the closed spheres' 12 x 12
  const std::array<tracer::SplitCounts, 4> counts = {{{1, 1}, {3, 1}, {1, 5}, {2, 3}}};
  for (std::size_t p = 0; p < 12 * 12; ++p) map->counts.push_back(counts[(p + p / 16) % 4]);
  std::vector<Sampling> settings;
  for (SamplerKind k : {SamplerKind::kIndependent, SamplerKind::kSobol})
    for (bool given : {false, true}) {
      Sampling s{k};
      s.splits = 0;
      if (given) s.split_map = map;
      settings.push_back(s);
    }
  expect_closed_forms(settings, test::stat_seed(19) * 1000);
}

// The sample scenes, per class of the built-in set: each sampler and roulette setting agrees with
// the independent sampler under pbrt-v4's roulette (another seed) within k standard errors of the
// difference. The 7 x 10 x 5 checks (about 270 with an estimate) are many: k is family_sigmas over
// the checks made (Šidák, 0.1 % together), each at its difference's Welch–Satterthwaite degrees of
// freedom (two stderrs of 16 dof under the default 16 pixel groups give 16 to 32; the spot meter's
// 31 each). An earlier fixed 5.5 assumed more than 31 for every difference: about 0.1 % at 32, but
// 1.3 % where one stderr dominates (16 dof).
TEST(Sampling, EverySettingAgreesWithTheIndependentSamplerOnTheSampleScenes) {
  const std::vector<std::string> classes = {"L....E", "L.....E", "L......+E", "L..S+D.*..E", "L.*DD.*E"};
  const std::string dir = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/";
  const Sampling reference{SamplerKind::kIndependent, 3, 1.0f, 1.0f};
  const std::uint64_t seed = test::stat_seed(11);  // the reference's; every setting renders at seed + 1
  std::vector<test::Comparison> comparisons;
  for (const char* file : {"cornell.json", "point-glass.json", "point-mirror-caustic.json", "sun-window.json",
                           "laser.json", "mirror-ortho.json", "spotmeter-caustic.json"}) {
    const std::string renderer = std::string(file) == "sun-window.json"    ? "pt-nee+distant"
                                 : std::string(file) == "mirror-ortho.json" ? "bdpt+ortho"
                                                                            : "bdpt";
    const std::uint64_t spp = std::string(file) == "spotmeter-caustic.json" ? 2048 : 16;
    const Rendered base = render_scene(load_scene_file(dir + file), renderer, classes, spp, 0, seed, reference, 16);
    for (const Sampling& sampling : every_sampling()) {
      const Rendered r = render_scene(load_scene_file(dir + file), renderer, classes, spp, 0, seed + 1, sampling, 16);
      const std::string what = std::string(file) + ", " + renderer + ", " + sampling.name();
      EXPECT_EQ(r.report.nonfinite_samples, 0u) << what;
      for (std::size_t c = 0; c < classes.size(); ++c) {
        const Estimate& a = base.report.classes[c].estimate;
        const Estimate& b = r.report.classes[c].estimate;
        if (a.luminance == 0.0 && b.luminance == 0.0) continue;
        comparisons.push_back(test::compare(what + ", class " + classes[c] + ": the independent sampler against this", a, b));
      }
    }
  }
  EXPECT_GT(comparisons.size(), 250u);
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

// Issue 39: next-event estimation drawing a light's points by the solid angle it subtends
// (--light-sampling solid-angle: a rectangle's, Ureña et al. 2013, trace/spherical_rect.h; a
// sphere's cone, pbrt-v4) renders what area sampling renders: the sample Cornell box and Tungsten's
// (each lamp a one-sided rectangle) and the materials scene (a spherical lamp), for the renderers
// whose densities it changes (pt-nee: next-event estimation and the emitter hit's MIS; bdpt: every
// strategy through x0's and x1's densities; lt: the splat of the lamp itself). Every path string
// carrying more than 1 % of an image, and the image's total, by the one rule for comparing two
// renders' path estimates (tests/support/compare_estimates.h: Welch–Satterthwaite degrees of
// freedom, Šidák over every comparison, 0.1 % together; a path too sparse for its stderr is checked
// for being found). Comparing classes instead failed at seed 48 of issue 36's sweep: materials.json's
// one-bounce class under pt-nee holds the lamp seen in a specular surface (LDDSDSE, met by emitter
// hits alone: 103 samples), whose stderr read 4e-6 on a value of 0.0036 (its replicates tied) and
// took the class 5.9 σ from area sampling's (169 samples, 0.0029).
TEST(Sampling, SolidAngleLightSamplingAgreesWithAreaSampling) {
  const std::string root = std::string(PATHEX_SOURCE_DIR) + "/";
  const std::vector<std::string> scenes = {"samples/scenes/cornell.json", "bench/scenes/tungsten-cornell-box.json",
                                           "samples/scenes/materials.json"};
  const std::vector<std::string> renderers = {"pt-nee", "bdpt", "lt"};
  Sampling area, solid;
  area.light_sampling = LightSampling::kArea;
  solid.light_sampling = LightSampling::kSolidAngle;
  const std::uint64_t seed = test::stat_seed_from(41);
  std::vector<test::Comparison> comparisons;
  int sparse = 0;
  for (const std::string& file : scenes)
    for (const std::string& renderer : renderers) {
      const std::uint64_t spp = renderer == "lt" ? 32 : 16;
      const Rendered a = render_scene(load_scene_file(root + file), renderer, {"L.*E"}, spp, 0, seed, area, 16);
      const Rendered b = render_scene(load_scene_file(root + file), renderer, {"L.*E"}, spp, 0, seed + 1, solid, 16);
      const std::string what = file + ", " + renderer;
      EXPECT_EQ(b.report.nonfinite_samples, 0u) << what;
      sparse += test::compare_paths(a.report, b.report, 0.01, what + ": area against solid angle", &comparisons);
      comparisons.push_back(test::compare(what + ", total: area against solid angle", a.report.total, b.report.total));
    }
  EXPECT_GT(comparisons.size(), 40u);
  test::stat_log("paths found but too sparse to compare", sparse, static_cast<double>(comparisons.size()) / 4);
  EXPECT_LT(sparse, static_cast<int>(comparisons.size()) / 4) << "most comparisons must be of well-sampled paths";
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

// Issue 36: the reported standard error is the seed-to-seed spread under the default sampler too
// (sobol, whose batches are independently scrambled sequences; before, one sequence dealt over the
// batches made them correlated and the stderr 1.6–2.3× the spread on this scene). On the emitting
// sphere at kSeeds seeds: r² = mean over seeds of stderr² / the estimates' sample variance. For an
// honest stderr ln r² has standard deviation about sqrt(2/(S−1) + 2/(S(B−1))) (the spread's
// χ²_(S−1), the stderrs' B−1 degrees of freedom each): 0.18 at S = 64, B = the default; the test
// allows 4 of them (ln r within ±0.36: r in [0.70, 1.43]), a false failure about once in 16,000.
TEST(Sampling, SobolStandardErrorIsTheSpreadOverSeeds) {
  constexpr int kSeeds = 64;
  constexpr double kSigmas = 4.0;
  const int batches = RenderOptions{}.batches;
  ASSERT_EQ(RenderOptions{}.sampler, SamplerKind::kSobol);
  const double sd = std::sqrt(2.0 / (kSeeds - 1) + 2.0 / (kSeeds * (batches - 1)));
  const std::uint64_t seed0 = test::stat_seed(21) * 1000;
  for (const char* renderer : {"pt-nee", "bdpt"}) {
    double sum = 0, sum2 = 0, var = 0;
    for (int i = 0; i < kSeeds; ++i) {
      const Rendered r = render_json(closed_sphere_emitting(0.5, 1.5), renderer, {"L.*E"}, 32, 0, seed0 + static_cast<std::uint64_t>(i));
      sum += r.report.total.luminance;
      sum2 += r.report.total.luminance * r.report.total.luminance;
      var += r.report.total.std_error * r.report.total.std_error;
    }
    const double mean = sum / kSeeds, spread2 = (sum2 - kSeeds * mean * mean) / (kSeeds - 1);
    const double z = std::log(var / kSeeds / spread2) / sd;
    test::stat_log(std::string(renderer) + ", ln(stderr² / spread²) in its standard deviations", z, kSigmas);
    EXPECT_LE(std::fabs(z), kSigmas) << renderer << ": stderr / spread = " << std::sqrt(var / kSeeds / spread2) << " (z = " << z
                                     << ", 1 is honest)";
  }
}

// Issue 39: eye subpaths roulette below rr_threshold, light subpaths below rr_light_threshold, and
// neither threshold touches the other's walks: pt-nee (eye subpaths alone) is bit-identical whatever
// the light threshold, lt (light subpaths joined to the camera) whatever the eye threshold, and bdpt
// changes with either.
TEST(Sampling, EachRouletteThresholdActsOnItsOwnSubpaths) {
  const auto total = [](const char* renderer, float eye, float light) {
    const Sampling s{SamplerKind::kSobol, 2, eye, light};
    return render_json(closed_sphere_emitting(0.8, 1.5), renderer, {"L.*E"}, 8, 1, 5, s).report.total;
  };
  const Estimate pt = total("pt-nee", 0.3f, 1.0f), pt_light = total("pt-nee", 0.3f, 0.05f);
  EXPECT_EQ(pt.rgb, pt_light.rgb);
  EXPECT_EQ(pt.std_error, pt_light.std_error);
  const Estimate lt = total("lt", 0.3f, 1.0f), lt_eye = total("lt", 0.05f, 1.0f);
  EXPECT_EQ(lt.rgb, lt_eye.rgb);
  EXPECT_EQ(lt.std_error, lt_eye.std_error);
  EXPECT_FALSE(total("pt-nee", 0.05f, 1.0f).rgb == pt.rgb);
  EXPECT_FALSE(total("lt", 0.3f, 0.05f).rgb == lt.rgb);
  const Estimate bd = total("bdpt", 0.3f, 1.0f);
  EXPECT_FALSE(total("bdpt", 0.05f, 1.0f).rgb == bd.rgb);
  EXPECT_FALSE(total("bdpt", 0.3f, 0.05f).rgb == bd.rgb);
}

// Bit-identical for one and two threads with either sampler.
TEST(Sampling, EachSamplerIsTheSameForOneAndTwoThreads) {
  for (SamplerKind k : {SamplerKind::kIndependent, SamplerKind::kSobol}) {
    const Sampling sampling{k, RenderOptions{}.rr_depth, RenderOptions{}.rr_threshold};
    Rendered a = render_json(closed_sphere_point(0.5, 1.0), "bdpt", {"LSDDDSE"}, 8, 1, 7, sampling);
    Rendered b = render_json(closed_sphere_point(0.5, 1.0), "bdpt", {"LSDDDSE"}, 8, 2, 7, sampling);
    EXPECT_EQ(a.report.total.rgb, b.report.total.rgb) << to_string(k);
    EXPECT_EQ(a.report.total.std_error, b.report.total.std_error) << to_string(k);
    ASSERT_EQ(a.report.paths.size(), b.report.paths.size()) << to_string(k);
    for (std::size_t i = 0; i < a.report.paths.size(); ++i) {
      EXPECT_EQ(a.report.paths[i].path, b.report.paths[i].path);
      EXPECT_EQ(a.report.paths[i].estimate.rgb, b.report.paths[i].estimate.rgb);
    }
    const std::vector<ImageLayer> la = a.out.images.layers(1.0), lb = b.out.images.layers(1.0);
    ASSERT_EQ(la.size(), lb.size());
    for (std::size_t i = 0; i < la.size(); ++i) EXPECT_EQ(la[i].image.rgb, lb[i].image.rgb) << to_string(k);
  }
}

// --- pbrt-v4's coateddiffuse (trace/bsdf_layered.h) in the tracer ---

std::string coated_furnace_scene(const std::string& coat) {
  return R"({"camera": {"type": "pinhole", "position": [0, 0, -3], "look_at": [0, 0, 0], "up": [0, 1, 0],
                         "fov": 20, "width": 6, "height": 6},
    "materials": {"ball": )" + coat + R"(},
    "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"}],
    "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})";
}

// The white furnace with a coat (issue 35): a unit sphere of coateddiffuse, reflectance 1,
// albedo 0, under a uniform sky of radiance 1, max depth 64, must lose what pbrt-v4 loses, since
// an imported scene should render as pbrt renders it. pbrt-v4 (5f7a606, CPU, 1,024 spp, RGB
// means): 0.963 with a smooth coat and maxdepth 200, 0.765 with roughness 0.3 (alpha √0.3) and the
// same maxdepth. Those are image means over a frame in which the sky shows around the sphere: the
// sphere alone averages 0.920 and 0.485 here (the slab's exp(−thickness / |cos θ|) at each crossing,
// and for the rough coat its single-scattering microfacets, lose the rest), and both figures are
// met by one camera, pbrt's customary "LookAt 0 0 5 ... fov 30", where the sphere covers 45.6 % of
// the frame: 0.456 · 0.920 + 0.544 = 0.964 and 0.456 · 0.485 + 0.544 = 0.765. That camera here.
// Within 1.5 % (pbrt renders spectrally, pathex in RGB) plus 3 standard errors, for pt, pt-nee and
// bdpt (a smooth coat's reflection is S: `lt` cannot splat it to a pinhole).
TEST(ClosedForm, CoatedDiffuseWhiteFurnaceLosesWhatPbrtLoses) {
  const double kSigmas = test::family_sigmas(6);  // 6 checks, 0.1 % together
  struct Case {
    const char* coat;
    double pbrt;
  };
  const Case cases[] = {
      {R"({"type": "coateddiffuse", "reflectance": [1, 1, 1], "max_depth": 200})", 0.963},
      {R"({"type": "coateddiffuse", "reflectance": [1, 1, 1], "roughness": 0.5477226, "max_depth": 200})", 0.765},
  };
  for (const Case& c : cases) {
    const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 0, 5], "look_at": [0, 0, 0], "up": [0, 1, 0],
                                    "fov": 30, "width": 16, "height": 16},
      "materials": {"ball": )" + std::string(c.coat) + R"(},
      "shapes": [{"type": "sphere", "center": [0, 0, 0], "radius": 1, "material": "ball"}],
      "lights": [{"type": "environment", "radiance": [1, 1, 1]}]})";
    for (const char* renderer : {"pt", "pt-nee", "bdpt"}) {
      Rendered r = render_scene(load_scene_json(scene, ".", "test"), renderer, {"L.*E"}, 64, 0, test::stat_seed_from(7), {}, 64);
      EXPECT_EQ(r.report.nonfinite_samples, 0u);
      test::stat_log(std::string("coated furnace ") + renderer + " " + c.coat, r.report.classes[0].estimate.luminance, c.pbrt);
      expect_close(r.report.classes[0].estimate, c.pbrt, kSigmas, 0.015, std::string(renderer) + " coated furnace " + c.coat);
    }
  }
}

// The image mean of the coat's reflectance R(θ) (index 1.5) over coated_furnace_scene's film, which
// the sphere fills (radius 1 at distance 3, half-angle 10°): a midpoint sum over the film plane.
double coat_reflection_image_mean() {
  const double t = std::tan(10.0 * kPi / 180.0);
  const glm::dvec3 o(0, 0, -3);
  const int n = 400;
  double sum = 0.0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const glm::dvec3 d = glm::normalize(glm::dvec3((2.0 * (i + 0.5) / n - 1.0) * t, (2.0 * (j + 0.5) / n - 1.0) * t, 1.0));
      const double b = glm::dot(o, d), c = glm::dot(o, o) - 1.0;
      const glm::dvec3 normal = o + (-b - std::sqrt(b * b - c)) * d;
      sum += fresnel_dielectric(static_cast<float>(-glm::dot(d, normal)), 1.5f);
    }
  return sum / (static_cast<double>(n) * n);
}

// The same sphere in the same sky, classified: the smooth coat's reflection is an S vertex (class
// L DD S DS E, which is R(θ) at each pixel: the sky is 1 everywhere) and what passed the coat is D
// (L DD D DS E); nothing else. A rough coat gives no S.
TEST(Letters, ASmoothCoatReflectsAsSAndItsDiffuseLobeIsD) {
  for (const bool smooth : {true, false}) {
    const std::string coat = smooth ? R"({"type": "coateddiffuse", "reflectance": [0.5, 0.5, 0.5]})"
                                    : R"({"type": "coateddiffuse", "reflectance": [0.5, 0.5, 0.5], "roughness": 0.3})";
    // 512 spp: the S class is a rare event (R ≈ 0.04 of the samples), Poisson-like at 64 spp (1 in 100
    // seeds then fell 4.8σ short); at 512 its batch means are near normal.
    Rendered r = render_json(coated_furnace_scene(coat), "pt", {"LDDSDSE", "LDDDDSE", "L.*E"}, 512);
    const Estimate& s = r.report.classes[0].estimate;
    const Estimate& d = r.report.classes[1].estimate;
    const Estimate& all = r.report.classes[2].estimate;
    if (smooth) {
      // R(θ) at each pixel: its image mean (about 0.042; R is 0.04 at normal incidence).
      test::expect_close(s, coat_reflection_image_mean(), test::family_sigmas(1), 1e-4, "the smooth coat's reflection");
    } else {
      EXPECT_EQ(s.samples, 0u);
      EXPECT_EQ(s.luminance, 0.0);
    }
    EXPECT_GT(d.luminance, 0.2);
    // The two classes are all there is: every path is L DD ? DS E, one bounce.
    EXPECT_NEAR(s.luminance + d.luminance, all.luminance, 1e-9 + 1e-9 * all.luminance);
  }
}

// Estimators agree on a coated sphere (a smooth and a rough coat, a scattering slab) lit by a
// sphere light above it and standing on a diffuse floor: pt-nee, lt and bdpt reach the paths
// whose visible vertex is D (class L .* D DS E, pinhole) through different densities, so a pdf()
// that disagreed with sample(), or an eval() that disagreed with either, would show here.
//
// Pairwise per path of the class by the shared comparison rule (tests/support/compare_estimates.h,
// 0.1 % together over every comparison), each render at a seed of its own. Not the class as one
// number: under the smooth coat it holds LDDSDDSE, the lamp reflected by the coat onto the floor,
// which pt-nee meets only when a floor point's sampled direction hits the lamp through the coat
// (about 20 samples at 1,024 spp; bdpt's light tracing about 50): a heavy tail that carries 1 %
// of the class and most of its stderr, so a draw with few such hits read low with a small stderr
// (issue 36's sweep, seed 62: pt-nee 0.022085 ± 0.000030 against bdpt's 0.022376 ± 0.000050,
// 5.0σ; over 40 seeds through the CLI the three agree: 0.022379 ± 0.000017, 0.022384 ± 0.000079,
// 0.022355 ± 0.000012). Such a path is checked for being found. (The renders shared one seed
// before, which correlated pt-nee's camera paths with bdpt's and hid it.)
TEST(Estimators, AgreeOnACoatedSphere) {
  const std::array<const char*, 3> renderers = {"pt-nee", "lt", "bdpt"};
  std::uint64_t seed = test::stat_seed_from(7);
  std::vector<test::Comparison> comparisons;
  int sparse = 0;
  const char* coats[] = {
      R"({"type": "coateddiffuse", "reflectance": [0.7, 0.5, 0.3]})",
      R"({"type": "coateddiffuse", "reflectance": [0.7, 0.5, 0.3], "roughness": 0.3, "albedo": [0.8, 0.8, 0.8], "thickness": 0.2, "g": 0.3})",
  };
  for (const char* coat : coats) {
    const std::string scene = R"({"camera": {"type": "pinhole", "position": [0, 1, -4], "look_at": [0, 0.6, 0], "up": [0, 1, 0],
                                    "fov": 40, "width": 8, "height": 8},
      "materials": {"ball": )" + std::string(coat) + R"(, "floor": {"type": "diffuse", "albedo": [0.6, 0.6, 0.6]},
                    "lamp": {"type": "diffuse", "albedo": [0, 0, 0]}},
      "shapes": [{"type": "sphere", "center": [0, 0.8, 0], "radius": 0.8, "material": "ball"},
                 {"type": "quad", "corner": [-5, 0, -5], "edge1": [10, 0, 0], "edge2": [0, 0, 10], "material": "floor"},
                 {"type": "sphere", "center": [1.2, 3, -0.5], "radius": 0.4, "material": "lamp", "emission": [8, 8, 8]}],
      "lights": []})";
    std::vector<HistogramReport> reports;  // each the class's paths alone, its total the class's
    for (const char* renderer : renderers) {
      Rendered r = render_scene(load_scene_json(scene, ".", "test"), renderer, {"L.*DDSE"}, 1024, 0, seed++, {}, 64);
      EXPECT_EQ(r.report.nonfinite_samples, 0u) << renderer;
      HistogramReport c = r.report;
      std::erase_if(c.paths, [](const PathEstimate& p) { return !p.path.ends_with("DDSE"); });
      c.total = r.report.classes[0].estimate;
      EXPECT_GT(c.total.luminance, 0.0) << renderer;
      reports.push_back(std::move(c));
    }
    for (std::size_t i = 0; i < reports.size(); ++i)
      for (std::size_t j = i + 1; j < reports.size(); ++j)
        sparse += test::compare_paths(reports[i], reports[j], 0.005,
                                      std::string(coat) + ", " + renderers[i] + " against " + renderers[j], &comparisons);
  }
  // At the fixed seed 14 compared and 7 sparse (the smooth coat's caustic, and lt's deepest
  // paths); every pair compares the two largest paths, LDDDDSE and LDDDDDSE (95 % of the class).
  EXPECT_GE(comparisons.size(), 12u) << sparse << " sparse";
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

}  // namespace
}  // namespace pathex
