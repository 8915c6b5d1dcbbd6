// Scene import (pbrt-v4 .pbrt, Mitsuba 3 .xml): the exported Cornell boxes give the JSON scene's
// model and image (cornell.pbrt's mirror as pbrt-v4 states it, a conductor; per well-sampled path
// string within the family-wise tolerance of their stderrs, per pixel within 3 standard errors
// of the run-to-run spread), each format's conventions (handedness, field of view, light units)
// give exact values, and everything outside the subset is refused with its file, line, column
// and an exact message, by the library and by the CLI (exit 2).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>

#include "stats/histogram.h"
#include "io/profile_json.h"
#include "optics/internal_reflectance.h"
#include "scene/scene.h"
#include "trace/bsdf_layered.h"
#include "support/cli_run.h"
#include "support/load_scene.h"
#include "support/scratch_files.h"
#include "support/compare_estimates.h"
#include "support/stat_seed.h"
#include "trace/render.h"

namespace pathex {
namespace {

const std::string kDir = PATHEX_SOURCE_DIR;
const std::string kScenes = kDir + "/samples/scenes/";

using test::relative;
using test::scratch;
using test::write;

using test::load;

void expect_near(glm::vec3 a, glm::vec3 b, const std::string& what) {
  EXPECT_LT(glm::length(a - b), 1e-5f) << what << ": (" << a.x << ", " << a.y << ", " << a.z << ") vs (" << b.x << ", " << b.y
                                        << ", " << b.z << ")";
}

// --- the exported Cornell boxes: the same model ---

TEST(ImportCornell, SameCameraLightsAndTypesAsTheJsonScene) {
  const Scene json = load(kScenes + "cornell.json");
  for (const char* file : {"cornell.pbrt", "cornell.xml"}) {
    const Scene s = load(kScenes + file);
    SCOPED_TRACE(file);
    EXPECT_EQ(describe(scene_types(s)), describe(scene_types(json)));
    expect_near(s.camera.position, json.camera.position, "position");
    expect_near(glm::normalize(s.camera.look_at - s.camera.position), glm::normalize(json.camera.look_at - json.camera.position), "forward");
    expect_near(s.camera.up, json.camera.up, "up");
    EXPECT_NEAR(s.camera.fov_degrees, json.camera.fov_degrees, 1e-4);
    EXPECT_EQ(s.camera.width, 64);
    EXPECT_EQ(s.camera.height, 64);
    int emitters = 0;
    for (const Shape& shape : s.shapes) {
      if (!shape.emissive()) continue;
      ++emitters;
      expect_near(shape.emission, glm::vec3(17, 15, 12), "emission");
      EXPECT_FALSE(shape.two_sided);
      const QuadShape* q = std::get_if<QuadShape>(&shape.geometry);
      ASSERT_NE(q, nullptr);
      expect_near(glm::normalize(glm::cross(q->edge1, q->edge2)), glm::vec3(0, -1, 0), "the lamp faces down");
      expect_near(q->corner + 0.5f * (q->edge1 + q->edge2), glm::vec3(0, 1.98f, 0), "the lamp's centre");
    }
    EXPECT_EQ(emitters, 1);
    EXPECT_EQ(s.shapes.size(), json.shapes.size());
  }
}

// Renders `scene` at 16 x 16 with `seed`; returns the report and the total image's luminance.
struct Rendered {
  HistogramReport report;
  std::vector<double> luminance;
};
Rendered render_small(Scene scene, std::uint64_t seed, std::uint64_t spp) {
  scene.camera.width = scene.camera.height = 16;
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.threads = 2;
  o.max_bounces = 6;
  const Profile profile = resolve_profile("pt-nee", Limits{}).expect("a test input");
  Result<RenderOutput> out = render(scene, profile, nullptr, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  RunInfo info;
  info.spp = spp;
  Rendered r{make_report(out->histogram, info, nullptr, {}).expect("a test input"), {}};
  const ImageLayer total = out->images.layer(0, 1.0 / static_cast<double>(spp));
  for (int y = 0; y < 16; ++y)
    for (int x = 0; x < 16; ++x)
      r.luminance.push_back(0.2126 * total.image.at(x, y, 0) + 0.7152 * total.image.at(x, y, 1) + 0.0722 * total.image.at(x, y, 2));
  return r;
}

// The two-sided probability that Student's t with `dof` degrees of freedom exceeds |t| = 3
// (numerical integration of its density; dof >= 2).
double t_tail_beyond_3(double dof) {
  const double c = std::exp(std::lgamma((dof + 1) / 2) - std::lgamma(dof / 2)) / std::sqrt(dof * M_PI);
  double inside = 0;
  const int n = 6000;
  for (int i = 0; i < n; ++i) {
    const double t = 3.0 * (i + 0.5) / n;
    inside += c * std::pow(1 + t * t / dof, -(dof + 1) / 2) * (3.0 / n);
  }
  return 1.0 - 2.0 * inside;
}

// Per-pixel luminance over kRuns independent renders (seeds first_seed, first_seed + 1, ...).
constexpr int kRuns = 8;
constexpr std::uint64_t kSpp = 16;
struct PixelStats {
  std::vector<double> mean, var;
};
PixelStats pixel_stats(const Scene& s, std::uint64_t first_seed) {
  std::vector<std::vector<double>> runs;
  for (int i = 0; i < kRuns; ++i) {
    Rendered r = render_small(s, first_seed + static_cast<std::uint64_t>(i), kSpp);
    EXPECT_EQ(r.report.nonfinite_samples, 0u);
    runs.push_back(std::move(r.luminance));
  }
  PixelStats st{std::vector<double>(runs[0].size(), 0.0), std::vector<double>(runs[0].size(), 0.0)};
  for (const auto& run : runs)
    for (std::size_t p = 0; p < run.size(); ++p) st.mean[p] += run[p] / kRuns;
  for (const auto& run : runs)
    for (std::size_t p = 0; p < run.size(); ++p) st.var[p] += (run[p] - st.mean[p]) * (run[p] - st.mean[p]) / (kRuns - 1);
  return st;
}

// Welch's t per pixel; the images agree when |t| > 3 happens no more often than chance allows
// for that many pixels, plus 3 standard deviations of that count (binomial). Pixels that are
// exactly constant in both (they see only the lamp) must be equal.
struct PixelVerdict {
  int beyond = 0, lit = 0, unequal_constant = 0;
  double bound = 0;
  bool agree() const { return unequal_constant == 0 && beyond <= bound; }
};
PixelVerdict compare_pixels(const PixelStats& a, const PixelStats& b) {
  PixelVerdict v;
  for (std::size_t p = 0; p < a.mean.size(); ++p) {
    const double se = std::sqrt(a.var[p] / kRuns + b.var[p] / kRuns);
    if (!(se > 0)) {
      v.unequal_constant += a.mean[p] != b.mean[p] ? 1 : 0;
      continue;
    }
    ++v.lit;
    v.beyond += std::fabs(a.mean[p] - b.mean[p]) / se > 3.0 ? 1 : 0;
  }
  const double p = t_tail_beyond_3(kRuns - 1);  // the fewest degrees of freedom Welch's t can have: conservative
  v.bound = v.lit * p + 3 * std::sqrt(v.lit * p * (1 - p));
  return v;
}

// cornell.json as pbrt-v4 can state it: pbrt-v4 has no mirror of constant reflectance, so
// cornell.pbrt's "mirror" is a smooth conductor of reflectance 0.95 at normal incidence (eta 1,
// k = 2 sqrt(r / (1 - r)): include/cornell-materials.pbrt), whose Fresnel dips below 0.95 towards
// grazing before it rises to 1 — the paths through the mirror ball differ by ~0.8 % (LDDDSDSE at
// 32 x 32, 2,048 spp: 0.004443 against the constant mirror's 0.004480, 26 σ). Mitsuba's conductor
// of material "none" is exactly pathex's mirror, so cornell.xml is compared with cornell.json as is.
Scene as_pbrt_states_it(Scene json) {
  for (Material& m : json.materials)
    if (const auto* mirror = std::get_if<Mirror>(&m)) {
      const glm::vec3 r = mirror->reflectance;
      Conductor c;
      c.eta = glm::vec3(1.0f);
      c.k = 2.0f * glm::sqrt(r / (1.0f - r));
      m = c;
    }
  return json;
}

TEST(ImportCornell, ImagesMatchTheJsonSceneWithin3Sigma) {
  const Scene json = load(kScenes + "cornell.json");
  const std::uint64_t base = test::stat_seed(0);  // the seeds below, offset (PATHEX_STAT_SEED)
  std::uint64_t seed = base + 100;
  for (const char* file : {"cornell.pbrt", "cornell.xml"}) {
    SCOPED_TRACE(file);
    const Scene scene = load(kScenes + file);
    const bool pbrt = std::string(file) == "cornell.pbrt";
    const Scene want = pbrt ? as_pbrt_states_it(json) : json;
    if (pbrt) {  // the import's mirror is that conductor
      const auto mirror = std::find(scene.material_names.begin(), scene.material_names.end(), "mirror");
      ASSERT_NE(mirror, scene.material_names.end());
      const auto* c = std::get_if<Conductor>(&scene.materials[static_cast<std::size_t>(mirror - scene.material_names.begin())]);
      ASSERT_NE(c, nullptr);
      expect_near(c->eta, glm::vec3(1.0f), "the mirror's eta");
      expect_near(c->k, glm::vec3(2.0f * std::sqrt(0.95f / 0.05f)), "the mirror's k");
      EXPECT_TRUE(c->smooth());
    }
    const PixelStats ref = pixel_stats(want, base + 1);
    const HistogramReport ref_report = render_small(want, base + 1000, kSpp * kRuns).report;
    const PixelStats got = pixel_stats(scene, seed);
    const HistogramReport report = render_small(scene, seed + 1000, kSpp * kRuns).report;
    seed += 100;
    // --- per path string: every string carrying more than 0.5 % of the JSON image, and the total,
    // by their batch-means stderrs (tests/support/compare_estimates.h: a path with too few samples
    // or degrees of freedom for its stderr to mean anything — the lamp seen directly, whose stderr
    // under sobol is at times 0; a caustic pt-nee meets by chance — is checked for being found).
    // The tolerance holds the family of these checks to a 0.1 % false-failure rate. ---
    std::vector<test::Comparison> comparisons;
    const int sparse = test::compare_paths(ref_report, report, 0.005, std::string(file) + ": JSON against the import", &comparisons);
    // At the fixed seed 9 compared and 4 found but sparse (the caustics through the spheres that
    // pt-nee meets by chance: about 100 samples, 2 to 4 degrees of freedom; the lamp seen directly).
    EXPECT_GE(comparisons.size(), 5u);
    EXPECT_GE(comparisons.size(), static_cast<std::size_t>(sparse)) << "most paths must be well sampled";
    comparisons.push_back(test::compare(std::string(file) + " total: JSON against the import", ref_report.total, report.total));
    for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
    // --- per pixel ---
    const PixelVerdict v = compare_pixels(got, ref);
    EXPECT_TRUE(v.agree()) << v.beyond << " of " << v.lit << " pixels beyond 3 sigma (at most " << v.bound << " by chance), "
                           << v.unequal_constant << " constant pixels differ";
    EXPECT_GE(v.lit, 200);
  }
}

// The per-pixel statistic can fail: the box mirrored left-right (the red wall on the right, as
// pbrt shows cornell.pbrt without its Scale -1 1 1) is told apart from the JSON scene.
TEST(ImportCornell, AMirroredBoxFailsThePixelTest) {
  const Scene json = load(kScenes + "cornell.json");
  Scene mirrored = json;
  for (Shape& s : mirrored.shapes) {
    if (auto* q = std::get_if<QuadShape>(&s.geometry)) {
      q->corner.x = -q->corner.x;
      q->edge1.x = -q->edge1.x;
      q->edge2.x = -q->edge2.x;
      std::swap(q->edge1, q->edge2);
    } else if (auto* sp = std::get_if<SphereShape>(&s.geometry)) {
      sp->center.x = -sp->center.x;
    }
  }
  const PixelVerdict v = compare_pixels(pixel_stats(mirrored, 1), pixel_stats(json, 100));
  EXPECT_FALSE(v.agree());
  EXPECT_GT(v.beyond, 2 * v.bound);
}

// --- each format's conventions ---

TEST(ImportPbrt, LookAtWithoutAMirroringScaleShowsTheWorldMirrored) {
  // pbrt's image right is up x forward: looking down -z with y up, world +x is on the image's left.
  const std::string head = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 30\n"
                           "Film \"rgb\" \"integer xresolution\" 32 \"integer yresolution\" 32\nWorldBegin\n"
                           "LightSource \"point\" \"point3 from\" [1 0 0] \"rgb I\" [1 2 3] \"float scale\" 2\n"
                           "Shape \"sphere\" \"float radius\" 0.5\n";
  const Scene plain = load(write("lookat.pbrt", head));
  ASSERT_EQ(plain.lights.size(), 1u);
  const auto& p = std::get<PointLight>(plain.lights[0]);
  expect_near(p.position, glm::vec3(-1, 0, 0), "mirrored through the camera's vertical plane");
  expect_near(p.intensity, glm::vec3(2, 4, 6), "I times scale");
  const Scene flipped = load(write("lookat-scale.pbrt", "Scale -1 1 1\n" + head));
  expect_near(std::get<PointLight>(flipped.lights[0]).position, glm::vec3(1, 0, 0), "with Scale -1 1 1 nothing is mirrored");
  expect_near(flipped.camera.position, glm::vec3(0, 0, 5), "camera");
}

TEST(ImportPbrt, TransformsAttributeScopesAndOrientation) {
  const Scene s = load(write("transforms.pbrt",
                             "Scale -1 1 1\nLookAt 0 0 9  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\"\n"
                             "AttributeBegin\n  Translate 1 2 3\n  Rotate 90 1 0 0\n  Shape \"disk\" \"float radius\" 0.5\nAttributeEnd\n"
                             "Shape \"sphere\" \"float radius\" 0.5\n"
                             "ConcatTransform [2 0 0 0  0 2 0 0  0 0 2 0  1 0 0 1]\n"
                             "AttributeBegin\n  ReverseOrientation\n  AreaLightSource \"diffuse\" \"rgb L\" [1 2 3]\n"
                             "  Shape \"bilinearmesh\" \"point3 P\" [0 0 0  1 0 0  0 1 0  1 1 0]\nAttributeEnd\n"
                             "Shape \"sphere\"\n"));
  ASSERT_EQ(s.shapes.size(), 4u);
  const auto& disk = std::get<DiskShape>(s.shapes[0].geometry);
  expect_near(disk.center, glm::vec3(1, 2, 3), "Translate");
  expect_near(disk.normal, glm::vec3(0, -1, 0), "Rotate 90 about x takes +z to -y");
  expect_near(std::get<SphereShape>(s.shapes[1].geometry).center, glm::vec3(0), "AttributeEnd restores the transform");
  const auto& quad = std::get<QuadShape>(s.shapes[2].geometry);
  expect_near(quad.corner, glm::vec3(1, 0, 0), "ConcatTransform lists the matrix column by column");
  expect_near(glm::cross(quad.edge1, quad.edge2), glm::vec3(0, 0, -4), "ReverseOrientation turns the front to -z");
  expect_near(s.shapes[2].emission, glm::vec3(1, 2, 3), "the area light");
  EXPECT_FALSE(s.shapes[3].emissive()) << "AttributeEnd ends the area light";
  const auto& sphere = std::get<SphereShape>(s.shapes[3].geometry);
  expect_near(sphere.center, glm::vec3(1, 0, 0), "the transform outlives the attribute block");
  EXPECT_FLOAT_EQ(sphere.radius, 2.0f);
}

TEST(ImportMitsuba, TransformOperationsApplyInOrder) {
  const Scene s = load(write("order.xml",
                             "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/>"
                             "<transform name=\"to_world\"><lookat origin=\"0, 0, 9\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>"
                             "<emitter type=\"point\"/>"
                             "<shape type=\"sphere\"><transform name=\"to_world\"><scale value=\"2\"/><translate x=\"1\"/></transform></shape>"
                             "<shape type=\"sphere\"><transform name=\"to_world\"><matrix value=\"1 0 0 5  0 1 0 0  0 0 1 0  0 0 0 1\"/></transform></shape>"
                             "</scene>"));
  ASSERT_EQ(s.shapes.size(), 2u);
  const auto& a = std::get<SphereShape>(s.shapes[0].geometry);
  expect_near(a.center, glm::vec3(1, 0, 0), "scale, then translate");
  EXPECT_FLOAT_EQ(a.radius, 2.0f);
  expect_near(std::get<SphereShape>(s.shapes[1].geometry).center, glm::vec3(5, 0, 0), "matrix is row by row");
}

TEST(ImportPbrt, FovIsTheShorterImageAxis) {
  auto fov = [](int w, int h) {
    const std::string text = "LookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nFilm \"rgb\" \"integer xresolution\" " +
                             std::to_string(w) + " \"integer yresolution\" " + std::to_string(h) +
                             "\nWorldBegin\nLightSource \"point\"\nShape \"sphere\"\n";
    return load(write("fov.pbrt", text)).camera.fov_degrees;
  };
  EXPECT_NEAR(fov(128, 64), 40.0, 1e-4);  // landscape: the vertical axis is the shorter
  EXPECT_NEAR(fov(64, 128), glm::degrees(2 * std::atan(2 * std::tan(glm::radians(20.0)))), 1e-3);
}

TEST(ImportPbrt, DistantLightCoversTheSceneWithItsIrradiance) {
  const Scene s = load(write("distant.pbrt",
                             "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                             "LightSource \"distant\" \"point3 from\" [0 10 0] \"point3 to\" [0 0 0] \"rgb L\" [3 3 3] \"float scale\" 0.5\n"
                             "Translate 2 0 0\nShape \"sphere\"\n"));
  ASSERT_EQ(s.lights.size(), 1u);
  const auto& d = std::get<DistantLight>(s.lights[0]);
  expect_near(d.direction, glm::vec3(0, -1, 0), "travels from 'from' to 'to'");
  expect_near(d.irradiance, glm::vec3(1.5f), "L times scale is the irradiance");
  // The aperture lies above the sphere (centre (2, 0, 0), radius 1) and covers its shadow.
  const glm::vec3 lo = glm::min(d.aperture_corner, d.aperture_corner + d.aperture_edge1 + d.aperture_edge2);
  const glm::vec3 hi = glm::max(d.aperture_corner, d.aperture_corner + d.aperture_edge1 + d.aperture_edge2);
  EXPECT_GT(lo.y, 1.0f);
  EXPECT_LT(lo.x, 1.0f);
  EXPECT_GT(hi.x, 3.0f);
  EXPECT_LT(lo.z, -1.0f);
  EXPECT_GT(hi.z, 1.0f);
}

TEST(ImportPbrt, MaterialsMapOntoPathexKinds) {
  const Scene s = load(write("materials.pbrt",
                             "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\"\n"
                             "MakeNamedMaterial \"d\" \"string type\" \"diffuse\" \"rgb reflectance\" [0.2 0.4 0.6]\n"
                             "MakeNamedMaterial \"g\" \"string type\" \"conductor\" \"rgb reflectance\" [0.9 0.9 0.9] \"float roughness\" 0.04\n"
                             "MakeNamedMaterial \"m\" \"string type\" \"mix\" \"string materials\" [\"d\" \"g\"] \"float amount\" 0.25\n"
                             "NamedMaterial \"m\"\nShape \"sphere\"\n"
                             "Material \"conductor\" \"rgb eta\" [2 2 2] \"rgb k\" [0 0 0]\nShape \"disk\" \"float height\" -1\n"));
  ASSERT_EQ(s.shapes.size(), 2u);
  const auto& mix = std::get<Mixture>(s.materials[static_cast<std::size_t>(s.shapes[0].material)]);
  ASSERT_EQ(mix.components.size(), 2u);
  EXPECT_FLOAT_EQ(mix.components[0].weight, 0.75f);
  expect_near(std::get<Diffuse>(mix.components[0].material).albedo, glm::vec3(0.2f, 0.4f, 0.6f), "diffuse");
  EXPECT_FLOAT_EQ(mix.components[1].weight, 0.25f);
  const auto& rough = std::get<Conductor>(mix.components[1].material);
  EXPECT_FLOAT_EQ(rough.alpha_u, 0.2f);  // alpha = sqrt(roughness)
  EXPECT_FLOAT_EQ(rough.alpha_v, 0.2f);
  expect_near(rough.eta, glm::vec3(1.0f), "reflectance: eta 1");
  expect_near(rough.k, glm::vec3(2.0f * std::sqrt(0.9f / 0.1f)), "reflectance: k = 2 sqrt(r / (1 - r))");
  const auto& smooth = std::get<Conductor>(s.materials[static_cast<std::size_t>(s.shapes[1].material)]);
  EXPECT_TRUE(smooth.smooth());
  expect_near(smooth.eta, glm::vec3(2.0f), "eta");
  expect_near(smooth.k, glm::vec3(0.0f), "k");
}

TEST(ImportMitsuba, FovAxisAndOrthographicFilm) {
  auto camera = [](const std::string& sensor) {
    return load(write("sensor.xml", "<scene version=\"3.0.0\">" + sensor +
                                        "<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"3\" z=\"0\"/></emitter>"
                                        "<shape type=\"sphere\"/></scene>"))
        .camera;
  };
  const std::string film = "<film type=\"hdrfilm\"><integer name=\"width\" value=\"128\"/><integer name=\"height\" value=\"64\"/></film>";
  const std::string look = "<transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>";
  const double t = std::tan(glm::radians(20.0));
  EXPECT_NEAR(camera("<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>" + look + film + "</sensor>").fov_degrees,
              glm::degrees(2 * std::atan(t / 2)), 1e-3);  // fov_axis x by default
  EXPECT_NEAR(camera("<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"y\"/>" + look + film +
                     "</sensor>")
                  .fov_degrees,
              40.0, 1e-4);
  EXPECT_NEAR(camera("<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><string name=\"fov_axis\" value=\"diagonal\"/>" + look +
                     film + "</sensor>")
                  .fov_degrees,
              glm::degrees(2 * std::atan(t / std::sqrt(5.0))), 1e-3);
  const Camera ortho = camera("<sensor type=\"orthographic\"><transform name=\"to_world\"><scale value=\"3\"/>"
                              "<lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform>" +
                              film + "</sensor>");
  EXPECT_EQ(ortho.type, SensorType::kOrthographic);
  EXPECT_NEAR(ortho.film_width, 6.0, 1e-5);   // [-1, 1] scaled by 3
  EXPECT_NEAR(ortho.film_height, 3.0, 1e-5);  // [-1/aspect, 1/aspect] scaled by 3
  expect_near(ortho.position, glm::vec3(0, 0, 5), "position");
}

TEST(ImportMitsuba, LightsKeepTheirUnitsAndPlaces) {
  const Scene s = load(write("lights.xml",
                             "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>"
                             "<transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>"
                             "<emitter type=\"point\"><rgb name=\"intensity\" value=\"1, 2, 3\"/><point name=\"position\" x=\"1\" y=\"0\" z=\"0\"/></emitter>"
                             "<emitter type=\"spot\"><rgb name=\"intensity\" value=\"4\"/><float name=\"cutoff_angle\" value=\"25\"/>"
                             "<float name=\"beam_width\" value=\"25\"/><transform name=\"to_world\"><lookat origin=\"0, 2, 0\" target=\"0, 0, 0\" up=\"0, 0, 1\"/></transform></emitter>"
                             "<emitter type=\"directional\"><vector name=\"direction\" x=\"0\" y=\"-1\" z=\"0\"/><rgb name=\"irradiance\" value=\"5\"/></emitter>"
                             "<shape type=\"sphere\"/></scene>"));
  ASSERT_EQ(s.lights.size(), 3u);
  const auto& p = std::get<PointLight>(s.lights[0]);
  expect_near(p.position, glm::vec3(1, 0, 0), "Mitsuba is right-handed: nothing is mirrored");
  expect_near(p.intensity, glm::vec3(1, 2, 3), "intensity in W/sr");
  const auto& spot = std::get<SpotLight>(s.lights[1]);
  expect_near(spot.position, glm::vec3(0, 2, 0), "spot position");
  expect_near(spot.direction, glm::vec3(0, -1, 0), "spot emits along to_world's +z");
  EXPECT_FLOAT_EQ(spot.cone_degrees, 25.0f);
  const auto& d = std::get<DistantLight>(s.lights[2]);
  expect_near(d.direction, glm::vec3(0, -1, 0), "direction of travel");
  expect_near(d.irradiance, glm::vec3(5), "irradiance");
}

// The environment box holds every shape, the camera and the lights, and its faces emit inwards.
void expect_environment_box(const Scene& s, glm::vec3 radiance) {
  ASSERT_TRUE(s.environment.has_value());
  expect_near(*s.environment, radiance, "the environment's radiance");
  const Shape& box = s.shapes.back();
  expect_near(box.emission, radiance, "the box emits the environment's radiance");
  const auto& mesh = std::get<MeshShape>(box.geometry);
  ASSERT_EQ(mesh.positions.size(), 8u);
  ASSERT_EQ(mesh.triangles.size(), 12u);
  glm::vec3 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : mesh.positions) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  const glm::vec3 centre = 0.5f * (lo + hi);
  for (const glm::uvec3& t : mesh.triangles) {  // every face's normal points at the box's centre
    const glm::vec3 a = mesh.positions[t.x], b = mesh.positions[t.y], c = mesh.positions[t.z];
    EXPECT_GT(glm::dot(glm::cross(b - a, c - a), centre - a), 0.0f);
  }
  EXPECT_TRUE(glm::all(glm::lessThan(lo, s.camera.position)) && glm::all(glm::lessThan(s.camera.position, hi)));
  EXPECT_TRUE(std::holds_alternative<Mixture>(s.materials[static_cast<std::size_t>(box.material)]));
  EXPECT_EQ(letters_of(s.materials[static_cast<std::size_t>(box.material)]), 0u);  // it absorbs: no letter
  EXPECT_EQ(describe(scene_types(s)).substr(0, 11), "lights area");
}

TEST(ImportPbrt, UniformInfiniteLightAndSoftSpot) {
  const Scene s = load(write("infinite.pbrt",
                             "Scale -1 1 1\nLookAt 0 0 5  0 0 0  0 1 0\nCamera \"perspective\"\nWorldBegin\n"
                             "LightSource \"infinite\" \"rgb L\" [0.5 0.25 0.5] \"float scale\" 2\n"
                             "LightSource \"infinite\" \"rgb L\" [0.5 0.5 0.5]\n"
                             "LightSource \"spot\" \"point3 from\" [0 3 0] \"point3 to\" [0 0 0] \"float coneangle\" 30 \"float conedeltaangle\" 10\n"
                             "Shape \"sphere\"\n"));
  expect_environment_box(s, glm::vec3(1.5f, 1.0f, 1.5f));  // two infinite lights add up
  ASSERT_EQ(s.lights.size(), 1u);
  const auto& spot = std::get<SpotLight>(s.lights[0]);
  EXPECT_FLOAT_EQ(spot.cone_degrees, 30.0f);
  EXPECT_FLOAT_EQ(spot.falloff_start_degrees, 20.0f);  // coneangle − conedeltaangle
  EXPECT_EQ(spot.falloff, SpotFalloff::kSmoothstep);
}

// An index below 1 (the inside the less dense medium) is read as given, in both formats.
TEST(ImportDielectric, AnIndexBelowOneIsTheBubble) {
  const Scene pbrt = load(write("bubble.pbrt", "LookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\"\nWorldBegin\nLightSource \"point\"\nMaterial \"dielectric\" \"float eta\" 0.75\nShape \"sphere\"\n"));
  EXPECT_FLOAT_EQ(std::get<Dielectric>(pbrt.materials[static_cast<std::size_t>(pbrt.shapes[0].material)]).ior, 0.75f);
  const Scene xml = load(write("bubble.xml", "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 5\" "
                                                        "target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor><emitter type=\"point\"/>"
                                                        "<shape type=\"sphere\"><bsdf type=\"dielectric\"><string name=\"int_ior\" value=\"air\"/>"
                                                        "<string name=\"ext_ior\" value=\"water\"/></bsdf></shape></scene>"));
  EXPECT_NEAR(std::get<Dielectric>(xml.materials[static_cast<std::size_t>(xml.shapes[0].material)]).ior, 1.000277 / 1.333, 1e-6);
}

TEST(ImportMitsuba, ConstantEmitterAndSoftSpot) {
  const Scene s = load(write("constant.xml",
                             "<scene version=\"3.0.0\"><sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/>"
                             "<transform name=\"to_world\"><lookat origin=\"0, 0, 5\" target=\"0, 0, 0\" up=\"0, 1, 0\"/></transform></sensor>"
                             "<emitter type=\"constant\"><rgb name=\"radiance\" value=\"0.25\"/></emitter>"
                             "<emitter type=\"spot\"><float name=\"cutoff_angle\" value=\"25\"/><float name=\"beam_width\" value=\"15\"/></emitter>"
                             "<shape type=\"sphere\"/></scene>"));
  expect_environment_box(s, glm::vec3(0.25f));
  const auto& spot = std::get<SpotLight>(s.lights[0]);
  EXPECT_FLOAT_EQ(spot.cone_degrees, 25.0f);
  EXPECT_FLOAT_EQ(spot.falloff_start_degrees, 15.0f);
  EXPECT_EQ(spot.falloff, SpotFalloff::kLinear);
}

// --- refusals: located, exact ---

struct Refusal {
  const char* file;
  const char* text;
  const char* where;  // relative to the scratch folder
  const char* message;
};

const std::string kPbrtHead = "LookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n";
const std::string kXmlHead = "<scene version=\"3.0.0\">\n";

// Attribute "light" "float a0" 1 … "float a64" 1: the 65th (column 905) is one too many.
const char* sixty_five_attributes() {
  static const std::string text = [] {
    std::string t = "Attribute \"light\" ";
    for (int i = 0; i < 65; ++i) t += "\"float a" + std::to_string(i) + "\" 1 ";
    return t + "\n";
  }();
  return text.c_str();
}

std::vector<Refusal> refusals() {
  return {
      // pbrt-v4
      {"object.pbrt", "ObjectBegin \"thing\"\n", "object.pbrt:4:1", "ObjectBegin \"thing\" has no matching ObjectEnd"},
      {"medium.pbrt", "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\"\n", "medium.pbrt:4:1",
       "medium \"fog\" scatters (pbrt-v4's default sigma_s is not 0): a scattering medium needs a volume letter that pathex's alphabet "
       "does not have; give \"rgb sigma_s\" [0 0 0] for an absorbing one"},
      {"medium-scatters.pbrt", "MakeNamedMedium \"fog\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [0 0.1 0]\n", "medium-scatters.pbrt:4:51",
       "a scattering medium (sigma_s not 0) needs a volume letter that pathex's alphabet does not have"},
      {"medium-grid.pbrt", "MakeNamedMedium \"smoke\" \"string type\" \"uniformgrid\"\n", "medium-grid.pbrt:4:1",
       "medium type \"uniformgrid\" is not supported: pathex has absorbing homogeneous media only"},
      {"medium-exterior.pbrt", "MediumInterface \"\" \"fog\"\n", "medium-exterior.pbrt:4:1",
       "an exterior medium (\"fog\") is not supported: pathex's media are the absorbing interiors of shapes, surrounded by vacuum (give "
       "MediumInterface \"\" \"\")"},
      {"medium-undefined.pbrt", "MediumInterface \"tea\" \"\"\n", "medium-undefined.pbrt:4:1",
       "medium \"tea\" is not defined (MakeNamedMedium must come first)"},
      {"medium-interface.pbrt",
       "MakeNamedMedium \"tea\" \"string type\" \"homogeneous\" \"rgb sigma_s\" [0 0 0]\nMaterial \"interface\"\nMediumInterface \"tea\" \"\"\nShape \"sphere\"\n",
       "medium-interface.pbrt:7:1",
       "a medium bounded by the \"interface\" material (no surface) is not supported: pathex's media fill the inside of a transmissive surface, "
       "such as a dielectric"},
      {"curve.pbrt", "Shape \"curve\"\n", "curve.pbrt:4:1",
       "shape \"curve\" is not supported, expected trianglemesh, plymesh, bilinearmesh, loopsubdiv, sphere, disk or cylinder"},
      {"cylinder.pbrt", "Shape \"cylinder\" \"float phimax\" 180\n", "cylinder.pbrt:4:18", "partial cylinders (phimax) are not supported"},
      {"coated.pbrt", "Material \"coatedplastic\"\n", "coated.pbrt:4:1",
       "material \"coatedplastic\" is not supported, expected diffuse, coateddiffuse, coatedconductor, conductor, dielectric, thindielectric, "
       "diffusetransmission, interface or mix"},
      {"coated-metal.pbrt", "Material \"coatedconductor\" \"rgb albedo\" [0.5 0.5 0.5]\n", "coated-metal.pbrt:4:28",
       "coatedconductor with a smooth interface over a smooth conductor and a scattering layer (albedo > 0) is not supported: pathex samples "
       "it as one delta reflection, which needs albedo 0"},
      {"coated-metal-both.pbrt", "Material \"coatedconductor\" \"rgb reflectance\" [0.5 0.5 0.5] \"rgb conductor.k\" [1 1 1]\n",
       "coated-metal-both.pbrt:4:28", "coatedconductor takes either reflectance or conductor.eta and conductor.k, not both"},
      {"coated-metal-texture.pbrt", "Texture \"r\" \"float\" \"constant\"\nMaterial \"coatedconductor\" \"texture conductor.roughness\" \"r\"\n",
       "coated-metal-texture.pbrt:5:1", "a texture for coatedconductor's conductor roughness is not supported"},
      {"coated-thickness.pbrt", "Material \"coateddiffuse\" \"float thickness\" -1\n", "coated-thickness.pbrt:4:26",
       "coateddiffuse thickness must be within [0, 1e6]"},
      {"coated-eta.pbrt", "Material \"coateddiffuse\" \"float eta\" 1\n", "coated-eta.pbrt:4:26",
       "coateddiffuse eta must be within [0.1, 10] and not 1 (1 is no surface), found 1"},
      {"coated-spectrum.pbrt", "Material \"coateddiffuse\" \"spectrum eta\" \"glass-BK7\"\n", "coated-spectrum.pbrt:4:26",
       "parameter \"spectrum eta\" is not supported: give \"float eta\" (pathex's coat has one index)"},
      {"coated-depth.pbrt", "Material \"coateddiffuse\" \"integer maxdepth\" 0\n", "coated-depth.pbrt:4:26",
       "coateddiffuse maxdepth must be within [1, 10000]"},
      {"coated-samples.pbrt", "Material \"coateddiffuse\" \"integer nsamples\" 2000\n", "coated-samples.pbrt:4:26",
       "coateddiffuse nsamples must be within [1, 1024]"},
      {"coated-albedo.pbrt", "Material \"coateddiffuse\" \"rgb albedo\" [0.5 1.5 0.5]\n", "coated-albedo.pbrt:4:26",
       "coateddiffuse albedo must be within [0, 1]"},
      {"coated-g.pbrt", "Material \"coateddiffuse\" \"float g\" 1\n", "coated-g.pbrt:4:26", "coateddiffuse g must be within (-1, 1)"},
      {"coated-aniso.pbrt", "Material \"coateddiffuse\" \"float uroughness\" 0.1 \"float vroughness\" 0.2\n", "coated-aniso.pbrt:4:1",
       "anisotropic roughness (uroughness != vroughness) is not supported"},
      {"coated-displacement.pbrt", "Material \"coateddiffuse\" \"texture displacement\" \"bumps\"\n", "coated-displacement.pbrt:4:26",
       "unknown texture \"bumps\""},
      {"infinite.pbrt", "LightSource \"infinite\" \"string filename\" \"sky.exr\"\n", "infinite.pbrt:4:24",
       "the image 'sky.exr': cannot read the image: No such file or directory"},
      {"goniometric.pbrt", "LightSource \"goniometric\"\n", "goniometric.pbrt:4:1",
       "light \"goniometric\" is not supported, expected point, spot, distant, infinite or an AreaLightSource"},
      {"zmin.pbrt", "Shape \"sphere\" \"float zmin\" -0.5\n", "zmin.pbrt:4:16", "partial spheres (zmin) are not supported"},
      {"typo.pbrt", "Shape \"sphere\" \"float radiu\" 2\n", "typo.pbrt:4:16", "parameter \"float radiu\" of Shape \"sphere\" is not supported"},
      {"eta-one.pbrt", "Material \"dielectric\" \"float eta\" 1\n", "eta-one.pbrt:4:1",
       "dielectric eta must be within [0.1, 10] and not 1 (1 is no surface), found 1"},
      {"measured.pbrt", "Material \"measured\" \"string filename\" \"gold.bsdf\"\n", "measured.pbrt:4:1",
       "material \"measured\" is not supported: it needs the RGL measured-BSDF file reader and its spectral tables, which pathex does not "
       "have"},
      {"blackbody.pbrt", "LightSource \"point\" \"blackbody I\" 3000\n", "blackbody.pbrt:4:21",
       "parameter \"blackbody I\" is not supported: pathex renders in RGB, give \"rgb I\" [r g b]"},
      {"texture.pbrt", "Material \"diffuse\" \"texture reflectance\" \"checks\"\n", "texture.pbrt:4:20",
       "unknown texture \"checks\""},
      {"normals.pbrt", "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"normal N\" [0 0 1 0 0 1]\n", "normals.pbrt:4:53",
       "\"normal N\" has 2 normals for 3 points, expected one per point"},
      {"uv-count.pbrt", "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"point2 uv\" [0 0 1 0]\n", "uv-count.pbrt:4:53",
       "\"point2 uv\" has 2 pairs for 3 points, expected one per point"},
      {"zero-normal.pbrt", "Shape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"normal N\" [0 0 1 0 0 0 0 0 1]\n", "zero-normal.pbrt:4:1",
       "normal 1 of the mesh is zero, expected a direction"},
      {"include.pbrt", "Include \"missing.pbrt\"\n", "include.pbrt:4:1", "cannot open the included file 'missing.pbrt'"},
      {"self.pbrt", "Include \"loop.pbrt\"\n", "loop.pbrt:1:1", "Include/Import nested more than 32 deep (a file including itself?)"},
      {"end.pbrt", "AttributeEnd\n", "end.pbrt:4:1", "AttributeEnd has no matching AttributeBegin"},
      {"string.pbrt", "Shape \"sphere\n", "string.pbrt:4:7", "unterminated string, expected a closing '\"' on the same line"},
      {"bright.pbrt", "AreaLightSource \"diffuse\" \"rgb L\" [1 1 1] \"float scale\" 1e12\n", "bright.pbrt:4:1",
       "a light's emission (1e+12 after scale) exceeds 1e9: the tracer sums contributions exactly below 2^50 and drops larger ones; scale "
       "the scene's lights down (the image scales with them)"},
      {"nolight.pbrt", "Shape \"sphere\"\n", "nolight.pbrt", "the scene has no light: expected a light source or an emitting shape"},
      // pbrt-v4's hints and settings that change the light (README "Importing pbrt-v4 and Mitsuba 3 scenes")
      {"colorspace.pbrt", "ColorSpace \"aces2065-1\"\n", "colorspace.pbrt:4:1", "color space \"aces2065-1\" is not supported, expected \"srgb\""},
      {"forcediffuse.pbrt", "Option \"bool forcediffuse\" true\n", "forcediffuse.pbrt:4:8",
       "Option forcediffuse true (every material rendered as diffuse) is not supported: remove it or set it false"},
      {"option.pbrt", "Option \"bool fastrender\" true\n", "option.pbrt:4:8", "unknown Option \"fastrender\""},
      {"attribute-target.pbrt", "Attribute \"camera\" \"float fov\" 30\n", "attribute-target.pbrt:4:1",
       "Attribute target \"camera\" is not supported, expected shape, light, material, medium or texture"},
      {"attribute-unused.pbrt",
       "Attribute \"shape\" \"float radius\" 2\nShape \"trianglemesh\" \"point3 P\" [0 0 0 1 0 0 0 1 0] \"integer indices\" [0 1 2]\n",
       "attribute-unused.pbrt:4:19", "parameter \"float radius\" (an Attribute default) of Shape \"trianglemesh\" is not supported"},
      {"attribute-zmax.pbrt", "AttributeBegin\nAttribute \"shape\" \"float zmax\" 0.5\nShape \"sphere\"\n", "attribute-zmax.pbrt:5:19",
       "partial spheres (zmax) are not supported"},
      {"attributes.pbrt", sixty_five_attributes(), "attributes.pbrt:4:905", "more than 64 parameters of Attribute \"light\" at once"},
      {"motion.pbrt", "ActiveTransform StartTime\n", "motion.pbrt:4:17",
       "ActiveTransform StartTime (a moving transform, motion blur) is not supported: pathex renders static scenes"},
      {"accelerator.pbrt", "Accelerator \"bvh\"\n", "accelerator.pbrt:4:1", "Accelerator must come before WorldBegin"},
      // Mitsuba 3
      {"negative.xml", "  <emitter type=\"point\">\n    <rgb name=\"intensity\" value=\"1, -1, 1\"/>\n  </emitter>\n</scene>\n", "negative.xml:2:3",
       "a light's emission must be non-negative"},
      {"curve.xml", "  <shape type=\"bsplinecurve\"/>\n</scene>\n", "curve.xml:2:3",
       "shape \"bsplinecurve\" is not supported, expected obj, ply, serialized, sphere, rectangle, disk, cube or cylinder"},
      {"envmap.xml", "  <emitter type=\"envmap\"/>\n</scene>\n", "envmap.xml:2:3",
       "the envmap has no filename"},
      {"projector.xml", "  <emitter type=\"projector\"/>\n</scene>\n", "projector.xml:2:3",
       "emitter \"projector\" is not supported, expected point, spot, directional, constant, or area inside a shape"},
      {"plastic-specular.xml", "  <bsdf type=\"plastic\" id=\"p\">\n    <float name=\"specular_reflectance\" value=\"0.5\"/>\n  </bsdf>\n</scene>\n",
       "plastic-specular.xml:3:5",
       "specular_reflectance other than 1 is not supported: pathex's coat reflects by the Fresnel equations alone"},
      {"plastic-diffuse.xml", "  <bsdf type=\"plastic\" id=\"p\">\n    <rgb name=\"diffuse_reflectance\" value=\"0.5, 1.2, 0.5\"/>\n  </bsdf>\n</scene>\n",
       "plastic-diffuse.xml:3:5", "diffuse_reflectance must be within [0, 1]"},
      {"plastic-ior.xml", "  <bsdf type=\"plastic\" id=\"p\">\n    <float name=\"int_ior\" value=\"1.000277\"/>\n  </bsdf>\n</scene>\n",
       "plastic-ior.xml:2:3", "int_ior / ext_ior must be within [0.1, 10] and not 1 (1 is no surface), found 1"},
      {"roughplastic.xml", "  <bsdf type=\"roughplastic\" id=\"p\">\n    <string name=\"distribution\" value=\"phong\"/>\n  </bsdf>\n</scene>\n",
       "roughplastic.xml:3:5", "microfacet distribution \"phong\" is not supported, expected beckmann or ggx"},
      {"roughplastic-alpha.xml",
       "  <bsdf type=\"roughplastic\" id=\"p\">\n    <string name=\"distribution\" value=\"ggx\"/>\n    <float name=\"alpha\" value=\"2\"/>\n  </bsdf>\n</scene>\n",
       "roughplastic-alpha.xml:2:3", "alpha must be within [0, 1]"},
      {"medium.xml", "  <medium type=\"homogeneous\"/>\n</scene>\n", "medium.xml:2:3",
       "<medium> is not supported (pathex imports shapes, bsdfs, emitters, a sensor, includes and paths)"},
      {"principled.xml", "  <shape type=\"sphere\">\n    <bsdf type=\"principled\"/>\n  </shape>\n</scene>\n", "principled.xml:3:5",
       "bsdf \"principled\" is not supported: it needs the Disney principled BSDF (sheen, clearcoat, specular transmission and their "
       "blend), which pathex does not have"},
      {"phong.xml",
       "  <shape type=\"sphere\">\n    <bsdf type=\"roughconductor\">\n      <string name=\"distribution\" value=\"phong\"/>\n    </bsdf>\n  </shape>\n</scene>\n",
       "phong.xml:4:7", "microfacet distribution \"phong\" is not supported, expected beckmann or ggx"},
      {"bitmap.xml",
       "  <shape type=\"sphere\">\n    <bsdf type=\"diffuse\">\n      <texture type=\"bitmap\" name=\"reflectance\"/>\n    </bsdf>\n  </shape>\n</scene>\n",
       "bitmap.xml:4:7", "bitmap needs a <string name=\"filename\">"},
      {"typo.xml", "  <shape type=\"sphere\">\n    <float name=\"radiuss\" value=\"1\"/>\n  </shape>\n</scene>\n", "typo.xml:3:5",
       "<float name=\"radiuss\"> in <shape type=\"sphere\"> is not supported"},
      {"wide-beam.xml", "  <emitter type=\"spot\">\n    <float name=\"beam_width\" value=\"30\"/>\n  </emitter>\n</scene>\n", "wide-beam.xml:2:3",
       "beam_width must be within [0, cutoff_angle]"},
      {"param.xml", "  <shape type=\"sphere\">\n    <float name=\"radius\" value=\"$r\"/>\n  </shape>\n</scene>\n", "param.xml:3:5",
       "unknown parameter $r (no <default name=\"r\">)"},
      {"broken.xml", "  <shape type=\"sphere\">\n</scene>\n", "broken.xml:3:3", "not valid XML: Start-end tags mismatch"},
  };
}

// loop.pbrt includes itself (for self.pbrt).
void write_fixtures() { write("loop.pbrt", "Include \"loop.pbrt\"\n"); }

std::string full_text(const Refusal& r) {
  const std::string f = r.file;
  return (f.size() > 5 && f.substr(f.size() - 5) == ".pbrt" ? kPbrtHead : kXmlHead) + r.text;
}

TEST(ImportRefusals, LibraryNamesFileLineColumnAndWhat) {
  write_fixtures();
  for (const Refusal& r : refusals()) {
    const Result<Scene> s = load_scene_file(write(r.file, full_text(r)));
    ASSERT_FALSE(s.ok()) << r.file;
    EXPECT_EQ(relative(s.error().where), r.where) << r.file;
    EXPECT_EQ(relative(s.error().message), r.message) << r.file;
  }
}

TEST(ImportRefusals, CliPrintsTheSameLineAndExits2) {
  write_fixtures();
  for (const Refusal& r : refusals()) {
    const std::string path = write(r.file, full_text(r));
    const pathex::test::CliRun run = pathex::test::run_pathex("trace " + path + " --quiet --out " + scratch() + "/out");
    EXPECT_EQ(run.code, 2) << r.file;
    EXPECT_EQ(relative(run.err), std::string("pathex: error: ") + r.where + ": " + r.message + "\n") << r.file;
  }
  // query --scene and check read scenes through the same entry point.
  const pathex::test::CliRun q = pathex::test::run_pathex("query --scene " + write("object.pbrt", kPbrtHead + "ObjectBegin \"thing\"\n") + " 'L.*E'");
  EXPECT_EQ(q.code, 2);
  EXPECT_NE(q.err.find("object.pbrt:4:1: ObjectBegin \"thing\" has no matching ObjectEnd"), std::string::npos) << q.err;
}

// pbrt-v4's hints are accepted and change nothing; Attribute defaults are honoured, scoped by
// AttributeBegin/End, and a directive's own parameter wins over them.
TEST(ImportPbrt, HintsAreIgnoredAndAttributesHonoured) {
  const std::string plain = "Scale -1 1 1\nLookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\nWorldBegin\n"
                            "LightSource \"point\" \"rgb I\" [3 3 3] \"point3 from\" [0 2 2]\n"
                            "Material \"diffuse\" \"rgb reflectance\" [0.2 0.3 0.4]\nShape \"sphere\" \"float radius\" 2\n"
                            "Material \"diffuse\"\nShape \"sphere\"\nShape \"sphere\" \"float radius\" 0.5\n";
  const std::string hinted =
      "Option \"bool disablepixeljitter\" true\nOption \"integer seed\" 7\nOption \"string rendercoordsys\" \"world\"\n"
      "Option \"bool forcediffuse\" false\nScale -1 1 1\nLookAt 0 1 3  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 40\n"
      "Accelerator \"kdtree\" \"integer maxprims\" 4\nTransformTimes 0 1\nColorSpace \"srgb\"\nWorldBegin\nActiveTransform All\n"
      "ColorSpace \"srgb\"\nAttributeBegin\nAttribute \"light\" \"float scale\" 3\nLightSource \"point\" \"rgb I\" [1 1 1] \"point3 from\" [0 2 2]\n"
      "Attribute \"material\" \"rgb reflectance\" [0.2 0.3 0.4]\nAttribute \"shape\" \"float radius\" 2\nMaterial \"diffuse\"\nShape \"sphere\"\n"
      "AttributeEnd\nMaterial \"diffuse\"\nShape \"sphere\"\nAttribute \"shape\" \"float radius\" 3\nShape \"sphere\" \"float radius\" 0.5\n"
      "Attribute \"texture\" \"float scale\" 2\nAttribute \"medium\" \"float scale\" 2\n";
  const Scene a = load(write("plain.pbrt", plain));
  const Scene b = load(write("hinted.pbrt", hinted));
  ASSERT_EQ(a.shapes.size(), 3u);
  ASSERT_EQ(b.shapes.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto& sa = std::get<SphereShape>(a.shapes[i].geometry);
    const auto& sb = std::get<SphereShape>(b.shapes[i].geometry);
    EXPECT_EQ(sb.radius, sa.radius) << i;
    EXPECT_EQ(sb.radius, (std::vector<float>{2.0f, 1.0f, 0.5f})[i]) << i;
    EXPECT_EQ(std::get<Diffuse>(b.materials[static_cast<std::size_t>(b.shapes[i].material)]).albedo,
              std::get<Diffuse>(a.materials[static_cast<std::size_t>(a.shapes[i].material)]).albedo)
        << i;
  }
  ASSERT_EQ(b.lights.size(), 1u);
  expect_near(std::get<PointLight>(b.lights[0]).intensity, glm::vec3(3.0f), "the light's scale from its Attribute");
  EXPECT_EQ(describe(scene_types(b)), describe(scene_types(a)));
}

// Mitsuba's cube and both formats' cylinders become meshes whose front sides face outwards (inwards
// under flip_normals / ReverseOrientation), on the analytic surface, of its area within 3e-5.
TEST(ImportShapes, CubeAndCylindersAreMeshesFacingOutwards) {
  struct Expect {
    glm::vec3 axis_point, axis;  // cylinders; axis zero for the cube (centred at axis_point)
    float radius, area;
    int triangles;
    bool inwards;
  };
  auto check = [](const Shape& shape, const Expect& e, const std::string& what) {
    const auto* mesh = std::get_if<MeshShape>(&shape.geometry);
    ASSERT_NE(mesh, nullptr) << what;
    EXPECT_EQ(static_cast<int>(mesh->triangles.size()), e.triangles) << what;
    EXPECT_EQ(mesh->uvs.size(), mesh->positions.size()) << what;
    double area = 0.0;
    for (const glm::uvec3& t : mesh->triangles) {
      const glm::vec3 a = mesh->positions[t.x], b = mesh->positions[t.y], c = mesh->positions[t.z];
      const glm::vec3 n = glm::cross(b - a, c - a);
      area += 0.5 * glm::length(n);
      glm::vec3 out = (a + b + c) / 3.0f - e.axis_point;
      out -= glm::dot(out, e.axis) * e.axis;  // radial for a cylinder, from the centre for the cube
      EXPECT_EQ(glm::dot(n, out) < 0.0f, e.inwards) << what;
    }
    EXPECT_NEAR(area, e.area, 3e-5 * e.area) << what;
    if (glm::length(e.axis) > 0.0f)
      for (const glm::vec3& p : mesh->positions) {
        glm::vec3 r = p - e.axis_point;
        r -= glm::dot(r, e.axis) * e.axis;
        EXPECT_NEAR(glm::length(r), e.radius, 1e-5f) << what;
      }
  };
  const float pi = 3.14159265f;
  const std::string sensor = "<sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/><transform name=\"to_world\">"
                             "<lookat origin=\"0 1 8\" target=\"0 1 0\"/></transform></sensor>\n<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"5\" z=\"5\"/></emitter>\n";
  const Scene xml = load(write("shapes.xml",
      "<scene version=\"3.0.0\">\n" + sensor +
      "<shape type=\"cube\"><transform name=\"to_world\"><scale value=\"0.5\"/><translate x=\"2\"/></transform></shape>\n"
      "<shape type=\"cube\"><boolean name=\"flip_normals\" value=\"true\"/></shape>\n"
      "<shape type=\"cylinder\"><point name=\"p1\" x=\"0\" y=\"2\" z=\"0\"/><float name=\"radius\" value=\"0.5\"/></shape>\n"
      "<shape type=\"cylinder\"><boolean name=\"flip_normals\" value=\"true\"/><transform name=\"to_world\"><scale x=\"-1\"/></transform></shape>\n"
      "</scene>\n"));
  ASSERT_EQ(xml.shapes.size(), 4u);
  check(xml.shapes[0], {{2, 0, 0}, {0, 0, 0}, 0, 6.0f, 12, false}, "the cube");
  check(xml.shapes[1], {{0, 0, 0}, {0, 0, 0}, 0, 24.0f, 12, true}, "the flipped cube");
  check(xml.shapes[2], {{0, 0, 0}, {0, 1, 0}, 0.5f, 2 * pi * 0.5f * 2, 512, false}, "the cylinder");
  check(xml.shapes[3], {{0, 0, 0}, {0, 0, 1}, 1.0f, 2 * pi, 512, true}, "the flipped cylinder under a mirror");
  const Scene pbrt = load(write("shapes.pbrt",
      "Scale -1 1 1\nLookAt 0 1 8  0 1 0  0 1 0\nCamera \"perspective\" \"float fov\" 60\nWorldBegin\n"
      "LightSource \"point\" \"point3 from\" [0 5 5]\nShape \"cylinder\" \"float radius\" 0.5 \"float zmin\" 0 \"float zmax\" 2\n"
      "AttributeBegin\nScale -1 1 1\nShape \"cylinder\"\nReverseOrientation\nShape \"cylinder\"\nAttributeEnd\n"));
  ASSERT_EQ(pbrt.shapes.size(), 3u);
  check(pbrt.shapes[0], {{0, 0, 0}, {0, 0, 1}, 0.5f, 2 * pi * 0.5f * 2, 512, false}, "pbrt's cylinder");
  check(pbrt.shapes[1], {{0, 0, 0}, {0, 0, 1}, 1.0f, 2 * pi * 2, 512, false}, "pbrt's cylinder under a mirror");
  check(pbrt.shapes[2], {{0, 0, 0}, {0, 0, 1}, 1.0f, 2 * pi * 2, 512, true}, "pbrt's reversed cylinder");
}

// A Mitsuba file of another version names the same plugins differently: refused naming it.
TEST(ImportMitsuba, AVersionOtherThan3IsRefusedNamingIt) {
  const std::string body = "\n  <sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\">"
                           "<lookat origin=\"0 0 5\" target=\"0 0 0\"/></transform></sensor>\n  <emitter type=\"point\"/>\n  <shape type=\"sphere\"/>\n</scene>\n";
  for (const char* ok : {"3.0.0", "3.5.2", "3.1"}) EXPECT_TRUE(load_scene_file(write("v3.xml", "<scene version=\"" + std::string(ok) + "\">" + body)).ok()) << ok;
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"<scene version=\"0.6.0\">", "scene version 0.6.0 is Mitsuba 0.6; pathex reads Mitsuba 3 scenes (version 3.x)"},
      {"<scene version=\"0.5.0\">", "scene version 0.5.0 is Mitsuba 0.5; pathex reads Mitsuba 3 scenes (version 3.x)"},
      {"<scene version=\"2.1.0\">", "scene version 2.1.0 is Mitsuba 2; pathex reads Mitsuba 3 scenes (version 3.x)"},
      {"<scene version=\"three\">", "scene version \"three\" is not a version number; pathex reads Mitsuba 3 scenes (version 3.x)"},
      {"<scene>", "the <scene> has no version attribute; pathex reads Mitsuba 3 scenes (version 3.x)"},
  };
  for (const auto& [head, message] : refused) {
    const Result<Scene> s = load_scene_file(write("v.xml", head + body));
    ASSERT_FALSE(s.ok()) << head;
    EXPECT_EQ(relative(s.error().where), "v.xml:1:1") << head;
    EXPECT_EQ(s.error().message, message) << head;
  }
  // An included file too, at its own <scene>.
  write("old.xml", "<?xml version=\"1.0\"?>\n<scene version=\"0.6.0\"/>\n");
  const Result<Scene> inc = load_scene_file(write("includes-old.xml", "<scene version=\"3.0.0\">\n  <include filename=\"old.xml\"/>" + body));
  ASSERT_FALSE(inc.ok());
  EXPECT_EQ(relative(inc.error().where), "old.xml:2:1");
  EXPECT_EQ(inc.error().message, "scene version 0.6.0 is Mitsuba 0.6; pathex reads Mitsuba 3 scenes (version 3.x)");
  const pathex::test::CliRun run = pathex::test::run_pathex("trace " + write("v.xml", "<scene version=\"0.6.0\">" + body) + " --quiet --out " + scratch() + "/out");
  EXPECT_EQ(run.code, 2);
  EXPECT_EQ(relative(run.err), "pathex: error: v.xml:1:1: scene version 0.6.0 is Mitsuba 0.6; pathex reads Mitsuba 3 scenes (version 3.x)\n");
}

TEST(ImportRefusals, PlyMeshesWithCurvedQuadsOrOfAnotherFormat) {
  const std::string header = "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n";
  write("curved.ply", header + "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 1\n0 1 0\n4 0 1 2 3\n");
  const Result<Scene> b = load_scene_file(write("ply-curved.pbrt", kPbrtHead + "Shape \"plymesh\" \"string filename\" \"curved.ply\"\n"));
  ASSERT_FALSE(b.ok());
  EXPECT_EQ(relative(b.error().message),
            "the PLY mesh 'curved.ply' has a non-planar quad (face 0), which pbrt renders as a curved bilinear patch; pathex supports planar "
            "quads only");
  const Result<Scene> c = load_scene_file(write("ply-obj.pbrt", kPbrtHead + "Shape \"plymesh\" \"string filename\" \"mesh.obj\"\n"));
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(relative(c.error().message), "the mesh 'mesh.obj' is not a .ply or .ply.gz file");
}

// Per-vertex normals (README "Importing pbrt-v4 and Mitsuba 3 scenes"): transformed as normals,
// negated by ReverseOrientation / flip_normals, and each triangle wound to face their side.
TEST(ImportShapes, VertexNormalsArePlacedAndWindTheirTriangles) {
  const auto mesh_of = [](const Scene& s, std::size_t i) -> const MeshShape& { return std::get<MeshShape>(s.shapes.at(i).geometry); };
  const auto face = [](const MeshShape& m, std::size_t t) {
    const glm::uvec3 v = m.triangles[t];
    return glm::normalize(glm::cross(m.positions[v.y] - m.positions[v.x], m.positions[v.z] - m.positions[v.x]));
  };
  // Wound clockwise seen from +z (face -z) with normals +z: rewound to face +z. Rotated 90° about x
  // (+z to -y). Reversed: the normals turn to -z and the winding with them.
  const std::string tri = "Shape \"trianglemesh\" \"point3 P\" [0 0 0 0 1 0 1 0 0] \"integer indices\" [0 1 2] \"normal N\" [0 0 2 0 0 1 0 0 1] "
                          "\"point2 uv\" [0 0 0 1 1 0]\n";
  const Scene s = load(write("vertex-normals.pbrt", kPbrtHead + "LightSource \"point\"\n" + tri +
                                                         "AttributeBegin\nRotate 90 1 0 0\n" + tri + "AttributeEnd\n"
                                                         "AttributeBegin\nReverseOrientation\n" + tri + "AttributeEnd\n"));
  ASSERT_EQ(s.shapes.size(), 3u);
  const glm::vec3 expected[3] = {{0, 0, 1}, {0, -1, 0}, {0, 0, -1}};
  for (std::size_t i = 0; i < 3; ++i) {
    const MeshShape& m = mesh_of(s, i);
    ASSERT_EQ(m.normals.size(), 3u) << i;
    for (const glm::vec3& n : m.normals) expect_near(n, expected[i], "pbrt vertex normal of shape " + std::to_string(i));
    expect_near(face(m, 0), expected[i], "pbrt face normal of shape " + std::to_string(i));
    EXPECT_EQ(m.uvs, (std::vector<glm::vec2>{{0, 0}, {0, 1}, {1, 0}})) << i;  // "point2 uv", one pair per point
  }
  // Mitsuba: a PLY's normals unless face_normals; an OBJ (whose vn pathex does not read) gets
  // Mitsuba's angle-weighted normals: two faces meeting at a right angle along the y axis, +z
  // (angle 45° at (0, 1, 0)) and +x (angle atan 2 there), so (0, 1, 0)'s normal is
  // normalize(atan(2) x + (pi/4) z), not the area-weighted normalize(x + z / 2).
  write("normals.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                       "property float nx\nproperty float ny\nproperty float nz\nelement face 1\nproperty list uchar int vertex_indices\n"
                       "end_header\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n3 0 1 2\n");
  write("roof.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 2\nf 1 2 3\nf 1 3 4\n");
  const std::string sensor = "<sensor type=\"perspective\"><float name=\"fov\" value=\"60\"/><transform name=\"to_world\">"
                             "<lookat origin=\"0 1 8\" target=\"0 1 0\"/></transform></sensor>\n<emitter type=\"point\"/>\n";
  const Scene x = load(write("vertex-normals.xml", kXmlHead + sensor +
      "<shape type=\"ply\"><string name=\"filename\" value=\"normals.ply\"/></shape>\n"
      "<shape type=\"ply\"><string name=\"filename\" value=\"normals.ply\"/><boolean name=\"face_normals\" value=\"true\"/></shape>\n"
      "<shape type=\"ply\"><string name=\"filename\" value=\"normals.ply\"/><boolean name=\"flip_normals\" value=\"true\"/></shape>\n"
      "<shape type=\"obj\"><string name=\"filename\" value=\"roof.obj\"/></shape>\n</scene>\n"));
  ASSERT_EQ(x.shapes.size(), 4u);
  ASSERT_EQ(mesh_of(x, 0).normals.size(), 3u);
  expect_near(mesh_of(x, 0).normals[1], {0, 0, 1}, "the PLY's own normal");
  EXPECT_TRUE(mesh_of(x, 1).normals.empty());
  expect_near(mesh_of(x, 2).normals[1], {0, 0, -1}, "flip_normals");
  expect_near(face(mesh_of(x, 2), 0), {0, 0, -1}, "flip_normals' winding");
  const MeshShape& roof = mesh_of(x, 3);
  ASSERT_EQ(roof.normals.size(), 4u);
  const float pi = 3.14159265f;
  expect_near(roof.normals[2], glm::normalize(std::atan(2.0f) * glm::vec3(1, 0, 0) + (pi / 4) * glm::vec3(0, 0, 1)), "angle-weighted");
  expect_near(roof.normals[0], glm::normalize(glm::vec3(1, 0, 1)), "angle-weighted at the right-angled corner");
  expect_near(roof.normals[1], {0, 0, 1}, "one face");
  expect_near(roof.normals[3], {1, 0, 0}, "the other face");
}

// --- coated materials: pbrt-v4's coateddiffuse, Mitsuba 3's plastic and roughplastic ---

// pbrt-v4's coateddiffuse keeps its parameters and defaults (reflectance 0.5, eta 1.5, thickness
// 0.01, albedo 0, g 0, maxdepth 10, nsamples 1, smooth); roughness is remapped by √ unless
// remaproughness is false, and an alpha below 1e-3 is smooth, as pbrt has it.
TEST(ImportPbrt, CoatedDiffuseKeepsPbrtsParametersAndDefaults) {
  const Scene s = load(write("coated.pbrt",
                             kPbrtHead + "LightSource \"point\"\nMaterial \"coateddiffuse\"\nShape \"sphere\"\n"
                             "Material \"coateddiffuse\" \"rgb reflectance\" [0.2 0.4 0.6] \"float roughness\" 0.09 \"float thickness\" 0.5 "
                             "\"rgb albedo\" [0.1 0.2 0.3] \"float g\" 0.4 \"float eta\" 1.33 \"integer maxdepth\" 32 \"integer nsamples\" 4\n"
                             "Shape \"sphere\" \"float radius\" 2\n"
                             "Material \"coateddiffuse\" \"float roughness\" 0.09 \"bool remaproughness\" false\nShape \"sphere\" \"float radius\" 3\n"
                             "Material \"coateddiffuse\" \"float roughness\" 1e-7\nShape \"sphere\" \"float radius\" 4\n"));
  ASSERT_EQ(s.shapes.size(), 4u);
  auto coat = [&](int i) { return std::get<CoatedDiffuse>(s.materials[static_cast<std::size_t>(s.shapes[static_cast<std::size_t>(i)].material)]); };
  const CoatedDiffuse d = coat(0);
  expect_near(d.reflectance, glm::vec3(0.5f), "default reflectance");
  expect_near(d.albedo, glm::vec3(0.0f), "default albedo");
  EXPECT_EQ(d.roughness, 0.0f);
  EXPECT_TRUE(d.smooth());
  EXPECT_FLOAT_EQ(d.eta, 1.5f);
  EXPECT_FLOAT_EQ(d.thickness, 0.01f);
  EXPECT_EQ(d.g, 0.0f);
  EXPECT_EQ(d.max_depth, 10);
  EXPECT_EQ(d.samples, 1);
  EXPECT_EQ(letters_of(Material{d}), (1u << kS) | (1u << kD));
  const CoatedDiffuse e = coat(1);
  expect_near(e.reflectance, glm::vec3(0.2f, 0.4f, 0.6f), "reflectance");
  expect_near(e.albedo, glm::vec3(0.1f, 0.2f, 0.3f), "albedo");
  EXPECT_FLOAT_EQ(e.roughness, 0.3f);  // alpha = sqrt(roughness)
  EXPECT_FLOAT_EQ(e.thickness, 0.5f);
  EXPECT_FLOAT_EQ(e.g, 0.4f);
  EXPECT_FLOAT_EQ(e.eta, 1.33f);
  EXPECT_EQ(e.max_depth, 32);
  EXPECT_EQ(e.samples, 4);
  EXPECT_EQ(letters_of(Material{e}), 1u << kD);
  EXPECT_FLOAT_EQ(coat(2).roughness, 0.09f);
  EXPECT_EQ(coat(3).roughness, 0.0f);
}

// Mitsuba 3's plastic is a coat of thickness 0 (README import table). Its default (nonlinear
// false) takes diffuse_reflectance as the albedo under the coat, so the base is ρ / (1 − R̄ + ρ R̄);
// nonlinear true is the base itself. The BSDF then is Mitsuba's,
//   f = ρ T(θo) T(θi) / (π η² (1 − R̄_fit))   (Mitsuba's plastic.cpp, linear),
// where Mitsuba's R̄_fit is Egan and Hilgeman's polynomial for the internal diffuse reflectance
// (0.5906 for η = 1.49 where the integral is 0.5900): the diffuse lobe differs by that fit,
// (1 − 0.5900) / (1 − 0.5906) = 1.0015, and by the walk's Monte Carlo noise. Checked here within
// 0.3 % plus 4 standard errors of the mean of 4,000 walks.
TEST(ImportMitsuba, PlasticIsACoatOfThicknessZero) {
  const Scene s = load(write("plastic.xml",
                             kXmlHead + "  <sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/><transform name=\"to_world\"><lookat origin=\"0, 0, 9\" target=\"0, 0, 0\" "
                                        "up=\"0, 1, 0\"/></transform></sensor>\n  <emitter type=\"point\"/>\n"
                                        "  <shape type=\"sphere\">\n    <bsdf type=\"plastic\"/>\n  </shape>\n"
                                        "  <shape type=\"sphere\">\n    <bsdf type=\"plastic\">\n      <boolean name=\"nonlinear\" value=\"true\"/>\n"
                                        "      <rgb name=\"diffuse_reflectance\" value=\"0.2, 0.4, 0.6\"/>\n    </bsdf>\n  </shape>\n"
                                        "  <shape type=\"sphere\">\n    <bsdf type=\"roughplastic\">\n      <string name=\"distribution\" value=\"ggx\"/>\n"
                                        "      <float name=\"alpha\" value=\"0.2\"/>\n      <string name=\"int_ior\" value=\"water\"/>\n    </bsdf>\n  </shape>\n"
                                        "</scene>\n"));
  ASSERT_EQ(s.shapes.size(), 3u);
  auto coat = [&](int i) { return std::get<CoatedDiffuse>(s.materials[static_cast<std::size_t>(s.shapes[static_cast<std::size_t>(i)].material)]); };
  const double eta = 1.49 / 1.000277;
  const CoatedDiffuse p = coat(0);
  EXPECT_FLOAT_EQ(p.eta, static_cast<float>(eta));
  EXPECT_EQ(p.thickness, 0.0f);
  EXPECT_EQ(p.albedo, glm::vec3(0.0f));
  EXPECT_TRUE(p.smooth());
  EXPECT_EQ(p.max_depth, 64);
  const double r_bar = mean_internal_reflectance(p.eta);
  EXPECT_NEAR(r_bar, 0.5900, 2e-4);
  expect_near(p.reflectance, glm::vec3(static_cast<float>(0.5 / (1.0 - r_bar + 0.5 * r_bar))), "linear plastic's base");
  expect_near(coat(1).reflectance, glm::vec3(0.2f, 0.4f, 0.6f), "nonlinear plastic's base");
  const CoatedDiffuse rough = coat(2);
  EXPECT_FLOAT_EQ(rough.roughness, 0.2f);
  EXPECT_FLOAT_EQ(rough.eta, static_cast<float>(1.333 / 1.000277));

  // The imported plastic's BSDF against Mitsuba's formula.
  const double e = 1.0 / eta;  // Mitsuba's fresnel_diffuse_reflectance(1 / eta), eta < 1 branch
  const double r_fit = -1.4399 * e * e + 0.7099 * e + 0.6681 + 0.0636 / e;
  auto fresnel = [](double c, double n) {  // outside, unpolarised
    const double s2 = (1 - c * c) / (n * n), ct = std::sqrt(1 - s2);
    const double rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
    return 0.5 * (rs * rs + rp * rp);
  };
  for (const auto& [to, ti] : std::vector<std::pair<double, double>>{{0, 0}, {30, 60}, {75, 20}}) {
    const double a = to * 3.14159265358979 / 180, b = ti * 3.14159265358979 / 180;
    const glm::vec3 wo(static_cast<float>(std::sin(a)), 0.0f, static_cast<float>(std::cos(a)));
    const glm::vec3 wi(static_cast<float>(-std::sin(b) * 0.5), static_cast<float>(std::sin(b) * 0.866), static_cast<float>(std::cos(b)));
    const double mitsuba = 0.5 * (1 - fresnel(wo.z, eta)) * (1 - fresnel(wi.z, eta)) / (3.14159265358979 * eta * eta * (1 - r_fit));
    double sum = 0, sum2 = 0;
    const int n = 4000;
    for (int k = 0; k < n; ++k) {
      const double f = bsdf::layered::eval_estimate(p, wo, wi, static_cast<std::uint64_t>(k)).x;
      sum += f;
      sum2 += f * f;
    }
    const double mean = sum / n, se = std::sqrt(std::max(0.0, sum2 / n - mean * mean) / n);
    EXPECT_NEAR(mean, mitsuba, 0.003 * mitsuba + 4 * se) << to << ", " << ti;
  }
}

// Absorbing media (README "Importing pbrt-v4 and Mitsuba 3 scenes", trace/media.h): pbrt-v4's
// MakeNamedMedium homogeneous with sigma_s 0 behind MediumInterface, scaled, scoped by
// AttributeBegin; Mitsuba 3's homogeneous interior of albedo 0, sigma_t × scale.
TEST(ImportMedia, AbsorbingInteriorsInBothFormats) {
  const Scene p = load(write("tea.pbrt", kPbrtHead + "LightSource \"point\"\n"
      "MakeNamedMedium \"tea\" \"string type\" \"homogeneous\" \"rgb sigma_a\" [0.5 1 2] \"rgb sigma_s\" [0 0 0] \"float scale\" 3\n"
      "Material \"dielectric\"\nAttributeBegin\nMediumInterface \"tea\" \"\"\nShape \"sphere\"\nAttributeEnd\nShape \"sphere\" \"float radius\" 2\n"));
  ASSERT_EQ(p.shapes.size(), 2u);
  EXPECT_EQ(p.shapes[0].absorption, glm::vec3(1.5f, 3.0f, 6.0f));
  EXPECT_EQ(p.shapes[1].absorption, glm::vec3(0.0f));  // outside the AttributeBegin: vacuum again
  const std::string head = kXmlHead + "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n<emitter type=\"point\"/>\n";
  const Scene x = load(write("tea.xml", head +
      "<shape type=\"sphere\"><bsdf type=\"dielectric\"/><medium type=\"homogeneous\" name=\"interior\"><rgb name=\"albedo\" value=\"0\"/>"
      "<rgb name=\"sigma_t\" value=\"0.5, 1, 2\"/><float name=\"scale\" value=\"2\"/></medium></shape>\n</scene>\n"));
  ASSERT_EQ(x.shapes.size(), 1u);
  EXPECT_EQ(x.shapes[0].absorption, glm::vec3(1.0f, 2.0f, 4.0f));
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"<medium type=\"homogeneous\" name=\"interior\"/>",
       "a scattering medium (albedo not 0; Mitsuba's default is 0.75) needs a volume letter that pathex's alphabet does not have; give "
       "<rgb name=\"albedo\" value=\"0\"/> for an absorbing one"},
      {"<medium type=\"homogeneous\" name=\"exterior\"/>",
       "an exterior medium is not supported: pathex's media are the absorbing interiors of shapes, surrounded by vacuum"},
      {"<medium type=\"heterogeneous\" name=\"interior\"/>", "medium \"heterogeneous\" is not supported: pathex has absorbing homogeneous media only"},
  };
  for (const auto& [medium, message] : refused) {
    const Result<Scene> s = load_scene_file(write("bad-medium.xml", head + "<shape type=\"sphere\">\n  " + medium + "\n</shape>\n</scene>\n"));
    ASSERT_FALSE(s.ok()) << medium;
    EXPECT_EQ(relative(s.error().where), "bad-medium.xml:5:3") << medium;
    EXPECT_EQ(s.error().message, message);
  }
}

// Mitsuba 3's spectra in its RGB variants (Properties::get_texture, spectrum_list_to_srgb): a
// reflectance of wavelength:value pairs by the CIE 1931 curves under D65 (so a constant 0.5 over
// 360..830 nm is grey 0.5), a uniform light spectrum as the equal-energy white (sRGB of XYZ
// (1, 1, 1): (1.2049, 0.9484, 0.9086)); and an area emitter defined by id after the shape that
// <ref>s it, as Mitsuba's own cbox.xml has it.
TEST(ImportMitsuba, SpectraAndAreaEmittersByReference) {
  const std::string head = kXmlHead + "<sensor type=\"perspective\"><float name=\"fov\" value=\"40\"/></sensor>\n";
  const Scene x = load(write("spectra.xml", head +
      "<bsdf type=\"diffuse\" id=\"grey\"><spectrum name=\"reflectance\" value=\"360:0.5, 830:0.5\"/></bsdf>\n"
      "<bsdf type=\"diffuse\" id=\"red\"><spectrum name=\"reflectance\" value=\"400:0, 550:0, 600:0.9, 700:0.9\"/></bsdf>\n"
      "<shape type=\"sphere\"><ref id=\"grey\"/><ref id=\"lamp\"/></shape>\n"
      "<shape type=\"sphere\"><ref id=\"red\"/><float name=\"radius\" value=\"2\"/></shape>\n"
      "<emitter type=\"area\" id=\"lamp\"><spectrum name=\"radiance\" value=\"2\"/></emitter>\n</scene>\n"));
  ASSERT_EQ(x.shapes.size(), 2u);
  const glm::vec3 grey = std::get<Diffuse>(x.materials[static_cast<std::size_t>(x.shapes[0].material)]).albedo;
  EXPECT_LT(glm::length(grey - glm::vec3(0.5f)), 1e-5f) << grey.x << " " << grey.y << " " << grey.z;
  const glm::vec3 red = std::get<Diffuse>(x.materials[static_cast<std::size_t>(x.shapes[1].material)]).albedo;
  EXPECT_GT(red.x, 0.5f);
  EXPECT_LT(red.z, 0.02f);
  EXPECT_GT(red.x, 4.0f * red.y);
  for (int c = 0; c < 3; ++c)  // Mitsuba's sRGB matrix against ours (the sRGB primaries with these tables' D65 white): within 2e-4
    EXPECT_NEAR(x.shapes[0].emission[c], 2.0f * glm::vec3(1.20494f, 0.948373f, 0.908632f)[c], 4e-4f) << c;
  EXPECT_EQ(x.shapes[1].emission, glm::vec3(0.0f));
  const std::vector<std::pair<std::string, std::string>> refused = {
      {"400:0.5, 300:0.5", "the spectrum's wavelengths must increase, found 300:0.5 after 400.000000"},
      {"400:0.5", "a sampled spectrum needs at least two wavelength:value pairs"},
      {"400:0.5, 500:x", "bad spectrum entry '500:x', expected wavelength:value"},
      {"400:0.5, 500:-1", "a reflectance spectrum must be non-negative"},
  };
  for (const auto& [value, message] : refused) {
    const Result<Scene> s = load_scene_file(write("bad-spectrum.xml", head + "<emitter type=\"point\"/>\n<shape type=\"sphere\">\n  <bsdf type=\"diffuse\">"
                                                  "<spectrum name=\"reflectance\" value=\"" + value + "\"/></bsdf>\n</shape>\n</scene>\n"));
    ASSERT_FALSE(s.ok()) << value;
    EXPECT_EQ(relative(s.error().where), "bad-spectrum.xml:5:24") << value;
    EXPECT_EQ(s.error().message, message);
  }
}

}  // namespace
}  // namespace pathex
