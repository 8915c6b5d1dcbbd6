// Splitting at the eye subpath's first vertex (issue 39, `pathex trace --splits N|auto`): a
// sample's camera ray and the surface it finds are made once and the rest of the sample, from the
// first vertex's scattering on (and every join), runs N times, each run's contributions weighted
// 1/N. Under `--splits auto` each pixel has counts of its own (trace/accel/split_plan.h): M camera
// rays per sample, each with N such runs, every run weighted 1/(M·N).
//
// Unbiased for any counts fixed before the render's samples: every run is a whole sample whose
// numbers are uniform (below), so each run's sum estimates the pixel and their mean does too. What
// it buys: off a directly seen light the error of an image is the indirect light's, which the
// camera's numbers hardly change, so N continuations cost the camera ray and its hit once instead
// of N times. What it does not: where the pixel's own area is the error (a light's edge seen
// directly), the N runs share their camera ray and remove none of it; M camera rays do.
//
// The numbers. Camera ray m of pass p takes the camera's dimensions from point i·M + m (the
// sample's own point i when M = 1, so that the eye's packets, trace/accel/eye_packets.h, still
// serve it), and run j after it every later dimension from point (i·M + m)·N + j of the same
// scrambled sequence, where i is the pass's point index in its replicate (trace/rng.h,
// sobol_stream()): the camera rays of a replicate's first k passes are the first k·M points of its
// sequence, their continuations the first k·M·N. Under the independent sampler each camera ray and
// each run has a stream of its own (Sampler::reindex()).
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include <glm/vec3.hpp>

#include "trace/accel/eye_ahead.h"
#include "trace/accel/split_counts.h"
#include "trace/embree_scene.h"
#include "trace/emitters.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

class FirstVertexSplit {
 public:
  // Every sample split alike (--splits N), or by the pixel's counts in `map` (--splits auto).
  void set(int runs, std::shared_ptr<const SplitMap> map) {
    fixed_ = runs;
    map_ = std::move(map);
  }
  // Camera ray `camera` of `counts.cameras`, its run `run` of `counts.runs`, of the sample whose
  // point index in its replicate is `point`.
  void begin(SplitCounts counts, int camera, int run, std::uint32_t point) {
    counts_ = counts;
    camera_ = camera;
    run_ = run;
    weight_ = 1.0f / static_cast<float>(counts.cameras * counts.runs);
    camera_point_ = point * static_cast<std::uint32_t>(counts.cameras) + static_cast<std::uint32_t>(camera);
    point_ = camera_point_ * static_cast<std::uint32_t>(counts.runs) + static_cast<std::uint32_t>(run);
  }
  // The runs of pass `pass`'s sample at pixel (px, py): run_one() once without splitting (no
  // bookkeeping), else once per camera ray and run, each after begin() at the pass's point in its
  // replicate (sobol_stream()).
  template <class RunOne>
  void runs(int px, int py, std::uint64_t pass, std::uint64_t replicates, RunOne run_one) {
    const SplitCounts c = map_ ? map_->at(px, py) : SplitCounts{1, fixed_};
    if (c.cameras * c.runs == 1) {
      counts_ = c;
      weight_ = 1.0f;
      return run_one();
    }
    const std::uint32_t point = sobol_stream(pass, replicates).index;
    for (int camera = 0; camera < c.cameras; ++camera)
      for (int run = 0; run < c.runs; ++run) {
        begin(c, camera, run, point);
        run_one();
      }
  }
  bool splitting() const { return counts_.cameras * counts_.runs > 1; }
  // The weight of every contribution of this run: 1 / (M·N) (exactly 1 without splitting).
  float weight() const { return weight_; }

  // While splitting(): the camera ray (EyeAhead::primary_ray(), made by run 0 and kept), with rng
  // moved past the camera's numbers and on to this run's point.
  std::optional<EndpointRay> primary_ray(EyeAhead& ahead, const RenderSensor& sensor, Sampler& rng, int px, int py) {
    if (counts_.cameras > 1) rng.reindex(camera_point_, kCameraSalt + static_cast<std::uint64_t>(camera_));
    if (run_ == 0) {
      ray_ = ahead.primary_ray(sensor, rng, px, py);
      after_camera_ = rng.dimension();
    } else {
      rng.set_dimension(after_camera_);
    }
    rng.reindex(point_, static_cast<std::uint64_t>(run_));
    return ray_;
  }
  // While splitting(): the camera ray's hit (EyeAhead::intersect()), traced by run 0 and kept.
  std::optional<Hit> first_hit(EyeAhead& ahead, const EmbreeScene& scene, const glm::vec3& o, const glm::vec3& d,
                               const glm::vec3& n, const glm::vec3& e, HitDetail detail) {
    if (run_ > 0) return hit_;
    hit_ = ahead.intersect(scene, o, d, n, e, detail);
    return hit_;
  }

 private:
  // The independent sampler's salt of camera ray m's stream: apart from every run's (0 … N − 1).
  static constexpr std::uint64_t kCameraSalt = std::uint64_t{1} << 32;
  int fixed_ = 1;
  std::shared_ptr<const SplitMap> map_;
  SplitCounts counts_{};
  int camera_ = 0, run_ = 0;
  float weight_ = 1.0f;
  std::uint32_t camera_point_ = 0, point_ = 0;
  std::uint64_t after_camera_ = 0;
  std::optional<EndpointRay> ray_;
  std::optional<Hit> hit_;
};

}  // namespace pathex::tracer
