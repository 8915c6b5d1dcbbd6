// trace's run (measure/trace_run.h): the job, the plan, the render (dealt among MPI ranks), --missed's
// reference, the ranks' shard files and the render folder. The command (cli/trace.cpp) parses
// options, warns with the checker and prints the table.
#include "measure/trace_run.h"

#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <memory>
#include <sstream>
#include <thread>

#include "automata/ops.h"
#include "io/atomic_file.h"
#include "io/image_io.h"
#include "io/output_set.h"
#include "measure/render_watch.h"
#include "output/bias_json.h"
#include "reach/profile.h"
#include "scene/universe.h"
#include "trace/plan.h"
#include "trace/render.h"

namespace pathex {
namespace {

std::string gib(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / static_cast<double>(std::uint64_t{1} << 30));
  return buf;
}

}  // namespace

Result<TraceResult> run_trace(const TraceOptions& a, const TraceHooks& hooks) {
  const TraceJobOptions& o = a.job;
  TraceResult res;
  {
    Result<TraceJob> loaded = load_trace_job(o);
    if (!loaded) return loaded.error();
    res.job = std::move(*loaded);
  }
  TraceJob& job = res.job;
  const RenderIdentity& id = job.header.identity;
  Cluster* cluster = current_cluster();
  const int rank = cluster != nullptr ? cluster->rank() : 0;
  const int ranks = cluster != nullptr ? cluster->size() : 1;
  if (a.missed && (!o.shard.empty() || !o.resume.empty() || ranks > 1))
    return make_error(ErrorCode::kUsage, "--missed measures a whole render in one process: it cannot be given with "
                                         "--shard, --resume or MPI");
  if (!a.write && (!o.shard.empty() || !o.resume.empty() || ranks > 1))
    return make_error(ErrorCode::kUsage, "a render that writes no files cannot be a shard, a resumed render or an MPI run");
  if (a.missed && !id.only.empty())
    return make_error(ErrorCode::kUsage, "--missed measures what the whole render misses: it cannot be given with --only");

  // --- DESIGN §11: the plan (trace/plan.h): the strategies that can sample a requested path of
  // this scene, the lights' emission narrowing, the paths recorded ---
  res.universe = scene_universe(scene_types(*job.scene));
  Result<RenderPlan> plan = plan_render(*job.scene, *job.profile, id.max_bounces, job.classes->requested, o.limits);
  if (!plan) return plan.error();
  res.changes = plan->changes;
  if (plan->samples_nothing()) {
    res.nothing_to_render = true;
    for (const PathClass* c : job.classes->requested)
      if (is_empty(dfa_intersect(dfa_intersect(c->dfa, res.universe), bounded_universe(id.max_bounces))))
        res.no_path.push_back(c->text);
    return res;
  }
  if (Result<bool> r = settle_strategies(plan->profile, &job); !r) return r.error();

  // The output folder is checked before the render, not after it.
  std::optional<OutputSet> out_set;
  if (rank == 0 && a.write) {
    Result<OutputSet> prepared = OutputSet::prepare(job.out);
    if (!prepared) return prepared.error();
    out_set.emplace(std::move(*prepared));
  }
  if (rank == 0 && hooks.before_render)
    if (Result<bool> r = hooks.before_render(job, res.universe); !r) return r.error();

  // --- render the passes still missing: all of them, or under MPI the chunks of them that the
  // ranks' shared deal hands this rank (whoever is free takes the next, schedule/pass_deal.h) ---
  const PassSet todo = job.header.share.minus(job.header.passes);
  RenderOptions ro;
  ro.spp = job.header.spp;
  std::unique_ptr<PassDealer> dealer;
  if (cluster != nullptr) {
    dealer = cluster->deal(todo, kPassesPerChunk, id.batches);
    ro.dealer = dealer.get();
  } else {
    ro.passes = todo;
  }
  ro.seed = id.seed;
  ro.threads = a.threads;
  ro.max_bounces = id.max_bounces;
  ro.sampler = id.sampler == "sobol" ? SamplerKind::kSobol : SamplerKind::kIndependent;
  ro.light_sampling = light_sampling_named(id.light_sampling);
  ro.rr_depth = id.rr_depth;
  ro.rr_threshold = static_cast<float>(id.rr_threshold);
  ro.rr_light_threshold = static_cast<float>(id.rr_light_threshold);
  ro.rr_join_threshold = static_cast<float>(id.rr_join_threshold);
  ro.splits = id.splits;
  ro.manifold = id.manifold.value_or(ManifoldOptions{});
  ro.batches = id.batches;
  ro.replicates = id.replicates;
  // Without image outputs the render keeps the histogram alone (the same histogram).
  ro.images = id.images;
  if (ro.images)
    for (int i = 0; i < job.classes->classifier->num_classes(); ++i) ro.layer_classes.push_back(i);
  // --- memory: the images and their writing, estimated before the render ---
  const int num_layers = 1 + static_cast<int>(ro.layer_classes.size());
  const std::uint64_t need = ro.images ? render_memory_estimate(id.width, id.height, num_layers) : 0;
  if (need > a.max_memory) {
    Error e = make_error(ErrorCode::kLimit,
                         "the images would take about " + gib(need) + " (" + std::to_string(id.width) + " x " +
                             std::to_string(id.height) + " pixels, " + std::to_string(num_layers) +
                             " layers), more than --max-memory " + gib(a.max_memory) +
                             "; pass --no-images for the histogram alone, render fewer pixels or classes, or raise --max-memory");
    e.where = id.scene + ":/camera";
    return e;
  }
  const std::atomic<bool>* stopped = nullptr;
  const double cpu_start = process_cpu_seconds();
  Result<RenderOutput> out = [&] {
    const RenderWatch watch(rank == 0 && a.progress, a.time_limit);
    ro.progress = watch.progress();
    ro.cancel = stopped = watch.cancel();
    return render(*job.scene, *plan, job.classes->classifier.get(), ro);
  }();
  const double cpu_s = process_cpu_seconds() - cpu_start;
  if (!out) return out.error();
  res.time_s = out->time_s;
  res.roulette = out->roulette;
  // --only: a light aimed at the shapes a requested path can reach first is listed with the
  // strategies the checker narrowed (the table's "narrowed:" lines, run.json's "pruned").
  for (const AimedLight& l : out->aimed) {
    std::ostringstream now;
    now << "the cones around " << l.shapes << (l.shapes == 1 ? " shape" : " shapes") << " with a specular component ("
        << std::fixed << std::setprecision(1) << 100.0 * l.share << " % of the directions)";
    res.changes.push_back({"light /lights/" + std::to_string(l.light) + " (" + l.kind + ")", "emission (every direction)", now.str(),
                           "every requested path scatters specularly at its first vertex"});
  }
  // Non-finite samples are bugs (DESIGN §7): say so, and where the first arose.
  if (const std::uint64_t n = out->histogram.nonfinite(); n > 0 && hooks.notice) {
    std::ostringstream line;
    line << "warning: " << n << " non-finite samples (dropped; any is a bug)";
    if (const auto& f = out->first_nonfinite)
      line << "; the first from strategy " << f->strategy << " on path " << f->path << " (near pixel (" << f->x << ", "
           << f->y << "), pass " << f->pass << ")";
    hooks.notice(line.str());
  }

  // --- missed: a reference render of the same scene, spp and seed measures what this one misses ---
  if (a.missed) {
    BiasOptions bo;
    bo.spp = job.header.spp;
    bo.seed = id.seed;
    bo.threads = a.threads;
    bo.renderer_bounces = id.max_bounces;  // what this render could sample: its own bound
    bo.renderer_histogram = &out->histogram;  // and what it found, against the reference
    bo.images = false;
    bo.limits = o.limits;
    const RenderWatch watch(a.progress);
    bo.progress = watch.progress();
    bo.cancel = watch.cancel();
    Result<BiasRun> b = measure_missed(*job.scene, id.scene, *job.profile, a.reference, {}, bo);
    if (!b) return b.error();
    res.missed = std::move(b->report);
  }

  res.sums.emplace(RenderSums{std::move(out->histogram), std::move(out->images), std::move(out->connectors)});
  RenderSums& sums = *res.sums;
  ShardHeader& header = res.header;
  header = job.header;
  header.passes = out->passes_done;
  header.run = {out->time_s, ro.threads > 0 ? ro.threads : static_cast<int>(std::thread::hardware_concurrency()), out->rays,
                cpu_s};

  // --- MPI: keep this rank's work in a shard file, written while every rank's sums are added
  // into rank 0's (the reduction reads the sums; rank 0 waits for the file before it changes
  // them). Signals wait for the file: a rank that dies makes mpirun stop the others ---
  if (cluster != nullptr) {
    const std::string mine = rank_shard_path(job.out, rank);
    std::error_code ec;
    std::filesystem::create_directories(ranks_folder(job.out), ec);
    std::optional<Result<bool>> kept;
    std::thread keeper([&, h = header] {
      const SignalShield shield;
      kept.emplace(write_shard(mine, h, sums));
    });
    const auto kept_now = [&] {
      if (keeper.joinable()) keeper.join();
    };
    dealer.reset();  // the deal ends once every rank has left it
    Result<bool> reduced = cluster->reduce(&sums, &header.passes, &header.run, kept_now);
    kept_now();
    if (!*kept) return kept->error();
    // Every rank's file is whole before rank 0 writes the outputs: a rank that dies before this
    // point leaves rank files that --resume completes, never outputs beside them.
    cluster->count_failures(true);
    if (stopped->load() && hooks.notice)
      hooks.notice("rank " + std::to_string(rank) + " stopped after " + out->passes_done.to_string() +
                   " of its passes; they are kept in " + mine + " ('pathex trace --resume " + job.out +
                   "' finishes the render)");
    if (!reduced) return reduced.error();
  }
  if (job.resumed) {
    if (Result<bool> m = sums.histogram.merge(job.resumed->sums.histogram); !m) return m.error();
    if (Result<bool> m = sums.images.merge(job.resumed->sums.images); !m) return m.error();
    for (std::size_t i = 0; i < sums.connectors.size(); ++i) sums.connectors[i] += job.resumed->sums.connectors[i];
    header.passes.add(job.resumed->header.passes);
    header.run.time_s += job.resumed->header.run.time_s;
    header.run.rays += job.resumed->header.run.rays;
    header.run.cpu_s += job.resumed->header.run.cpu_s;
  }

  // --- outputs (rank 0): one set, whole or not at all, shielded from signals (io/output_set.h) ---
  std::optional<Error> failure;
  if (!a.write) {
    Result<WrittenReport> r = render_report(header, sums, *job.classes);
    if (!r) return r.error();
    res.written = std::move(*r);
    return res;
  }
  if (rank == 0) {
    const SignalShield shield;
    Result<bool> w = out_set->write([&](const std::string& dir) -> Result<bool> {
      Result<WrittenReport> r = write_render_outputs(dir, header, sums, *job.classes, res.changes);
      if (!r) return r.error();
      res.written = std::move(*r);
      if (res.missed)  // what pathex bias writes to bias.json, without images
        if (Result<bool> m = write_file_atomic(dir + "/missed.json", bias_json_text(*res.missed)); !m) return m;
      if (hooks.extra_files)
        if (Result<bool> x = hooks.extra_files(dir, res); !x) return x.error();
      return true;
    });
    if (!w) failure = w.error();
  }
  if (cluster != nullptr) {
    // Every rank's work is in render.shard once rank 0 has written it: the ranks' files go.
    if (cluster->count_failures(!failure) == 0) {
      std::error_code ec;
      std::filesystem::remove(rank_shard_path(job.out, rank), ec);
    }
    if (rank != 0) {
      res.root = false;
      return res;
    }
  }
  if (failure) return *failure;
  {  // the ranks' files of a failed MPI run, now held by render.shard
    std::error_code ec;
    std::filesystem::remove_all(ranks_folder(job.out), ec);
  }
  return res;
}

}  // namespace pathex
