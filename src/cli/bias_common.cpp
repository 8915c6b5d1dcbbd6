#include "cli/bias_common.h"

#include "cli/estimate_text.h"
#include "cli/witness_text.h"
#include "io/input_file.h"
#include "io/histogram_json.h"
#include "io/reach_json.h"

namespace pathex::cli {

Result<std::unique_ptr<RenderClasses>> bias_classes(const std::string& classes_file, const Scene& scene,
                                                    const Limits& limits) {
  RenderIdentity ends;
  const SceneTypes types = scene_types(scene);
  for (LightType l : types.lights) ends.lights.push_back(to_string(l));
  ends.sensor = to_string(types.sensor);
  std::string text;
  if (!classes_file.empty()) {
    Result<std::string> read = read_input_file(classes_file, limits.max_file_bytes);
    if (!read) return read.error();
    text = std::move(*read);
  }
  Result<std::unique_ptr<RenderClasses>> classes = compile_render_classes(text, classes_file, ends, limits);
  if (!classes) return classes.error();
  const auto& user = (*classes)->table.user_classes();
  for (std::size_t i = 0; i < user.size(); ++i)
    if (user[i]->name == kMissedClass) {
      Error e = make_error(ErrorCode::kBadValue, std::string("the class name '") + kMissedClass +
                                                     "' is reserved for what the renderer misses (missed.exr), "
                                                     "expected another name");
      e.where = classes_file + ":/classes/" + std::to_string(i) + "/name";
      return e;
    }
  return classes;
}

Result<BiasRun> measure_missed(const Scene& scene, const std::string& scene_name, const Profile& renderer,
                               const std::string& reference, const std::vector<const PathClass*>& classes,
                               const BiasOptions& options) {
  Result<Profile> ref = choose_reference(reference, scene, renderer, options);
  if (!ref) return ref.error();
  return run_bias(scene, scene_name, renderer, *ref, classes, options);
}

namespace {

nlohmann::ordered_json estimate_json(const Estimate& e) {
  nlohmann::ordered_json j;
  j["estimate"] = {e.rgb[0], e.rgb[1], e.rgb[2]};
  j["luminance"] = e.luminance;
  j["stderr"] = std::isfinite(e.std_error) ? nlohmann::ordered_json(e.std_error) : nlohmann::ordered_json(nullptr);
  j["samples"] = e.samples;
  return j;
}

nlohmann::ordered_json optional_witness(const std::optional<Witness>& w) {
  return w ? nlohmann::ordered_json(to_json(*w)) : nlohmann::ordered_json(nullptr);
}

}  // namespace

nlohmann::ordered_json to_json(const BiasReport& r) {
  using J = nlohmann::ordered_json;
  J j;
  j["scene"] = r.scene;
  j["renderer"] = r.renderer;
  j["renderer_max_bounces"] = r.renderer_bounces ? J(*r.renderer_bounces) : J(nullptr);
  j["reference"] = {{"name", r.reference}, {"strategies", r.reference_strategies}, {"max_bounces", r.reference_bounces},
                    {"spp", r.spp}, {"seed", r.seed}, {"time_s", r.time_s}, {"complete", r.complete}};
  j["nonfinite_samples"] = r.nonfinite_samples;
  j["total"] = estimate_json(r.total);
  J missed = estimate_json(r.missed);
  missed["share"] = r.share;
  missed["share_stderr"] = r.share_std_error;
  missed["exact"] = r.covered;
  missed["shortest"] = optional_witness(r.shortest);
  j["missed"] = missed;
  J classes = J::array();
  for (const MissedClass& c : r.classes) {
    J jc;
    jc["name"] = c.name;
    jc["expr"] = c.expr;
    jc["verdict"] = to_string(c.verdict);
    jc["light"] = estimate_json(c.light);
    jc["missed"] = estimate_json(c.missed);
    jc["missed_share_of_class"] = c.light.luminance > 0 ? c.missed.luminance / c.light.luminance : 0.0;
    jc["missed_share_of_image"] = r.total.luminance > 0 ? c.missed.luminance / r.total.luminance : 0.0;
    jc["witness"] = optional_witness(c.witness);
    jc["neither"] = optional_witness(c.neither);
    classes.push_back(jc);
  }
  j["classes"] = classes;
  J paths = J::array();
  for (const MissedPath& p : r.paths) {
    J jp;
    jp["path"] = p.estimate.path;
    jp["verdict"] = "unreachable";
    jp["share"] = p.share;
    const J e = estimate_json(p.estimate.estimate);
    for (auto it = e.begin(); it != e.end(); ++it) jp[it.key()] = it.value();
    J chains = J::array();
    for (const ChainEvidence& c : p.chains) chains.push_back(J(to_json(c)));
    jp["chains"] = chains;
    jp["reason"] = p.reason;
    paths.push_back(jp);
  }
  j["paths"] = paths;
  j["other_missed_paths"] = r.other_missed_paths;
  J neither = J::array();
  for (const Witness& w : r.neither) neither.push_back(J(to_json(w)));
  if (r.undersampled) {
    const UnderSampling& u = *r.undersampled;
    J flagged = J::array();
    for (const UnderSampled& f : u.flagged)
      flagged.push_back({{f.path ? "path" : "class", f.name}, {"renderer", estimate_json(f.renderer)},
                         {"reference", estimate_json(f.reference)}, {"z", f.z}, {"dof", f.dof}});
    j["undersampled"] = {{"spp", u.spp}, {"seed", u.seed}, {"sigmas", u.sigmas}, {"false_alarm_rate", u.rate},
                         {"dof", u.dof}, {"comparisons", u.comparisons}, {"each", u.each}, {"min_share", u.min_share},
                         {"min_difference", u.min_difference}, {"flagged", flagged}};
  } else {
    j["undersampled"] = nullptr;
  }
  j["not_counted"] = {
      {"neither", {{"witnesses", neither}, {"finite", r.neither_finite},
                   {"note", "paths neither " + r.renderer + " nor " + r.reference +
                                " can sample: their light is not known (it is not 0)"}}},
      {"beyond_bound", "light on paths with more than " + std::to_string(r.reference_bounces) +
                           " interior vertices, which the reference does not render"}};
  return j;
}

std::string missed_line(const BiasReport& r) {
  if (r.covered)
    return r.renderer + " cannot sample 0 % of what " + r.reference + " finds: it samples every path of the scene up to " +
           std::to_string(r.reference_bounces) + " interior vertices (exact, by the checker)";
  return r.renderer + " cannot sample " + percent(r.share) + " ± " + percent(r.share_std_error, 2) + " of what " +
         r.reference + " finds (luminance " + absolute(r.missed) + " of " + absolute(r.total) + ")";
}

std::vector<std::string> undersampled_lines(const BiasReport& r, int top) {
  std::vector<std::string> lines;
  if (!r.undersampled) return lines;
  const UnderSampling& u = *r.undersampled;
  char each[32];
  std::snprintf(each, sizeof each, "%.2g", u.each);
  lines.push_back("under-sampled: light " + r.renderer + " can sample where its estimate at " + std::to_string(u.spp) +
                  " spp and " + r.reference + "'s differ beyond their combined stderr (two-sided p < " + each + ": " +
                  percent(u.rate, 0) + " false alarms over " + std::to_string(u.comparisons) +
                  " comparisons, Šidák; Student's t, Welch's dof) by at least " + percent(u.min_share) +
                  " of the light it can sample:");
  if (u.flagged.empty())
    lines.push_back("  none: its estimates of the image, each class and each listed path it can sample agree with the reference's");
  for (std::size_t i = 0; i < u.flagged.size() && static_cast<int>(i) < top; ++i) {
    const UnderSampled& f = u.flagged[i];
    char z[32];
    std::snprintf(z, sizeof z, "%.1f", f.z);
    lines.push_back("  " + std::string(f.path ? "path " : "") + f.name + ": reachable, under-sampled at " +
                    std::to_string(u.spp) + " spp: estimate " + absolute(f.renderer) + ", reference " +
                    absolute(f.reference) + " (z " + z + ")");
  }
  if (u.flagged.size() > static_cast<std::size_t>(std::max(top, 0)))
    lines.push_back("  … " + std::to_string(u.flagged.size() - static_cast<std::size_t>(top)) + " more (\"undersampled\" in the JSON)");
  return lines;
}

std::string witness_line(const Witness& w) {
  return w.path + ", chains " + chains_text(w.chains) + "; " + w.reason;
}

}  // namespace pathex::cli
