// pathex report: a render folder (of pathex trace, bias or converge) as one self-contained
// report.html (output/report_html.h builds it). The command reads the folder, asks the checker for each
// class's verdict when the folder is a trace render (the scene and renderer its render.shard names),
// writes the page and says where. trace, bias and converge call write_folder_report for --report.
#include <iostream>

#include "cli/common.h"
#include "cli/folder_report.h"
#include "cli/reach_common.h"
#include "output/render_job.h"
#include "output/report_html.h"
#include "reach/query.h"
#include "scene/scene.h"
#include "scene/universe.h"

namespace pathex::cli {
namespace {

// The checker's verdict for the render's renderer on each class, under the render's bound and its
// scene's universe, as pathex trace prints them. Nothing when the scene cannot be read again (it
// moved): the tiles then say the verdict is not known.
void add_verdicts(const RenderIdentity& id, const Limits& limits, ReportData* d) {
  Result<Scene> scene = id.scene_file.empty() ? load_scene_json(default_scene_json(), ".", id.scene)
                                              : load_scene_file(id.scene_file, scene_load_options(limits, /*triangles=*/false));
  if (!scene) return;
  Result<std::unique_ptr<RenderClasses>> classes = compile_render_classes(id.classes_text, id.classes_file, id, limits);
  if (!classes) return;
  ReachCache cache(limits);
  Result<const CompiledProfile*> compiled = cache.compiled(id.renderer_source, id.max_bounces);
  if (!compiled) return;
  QueryOptions qo;
  qo.universe = scene_universe(scene_types(*scene));
  qo.max_bounces = id.max_bounces;
  qo.witnesses = 0;
  qo.max_len = 0;
  for (const PathClass* c : (*classes)->classes) {
    Result<QueryResult> q = query(*c, **compiled, qo);
    if (q) d->verdicts[c->name] = to_string(q->verdict);
  }
  d->verdict_renderer = id.renderer;
}

struct ReportArgs {
  std::string dir;
  ReportOptions options;
  Limits limits;
};

}  // namespace

Result<std::string> write_folder_report(const std::string& dir, const ReportOptions& options, const Limits& limits,
                                        const KnownRender* known) {
  ReportOptions o = options;
  o.max_file_bytes = limits.max_file_bytes;
  Result<ReportData> data = load_report_folder(dir, o, known);
  if (!data) return data.error();
  if (data->identity && data->verdicts.empty()) add_verdicts(*data->identity, limits, &*data);
  const std::string html = report_html(*data, o);
  if (Result<bool> w = write_report(dir, html); !w) return w.error();
  return dir + "/" + kReportName;
}

void add_report_options(CLI::App* sub, ReportOptions* o) {
  sub->add_option("--hover-size", o->hover_max,
                  "report.html: the largest side, in cells, of the per-class data shown under the pointer (larger images are "
                  "box-downsampled)")
      ->capture_default_str()->check(CLI::Range(1, 4096));
}

Command add_report(CLI::App& app) {
  auto args = std::make_shared<ReportArgs>();
  CLI::App* sub = app.add_subcommand("report", "Write DIR/report.html: a render folder as one self-contained web page");
  sub->footer("Example:\n  pathex trace --out out && pathex report out      # then open out/report.html\n"
              "Reads the folder pathex trace, bias or converge wrote (histogram.json, classes.exr, run.json, bias.json or\n"
              "missed.json, converge.json) and writes DIR/report.html: the render and one tile per class with share, error,\n"
              "luminance, the checker's verdict and strategies, the exact paths, and when present the missed light, the\n"
              "convergence plot, the --only narrowing and the connectors. Images are embedded; it needs no network.\n"
              "trace --report, bias --report and converge --report write it after their run.");
  sub->add_option("DIR", args->dir, "The output folder of pathex trace, bias or converge")->required();
  sub->add_option("--top", args->options.top_paths, "Exact paths to list")->capture_default_str()->check(CLI::Range(0, 100000));
  add_report_options(sub, &args->options);
  add_limit_options(sub, &args->limits);
  return {sub, [args] {
            Result<std::string> written = write_folder_report(args->dir, args->options, args->limits);
            if (!written) return report(written.error());
            std::cout << "wrote " << *written << "\n";
            return kExitOk;
          }};
}

}  // namespace pathex::cli
