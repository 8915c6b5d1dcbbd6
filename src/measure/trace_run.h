// trace's run, one library call (`pathex trace`, issue 38): loads the render (output/trace_job.h),
// plans it (trace/plan.h: the strategies that can sample a requested path), renders the passes
// still missing, with --missed the reference that measures what the renderer misses (pathex bias),
// and writes the render folder (output/render_job.h) as one set, whole or not at all.
//
// Under MPI (a Cluster installed, output/render_job.h) the ranks deal the passes as they go; each
// keeps its work in its own shard file (rank_shard_path) while every rank's sums are added into
// rank 0's, which alone writes the outputs; the ranks' files go once render.shard holds them.
// Ctrl-C, SIGTERM or the time limit (measure/render_watch.h) stop the render after the chunk in
// progress, and what was rendered is written, marked incomplete.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "bias/bias.h"
#include "core/error.h"
#include "output/render_job.h"
#include "output/trace_job.h"
#include "trace/prune.h"

namespace pathex {

// The default of TraceOptions::max_memory.
inline constexpr std::uint64_t kDefaultTraceMaxMemory = std::uint64_t{4} << 30;

struct TraceOptions {
  TraceJobOptions job;  // what is rendered (output/trace_job.h)
  int threads = 0;      // 0: all cores
  double time_limit = 0;  // seconds; 0: none
  // Refuse a render whose images (and their writing) would take more, estimated before rendering.
  std::uint64_t max_memory = kDefaultTraceMaxMemory;
  bool missed = false;    // also render the reference and measure what the renderer misses
  std::string reference;  // the reference for `missed`; empty: bias's default
  bool progress = true;   // a progress line on a terminal (rank 0)
  // False: nothing is written and the output folder is not touched; `written` holds what
  // histogram.json would (the C++ API's trace without a folder). Refused with --shard, --resume or MPI,
  // whose work lives in files.
  bool write = true;
};

struct TraceResult;

struct TraceHooks {
  // Rank 0, once the plan is made and the output folder checked, before the render: trace's
  // warnings of what the renderer cannot sample. An error stops the run.
  std::function<Result<bool>(const TraceJob& job, const Dfa& universe)> before_render;
  // A line for stderr, without "pathex: " (the non-finite samples' warning; an MPI rank stopped).
  std::function<void(const std::string& line)> notice;
  // Adds files to the output set, staged in `dir`, after trace's own (pathex trace --report);
  // `run`'s job, header, sums and written report are those of the files staged.
  std::function<Result<bool>(const std::string& dir, const TraceResult& run)> extra_files;
};

struct TraceResult {
  TraceJob job;  // the render, loaded; its header's identity lists the strategies run
  Dfa universe;  // the scene's paths (scene/universe.h)
  // The strategies the checker did not run or narrowed, and the lights aimed (trace/prune.h).
  std::vector<PrunedStrategy> changes;
  // Set when no strategy samples a path of the requested classes in the scene: nothing is rendered
  // or written, and `no_path` holds the requested classes' expressions that have no path in it.
  bool nothing_to_render = false;
  std::vector<std::string> no_path;
  bool root = true;  // false on the MPI ranks other than 0: nothing below is set
  ShardHeader header;  // as written: the passes and the run's figures, the resumed ones' added
  std::optional<RenderSums> sums;  // the render's exact sums (the resumed and the other ranks' added)
  double time_s = 0;   // this process's render time
  std::optional<RouletteThresholds> roulette;  // what --rr-threshold and --rr-join-threshold auto took (trace/accel/join_plan.h)
  std::optional<BiasReport> missed;  // with `missed`: what missed.json holds
  std::optional<WrittenReport> written;  // histogram.json as written (or as it would be, without `write`)
};

// Errors (bad options, scene, profile, classes, resumed folder, output folder, memory, a shard file
// not written) are the command's located messages, in the order the command meets them.
Result<TraceResult> run_trace(const TraceOptions& options, const TraceHooks& hooks = {});

}  // namespace pathex
