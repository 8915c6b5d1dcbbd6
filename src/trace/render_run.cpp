// The tracer's entry point, render() (trace/render.h): which profile strategies the tracer runs,
// and the run itself: the threads (TBB), the passes dealt in chunks (schedule/pass_deal.h), each
// thread's integrator state, and the threads' histograms, images and statistics summed into the
// output. The estimator it drives, sample by sample, is render.cpp's Integrator.
#include <tbb/enumerable_thread_specific.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>

#include "trace/accel/eye_packets.h"
#include "trace/accel/join_plan.h"
#include "trace/accel/split_plan.h"
#include "trace/integrator.h"
#include "trace/plan.h"
#include "trace/render.h"
#include "trace/render_scene.h"

namespace pathex {

// --- strategies the tracer runs ---

Result<StrategySet> runnable_strategies(const Profile& profile) {
  // Every strategy the checker accepts (the manifold connector at t = 1 too: its eye end a fresh
  // sensor point, trace/joins/manifold_join.cpp).
  return StrategySet{profile.strategies};
}

bool manifold_shares_paths(const Profile& profile) {
  return std::any_of(profile.strategies.begin(), profile.strategies.end(), [](const Strategy& st) {
    return st.connector == ConnectorKind::kNone && (st.s.hi == Range::kOpen || st.s.hi >= 2);
  });
}

ManifoldOptions resolved_manifold(const Profile& profile, ManifoldOptions o) {
  const bool shares = manifold_shares_paths(profile);
  if (!o.rate) o.rate = kShareWithOtherPaths;  // (where another strategy samples the path too: Integrator::manifold_rate())
  if (!o.seeds) o.seeds = shares ? 1 : kManifoldSeeds;
  return o;
}

bool has_light_subpath(const Profile& profile) {
  return std::any_of(profile.strategies.begin(), profile.strategies.end(), [](const Strategy& st) {
    return st.s.hi == Range::kOpen || st.s.hi >= 2 || (st.s.contains(1) && st.t.lo < 2);
  });
}

// render.h says why; under the manifold connector auto took 6x the CPU on point-glass.json for
// 0.46x the efficiency (lamp-glass.json: 3.4x at 16 spp).
int resolved_splits(const Profile& profile, std::optional<int> splits) {
  const bool manifold = std::any_of(profile.strategies.begin(), profile.strategies.end(),
                                    [](const Strategy& st) { return st.connector == ConnectorKind::kManifold; });
  const bool nee = std::any_of(profile.strategies.begin(), profile.strategies.end(),
                               [](const Strategy& st) { return st.s.contains(1) && st.connector == ConnectorKind::kNone; });
  return splits.value_or(nee && !has_light_subpath(profile) && !manifold ? 0 : 1);
}

namespace tracer {
namespace {
// Paths a thread's histogram has room for before it first regrows (address space only).
constexpr std::size_t kReservedPaths = std::size_t{1} << 14;
}  // namespace
}  // namespace tracer

using tracer::Integrator;

Result<RenderOutput> render(const Scene& scene, const Profile& profile, const Classifier* classifier,
                            const RenderOptions& options) {
  return render(scene, whole_plan(profile), classifier, options);
}

Result<RenderOutput> render(const Scene& scene, const RenderPlan& plan, const Classifier* classifier,
                            const RenderOptions& options) {
  const Profile& profile = plan.profile;
  Result<StrategySet> strategies = runnable_strategies(profile);
  if (!strategies) return strategies.error();
  Result<RenderScene> rs = make_render_scene(scene);
  if (!rs) return rs.error();
  aim_emission(*rs, scene, plan.aimed_lights);
  if (options.light_sampling != LightSampling::kArea)
    sample_lights_by_solid_angle(*rs, scene, /*rectangles=*/options.light_sampling == LightSampling::kSolidAngle);
  RenderOptions o = options;
  const std::uint64_t pixels = static_cast<std::uint64_t>(rs->camera.width) * static_cast<std::uint64_t>(rs->camera.height);
  if (o.replicates == 0 && o.batches >= 1) o.replicates = default_replicates(o.batches, pixels);
  if (o.batches < 1 || o.replicates < 1 || o.batches % o.replicates != 0)
    return make_error(ErrorCode::kUsage, "the replicate count (" + std::to_string(o.replicates) +
                                             ") must divide the batch count (" + std::to_string(o.batches) + ")");
  // The same rule as the checker's: an explicit bound overrides the profile's own.
  if (!o.max_bounces) o.max_bounces = profile.max_bounces.value_or(16);
  o.manifold = resolved_manifold(profile, o.manifold);
  const int splits = resolved_splits(profile, o.splits);
  o.splits = splits;
  HistogramLayout layout;
  layout.num_batches = o.batches;
  layout.groups = o.batches / o.replicates;
  for (const Strategy& st : strategies->strategies) layout.strategies.push_back(st.name);

  RenderOutput out{Histogram(layout, classifier),
                   o.images ? ClassImages(rs->camera.width, rs->camera.height, classifier, o.layer_classes)
                            : ClassImages(0, 0, nullptr, {}),
                   layout.strategies};
  // --rr-threshold or --rr-join-threshold auto: the thresholds from a pilot, the same for every
  // shard (trace/accel/join_plan.h); without one (no joins with a light subpath) the defaults.
  if (o.rr_threshold < 0.0f || o.rr_join_threshold < 0.0f) {
    out.roulette = tracer::plan_roulette(*rs, *strategies, o, plan.filter, layout);
    o.rr_threshold = out.roulette ? out.roulette->eye : o.rr_threshold < 0.0f ? kDefaultEyeThreshold : o.rr_threshold;
    o.rr_join_threshold = out.roulette ? out.roulette->join : o.rr_join_threshold < 0.0f ? 0.0f : o.rr_join_threshold;
  }
  Integrator integrator(*rs, *strategies, o, plan.filter);
  // --splits auto: each pixel's counts, the same for every shard (trace/accel/split_plan.h).
  std::shared_ptr<const tracer::SplitMap> split_map;
  if (splits == 0 && o.split_map && (o.split_map->width != rs->camera.width || o.split_map->height != rs->camera.height ||
                                        o.split_map->counts.size() != pixels))
    return make_error(ErrorCode::kUsage, "the split map is not of the sensor's size");
  if (splits == 0) split_map = o.split_map ? o.split_map : tracer::plan_splits(*rs, *strategies, o, plan.filter, layout);
  const std::size_t area_lights = rs->lights.size() - scene.lights.size();  // the emissive shapes come first
  for (const int i : plan.aimed_lights)
    if (const std::optional<EmissionCones>& c = rs->lights[area_lights + static_cast<std::size_t>(i)].aim)
      out.aimed.push_back({i, std::holds_alternative<PointLight>(scene.lights[static_cast<std::size_t>(i)]) ? "point" : "spot",
                           c->size(), c->share()});
  const int threads = o.threads > 0 ? o.threads : static_cast<int>(tbb::this_task_arena::max_concurrency());
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
  tbb::enumerable_thread_specific<Integrator::Thread> locals(
      [&] {
        Integrator::Thread th{Histogram(layout, classifier),
                              std::vector<ClassImages::PixelSum>(static_cast<std::size_t>(out.images.width()), ClassImages::PixelSum(out.images)),
                              {}, {}, 0, {}, {}, {}};
        // Room for many paths and technique rows at once: the histogram keeps each of its batches'
        // cells and row sums in a row of its own, and a render finds new paths to the end (the
        // rare long ones), so regrowing moved every row into fresh pages, again and again (a
        // quarter of pt-nee's CPU time on the embedded Cornell box at 128 spp went to the copies
        // and their page faults). Address space only: pages are touched as paths arrive.
        th.hist.reserve_paths(tracer::kReservedPaths);
        th.hist.reserve_rows(2 * tracer::kReservedPaths);
        th.images = &out.images;
        th.splats = ClassImages::SplatBuffer(out.images.splat_entries(), out.images.splat_keys());
        th.connectors.resize(strategies->strategies.size());
        th.split.set(splits, split_map);
        return th;
      });
  const int w = rs->camera.width, h = rs->camera.height;
  // The eye subpaths' first rays in packets (outputs identical): wherever an eye subpath goes past z0.
  const bool eye_packets = integrator.traces_eye_rays();
  const auto start = std::chrono::steady_clock::now();
  // Passes run in chunks: a pixel takes a chunk's passes back to back, so that its camera
  // contributions reach the shared image once per chunk (and its part of the scene stays in
  // cache); cancelling stops on a whole chunk, so every finished pass covers the whole image. The
  // chunks come from a deal (schedule/pass_deal.h): this render's passes in order, or an MPI job's.
  ChunkDeal own(o.passes.value_or(PassSet::range(0, o.spp)), kPassesPerChunk);
  PassDealer& deal = o.dealer != nullptr ? *o.dealer : own;
  bool dealt_all = false;
  while (!(o.cancel && o.cancel->load())) {
    const std::optional<PassRange> chunk = deal.next();
    if (!chunk) {
      dealt_all = true;
      break;
    }
    const std::uint64_t first = chunk->first, end = chunk->last;
    tbb::parallel_for(tbb::blocked_range<int>(0, h, 1), [&](const tbb::blocked_range<int>& rows) {
      Integrator::Thread& th = locals.local();
      for (int y = rows.begin(); y < rows.end(); ++y) {
        if (eye_packets) {
          tracer::sample_row_in_packets(integrator, th, *rs, o, y, first, end);  // trace/accel/eye_packets.h
        } else {
          for (int x = 0; x < w; ++x)
            for (std::uint64_t p = first; p < end; ++p) integrator.sample(th, x, y, p);
        }
        integrator.finish_row(th, out.images, y);
      }
    });
    // Each pass adds one sample per pixel: pixels / G to every group, one more to the first pixels mod G.
    const auto groups = static_cast<std::uint64_t>(layout.groups);
    for (std::uint64_t p = first; p < end; ++p)
      for (std::uint64_t g = 0; g < std::min(groups, pixels); ++g)
        out.histogram.add_samples(batch_of(g, p, o.batches, o.replicates), pixels / groups + (g < pixels % groups ? 1 : 0));
    out.passes_done.add(first, end);
    if (o.progress) o.progress(deal.dealt() * pixels, deal.total() * pixels);
  }
  out.spp_done = out.passes_done.count();
  out.complete = dealt_all;
  // The threads' histograms are summed into the first of them, which then takes the place of
  // the output's (holding only the sample counts so far): one fewer copy of every path, and of
  // its classification. Ids are local to a histogram, so which thread comes first does not show.
  std::optional<Histogram> summed;
  for (Integrator::Thread& th : locals) {
    th.splats.flush(out.images);
    th.ids.flush(th.hist);
    if (!summed) {
      summed.emplace(std::move(th.hist));
    } else {
      Result<bool> m = summed->merge(th.hist);
      if (!m) return m.error();
    }
    out.rays += th.rays;
    if (th.first_nonfinite && (!out.first_nonfinite || th.first_nonfinite->order() < out.first_nonfinite->order()))
      out.first_nonfinite = th.first_nonfinite;
  }
  if (summed) {
    Result<bool> m = summed->merge(out.histogram);  // the sample counts of every batch
    if (!m) return m.error();
    out.histogram = std::move(*summed);
  }
  // Connector statistics, in the profile's order (integer sums: the same for every thread count).
  for (std::size_t i = 0; i < strategies->strategies.size(); ++i) {
    const Strategy& st = strategies->strategies[i];
    if (st.connector == ConnectorKind::kNone) continue;
    ConnectorStats total{st.name, to_string(st.connector)};
    for (const Integrator::Thread& th : locals) total += th.connectors[i];
    out.connectors.push_back(total);
  }
  out.time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return out;
}

}  // namespace pathex
