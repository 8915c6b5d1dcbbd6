// `--rr-join-threshold auto` (trace/accel/join_plan.h): the model's choice from a pilot's sums, in
// closed form, and the pilot's verdicts on the scenes that set the default: no roulette where the
// deep eye vertices' joins carry the light (a closed sphere round a point light), a threshold where
// the light subpath's joins with the eye's first vertices already reach their paths.
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
// cost 10 rays; threshold 1 (kJoinThresholds[2]) adds `added` / 100 to the variance and skips
// `skipped` / 100 joins of kJoinCost = 1.5 rays each.
JoinPilot pilot_with(double added, double skipped) {
  JoinPilot p;
  p.samples = 100;
  p.pixels = 50;
  p.camera = 70;
  p.cost = 1000;
  p.added[2] = added;
  p.skipped[2] = skipped;
  return p;
}

TEST(JoinPlan, TakesTheThresholdTheModelFindsMostEfficient) {
  // Sobol: V = 1, C = 10; at 1: (1 + 0.1) (10 - 1.5) = 9.35 against 10.
  const JoinRoulette sobol = choose_join_threshold(pilot_with(10, 100), true);
  EXPECT_EQ(sobol.threshold, 1.0f);
  EXPECT_NEAR(sobol.gain, 10.0 / 9.35, 1e-12);
  // Independent samples: V = 1.4; 14 against 1.5 x 8.5 = 12.75.
  const JoinRoulette independent = choose_join_threshold(pilot_with(10, 100), false);
  EXPECT_EQ(independent.threshold, 1.0f);
  EXPECT_NEAR(independent.gain, 14.0 / 12.75, 1e-12);
  // The splats' Σ c² add to V: 100 / 100 more, so (2 + 0.1) x 8.5 against 20.
  JoinPilot splats = pilot_with(10, 100);
  splats.splats = 100;
  EXPECT_NEAR(choose_join_threshold(splats, true).gain, 20.0 / 17.85, 1e-12);
}

TEST(JoinPlan, TakesTheLargerThresholdWhereItsExtraVarianceIsWorthItsSaving) {
  JoinPilot p = pilot_with(10, 100);  // at 1: 10 / 9.35 = 1.0695
  p.added[3] = 20;                    // at 2: (1 + 0.2) (10 - 3) = 8.4: 1.1905
  p.skipped[3] = 200;
  p.added[4] = 100;                   // at 4: (1 + 1) (10 - 4.5) = 11: a loss
  p.skipped[4] = 300;
  const JoinRoulette c = choose_join_threshold(p, true);
  EXPECT_EQ(c.threshold, 2.0f);
  EXPECT_NEAR(c.gain, 10.0 / 8.4, 1e-12);
}

TEST(JoinPlan, TakesNoneBelowTheMinimumGain) {
  // At 1: (1 + 0.05) (10 - 0.3) = 10.185: a loss; none.
  const JoinRoulette loss = choose_join_threshold(pilot_with(5, 20), true);
  EXPECT_EQ(loss.threshold, 0.0f);
  EXPECT_EQ(loss.gain, 1.0);
  // At 1: (1 + 0.01) (10 - 0.3) = 9.797, 1.0207x: a gain below kMinJoinGain (1.03); none, and the gain said.
  const JoinRoulette small = choose_join_threshold(pilot_with(1, 20), true);
  EXPECT_EQ(small.threshold, 0.0f);
  EXPECT_NEAR(small.gain, 10.0 / 9.797, 1e-12);
  // No variance or no samples: nothing to weigh.
  EXPECT_EQ(choose_join_threshold(JoinPilot{}, true).threshold, 0.0f);
  JoinPilot dark = pilot_with(0, 100);
  dark.camera = 0;
  EXPECT_EQ(choose_join_threshold(dark, true).threshold, 0.0f);
}

// What `pathex trace --renderer bdpt --spp 64` takes on three scenes (their own resolution, seed 1).
std::optional<JoinRoulette> auto_threshold(const std::string& file, const std::string& renderer = "bdpt") {
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
  return out.ok() ? out->join_roulette : std::nullopt;
}

TEST(JoinPlan, ThePilotsVerdictsOnTheScenesThatSetTheDefault) {
  // At 1 the closed sphere lost 18 % (docs/efficiency.md): none.
  const std::optional<JoinRoulette> sphere = auto_threshold("samples/scenes/closed-sphere-point.json");
  ASSERT_TRUE(sphere.has_value());
  EXPECT_EQ(sphere->threshold, 0.0f);
  // Tungsten's box gained 4 % at 1, sun-window.json 34 % (and more at 2).
  const std::optional<JoinRoulette> box = auto_threshold("bench/scenes/tungsten-cornell-box.json");
  ASSERT_TRUE(box.has_value());
  EXPECT_EQ(box->threshold, 1.0f);
  const std::optional<JoinRoulette> window = auto_threshold("samples/scenes/sun-window.json");
  ASSERT_TRUE(window.has_value());
  EXPECT_EQ(window->threshold, 2.0f);
  // pt-nee joins no eye vertex with a light subpath: no pilot, no roulette.
  EXPECT_FALSE(auto_threshold("samples/scenes/sun-window.json", "pt-nee").has_value());
}

}  // namespace
}  // namespace pathex::tracer
