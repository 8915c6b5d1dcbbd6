// `--rr-threshold auto` and `--rr-join-threshold auto` (trace/accel/join_plan.h): the model's
// price of one pilot sample and its choice from a pilot's sums, in closed form, and the pilot's
// verdicts on the scenes that set the defaults: no roulette of the joins where the deep eye
// vertices' joins carry the light (a closed sphere round a point light), a threshold where the
// light subpath's joins with the eye's first vertices already reach their paths.
#include "trace/accel/join_plan.h"

#include <gtest/gtest.h>

#include <optional>
#include <string>

#include "io/profile_json.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace pathex::tracer {
namespace {

// 100 samples at 50 pixels: the camera's variance 1.4 a pixel (1 under Sobol points), a sample's
// cost 10 rays; candidates eye 0.3 and 1, joins none and 1.
JoinPilot pilot_with(double added, double saved) {
  JoinPilot p({0.3f, 1.0f}, {0.0f, 1.0f});
  p.samples = 100;
  p.pixels = 50;
  p.camera = 70;
  p.cost = 1000;
  p.added[p.at(0, 1)] = added;
  p.saved[p.at(0, 1)] = saved;
  return p;
}

TEST(JoinPlan, TakesThePairTheModelFindsMostEfficient) {
  // Sobol: V = 1, C = 10; at (0.3, 1): (1 + 0.1) (10 - 1.5) = 9.35 against 10.
  const RouletteThresholds sobol = choose_thresholds(pilot_with(10, 150), true);
  EXPECT_EQ(sobol.eye, 0.3f);
  EXPECT_EQ(sobol.join, 1.0f);
  EXPECT_TRUE(sobol.taken);
  EXPECT_NEAR(sobol.gain, 10.0 / 9.35, 1e-12);
  // Independent samples: V = 1.4; 14 against 1.5 x 8.5 = 12.75.
  const RouletteThresholds independent = choose_thresholds(pilot_with(10, 150), false);
  EXPECT_EQ(independent.join, 1.0f);
  EXPECT_NEAR(independent.gain, 14.0 / 12.75, 1e-12);
  // The splats' Σ c² add to V: 100 / 100 more, so (2 + 0.1) x 8.5 against 20.
  JoinPilot splats = pilot_with(10, 150);
  splats.splats = 100;
  EXPECT_NEAR(choose_thresholds(splats, true).gain, 20.0 / 17.85, 1e-12);
  // The eye's 1 with no join roulette: (1 + 0.2) (10 - 3) = 8.4, 1.19x: taken over (0.3, 1).
  JoinPilot eye = pilot_with(10, 150);
  eye.added[eye.at(1, 0)] = 20;
  eye.saved[eye.at(1, 0)] = 300;
  eye.added[eye.at(1, 1)] = 100;  // (1 + 1) (10 - 4.5) = 11: a loss
  eye.saved[eye.at(1, 1)] = 450;
  const RouletteThresholds e = choose_thresholds(eye, true);
  EXPECT_EQ(e.eye, 1.0f);
  EXPECT_EQ(e.join, 0.0f);
  EXPECT_NEAR(e.gain, 10.0 / 8.4, 1e-12);
}

TEST(JoinPlan, KeepsTheFirstPairBelowTheMinimumGain) {
  // At (0.3, 1): (1 + 0.05) (10 - 0.45) = 10.0275: a loss; the first pair, none better.
  const RouletteThresholds loss = choose_thresholds(pilot_with(5, 45), true);
  EXPECT_EQ(loss.eye, 0.3f);
  EXPECT_EQ(loss.join, 0.0f);
  EXPECT_FALSE(loss.taken);
  EXPECT_EQ(loss.gain, 1.0);
  // At (0.3, 1): (1 + 0.01) (10 - 0.3) = 9.797, 1.0207x: a gain below kMinJoinGain (1.03); the
  // first pair, and the gain said.
  const RouletteThresholds small = choose_thresholds(pilot_with(1, 30), true);
  EXPECT_EQ(small.join, 0.0f);
  EXPECT_FALSE(small.taken);
  EXPECT_NEAR(small.gain, 10.0 / 9.797, 1e-12);
  // The first pair is the one given where an option is not auto: the join threshold 1 given, the
  // eye's to choose; (0.3, 1) costs (1 + 0.1) (10 - 1.5), (1, 1) (1 + 0.2) (10 - 3.3) = 8.04.
  JoinPilot given({0.3f, 1.0f}, {1.0f});
  given.samples = 100;
  given.pixels = 50;
  given.camera = 70;
  given.cost = 1000;
  given.added = {10, 20};
  given.saved = {150, 330};
  const RouletteThresholds g = choose_thresholds(given, true);
  EXPECT_EQ(g.eye, 1.0f);
  EXPECT_EQ(g.join, 1.0f);
  EXPECT_NEAR(g.gain, 9.35 / 8.04, 1e-12);
  // No variance or no samples: nothing to weigh.
  EXPECT_FALSE(choose_thresholds(JoinPilot({0.3f}, {0.0f, 1.0f}), true).taken);
  JoinPilot dark = pilot_with(0, 150);
  dark.camera = 0;
  EXPECT_FALSE(choose_thresholds(dark, true).taken);
}

// One pilot sample priced by hand. Its eye subpath z0..z4 under the pilot's eye threshold 0.3: no
// roulette on the way to z1 and z2; the step to z3 survived with probability 0.5 (throughput 0.15,
// carried on as 0.3), the step to z4 with 0.8 (0.24 of the 0.3 carried: 0.12 without the weights).
// Under the eye threshold 1 the walk reaches z3 with 0.15 and z4 with min(0.15, 0.12) = 0.12:
// P'(3) = 0.15 / 0.5 = 0.3, P'(4) = 0.12 / 0.4 = 0.3.
TEST(JoinPlan, PricesTheNestedEyeRouletteAndTheJoinsItCarries) {
  JoinTally tally;
  tally.survive[3] = 0.5f;
  tally.survive[4] = 0.8f;
  tally.by_t[2] = vec3(1, 0, 0);  // z1's: no roulette touches it
  tally.by_t[4] = vec3(2, 0, 0);  // z3's
  tally.by_t[5] = vec3(1, 0, 0);  // z4's
  tally.joins_at[4] = 2;
  tally.joins_at[5] = 2;
  tally.deep[2] = vec3(0.5f, 0, 0);  // z1's joins with the light subpath: 1 of them
  tally.deep_joins[2] = 1;
  tally.deep[4] = vec3(1, 0, 0);  // z3's: 2
  tally.deep_joins[4] = 2;
  tally.deep[5] = vec3(0.5f, 0, 0);  // z4's: 2
  tally.deep_joins[5] = 2;
  std::array<Vertex, 5> eye{};
  for (const auto& [j, r] : {std::pair{1, 0.9f}, {2, 0.6f}, {3, 0.3f}, {4, 0.3f}}) eye[static_cast<std::size_t>(j)].rr_throughput = r;
  JoinPilot p({0.3f, 1.0f}, {0.0f, 1.0f});
  price_sample(p, tally, eye.data(), 5);
  // The first pair: nothing added.
  EXPECT_EQ(p.added[p.at(0, 0)], 0.0);
  EXPECT_EQ(p.saved[p.at(0, 0)], 0.0);
  // (0.3, 1): the joins of z1 (q = 0.9) and of z3, z4 (q = 0.3); z2 made none.
  EXPECT_NEAR(p.added[p.at(0, 1)], 0.25 * (1 / 0.9 - 1) + 1.0 * (1 / 0.3 - 1) + 0.25 * (1 / 0.3 - 1), 1e-6);
  EXPECT_NEAR(p.saved[p.at(0, 1)], 1.5 * (1 * 0.1 + 2 * 0.7 + 2 * 0.7), 1e-6);
  // (1, none): Y_3 = 2 + 1 weighted by 1 / P'(3) = 1 / 0.3, and Y_4 no more (P'(4) = P'(3)); z3
  // and z4 each skipped with 0.7, a walk ray and 2 joins each.
  const double eye_v = (1 / 0.3 - 1) * 9.0, eye_c = 0.7 * (1 + 1.5 * 2) * 2;
  EXPECT_NEAR(p.added[p.at(1, 0)], eye_v, 1e-5);
  EXPECT_NEAR(p.saved[p.at(1, 0)], eye_c, 1e-5);
  // (1, 1): z3 and z4 carry 0.3 / 0.3 = 1 under the eye's 1, so their joins are all made; z1's as at 0.3.
  EXPECT_NEAR(p.added[p.at(1, 1)], eye_v + 0.25 * (1 / 0.9 - 1), 1e-5);
  EXPECT_NEAR(p.saved[p.at(1, 1)], eye_c + 1.5 * 0.1, 1e-5);
}

// What `pathex trace --renderer bdpt --spp 64` takes on three scenes (their own resolution, seed 1).
std::optional<RouletteThresholds> auto_thresholds(const std::string& file, const std::string& renderer = "bdpt") {
  Result<Scene> scene = load_scene_file(std::string(PATHEX_SOURCE_DIR) + "/" + file);
  EXPECT_TRUE(scene.ok()) << file;
  Result<Profile> profile = resolve_profile(renderer, Limits{});
  EXPECT_TRUE(profile.ok());
  if (!scene.ok() || !profile.ok()) return std::nullopt;
  RenderOptions o;
  o.spp = 64;  // the pilot's size is a share of the render's (kJoinPilotShare): its first pass is enough
  o.passes = PassSet::range(0, 1);
  o.images = false;
  Result<RenderOutput> out = render(*scene, *profile, nullptr, o);
  EXPECT_TRUE(out.ok()) << file;
  return out.ok() ? out->roulette : std::nullopt;
}

TEST(JoinPlan, ThePilotsVerdictsOnTheScenesThatSetTheDefaults) {
  // A join roulette of 1 lost the closed sphere 18 % (docs/efficiency.md): the first pair.
  const std::optional<RouletteThresholds> sphere = auto_thresholds("samples/scenes/closed-sphere-point.json");
  ASSERT_TRUE(sphere.has_value());
  EXPECT_FALSE(sphere->taken);
  EXPECT_EQ(sphere->eye, kDefaultEyeThreshold);
  EXPECT_EQ(sphere->join, 0.0f);
  // Tungsten's box gained 4 % at the join threshold 1 and 3 % more at the eye's 1;
  // sun-window.json 34 % at the join's 1 (and more at 2).
  const std::optional<RouletteThresholds> box = auto_thresholds("bench/scenes/tungsten-cornell-box.json");
  ASSERT_TRUE(box.has_value());
  EXPECT_EQ(box->eye, 0.5f);
  EXPECT_EQ(box->join, 1.0f);
  const std::optional<RouletteThresholds> window = auto_thresholds("samples/scenes/sun-window.json");
  ASSERT_TRUE(window.has_value());
  EXPECT_EQ(window->eye, 1.0f);
  EXPECT_EQ(window->join, 2.0f);
  // pt-nee joins no eye vertex with a light subpath: no pilot; its eye threshold the default.
  EXPECT_FALSE(auto_thresholds("samples/scenes/sun-window.json", "pt-nee").has_value());
}

}  // namespace
}  // namespace pathex::tracer
