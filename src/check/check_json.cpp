// The check's JSON report (check/check_json.h): the JSON at the edge, built from the outcomes that
// check_file decides; the chains' and the missed light's JSON are io/reach_json's and
// output/bias_json's.
#include "check/check_json.h"

#include <nlohmann/json.hpp>

#include "io/reach_json.h"
#include "output/bias_json.h"

namespace pathex {

std::string check_json(const std::string& file, const std::vector<Outcome>& outcomes) {
  int failed = 0;
  nlohmann::json jcases = nlohmann::json::array();
  for (const Outcome& o : outcomes) {
    failed += o.passed ? 0 : 1;
    nlohmann::json jr = {{"case", o.c->name}, {"renderer", o.c->renderer}, {"requirement", o.r->describe()},
                         {"passed", o.passed}, {"verdict", o.verdict}};
    jr["scene"] = o.c->scene.empty() ? nlohmann::json(nullptr) : nlohmann::json(o.c->scene);
    jr["max_bounces"] = o.c->max_bounces ? nlohmann::json(*o.c->max_bounces) : nlohmann::json(nullptr);
    if (o.counterexample) {
      nlohmann::json chains = nlohmann::json::array();
      for (const ChainEvidence& c : o.counterexample->chains) chains.push_back(to_json(c));
      jr["counterexample"] = {{"path", o.counterexample->path}, {"chains", chains}};
      if (o.counterexample->reason.empty()) jr["counterexample"]["strategies"] = o.counterexample->strategies;
      else jr["counterexample"]["reason"] = o.counterexample->reason;
    }
    if (o.missed && o.missed->undersampled) {
      jr["undersampled"] = nlohmann::json::parse(to_json(*o.missed)["undersampled"].dump());
    } else if (o.missed) {
      const BiasReport& b = *o.missed;
      jr["missed"] = {{"share", b.share}, {"stderr", b.share_std_error}, {"max_share", o.r->missed->max_share},
                      {"reference", b.reference}, {"spp", b.spp}, {"luminance", b.missed.luminance},
                      {"total", b.total.luminance}};
      if (!b.paths.empty())
        jr["missed"]["largest_path"] = {{"path", b.paths.front().estimate.path}, {"share", b.paths.front().share},
                                        {"reason", b.paths.front().reason}};
    }
    jcases.push_back(jr);
  }
  const int passed = static_cast<int>(outcomes.size()) - failed;
  return nlohmann::json{{"file", file}, {"passed", passed}, {"failed", failed}, {"requirements", jcases}}.dump(2);
}

}  // namespace pathex
