// pathex trace: render a scene, label every sampled path, write the path-class histogram, the
// per-class EXR and PNG previews, and print where the light went, class by class, next to what the
// checker says the renderer can reach. The render's run is the library's (measure/trace_run.h: the
// job and its identity, the plan, the render dealt among MPI ranks, --missed, the outputs); this
// file holds its options, the checker's warning, the table and the exit codes.
#include <chrono>
#include <cstdlib>
#include <iomanip>
#include <iostream>
#include <sstream>

#include <tbb/global_control.h>

#include "cli/bias_common.h"
#include "cli/common.h"
#include "io/estimate_text.h"
#include "measure/trace_run.h"
#include "cli/folder_report.h"
#include "cli/reach_common.h"
#include "output/render_job.h"
#include "cli/trace_checks.h"
#include "scene/universe.h"
#include "trace/render.h"

namespace pathex::cli {
namespace {

struct TraceArgs {
  TraceOptions options;  // measure/trace_run.h: the render's settings and its run
  int top_paths = 8;
  bool json = false;
  bool quiet = false;  // no progress line (TraceOptions::progress)
  bool report_html = false;  // --report: also write DIR/report.html (pathex report)
  ReportOptions report_options;
};

int run(const TraceArgs& a) {
  TraceOptions o = a.options;
  o.progress = !a.quiet;
  // --threads bounds the whole command, not only the render's loop: Embree's BVH build before it
  // and the concurrent writing after it would otherwise start TBB worker threads (which spin
  // while they wait) for a render that asked for one thread.
  std::optional<tbb::global_control> limit;
  if (o.threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(o.threads));
  // The checker's view of the profile, for the warning before the render and the table after it
  // (rank 0 prints both; the other ranks skip the compilation).
  ReachCache cache(o.job.limits);
  const CompiledProfile* compiled = nullptr;
  TraceHooks hooks;
  hooks.before_render = [&](const TraceJob& job, const Dfa& universe) -> Result<bool> {
    const RenderIdentity& id = job.header.identity;
    Result<const CompiledProfile*> cp = cache.compiled(id.renderer_source, id.max_bounces);
    if (!cp) return cp.error();
    compiled = *cp;
    warn_unreachable_lights(*job.scene, *job.profile, *compiled, universe, id.max_bounces, o.job.limits);
    return true;
  };
  hooks.notice = [](const std::string& line) { std::cerr << "pathex: " << line << "\n"; };
  double report_ms = 0;  // --report: the time report.html took
  if (a.report_html)  // a file of the set, from the files just staged and what is in memory
    hooks.extra_files = [&](const std::string& dir, const TraceResult& r) -> Result<bool> {
      const auto start = std::chrono::steady_clock::now();
      KnownRender known;  // histogram.json and render.shard's header as written, not read back
      known.folder = r.job.out;
      known.histogram = &r.written->report;
      known.connectors = report_connectors(r.sums->connectors);
      for (const PathClass* c : r.job.classes->requested) known.only.emplace_back(c->name, c->text);
      known.identity = &r.header.identity;
      known.spp = r.header.spp;
      if (Result<std::string> rw = write_folder_report(dir, a.report_options, o.job.limits, &known); !rw) return rw.error();
      report_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      return true;
    };
  Result<TraceResult> run = run_trace(o, hooks);
  if (!run) return report(run.error());
  const TraceResult& r = *run;
  const TraceJob& job = r.job;
  const RenderIdentity& id = job.header.identity;
  const std::vector<PrunedStrategy>& changes = r.changes;
  if (r.nothing_to_render) {
    std::cout << "nothing to render: no strategy of " << id.renderer << " samples a path of "
              << (id.only.empty() ? "this scene" : "the requested classes in this scene") << " ("
              << describe(scene_types(*job.scene)) << ")\n";
    for (const std::string& c : r.no_path) std::cout << "  " << c << " has no path in this scene\n";
    for (const PrunedStrategy& p : changes) std::cout << "  " << p.strategy << " " << p.was << ": " << p.reason << "\n";
    return kExitNo;
  }
  if (!r.root) return kExitOk;  // the other ranks have done their part
  const ShardHeader& header = r.header;
  const RenderSums& sums = *r.sums;
  const std::optional<BiasReport>& missed = r.missed;
  const std::optional<WrittenReport>& written = r.written;
  const HistogramReport* rep = &written->report;
  const bool complete = rep->run.complete;
  if (a.json) {
    std::cout << written->json_text;
    return finish_command(complete ? kExitOk : kExitNo);
  }

  // --- the table: classes with the checker's verdict, then the most important exact paths ---
  const std::vector<const PathClass*>& classes = job.classes->classes;
  QueryOptions qo;
  qo.universe = r.universe;
  qo.max_bounces = id.max_bounces;
  qo.witnesses = 0;
  qo.max_len = 0;
  std::cout << "scene " << id.scene << ", renderer " << id.renderer << ", " << rep->run.spp << " spp";
  if (!(job.header.share == PassSet::range(0, job.header.spp)))
    std::cout << " (passes " << header.passes.to_string() << " of " << job.header.spp << ")";
  std::cout << ", " << std::fixed << std::setprecision(2) << r.time_s << " s" << (complete ? "" : " (interrupted)")
            << ", non-finite samples " << rep->nonfinite_samples << "\n";
  if (const std::optional<RouletteThresholds>& j = r.roulette) {
    const auto value = [](double t) {
      std::ostringstream text;
      text << std::defaultfloat << t;
      return t > 0 ? text.str() : std::string("none");
    };
    const std::string first = value(id.rr_threshold < 0 ? kDefaultEyeThreshold : id.rr_threshold) + " and " +
                              value(id.rr_join_threshold < 0 ? 0.0 : id.rr_join_threshold);
    std::cout << "roulette (auto): --rr-threshold " << value(j->eye) << ", --rr-join-threshold " << value(j->join);
    if (j->taken)
      std::cout << ", where the pilot's model finds " << std::fixed << std::setprecision(2) << j->gain << "x the efficiency of " << first << "\n";
    else std::cout << " (the pilot's model finds " << std::fixed << std::setprecision(2) << j->gain << "x at best)\n";
  }
  if (!job.classes->requested.empty()) {
    std::cout << "rendered only";
    for (const PathClass* c : job.classes->requested) std::cout << " " << c->name << " (" << c->text << ")";
    std::cout << "\nluminance of those paths " << absolute(rep->total) << unstable_text(rep->total) << "\n"
              << "(shares are of the requested paths' total; luminances are absolute, comparable between renderers)\n";
  } else {
    std::cout << "image mean luminance " << absolute(rep->total) << unstable_text(rep->total) << "\n"
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
              << absolute(c.estimate) << unstable_text(c.estimate) << "\n";
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
  sub->add_option("SCENE", args->options.job.scene, "Scene file (grammar/scene.schema.json); default: the embedded Cornell box");
  sub->add_option("--renderer", args->options.job.renderer, "Renderer profile: built-in name or file")->capture_default_str();
  sub->add_option("--spp", args->options.job.spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(std::uint64_t{1}, kMaxTraceSpp));
  sub->add_option("--classes", args->options.job.classes_file, "Class file; default: the built-in classes");
  sub->add_option("--only", args->options.job.only,
                  "Estimate only the paths of this class (an expression; repeatable): other strategies and subpaths are not "
                  "simulated, and classes outside it are reported as not rendered");
  sub->add_option("--seed", args->options.job.seed, "Random seed (0 to 2^64 - 1)")->capture_default_str()->check(non_negative());
  sub->add_option("--threads", args->options.threads, "Worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
  sub->add_option("--max-bounces", args->options.job.max_bounces, "Largest number of interior vertices (k - 1); default: the profile's bound, else 16")
      ->check(CLI::Range(0, kMaxTraceBounces));
  sub->add_option("--out", args->options.job.out, "Output folder")->capture_default_str();
  sub->add_option("--sampler", args->options.job.sampler,
                  "Random numbers: sobol (Owen-scrambled Sobol points, stratified per pixel) or independent")
      ->transform(CLI::CheckedTransformer(std::map<std::string, SamplerKind>{{"independent", SamplerKind::kIndependent},
                                                                              {"sobol", SamplerKind::kSobol}})
                     .description("{independent,sobol}"))  // CLI11 would print the enum's bytes
      ->default_str(to_string(RenderOptions{}.sampler));
  sub->add_option("--light-sampling", args->options.job.light_sampling,
                  "Points of lights for next-event estimation: area (uniform on every light), sphere-cone (spheres uniform "
                  "in the cone they subtend, seen from outside; others by area) or solid-angle (also rectangles uniform in "
                  "the solid angle they subtend, where not tiny)")
      ->transform(CLI::CheckedTransformer(std::map<std::string, LightSampling>{{"area", LightSampling::kArea},
                                                                                {"sphere-cone", LightSampling::kSphereCone},
                                                                                {"solid-angle", LightSampling::kSolidAngle}})
                     .description("{area,sphere-cone,solid-angle}"))
      ->default_str(to_string(RenderOptions{}.light_sampling));
  sub->add_option("--batches", args->options.job.batches,
                  "Batches that give the standard error: B / R pixel groups (pixel mod B/R) of R replicates (pass mod R)")
      ->capture_default_str()->check(CLI::Range(2, 1024));
  sub->add_option("--replicates", args->options.job.replicates,
                  "Replicates per pixel, dividing --batches; under sobol each is an independently scrambled sequence of spp/R "
                  "points, and the standard error comes from their differences (R = B: plain batch means). Default: 2, "
                  "or on a sensor of fewer pixels than B/2 groups B over the largest divisor of B not above its pixel count")
      ->default_str("2")->check(CLI::Range(2, 1024));
  sub->add_option("--rr-depth", args->options.job.rr_depth,
                  "Russian roulette from this vertex of a subpath on (the camera or light point is the first)")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  // A roulette threshold: from 0 to 1000.
  const auto threshold = [](const std::string& value) {
    char* end = nullptr;
    const double t = std::strtod(value.c_str(), &end);
    return !value.empty() && end == value.c_str() + value.size() && t >= 0 && t <= 1000;
  };
  sub->add_option("--rr-threshold", args->options.job.rr_threshold,
                  "Russian roulette of eye subpaths only below this throughput (relative to the subpath's start); 0: no roulette; "
                  "auto (the default): under bdpt's joins (bdpt and its connector profiles, pbrt-v4-bdpt) the one "
                  "of 0.3, 0.5, 1 a pilot's model of its variance and cost finds most efficient for the scene, with "
                  "--rr-join-threshold's; else 0.3 (issue 39, docs/efficiency.md)")
      ->transform(auto_or("-1",  // kEyeThresholdAuto
                          threshold, "a number from 0 to 1000", "rr-threshold"))
      ->type_name("T|auto")
      ->default_str("auto");
  sub->add_option("--rr-light-threshold", args->options.job.rr_light_threshold,
                  "The same for light subpaths (lt, bdpt)")
      ->capture_default_str()->check(CLI::Range(0.0f, 1000.0f));
  sub->add_option("--rr-join-threshold", args->options.job.rr_join_threshold,
                  "bdpt: an eye vertex whose throughput (as for --rr-threshold) is below this makes its joins with the light "
                  "subpath's vertices with probability throughput / threshold, weighted by its inverse; 0: always; auto (the "
                  "default): the threshold a pilot's model of its variance and cost finds most efficient for the scene "
                  "(issue 39, docs/efficiency.md)")
      ->transform(auto_or("-1",  // kJoinThresholdAuto
                          threshold, "a number from 0 to 1000", "rr-join-threshold"))
      ->type_name("T|auto")
      ->default_str("auto");
  sub->add_option("--splits", args->options.job.splits,
                  "Runs of each sample after its camera ray and first hit, each weighted 1/N: more paths of indirect light "
                  "per camera ray; auto: camera rays and runs per pixel from a pilot's variances (issue 39, docs/efficiency.md); "
                  "default: auto if the profile has no light subpath (no strategy with s >= 1 but next-event estimation's "
                  "s = 1, t >= 2: pt, pt-nee) and no manifold connector, else 1 (light tracing, bdpt's joins, manifold walks)")
      ->transform(auto_or(
          "0",  // RenderOptions::splits
          [](const std::string& value) {
            const bool digits = !value.empty() && value.size() <= 4 && value.find_first_not_of("0123456789") == std::string::npos;
            return digits && std::stoi(value) >= 1 && std::stoi(value) <= 1024;
          },
          "a whole number from 1 to 1024", "splits"))
      ->type_name("N|auto");
  sub->add_option("--resolution", args->options.job.resolution, "Image size WIDTHxHEIGHT, such as 640x480; default: the scene's")
      ->type_name("WxH");
  sub->add_option("--max-paths", args->options.job.max_paths,
                  "Rows of histogram.json's path table; the rest are summed into one \"other\" row")
      ->capture_default_str()->check(non_negative());
  sub->add_option("--top", args->top_paths, "Exact paths to list")->capture_default_str()->check(CLI::Range(0, 100000));
  sub->add_flag("--json", args->json, "Print histogram.json to stdout instead of the table");
  sub->add_flag("--quiet", args->quiet, "No progress bar");
  sub->add_flag("--missed", args->options.missed,
                "Also render the reference (pathex bias) and print what share of its light this renderer cannot "
                "sample; writes DIR/missed.json");
  sub->add_option("--reference", args->options.reference, "The reference of --missed; default: bdpt plus the connectors the scene needs")
      ->needs("--missed");
  sub->add_flag("--report", args->report_html, "Also write DIR/report.html, the render as one self-contained web page (pathex report)");
  add_report_options(sub, &args->report_options);
  sub->add_flag("--no-images", args->options.job.no_images, "Skip the EXR and PNG outputs and the per-pixel sums behind them (the histogram is the same)");
  sub->add_option("--max-memory", args->options.max_memory,
                  "Refuse a render whose images (and their writing) would take more, estimated before rendering; e.g. 512M, 16G")
      ->transform(CLI::AsSizeValue(false))
      ->default_str("4G");
  sub->add_option("--shard", args->options.job.shard, "Render shard i of n of the passes (i/n, 0 <= i < n); merge the shards with pathex merge");
  sub->add_option("--resume", args->options.job.resume, "Continue the interrupted render in this folder to its requested spp (settings come from the folder)");
  sub->add_option("--time", args->options.time_limit, "Stop after this many seconds (at the end of a chunk of passes); --resume continues")
      ->check(CLI::PositiveNumber);
  add_manifold_options(sub, &args->options.job.manifold);
  add_limit_options(sub, &args->options.job.limits);
  add_scene_limit_options(sub, &args->options.job.limits);
  return {sub, [args, sub] {
            for (const char* o : {"SCENE", "--renderer", "--spp", "--classes", "--only", "--seed", "--max-bounces", "--out", "--no-images", "--shard",
                                  "--resolution", "--max-paths", "--sampler", "--light-sampling", "--batches", "--replicates", "--rr-depth", "--rr-threshold",
                                  "--rr-light-threshold", "--rr-join-threshold", "--splits"})
              if (sub->count(o) > 0) args->options.job.settings_given.push_back(o);
            for (const std::string& o : manifold_option_names())
              if (sub->count(o) > 0) args->options.job.settings_given.push_back(o);
            return run(*args);
          }};
}

}  // namespace pathex::cli
