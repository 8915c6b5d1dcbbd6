// converge's run, one library call (`pathex converge` and api::converge): what accuracy costs in
// time (DESIGN §8, issue 13). Renders a ladder of budgets per renderer, measures each rung's error
// against a reference (a closed form the scene declares, an earlier run's histogram.json or EXR, or
// a long reference run it makes itself), checks with the checker which classes each renderer and
// the reference can sample, and computes per renderer and class the statistics of measure/ladder.h
// and the ranking; with an output folder it writes converge.json, the plot (converge.svg and .png)
// and the reference run's reference.json and reference.exr as one output set.
//
// Rendering goes through the tracer's library entry point, render(), one call per rung: the ladder
// is a plain loop over independent rungs, each a function of its renderer, budget and seed. Under
// MPI (a Cluster installed, output/render_job.h) every rung is split like `pathex trace`: the ranks
// deal the rung's passes as they go (Cluster::deal), the exact sums are added on rank 0
// (Cluster::reduce), which measures the rung from the same sums as one process, so every estimate,
// stderr and error is the same number; its CPU time is the ranks' sum, its wall time rank 0's.
// Rank 0 alone writes. Ctrl-C or SIGTERM (caught while the call runs, measure/render_watch.h)
// stops the rung in progress and keeps the finished ones.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "measure/ladder.h"
#include "trace/joins/manifold.h"

namespace pathex {

struct ConvergeOptions {
  std::string scene;  // the scene file
  std::vector<std::string> renderers;  // profile names or files, at least one
  std::string classes_file;            // empty: the scene's closed-form classes, else the built-ins
  std::string spp_list;                // "4,16,64"; with time_list empty and this empty: 4,16,64,256
  std::string time_list;               // "1,4": seconds per rung instead
  std::string reference;               // an earlier run's histogram.json or an EXR
  std::string reference_renderer;      // empty: bdpt plus the connectors the scene needs
  std::uint64_t reference_factor = 4;  // the reference run's budget over the ladder's largest
  std::uint64_t seed = 1;              // rung i of renderer k uses seed + 1000 k + i
  int threads = 0;                     // 0: all cores
  std::optional<int> max_bounces;      // unset: each profile's own bound, else 16
  std::string resolution;              // "WxH"; empty: the scene's
  std::vector<std::string> only;       // the requested classes, as trace --only
  std::string out;                     // the output folder; empty: nothing is written
  Limits limits;
  // The manifold connector's limits for the ladder's renders (pathex converge --manifold-*, as
  // trace's), so that a variant such as the biased --manifold-biased-trials can be measured against
  // a reference; a reference run keeps the defaults (the unbiased estimator).
  ManifoldOptions manifold;
};

struct ConvergeHooks {
  // Before each rung: "pt-nee at 16 spp", or "reference run: bdpt at 1024 spp"; once more with ""
  // when the ladder ends.
  std::function<void(const std::string& rung, bool reference)> progress;
  // Adds files to the output set, staged in `dir`, after converge's own (pathex converge --report).
  std::function<Result<bool>(const std::string& dir)> extra_files;
};

struct ConvergeResult {
  // Set when no strategy of a renderer samples a path of the requested classes in the scene: the
  // line the command prints; nothing else is set.
  std::string nothing_to_render;
  // Ctrl-C during the reference run: nothing measured, nothing written.
  bool reference_interrupted = false;
  // false on the MPI ranks other than 0, which render their part and hold nothing else.
  bool root = true;
  bool complete = true;  // false: interrupted, the finished rungs only
  std::string reference_kind;    // "closed-form", "file", "run"
  std::string reference_source;  // the formula, the file, or the run that made it
  bool reference_written = false;  // reference.json and reference.exr (a reference run, written)
  std::string reach_note;          // why what the reference reaches is not known, when it is not
  bool only = false;               // --only: row 0 is the requested paths
  std::vector<std::pair<std::string, std::string>> not_rendered;  // (name, expression) with --only
  std::vector<ClassRow> rows;                                     // row 0 the total (or requested)
  std::vector<std::string> renderers;                             // the profiles' names
  std::vector<std::vector<RungResult>> results;                   // [renderer][rung]
  std::vector<std::vector<Series>> series;                        // [renderer][row]
  std::vector<std::vector<std::optional<std::string>>> cannot;    // [renderer][row]
  Rankings rankings;
  std::vector<std::string> warnings;
  std::string json_text;  // converge.json (measure/converge_json.h)
};

// Errors (bad options, scene, profiles, classes, reference, output folder) are the command's
// located messages, in the order the command meets them.
Result<ConvergeResult> converge(const ConvergeOptions& options, const ConvergeHooks& hooks = {});

}  // namespace pathex
