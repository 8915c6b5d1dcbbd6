// pathex bias: how much light does a renderer miss in this scene, and where? One reference
// render (bias/bias.h) labels every sampled path; the checker decides, per exact path, whether the
// renderer can sample it. Prints the missed light (absolute and as a share of the image), by class
// and by exact path with the checker's explanation, the paths nobody samples, and writes the
// missed image beside the total.
#include <iomanip>
#include <iostream>
#include <thread>

#include "cli/bias_common.h"
#include "output/bias_json.h"
#include "output/render_job.h"
#include "cli/common.h"
#include "io/estimate_text.h"
#include "cli/folder_report.h"
#include "measure/render_watch.h"
#include "scene/resolution.h"
#include "cli/witness_text.h"
#include "io/atomic_file.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/output_set.h"
#include "io/profile_json.h"

namespace pathex::cli {
namespace {

struct BiasArgs {
  std::string scene;
  std::string renderer;
  std::string reference;
  std::string classes_file;
  std::string out = "pathex-bias";
  std::string resolution;
  BiasOptions options;
  std::optional<std::uint64_t> renderer_spp;  // default: options.spp; 0: no comparison
  int top_paths = 8;
  bool json = false;
  bool no_images = false;
  bool quiet = false;
  bool report_html = false;  // --report
  ReportOptions report_options;
};

void print_text(const BiasReport& r, int top, const std::string& out_dir, bool images) {
  std::cout << "scene " << r.scene << "\n"
            << r.renderer << (r.renderer_bounces ? " (max_bounces " + std::to_string(*r.renderer_bounces) + ")" : "")
            << " against the reference " << r.reference << ", rendered at " << r.spp << " spp up to "
            << r.reference_bounces << " interior vertices in " << std::fixed << std::setprecision(2) << r.time_s
            << " s; non-finite samples " << r.nonfinite_samples << (r.complete ? "" : " (interrupted)") << "\n";
  std::cout << "image mean luminance " << absolute(r.total) << "\n";
  if (r.covered)
    std::cout << r.renderer << " misses nothing: it samples every path of the scene's universe up to "
              << r.reference_bounces << " interior vertices (the checker proves it), so the missed light is 0 exactly\n";
  else
    std::cout << r.renderer << " misses " << absolute(r.missed) << ", " << percent(r.share) << " ± "
              << percent(r.share_std_error, 2) << " of the image" << (images ? " (missed.exr, missed.png)" : "") << "\n";
  if (r.shortest) std::cout << "shortest path it cannot sample: " << witness_line(*r.shortest) << "\n";

  int width = 8;
  for (const MissedClass& c : r.classes) width = std::max(width, static_cast<int>(c.name.size()));
  std::cout << "\nmissed by class: luminance, share of the class, " << r.renderer
            << "'s verdict, the shortest path of the class it cannot sample\n";
  for (const MissedClass& c : r.classes) {
    std::cout << "  " << std::left << std::setw(width) << c.name << std::right << "  " << absolute(c.missed) << "  "
              << std::setw(7) << percent(c.light.luminance > 0 ? c.missed.luminance / c.light.luminance : 0.0) << "  "
              << std::left << std::setw(11) << to_string(c.verdict) << std::right;
    if (c.witness) std::cout << "  " << witness_line(*c.witness);
    std::cout << "\n";
    if (c.neither)
      std::cout << "  " << std::string(static_cast<std::size_t>(width), ' ') << "  and paths " << r.reference
                << " cannot sample either, not counted: " << witness_line(*c.neither) << "\n";
  }

  std::cout << "\nmissed by exact path: share of the image, luminance, why " << r.renderer << " cannot sample it\n";
  if (r.paths.empty()) std::cout << "  none sampled\n";
  for (std::size_t i = 0; i < r.paths.size() && static_cast<int>(i) < top; ++i) {
    const MissedPath& p = r.paths[i];
    std::cout << "  " << std::left << std::setw(16) << p.estimate.path << std::right << std::setw(8) << percent(p.share)
              << "  " << absolute(p.estimate.estimate) << "  chains " << chains_text(p.chains) << "; " << p.reason
              << "\n";
  }
  const std::uint64_t more = r.paths.size() - std::min(r.paths.size(), static_cast<std::size_t>(top)) + r.other_missed_paths;
  if (more > 0) std::cout << "  … " << more << " more (bias.json lists " << r.paths.size() << "; --top, --max-paths)\n";

  if (r.undersampled) {
    std::cout << "\n";
    for (const std::string& line : undersampled_lines(r, top)) std::cout << line << "\n";
  }

  std::cout << "\nnot counted\n";
  if (r.neither.empty()) {
    std::cout << "  paths neither can sample: none (" << r.reference << " samples every path " << r.renderer
              << " misses)\n";
  } else {
    std::cout << "  paths neither " << r.renderer << " nor " << r.reference
              << " can sample (their light is unknown, not 0), the shortest:\n";
    for (const Witness& w : r.neither) std::cout << "    " << witness_line(w) << "\n";
  }
  std::cout << "  light on paths with more than " << r.reference_bounces
            << " interior vertices (the reference's bound, --reference-bounces)\n";
  std::cout << "\nwrote " << out_dir << "/bias.json, histogram.json"
            << (images ? ", classes.exr, missed.exr and PNG previews (missed.png on total.png's exposure)" : "") << "\n";
}

int run(BiasArgs a) {
  // --- scene, renderer, classes ---
  Result<Scene> scene = load_scene_file(a.scene, scene_load_options(a.options.limits));
  if (!scene) return report(scene.error());
  if (!a.resolution.empty())
    if (Result<bool> r = apply_resolution(a.resolution, &scene->camera); !r) return report(r.error());
  Result<OutputSet> out_set = OutputSet::prepare(a.out);
  if (!out_set) return report(out_set.error());
  Result<Profile> renderer = resolve_profile(a.renderer, a.options.limits);
  if (!renderer) return report(renderer.error());
  Result<std::unique_ptr<RenderClasses>> classes = bias_classes(a.classes_file, *scene, a.options.limits);
  if (!classes) return report(classes.error());

  // --- the reference render and what the renderer misses ---
  a.options.images = !a.no_images;
  a.options.renderer_spp = a.renderer_spp.value_or(a.options.spp);
  Result<BiasRun> run = [&] {
    const RenderWatch watch(!a.quiet);
    a.options.progress = watch.progress();
    a.options.cancel = watch.cancel();
    return measure_missed(*scene, a.scene, *renderer, a.reference, (*classes)->classes, a.options);
  }();
  if (!run) return report(run.error());
  const std::string bias_text = bias_json_text(run->report);

  // --- outputs: one set, whole or not at all ---
  {
    const SignalShield shield;
    Result<bool> written = out_set->write([&](const std::string& dir) -> Result<bool> {
      if (Result<bool> w = write_file_atomic(dir + "/bias.json", bias_text); !w) return w;
      if (Result<bool> w = write_file_atomic(dir + "/histogram.json", histogram_json_text(run->histogram)); !w) return w;
      if (!a.no_images) {
        const double scale = run->render.spp_done ? 1.0 / static_cast<double>(run->render.spp_done) : 0.0;
        std::vector<ImageLayer> layers = run->render.images.layers(scale);  // total, the classes, missed
        const std::vector<ImageLayer> missed(layers.end() - 1, layers.end());
        if (Result<bool> w = write_exr(dir + "/missed.exr", missed); !w) return w;
        if (Result<bool> w = write_previews(dir, layers); !w) return w;  // one exposure: the total's
        layers.pop_back();
        if (Result<bool> w = write_exr(dir + "/classes.exr", layers); !w) return w;
      }
      if (a.report_html) {  // a file of the set, read from the files just staged
        KnownRender known;
        known.folder = a.out;
        if (Result<std::string> w = write_folder_report(dir, a.report_options, a.options.limits, &known); !w) return w.error();
      }
      return true;
    });
    if (!written) return report(written.error());
  }
  if (a.json) std::cout << bias_text;
  else print_text(run->report, a.top_paths, a.out, !a.no_images);
  if (!a.json && a.report_html) std::cout << "wrote " << a.out << "/" << kReportName << " (open it in a browser)\n";
  return run->report.complete ? kExitOk : kExitNo;
}

}  // namespace

Command add_bias(CLI::App& app) {
  auto args = std::make_shared<BiasArgs>();
  CLI::App* sub = app.add_subcommand("bias", "How much light a renderer misses in a scene, by class, by exact path and per pixel");
  sub->footer("Example:\n  pathex bias samples/scenes/point-mirror-caustic.json --renderer pt-nee --spp 64\n"
              "Renders the scene once with the reference (default: bdpt plus every connector the scene's universe\n"
              "needs) and reports the light the renderer cannot sample, with the checker's reasons; then renders the\n"
              "renderer itself (--renderer-spp) and reports light it can sample but under-samples. Writes\n"
              "DIR/bias.json, DIR/histogram.json, DIR/classes.exr, DIR/missed.exr and DIR/<layer>.png (missed.png\n"
              "on the total's exposure). Ctrl-C stops early and writes what was rendered (exit 1).");
  sub->add_option("SCENE", args->scene, "Scene file (grammar/scene.schema.json)")->required();
  sub->add_option("--renderer", args->renderer, "The renderer profile to measure: built-in name or file")->required();
  sub->add_option("--reference", args->reference,
                  "The profile that renders the scene; default: bdpt plus every connector the scene's universe needs");
  sub->add_option("--spp", args->options.spp, "Samples per pixel of the reference render")->capture_default_str()->check(CLI::Range(1, 1 << 24));
  sub->add_option("--renderer-spp", args->renderer_spp,
                  "Also render the renderer at this budget and report light it can sample but under-samples there "
                  "(0: skip); default: --spp")
      ->check(CLI::Range(std::uint64_t{0}, std::uint64_t{1} << 24));
  sub->add_option("--undersampled-share", args->options.undersampled_share,
                  "Smallest difference reported as under-sampled, as a share of the light the renderer can sample")
      ->capture_default_str()->check(CLI::Range(0.0, 1.0));
  sub->add_option("--classes", args->classes_file, "Class file; default: the built-in classes");
  sub->add_option("--seed", args->options.seed, "Random seed (0 to 2^64 - 1)")->capture_default_str()->check(non_negative());
  sub->add_option("--threads", args->options.threads, "Worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
  sub->add_option("--max-bounces", args->options.renderer_bounces,
                  "The renderer's bound on interior vertices, overriding its profile's (as in query)")
      ->check(CLI::Range(0, kMaxReferenceBounces - 1));
  sub->add_option("--reference-bounces", args->options.reference_bounces,
                  "The reference's bound on interior vertices, above the renderer's; default: 16, or the renderer's bound + 8 if more")
      ->check(CLI::Range(0, kMaxReferenceBounces));
  sub->add_option("--resolution", args->resolution, "Image size WIDTHxHEIGHT, such as 64x64; default: the scene's")->type_name("WxH");
  sub->add_option("--witnesses", args->options.witnesses, "Paths neither renderer samples to show")->capture_default_str()->check(CLI::Range(1, 100));
  sub->add_option("--max-paths", args->options.max_paths,
                  "Rows of the path tables of histogram.json and bias.json; the rest are summed (histogram.json) or counted (bias.json)")
      ->capture_default_str()->check(non_negative());
  sub->add_option("--top", args->top_paths, "Missed exact paths to list (bias.json has all)")->capture_default_str()->check(CLI::Range(0, 100000));
  sub->add_option("--out", args->out, "Output folder")->capture_default_str();
  sub->add_flag("--json", args->json, "Print bias.json to stdout instead of the table");
  sub->add_flag("--quiet", args->quiet, "No progress bar");
  sub->add_flag("--no-images", args->no_images, "Skip the EXR and PNG outputs (the numbers are the same)");
  sub->add_flag("--report", args->report_html, "Also write DIR/report.html, the result as one self-contained web page (pathex report)");
  add_report_options(sub, &args->report_options);
  add_limit_options(sub, &args->options.limits);
  add_scene_limit_options(sub, &args->options.limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
