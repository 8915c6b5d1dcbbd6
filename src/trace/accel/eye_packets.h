// The eye subpaths' first rays traced in packets: a speed-up of the render loop, kept out of the
// estimator (render.cpp).
//
// A row's samples (pixel after pixel, a chunk's passes of each in turn) start their eye subpaths
// with rays from one point (a pinhole) or a small lens through neighbouring pixels: coherent
// rays, which Embree traces markedly faster in a packet of 16 than one by one, and whose making
// (the film point's Sobol numbers, the sensor's map) is a chain of dependent steps that 16
// samples made side by side overlap (bench/trace_bench BM_EyeRayPackets). So a row's samples go
// 16 at a time: their first rays are made from their own numbers (RenderSensor::primary_ray at
// the eye's dimensions, as the eye subpath makes them), traced as one packet, and each sample then
// runs as before with its ray and hit handed to its walk (EyeAhead, trace/accel/eye_ahead.h),
// which takes them only for that very sample and query. The samples run in the same order and
// every ray and hit is the one the walk would have made: outputs are identical
// (bench/identical_outputs.sh).
#pragma once

#include <array>
#include <cstdint>
#include <optional>

#include "trace/embree_scene.h"
#include "trace/integrator.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

// Integrator::sample(th, x, y, pass) for every pixel x of row y and pass in [first, end), in that
// order, the eye subpaths' first rays made and traced 16 at a time.
inline void sample_row_in_packets(const Integrator& integrator, Integrator::Thread& th, const RenderScene& rs,
                                  const RenderOptions& o, int y, std::uint64_t first, std::uint64_t end) {
  EyeAhead& ahead = th.ahead;
  const auto run = [&] {
    ahead.trace(*rs.geometry, rs.textured ? HitDetail::kFull : HitDetail::kNoUv);  // the detail the walk asks for
    for (int i = 0; i < ahead.size(); ++i) {
      ahead.select(i);
      integrator.sample(th, ahead.start(i).x, y, ahead.start(i).pass);
    }
    ahead.clear();
  };
  const std::uint64_t row = static_cast<std::uint64_t>(y) * static_cast<std::uint64_t>(rs.camera.width);
  for (int x = 0; x < rs.camera.width; ++x)
    for (std::uint64_t p = first; p < end; ++p) {
      // The sample's numbers as Integrator::sample() starts them: the eye subpath's, from dimension 0.
      ahead.add(rs.camera, Sampler(o.seed, row + static_cast<std::uint64_t>(x), p, o.sampler, static_cast<std::uint64_t>(o.replicates)),
                x, y, p);
      if (ahead.full()) run();
    }
  if (ahead.size() > 0) run();
}

}  // namespace pathex::tracer
