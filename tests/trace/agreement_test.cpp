// The checker and the tracer agree (issues 4 and 11). For every sample scene and every built-in
// profile that renders, rendered at low resolution with fixed seeds:
//   - every path string with a nonzero estimate is in the profile's reachable language (the
//     checker's R under the same bound): the tracer never samples what the checker forbids;
//   - every string that bdpt finds carrying more than 1 % of the image, and that the profile can
//     reach, is found by the profile with an estimate within the family-wise tolerance of bdpt's
//     (the two errors combined at their Welch–Satterthwaite degrees of freedom; test::family_sigmas
//     over every such comparison, 0.1 %); a path with too few samples or degrees of freedom for a
//     stderr, or sampled by the manifold walk (heavy-tailed: docs/manifold.md), is
//     checked for being found;
//     "can reach" is the checker's R, except that the mirror connector joins across planar
//     mirrors only (quads of a pure mirror material, trace/joins/mirror.h), which the checker,
//     knowing no geometry, cannot see: in a scene without one, its strategies are left out;
//   - no sample is non-finite.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <vector>

#include "io/profile_json.h"
#include "reach/query.h"
#include "scene/scene.h"
#include "trace/render.h"
#include "support/compare_estimates.h"
#include "support/stat_seed.h"

namespace pathex {
namespace {

constexpr int kBounces = 6;
// Which estimates are compared by their stderrs, and how: tests/support/compare_estimates.h.

HistogramReport render_scene(const Scene& scene, const Profile& profile, std::uint64_t spp) {
  RenderOptions o;
  o.spp = spp;
  o.seed = test::stat_seed(3);
  o.max_bounces = kBounces;
  Result<RenderOutput> out = render(scene, profile, nullptr, o);
  EXPECT_TRUE(out.ok()) << (out.ok() ? "" : out.error().render());
  RunInfo info;
  info.spp = spp;
  return make_report(out->histogram, info, nullptr, {}).expect("a test input");
}

TEST(Agreement, TracerSamplesExactlyWhatTheCheckerAllows) {
  const std::string dir = std::string(PATHEX_SOURCE_DIR) + "/samples/scenes";
  // Every built-in profile (bdpt, the reference, is checked against R below too); all render.
  std::vector<Profile> profiles;
  for (Profile& p : builtin_profiles(Limits{}).expect("a test input"))
    if (p.name != "bdpt") profiles.push_back(std::move(p));
  ASSERT_EQ(profiles.size(), 14u);
  std::vector<test::Comparison> comparisons;
  int sparse = 0;  // paths found, but with too few samples or degrees of freedom for their stderr to mean anything
  int heavy = 0;   // paths found that the manifold walk samples (heavy-tailed: checked for being found)
  auto has_connector = [](const Profile& p, ConnectorKind kind) {
    return std::any_of(p.strategies.begin(), p.strategies.end(), [&](const Strategy& st) { return st.connector == kind; });
  };
  std::map<std::pair<std::string, ConnectorKind>, CompiledProfile> pruned;  // per profile: its checker without a connector
  auto without = [&](const Profile& p, ConnectorKind kind) -> const CompiledProfile& {
    auto it = pruned.find({p.name, kind});
    if (it != pruned.end()) return it->second;
    Profile q = p;
    std::erase_if(q.strategies, [&](const Strategy& st) { return st.connector == kind; });
    return pruned.emplace(std::pair{p.name, kind}, compile_profile(q, kBounces, Limits{}).expect("a test input")).first->second;
  };
  std::map<std::string, CompiledProfile> manifold_only;  // per profile: the checker of its manifold strategies alone
  auto manifold_reach = [&](const Profile& p) -> const CompiledProfile& {
    auto it = manifold_only.find(p.name);
    if (it != manifold_only.end()) return it->second;
    Profile q = p;
    std::erase_if(q.strategies, [&](const Strategy& st) { return st.connector != ConnectorKind::kManifold; });
    return manifold_only.emplace(p.name, compile_profile(q, kBounces, Limits{}).expect("a test input")).first->second;
  };
  for (const auto& entry : std::filesystem::directory_iterator(dir)) {
    if (entry.path().extension() != ".json") continue;
    // Made to be under-sampled (issue 36): pt meets its lamp of radius 0.03 by chance only, so
    // "every profile finds every path above 1 % at 128 spp" does not hold there by design;
    // tests/bias/bias_test.cpp measures that scene with pathex bias's under-sampling check.
    // lamp-glass.json (issue 40) likewise: pt and pt-nee meet its lamp of radius 0.04 through the
    // glass by chance only; its caustics are checked against bdpt and a quadrature in
    // tests/trace/manifold_reference_test.cpp.
    if (entry.path().filename() == "small-light-caustic.json" || entry.path().filename() == "lamp-glass.json") continue;
    Result<Scene> loaded = load_scene_file(entry.path().string());
    ASSERT_TRUE(loaded.ok()) << loaded.error().render();
    Scene scene = *loaded;
    // The manifold walk's estimate of a caustic is heavy-tailed: under a point or spot light its
    // second moment is log-divergent (docs/manifold.md; point-glass.json's LSDSSDDSE read 35-45 % low
    // with a tight stderr at 4 seeds of 100 in issue 36's sweep), and under any light its unbiased
    // trial-count weight makes each sample a whole multiple of a chain's contribution (cornell.json's
    // LDDSSDDSE under pt-nee+manifold read 0.0089 ± 0.0006 and 0.0028 ± 0.0005 at seeds 35 and 43 of
    // the tenth session's sweep, against 0.0044 at 4,096 spp; 12 seeds' stderrs 0.0006-0.0020).
    // Paths the walk samples are checked for being found; their values against quadratures, light
    // tracing and bdpt in tests/trace/manifold_test.cpp and manifold_reference_test.cpp.
    const bool planar_mirror = std::any_of(scene.shapes.begin(), scene.shapes.end(), [&](const Shape& sh) {
      return std::holds_alternative<QuadShape>(sh.geometry) && std::holds_alternative<Mirror>(scene.materials[static_cast<std::size_t>(sh.material)]);
    });
    if (scene.camera.type != SensorType::kSpotmeter) scene.camera.width = scene.camera.height = 16;
    const std::uint64_t spp = scene.camera.type == SensorType::kSpotmeter ? 8192 : 128;
    // A profile with no light subpath (pt) meets an image light's sun only by chance, and there its
    // estimate is a sum of few heavy hits among many dim ones (sky-image.json: the sun 60 times the
    // sky; LDDDDDSE at 128 spp holds ~500 samples but only a dozen sun hits). A draw with fewer
    // hits is low *and* has a small stderr: issue 36's sweep, seed 61 of 66, read 0.00173 ± 0.00013
    // against bdpt's 0.00269 (7.6σ; seeds 1–6 read 0.0023–0.0036 ± 0.0003–0.0005). Such a profile
    // renders 8 times the samples under an image light, so that its batches hold enough hits.
    const bool environment = scene.environment_image.has_value();
    const auto chance_only = [](const Profile& p) {
      return std::all_of(p.strategies.begin(), p.strategies.end(), [](const Strategy& st) { return st.s.hi == 0; });
    };
    const Profile bdpt = resolve_profile("bdpt", Limits{}).expect("a test input");
    const HistogramReport reference = render_scene(scene, bdpt, spp);
    EXPECT_EQ(reference.nonfinite_samples, 0u) << entry.path().filename();
    const CompiledProfile bdpt_checker = compile_profile(bdpt, kBounces, Limits{}).expect("a test input");
    for (const PathEstimate& p : reference.paths) {
      if (p.estimate.luminance != 0.0) {
        EXPECT_TRUE(bdpt_checker.reachable.accepts(p.path)) << entry.path().filename() << ": " << p.path;
      }
    }
    std::map<std::string, const PathEstimate*> by_path;
    for (const PathEstimate& p : reference.paths) by_path[p.path] = &p;
    for (const Profile& profile : profiles) {
      const std::string& name = profile.name;
      const CompiledProfile checker = compile_profile(profile, kBounces, Limits{}).expect("a test input");
      const HistogramReport r = render_scene(scene, profile, environment && chance_only(profile) ? 8 * spp : spp);
      const std::string where = entry.path().filename().string() + " with " + name;
      EXPECT_EQ(r.nonfinite_samples, 0u) << where;
      std::map<std::string, const PathEstimate*> found;
      for (const PathEstimate& p : r.paths) {
        found[p.path] = &p;
        if (p.estimate.luminance != 0.0) {
          EXPECT_TRUE(checker.reachable.accepts(p.path)) << where << ": " << p.path;
        }
      }
      const CompiledProfile& reach = planar_mirror || !has_connector(profile, ConnectorKind::kMirror) ? checker : without(profile, ConnectorKind::kMirror);
      const bool manifold_heavy = has_connector(profile, ConnectorKind::kManifold);
      for (const PathEstimate& p : reference.paths) {
        if (!(p.estimate.luminance > 0.01 * reference.total.luminance) || !reach.reachable.accepts(p.path)) continue;
        auto it = found.find(p.path);
        ASSERT_NE(it, found.end()) << where << ": bdpt finds " << p.path << " but the profile never samples it";
        // A path with too few samples or degrees of freedom for its stderr to mean anything is
        // checked for being found, not for its value (tests/support/compare_estimates.h).
        const Estimate& a = p.estimate;
        const Estimate& b = it->second->estimate;
        if (!test::comparable(a, b)) {
          ++sparse;
          continue;
        }
        if (manifold_heavy && manifold_reach(profile).reachable.accepts(p.path)) {
          ++heavy;
          continue;
        }
        comparisons.push_back(test::compare(where + ": " + p.path + " bdpt against " + name, a, b));
      }
    }
  }
  EXPECT_GT(comparisons.size(), 40u);
  test::stat_log("paths found but too sparse to compare", sparse, static_cast<double>(comparisons.size()) / 4);
  EXPECT_LT(sparse, static_cast<int>(comparisons.size()) / 4) << "most comparisons must be of well-sampled paths";
  test::stat_log("paths found, sampled by the manifold walk", heavy, 0);
  for (const std::string& failure : test::family_failures(comparisons)) ADD_FAILURE() << failure;
}

}  // namespace
}  // namespace pathex
