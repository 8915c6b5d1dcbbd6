// pathex trace: render a scene, label every sampled path, write the path-class histogram, the
// per-class EXR and PNG previews, and print where the light went, class by class, next to what the
// checker says the renderer can reach.
#include <sys/ioctl.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "cli/common.h"
#include "cli/reach_common.h"
#include "cli/trace_checks.h"
#include "io/atomic_file.h"
#include "io/class_file.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/output_set.h"
#include "io/profile_json.h"
#include "io/progress.h"
#include "scene/universe.h"
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
  std::string out = "pathex-out";
  std::uint64_t spp = 16;
  std::uint64_t seed = 1;
  int threads = 0;
  std::optional<int> max_bounces;
  SamplerKind sampler = RenderOptions{}.sampler;  // the defaults of these three: RenderOptions'
  int rr_depth = RenderOptions{}.rr_depth;
  float rr_threshold = RenderOptions{}.rr_threshold;
  std::string resolution;  // "WxH"; empty: the scene's
  std::uint64_t max_paths = 1000;
  int top_paths = 8;
  bool json = false;
  bool quiet = false;
  bool no_images = false;
  ExrCompression exr_compression = ExrOptions{}.compression;
  std::uint64_t max_memory = kDefaultMaxMemory;
  Limits limits;
};

std::atomic<bool> g_cancel{false};
extern "C" void on_sigint(int) { g_cancel.store(true); }

std::string percent(double share, int decimals = 1) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f %%", decimals, 100.0 * share);
  return buf;
}

// An absolute estimate: the mean pixel luminance and its standard error, "0.01234 ± 0.00012".
std::string absolute(const Estimate& e) {
  char buf[64];
  if (std::isfinite(e.std_error)) std::snprintf(buf, sizeof buf, "%.5f ± %.5f", e.luminance, e.std_error);
  else std::snprintf(buf, sizeof buf, "%.5f (too few batches for an error)", e.luminance);
  return buf;
}

// The terminal's width in columns (stderr's), or 80 when it does not say.
int terminal_columns() {
  winsize w{};
  if (::ioctl(STDERR_FILENO, TIOCGWINSZ, &w) == 0 && w.ws_col > 0) return w.ws_col;
  return 80;
}

std::string gib(std::uint64_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f GiB", static_cast<double>(bytes) / static_cast<double>(std::uint64_t{1} << 30));
  return buf;
}

// CPU seconds used by this process so far, all threads.
double process_cpu_seconds() {
  timespec ts{};
  ::clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// histogram.json's "efficiency": Veach's efficiency of the image-mean estimate, 1 / (relative
// variance × CPU seconds of the render), with its two factors. Independent of the spp (the
// variance falls as the time grows), so two settings compare without a reference. Null when the
// total has no finite relative error (a black image, fewer than two batches of passes).
nlohmann::ordered_json efficiency_json(const Estimate& total, double cpu_s) {
  const double rel = total.luminance > 0.0 ? total.std_error / total.luminance : 0.0;
  const double rel_var = rel * rel;
  nlohmann::ordered_json e;
  e["cpu_s"] = cpu_s;
  if (std::isfinite(rel_var) && rel_var > 0.0 && cpu_s > 0.0) {
    e["relative_variance"] = rel_var;
    e["per_cpu_s"] = 1.0 / (rel_var * cpu_s);
  } else {
    e["relative_variance"] = nullptr;
    e["per_cpu_s"] = nullptr;
  }
  return e;
}

int run(const TraceArgs& a) {
  // --- scene, profile, classes ---
  Result<Scene> scene = a.scene.empty() ? load_scene_json(default_scene_json(), ".", "default (embedded cornell)")
                                        : load_scene_file(a.scene, SceneLoadOptions{a.limits.max_file_bytes});
  if (!scene) return report(scene.error());
  if (!a.resolution.empty())
    if (Result<bool> r = apply_resolution(a.resolution, &scene->camera); !r) return report(r.error());
  // The output folder is checked before the render, not after it.
  Result<OutputSet> out_set = OutputSet::prepare(a.out);
  if (!out_set) return report(out_set.error());
  const std::string scene_name = a.scene.empty() ? "default (embedded cornell)" : a.scene;
  Result<Profile> profile = resolve_profile(a.renderer, a.limits);
  if (!profile) return report(profile.error());
  if (Result<StrategySet> runnable = runnable_strategies(*profile); !runnable) return report(runnable.error());

  ClassOptions copts;
  copts.limits = a.limits;
  const SceneTypes types = scene_types(*scene);
  copts.ends.lights.assign(types.lights.begin(), types.lights.end());
  copts.ends.sensors = {types.sensor};
  ClassTable table;
  std::vector<const PathClass*> classes;
  if (!a.classes_file.empty()) {
    Result<bool> r = read_class_file(a.classes_file, copts, &table);
    if (!r) return report(r.error());
    for (const auto& c : table.user_classes()) classes.push_back(c.get());
  } else {
    for (const auto& c : ClassTable::builtins().builtin_classes())
      if (c->name != "all") classes.push_back(c.get());
  }
  Result<Classifier> classifier = Classifier::build(classes, a.limits);
  if (!classifier) return report(classifier.error());
  std::vector<ClassInfo> infos;
  for (const PathClass* c : classes) infos.push_back({c->name, c->text});

  // One bound for the render and for the checker's verdicts: --max-bounces, else the profile's, else 16.
  const int bound = a.max_bounces.value_or(profile->max_bounces.value_or(16));
  ReachCache cache(a.limits);
  Result<const CompiledProfile*> cp = cache.compiled(a.renderer, bound);
  if (!cp) return report(cp.error());
  const Dfa universe = scene_universe(types);
  warn_unreachable_lights(*scene, *profile, **cp, universe, bound, a.limits);

  // --- render ---
  RenderOptions ro;
  ro.spp = a.spp;
  ro.seed = a.seed;
  ro.threads = a.threads;
  ro.max_bounces = bound;
  ro.sampler = a.sampler;
  ro.rr_depth = a.rr_depth;
  ro.rr_threshold = a.rr_threshold;
  // Without image outputs the render keeps the histogram alone (the same histogram).
  ro.images = !a.no_images;
  if (ro.images)
    for (int i = 0; i < classifier->num_classes(); ++i) ro.layer_classes.push_back(i);
  // --- memory: the images and their writing, estimated before the render ---
  const int num_layers = 1 + static_cast<int>(ro.layer_classes.size());
  const std::uint64_t need = ro.images ? render_memory_estimate(scene->camera.width, scene->camera.height, num_layers) : 0;
  if (need > a.max_memory) {
    Error e = make_error(ErrorCode::kLimit,
                         "the images would take about " + gib(need) + " (" + std::to_string(scene->camera.width) + " x " +
                             std::to_string(scene->camera.height) + " pixels, " + std::to_string(num_layers) +
                             " layers), more than --max-memory " + gib(a.max_memory) +
                             "; pass --no-images for the histogram alone, render fewer pixels or classes, or raise --max-memory");
    e.where = scene_name + ":/camera";
    return report(e);
  }
  const bool show_progress = !a.quiet && ::isatty(STDERR_FILENO);
  const auto start = std::chrono::steady_clock::now();
  if (show_progress) {
    ro.progress = [start](std::uint64_t done, std::uint64_t total) {
      Progress p;
      p.fraction = total ? static_cast<double>(done) / static_cast<double>(total) : 1.0;
      const double el = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      p.samples_per_s = el > 0 ? static_cast<double>(done) / el : 0.0;
      p.seconds_left = p.fraction > 0 ? el / p.fraction - el : 0;
      // Padded to the width it was fitted to, so a shorter line covers a longer one.
      const int columns = terminal_columns();
      std::fprintf(stderr, "\r%-*s", std::max(columns - 1, 0), progress_line(p, columns).c_str());
      std::fflush(stderr);
    };
  }
  g_cancel.store(false);
  ro.cancel = &g_cancel;
  std::signal(SIGINT, on_sigint);
  const double cpu_start = process_cpu_seconds();
  Result<RenderOutput> out = render(*scene, *profile, &*classifier, ro);
  const double cpu_s = process_cpu_seconds() - cpu_start;
  std::signal(SIGINT, SIG_DFL);
  if (show_progress) std::fprintf(stderr, "\r%*s\r", std::max(terminal_columns() - 1, 0), "");
  if (!out) return report(out.error());

  RunInfo info;
  info.scene = scene_name;
  info.renderer = profile->name;
  info.spp = out->spp_done;
  info.spp_requested = a.spp;
  info.seed = a.seed;
  info.threads = a.threads > 0 ? a.threads : static_cast<int>(std::thread::hardware_concurrency());
  info.time_s = out->time_s;
  info.complete = out->complete;
  Result<HistogramReport> rep = make_report(out->histogram, info, &*classifier, infos, a.max_paths);
  if (!rep) return report(rep.error());

  // --- outputs: one set, whole or not at all, shielded from signals (io/output_set.h) ---
  // histogram.json, plus what each connector did ("connectors": [{strategy, connector, attempts,
  // successes, failures {outside, occluded, no_transport}}] in the profile's order; absent when the
  // profile has none).
  nlohmann::ordered_json doc = to_json(*rep);
  if (!out->connectors.empty()) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const ConnectorStats& c : out->connectors)
      list.push_back({{"strategy", c.strategy},
                      {"connector", c.connector},
                      {"attempts", c.attempts},
                      {"successes", c.successes},
                      {"failures", {{"outside", c.outside}, {"occluded", c.occluded}, {"no_transport", c.no_transport}}}});
    doc["connectors"] = std::move(list);
  }
  doc["sampler"] = to_string(a.sampler);
  doc["roulette"] = {{"depth", a.rr_depth}, {"threshold", a.rr_threshold}};
  doc["efficiency"] = efficiency_json(rep->total, cpu_s);
  const std::string json_text = doc.dump(2) + "\n";
  {
    const SignalShield shield;
    Result<bool> written = out_set->write([&](const std::string& dir) -> Result<bool> {
      if (Result<bool> w = write_file_atomic(dir + "/histogram.json", json_text); !w) return w;
      if (a.no_images) return true;
      const std::vector<ImageLayer> layers = out->images.layers(out->spp_done ? 1.0 / static_cast<double>(out->spp_done) : 0.0);
      ExrOptions exr;
      exr.compression = a.exr_compression;
      if (Result<bool> w = write_exr(dir + "/classes.exr", layers, exr); !w) return w;
      return write_previews(dir, layers);
    });
    if (!written) return report(written.error());
  }
  if (a.json) {
    std::cout << json_text;
    return out->complete ? kExitOk : kExitNo;
  }

  // --- the table: classes with the checker's verdict, then the most important exact paths ---
  QueryOptions qo;
  qo.universe = universe;
  qo.max_bounces = bound;
  qo.witnesses = 0;
  qo.max_len = 0;
  std::cout << "scene " << scene_name << ", renderer " << profile->name << ", " << out->spp_done << " spp, "
            << std::fixed << std::setprecision(2) << out->time_s << " s" << (out->complete ? "" : " (interrupted)")
            << ", non-finite samples " << rep->nonfinite_samples << "\n";
  std::cout << "image mean luminance " << absolute(rep->total) << "\n"
            << "(shares are of this render's total; luminances are absolute, comparable between renderers)\n\n";
  for (std::size_t i = 0; i < rep->classes.size(); ++i) {
    const ClassEstimate& c = rep->classes[i];
    Result<QueryResult> q = query(*classes[i], **cp, qo);
    const double err = rep->total.luminance > 0 ? c.estimate.std_error / rep->total.luminance : 0.0;
    std::cout << c.name << ": " << percent(c.share) << " of the image, ±" << percent(std::isfinite(err) ? err : 0.0, 2)
              << "; " << profile->name << ": " << (q ? to_string(q->verdict) : "?") << "; luminance "
              << absolute(c.estimate) << "\n";
  }
  if (!out->connectors.empty()) {
    int width = 10;
    for (const ConnectorStats& c : out->connectors) width = std::max(width, static_cast<int>(c.strategy.size()));
    std::cout << "\n" << std::left << std::setw(width + 2) << "connectors" << std::right
              << "  attempts  successes   outside  occluded  no transport\n";
    for (const ConnectorStats& c : out->connectors)
      std::cout << "  " << std::left << std::setw(width) << c.strategy << std::right << std::setw(10) << c.attempts
                << std::setw(11) << c.successes << std::setw(10) << c.outside << std::setw(10) << c.occluded
                << std::setw(14) << c.no_transport << "   (" << c.connector << ")\n";
  }
  std::cout << "\nmost important paths\n";
  for (std::size_t i = 0; i < rep->paths.size() && static_cast<int>(i) < a.top_paths; ++i) {
    const PathEstimate& p = rep->paths[i];
    const double share = rep->total.luminance > 0 ? p.estimate.luminance / rep->total.luminance : 0.0;
    const double err = rep->total.luminance > 0 ? p.estimate.std_error / rep->total.luminance : 0.0;
    std::cout << "  " << std::left << std::setw(16) << p.path << std::right << std::setw(8) << percent(share) << "  ±"
              << percent(std::isfinite(err) ? err : 0.0, 2) << "  luminance " << absolute(p.estimate) << "  via";
    for (const auto& [name, s] : p.strategies) std::cout << " " << name << " " << percent(s);
    std::cout << "\n";
  }
  std::cout << "\nwrote " << a.out << "/histogram.json" << (a.no_images ? "" : ", classes.exr and PNG previews") << "\n";
  return out->complete ? kExitOk : kExitNo;
}

}  // namespace

Command add_trace(CLI::App& app) {
  auto args = std::make_shared<TraceArgs>();
  CLI::App* sub = app.add_subcommand("trace", "Render a scene, label every path, write path-class histograms and images");
  sub->footer("Example:\n  pathex trace                         # the embedded Cornell box\n"
              "  pathex trace samples/scenes/point-mirror-caustic.json --renderer pt-nee --spp 64 --out out/\n"
              "Writes DIR/histogram.json, DIR/classes.exr (a layer per class and the total) and DIR/<layer>.png,\n"
              "as one set that replaces the previous one whole (DIR must hold only what pathex wrote there).\n"
              "Ctrl-C stops early and writes what was rendered, marked \"complete\": false (exit 1).");
  sub->add_option("SCENE", args->scene, "Scene file (grammar/scene.schema.json); default: the embedded Cornell box");
  sub->add_option("--renderer", args->renderer, "Renderer profile: built-in name or file")->capture_default_str();
  sub->add_option("--spp", args->spp, "Samples per pixel")->capture_default_str()->check(CLI::Range(1, 1 << 24));
  sub->add_option("--classes", args->classes_file, "Class file; default: the built-in classes");
  sub->add_option("--seed", args->seed, "Random seed (0 to 2^64 - 1)")->capture_default_str()->check(non_negative());
  sub->add_option("--threads", args->threads, "Worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
  sub->add_option("--max-bounces", args->max_bounces, "Largest number of interior vertices (k - 1); default: the profile's bound, else 16")
      ->check(CLI::Range(0, 1000));
  sub->add_option("--out", args->out, "Output folder")->capture_default_str();
  sub->add_option("--sampler", args->sampler,
                  "Random numbers: sobol (Owen-scrambled Sobol points, stratified per pixel) or independent")
      ->transform(CLI::CheckedTransformer(std::map<std::string, SamplerKind>{{"independent", SamplerKind::kIndependent},
                                                                              {"sobol", SamplerKind::kSobol}}))
      ->default_str(to_string(RenderOptions{}.sampler));
  sub->add_option("--rr-depth", args->rr_depth,
                  "Russian roulette from this vertex of a subpath on (the camera or light point is the first)")
      ->capture_default_str()->check(CLI::Range(1, 1000));
  sub->add_option("--rr-threshold", args->rr_threshold,
                  "Russian roulette only below this throughput (relative to the subpath's start); 0: no roulette")
      ->capture_default_str()->check(CLI::Range(0.0f, 1000.0f));
  sub->add_option("--resolution", args->resolution, "Image size WIDTHxHEIGHT, such as 640x480; default: the scene's")
      ->type_name("WxH");
  sub->add_option("--max-paths", args->max_paths,
                  "Rows of histogram.json's path table; the rest are summed into one \"other\" row")
      ->capture_default_str()->check(non_negative());
  sub->add_option("--top", args->top_paths, "Exact paths to list")->capture_default_str()->check(CLI::Range(0, 100000));
  sub->add_flag("--json", args->json, "Print histogram.json to stdout instead of the table");
  sub->add_flag("--quiet", args->quiet, "No progress bar");
  sub->add_flag("--no-images", args->no_images, "Skip the EXR and PNG outputs and the per-pixel sums behind them (the histogram is the same)");
  sub->add_option("--exr-compression", args->exr_compression,
                  "classes.exr's lossless compression: rle (fast), zip (smaller files, about 8 times the CPU time) or none")
      ->transform(CLI::CheckedTransformer(std::map<std::string, ExrCompression>{{"rle", ExrCompression::kRle},
                                                                                {"zip", ExrCompression::kZip},
                                                                                {"none", ExrCompression::kNone}}))
      ->default_str("rle");
  sub->add_option("--max-memory", args->max_memory,
                  "Refuse a render whose images (and their writing) would take more, estimated before rendering; e.g. 512M, 16G")
      ->transform(CLI::AsSizeValue(false))
      ->default_str("4G");
  add_limit_options(sub, &args->limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
