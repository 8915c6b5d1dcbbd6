// `pathex trace --rr-join-threshold auto` (issue 39, the default): bdpt's join roulette threshold
// chosen for the scene from a pilot, as efficiency-aware roulette (EARS, Rath et al. 2022) chooses
// its factors from estimates of the variance and cost each part of a path brings.
//
// The roulette (Integrator::join_roulette()): eye vertex z(t-1), of throughput r relative to its
// walk's start, makes its joins with the light subpath's vertices (s >= 2) with probability q =
// min(1, r / T), each weighted 1 / q. Where their summed (MIS-weighted) contribution to the sample
// is X, that adds X² (1/q − 1) to the sample's variance and saves (1 − q) of their cost. Whether
// that pays is the scene's: where the light subpath's joins with the eye's first vertices already
// reach the paths a deep eye vertex's joins would, X is small and T = 1 gains (Tungsten's box
// 1.04×, cornell.json 1.13×, sun-window.json 1.34×); where the deep joins carry the light (a
// closed sphere round a point light) it loses (0.82×). No one threshold is right for both.
//
// The model. The image's efficiency 1 / (V · C), V the pixels' summed variance of a sample, C a
// sample's cost, becomes 1 / ((V + ΔV_T) · (C − ΔC_T)) under threshold T, with ΔV_T the mean over
// samples of Σ_t X_t² (1/q_t − 1) and ΔC_T = kJoinCost · Σ_t n_t (1 − q_t), n_t the joins z(t-1)
// made. V counts the camera's contributions (the spread of a pixel's samples) and the light
// tracer's splats (each sample's Σ c² over the image: a splat lands on one pixel of many), both
// less the emission seen directly (s + t = 2: no join of the roulette touches it, and its variance
// is the lamp's edge, which the render's sampler stratifies); the camera's part divided by
// kStratified when the render samples by Sobol points (they lower it; the splats, landing on other
// pixels than their sample's, keep theirs). C is in rays: each ray traced and each join weighed
// counts 1. The chosen T is the candidate (kJoinThresholds) of the largest predicted efficiency,
// if that is at least kMinJoinGain times the efficiency without the roulette; else 0 (none).
//
// The pilot. Before the render, kJoinPilotSamples camera samples at evenly spread pixels (at most
// 1 / kJoinPilotShare of the render's samples), 2 at each, under the independent sampler
// at a seed of its own, with no roulette of the joins, no images, nothing recorded; for every
// sample it tallies (Integrator::Thread::tally) its camera contributions by their eye vertex and
// its splats. Unbiased: T is a function of the pilot's numbers alone, which no sample of the render
// uses, and the render is unbiased for any T fixed before it. Deterministic: a function of (seed,
// the pixels, the scene), not of the threads or the shards, so every shard of a render (and a
// resumed one) takes the same T and their sums merge to the unsharded render's, byte for byte.
#pragma once

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <vector>

#include "stats/histogram.h"
#include "trace/integrator.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

inline constexpr std::array<float, 6> kJoinThresholds{0.25f, 0.5f, 1.0f, 2.0f, 4.0f, 8.0f};
// A join skipped saves its shadow ray and its evaluation: measured 1.2-1.9 rays' worth on five
// sample scenes (the CPU of --rr-join-threshold 1000 against 0 over the joins it skips; bench/README.md,
// issue 39, nineteenth session).
inline constexpr double kJoinCost = 1.5;
// The camera's variance under Sobol points against independent samples: pt-nee off the lamp of
// Tungsten's box measured 1.4x (issue 39).
inline constexpr double kStratified = 1.4;
// A threshold is taken only where the model predicts at least this gain: the pilot's estimates
// are noisy, and closed-sphere-point.json, the scene that loses, reads 1.02x at T = 0.5 by the
// model without the Sobol points' correction.
inline constexpr double kMinJoinGain = 1.03;
// The pilot's size: kJoinPilotSamples camera samples, at most 1 / kJoinPilotShare of the render's
// (where the roulette does not pay the pilot is the loss: 1.6 % at 1 / 64 measured on
// closed-sphere-point.json at 16 spp).
inline constexpr std::uint64_t kJoinPilotSamples = 8192, kJoinPilotShare = 128;

// The pilot's sums over its samples (per channel, summed over the three).
struct JoinPilot {
  double samples = 0;
  double camera = 0;  // Σ over pilot pixels of their two samples' half squared difference
  double pixels = 0;
  double splats = 0;  // Σ over samples of their splats' Σ c²
  double cost = 0;    // rays and joins
  std::array<double, kJoinThresholds.size()> added{}, skipped{};  // Σ X² (1/q − 1), Σ n (1 − q)
};

// The threshold of the largest predicted efficiency (above).
inline JoinRoulette choose_join_threshold(const JoinPilot& p, bool stratified) {
  JoinRoulette best;
  if (!(p.samples > 0) || !(p.pixels > 0)) return best;
  const double v = p.camera / p.pixels / (stratified ? kStratified : 1.0) + p.splats / p.samples, c = p.cost / p.samples;
  if (!(v > 0) || !(c > 0)) return best;
  for (std::size_t k = 0; k < kJoinThresholds.size(); ++k) {
    const double dv = p.added[k] / p.samples, dc = kJoinCost * p.skipped[k] / p.samples;
    if (!(dc < c)) continue;
    const double gain = v * c / ((v + dv) * (c - dc));
    if (gain > best.gain) best = {kJoinThresholds[k], gain};
  }
  return best.gain >= kMinJoinGain ? best : JoinRoulette{0.0f, best.gain};
}

// The pilot and choose_join_threshold(): the threshold of a --rr-join-threshold auto render of
// `strategies` under `o`; none (no pilot, no roulette) where no strategy joins an eye vertex with
// the light subpath.
inline std::optional<JoinRoulette> plan_join_threshold(const RenderScene& rs, const StrategySet& strategies, const RenderOptions& o, const PathFilter& filter,
                                      const HistogramLayout& layout) {
  RenderOptions po = o;
  po.sampler = SamplerKind::kIndependent;
  po.seed = mix64(o.seed ^ 0x3c6ef372fe94f82bULL);  // streams of its own (trace/rng.h)
  po.images = false;
  po.rr_join_threshold = 0.0f;
  po.splits = 1;
  const Integrator pilot(rs, strategies, po, filter);
  if (!pilot.traces_eye_rays() || !pilot.joins_with_light_subpath()) return std::nullopt;
  const std::uint64_t pixels = static_cast<std::uint64_t>(rs.camera.width) * static_cast<std::uint64_t>(rs.camera.height);
  // Pilot pixels, 2 samples each: kJoinPilotSamples, or fewer where that is more than
  // 1 / kJoinPilotShare of the render's samples.
  const std::uint64_t n = std::max<std::uint64_t>(1, std::min<std::uint64_t>(kJoinPilotSamples, pixels * o.spp / kJoinPilotShare) / 2);
  std::vector<JoinPilot> at(n);  // each pilot pixel's sums, added in order below
  tbb::enumerable_thread_specific<Integrator::Thread> locals([&] {
    Integrator::Thread th{Histogram(layout, nullptr), {}, {}, {}, 0, {}, {}, {}};
    th.connectors.resize(strategies.strategies.size());
    th.split.set(1, nullptr);
    return th;
  });
  tbb::parallel_for(tbb::blocked_range<std::uint64_t>(0, n, 16), [&](const tbb::blocked_range<std::uint64_t>& range) {
    Integrator::Thread& th = locals.local();
    JoinTally tally;
    th.tally = &tally;
    for (std::uint64_t i = range.begin(); i < range.end(); ++i) {
      const std::uint64_t p = i * pixels / n;
      const int x = static_cast<int>(p % static_cast<std::uint64_t>(rs.camera.width)),
                y = static_cast<int>(p / static_cast<std::uint64_t>(rs.camera.width));
      JoinPilot& sums = at[i];
      std::array<vec3, 2> f{};
      for (int s = 0; s < 2; ++s) {
        tally.clear();
        const std::uint64_t rays_before = th.rays;
        pilot.sample_run(th, x, y, static_cast<std::uint64_t>(s));
        pilot.trace_shadows(th);
        f[static_cast<std::size_t>(s)] = tally.camera;
        sums.samples += 1;
        sums.splats += tally.splats;
        sums.cost += static_cast<double>(th.rays - rays_before) + tally.joins;
        for (int t = 2; t <= th.nt; ++t) {
          const vec3 xt = tally.deep[static_cast<std::size_t>(t)];
          const double x2 = double(xt.x) * xt.x + double(xt.y) * xt.y + double(xt.z) * xt.z;
          const double r = th.eye[static_cast<std::size_t>(t - 1)].rr_throughput;
          const int joins = tally.deep_joins[static_cast<std::size_t>(t)];
          for (std::size_t k = 0; k < kJoinThresholds.size(); ++k) {
            const double q = std::min(1.0, r / kJoinThresholds[k]);
            if (!(q < 1.0)) continue;
            sums.added[k] += q > 0 ? x2 * (1.0 / q - 1.0) : 0.0;
            sums.skipped[k] += joins * (1.0 - q);
          }
        }
      }
      const vec3 d = f[0] - f[1];
      sums.camera = 0.5 * (double(d.x) * d.x + double(d.y) * d.y + double(d.z) * d.z);
      sums.pixels = 1;
    }
  });
  JoinPilot all;
  for (const JoinPilot& s : at) {
    all.samples += s.samples;
    all.camera += s.camera;
    all.pixels += s.pixels;
    all.splats += s.splats;
    all.cost += s.cost;
    for (std::size_t k = 0; k < kJoinThresholds.size(); ++k) {
      all.added[k] += s.added[k];
      all.skipped[k] += s.skipped[k];
    }
  }
  return choose_join_threshold(all, o.sampler == SamplerKind::kSobol);
}

}  // namespace pathex::tracer
