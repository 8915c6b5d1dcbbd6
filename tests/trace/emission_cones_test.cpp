// Emission aimed at the shapes a requested path can reach first (trace/emission_cones.h, issue 14):
// the cones' density against their sampling, their cover of the targets, when they are refused, and
// in renders: when --only aims a light, and that the caustic keeps its value with less variance.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "classify/classifier.h"
#include "classify/pathclass.h"
#include "stats/histogram.h"
#include "io/profile_json.h"
#include "support/compare_estimates.h"
#include "support/stat_seed.h"
#include "trace/plan.h"
#include "trace/prune.h"
#include "scene/scene.h"
#include "scene/universe.h"
#include "trace/emission_cones.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex {
namespace {

constexpr float kFourPi = 4.0f * kPi;

glm::vec2 uniform2(std::mt19937_64& g) {
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  return {std::min(u(g), kOneMinusEpsilon), std::min(u(g), kOneMinusEpsilon)};
}

// Two overlapping spheres and a third apart, seen from the origin.
const std::vector<BoundingSphere> kTargets = {{{0.0f, 2.0f, 0.0f}, 0.5f}, {{0.3f, 2.1f, 0.1f}, 0.4f}, {{-1.0f, -0.5f, 3.0f}, 0.2f}};

TEST(EmissionCones, SampledDensityIsThePdfAndTheEstimatorIsUnbiased) {
  const std::optional<EmissionCones> cones = EmissionCones::make(glm::vec3(0.0f), kTargets);
  ASSERT_TRUE(cones.has_value());
  EXPECT_EQ(cones->size(), 3u);
  std::mt19937_64 g(test::stat_seed(7));
  // The density sample() reports is pdf(w), up to a direction rounding left a hair outside a cone.
  constexpr int kN = 200000;
  int mismatches = 0;
  // f(w) = 1 + w.x², on the cones' union: E_p[f / p] is its integral over the union.
  double sum_p = 0, sum2_p = 0;
  for (int i = 0; i < kN; ++i) {
    float pdf = 0.0f;
    const glm::vec3 w = cones->sample(uniform2(g), &pdf);
    EXPECT_NEAR(glm::length(w), 1.0f, 1e-5f);
    ASSERT_GT(pdf, 0.0f);
    if (pdf != cones->pdf(w)) ++mismatches;
    const double f = (1.0 + static_cast<double>(w.x) * w.x) / pdf;
    sum_p += f;
    sum2_p += f * f;
  }
  EXPECT_LE(mismatches, kN / 10000);
  // The same integral by directions uniform over the sphere.
  double sum_u = 0, sum2_u = 0;
  for (int i = 0; i < kN; ++i) {
    const glm::vec3 w = sample_uniform_sphere(uniform2(g));
    const double f = cones->pdf(w) > 0.0f ? (1.0 + static_cast<double>(w.x) * w.x) * kFourPi : 0.0;
    sum_u += f;
    sum2_u += f * f;
  }
  const auto mean_var = [](double s, double s2) {
    const double m = s / kN;
    return std::pair<double, double>{m, (s2 / kN - m * m) / kN};
  };
  const auto [mp, vp] = mean_var(sum_p, sum2_p);
  const auto [mu, vu] = mean_var(sum_u, sum2_u);
  EXPECT_GT(mp, 0.05);
  // Two checks below, each of means of 200,000 samples (near normal): 0.1 % family-wise.
  const double k = test::family_sigmas(2, 1e-3, 1 << 20);
  test::stat_log("aimed against uniform", (mp - mu) / std::sqrt(vp + vu), k);
  EXPECT_LE(std::fabs(mp - mu), k * std::sqrt(vp + vu)) << "aimed " << mp << ", uniform " << mu;
  // And the density integrates to 1 over the sphere (E_uniform[4π p(w)]).
  double sum_pdf = 0, sum2_pdf = 0;
  for (int i = 0; i < kN; ++i) {
    const double v = kFourPi * cones->pdf(sample_uniform_sphere(uniform2(g)));
    sum_pdf += v;
    sum2_pdf += v * v;
  }
  const auto [m1, v1] = mean_var(sum_pdf, sum2_pdf);
  test::stat_log("density integral", (m1 - 1.0) / std::sqrt(v1), k);
  EXPECT_LE(std::fabs(m1 - 1.0), k * std::sqrt(v1)) << m1;
}

TEST(EmissionCones, EveryPointOfATargetIsInACone) {
  const glm::vec3 origin(0.2f, -0.1f, 0.05f);
  const std::optional<EmissionCones> cones = EmissionCones::make(origin, kTargets);
  ASSERT_TRUE(cones.has_value());
  std::mt19937_64 g(3);
  for (const BoundingSphere& b : kTargets)
    for (int i = 0; i < 20000; ++i) {
      // Points on the sphere itself: its silhouette is the cone's rim.
      const glm::vec3 p = b.center + b.radius * sample_uniform_sphere(uniform2(g));
      EXPECT_GT(cones->pdf(glm::normalize(p - origin)), 0.0f) << p.x << " " << p.y << " " << p.z;
    }
  // A direction away from every target is not.
  EXPECT_EQ(cones->pdf(glm::vec3(0.0f, -1.0f, 0.0f)), 0.0f);
  // The share of the sphere: two caps overlapping and a small one.
  EXPECT_GT(cones->share(), 0.0f);
  EXPECT_LT(cones->share(), 0.1f);
}

TEST(EmissionCones, RefusedWhereAimingLeavesNoDirectionOut) {
  EXPECT_FALSE(EmissionCones::make(glm::vec3(0.0f), {}).has_value());
  // The light inside a target (its bounding sphere).
  EXPECT_FALSE(EmissionCones::make(glm::vec3(0.0f, 1.8f, 0.0f), kTargets).has_value());
  // Cones whose solid angles add up to the whole sphere.
  std::vector<BoundingSphere> around;
  for (const glm::vec3 c : {glm::vec3(1.2f, 0, 0), glm::vec3(-1.2f, 0, 0), glm::vec3(0, 1.2f, 0), glm::vec3(0, -1.2f, 0),
                            glm::vec3(0, 0, 1.2f), glm::vec3(0, 0, -1.2f)})
    around.push_back({c, 1.0f});
  EXPECT_FALSE(EmissionCones::make(glm::vec3(0.0f), around).has_value());
}

// --- in renders ---

const std::string kScenes = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes/";

struct ClassRender {
  Estimate estimate;
  std::vector<AimedLight> aimed;
};

ClassRender render_class(const Scene& scene, const std::string& renderer, const std::string& expr, bool only, std::uint64_t seed,
                         std::uint64_t spp) {
  const SceneTypes types = scene_types(scene);
  ClassOptions co;
  co.ends.lights.assign(types.lights.begin(), types.lights.end());
  co.ends.sensors = {types.sensor};
  auto c = std::make_unique<PathClass>(compile_class(expr, co).expect("a test class"));
  c->name = expr;
  const std::vector<const PathClass*> classes = {c.get()};
  const Classifier cl = Classifier::build(classes, Limits{}).expect("a classifier");
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.max_bounces = 10;
  o.images = false;
  o.threads = 1;
  Profile profile = resolve_profile(renderer, Limits{}).expect("a profile");
  const RenderOutput out =
      (only ? render(scene, plan_render(scene, profile, 10, classes, Limits{}).expect("a plan"), &cl, o) : render(scene, profile, &cl, o))
          .expect("a render");
  const HistogramReport rep = make_report(out.histogram, RunInfo{}, &cl, {{expr, expr}}).expect("a report");
  return {rep.classes.at(0).estimate, out.aimed};
}

Scene scene_at(const std::string& name, int size) {
  Scene s = load_scene_file(kScenes + name).expect("a sample scene");
  s.camera.width = size;
  s.camera.height = size;
  return s;
}

// A point light above a glass sphere: --only '$caustic' aims it at the sphere and the pyramid (the
// shapes with a specular component); the caustic keeps its value (4σ) and its variance falls.
TEST(AimedEmission, PointLightCausticKeepsItsValueWithLessVariance) {
  const Scene scene = scene_at("point-glass.json", 24);
  const ClassRender full = render_class(scene, "bdpt", "$caustic", false, test::stat_seed(21), 32);
  const ClassRender only = render_class(scene, "bdpt", "$caustic", true, test::stat_seed(21) + 1, 32);
  EXPECT_TRUE(full.aimed.empty());
  ASSERT_EQ(only.aimed.size(), 1u);
  EXPECT_EQ(only.aimed[0].light, 0);
  EXPECT_EQ(only.aimed[0].kind, "point");
  EXPECT_EQ(only.aimed[0].shapes, 2u);
  EXPECT_GT(only.aimed[0].share, 0.02f);
  EXPECT_LT(only.aimed[0].share, 0.08f);
  // The shared rule (tests/support/compare_estimates.h), one check at 0.1 %.
  for (const std::string& failure : test::family_failures({test::compare("full against only", full.estimate, only.estimate)}))
    ADD_FAILURE() << failure;
  // 3 % of the directions reach the sphere: the variance falls about 50-fold (measured 56x).
  EXPECT_LT(only.estimate.std_error, full.estimate.std_error / 3.0);
}

// The same with a spot light (its falloff weighs the aimed directions) pointing at the sphere.
TEST(AimedEmission, SpotLightCausticKeepsItsValue) {
  Scene scene = scene_at("point-glass.json", 24);
  const PointLight p = std::get<PointLight>(scene.lights.at(0));
  SpotLight spot;
  spot.position = p.position;
  spot.direction = glm::vec3(0.0f, -1.0f, 0.0f);
  spot.intensity = p.intensity;
  spot.cone_degrees = 30.0f;
  scene.lights = {spot};
  const ClassRender full = render_class(scene, "bdpt", "$caustic", false, test::stat_seed(31), 32);
  const ClassRender only = render_class(scene, "bdpt", "$caustic", true, test::stat_seed(31) + 1, 32);
  ASSERT_EQ(only.aimed.size(), 1u);
  EXPECT_EQ(only.aimed[0].kind, "spot");
  EXPECT_GT(full.estimate.luminance, 0.0);
  for (const std::string& failure : test::family_failures({test::compare("full against only", full.estimate, only.estimate)}))
    ADD_FAILURE() << failure;
}

// Aimed emission is a decorator over the light's own sampling (RenderLight::sample_ray and
// pdf_ray): the ray it draws has the density its pdf reports, the light's origin and its emission
// that way, for a point and a spot light.
TEST(AimedEmission, TheDecoratorDrawsWhatItsDensitySays) {
  const std::optional<EmissionCones> cones = EmissionCones::make(glm::vec3(0.0f), kTargets);
  ASSERT_TRUE(cones.has_value());
  const PointLightParams point{glm::vec3(0.0f), glm::vec3(2.0f)};
  const SpotLightParams spot{glm::vec3(0.0f), glm::vec3(0.0f, 1.0f, 0.0f), glm::vec3(3.0f), std::cos(0.5f), std::cos(0.3f), false};
  std::mt19937_64 g(7);
  for (const LightParams& l : {LightParams(point), LightParams(spot)}) {
    RenderLight light;
    light.params = l;
    light.aim = cones;
    int drawn = 0;
    for (int i = 0; i < 2000; ++i) {
      const glm::vec2 u = uniform2(g);
      const std::optional<EndpointRay> r = light.sample_ray({}, u);
      if (!r) continue;  // outside the spot's cone
      ++drawn;
      const RayPdf p = light.pdf_ray({}, r->direction);
      EXPECT_FALSE(p.delta_dir);
      EXPECT_TRUE(p.delta_pos);
      EXPECT_NEAR(p.dir, r->pdf.dir, 1e-6f * r->pdf.dir);
      EXPECT_NEAR(r->pdf.dir, cones->pdf(r->direction), 1e-6f * r->pdf.dir);
      EXPECT_EQ(r->origin, glm::vec3(0.0f));
      const glm::vec3 value = spatial_emission(l) * directional_emission(l, r->normal, r->direction);
      EXPECT_EQ(r->value, value);
      EXPECT_NEAR(r->weight.x, value.x / r->pdf.dir, 1e-6f * r->weight.x);
    }
    EXPECT_GT(drawn, 500);
  }
  // Without cones the light answers as the emitter model does.
  RenderLight plain;
  plain.params = point;
  const std::optional<EndpointRay> r = plain.sample_ray({}, {0.3f, 0.6f});
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->direction, sample_ray(plain.params, SurfacePoint{}, {0.3f, 0.6f})->direction);
  EXPECT_EQ(plain.pdf_ray({}, r->direction).dir, pdf_ray(plain.params, SurfacePoint{}, r->direction).dir);
}

// The caustic of a point light above a glass sphere under --only, aimed through the decorator,
// has the image statistics it had when the integrator overwrote the light's ray (main 73e5985,
// before issue 37's plan): its total and its two brightest paths against that render's (1,024
// spp, seed 1, `pathex trace samples/scenes/point-glass.json --renderer bdpt --only '$caustic'
// --resolution 24x24 --max-bounces 10`), within a family-wise false-failure rate of 0.1 %.
TEST(AimedEmission, TheDecoratorKeepsTheImageStatisticsOfTheOverwrittenRay) {
  struct Reference {
    std::string path;  // "" for the total
    double luminance, std_error;
  };
  const std::vector<Reference> before = {{"", 0.025325321171819567, 1.5660826840422674e-05},
                                         {"LSDSSDDSE", 0.023886815822522767, 1.5580830554106613e-05},
                                         {"LSDSDDSE", 0.0008975720323029348, 6.983148888540889e-06}};
  const Scene scene = scene_at("point-glass.json", 24);
  const SceneTypes types = scene_types(scene);
  ClassOptions co;
  co.ends.lights.assign(types.lights.begin(), types.lights.end());
  co.ends.sensors = {types.sensor};
  const PathClass c = compile_class("$caustic", co).expect("a test class");
  const Classifier cl = Classifier::build({&c}, Limits{}).expect("a classifier");
  const RenderPlan plan = plan_render(scene, resolve_profile("bdpt", Limits{}).expect("a profile"), 10, {&c}, Limits{}).expect("a plan");
  ASSERT_EQ(plan.aimed_lights, std::vector<int>{0});
  RenderOptions o;
  o.spp = 64;
  o.seed = test::stat_seed(41);
  o.max_bounces = 10;
  o.images = false;
  const RenderOutput out = render(scene, plan, &cl, o).expect("a render");
  ASSERT_EQ(out.aimed.size(), 1u);
  const HistogramReport rep = make_report(out.histogram, RunInfo{}, &cl, {{"caustic", "$caustic"}}).expect("a report");
  std::vector<test::Comparison> comparisons;  // by the shared rule (tests/support/compare_estimates.h), 0.1 % together
  for (const Reference& b : before) {
    const Estimate* e = b.path.empty() ? &rep.total : nullptr;
    for (const PathEstimate& p : rep.paths)
      if (p.path == b.path) e = &p.estimate;
    ASSERT_NE(e, nullptr) << b.path;
    Estimate then;  // the reference render's; 16 degrees of freedom, at most what its batches gave (errs looser)
    then.luminance = b.luminance;
    then.std_error = b.std_error;
    then.dof = kDefaultDof;
    comparisons.push_back(test::compare("aimed decorator " + (b.path.empty() ? std::string("total") : b.path), *e, then));
  }
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

// No aiming where a requested path may start with a diffuse vertex, without a light walk, or with
// an area light.
TEST(AimedEmission, OnlyWhereEveryRequestedPathStartsSpecular) {
  const Scene glass = scene_at("point-glass.json", 8);
  EXPECT_TRUE(render_class(glass, "bdpt", "$direct", true, 1, 2).aimed.empty());
  EXPECT_TRUE(render_class(glass, "bdpt", "L.*E", true, 1, 2).aimed.empty());
  EXPECT_TRUE(render_class(glass, "pt-nee", "$caustic", true, 1, 2).aimed.empty());  // no light subpath
  EXPECT_FALSE(render_class(glass, "lt", "$caustic", true, 1, 2).aimed.empty());
  const Scene cornell = scene_at("cornell.json", 8);
  EXPECT_TRUE(render_class(cornell, "bdpt", "$caustic", true, 1, 2).aimed.empty());  // an area light
}

}  // namespace
}  // namespace pathex
