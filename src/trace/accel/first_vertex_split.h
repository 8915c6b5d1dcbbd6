// Splitting at the eye subpath's first vertex (issue 39, `pathex trace --splits N`): a sample's
// camera ray and the surface it finds are made once and the rest of the sample, from the first
// vertex's scattering on (and every join), runs N times, each run's contributions weighted 1/N.
//
// Unbiased for any N: every run is a whole sample whose numbers past the camera's are uniform
// (below), so each run's sum estimates the pixel and their mean does too. What it buys: off a
// directly seen light the error of an image is the indirect light's, which the camera's numbers
// hardly change, so N continuations cost the camera ray and its hit once instead of N times. What
// it does not: where the pixel's own area is the error (a light's edge seen directly), the N
// runs share their camera ray and remove none of it.
//
// The numbers. Run j of pass p takes the camera's dimensions from the sample's own point (so
// that the eye's packets, trace/accel/eye_packets.h, still serve run 0) and every later dimension
// from point i·N + j of the same scrambled sequence, where i is the pass's point index in its
// replicate (trace/rng.h, sobol_stream()): the continuations of a replicate's first k passes are
// the first k·N points of its sequence, a net wherever the passes' points are one. Under the
// independent sampler run j's later numbers come from a stream of their own (Sampler::reindex()).
#pragma once

#include <cstdint>
#include <optional>

#include <glm/vec3.hpp>

#include "trace/accel/eye_ahead.h"
#include "trace/embree_scene.h"
#include "trace/emitters.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

class FirstVertexSplit {
 public:
  // Run `run` of `runs` of the sample whose point index in its replicate is `point`.
  void begin(int runs, int run, std::uint32_t point) {
    runs_ = runs;
    run_ = run;
    weight_ = 1.0f / static_cast<float>(runs);
    point_ = point * static_cast<std::uint32_t>(runs) + static_cast<std::uint32_t>(run);
  }
  // The runs of pass `pass`'s sample: run_one() once without splitting (no bookkeeping), else
  // `runs` times, each after begin() at the pass's point in its replicate (sobol_stream()).
  template <class RunOne>
  void runs(int runs, std::uint64_t pass, std::uint64_t replicates, RunOne run_one) {
    if (runs == 1) return run_one();
    for (int run = 0; run < runs; ++run) {
      begin(runs, run, sobol_stream(pass, replicates).index);
      run_one();
    }
  }
  bool splitting() const { return runs_ > 1; }
  // The weight of every contribution of this run: 1 / N (exactly 1 without splitting).
  float weight() const { return weight_; }

  // While splitting(): the camera ray (EyeAhead::primary_ray(), made by run 0 and kept), with rng
  // moved past the camera's numbers and on to this run's point.
  std::optional<EndpointRay> primary_ray(EyeAhead& ahead, const RenderSensor& sensor, Sampler& rng, int px, int py) {
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
  int runs_ = 1, run_ = 0;
  float weight_ = 1.0f;
  std::uint32_t point_ = 0;
  std::uint64_t after_camera_ = 0;
  std::optional<EndpointRay> ray_;
  std::optional<Hit> hit_;
};

}  // namespace pathex::tracer
