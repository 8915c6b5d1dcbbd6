// The hard-case suite (DESIGN §10, issue 13): the scenes of samples/scenes/hard/ (written by its
// make_scenes.py) rendered small and checked for finite values and against exact references —
// closed forms, or quadrature in double precision done here. Tolerances: 3 standard errors (batch
// means over 32 batches, fixed seeds) plus a stated relative slack for what the reference leaves
// out (float geometry, light leaking through 1e-6 gaps).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <iomanip>
#include <memory>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/cli_run.h"
#include "support/compare_estimates.h"
#include "support/stat_seed.h"
#include "support/test_classes.h"
#include "trace/render.h"

namespace pathex {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string hard(const std::string& name) { return std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/hard/" + name; }

struct Rendered {
  HistogramReport report;
  std::uint64_t nonfinite = 0;
};

// Renders a scene file with `renderer`, classifying by `classes` (full notation).
Rendered render_file(const std::string& file, const std::string& renderer, const std::vector<std::string>& classes,
                     std::uint64_t spp, std::optional<int> max_bounces = std::nullopt, std::uint64_t seed = test::stat_seed(7),
                     int replicates = 0) {
  Result<Scene> scene = load_scene_file(file);
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().render());
  if (!scene) return {};
  Result<Profile> profile = resolve_profile(renderer, Limits{});
  EXPECT_TRUE(profile.ok());
  const std::unique_ptr<test::TestClasses> tc = test::test_classes(classes);
  const std::vector<ClassInfo>& infos = tc->infos;
  const Classifier& classifier = *tc->classifier;
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.max_bounces = max_bounces.value_or(12);
  o.images = false;
  o.replicates = replicates;
  Result<RenderOutput> out = render(*scene, *profile, &classifier, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  if (!out) return {};
  RunInfo info;
  info.spp = spp;
  Result<HistogramReport> rep = make_report(out->histogram, info, &classifier, infos);
  EXPECT_TRUE(rep.ok());
  return Rendered{std::move(*rep), out->histogram.nonfinite()};
}

// test::expect_close: |estimate − expected| within `sigmas` standard errors plus `rel` of expected.
// Each test passes test::family_sigmas(its number of checks): a family-wise false-failure rate of
// 0.1 % (Šidák over Student's t with 16 dof), and its seed comes from test::stat_seed.
using test::expect_close;

// The mean over a square film of half-width w (tangent units) of f(x, y), with the substitution
// x = c sinh(s) per axis, which puts most nodes where a peak of width c at the film's centre is:
// the midpoint rule in s is then accurate for peaks from c = w down to c = 1e-4 w and below.
double film_mean(double w, double c, const std::function<double(double, double)>& f, int n = 1200) {
  const double s_max = std::asinh(w / c), ds = 2.0 * s_max / n;
  std::vector<double> xs(static_cast<std::size_t>(n)), ws(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const double s = -s_max + (i + 0.5) * ds;
    xs[static_cast<std::size_t>(i)] = c * std::sinh(s);
    ws[static_cast<std::size_t>(i)] = c * std::cosh(s) * ds;
  }
  double sum = 0.0;
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      sum += ws[static_cast<std::size_t>(i)] * ws[static_cast<std::size_t>(j)] * f(xs[static_cast<std::size_t>(i)], xs[static_cast<std::size_t>(j)]);
  return sum / (4.0 * w * w);
}

// --- GGX plane under a point light (samples/scenes/hard/ggx-point-*.json) ---
//
// The plane y = 0 (GGX, roughness alpha, Schlick Fresnel from R0 = 0.5, height-correlated Smith
// masking), a point light I = 1 at (0, 1, 0), a pinhole at (0, 2, 0) looking straight down. The
// film point (x, y) (tangent units) sees the plane at p = (2x, 0, -2y), whose radiance towards the
// camera is f(wo, wi) I cos θi / |light - p|². Written here from the textbook forms (Walter et al.
// 2007; Heitz 2014), in double precision, independently of trace/bsdf.cpp.
constexpr double kR0 = 0.5;

double ggx_radiance(double alpha, double x, double y) {
  const double px = 2 * x, pz = -2 * y;
  auto unit = [](double a, double b, double c, double* o) {
    const double l = std::sqrt(a * a + b * b + c * c);
    o[0] = a / l, o[1] = b / l, o[2] = c / l;
    return l;
  };
  double wo[3], wi[3], h[3];
  unit(-px, 2.0, -pz, wo);
  const double dl = unit(-px, 1.0, -pz, wi);
  unit(wo[0] + wi[0], wo[1] + wi[1], wo[2] + wi[2], h);
  const double a2 = alpha * alpha;
  const double sin2h = h[0] * h[0] + h[2] * h[2], cos2h = h[1] * h[1];
  const double d = a2 / (kPi * (a2 * cos2h + sin2h) * (a2 * cos2h + sin2h));
  auto lambda = [&](const double* w) {
    const double tan2 = (w[0] * w[0] + w[2] * w[2]) / (w[1] * w[1]);
    return 0.5 * (-1.0 + std::sqrt(1.0 + a2 * tan2));
  };
  const double g2 = 1.0 / (1.0 + lambda(wo) + lambda(wi));
  const double cos_oh = wo[0] * h[0] + wo[1] * h[1] + wo[2] * h[2];
  const double fresnel = kR0 + (1.0 - kR0) * std::pow(1.0 - cos_oh, 5);
  const double f = fresnel * d * g2 / (4.0 * wo[1] * wi[1]);
  return f * wi[1] / (dl * dl);
}

// The image mean of a film of half-width w.
double ggx_image_mean(double alpha, double w) {
  return film_mean(w, alpha / 1.5, [&](double x, double y) { return ggx_radiance(alpha, x, y); });
}

std::string alpha_name(double alpha) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", alpha);
  return buf;
}

// pbrt-v3 reads +5.2 % at alpha = 0.001 (issue 13); pathex agrees with the quadrature at every
// alpha, with next-event estimation (pt-nee) and with bdpt's MIS of it and light tracing: 8 checks,
// 0.1 % together, plus 1e-3 of the value for the quadrature.
//
// The stderr from one group of 32 replicates (31 degrees of freedom, `--replicates 32`), not the
// default 16 pixel groups of two: the highlight's peak lies in a few of the 16 x 16 pixels, whose
// two replicates carry nearly all the variance, so the default stderr had one to three effective
// degrees of freedom (bdpt at alpha 0.01, 64 spp: its square's relative spread over 60 seeds 1.15,
// implying 1.5; z of 4.1 among them) and issue 36's sweep failed 2 of 100 seeds (bdpt at alpha
// 0.01 and 0.001 at once, 7.8 and 10σ: the scenes are scaled copies, so one seed's renders agree
// in their error). With every replicate spanning every pixel: 30 (pt-nee, 64 spp) and 23 (bdpt,
// 512 spp) implied, the largest of 40-50 z 2.7 and 2.5. bdpt takes 512 spp: at 64, 32 replicates
// of 2 Sobol points each spread it 4 % (0.3 % at 512).
TEST(GgxPlane, AgreesWithQuadratureAtEveryAlpha) {
  for (double alpha : {0.1, 0.01, 0.001, 1e-4}) {
    const double expected = ggx_image_mean(alpha, 10.0 * alpha);
    for (const char* renderer : {"pt-nee", "bdpt"}) {
      const std::uint64_t spp = std::string(renderer) == "bdpt" ? 512 : 64;
      const Rendered r = render_file(hard("ggx-point-" + alpha_name(alpha) + ".json"), renderer, {"LSDDDSE"}, spp, std::nullopt,
                                     test::stat_seed(7), kDefaultBatches);
      EXPECT_EQ(r.nonfinite, 0u);
      ASSERT_EQ(r.report.classes.size(), 1u);
      EXPECT_EQ(r.report.classes[0].estimate.dof, kDefaultBatches - 1);
      const Estimate& e = r.report.classes[0].estimate;
      test::stat_log(std::string(renderer) + " alpha " + alpha_name(alpha), (e.luminance - expected) / e.std_error,
                     test::family_sigmas(8, 1e-3, kDefaultBatches - 1));
      expect_close(e, expected, test::family_sigmas(8, 1e-3, kDefaultBatches - 1), 1e-3,
                   std::string(renderer) + " alpha " + alpha_name(alpha));
    }
  }
}

// As alpha -> 0 the lobe integrates to the mirror's image of the light: over the whole film,
// ∫ L dx dy -> F(0) I / D² with D = 3 the unfolded distance and F(0) = R0 (G2 -> 1). The narrow
// scenes' films (half-width 10 alpha) hold the same fraction of it at every small alpha.
TEST(GgxPlane, ConvergesToTheMirrorAsAlphaVanishes) {
  const double mirror = kR0 * 1.0 / 9.0;
  const double whole = ggx_image_mean(1e-4, 1.0) * 4.0;  // film half-width 1: all of the lobe
  EXPECT_NEAR(whole, mirror, 1e-5 * mirror);
  const double fraction_3 = ggx_image_mean(1e-3, 1e-2) * 4e-4 / mirror;
  const double fraction_4 = ggx_image_mean(1e-4, 1e-3) * 4e-6 / mirror;
  EXPECT_NEAR(fraction_3, fraction_4, 1e-4);
  EXPECT_GT(fraction_4, 0.98);  // the r^-4 tails beyond 10 alpha
  // And the render at alpha = 1e-4 is that fraction of the mirror's image.
  const Rendered r = render_file(hard("ggx-point-0.0001.json"), "pt-nee", {"LSDDDSE"}, 64);
  expect_close(r.report.classes[0].estimate, fraction_4 * mirror / 4e-6, test::family_sigmas(1), 1e-3, "alpha 1e-4 against the mirror");
}

// The near-delta scene that `pathex converge` flags declares its reference: this quadrature.
TEST(GgxPlane, DeclaredReferenceOfTheNearDeltaSceneIsTheQuadrature) {
  Result<Scene> scene = load_scene_file(hard("ggx-point-wide-0.001.json"));
  ASSERT_TRUE(scene.ok()) << scene.error().render();
  ASSERT_TRUE(scene->reference.has_value());
  const double expected = ggx_image_mean(1e-3, std::tan(30.0 * kPi / 180.0));
  EXPECT_NEAR(scene->reference->classes.at(0).luminance, expected, 1e-6 * expected) << std::setprecision(17) << expected;
}

// --- grazing configurations: cos θ about 1e-6 at the light, the surface and the sensor ---

// A point light 1e-6 above the plane, seen from (1, 1, 0) straight down: every ray from the light
// to what the camera sees leaves at cos θ ≈ 1e-6 to the plane and meets it at the same cosine.
TEST(Grazing, PointLightJustAboveThePlane) {
  const double h = 1e-6, rho = 0.5, w = std::tan(10.0 * kPi / 180.0);
  const double expected = film_mean(w, w, [&](double x, double y) {
    const double px = 1 + x, pz = -y, d2 = px * px + h * h + pz * pz;
    return rho * h / (kPi * d2 * std::sqrt(d2));
  }, 200);
  for (const char* renderer : {"pt-nee", "bdpt"}) {
    const Rendered r = render_file(hard("grazing-light.json"), renderer, {"LSDDDSE"}, 32);
    EXPECT_EQ(r.nonfinite, 0u);
    expect_close(r.report.classes[0].estimate, expected, test::family_sigmas(2), 1e-3, renderer);
  }
}

// Sunlight at cos θ = 1e-6 to the plane: L = rho E cos θ / pi at every pixel. The distant-projection
// connector samples it exactly; light tracing (lt, bdpt) lands no splat in view at 16 spp, which
// its stderr of 0 reports as certainty (what `pathex converge` flags).
TEST(Grazing, SunlightAtTheSurface) {
  const double expected = 0.5 * 1e-6 / kPi;
  for (const char* renderer : {"pt-nee+distant", "pbrt-v4-path"}) {
    const Rendered r = render_file(hard("grazing-surface.json"), renderer, {"LDSDDSE"}, 16);
    EXPECT_EQ(r.nonfinite, 0u);
    expect_close(r.report.classes[0].estimate, expected, test::family_sigmas(2), 1e-3, renderer);
  }
}

// A pinhole 1e-6 above the plane, looking along it: the lower half of the image sees the plane
// (radiance rho E / pi, at cosines down to 1e-6), the upper half nothing. What the lower half sees
// lies within about 1e-4 of the camera's foot, which light tracing almost never reaches.
TEST(Grazing, SensorJustAboveThePlane) {
  const double expected = 0.5 / kPi / 2.0;
  for (const char* renderer : {"pt-nee+distant", "pbrt-v4-path"}) {
    const Rendered r = render_file(hard("grazing-sensor.json"), renderer, {"LDSDDSE"}, 16);
    EXPECT_EQ(r.nonfinite, 0u);
    expect_close(r.report.classes[0].estimate, expected, test::family_sigmas(2), 1e-4, renderer);
  }
}

// --- vertices that almost touch; albedo 1 in a closed box ---

// Six emitting walls of albedo 1 with gaps of 1e-6 at every edge and corner: paths with n bounces
// carry Le = 1 at every pixel (what leaks through the gaps is about 1e-6 of it), for every n up to
// the bound. Russian roulette never stops a path of albedo 1; the bound does.
TEST(NearlyTouching, WhiteFurnaceBoxWithGapsOfOneMillionth) {
  std::vector<std::string> classes;
  for (int n = 0; n <= 4; ++n) classes.push_back("LDDD{" + std::to_string(n) + "}DSE");
  for (const char* renderer : {"pt", "pt-nee", "bdpt"}) {
    const Rendered r = render_file(hard("white-box-gaps.json"), renderer, classes, 64, 4);
    EXPECT_EQ(r.nonfinite, 0u);
    for (int n = 0; n <= 4; ++n)
      expect_close(r.report.classes[static_cast<std::size_t>(n)].estimate, 1.0, test::family_sigmas(18), 1e-4,
                   std::string(renderer) + " n=" + std::to_string(n));
    expect_close(r.report.total, 5.0, test::family_sigmas(18), 1e-4, std::string(renderer) + " total");
  }
}

// --- scale and position ---

// The Cornell box scaled by 1e-4 and 1e+4 and moved 1e+5 from the origin renders the same image:
// each class and the total against the unit box's by the shared comparison rule (15 checks, 0.1 %
// together). The renders share a seed, so they differ by far less than their errors would allow
// renders with numbers of their own; a scale that changed what the walk meets would still show.
TEST(ScaleAndPosition, CornellBoxIsTheSameImage) {
  const std::vector<std::string> classes = {"L.*DD.*E", "L..S+D.*..E", "L.....E", "L......+E"};
  const Rendered unit = render_file(hard("cornell-16.json"), "pt-nee", classes, 16);
  std::vector<test::Comparison> comparisons;  // by the shared rule (tests/support/compare_estimates.h), 15 at 0.1 %
  for (const char* name : {"cornell-1e-4.json", "cornell-1e+4.json", "cornell-moved-1e+5.json"}) {
    const Rendered r = render_file(hard(name), "pt-nee", classes, 16);
    EXPECT_EQ(r.nonfinite, 0u) << name;
    for (std::size_t i = 0; i <= classes.size(); ++i) {
      const Estimate& a = i < classes.size() ? unit.report.classes[i].estimate : unit.report.total;
      const Estimate& b = i < classes.size() ? r.report.classes[i].estimate : r.report.total;
      comparisons.push_back(test::compare(std::string(name) + " " + (i < classes.size() ? classes[i] : "total"), b, a));
    }
  }
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

// --- degenerate input ---

// Degenerate triangles (a repeated vertex, collinear points), a zero-area emissive triangle and a
// zero-power point light inside the closed sphere of DESIGN §9 change nothing: n bounces still
// carry rho^n I / (pi r^2).
TEST(Degenerate, TrianglesZeroAreaAndZeroPowerLightsChangeNothing) {
  std::vector<std::string> classes;
  for (int n = 1; n <= 3; ++n) classes.push_back("LSDD{" + std::to_string(n) + "}DSE");
  for (const char* renderer : {"pt-nee", "bdpt"}) {
    const Rendered r = render_file(hard("degenerate.json"), renderer, classes, 64);
    EXPECT_EQ(r.nonfinite, 0u);
    for (int n = 1; n <= 3; ++n)
      expect_close(r.report.classes[static_cast<std::size_t>(n - 1)].estimate, std::pow(0.5, n) / kPi, test::family_sigmas(6), 1e-3,
                   std::string(renderer) + " n=" + std::to_string(n));
  }
}

// --- long specular chains ---

// Ten glass interfaces at normal incidence: the light seen through all of them is Le T^10 with
// T = 1 - ((1.5 - 1) / (1.5 + 1))^2 = 0.96 (radiance's eta^2 cancels slab by slab). Total internal
// reflection is checked per interface in bsdf_test (Fresnel.TotalInternalReflectionBeyondTheCriticalAngle).
TEST(SpecularChains, TenGlassInterfacesTransmitTToTheTenth) {
  for (const char* renderer : {"pt", "bdpt"}) {
    const Rendered r = render_file(hard("ten-glass-interfaces.json"), renderer, {"LDDS{10}DSE"}, 64, 16);
    EXPECT_EQ(r.nonfinite, 0u);
    expect_close(r.report.classes[0].estimate, std::pow(0.96, 10), test::family_sigmas(2), 1e-4, renderer);
  }
}

// Total internal reflection in a render: a pinhole inside glass looks up at 60 degrees from the
// interface's normal, beyond the critical angle asin(1 / 1.5) = 41.8 degrees (scene comment). The
// reflectance there is exactly 1 and nothing is transmitted, so every pixel sees the emitter below
// (Le = 0.5) alone: LDDSDSE is 0.5 and is the whole image; the brighter emitter above (Le = 1),
// which a transmitted share would add, contributes nothing.
TEST(SpecularChains, TotalInternalReflectionReflectsAllAndTransmitsNothing) {
  for (const char* renderer : {"pt", "pt-nee", "bdpt"}) {
    const Rendered r = render_file(hard("total-internal-reflection.json"), renderer, {"LDDSDSE"}, 16);
    EXPECT_EQ(r.nonfinite, 0u) << renderer;
    expect_close(r.report.classes[0].estimate, 0.5, test::family_sigmas(6), 1e-6, renderer);
    expect_close(r.report.total, 0.5, test::family_sigmas(6), 1e-6, renderer);
  }
}

// --- non-finite samples are failures ---

// A legal scene whose contributions all exceed the fixed-point range (a 1e9 W/sr point light inside
// a sphere of radius 1e-4): trace warns, naming the strategy and path of the first, and a check
// file's {"finite": true} fails with the same words.
TEST(Nonfinite, TraceWarnsAndTheCheckFails) {
  const std::string dir = (test::scratch_dir() / "nonfinite").string();
  const test::CliRun t = test::run_pathex("trace samples/scenes/hard/nonfinite-hot-sphere.json --renderer pt-nee --spp 4 --no-images --out " + dir);
  EXPECT_EQ(t.code, 0);
  EXPECT_NE(t.err.find("pathex: warning: "), std::string::npos) << t.err;
  EXPECT_NE(t.err.find("non-finite samples (dropped; any is a bug); the first from strategy nee on path LSDDDSE"), std::string::npos) << t.err;
  const std::string check = (test::scratch_dir() / "finite.json").string();
  {
    std::ofstream f(check);
    f << R"({"cases": [{"name": "hot", "renderer": "pt-nee", "scene": ")" << PATHEX_SOURCE_DIR
      << R"(/samples/scenes/hard/nonfinite-hot-sphere.json", "require": [{"finite": true, "spp": 4}]},
                      {"name": "sphere", "renderer": "bdpt", "scene": ")" << PATHEX_SOURCE_DIR
      << R"(/samples/scenes/closed-sphere-point.json", "require": [{"finite": true}]}]})";
  }
  const test::CliRun c = test::run_pathex("check " + check);
  EXPECT_EQ(c.code, 1) << c.out << c.err;
  EXPECT_NE(c.out.find("FAIL  hot: renders finite (4 spp, seed 1) ("), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("non-finite samples; the first from strategy nee on path LSDDDSE)"), std::string::npos) << c.out;
  EXPECT_NE(c.out.find("PASS  sphere: renders finite (16 spp, seed 1) (no non-finite sample)"), std::string::npos) << c.out;
}

// The first non-finite sample the warning names is the earliest by (pass, row, column) of the
// sample that made it, whatever the thread count (it was the first a thread recorded, at the pass in
// progress when its shadow rays were traced: pass 3 with one thread, pass 0 at (0, 2) with two).
TEST(Nonfinite, TheFirstNamedIsTheSameForEveryThreadCount) {
  for (const char* threads : {"1", "2", "3"}) {
    const std::string dir = (test::scratch_dir() / (std::string("nonfinite-threads-") + threads)).string();
    const test::CliRun t = test::run_pathex("trace samples/scenes/hard/nonfinite-hot-sphere.json --renderer pt-nee --spp 4 --no-images --threads " +
                                            std::string(threads) + " --out " + dir);
    EXPECT_EQ(t.code, 0);
    EXPECT_NE(t.err.find("257 non-finite samples (dropped; any is a bug); the first from strategy nee on path LSDDDSE (near pixel (0, 0), pass 0)"),
              std::string::npos)
        << threads << " threads: " << t.err;
  }
}

TEST(Nonfinite, FiniteRequirementNeedsASceneAndOnlyItsKeys) {
  const std::string check = (test::scratch_dir() / "finite-bad.json").string();
  {
    std::ofstream f(check);
    f << R"({"cases": [{"name": "x", "renderer": "bdpt", "require": [{"finite": true}]}]})";
  }
  test::CliRun c = test::run_pathex("check " + check);
  EXPECT_EQ(c.code, 2);
  EXPECT_EQ(c.err, "pathex: error: " + check + ":/cases/0/scene: a finite requirement renders the case's scene: expected a scene file path\n");
  {
    std::ofstream f(check);
    f << R"({"cases": [{"name": "x", "renderer": "bdpt", "scene": "s.json", "require": [{"finite": true, "class": "L.*E"}]}]})";
  }
  c = test::run_pathex("check " + check);
  EXPECT_EQ(c.code, 2);
  EXPECT_EQ(c.err, "pathex: error: " + check + ":/cases/0/require/0/class: unknown key 'class', expected finite with optional spp and seed\n");
}

}  // namespace
}  // namespace pathex
