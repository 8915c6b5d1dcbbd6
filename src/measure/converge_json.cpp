#include "measure/converge_json.h"

#include <cmath>

#include <nlohmann/json.hpp>

#include "stats/convergence.h"

namespace pathex {
namespace {

nlohmann::ordered_json number_or_null(double v) { return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr); }

}  // namespace

std::string converge_json_text(const ConvergeRun& r) {
  const std::vector<ClassRow>& rows = *r.rows;
  const std::vector<std::vector<RungResult>>& results = *r.results;
  const std::vector<std::vector<Series>>& series = *r.series;
  const std::vector<std::vector<std::optional<std::string>>>& cannot = *r.cannot;
  nlohmann::ordered_json doc;
  doc["scene"] = r.scene;
  doc["complete"] = r.complete;
  doc["budget"] = r.by_time ? "time" : "spp";
  nlohmann::ordered_json lad = nlohmann::ordered_json::array();
  for (const Budget& b : r.ladder) lad.push_back(b.spp ? nlohmann::ordered_json(b.spp) : nlohmann::ordered_json(b.seconds));
  doc["ladder"] = lad;
  doc["seed"] = r.seed;
  doc["threads"] = r.threads;
  doc["ranks"] = r.ranks;  // MPI ranks, each with `threads`
  doc["max_bounces"] = r.max_bounces ? nlohmann::ordered_json(*r.max_bounces) : nlohmann::ordered_json(nullptr);
  doc["resolution"] = {r.width, r.height};
  if (r.only) {  // --only: what was estimated, and what was not
    nlohmann::ordered_json jo = nlohmann::ordered_json::array(), jn = nlohmann::ordered_json::array();
    for (std::size_t i = 1; i < rows.size(); ++i) jo.push_back({{"name", rows[i].name}, {"expr", rows[i].expr}});
    for (const auto& [name, expr] : r.not_rendered)
      jn.push_back({{"name", name}, {"expr", expr}, {"rendered", false},
                    {"note", "not rendered: only the requested classes were estimated (--only)"}});
    doc["only"] = jo;
    doc["not_rendered"] = jn;
  }
  nlohmann::ordered_json jref = {{"kind", r.reference_kind}, {"source", r.reference_source}};
  if (r.reference_kind == "run" && r.reference_run) {
    const ReferenceRun& run = *r.reference_run;
    jref["run"] = {{"renderer", run.renderer}, {"spp", run.spp}, {"seed", run.seed}, {"cpu_s", run.cpu_s}, {"wall_s", run.wall_s},
                   {"nonfinite_samples", run.nonfinite_samples}};
  }
  nlohmann::ordered_json jrefc = nlohmann::ordered_json::array();
  for (const ClassRow& c : rows)
    jrefc.push_back({{"name", c.name}, {"expr", c.expr}, {"luminance", c.reference ? number_or_null(*c.reference) : nullptr},
                     {"stderr", c.reference_stderr}, {"per_pixel", c.pixels.has_value()},
                     {"measurable", c.unmeasurable.empty()},
                     {"note", c.unmeasurable.empty() ? nlohmann::ordered_json(nullptr)
                                                     : nlohmann::ordered_json("not measurable with this reference: " + c.unmeasurable)}});
  jref["classes"] = jrefc;
  jref["reach_note"] = r.reach_note.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(r.reach_note);
  doc["reference"] = jref;
  doc["stderr_check"] = {{"alpha", kStderrCheckAlpha}, {"unstable_variance", kUnstableVariance}};
  nlohmann::ordered_json jren = nlohmann::ordered_json::array();
  for (std::size_t k = 0; k < r.renderers.size(); ++k) {
    std::uint64_t nonfinite = 0;
    for (const RungResult& rung : results[k]) nonfinite += rung.nonfinite;
    nlohmann::ordered_json jc = nlohmann::ordered_json::array();
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Series& s = series[k][i];
      nlohmann::ordered_json jr = nlohmann::ordered_json::array();
      for (std::size_t j = 0; j < results[k].size(); ++j) {
        const RungResult& rung = results[k][j];
        const ClassMeasure& m = rung.classes[i];
        jr.push_back({{"budget", rung.budget.spp ? nlohmann::ordered_json(rung.budget.spp) : nlohmann::ordered_json(rung.budget.seconds)},
                      {"spp", rung.spp},
                      {"seed", rung.seed},
                      {"cpu_s", rung.cpu_s},
                      {"wall_s", rung.wall_s},
                      {"estimate", m.estimate},
                      {"stderr", number_or_null(m.std_error)},
                      {"error", j < s.error.size() ? number_or_null(s.error[j]) : nullptr},
                      {"z", j < s.z.size() ? number_or_null(s.z[j]) : nullptr},
                      {"rms_pixel_error", m.rms_pixel ? number_or_null(*m.rms_pixel) : nullptr},
                      {"stderr_stability", number_or_null(m.stability)},
                      {"efficiency", j < s.efficiency.size() ? number_or_null(s.efficiency[j]) : nullptr}});
      }
      jc.push_back({{"name", rows[i].name},
                    {"expr", rows[i].expr},
                    {"rungs", jr},
                    {"slope", number_or_null(s.slope)},
                    {"efficiency", number_or_null(s.pooled_efficiency)},
                    {"cannot_sample", cannot[k][i] ? nlohmann::ordered_json(*cannot[k][i]) : nlohmann::ordered_json(nullptr)},
                    {"stderr_check",
                     {{"chi2", number_or_null(s.check.chi2)}, {"dof", s.check.dof}, {"limit", s.check.limit},
                      {"lower_chi2", number_or_null(s.check.lower_chi2)}, {"lower_dof", s.check.lower_dof},
                      {"lower_limit", s.check.lower_limit},
                      {"max_abs_z", number_or_null(s.check.max_abs_z)}, {"stability", number_or_null(s.check.stability)},
                      {"disagrees", s.check.disagrees}, {"too_large", s.check.too_large}, {"unstable", s.check.unstable}}},
                    {"warning", s.warning.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(s.warning)}});
    }
    jren.push_back({{"name", r.renderers[k]}, {"nonfinite_samples", nonfinite}, {"classes", jc}});
  }
  doc["renderers"] = jren;
  nlohmann::ordered_json best = nlohmann::ordered_json::array();
  for (const Ranking& b : r.rankings->best)
    best.push_back({{"class", b.cls}, {"renderer", b.renderer}, {"efficiency", b.efficiency},
                    {"runner_up", b.runner_up.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(b.runner_up)},
                    {"ratio", b.runner_up.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(b.ratio)}});
  doc["best"] = best;
  doc["warnings"] = *r.warnings;
  const double overhead_wall = r.wall_s - r.render_wall_s;
  doc["timing"] = {{"render_wall_s", r.render_wall_s}, {"render_cpu_s", r.render_cpu_s},
                   {"overhead_wall_s", overhead_wall}, {"overhead_cpu_s", r.overhead_cpu_s},
                   {"overhead_pct", r.render_wall_s > 0 ? 100.0 * overhead_wall / r.render_wall_s : 0.0}};
  return doc.dump(2) + "\n";
}

}  // namespace pathex
