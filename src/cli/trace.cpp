// pathex trace: render a scene, label every sampled path, write the path-class histogram, the
// per-class EXR and PNG previews, and print where the light went, class by class, next to what the
// checker says the renderer can reach.
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
#include "cli/folder_report.h"
#include "cli/reach_common.h"
#include "output/bias_json.h"
#include "output/render_job.h"
#include "measure/render_watch.h"
#include "cli/trace_checks.h"
#include "core/hash.h"
#include "core/version.h"
#include "io/atomic_file.h"
#include "io/class_file.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/output_set.h"
#include "io/input_file.h"
#include "io/profile_json.h"
#include "scene/scene_hash.h"
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
  std::string scene;
  std::string renderer = "bdpt";
  std::string classes_file;
  std::vector<std::string> only;  // --only: the requested classes (DESIGN §11)
  std::string out = "pathex-out";
  std::uint64_t spp = 16;
  std::uint64_t seed = 1;
  int threads = 0;
  std::optional<int> max_bounces;
  SamplerKind sampler = RenderOptions{}.sampler;  // the defaults of these three: RenderOptions'
  int rr_depth = RenderOptions{}.rr_depth;
  float rr_threshold = RenderOptions{}.rr_threshold;
  float rr_light_threshold = RenderOptions{}.rr_light_threshold;
  std::optional<int> batches;  // --batches; unset: default_batches(sampler)
  ManifoldOptions manifold = RenderOptions{}.manifold;
  std::string resolution;  // "WxH"; empty: the scene's
  std::uint64_t max_paths = 1000;
  int top_paths = 8;
  bool json = false;
  bool quiet = false;
  bool no_images = false;
  std::string shard;       // "i/n"
  std::string resume;      // a render folder
  double time_limit = 0;   // seconds; 0: none
  std::uint64_t max_memory = kDefaultMaxMemory;
  bool missed = false;       // also measure what the renderer misses (pathex bias)
  std::string reference;     // the reference for --missed; empty: bias's default
  std::vector<std::string> settings_given;  // render settings named on the command line (refused with --resume)
  Limits limits;
  bool report_html = false;  // --report: also write DIR/report.html (pathex report)
  ReportOptions report_options;
};

std::string gib(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / static_cast<double>(std::uint64_t{1} << 30));
  return buf;
}

// "i/n" with 0 ≤ i < n.
Result<std::pair<std::uint64_t, std::uint64_t>> parse_shard_option(const std::string& text) {
  const auto bad = [&] {
    return make_error(ErrorCode::kUsage, "--shard " + text + ": expected i/n, shard i of n with 0 <= i < n (e.g. 0/4)");
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) return bad();
  std::uint64_t i = 0, n = 0;
  try {
    std::size_t used_i = 0, used_n = 0;
    if (text.empty() || text[0] == '-' || text[slash + 1] == '-') return bad();
    i = std::stoull(text.substr(0, slash), &used_i);
    n = std::stoull(text.substr(slash + 1), &used_n);
    if (used_i != slash || used_n != text.size() - slash - 1) return bad();
  } catch (const std::exception&) {
    return bad();
  }
  if (n == 0 || i >= n) return bad();
  return std::make_pair(i, n);
}

std::string profile_hash(const Profile& p) {
  Fnv64 h;
  h.add(p.name);
  for (const Strategy& st : p.strategies) h.add(st.name + " " + st.describe());
  h.add(p.max_bounces.value_or(-1));
  return h.hex();
}

std::string classes_hash(const std::string& text, const RenderClasses& classes) {
  Fnv64 h;
  h.add(text);
  for (const ClassInfo& c : classes.infos) h.add(c.name + "=" + c.expr);
  return h.hex();
}

// The render to run: what it renders and the passes it is asked for, with what an earlier,
// interrupted run of it already holds (--resume).
struct Job {
  std::optional<Scene> scene;
  std::optional<Profile> profile;
  std::unique_ptr<RenderClasses> classes;
  ShardHeader header;  // identity, spp, share; passes: those already held
  std::optional<CombinedRender> resumed;
  std::string out;
};

Result<bool> load_fresh(const TraceArgs& a, Job* job) {
  Result<Scene> scene = a.scene.empty() ? load_scene_json(default_scene_json(), ".", "default (embedded cornell)")
                                        : load_scene_file(a.scene, scene_load_options(a.limits));
  if (!scene) return scene.error();
  // The content hash is the file's; the resolution is an option of the render, kept beside it.
  const std::string scene_hash = scene_content_hash(*scene);
  if (!a.resolution.empty())
    if (Result<bool> r = apply_resolution(a.resolution, &scene->camera); !r) return r.error();
  Result<Profile> profile = resolve_profile(a.renderer, a.limits);
  if (!profile) return profile.error();
  Result<StrategySet> runnable = runnable_strategies(*profile);
  if (!runnable) return runnable.error();

  RenderIdentity& id = job->header.identity;
  id.pathex = pathex_version();
  id.scene = a.scene.empty() ? "default (embedded cornell)" : a.scene;
  id.scene_file = a.scene.empty() ? "" : std::filesystem::absolute(a.scene).lexically_normal().string();
  id.scene_hash = scene_hash;
  id.renderer = profile->name;
  const bool builtin = std::any_of(builtin_profile_texts().begin(), builtin_profile_texts().end(),
                                   [&](const BuiltinProfileText& t) { return a.renderer == t.name; });
  id.renderer_source = builtin ? a.renderer : std::filesystem::absolute(a.renderer).lexically_normal().string();
  id.renderer_hash = profile_hash(*profile);
  const SceneTypes types = scene_types(*scene);
  for (LightType l : types.lights) id.lights.push_back(to_string(l));
  id.sensor = to_string(types.sensor);
  id.seed = a.seed;
  // One bound for the render and for the checker's verdicts: --max-bounces, else the profile's, else 16.
  id.max_bounces = a.max_bounces.value_or(profile->max_bounces.value_or(16));
  id.sampler = to_string(a.sampler);
  id.rr_depth = a.rr_depth;
  id.rr_threshold = a.rr_threshold;
  id.rr_light_threshold = a.rr_light_threshold;
  id.batches = a.batches.value_or(default_batches(a.sampler));
  id.images = !a.no_images;
  id.width = scene->camera.width;
  id.height = scene->camera.height;
  id.max_paths = a.max_paths;
  // The manifold's limits are part of the render only where its connector runs.
  if (std::any_of(profile->strategies.begin(), profile->strategies.end(),
                  [](const Strategy& st) { return st.connector == ConnectorKind::kManifold; }))
    id.manifold = a.manifold;
  for (const Strategy& st : runnable->strategies) id.strategies.push_back(st.name);

  std::string class_text;
  if (!a.classes_file.empty()) {
    Result<std::string> text = read_input_file(a.classes_file, a.limits.max_file_bytes);
    if (!text) return text.error();
    class_text = std::move(*text);
    id.classes_file = std::filesystem::absolute(a.classes_file).lexically_normal().string();
  }
  id.only = a.only;
  Result<std::unique_ptr<RenderClasses>> classes =
      compile_render_classes(class_text, a.classes_file.empty() ? "" : a.classes_file, id, a.limits);
  if (!classes) return classes.error();
  id.classes_text = class_text;
  id.classes_hash = classes_hash(class_text, **classes);

  job->header.spp = a.spp;
  job->header.share = PassSet::range(0, a.spp);
  if (!a.shard.empty()) {
    Result<std::pair<std::uint64_t, std::uint64_t>> shard = parse_shard_option(a.shard);
    if (!shard) return shard.error();
    job->header.share = job->header.share.part(shard->first, shard->second);
  }
  job->scene = std::move(*scene);
  job->profile = std::move(*profile);
  job->classes = std::move(*classes);
  job->out = a.out;
  return true;
}

// --resume DIR: the render's settings come from DIR's shard files; the scene and the profile are
// loaded again from where the render found them and must not have changed.
Result<bool> load_resumed(const TraceArgs& a, Job* job) {
  if (!a.settings_given.empty())
    return make_error(ErrorCode::kUsage, "--resume takes the render's settings from " + a.resume + "; " +
                                             a.settings_given.front() + " cannot be given with it");
  Result<std::vector<std::string>> files = render_folder_shards(a.resume);
  if (!files) return files.error();
  Result<CombinedRender> combined = combine_shards(*files, a.limits);
  if (!combined) return combined.error();
  const RenderIdentity& id = combined->header.identity;
  Result<Scene> scene = id.scene_file.empty()
                            ? load_scene_json(default_scene_json(), ".", id.scene)
                            : load_scene_file(id.scene_file, scene_load_options(a.limits));
  if (!scene) return scene.error();
  if (scene_content_hash(*scene) != id.scene_hash)
    return make_error(ErrorCode::kUsage, "the scene " + id.scene + " changed since " + a.resume + " was rendered (content hash " +
                                             scene_content_hash(*scene) + ", the render's " + id.scene_hash + ")");
  // The render's resolution (the scene's, or --resolution's).
  scene->camera.width = id.width;
  scene->camera.height = id.height;
  Result<Profile> profile = resolve_profile(id.renderer_source, a.limits);
  if (!profile) return profile.error();
  if (profile_hash(*profile) != id.renderer_hash)
    return make_error(ErrorCode::kUsage, "the renderer profile " + id.renderer_source + " changed since " + a.resume +
                                             " was rendered");
  job->header.identity = id;
  job->header.spp = combined->header.spp;
  job->header.share = combined->header.share;
  job->header.passes = combined->header.passes;
  job->scene = std::move(*scene);
  job->profile = std::move(*profile);
  job->classes = std::move(combined->classes);
  job->resumed = std::move(*combined);
  job->out = a.resume;
  return true;
}

std::string rank_shard_path(const std::string& dir, int rank) {
  return ranks_folder(dir) + "/rank-" + std::to_string(rank) + kShardExtension;
}

int run(const TraceArgs& a) {
  // --threads bounds the whole command, not only the render's loop: Embree's BVH build before it
  // and the concurrent writing after it would otherwise start TBB worker threads (which spin
  // while they wait) for a render that asked for one thread.
  std::optional<tbb::global_control> limit;
  if (a.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(a.threads));
  Job job;
  if (Result<bool> r = a.resume.empty() ? load_fresh(a, &job) : load_resumed(a, &job); !r) return report(r.error());
  const RenderIdentity& id = job.header.identity;
  Cluster* cluster = current_cluster();
  const int rank = cluster != nullptr ? cluster->rank() : 0;
  const int ranks = cluster != nullptr ? cluster->size() : 1;
  if (a.missed && (!a.shard.empty() || !a.resume.empty() || ranks > 1))
    return report(make_error(ErrorCode::kUsage, "--missed measures a whole render in one process: it cannot be given with "
                                                "--shard, --resume or MPI"));
  if (a.missed && !id.only.empty())
    return report(make_error(ErrorCode::kUsage, "--missed measures what the whole render misses: it cannot be given with --only"));

  // --- DESIGN §11: the plan (trace/plan.h): the strategies that can sample a requested path of
  // this scene, the lights' emission narrowing, the paths recorded ---
  const Dfa universe = scene_universe(scene_types(*job.scene));
  Result<RenderPlan> plan = plan_render(*job.scene, *job.profile, id.max_bounces, job.classes->requested, a.limits);
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
  std::vector<std::string> runs;
  std::vector<ConnectorStrategy> connectors;
  for (const Strategy& st : plan->profile.strategies) {
    runs.push_back(st.name);
    if (st.connector != ConnectorKind::kNone) connectors.push_back({st.name, to_string(st.connector)});
  }
  if (a.resume.empty()) {  // the histogram and the connector statistics are laid out for these
    job.header.identity.strategies = runs;
    job.header.identity.connectors = connectors;
  } else if (runs != id.strategies || connectors != id.connectors) {
    return report(make_error(ErrorCode::kUsage, "the strategies " + a.resume + " was rendered with are not the ones this pathex runs for it"));
  }

  // The output folder is checked before the render, not after it.
  std::optional<OutputSet> out_set;
  if (rank == 0) {
    Result<OutputSet> prepared = OutputSet::prepare(job.out);
    if (!prepared) return report(prepared.error());
    out_set.emplace(std::move(*prepared));
  }

  // The checker's view of the profile, for the warning now and the table after the render (rank
  // 0 prints both; the other ranks skip the compilation).
  ReachCache cache(a.limits);
  const CompiledProfile* compiled = nullptr;
  if (rank == 0) {
    Result<const CompiledProfile*> cp = cache.compiled(id.renderer_source, id.max_bounces);
    if (!cp) return report(cp.error());
    compiled = *cp;
    warn_unreachable_lights(*job.scene, *job.profile, *compiled, universe, id.max_bounces, a.limits);
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
    bo.limits = a.limits;
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
        if (Result<std::string> rw = write_folder_report(dir, a.report_options, a.limits, &known); !rw) return rw.error();
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
  sub->add_option("SCENE", args->scene, "Scene file (grammar/scene.schema.json); default: the embedded Cornell box");
  sub->add_option("--renderer", args->renderer, "Renderer profile: built-in name or file")->capture_default_str();
  sub->add_option("--spp", args->spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(1, 1 << 24));
  sub->add_option("--classes", args->classes_file, "Class file; default: the built-in classes");
  sub->add_option("--only", args->only,
                  "Estimate only the paths of this class (an expression; repeatable): other strategies and subpaths are not "
                  "simulated, and classes outside it are reported as not rendered");
  sub->add_option("--seed", args->seed, "Random seed (0 to 2^64 - 1)")->capture_default_str()->check(non_negative());
  sub->add_option("--threads", args->threads, "Worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
  sub->add_option("--max-bounces", args->max_bounces, "Largest number of interior vertices (k - 1); default: the profile's bound, else 16")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--out", args->out, "Output folder")->capture_default_str();
  sub->add_option("--sampler", args->sampler,
                  "Random numbers: sobol (Owen-scrambled Sobol points, stratified per pixel) or independent")
      ->transform(CLI::CheckedTransformer(std::map<std::string, SamplerKind>{{"independent", SamplerKind::kIndependent},
                                                                              {"sobol", SamplerKind::kSobol}})
                     .description("{independent,sobol}"))  // CLI11 would print the enum's bytes
      ->default_str(to_string(RenderOptions{}.sampler));
  sub->add_option("--batches", args->batches,
                  "Batches of passes (pass mod B) whose means give the standard error; under sobol each is an independently "
                  "scrambled sequence. Default: " + std::to_string(default_batches(SamplerKind::kSobol)) + " (sobol), " +
                      std::to_string(default_batches(SamplerKind::kIndependent)) + " (independent)")
      ->check(CLI::Range(2, 1024));
  sub->add_option("--rr-depth", args->rr_depth,
                  "Russian roulette from this vertex of a subpath on (the camera or light point is the first)")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  sub->add_option("--rr-threshold", args->rr_threshold,
                  "Russian roulette of eye subpaths only below this throughput (relative to the subpath's start); 0: no roulette")
      ->capture_default_str()->check(CLI::Range(0.0f, 1000.0f));
  sub->add_option("--rr-light-threshold", args->rr_light_threshold,
                  "The same for light subpaths (lt, bdpt)")
      ->capture_default_str()->check(CLI::Range(0.0f, 1000.0f));
  sub->add_option("--resolution", args->resolution, "Image size WIDTHxHEIGHT, such as 640x480; default: the scene's")
      ->type_name("WxH");
  sub->add_option("--max-paths", args->max_paths,
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
  sub->add_flag("--no-images", args->no_images, "Skip the EXR and PNG outputs and the per-pixel sums behind them (the histogram is the same)");
  sub->add_option("--max-memory", args->max_memory,
                  "Refuse a render whose images (and their writing) would take more, estimated before rendering; e.g. 512M, 16G")
      ->transform(CLI::AsSizeValue(false))
      ->default_str("4G");
  sub->add_option("--shard", args->shard, "Render shard i of n of the passes (i/n, 0 <= i < n); merge the shards with pathex merge");
  sub->add_option("--resume", args->resume, "Continue the interrupted render in this folder to its requested spp (settings come from the folder)");
  sub->add_option("--time", args->time_limit, "Stop after this many seconds (at the end of a chunk of passes); --resume continues")
      ->check(CLI::PositiveNumber);
  add_manifold_options(sub, &args->manifold);
  add_limit_options(sub, &args->limits);
  add_scene_limit_options(sub, &args->limits);
  return {sub, [args, sub] {
            for (const char* o : {"SCENE", "--renderer", "--spp", "--classes", "--only", "--seed", "--max-bounces", "--out", "--no-images", "--shard",
                                  "--resolution", "--max-paths", "--sampler", "--batches", "--rr-depth", "--rr-threshold",
                                  "--rr-light-threshold"})
              if (sub->count(o) > 0) args->settings_given.push_back(o);
            for (const std::string& o : manifold_option_names())
              if (sub->count(o) > 0) args->settings_given.push_back(o);
            return run(*args);
          }};
}

}  // namespace pathex::cli
