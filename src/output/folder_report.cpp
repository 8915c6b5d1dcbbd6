// A render folder into report.html: the folder's files read (output/report_html.h), the checker's
// verdict for each class added when the folder is a trace render (the scene and renderer its
// render.shard names), the page written whole.
#include "output/folder_report.h"

#include <memory>

#include "io/profile_json.h"
#include "output/render_job.h"
#include "reach/query.h"
#include "scene/scene.h"
#include "scene/universe.h"

namespace pathex {
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
  Result<Profile> profile = resolve_profile(id.renderer_source, limits);
  if (!profile) return;
  Result<CompiledProfile> compiled = compile_profile(*profile, id.max_bounces, limits);
  if (!compiled) return;
  QueryOptions qo;
  qo.universe = scene_universe(scene_types(*scene));
  qo.max_bounces = id.max_bounces;
  qo.witnesses = 0;
  qo.max_len = 0;
  for (const PathClass* c : (*classes)->classes) {
    Result<QueryResult> q = query(*c, *compiled, qo);
    if (q) d->verdicts[c->name] = to_string(q->verdict);
  }
  d->verdict_renderer = id.renderer;
}

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

}  // namespace pathex
