// converge.json (keys in README "pathex converge"): what `pathex converge` measured, written from the
// ladder's results (measure/ladder.h). JSON at the edge: the only file of converge that includes nlohmann.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "measure/ladder.h"

namespace pathex {

struct ConvergeRun {
  std::string scene;
  bool complete = true;  // false: interrupted, the finished rungs only
  bool by_time = false;  // the ladder's budgets are seconds, not spp
  std::vector<Budget> ladder;
  std::uint64_t seed = 0;
  int threads = 0;  // per rank
  int ranks = 1;
  std::optional<int> max_bounces;
  int width = 0, height = 0;
  bool only = false;                                            // --only: row 0 is the requested paths
  std::vector<std::pair<std::string, std::string>> not_rendered;  // (name, expression) with --only
  std::string reference_kind;  // "closed-form", "file", "run"
  std::string reference_source;
  std::optional<ReferenceRun> reference_run;
  std::string reach_note;  // why what the reference reaches is not known, when it is not
  const std::vector<ClassRow>* rows = nullptr;
  std::vector<std::string> renderers;
  const std::vector<std::vector<RungResult>>* results = nullptr;  // [renderer][rung]
  const std::vector<std::vector<Series>>* series = nullptr;       // [renderer][row]
  const std::vector<std::vector<std::optional<std::string>>>* cannot = nullptr;  // [renderer][row]
  const Rankings* rankings = nullptr;
  const std::vector<std::string>* warnings = nullptr;
  // Inside render() (the ladder and the reference run), and the whole command's wall time and CPU
  // time outside render() (references, statistics, the plot).
  double render_wall_s = 0.0, render_cpu_s = 0.0, wall_s = 0.0, overhead_cpu_s = 0.0;
};

std::string converge_json_text(const ConvergeRun& r);

}  // namespace pathex
