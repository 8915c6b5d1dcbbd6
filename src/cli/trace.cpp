// pathex trace: render a scene, label every sampled path, write the path-class histogram, the
// per-class EXR and PNG previews, and print where the light went, class by class, next to what the
// checker says the renderer can reach. The render's loading (its identity, hashes, classes, the
// shards to resume) is the library's, output/trace_job.h.
#include <chrono>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include <tbb/global_control.h>

#include "cli/bias_common.h"
#include "cli/common.h"
#include "io/estimate_text.h"
#include "output/trace_job.h"
#include "cli/folder_report.h"
#include "cli/reach_common.h"
#include "output/bias_json.h"
#include "output/render_job.h"
#include "measure/render_watch.h"
#include "cli/trace_checks.h"
#include "io/atomic_file.h"
#include "io/class_file.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/output_set.h"
#include "scene/universe.h"
#include "automata/ops.h"
#include "trace/plan.h"
#include "trace/render.h"

namespace pathex::cli {
namespace {

// --max-memory's default: what the render's images and their writing may take, estimated before
// rendering (render_memory_estimate()).
constexpr std::uint64_t kDefaultMaxMemory = std::uint64_t{4} << 30;

struct TraceArgs {
  TraceJobOptions options;  // output/trace_job.h: the render's settings
  int threads = 0;
  int top_paths = 8;
  bool json = false;
  bool quiet = false;
  double time_limit = 0;   // seconds; 0: none
  std::uint64_t max_memory = kDefaultMaxMemory;
  bool missed = false;       // also measure what the renderer misses (pathex bias)
  std::string reference;     // the reference for --missed; empty: bias's default
  bool report_html = false;  // --report: also write DIR/report.html (pathex report)
  ReportOptions report_options;
};

std::string gib(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / static_cast<double>(std::uint64_t{1} << 30));
  return buf;
}

int run(const TraceArgs& a) {
  const TraceJobOptions& o = a.options;
  // --threads bounds the whole command, not only the render's loop: Embree's BVH build before it
  // and the concurrent writing after it would otherwise start TBB worker threads (which spin
  // while they wait) for a render that asked for one thread.
  std::optional<tbb::global_control> limit;
  if (a.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(a.threads));
  Result<TraceJob> loaded = load_trace_job(o);
  if (!loaded) return report(loaded.error());
  TraceJob& job = *loaded;
  const RenderIdentity& id = job.header.identity;
  Cluster* cluster = current_cluster();
  const int rank = cluster != nullptr ? cluster->rank() : 0;
  const int ranks = cluster != nullptr ? cluster->size() : 1;
  if (a.missed && (!o.shard.empty() || !o.resume.empty() || ranks > 1))
    return report(make_error(ErrorCode::kUsage, "--missed measures a whole render in one process: it cannot be given with "
                                                "--shard, --resume or MPI"));
  if (a.missed && !id.only.empty())
    return report(make_error(ErrorCode::kUsage, "--missed measures what the whole render misses: it cannot be given with --only"));

  // --- DESIGN §11: the plan (trace/plan.h): the strategies that can sample a requested path of
  // this scene, the lights' emission narrowing, the paths recorded ---
  const Dfa universe = scene_universe(scene_types(*job.scene));
  Result<RenderPlan> plan = plan_render(*job.scene, *job.profile, id.max_bounces, job.classes->requested, o.limits);
  if (!plan) return report(plan.error());
  std::vector<PrunedStrategy>& changes = plan->changes;
  if (plan->samples_nothing()) {
    std::cout << "nothing to render: no strategy of " << id.renderer << " samples a path of "
              << (id.only.empty() ? "this scene" : "the requested classes in this scene") << " ("
              << describe(scene_types(*job.scene)) << ")\n";
    for (const PathClass* c : job.classes->requested)
      if (is_empty(dfa_intersect(dfa_intersect(c->dfa, universe), bounded_universe(id.max_bounces))))
        std::cout << "  " << c->text << " has no path in this scene\n";
    for (const PrunedStrategy& p : changes) std::cout << "  " << p.strategy << " " << p.was << ": " << p.reason << "\n";
    return kExitNo;
  }
  if (Result<bool> r = settle_strategies(plan->profile, &job); !r) return report(r.error());

  // The output folder is checked before the render, not after it.
  std::optional<OutputSet> out_set;
  if (rank == 0) {
    Result<OutputSet> prepared = OutputSet::prepare(job.out);
    if (!prepared) return report(prepared.error());
    out_set.emplace(std::move(*prepared));
  }

  // The checker's view of the profile, for the warning now and the table after the render (rank
  // 0 prints both; the other ranks skip the compilation).
  ReachCache cache(o.limits);
  const CompiledProfile* compiled = nullptr;
  if (rank == 0) {
    Result<const CompiledProfile*> cp = cache.compiled(id.renderer_source, id.max_bounces);
    if (!cp) return report(cp.error());
    compiled = *cp;
    warn_unreachable_lights(*job.scene, *job.profile, *compiled, universe, id.max_bounces, o.limits);
  }

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
  ro.rr_depth = id.rr_depth;
  ro.rr_threshold = static_cast<float>(id.rr_threshold);
  ro.rr_light_threshold = static_cast<float>(id.rr_light_threshold);
  ro.manifold = id.manifold.value_or(ManifoldOptions{});
  ro.batches = id.batches;
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
    return report(e);
  }
  const std::atomic<bool>* stopped = nullptr;
  const double cpu_start = process_cpu_seconds();
  Result<RenderOutput> out = [&] {
    const RenderWatch watch(rank == 0 && !a.quiet, a.time_limit);
    ro.progress = watch.progress();
    ro.cancel = stopped = watch.cancel();
    return render(*job.scene, *plan, job.classes->classifier.get(), ro);
  }();
  const double cpu_s = process_cpu_seconds() - cpu_start;
  if (!out) return report(out.error());
  // --only: a light aimed at the shapes a requested path can reach first is listed with the
  // strategies the checker narrowed (the table's "narrowed:" lines, run.json's "pruned").
  for (const AimedLight& l : out->aimed) {
    std::ostringstream now;
    now << "the cones around " << l.shapes << (l.shapes == 1 ? " shape" : " shapes") << " with a specular component ("
        << std::fixed << std::setprecision(1) << 100.0 * l.share << " % of the directions)";
    changes.push_back({"light /lights/" + std::to_string(l.light) + " (" + l.kind + ")", "emission (every direction)", now.str(),
                                "every requested path scatters specularly at its first vertex"});
  }
  // Non-finite samples are bugs (DESIGN §7): say so, and where the first arose.
  if (const std::uint64_t n = out->histogram.nonfinite(); n > 0) {
    std::cerr << "pathex: warning: " << n << " non-finite samples (dropped; any is a bug)";
    if (const auto& f = out->first_nonfinite)
      std::cerr << "; the first from strategy " << f->strategy << " on path " << f->path << " (near pixel (" << f->x << ", "
                << f->y << "), pass " << f->pass << ")";
    std::cerr << "\n";
  }

  // --- --missed: a reference render of the same scene, spp and seed measures what this one misses ---
  std::optional<BiasReport> missed;
  if (a.missed) {
    BiasOptions bo;
    bo.spp = job.header.spp;
    bo.seed = id.seed;
    bo.threads = a.threads;
    bo.renderer_bounces = id.max_bounces;  // what this render could sample: its own bound
    bo.renderer_histogram = &out->histogram;  // and what it found, against the reference
    bo.images = false;
    bo.limits = o.limits;
    const RenderWatch watch(!a.quiet);
    bo.progress = watch.progress();
    bo.cancel = watch.cancel();
    Result<BiasRun> b = measure_missed(*job.scene, id.scene, *job.profile, a.reference, {}, bo);
    if (!b) return report(b.error());
    missed = std::move(b->report);
  }

  RenderSums sums{std::move(out->histogram), std::move(out->images), std::move(out->connectors)};
  ShardHeader header = job.header;
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
    if (!*kept) return report(kept->error());
    // Every rank's file is whole before rank 0 writes the outputs: a rank that dies before this
    // point leaves rank files that --resume completes, never outputs beside them.
    cluster->count_failures(true);
    if (stopped->load())
      std::fprintf(stderr, "pathex: rank %d stopped after %s of its passes; they are kept in %s ('pathex trace --resume %s' finishes the render)\n",
                   rank, out->passes_done.to_string().c_str(), mine.c_str(), job.out.c_str());
    if (!reduced) return report(reduced.error());
  }
  if (job.resumed) {
    if (Result<bool> m = sums.histogram.merge(job.resumed->sums.histogram); !m) return report(m.error());
    if (Result<bool> m = sums.images.merge(job.resumed->sums.images); !m) return report(m.error());
    for (std::size_t i = 0; i < sums.connectors.size(); ++i) sums.connectors[i] += job.resumed->sums.connectors[i];
    header.passes.add(job.resumed->header.passes);
    header.run.time_s += job.resumed->header.run.time_s;
    header.run.rays += job.resumed->header.run.rays;
    header.run.cpu_s += job.resumed->header.run.cpu_s;
  }

  // --- outputs (rank 0): one set, whole or not at all, shielded from signals (io/output_set.h) ---
  std::optional<WrittenReport> written;
  std::optional<Error> failure;
  double report_ms = 0;  // --report: the time report.html took
  if (rank == 0) {
    const SignalShield shield;
    Result<bool> w = out_set->write([&](const std::string& dir) -> Result<bool> {
      Result<WrittenReport> r = write_render_outputs(dir, header, sums, *job.classes, changes);
      if (!r) return r.error();
      written = std::move(*r);
      if (missed)  // what pathex bias writes to bias.json, without images
        if (Result<bool> m = write_file_atomic(dir + "/missed.json", bias_json_text(*missed)); !m) return m;
      if (a.report_html) {  // a file of the set, from the files just staged and what is in memory
        const auto start = std::chrono::steady_clock::now();
        KnownRender known;  // histogram.json and render.shard's header as written, not read back
        known.folder = job.out;
        known.histogram = &written->report;
        known.connectors = report_connectors(sums.connectors);
        for (const PathClass* c : job.classes->requested) known.only.emplace_back(c->name, c->text);
        known.identity = &header.identity;
        known.spp = header.spp;
        if (Result<std::string> rw = write_folder_report(dir, a.report_options, o.limits, &known); !rw) return rw.error();
        report_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      }
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
    if (rank != 0) return kExitOk;
  }
  if (failure) return report(*failure);
  {  // the ranks' files of a failed MPI run, now held by render.shard
    std::error_code ec;
    std::filesystem::remove_all(ranks_folder(job.out), ec);
  }
  const HistogramReport* rep = &written->report;
  const bool complete = rep->run.complete;
  if (a.json) {
    std::cout << written->json_text;
    return finish_command(complete ? kExitOk : kExitNo);
  }

  // --- the table: classes with the checker's verdict, then the most important exact paths ---
  const std::vector<const PathClass*>& classes = job.classes->classes;
  QueryOptions qo;
  qo.universe = universe;
  qo.max_bounces = id.max_bounces;
  qo.witnesses = 0;
  qo.max_len = 0;
  std::cout << "scene " << id.scene << ", renderer " << id.renderer << ", " << rep->run.spp << " spp";
  if (!(job.header.share == PassSet::range(0, job.header.spp)))
    std::cout << " (passes " << header.passes.to_string() << " of " << job.header.spp << ")";
  std::cout << ", " << std::fixed << std::setprecision(2) << out->time_s << " s" << (complete ? "" : " (interrupted)")
            << ", non-finite samples " << rep->nonfinite_samples << "\n";
  if (!job.classes->requested.empty()) {
    std::cout << "rendered only";
    for (const PathClass* c : job.classes->requested) std::cout << " " << c->name << " (" << c->text << ")";
    std::cout << "\nluminance of those paths " << absolute(rep->total) << "\n"
              << "(shares are of the requested paths' total; luminances are absolute, comparable between renderers)\n";
  } else {
    std::cout << "image mean luminance " << absolute(rep->total) << "\n"
              << "(shares are of this render's total; luminances are absolute, comparable between renderers)\n";
  }
  for (const PrunedStrategy& p : changes)
    std::cout << (p.now.empty() ? "not run: " : "narrowed: ") << p.strategy << " " << p.was << (p.now.empty() ? "" : " to " + p.now) << ": " << p.reason << "\n";
  if (missed) {
    std::cout << "this renderer " << missed_line(*missed).substr(missed->renderer.size() + 1) << "\n";
    for (const std::string& line : undersampled_lines(*missed, 8)) std::cout << line << "\n";
  }
  std::cout << "\n";
  for (std::size_t i = 0; i < rep->classes.size(); ++i) {
    const ClassEstimate& c = rep->classes[i];
    if (!c.rendered) {
      std::cout << c.name << ": not rendered\n";
      continue;
    }
    Result<QueryResult> q = query(*classes[i], *compiled, qo);
    const double err = rep->total.luminance > 0 ? c.estimate.std_error / rep->total.luminance : 0.0;
    std::cout << c.name << ": " << percent(c.share) << " of the image, ±" << percent(std::isfinite(err) ? err : 0.0, 2)
              << "; " << id.renderer << ": " << (q ? to_string(q->verdict) : "?") << "; luminance "
              << absolute(c.estimate) << "\n";
    if (!c.strategies.empty()) std::cout << "  from " << techniques_text(c.strategies, 3) << "\n";
  }
  if (!sums.connectors.empty()) {  // the render's: with the resumed and the other ranks' passes
    int width = 10;
    for (const ConnectorStats& c : sums.connectors) width = std::max(width, static_cast<int>(c.strategy.size()));
    std::cout << "\n" << std::left << std::setw(width + 2) << "connectors" << std::right
              << "  attempts  successes   outside  occluded  no transport\n";
    for (const ConnectorStats& c : sums.connectors)
      std::cout << "  " << std::left << std::setw(width) << c.strategy << std::right << std::setw(10) << c.attempts
                << std::setw(11) << c.successes << std::setw(10) << c.outside << std::setw(10) << c.occluded
                << std::setw(14) << c.no_transport << "   (" << c.connector << ")\n";
    for (const ConnectorStats& c : sums.connectors)
      if (c.connector == "manifold")
        std::cout << "  " << c.strategy << " (manifold): no solution " << c.no_solution << ", singular " << c.singular
                  << ", wrong type " << c.wrong_type << ", too short " << c.too_short << ", iteration limit "
                  << c.iteration_limit << "; repeats " << c.repeats << ", truncated " << c.truncated
                  << "; mean Newton iterations "
                  << (c.walks > 0 ? static_cast<double>(c.iterations) / static_cast<double>(c.walks) : 0.0) << "\n";
  }
  std::cout << "\nmost important paths\n";
  for (std::size_t i = 0; i < rep->paths.size() && static_cast<int>(i) < a.top_paths; ++i) {
    const PathEstimate& p = rep->paths[i];
    const double share = rep->total.luminance > 0 ? p.estimate.luminance / rep->total.luminance : 0.0;
    const double err = rep->total.luminance > 0 ? p.estimate.std_error / rep->total.luminance : 0.0;
    std::cout << "  " << std::left << std::setw(16) << p.path << std::right << std::setw(8) << percent(share) << "  ±"
              << percent(std::isfinite(err) ? err : 0.0, 2) << "  luminance " << absolute(p.estimate) << "  via";
    std::cout << " " << techniques_text(p.strategies, 2) << "\n";
  }
  std::cout << "\nwrote " << job.out << "/histogram.json" << (id.images ? ", classes.exr and PNG previews" : "") << ", "
            << kRenderShardName << (missed ? ", missed.json" : "") << "\n";
  if (a.report_html)
    std::cout << "wrote " << job.out << "/" << kReportName << " in " << std::fixed << std::setprecision(1) << report_ms << " ms (open it in a browser)\n";
  if (!complete)
    std::cout << "interrupted: 'pathex trace --resume " << job.out << "' renders the missing passes "
              << job.header.share.minus(header.passes).to_string() << "\n";
  return finish_command(complete ? kExitOk : kExitNo);
}

}  // namespace

Command add_trace(CLI::App& app) {
  auto args = std::make_shared<TraceArgs>();
  CLI::App* sub = app.add_subcommand("trace", "Render a scene, label every path, write path-class histograms and images");
  sub->footer("Example:\n  pathex trace                         # the embedded Cornell box\n"
              "  pathex trace samples/scenes/point-mirror-caustic.json --renderer pt-nee --spp 64 --out out/\n"
              "Writes DIR/histogram.json, DIR/classes.exr (a layer per class and the total) and DIR/<layer>.png,\n"
              "as one set that replaces the previous one whole (DIR must hold only what pathex wrote there).\n"
              "Also DIR/render.shard (the exact sums, for merge and --resume) and DIR/run.json (time, threads).\n"
              "Ctrl-C, SIGTERM or --time stop early and write what was rendered, marked \"complete\": false (exit 1);\n"
              "'pathex trace --resume DIR' renders the rest. Split a render: --shard 0/4 … 3/4, then pathex merge.");
  sub->add_option("SCENE", args->options.scene, "Scene file (grammar/scene.schema.json); default: the embedded Cornell box");
  sub->add_option("--renderer", args->options.renderer, "Renderer profile: built-in name or file")->capture_default_str();
  sub->add_option("--spp", args->options.spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(1, 1 << 24));
  sub->add_option("--classes", args->options.classes_file, "Class file; default: the built-in classes");
  sub->add_option("--only", args->options.only,
                  "Estimate only the paths of this class (an expression; repeatable): other strategies and subpaths are not "
                  "simulated, and classes outside it are reported as not rendered");
  sub->add_option("--seed", args->options.seed, "Random seed (0 to 2^64 - 1)")->capture_default_str()->check(non_negative());
  sub->add_option("--threads", args->threads, "Worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
  sub->add_option("--max-bounces", args->options.max_bounces, "Largest number of interior vertices (k - 1); default: the profile's bound, else 16")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--out", args->options.out, "Output folder")->capture_default_str();
  sub->add_option("--sampler", args->options.sampler,
                  "Random numbers: sobol (Owen-scrambled Sobol points, stratified per pixel) or independent")
      ->transform(CLI::CheckedTransformer(std::map<std::string, SamplerKind>{{"independent", SamplerKind::kIndependent},
                                                                              {"sobol", SamplerKind::kSobol}})
                     .description("{independent,sobol}"))  // CLI11 would print the enum's bytes
      ->default_str(to_string(RenderOptions{}.sampler));
  sub->add_option("--batches", args->options.batches,
                  "Batches of passes (pass mod B) whose means give the standard error; under sobol each is an independently "
                  "scrambled sequence. Default: " + std::to_string(default_batches(SamplerKind::kSobol)) + " (sobol), " +
                      std::to_string(default_batches(SamplerKind::kIndependent)) + " (independent)")
      ->check(CLI::Range(2, 1024));
  sub->add_option("--rr-depth", args->options.rr_depth,
                  "Russian roulette from this vertex of a subpath on (the camera or light point is the first)")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  sub->add_option("--rr-threshold", args->options.rr_threshold,
                  "Russian roulette of eye subpaths only below this throughput (relative to the subpath's start); 0: no roulette")
      ->capture_default_str()->check(CLI::Range(0.0f, 1000.0f));
  sub->add_option("--rr-light-threshold", args->options.rr_light_threshold,
                  "The same for light subpaths (lt, bdpt)")
      ->capture_default_str()->check(CLI::Range(0.0f, 1000.0f));
  sub->add_option("--resolution", args->options.resolution, "Image size WIDTHxHEIGHT, such as 640x480; default: the scene's")
      ->type_name("WxH");
  sub->add_option("--max-paths", args->options.max_paths,
                  "Rows of histogram.json's path table; the rest are summed into one \"other\" row")
      ->capture_default_str()->check(non_negative());
  sub->add_option("--top", args->top_paths, "Exact paths to list")->capture_default_str()->check(CLI::Range(0, 100000));
  sub->add_flag("--json", args->json, "Print histogram.json to stdout instead of the table");
  sub->add_flag("--quiet", args->quiet, "No progress bar");
  sub->add_flag("--missed", args->missed,
                "Also render the reference (pathex bias) and print what share of its light this renderer cannot "
                "sample; writes DIR/missed.json");
  sub->add_option("--reference", args->reference, "The reference of --missed; default: bdpt plus the connectors the scene needs")
      ->needs("--missed");
  sub->add_flag("--report", args->report_html, "Also write DIR/report.html, the render as one self-contained web page (pathex report)");
  add_report_options(sub, &args->report_options);
  sub->add_flag("--no-images", args->options.no_images, "Skip the EXR and PNG outputs and the per-pixel sums behind them (the histogram is the same)");
  sub->add_option("--max-memory", args->max_memory,
                  "Refuse a render whose images (and their writing) would take more, estimated before rendering; e.g. 512M, 16G")
      ->transform(CLI::AsSizeValue(false))
      ->default_str("4G");
  sub->add_option("--shard", args->options.shard, "Render shard i of n of the passes (i/n, 0 <= i < n); merge the shards with pathex merge");
  sub->add_option("--resume", args->options.resume, "Continue the interrupted render in this folder to its requested spp (settings come from the folder)");
  sub->add_option("--time", args->time_limit, "Stop after this many seconds (at the end of a chunk of passes); --resume continues")
      ->check(CLI::PositiveNumber);
  add_manifold_options(sub, &args->options.manifold);
  add_limit_options(sub, &args->options.limits);
  add_scene_limit_options(sub, &args->options.limits);
  return {sub, [args, sub] {
            for (const char* o : {"SCENE", "--renderer", "--spp", "--classes", "--only", "--seed", "--max-bounces", "--out", "--no-images", "--shard",
                                  "--resolution", "--max-paths", "--sampler", "--batches", "--rr-depth", "--rr-threshold",
                                  "--rr-light-threshold"})
              if (sub->count(o) > 0) args->options.settings_given.push_back(o);
            for (const std::string& o : manifold_option_names())
              if (sub->count(o) > 0) args->options.settings_given.push_back(o);
            return run(*args);
          }};
}

}  // namespace pathex::cli
