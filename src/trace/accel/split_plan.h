// `pathex trace --splits auto` (issue 39): each pixel's split counts (trace/accel/first_vertex_split.h)
// chosen from a pilot, as efficiency-aware splitting (EARS, Rath et al. 2022) chooses its factors
// from estimates of the variance and cost each part of a path brings.
//
// The model. A pixel's sample of M camera rays, each with N runs after its first hit, has the
// variance (V_cam + V_run / N) / M and the cost M · (C_cam + N · C_run), where V_cam is the variance
// between camera rays of the pixel's expected light (a lamp's edge, the pixel's footprint) and V_run
// the mean variance of a run given its camera ray (the indirect light).
// - N, the pixel's own: the N that makes its sample most efficient, sqrt((V_run / V_cam) · (C_cam /
//   C_run)), rounded into [1, kMaxRunsPerCamera] (no V_cam: the bound).
// - M, the image's: with N so, the camera rays that minimise the image's summed variance for its
//   summed cost (its efficiency, 1 / (MSE × cost)) are M = sqrt(v / (λ c)), v and c a camera ray's
//   variance and cost with its runs, one multiplier λ for the whole image, rounded into [1,
//   kMaxCameras]. λ is the one of a fixed grid whose map the model finds most efficient, no lower
//   than half the pixels' v / c (a pass stays one camera ray for most pixels: below, the model's
//   product is flat, every M scaling alike). So a lamp's edge, whose error is its camera rays', takes
//   up to kMaxCameras of them, and the indirect light kMaxRunsPerCamera runs per camera ray.
//
// The pilot. Before the render, every other pixel (a checkerboard) takes 2 camera rays with 2 runs
// each, under the independent sampler at a seed of its own. Pooled over the 5 × 5 pixels around each
// pixel: V_run is the mean of the runs' squared differences / 2; V_cam the sample variance of the
// window's camera rays' means (the camera's variance over the window's footprint, so that a lamp's
// edge counts for every pixel within 2 of it, as issue 39's lamp border does) less what their runs
// add (V_run / 2) and less kNoise · V_run / sqrt(n), so that where the camera's share is within the
// pilot's noise (most of an image lit indirectly) it counts as none; C_run the rays a run traces past
// its camera ray; C_cam is a constant (kCameraCost rays, measured). Nothing the pilot draws is
// recorded; it costs about two samples per piloted pixel.
//
// Unbiased: the counts are a function of the pilot's numbers alone, which no sample of the render
// uses, and the render is unbiased for any counts fixed before it. Deterministic: the pilot is a
// function of (seed, pixel), not of the passes a render takes, its threads or its shards, so every
// shard of a render (and a resumed one) splits each pixel alike and their sums merge to the
// unsharded render's, byte for byte.
#pragma once

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "film/image.h"
#include "stats/histogram.h"
#include "trace/accel/split_counts.h"
#include "trace/integrator.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

inline constexpr int kMaxCameras = 16;
inline constexpr int kMaxRunsPerCamera = 8;
// A camera ray and its first hit cost as much as this many rays traced in a run (pt-nee on
// Tungsten's box: bench/README.md, issue 39, eleventh session).
inline constexpr double kCameraCost = 0.6;
inline constexpr int kPoolRadius = 2;  // the pilot's estimates pooled over (2r + 1)² pixels
// V_cam counts only beyond kNoise · V_run / sqrt(n), n the window's pilot pixels (measured on
// Tungsten's box: 1.6 and 4 let the noise of indirect light through, bench/README.md).
inline constexpr double kNoise = 10.0;

// The pilot's estimates at one pixel (pooled): variances summed over the three channels, and the
// rays a run traces past its camera ray.
struct SplitEstimate {
  double v_cam = 0, v_run = 0;
  double c_run = 1;
};

// The runs per camera ray that make the pixel's own sample most efficient, N = sqrt((V_run / V_cam)
// · (C_cam / C_run)), rounded into [1, kMaxRunsPerCamera].
inline int split_runs(const SplitEstimate& e) {
  if (!(e.v_run > 0)) return 1;
  if (!(e.v_cam > 0)) return kMaxRunsPerCamera;
  const double n = std::sqrt(e.v_run / e.v_cam * (kCameraCost / e.c_run));
  return static_cast<int>(std::clamp(n + 0.5, 1.0, static_cast<double>(kMaxRunsPerCamera)));
}
// The counts at multiplier λ: N as split_runs(), and M = sqrt(v / (λ c)) camera rays, v and c a
// camera ray's variance and cost with its N runs, rounded into [1, kMaxCameras].
inline SplitCounts split_counts(const SplitEstimate& e, int runs, double lambda) {
  const double v = e.v_cam + e.v_run / runs, c = kCameraCost + runs * e.c_run;
  return {static_cast<int>(std::clamp(std::sqrt(v / (lambda * c)) + 0.5, 1.0, static_cast<double>(kMaxCameras))), runs};
}

// What the model predicts for a map: the image's summed cost and variance.
inline double split_cost(const SplitEstimate& e, SplitCounts c) { return c.cameras * (kCameraCost + c.runs * e.c_run); }
inline double split_variance(const SplitEstimate& e, SplitCounts c) { return (e.v_cam + e.v_run / c.runs) / c.cameras; }

// The counts of every pixel: its own N, and M at the λ of a grid (2^(k/2) times the image's mean
// variance per cost of a camera ray, |k| <= 40) whose map the model finds most efficient for the
// whole image. Sums in pixel order: the same map on every machine.
inline SplitMap choose_splits(int width, int height, const std::vector<SplitEstimate>& estimates) {
  SplitMap best{width, height, std::vector<SplitCounts>(estimates.size())};
  std::vector<int> runs(estimates.size());
  double v = 0, c = 0;
  for (std::size_t p = 0; p < estimates.size(); ++p) {
    runs[p] = split_runs(estimates[p]);
    best.counts[p] = SplitCounts{1, runs[p]};
    v += estimates[p].v_cam + estimates[p].v_run / runs[p];
    c += kCameraCost + runs[p] * estimates[p].c_run;
  }
  if (!(v > 0) || !(c > 0)) return best;
  const auto product = [&](double lambda) {
    double cost = 0, variance = 0;
    for (std::size_t p = 0; p < estimates.size(); ++p) {
      const SplitCounts n = lambda > 0 ? split_counts(estimates[p], runs[p], lambda) : SplitCounts{1, runs[p]};
      cost += split_cost(estimates[p], n);
      variance += split_variance(estimates[p], n);
    }
    return cost * variance;
  };
  // At least half the pixels with any variance take one camera ray per sample (the render's spp):
  // λ no lower than their median v / c (below it the model's product is flat, every M scaling alike).
  std::vector<double> ratio;
  for (std::size_t p = 0; p < estimates.size(); ++p) {
    const SplitCounts one{1, runs[p]};
    if (split_variance(estimates[p], one) > 0) ratio.push_back(split_variance(estimates[p], one) / split_cost(estimates[p], one));
  }
  std::nth_element(ratio.begin(), ratio.begin() + static_cast<std::ptrdiff_t>(ratio.size() / 2), ratio.end());
  const double lambda_min = ratio[ratio.size() / 2];
  double best_product = product(0), best_lambda = 0;
  for (int k = 40; k >= -40; --k) {
    const double lambda = v / c * std::exp2(k / 2.0);
    if (lambda < lambda_min) break;
    const double here = product(lambda);
    if (here < best_product) {
      best_product = here;
      best_lambda = lambda;
    }
  }
  if (best_lambda > 0)
    for (std::size_t p = 0; p < estimates.size(); ++p) best.counts[p] = split_counts(estimates[p], runs[p], best_lambda);
  return best;
}

// The pilot and choose_splits(): the map of a --splits auto render of `strategies` under `o`.
inline std::shared_ptr<const SplitMap> plan_splits(const RenderScene& rs, const StrategySet& strategies, const RenderOptions& o,
                                                   const PathFilter& filter, const HistogramLayout& layout) {
  const int w = rs.camera.width, h = rs.camera.height;
  const std::size_t pixels = static_cast<std::size_t>(w) * static_cast<std::size_t>(h);
  RenderOptions po = o;
  po.sampler = SamplerKind::kIndependent;
  po.seed = mix64(o.seed ^ 0x8a2e03707344a409ULL);  // streams of its own (trace/rng.h)
  po.images = true;  // the pilot reads the pixels' sums: a --no-images render splits as the render with images
  const Integrator pilot(rs, strategies, po, filter);
  if (!pilot.traces_eye_rays()) return std::make_shared<SplitMap>(SplitMap{w, h, std::vector<SplitCounts>(pixels)});
  // Per pilot pixel: the runs' within-ray squared differences, each camera ray's mean, the rays.
  std::vector<double> within(pixels, 0.0), rays(pixels, 0.0);
  std::vector<std::array<Rgb, 2>> means(pixels);  // each camera ray's mean over its runs
  std::vector<std::uint8_t> piloted(pixels, 0);
  ClassImages camera(w, h, nullptr, {}), splats(w, h, nullptr, {});  // splats: thrown away
  tbb::enumerable_thread_specific<Integrator::Thread> locals([&] {
    Integrator::Thread th{Histogram(layout, nullptr), std::vector<ClassImages::PixelSum>(static_cast<std::size_t>(w), ClassImages::PixelSum(camera)),
                          {}, {}, 0, {}, {}, {}};
    th.images = &splats;
    th.splats = ClassImages::SplatBuffer(splats.splat_entries(), splats.splat_keys());
    th.connectors.resize(strategies.strategies.size());
    return th;
  });
  constexpr SplitCounts kPilot{1, 2};
  tbb::parallel_for(tbb::blocked_range<int>(0, h, 1), [&](const tbb::blocked_range<int>& rows) {
    Integrator::Thread& th = locals.local();
    for (int y = rows.begin(); y < rows.end(); ++y)
      for (int x = y % 2; x < w; x += 2) {
        const std::size_t p = static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x);
        Rgb run[2][2]{};
        Rgb before{};
        const std::uint64_t rays_before = th.rays;
        for (int i = 0; i < 2; ++i)
          for (int j = 0; j < kPilot.runs; ++j) {
            th.split.begin(kPilot, 0, j, static_cast<std::uint32_t>(i));
            pilot.sample_run(th, x, y, static_cast<std::uint64_t>(i));
            pilot.trace_shadows(th);
            th.row[static_cast<std::size_t>(x)].flush(camera, x, y);
            const Rgb sum = to_double(camera.sum(0, x, y));
            for (int ch = 0; ch < 3; ++ch) {
              const auto c = static_cast<std::size_t>(ch);
              run[i][j][c] = (sum[c] - before[c]) * kPilot.runs;  // a whole sample's
              before[c] = sum[c];
            }
          }
        for (std::size_t c = 0; c < 3; ++c)
          for (int i = 0; i < 2; ++i) {
            within[p] += 0.25 * (run[i][0][c] - run[i][1][c]) * (run[i][0][c] - run[i][1][c]);
            means[p][static_cast<std::size_t>(i)][c] = 0.5 * (run[i][0][c] + run[i][1][c]);
          }
        rays[p] = static_cast<double>(th.rays - rays_before) / 4.0 - 1.0;  // a run's, past its camera ray
        piloted[p] = 1;
      }
  });
  // Pooled over the window around each pixel (the pilot pixels in it), in a fixed order. V_run is
  // the mean within-ray estimate; V_cam the variance of all the window's camera rays' means less
  // what their runs add (V_run / 2) and kNoise · V_run / sqrt(n) more: the camera's variance over
  // the window's footprint, so that a lamp's edge counts for the pixels within kPoolRadius of it
  // (and where the camera's share is within the pilot's noise, most of an image lit indirectly,
  // it counts as none).
  std::vector<SplitEstimate> estimates(pixels);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      double sw = 0, sr = 0, n = 0;
      Rgb s1{}, s2{};
      for (int v = std::max(0, y - kPoolRadius); v <= std::min(h - 1, y + kPoolRadius); ++v)
        for (int u = std::max(0, x - kPoolRadius); u <= std::min(w - 1, x + kPoolRadius); ++u) {
          const std::size_t q = static_cast<std::size_t>(v) * static_cast<std::size_t>(w) + static_cast<std::size_t>(u);
          if (!piloted[q]) continue;
          sw += within[q];
          sr += rays[q];
          n += 1;
          for (const Rgb& m : means[q])
            for (std::size_t c = 0; c < 3; ++c) {
              s1[c] += m[c];
              s2[c] += m[c] * m[c];
            }
        }
      SplitEstimate& e = estimates[static_cast<std::size_t>(y) * static_cast<std::size_t>(w) + static_cast<std::size_t>(x)];
      if (n < 2) continue;
      double spread = 0;  // the camera rays' means' sample variance, summed over the channels
      for (std::size_t c = 0; c < 3; ++c) spread += std::max(s2[c] - s1[c] * s1[c] / (2 * n), 0.0) / (2 * n - 1);
      e.v_run = sw / n;
      e.v_cam = std::max(spread - 0.5 * e.v_run - kNoise * e.v_run / std::sqrt(n), 0.0);
      e.c_run = std::max(sr / n, 0.5);
    }
  return std::make_shared<SplitMap>(choose_splits(w, h, estimates));
}

}  // namespace pathex::tracer
