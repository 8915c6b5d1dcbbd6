// The render `pathex trace` runs, loaded (issue 38): what it renders (the scene, the profile, the
// classes), its identity (the settings and the hashes that make two shard files the same render's),
// the passes it is asked for (--shard), and, for --resume, what an earlier interrupted run of it
// already holds. The command (cli/trace.cpp) parses the options into TraceJobOptions, renders the
// passes still missing and prints.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "core/limits.h"
#include "output/render_job.h"
#include "output/shard.h"
#include "scene/scene.h"
#include "trace/render.h"

namespace pathex {

// The largest --spp and --max-bounces of a render (the command line's ranges).
inline constexpr std::uint64_t kMaxTraceSpp = std::uint64_t{1} << 24;
inline constexpr int kMaxTraceBounces = 1000;

struct TraceJobOptions {
  std::string scene;  // the scene file; empty: the embedded Cornell box
  std::string renderer = "bdpt";  // a built-in profile's name or a profile file
  std::string classes_file;       // empty: the built-in classes
  std::vector<std::string> only;  // the requested classes (DESIGN §11)
  std::string out = "pathex-out";
  std::uint64_t spp = 16;
  std::uint64_t seed = 1;
  std::optional<int> max_bounces;  // unset: the profile's bound, else 16
  SamplerKind sampler = RenderOptions{}.sampler;  // the defaults of these: RenderOptions'
  LightSampling light_sampling = RenderOptions{}.light_sampling;
  int rr_depth = RenderOptions{}.rr_depth;
  float rr_threshold = RenderOptions{}.rr_threshold;
  float rr_light_threshold = RenderOptions{}.rr_light_threshold;
  float rr_join_threshold = RenderOptions{}.rr_join_threshold;
  std::optional<int> splits;  // runs per camera ray (--splits; 0: auto); unset: the profile's (resolved_splits())
  int batches = RenderOptions{}.batches;  // the standard error's batches and replicates per pixel
  int replicates = RenderOptions{}.replicates;  // 0: default_replicates(batches, the sensor's pixels)
  ManifoldOptions manifold = RenderOptions{}.manifold;
  std::string resolution;  // "WxH"; empty: the scene's
  std::uint64_t max_paths = 1000;  // rows of histogram.json's path table
  bool no_images = false;          // the histogram alone
  std::string shard;               // "i/n"; empty: every pass
  std::string resume;              // an interrupted render's folder: the settings are its
  // The render settings the command line named (as "--spp"), refused with `resume`.
  std::vector<std::string> settings_given;
  Limits limits;
};

// The render to run: what it renders and the passes it is asked for, with what an earlier,
// interrupted run of it already holds (--resume).
struct TraceJob {
  std::optional<Scene> scene;  // at the render's resolution
  std::optional<Profile> profile;
  std::unique_ptr<RenderClasses> classes;
  ShardHeader header;  // identity, spp, share; passes: those already held
  std::optional<CombinedRender> resumed;
  std::string out;  // the output folder (the resumed one's)
};

// A fresh job loads the scene, the profile and the classes from the options; with `resume` the
// settings come from the folder's shard files, and the scene and the profile are loaded again from
// where the render found them and must not have changed (kUsage otherwise, as for settings given
// with it). Errors are the command's located messages, in the order it meets them.
Result<TraceJob> load_trace_job(const TraceJobOptions& options);

// The strategies `planned` (the plan's profile, trace/plan.h) runs: a fresh job's histogram and
// connector statistics are laid out for them; a resumed one must have been rendered with the same.
Result<bool> settle_strategies(const Profile& planned, TraceJob* job);

// "i/n" with 0 <= i < n (--shard).
Result<std::pair<std::uint64_t, std::uint64_t>> parse_shard_option(const std::string& text);

// Where MPI rank `rank` of a render into `dir` keeps its own shard file (in ranks_folder(dir)).
std::string rank_shard_path(const std::string& dir, int rank);

}  // namespace pathex
