#include "output/bias_json.h"

#include <cmath>

#include "io/reach_json.h"

namespace pathex {

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

std::string bias_json_text(const BiasReport& r) { return to_json(r).dump(2) + "\n"; }

}  // namespace pathex
