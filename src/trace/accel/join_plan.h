// `pathex trace --rr-threshold auto` and `--rr-join-threshold auto` (issue 39, the defaults): bdpt's
// roulette thresholds, the eye walk's and its joins', chosen per scene from a pilot, as
// efficiency-aware roulette (EARS, Rath et al. 2022) chooses its factors from estimates of the
// variance and cost each part of a path brings.
//
// The join roulette (Integrator::join_roulette()): eye vertex z(t-1), of throughput r relative to
// its walk's start, makes its joins with the light subpath's vertices (s >= 2) with probability q =
// min(1, r / T), each weighted 1 / q. Where their summed (MIS-weighted) contribution to the sample
// is X, that adds X² (1/q − 1) to the sample's variance and saves (1 − q) of their cost. Whether
// that pays is the scene's: where the light subpath's joins with the eye's first vertices already
// reach the paths a deep eye vertex's joins would, X is small and T = 1 gains (Tungsten's box
// 1.04×, cornell.json 1.13×, sun-window.json 1.34×); where the deep joins carry the light (a
// closed sphere round a point light) it loses (0.82×). No one threshold is right for both.
//
// The eye walk's roulette (Integrator::random_walk()): from vertex rr_depth on, the walk goes on to
// z(j) with probability min(1, ρ_j / (P(j-1) τ)), ρ_j its throughput there without the roulette's
// weights and P(j-1) its chance of having come so far: so it reaches z(j) with P(j) = min(P(j-1),
// ρ_j / τ), and everything z(j) and the vertices after it bring, Y_j (the camera contributions of
// t >= j + 1), weighted 1 / P(j). Nested so, the roulette adds Σ_j (1/P(j) − 1/P(j-1)) Y_j² to the
// sample's variance (the cross terms of two vertices weigh by the earlier's P) and saves (1 − P(j))
// of each vertex's cost. The eye's threshold 0.3 gains bdpt 1.2–9.7× over 1 where long eye walks
// carry the light (cornell.json, a closed sphere, materials.json); on Tungsten's box 1 is 1.03×
// 0.3 (issue 39, fourteenth and twentieth sessions).
//
// The model. The image's efficiency 1 / (V · C), V the pixels' summed variance of a sample, C a
// sample's cost, becomes 1 / ((V + ΔV) · (C − ΔC)) under thresholds (τ, T). V counts the camera's
// contributions (the spread of a pixel's samples) and the light tracer's splats (each sample's
// Σ c² over the image: a splat lands on one pixel of many), both less the emission seen directly
// (s + t = 2: no roulette touches it, and its variance is the lamp's edge, which the render's
// sampler stratifies); the camera's part divided by kStratified when the render samples by Sobol
// points (they lower it; the splats, landing on other pixels than their sample's, keep theirs). C
// is in rays: each ray traced and each join weighed counts 1; a join skipped saves kJoinCost, a
// vertex the eye walk does not reach 1 and its joins'. The pilot walks under the smallest eye
// candidate τ0 (its P0), so a candidate τ >= τ0 is the pilot's walk under a further roulette P'(j)
// = P(j) / P0(j): ΔV = Σ_j (1/P'(j) − 1/P'(j-1)) Y_j² + Σ_t X_t² (1/q_t − 1) / P'(t-1), the join's q_t
// of the throughput the walk carries under τ (the pilot's r / P'). Taken: the pair of candidates
// (kEyeThresholds × none and kJoinThresholds, or the value given where an option is not auto) of
// the largest predicted efficiency, if that is at least kMinJoinGain times the efficiency of the
// first pair (the eye's default or the one given; no join roulette or the one given); else that.
//
// The pilot. Before the render, kJoinPilotSamples camera samples at evenly spread pixels (at most
// 1 / kJoinPilotShare of the render's samples), 2 at each, under the independent sampler
// at a seed of its own, with no roulette of the joins, no images, nothing recorded; for every
// sample it tallies (Integrator::Thread::tally) its camera contributions by their eye vertex, its
// splats and its walk's roulette. Unbiased: the thresholds are a function of the pilot's numbers
// alone, which no sample of the render uses, and the render is unbiased for any thresholds fixed
// before it. Deterministic: a function of (seed, the pixels, the scene), not of the threads or the
// shards, so every shard of a render (and a resumed one) takes the same thresholds and their sums
// merge to the unsharded render's, byte for byte.
#pragma once

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <utility>
#include <vector>

#include "stats/histogram.h"
#include "trace/integrator.h"
#include "trace/render.h"
#include "trace/render_scene.h"
#include "trace/rng.h"

namespace pathex::tracer {

inline constexpr std::array<float, 6> kJoinThresholds{0.25f, 0.5f, 1.0f, 2.0f, 4.0f, 8.0f};
// The eye's candidates under `--rr-threshold auto`, ascending: the first, the default elsewhere
// (kDefaultEyeThreshold), is the pilot's own.
inline constexpr std::array<float, 3> kEyeThresholds{kDefaultEyeThreshold, 0.5f, 1.0f};
// A join skipped saves its shadow ray and its evaluation: measured 1.2-1.9 rays' worth on five
// sample scenes (the CPU of --rr-join-threshold 1000 against 0 over the joins it skips; bench/README.md,
// issue 39, nineteenth session).
inline constexpr double kJoinCost = 1.5;
// The camera's variance under Sobol points against independent samples: pt-nee off the lamp of
// Tungsten's box measured 1.4x (issue 39).
inline constexpr double kStratified = 1.4;
// Thresholds other than the first pair are taken only where the model predicts at least this
// gain: the pilot's estimates are noisy, and closed-sphere-point.json, the scene that loses under a
// join roulette, reads 1.02x at T = 0.5 by the model without the Sobol points' correction.
inline constexpr double kMinJoinGain = 1.03;
// The pilot's size: kJoinPilotSamples camera samples, at most 1 / kJoinPilotShare of the render's
// (where the roulette does not pay the pilot is the loss: 1.6 % at 1 / 64 measured on
// closed-sphere-point.json at 16 spp).
inline constexpr std::uint64_t kJoinPilotSamples = 8192, kJoinPilotShare = 128;

// The pilot's sums over its samples (per channel, summed over the three), and the candidates they
// price: eye[0] the pilot's own eye threshold, joins[0] the join threshold of the pair the others
// must beat (0: none).
struct JoinPilot {
  double samples = 0;
  double camera = 0;  // Σ over pilot pixels of their two samples' half squared difference
  double pixels = 0;
  double splats = 0;  // Σ over samples of their splats' Σ c²
  double cost = 0;    // rays and joins
  std::vector<float> eye{kDefaultEyeThreshold}, joins{0.0f};
  std::vector<double> added = std::vector<double>(1), saved = std::vector<double>(1);  // [e * joins.size() + k]: Σ ΔV, Σ ΔC

  JoinPilot() = default;
  JoinPilot(std::vector<float> eye_candidates, std::vector<float> join_candidates)
      : eye(std::move(eye_candidates)), joins(std::move(join_candidates)), added(eye.size() * joins.size()), saved(added.size()) {}
  std::size_t at(std::size_t e, std::size_t k) const { return e * joins.size() + k; }
  void add(const JoinPilot& o) {
    samples += o.samples;
    camera += o.camera;
    pixels += o.pixels;
    splats += o.splats;
    cost += o.cost;
    for (std::size_t i = 0; i < added.size(); ++i) {
      added[i] += o.added[i];
      saved[i] += o.saved[i];
    }
  }
};

inline double squared(vec3 c) { return double(c.x) * c.x + double(c.y) * c.y + double(c.z) * c.z; }

// One pilot sample's ΔV and ΔC (above) under every pair of candidates, added to `p`: `tally` its
// contributions, `eye` its eye subpath's nt vertices.
inline void price_sample(JoinPilot& p, const JoinTally& tally, const Vertex* eye, int nt) {
  std::array<vec3, kMaxVertices + 1> after{};  // after[j]: Y_j, the camera contributions of t >= j + 1
  for (int j = kMaxVertices - 1; j >= 0; --j)
    after[static_cast<std::size_t>(j)] = after[static_cast<std::size_t>(j + 1)] + tally.by_t[static_cast<std::size_t>(j + 1)];
  const double tau0 = p.eye[0];
  std::vector<double> dvj(p.joins.size()), dcj(p.joins.size());  // per join candidate, for one eye candidate
  for (std::size_t e = 0; e < p.eye.size(); ++e) {
    const double tau = p.eye[e];
    double p0 = 1, pe = 1, rel_before = 1, dv = 0, dc = 0;
    std::fill(dvj.begin(), dvj.end(), 0.0);
    std::fill(dcj.begin(), dcj.end(), 0.0);
    for (int j = 1; j < nt; ++j) {
      const auto ju = static_cast<std::size_t>(j);
      if (const float u = tally.survive[ju]; u > 0.0f && tau0 > 0) {  // the step to z(j) took the roulette
        const double rho = double(u) * tau0 * p0;  // the throughput at z(j) without the roulette's weights
        p0 = std::min(p0, rho / tau0);
        pe = std::min(pe, rho / tau);
      }
      const double rel = std::min(1.0, pe / p0);  // P'(j)
      if (rel <= 0) break;
      dv += (1.0 / rel - 1.0 / rel_before) * squared(after[ju]);
      dc += (1.0 - rel) * (1.0 + kJoinCost * tally.joins_at[ju + 1]);
      rel_before = rel;
      const double x2 = squared(tally.deep[ju + 1]), r = eye[j].rr_throughput / rel;
      const int n = tally.deep_joins[ju + 1];
      for (std::size_t k = 0; k < p.joins.size(); ++k) {
        const double q = p.joins[k] > 0 ? std::min(1.0, r / p.joins[k]) : 1.0;
        if (!(q < 1.0)) continue;
        dvj[k] += q > 0 ? x2 * (1.0 / q - 1.0) / rel : 0.0;
        dcj[k] += kJoinCost * n * (1.0 - q) * rel;
      }
    }
    for (std::size_t k = 0; k < p.joins.size(); ++k) {
      p.added[p.at(e, k)] += dv + dvj[k];
      p.saved[p.at(e, k)] += dc + dcj[k];
    }
  }
}

// The pair of the largest predicted efficiency (above).
inline RouletteThresholds choose_thresholds(const JoinPilot& p, bool stratified) {
  const RouletteThresholds first{p.eye[0], p.joins[0], 1.0, false};
  if (!(p.samples > 0) || !(p.pixels > 0)) return first;
  const double v = p.camera / p.pixels / (stratified ? kStratified : 1.0) + p.splats / p.samples, c = p.cost / p.samples;
  if (!(v > 0) || !(c > 0)) return first;
  const auto product = [&](std::size_t i) { return (v + p.added[i] / p.samples) * (c - p.saved[i] / p.samples); };
  const double base = product(p.at(0, 0));
  if (!(base > 0)) return first;
  RouletteThresholds best = first;
  for (std::size_t e = 0; e < p.eye.size(); ++e)
    for (std::size_t k = 0; k < p.joins.size(); ++k) {
      if (!(p.saved[p.at(e, k)] / p.samples < c)) continue;
      const double gain = base / product(p.at(e, k));
      if (gain > best.gain) best = {p.eye[e], p.joins[k], gain, true};
    }
  return best.gain >= kMinJoinGain ? best : RouletteThresholds{first.eye, first.join, best.gain, false};
}

// The pilot and choose_thresholds(): the thresholds of a render of `strategies` under `o`, whose
// rr_threshold or rr_join_threshold is auto (the other the value given); none (no pilot) where no
// strategy joins an eye vertex with the light subpath.
inline std::optional<RouletteThresholds> plan_roulette(const RenderScene& rs, const StrategySet& strategies, const RenderOptions& o, const PathFilter& filter,
                                                       const HistogramLayout& layout) {
  std::vector<float> eye{o.rr_threshold}, joins{o.rr_join_threshold};
  if (o.rr_threshold < 0) eye.assign(kEyeThresholds.begin(), kEyeThresholds.end());
  if (o.rr_join_threshold < 0) {
    joins = {0.0f};
    joins.insert(joins.end(), kJoinThresholds.begin(), kJoinThresholds.end());
  }
  RenderOptions po = o;
  po.sampler = SamplerKind::kIndependent;
  po.seed = mix64(o.seed ^ 0x3c6ef372fe94f82bULL);  // streams of its own (trace/rng.h)
  po.images = false;
  po.rr_threshold = eye[0];
  po.rr_join_threshold = 0.0f;
  po.splits = 1;
  const Integrator pilot(rs, strategies, po, filter);
  if (!pilot.traces_eye_rays() || !pilot.joins_with_light_subpath()) return std::nullopt;
  const std::uint64_t pixels = static_cast<std::uint64_t>(rs.camera.width) * static_cast<std::uint64_t>(rs.camera.height);
  // Pilot pixels, 2 samples each: kJoinPilotSamples, or fewer where that is more than
  // 1 / kJoinPilotShare of the render's samples.
  const std::uint64_t n = std::max<std::uint64_t>(1, std::min<std::uint64_t>(kJoinPilotSamples, pixels * o.spp / kJoinPilotShare) / 2);
  std::vector<JoinPilot> at(n, JoinPilot(eye, joins));  // each pilot pixel's sums, added in order below
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
        price_sample(sums, tally, th.eye.data(), th.nt);
      }
      sums.camera = 0.5 * squared(f[0] - f[1]);
      sums.pixels = 1;
    }
  });
  JoinPilot all(eye, joins);
  for (const JoinPilot& s : at) all.add(s);
  return choose_thresholds(all, o.sampler == SamplerKind::kSobol);
}

}  // namespace pathex::tracer
