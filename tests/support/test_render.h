// One render of a scene for a test, classified by full-notation classes, with its report, or the
// image's total alone: the renderer tests' one way to render (render_test, environment_test,
// texture_render_test, normal_map_render_test). A step that fails fails the
// test with its located message.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "stats/convergence.h"
#include "io/profile_json.h"
#include "scene/scene.h"
#include "support/test_classes.h"
#include "trace/render.h"

namespace pathex::test {

struct Rendered {
  HistogramReport report;
  RenderOutput out;
};

// How a test's render samples: the sampler and the Russian-roulette settings (RenderOptions).
struct Sampling {
  SamplerKind sampler = RenderOptions{}.sampler;
  int rr_depth = RenderOptions{}.rr_depth;
  float rr_threshold = RenderOptions{}.rr_threshold;
  float rr_light_threshold = RenderOptions{}.rr_light_threshold;
  float rr_join_threshold = RenderOptions{}.rr_join_threshold;
  LightSampling light_sampling = RenderOptions{}.light_sampling;
  std::optional<int> splits{};  // unset: the profile's (resolved_splits())
  std::shared_ptr<const tracer::SplitMap> split_map{};  // with splits 0: these counts instead of the pilot's
  std::string name() const {
    return std::string(to_string(sampler)) + " rr-depth " + std::to_string(rr_depth) + " rr-threshold " +
           (rr_threshold < 0 ? std::string("auto") : std::to_string(rr_threshold)) + " rr-light-threshold " + std::to_string(rr_light_threshold) + " rr-join-threshold " +
           (rr_join_threshold < 0 ? std::string("auto") : std::to_string(rr_join_threshold)) + " light-sampling " +
           to_string(light_sampling) + " splits " + (!splits ? "default" : *splits != 0 ? std::to_string(*splits) : split_map ? "map" : "auto");
  }
};

inline Rendered render_scene(Result<Scene> scene, const std::string& renderer, const std::vector<std::string>& classes,
                             std::uint64_t spp, int threads, std::uint64_t seed, const Sampling& sampling,
                             std::optional<int> max_bounces) {
  const Scene s = std::move(scene).expect("a test scene");
  const Profile profile = resolve_profile(renderer, Limits{}).expect("a built-in renderer");
  static std::vector<std::unique_ptr<TestClasses>> keep;  // the reports outlive this call
  keep.push_back(test_classes(classes));
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.threads = threads;
  o.max_bounces = max_bounces;
  o.sampler = sampling.sampler;
  o.rr_depth = sampling.rr_depth;
  o.rr_threshold = sampling.rr_threshold;
  o.rr_light_threshold = sampling.rr_light_threshold;
  o.rr_join_threshold = sampling.rr_join_threshold;
  o.light_sampling = sampling.light_sampling;
  o.splits = sampling.splits;
  o.split_map = sampling.split_map;
  RenderOutput out = render(s, profile, keep.back()->classifier.get(), o).expect("a render");
  RunInfo info;
  info.spp = spp;
  HistogramReport rep = make_report(out.histogram, info, keep.back()->classifier.get(), keep.back()->infos).expect("a report");
  return Rendered{std::move(rep), std::move(out)};
}

// The image's total estimate of a scene file rendered with `renderer` (no classes), at `seed`;
// a non-finite sample fails the test.
inline Estimate render_total(const std::string& path, const std::string& renderer, std::uint64_t spp, std::uint64_t seed,
                             int max_bounces = 8) {
  const Scene s = load_scene_file(path).expect("a test scene");
  const Profile profile = resolve_profile(renderer, Limits{}).expect("a built-in renderer");
  RenderOptions o;
  o.spp = spp;
  o.seed = seed;
  o.max_bounces = max_bounces;
  const RenderOutput out = render(s, profile, nullptr, o).expect("a render");
  RunInfo info;
  info.spp = spp;
  const HistogramReport r = make_report(out.histogram, info, nullptr, {}).expect("a report");
  EXPECT_EQ(r.nonfinite_samples, 0u) << path << " " << renderer;
  return r.total;
}

}  // namespace pathex::test
