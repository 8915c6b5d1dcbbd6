// pathex bias against closed forms and against the renders it is made of (issue 18), with fixed
// seeds; statistical tolerances are stated in standard errors (batch means over 32 batches).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <set>

#include <glm/glm.hpp>

#include "automata/ops.h"
#include "bias/bias.h"
#include "classify/classifier.h"
#include "io/profile_json.h"
#include "reach/query.h"
#include "scene/scene.h"
#include "scene/universe.h"
#include "support/load_scene.h"
#include "support/stat_seed.h"

namespace pathex {
namespace {

constexpr double kPi = 3.14159265358979323846;

std::string sample(const std::string& name) { return std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/" + name; }

using test::load;

Profile profile(const std::string& name) { return resolve_profile(name, Limits{}).expect("a built-in profile"); }

// The built-in classes but $all, as `pathex bias` uses them without --classes.
std::vector<const PathClass*> builtin_classes() {
  std::vector<const PathClass*> out;
  for (const auto& c : ClassTable::builtins().builtin_classes())
    if (c->name != "all") out.push_back(c.get());
  return out;
}

BiasRun bias(const Scene& scene, const std::string& renderer, std::uint64_t spp, const std::string& reference = "",
             std::uint64_t seed = 7) {
  BiasOptions o;
  o.spp = spp;
  o.seed = seed;
  const Profile r = profile(renderer);
  Result<Profile> ref = choose_reference(reference, scene, r, o);
  EXPECT_TRUE(ref.ok()) << (ref.ok() ? "" : ref.error().render());
  Result<BiasRun> run = run_bias(scene, "test", r, *ref, builtin_classes(), o);
  EXPECT_TRUE(run.ok()) << (run.ok() ? "" : run.error().render());
  if (run.ok()) {
    EXPECT_FALSE(run->report.undersampled);  // no renderer budget: no comparison
  }
  return std::move(*run);
}

// Does the profile sample the path? Decided from the strategies' definitions (no automata).
bool samples_path(const Profile& p, const std::string& path, std::optional<int> bound) {
  for (const Strategy& st : p.strategies)
    if (strategy_samples(st, path, bound)) return true;
  return false;
}

// --- point light, planar mirror, floor (samples/scenes/point-mirror-caustic.json) ---
// Pinhole at c looking at (0.3, 0, 0), fov 45°, square image; point light I = 4 at l; floor y = 0
// of albedo 0.7 (|x|, |z| ≤ 3); a mirror of reflectance 0.9 in the plane x = 1.2 (|z| ≤ 1,
// 0 ≤ y ≤ 1.5). Image means are integrals over the film (x, y in [-tan, tan]) / its area.
const glm::dvec3 kCam(-1.5, 2.2, 3.0), kLight(0.6, 0.8, 0.0), kImage(1.8, 0.8, 0.0);
const double kTan = std::tan(22.5 * kPi / 180.0), kI = 4.0, kRho = 0.7, kR = 0.9;

// The light seen directly (LSDDSE, sampled by splatting the light's own vertex): a point of
// intensity I at distance d, cos θ off the axis, puts I / (d² cos³θ) on the film (per unit film
// area at unit distance); the image mean divides by the film's area 4 tan².
double light_seen_directly() {
  const glm::dvec3 fwd = glm::normalize(glm::dvec3(0.3, 0, 0) - kCam);
  const glm::dvec3 v = kLight - kCam;
  const double d2 = glm::dot(v, v), cos_theta = glm::dot(v, fwd) / std::sqrt(d2);
  return kI / (d2 * cos_theta * cos_theta * cos_theta * 4.0 * kTan * kTan);
}

// DESIGN §9: the mirror's caustic (LSDSDDSE) is the floor lit by the light's mirror image (x = 1.8)
// with intensity R I, where the image's rays pass through the mirror's rectangle; the floor in
// front of the mirror (x < 1.2) is seen directly. Midpoint rule on an n × n grid over the film.
double mirror_caustic() {
  const glm::dvec3 fwd = glm::normalize(glm::dvec3(0.3, 0, 0) - kCam);
  const glm::dvec3 right = glm::normalize(glm::cross(fwd, glm::dvec3(0, 1, 0)));
  const glm::dvec3 up = glm::cross(right, fwd);
  const int n = 1500;
  double sum = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double fx = (2.0 * (i + 0.5) / n - 1.0) * kTan, fy = (2.0 * (j + 0.5) / n - 1.0) * kTan;
      const glm::dvec3 d = fwd + fx * right + fy * up;  // unit film distance: dA = cos³θ dω … as the camera weights it
      if (d.y >= 0) continue;
      const glm::dvec3 p = kCam + (-kCam.y / d.y) * d;
      if (p.x >= 1.2 || p.x < -3 || std::fabs(p.z) > 3) continue;
      const double t = (kImage.x - 1.2) / (kImage.x - p.x);  // where the segment image → p meets the mirror
      const double y = kImage.y + t * (p.y - kImage.y), z = kImage.z + t * (p.z - kImage.z);
      if (y < 0 || y > 1.5 || std::fabs(z) > 1) continue;
      const glm::dvec3 v = p - kImage;
      const double d2 = glm::dot(v, v);
      sum += kRho * kR * kI * (kImage.y / std::sqrt(d2)) / (kPi * d2);
    }
  return sum / (static_cast<double>(n) * n);
}

TEST(Bias, PtNeeMissesTheMirrorCausticAndTheLightItselfAsTheClosedFormsSay) {
  const Scene scene = load(sample("point-mirror-caustic.json"));
  // The reference is bdpt, named: the default adds the mirror connector once the tracer runs it,
  // and then also counts the light seen in the mirror.
  const BiasRun run = bias(scene, "pt-nee", 64, "bdpt");
  const BiasReport& r = run.report;
  EXPECT_EQ(r.reference, "bdpt");
  EXPECT_EQ(r.nonfinite_samples, 0u);
  EXPECT_FALSE(r.covered);
  // Exactly two paths carry what pt-nee misses: the light itself (deterministic: every splat of
  // the light's vertex lands with the same value) and the mirror's caustic on the floor.
  ASSERT_EQ(r.paths.size(), 2u);
  EXPECT_EQ(r.paths[0].estimate.path, "LSDDSE");
  EXPECT_EQ(r.paths[1].estimate.path, "LSDSDDSE");
  const double direct = light_seen_directly(), caustic = mirror_caustic();
  EXPECT_NEAR(r.paths[0].estimate.estimate.luminance, direct, 1e-4 * direct);
  const Estimate& c = r.paths[1].estimate.estimate;
  EXPECT_LE(std::fabs(c.luminance - caustic), 3.0 * c.std_error) << c.luminance << " ± " << c.std_error << " vs " << caustic;
  EXPECT_LE(std::fabs(r.missed.luminance - (direct + caustic)), 3.0 * r.missed.std_error + 1e-4 * direct)
      << r.missed.luminance << " ± " << r.missed.std_error;
  // Everything else pt-nee misses is the caustic: the $caustic class's missed light is the caustic path's, exactly.
  const auto cls = std::find_if(r.classes.begin(), r.classes.end(), [](const MissedClass& m) { return m.name == "caustic"; });
  ASSERT_NE(cls, r.classes.end());
  EXPECT_EQ(cls->missed.luminance, c.luminance);
  EXPECT_EQ(cls->verdict, Verdict::kUnreachable);
  ASSERT_TRUE(cls->witness.has_value());
  EXPECT_EQ(cls->witness->path, "LSDSDDSE");
  EXPECT_EQ(cls->witness->reason, "its DD joins (c3..c4) are not where pt-nee joins: (0, DD, 2..), (1, DD, 2..)");
  // The caustic seen in the mirror is a path bdpt cannot sample either: reported, not counted.
  ASSERT_FALSE(r.neither.empty());
  EXPECT_EQ(r.neither[0].path, "LSDSDSE");
  EXPECT_EQ(r.neither[0].reason, "no DD join: the point light fixes x0, x1 is specular and the pinhole camera fixes x2");
}

// The same samples: a plain bdpt render with the same seed, spp and bound, its paths that pt-nee
// cannot sample (decided from the strategies' definitions) sum to what bias reports.
TEST(Bias, MissedIsTheSumOfTheUnreachablePathsOfTheSameBdptRender) {
  const Scene scene = load(sample("point-mirror-caustic.json"));
  const BiasRun run = bias(scene, "pt-nee", 16, "bdpt");
  RenderOptions o;
  o.spp = 16;
  o.seed = 7;
  o.max_bounces = run.report.reference_bounces;
  Result<RenderOutput> out = render(scene, profile("bdpt"), nullptr, o);
  ASSERT_TRUE(out.ok());
  const HistogramReport plain = make_report(out->histogram, RunInfo{}, nullptr, {}).expect("a test input");
  const Profile pt_nee = profile("pt-nee");
  double unreachable = 0;
  for (const PathEstimate& p : plain.paths)
    if (!samples_path(pt_nee, p.path, std::nullopt)) unreachable += p.estimate.luminance;
  ASSERT_GT(unreachable, 0.0);
  EXPECT_NEAR(run.report.missed.luminance, unreachable, 1e-12);
  EXPECT_EQ(plain.total.luminance, run.report.total.luminance);  // the same samples, bit for bit
}

// --max-paths caps the rows: the missed paths past them are counted, their light is still in
// the missed total (an exact class sum), and histogram.json's "other" row sums the rest.
TEST(Bias, MaxPathsCapsTheRowsNotTheSums) {
  const Scene scene = load(sample("point-mirror-caustic.json"));
  BiasOptions o;
  o.spp = 4;
  o.max_paths = 1;
  const Profile r = profile("pt-nee");
  const BiasRun capped = run_bias(scene, "test", r, profile("bdpt"), builtin_classes(), o).expect("a run");
  ASSERT_EQ(capped.report.paths.size(), 1u);
  EXPECT_EQ(capped.report.paths[0].estimate.path, "LSDDSE");  // the largest row of the histogram
  EXPECT_EQ(capped.report.other_missed_paths, 1u);            // LSDSDDSE
  EXPECT_EQ(capped.histogram.paths.size(), 1u);
  ASSERT_TRUE(capped.histogram.other.has_value());
  o.max_paths = 1000;
  const BiasRun all = run_bias(scene, "test", r, profile("bdpt"), builtin_classes(), o).expect("a run");
  EXPECT_EQ(all.report.other_missed_paths, 0u);
  EXPECT_EQ(capped.report.missed.luminance, all.report.missed.luminance);
}

TEST(Bias, PtMissesNothingInTheCornellBoxAndEverythingUnderAPointLight) {
  const BiasRun cornell = bias(load(sample("cornell.json")), "pt", 4);
  EXPECT_TRUE(cornell.report.covered);
  EXPECT_EQ(cornell.report.missed.luminance, 0.0);  // exactly: the missed class is empty
  EXPECT_TRUE(cornell.report.paths.empty());
  EXPECT_GT(cornell.report.total.luminance, 0.0);
  EXPECT_TRUE(cornell.report.neither.size() > 0 || cornell.report.neither_finite);

  const BiasRun point = bias(load(sample("point-plane.json")), "pt", 4);
  EXPECT_FALSE(point.report.covered);
  EXPECT_GT(point.report.total.luminance, 0.0);
  EXPECT_EQ(point.report.missed.luminance, point.report.total.luminance);  // exact sums: every path
  EXPECT_EQ(point.report.share, 1.0);
}

// The missed image is the missed class's layer: its mean is the missed estimate.
TEST(Bias, MissedImageMeanIsTheMissedEstimate) {
  const BiasRun run = bias(load(sample("point-mirror-caustic.json")), "pt-nee", 4);
  const std::vector<ImageLayer> layers = run.render.images.layers(1.0 / static_cast<double>(run.render.spp_done));
  ASSERT_EQ(layers.back().name, kMissedClass);
  double sum = 0;
  for (std::size_t i = 0; i < layers.back().image.rgb.size(); i += 3)
    sum += luminance({layers.back().image.rgb[i], layers.back().image.rgb[i + 1], layers.back().image.rgb[i + 2]});
  const double mean = sum / static_cast<double>(layers.back().image.width * layers.back().image.height);
  EXPECT_NEAR(mean, run.report.missed.luminance, 1e-5 * run.report.missed.luminance);
}

// Every built-in real-integrator profile on every sample scene: the missed light is finite and
// non-negative, 0 exactly when the checker says the profile covers the scene's universe within the
// reference's bound, and otherwise the sum of the sampled paths the profile cannot sample.
TEST(Bias, RealIntegratorsOnEverySampleScene) {
  const char* const renderers[] = {"pbrt-v4-path", "pbrt-v4-bdpt", "pbrt-v4-lightpath", "mitsuba3-path", "mitsuba3-ptracer"};
  int scenes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(std::string(PATHEX_SOURCE_DIR) + "/samples/scenes")) {
    const std::string ext = entry.path().extension().string();
    if (!entry.is_regular_file() || (ext != ".json" && ext != ".pbrt" && ext != ".xml")) continue;
    Scene scene = load(entry.path().string());
    if (scene.camera.type != SensorType::kSpotmeter) scene.camera.width = scene.camera.height = 8;
    ++scenes;
    for (const char* name : renderers) {
      const std::string what = entry.path().filename().string() + " " + name;
      const BiasRun run = bias(scene, name, 4);
      const BiasReport& r = run.report;
      EXPECT_EQ(r.nonfinite_samples, 0u) << what;
      EXPECT_TRUE(std::isfinite(r.missed.luminance)) << what;
      EXPECT_GE(r.missed.luminance, 0.0) << what;
      // The checker's answer, asked independently: does the profile cover U_s within the bound?
      const Profile p = profile(name);
      const CompiledProfile cp = compile_profile(p, p.max_bounces, Limits{}).expect("a built-in profile");
      QueryOptions qo;
      qo.universe = dfa_intersect(scene_universe(scene_types(scene)), dfa_universe_bounded(r.reference_bounces));
      const PathClass all = compile_class("$all", ClassOptions{}).expect("a built-in class");
      const Verdict v = query(all, cp, qo).expect("a query").verdict;
      EXPECT_EQ(r.covered, v == Verdict::kReachable) << what;
      double outside = 0;
      bool any_outside = false;
      for (const PathEstimate& pe : run.histogram.paths)
        if (!samples_path(p, pe.path, p.max_bounces)) {
          outside += pe.estimate.luminance;
          any_outside = true;
        }
      EXPECT_NEAR(r.missed.luminance, outside, 1e-12 * std::max(1.0, r.total.luminance)) << what;
      EXPECT_EQ(r.missed.luminance == 0.0, v == Verdict::kReachable || !any_outside) << what;
      if (v == Verdict::kReachable) {
        EXPECT_EQ(r.missed.luminance, 0.0) << what;
      }
    }
  }
  EXPECT_GE(scenes, 12);
}

TEST(Bias, ReferenceIsBdptPlusTheConnectorsTheSceneNeeds) {
  const BiasOptions o;
  const Profile pt = profile("pt");
  // The Cornell box's mirror sphere puts interior S letters in its universe: the mirror and the
  // manifold connectors join the reference.
  EXPECT_EQ(choose_reference("", load(sample("cornell.json")), pt, o).expect("a reference").name, "bdpt+mirror+manifold");
  EXPECT_EQ(choose_reference("", load(sample("point-plane.json")), pt, o).expect("a reference").name, "bdpt");
  const Profile sun = choose_reference("", load(sample("sun-window.json")), pt, o).expect("a reference");
  EXPECT_EQ(sun.name, "bdpt+distant-projection");
  ASSERT_EQ(sun.strategies.size(), 2u);
  EXPECT_EQ(sun.strategies[1].describe(), "(0, DSD, 2..) via distant-projection");
  EXPECT_EQ(choose_reference("", load(sample("mirror-ortho.json")), pt, o).expect("a reference").name,
            "bdpt+mirror+ortho-projection+manifold");
}

// Per connector every widest strategy of the built-ins joins the reference: bdpt+manifold's t >= 2
// and its pinhole-ending t = 1 each sample paths the other cannot (pt-nee+manifold's (1, DS+D, 2..)
// lies within the first and stays out; so does pt-nee+mirror's within bdpt+mirror's).
TEST(Bias, ReferenceTakesEveryWidestStrategyOfAConnector) {
  const Profile ref = choose_reference("", load(sample("cornell.json")), profile("pt"), BiasOptions{}).expect("a reference");
  std::vector<std::string> described;
  for (const Strategy& st : ref.strategies) described.push_back(st.name + " " + st.describe());
  EXPECT_EQ(described, (std::vector<std::string>{"bdpt (0.., DD, 0..)", "mirror (1.., DSD, 1..) via mirror",
                                                  "manifold (1.., DS+D, 2..) via manifold",
                                                  "manifold-splat (1.., DS+D, 1) via manifold"}));
}

// The light seen in the planar mirror (LSDSDSE) is joined at t = 1 by two connectors of the default
// reference: the mirror's (exact: the light's image is one point) and the manifold's pinhole-ending
// join, weighed against each other by MIS. Their sum is the closed form, the light's image of
// intensity R I seen directly: R I / (d² cos³θ) over the film's area 4 tan² (the line of sight to
// the image crosses the mirror at (1.2, 1.05, 0.55), inside it).
TEST(Bias, TheReferencesTwoJoinsOfTheLightSeenInTheMirrorSumToTheClosedForm) {
  const BiasRun run = bias(load(sample("point-mirror-caustic.json")), "pt-nee", 64, "", test::stat_seed(7));
  const glm::dvec3 fwd = glm::normalize(glm::dvec3(0.3, 0, 0) - kCam);
  const glm::dvec3 v = kImage - kCam;
  const double d2 = glm::dot(v, v), cos_theta = glm::dot(v, fwd) / std::sqrt(d2);
  const double expected = kR * kI / (d2 * cos_theta * cos_theta * cos_theta * 4.0 * kTan * kTan);  // 0.295792
  const auto seen = std::find_if(run.report.paths.begin(), run.report.paths.end(),
                                 [](const MissedPath& p) { return p.estimate.path == "LSDSDSE"; });
  ASSERT_NE(seen, run.report.paths.end());
  const Estimate& e = seen->estimate.estimate;
  std::vector<std::string> techniques;
  for (const TechniqueEstimate& t : seen->estimate.strategies) techniques.push_back(t.name);
  EXPECT_EQ(techniques, (std::vector<std::string>{"mirror (1, DSD, 1)", "manifold-splat (1, DSD, 1)"}));
  EXPECT_GT(e.std_error, 0.0);  // the manifold's share is drawn at its rate
  EXPECT_LE(std::fabs(e.luminance - expected), 4.0 * e.std_error + 1e-6 * expected)
      << e.luminance << " ± " << e.std_error << " vs " << expected;
}

// Under a point light above a glass ball and a pinhole, the light seen through or in the ball
// (LSDSSDSE, LSDSDSE, …: x0 and the camera both fixed) is joined only by the manifold connector
// at t = 1. With it in the reference every path pt-nee misses is counted: none is left unknown
// (without it, LSDSSDSE, LSDSSSDSE, … were listed as paths neither can sample), and the light
// seen in the ball is measured.
TEST(Bias, TheReferenceCountsTheLightSeenInAndThroughGlassUnderAPointLight) {
  const BiasRun run = bias(load(sample("point-glass.json")), "pt-nee", 4);
  EXPECT_TRUE(run.report.neither.empty()) << run.report.neither.front().path;
  EXPECT_TRUE(run.report.neither_finite);
  const auto seen_in_ball = std::find_if(run.report.paths.begin(), run.report.paths.end(),
                                         [](const MissedPath& p) { return p.estimate.path == "LSDSDSE"; });
  ASSERT_NE(seen_in_ball, run.report.paths.end());
  EXPECT_GT(seen_in_ball->estimate.estimate.luminance, 0.0);
}

TEST(Bias, TheReferenceRendersDeeperThanTheRenderersBound) {
  EXPECT_EQ(reference_bound("pt", std::nullopt, std::nullopt).expect("a bound"), 16);
  EXPECT_EQ(reference_bound("pbrt-v4-path", 5, std::nullopt).expect("a bound"), 16);
  EXPECT_EQ(reference_bound("x", 12, std::nullopt).expect("a bound"), 20);
  EXPECT_EQ(reference_bound("x", 5, 6).expect("a bound"), 6);
  const Result<int> bad = reference_bound("pbrt-v4-path", 5, 5);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message,
            "--reference-bounces 5 must exceed pbrt-v4-path's bound of 5 interior vertices, or the light beyond that "
            "bound could not be counted");
  // What lies beyond pbrt-v4-path's maxdepth 5 is counted: in the closed sphere every bounce carries light.
  const BiasRun run = bias(load(sample("closed-sphere-point.json")), "pbrt-v4-path", 4);
  ASSERT_FALSE(run.report.paths.empty());
  EXPECT_GT(run.report.missed.luminance, 0.0);
  for (const MissedPath& p : run.report.paths)
    EXPECT_NE(p.reason.find("bounces exceed max_bounces 5"), std::string::npos) << p.estimate.path << ": " << p.reason;
}

// --- light a renderer can sample but under-samples (issue 36) ---
// samples/scenes/small-light-caustic.json: a lamp of radius 0.03 above a glass ball; the caustic
// on the floor (LDDSSDDSE) is reachable for pt-nee (a floor bounce through the glass that hits the
// lamp) but at 4 spp pt-nee never finds it and its stderr says 0 ± 0.
BiasRun undersampling(const std::string& renderer, std::uint64_t renderer_spp) {
  const Scene scene = load(sample("small-light-caustic.json"));
  BiasOptions o;
  o.spp = 256;  // the reference: at 64 spp its own caustic is a few heavy samples at some seeds
  o.seed = test::stat_seed(7);
  o.renderer_spp = renderer_spp;
  // pt-nee unsplit, the under-sampler of issue 36: its default, --splits auto, meets the caustic more
  // often (at this seed it did, and the stderr of that heavy sample admitted the difference).
  o.renderer_splits = 1;
  const Profile r = profile(renderer);
  Result<Profile> ref = choose_reference("bdpt", scene, r, o);  // bdpt samples the caustic from the lamp's side
  EXPECT_TRUE(ref.ok());
  Result<BiasRun> run = run_bias(scene, "test", r, *ref, builtin_classes(), o);
  EXPECT_TRUE(run.ok()) << (run.ok() ? "" : run.error().render());
  return std::move(*run);
}

TEST(Bias, UnderSampledLightIsFoundWhereTheStderrCannotSeeIt) {
  const BiasRun run = undersampling("pt-nee", 4);
  ASSERT_TRUE(run.report.undersampled);
  const UnderSampling& u = *run.report.undersampled;
  EXPECT_EQ(u.spp, 4u);
  EXPECT_EQ(u.seed, test::stat_seed(7) + 1);  // the reference's seed + 1
  EXPECT_EQ(u.dof, 16);   // 4 passes fill both replicates of the 16 pixel groups
  // Compared: the image, the five built-in classes, the reference's listed paths pt-nee can sample.
  // (Not a reference row that is not 0 with a stderr of 0: its few hits agreed exactly, no claim.)
  std::size_t reachable_rows = 0;
  for (const PathEstimate& p : run.histogram.paths)
    reachable_rows += p.path == "other" || (p.estimate.std_error == 0 && p.estimate.luminance != 0) ? 0 : 1;
  EXPECT_EQ(u.comparisons, static_cast<int>(1 + 5 + reachable_rows));  // pt-nee misses nothing here
  EXPECT_NEAR(u.each, 1 - std::pow(0.99, 1.0 / u.comparisons), 1e-15);
  auto flagged = [&](const std::string& name) -> const UnderSampled* {
    for (const UnderSampled& f : u.flagged)
      if (f.name == name) return &f;
    return nullptr;
  };
  // The caustic's main path: where pt-nee found nothing, z is the reference's own estimate over
  // its stderr, judged with the reference's 16 dof. Now and then (2 seeds in 50) pt-nee does meet
  // the path, and that rare, heavy sample gives its estimate a stderr that admits the difference;
  // then the caustic class is flagged instead, or with it. One of the two always is.
  const UnderSampled* path = flagged("LDDSSDDSE");
  const UnderSampled* caustic = flagged("caustic");
  EXPECT_TRUE(path != nullptr || caustic != nullptr);
  if (path != nullptr && path->renderer.luminance == 0) {
    EXPECT_TRUE(path->path);
    EXPECT_EQ(path->renderer.std_error, 0.0);
    EXPECT_NEAR(path->z, -path->reference.luminance / path->reference.std_error, 1e-6 * std::fabs(path->z));
    EXPECT_NEAR(path->dof, 16.0, 1e-9);
    EXPECT_GT(path->reference.luminance, 0.05 * run.report.total.luminance);  // a tenth of the image
  }
  if (caustic != nullptr) {
    EXPECT_FALSE(caustic->path);
    EXPECT_LT(caustic->z, 0);
  }
  // Every flag is significant at the stated level and at least min_share of the light.
  for (const UnderSampled& f : u.flagged) {
    EXPECT_GE(std::fabs(f.renderer.luminance - f.reference.luminance), u.min_difference) << f.name;
    EXPECT_GT(std::fabs(f.z), 4.0) << f.name;
  }
  EXPECT_NEAR(u.min_difference, 0.01 * run.report.total.luminance, 1e-12);  // pt-nee can sample it all
}

TEST(Bias, ACorrectRendererAtItsBudgetIsNotFlagged) {
  // lt samples the caustic from the lamp's side; at 64 spp its estimates agree with the
  // reference's (a false alarm here has probability 1 % by construction: Šidák over the comparisons).
  // Not bdpt: at 64 spp its image mean is bimodal here (0.221 ± 0.001 without a caustic firefly,
  // 0.23–0.25 with one, against 0.25), under-sampled as the check says once the reference's
  // stderr stops hiding it (issue 39's pixel groups: 3 flags in 60 seeds, bench/README.md).
  const BiasRun run = undersampling("lt", 64);
  ASSERT_TRUE(run.report.undersampled);
  EXPECT_GT(run.report.undersampled->comparisons, 20);
  EXPECT_TRUE(run.report.undersampled->flagged.empty())
      << run.report.undersampled->flagged.front().name << " z " << run.report.undersampled->flagged.front().z;
}

}  // namespace
}  // namespace pathex
