// pathex converge: what accuracy costs in time (DESIGN §8, issue 13). The run is the library's
// (measure/converge.h: the reference, the checker's verdicts, the ladder, its statistics and
// outputs); this file holds its options, the progress lines, the table and the exit codes.
#include <unistd.h>

#include <iomanip>
#include <iostream>
#include <memory>
#include <string>

#include "cli/common.h"
#include "cli/folder_report.h"
#include "measure/converge.h"
#include "output/render_job.h"

namespace pathex::cli {
namespace {

struct ConvergeArgs {
  ConvergeOptions options;  // measure/converge.h
  bool json = false;
  bool quiet = false;
  bool report_html = false;  // --report
  ReportOptions report_options;
};

int run(const ConvergeArgs& args) {
  const ConvergeOptions& a = args.options;
  const Cluster* cluster = current_cluster();
  const bool root = cluster == nullptr || cluster->rank() == 0;
  ConvergeHooks hooks;
  if (root && !args.quiet && ::isatty(STDERR_FILENO))
    hooks.progress = [](const std::string& rung, bool reference) {
      if (reference) std::cerr << "pathex: reference run: " << rung << "\n";
      else if (!rung.empty()) std::cerr << "\rpathex: " << rung << "        " << std::flush;
      else std::cerr << "\r" << std::string(60, ' ') << "\r" << std::flush;
    };
  if (args.report_html)  // --report: a file of the set, from the files staged
    hooks.extra_files = [&](const std::string& dir) -> Result<bool> {
      KnownRender known;
      known.folder = a.out;
      if (Result<std::string> w = write_folder_report(dir, args.report_options, a.limits, &known); !w) return w.error();
      return true;
    };
  Result<ConvergeResult> run = converge(a, hooks);
  if (!run) return report(run.error());
  const ConvergeResult& r = *run;
  if (!r.nothing_to_render.empty()) {
    std::cout << r.nothing_to_render << "\n";
    return kExitNo;
  }
  if (r.reference_interrupted) {
    if (r.root) std::cerr << "pathex: interrupted during the reference run; nothing written\n";
    return kExitNo;
  }
  if (!r.root) return r.complete ? kExitOk : kExitNo;  // the other ranks have done their part
  const bool complete = r.complete;
  const std::vector<ClassRow>& rows = r.rows;
  const auto& results = r.results;
  const auto& series = r.series;
  const auto& cannot = r.cannot;
  const std::vector<std::string>& names = r.renderers;
  if (args.json) {
    std::cout << r.json_text;
    return complete ? kExitOk : kExitNo;
  }

  // --- the table ---
  std::cout << "scene " << a.scene << ", reference: " << r.reference_kind << " (" << r.reference_source << ")"
            << (complete ? "" : "; interrupted: the finished rungs only") << "\n";
  if (!r.reach_note.empty()) std::cout << "note: " << r.reach_note << "\n";
  if (r.only) {
    std::cout << "rendered only";
    for (std::size_t i = 1; i < rows.size(); ++i) std::cout << (i > 1 ? "," : "") << " " << rows[i].name << " (" << rows[i].expr << ")";
    std::cout << "\n";
    for (const auto& [name, expr] : r.not_rendered) std::cout << name << ": not rendered\n";
  }
  for (std::size_t i = 0; i < rows.size(); ++i) {
    std::cout << "\nclass " << rows[i].name << " " << rows[i].expr << ": reference "
              << (rows[i].reference             ? fmt(*rows[i].reference, "%.6g")
                  : !rows[i].unmeasurable.empty() ? "not measurable with this reference (" + rows[i].unmeasurable + "); no errors measured"
                                                  : std::string("none (no errors measured)"));
    if (rows[i].reference && rows[i].reference_stderr > 0) std::cout << " ± " << fmt(rows[i].reference_stderr, "%.2g");
    std::cout << "\n  " << std::left << std::setw(16) << "renderer" << std::right << std::setw(10) << "budget" << std::setw(9)
              << "cpu s" << std::setw(9) << "wall s" << std::setw(12) << "estimate" << std::setw(11) << "stderr" << std::setw(11)
              << "error" << std::setw(7) << "z" << std::setw(11) << "rms/pixel" << std::setw(11) << "efficiency" << "\n";
    for (std::size_t k = 0; k < names.size(); ++k) {
      const Series& s = series[k][i];
      for (std::size_t j = 0; j < results[k].size(); ++j) {
        const RungResult& rung = results[k][j];
        const ClassMeasure& m = rung.classes[i];
        std::cout << "  " << std::left << std::setw(16) << names[k] << std::right << std::setw(10)
                  << (rung.budget.spp ? std::to_string(rung.spp) + " spp" : fmt(rung.budget.seconds, "%g") + " s") << std::setw(9)
                  << fmt(rung.cpu_s, "%.3f") << std::setw(9) << fmt(rung.wall_s, "%.3f") << std::setw(12) << fmt(m.estimate)
                  << std::setw(11) << fmt(m.std_error, "%.3g") << std::setw(11)
                  << (j < s.error.size() ? fmt(s.error[j], "%.3g") : "-") << std::setw(7)
                  << (j < s.z.size() ? fmt(s.z[j], "%.1f") : "-") << std::setw(11)
                  << (m.rms_pixel ? fmt(*m.rms_pixel, "%.3g") : "-") << std::setw(11)
                  << (j < s.efficiency.size() ? fmt(s.efficiency[j], "%.3g") : "-") << "\n";
      }
      if (cannot[k][i]) std::cout << "  " << names[k] << " cannot sample " << *cannot[k][i] << " of this class: not ranked on it\n";
      if (rows[i].reference && !results[k].empty())
        std::cout << "  " << names[k] << ": error slope against time " << fmt(s.slope, "%.2f")
                  << " (1/sqrt(t): -0.5), efficiency " << fmt(s.pooled_efficiency, "%.3g")
                  << (s.warning.empty() ? "" : "\n  WARNING " + names[k] + ": " + s.warning) << "\n";
    }
  }
  if (!r.warnings.empty()) {
    std::cout << "\nwarnings\n";
    for (const std::string& w : r.warnings) std::cout << "  " << w << "\n";
  }
  std::cout << "\nwrote " << a.out << "/converge.json, converge.svg and converge.png" << (r.reference_written ? ", reference.json and reference.exr" : "")
            << (args.report_html ? ", report.html" : "") << "\n\nmost efficient renderer per class (1 / mean(error^2 x CPU time) over the ladder)\n";
  for (const std::string& l : r.rankings.lines) std::cout << "  " << l << "\n";
  return complete ? kExitOk : kExitNo;
}

}  // namespace

Command add_converge(CLI::App& app) {
  auto args = std::make_shared<ConvergeArgs>();
  args->options.out = "pathex-converge";
  CLI::App* sub = app.add_subcommand("converge", "What accuracy costs in time: error against time per renderer and class");
  sub->footer("Example:\n  pathex converge samples/scenes/closed-sphere-point.json --renderer pt-nee --renderer bdpt --renderer lt\n"
              "Renders every renderer at every budget of the ladder (--spp 4,16,64,256 by default, or --time in seconds),\n"
              "measures each rung against a reference (the scene's closed form, --reference FILE, or a reference run it makes),\n"
              "checks that the reported stderr agrees with the true error, and writes DIR/converge.json, converge.svg and\n"
              "converge.png as one set. Ctrl-C keeps the finished rungs (exit 1).");
  sub->add_option("SCENE", args->options.scene, "Scene file")->required();
  sub->add_option("--renderer", args->options.renderers, "Renderer profile (repeat for several): built-in name or file")->required();
  sub->add_option("--classes", args->options.classes_file, "Class file; default: the scene's closed-form classes, else the built-ins");
  sub->add_option("--spp", args->options.spp_list, "Ladder of samples per pixel, increasing (default 4,16,64,256)")->type_name("N,N,...");
  sub->add_option("--time", args->options.time_list, "Ladder of wall-clock seconds per render, increasing")->type_name("S,S,...");
  sub->add_option("--reference", args->options.reference, "An earlier run's histogram.json (classes.exr beside it adds per-pixel errors) or EXR");
  sub->add_option("--reference-renderer", args->options.reference_renderer,
                  "Renderer of the reference run made when the scene declares no closed form and --reference is not given; "
                  "default: bdpt plus the connectors the scene needs (as pathex bias)");
  sub->add_option("--reference-factor", args->options.reference_factor, "The reference run's budget over the ladder's largest")
      ->capture_default_str()->check(CLI::Range(1, 1024));
  sub->add_option("--seed", args->options.seed, "Base seed: rung i of renderer k uses seed + 1000 k + i")->capture_default_str()->check(non_negative());
  sub->add_option("--threads", args->options.threads, "Worker threads (0: all cores)")->capture_default_str()->check(CLI::Range(0, 1024));
  sub->add_option("--max-bounces", args->options.max_bounces, "Largest number of interior vertices; default: each profile's bound, else 16")->check(CLI::Range(0, 1000));
  sub->add_option("--resolution", args->options.resolution, "Image size WIDTHxHEIGHT; default: the scene's")->type_name("WxH");
  sub->add_option("--only", args->options.only,
                  "Measure only the paths of this class (an expression or $name; repeatable), as pathex trace --only: the "
                  "other classes are reported as not rendered")
      ->type_name("EXPR");
  sub->add_option("--out", args->options.out, "Output folder")->capture_default_str();
  sub->add_flag("--json", args->json, "Print converge.json to stdout instead of the table");
  sub->add_flag("--quiet", args->quiet, "No progress lines");
  sub->add_flag("--report", args->report_html, "Also write DIR/report.html, the plot and table as one self-contained web page (pathex report)");
  add_report_options(sub, &args->report_options);
  add_limit_options(sub, &args->options.limits);
  add_manifold_options(sub, &args->options.manifold);
  add_scene_limit_options(sub, &args->options.limits);
  return {sub, [args] { return run(*args); }};
}

}  // namespace pathex::cli
