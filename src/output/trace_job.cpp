// The render `pathex trace` runs, loaded (output/trace_job.h).
#include "output/trace_job.h"

#include <algorithm>
#include <filesystem>

#include "core/hash.h"
#include "core/version.h"
#include "io/input_file.h"
#include "io/profile_json.h"
#include "scene/resolution.h"
#include "scene/scene_hash.h"

namespace pathex {
namespace {

std::string profile_hash(const Profile& p) {
  Fnv64 h;
  h.add(p.name);
  for (const Strategy& st : p.strategies) h.add(st.name + " " + st.describe());
  h.add(p.max_bounces.value_or(-1));
  return h.hex();
}

std::string classes_hash(const std::string& text, const RenderClasses& classes) {
  Fnv64 h;
  h.add(text);
  for (const ClassInfo& c : classes.infos) h.add(c.name + "=" + c.expr);
  return h.hex();
}

Result<bool> load_fresh(const TraceJobOptions& a, TraceJob* job) {
  // The command line checks these ranges as it parses (cli/trace.cpp); the library's other callers
  // (the C++ API) meet them here.
  if (a.spp < 1 || a.spp > kMaxTraceSpp)
    return make_error(ErrorCode::kUsage, "spp must be 1 to " + std::to_string(kMaxTraceSpp) + ", not " + std::to_string(a.spp));
  if (a.max_bounces && (*a.max_bounces < 0 || *a.max_bounces > kMaxTraceBounces))
    return make_error(ErrorCode::kUsage, "max bounces must be 0 to " + std::to_string(kMaxTraceBounces) + ", not " +
                                             std::to_string(*a.max_bounces));
  Result<Scene> scene = a.scene.empty() ? load_scene_json(default_scene_json(), ".", "default (embedded cornell)")
                                        : load_scene_file(a.scene, scene_load_options(a.limits));
  if (!scene) return scene.error();
  // The content hash is the file's; the resolution is an option of the render, kept beside it.
  const std::string scene_hash = scene_content_hash(*scene);
  if (!a.resolution.empty())
    if (Result<bool> r = apply_resolution(a.resolution, &scene->camera); !r) return r.error();
  Result<Profile> profile = resolve_profile(a.renderer, a.limits);
  if (!profile) return profile.error();
  Result<StrategySet> runnable = runnable_strategies(*profile);
  if (!runnable) return runnable.error();

  RenderIdentity& id = job->header.identity;
  id.pathex = pathex_version();
  id.scene = a.scene.empty() ? "default (embedded cornell)" : a.scene;
  id.scene_file = a.scene.empty() ? "" : std::filesystem::absolute(a.scene).lexically_normal().string();
  id.scene_hash = scene_hash;
  id.renderer = profile->name;
  const bool builtin = std::any_of(builtin_profile_texts().begin(), builtin_profile_texts().end(),
                                   [&](const BuiltinProfileText& t) { return a.renderer == t.name; });
  id.renderer_source = builtin ? a.renderer : std::filesystem::absolute(a.renderer).lexically_normal().string();
  id.renderer_hash = profile_hash(*profile);
  const SceneTypes types = scene_types(*scene);
  for (LightType l : types.lights) id.lights.push_back(to_string(l));
  id.sensor = to_string(types.sensor);
  id.seed = a.seed;
  // One bound for the render and for the checker's verdicts: --max-bounces, else the profile's, else 16.
  id.max_bounces = a.max_bounces.value_or(profile->max_bounces.value_or(16));
  id.sampler = to_string(a.sampler);
  id.light_sampling = to_string(a.light_sampling);
  id.rr_depth = a.rr_depth;
  id.rr_threshold = a.rr_threshold;
  id.rr_light_threshold = a.rr_light_threshold;
  id.rr_join_threshold = a.rr_join_threshold;
  id.splits = resolved_splits(*profile, a.splits);  // recorded resolved, as the manifold's limits below
  id.batches = a.batches;
  // Resolved here, from the resolution the render will have, so that every shard records the same R.
  id.replicates = a.replicates != 0 ? a.replicates
                                    : default_replicates(a.batches, static_cast<std::uint64_t>(scene->camera.width) *
                                                                        static_cast<std::uint64_t>(scene->camera.height));
  if (id.replicates < 1 || a.batches % id.replicates != 0)
    return make_error(ErrorCode::kUsage, "--replicates " + std::to_string(id.replicates) + " must divide --batches " +
                                             std::to_string(a.batches) + " (the batches are pixel groups of that many replicates)");
  id.images = !a.no_images;
  id.width = scene->camera.width;
  id.height = scene->camera.height;
  id.max_paths = a.max_paths;
  // The manifold's limits are part of the render only where its connector runs.
  if (std::any_of(profile->strategies.begin(), profile->strategies.end(),
                  [](const Strategy& st) { return st.connector == ConnectorKind::kManifold; }))
    id.manifold = resolved_manifold(*profile, a.manifold);  // recorded resolved: shards and merge agree
  for (const Strategy& st : runnable->strategies) id.strategies.push_back(st.name);

  std::string class_text;
  if (!a.classes_file.empty()) {
    Result<std::string> text = read_input_file(a.classes_file, a.limits.max_file_bytes);
    if (!text) return text.error();
    class_text = std::move(*text);
    id.classes_file = std::filesystem::absolute(a.classes_file).lexically_normal().string();
  }
  id.only = a.only;
  Result<std::unique_ptr<RenderClasses>> classes =
      compile_render_classes(class_text, a.classes_file.empty() ? "" : a.classes_file, id, a.limits);
  if (!classes) return classes.error();
  id.classes_text = class_text;
  id.classes_hash = classes_hash(class_text, **classes);

  job->header.spp = a.spp;
  job->header.share = PassSet::range(0, a.spp);
  if (!a.shard.empty()) {
    Result<std::pair<std::uint64_t, std::uint64_t>> shard = parse_shard_option(a.shard);
    if (!shard) return shard.error();
    job->header.share = job->header.share.part(shard->first, shard->second);
  }
  job->scene = std::move(*scene);
  job->profile = std::move(*profile);
  job->classes = std::move(*classes);
  job->out = a.out;
  return true;
}

// --resume DIR: the render's settings come from DIR's shard files; the scene and the profile are
// loaded again from where the render found them and must not have changed.
Result<bool> load_resumed(const TraceJobOptions& a, TraceJob* job) {
  if (!a.settings_given.empty())
    return make_error(ErrorCode::kUsage, "--resume takes the render's settings from " + a.resume + "; " +
                                             a.settings_given.front() + " cannot be given with it");
  Result<std::vector<std::string>> files = render_folder_shards(a.resume);
  if (!files) return files.error();
  Result<CombinedRender> combined = combine_shards(*files, a.limits);
  if (!combined) return combined.error();
  const RenderIdentity& id = combined->header.identity;
  Result<Scene> scene = id.scene_file.empty()
                            ? load_scene_json(default_scene_json(), ".", id.scene)
                            : load_scene_file(id.scene_file, scene_load_options(a.limits));
  if (!scene) return scene.error();
  if (scene_content_hash(*scene) != id.scene_hash)
    return make_error(ErrorCode::kUsage, "the scene " + id.scene + " changed since " + a.resume + " was rendered (content hash " +
                                             scene_content_hash(*scene) + ", the render's " + id.scene_hash + ")");
  // The render's resolution (the scene's, or --resolution's).
  scene->camera.width = id.width;
  scene->camera.height = id.height;
  Result<Profile> profile = resolve_profile(id.renderer_source, a.limits);
  if (!profile) return profile.error();
  if (profile_hash(*profile) != id.renderer_hash)
    return make_error(ErrorCode::kUsage, "the renderer profile " + id.renderer_source + " changed since " + a.resume +
                                             " was rendered");
  job->header.identity = id;
  job->header.spp = combined->header.spp;
  job->header.share = combined->header.share;
  job->header.passes = combined->header.passes;
  job->scene = std::move(*scene);
  job->profile = std::move(*profile);
  job->classes = std::move(combined->classes);
  job->resumed = std::move(*combined);
  job->out = a.resume;
  return true;
}

}  // namespace

Result<TraceJob> load_trace_job(const TraceJobOptions& options) {
  TraceJob job;
  if (Result<bool> r = options.resume.empty() ? load_fresh(options, &job) : load_resumed(options, &job); !r) return r.error();
  return job;
}

Result<bool> settle_strategies(const Profile& planned, TraceJob* job) {
  std::vector<std::string> runs;
  std::vector<ConnectorStrategy> connectors;
  for (const Strategy& st : planned.strategies) {
    runs.push_back(st.name);
    if (st.connector != ConnectorKind::kNone) connectors.push_back({st.name, to_string(st.connector)});
  }
  RenderIdentity& id = job->header.identity;
  if (!job->resumed) {  // the histogram and the connector statistics are laid out for these
    id.strategies = std::move(runs);
    id.connectors = std::move(connectors);
  } else if (runs != id.strategies || connectors != id.connectors) {
    return make_error(ErrorCode::kUsage, "the strategies " + job->out + " was rendered with are not the ones this pathex runs for it");
  }
  return true;
}

Result<std::pair<std::uint64_t, std::uint64_t>> parse_shard_option(const std::string& text) {
  const auto bad = [&] {
    return make_error(ErrorCode::kUsage, "--shard " + text + ": expected i/n, shard i of n with 0 <= i < n (e.g. 0/4)");
  };
  const std::size_t slash = text.find('/');
  if (slash == std::string::npos) return bad();
  std::uint64_t i = 0, n = 0;
  try {
    std::size_t used_i = 0, used_n = 0;
    if (text.empty() || text[0] == '-' || text[slash + 1] == '-') return bad();
    i = std::stoull(text.substr(0, slash), &used_i);
    n = std::stoull(text.substr(slash + 1), &used_n);
    if (used_i != slash || used_n != text.size() - slash - 1) return bad();
  } catch (const std::exception&) {
    return bad();
  }
  if (n == 0 || i >= n) return bad();
  return std::make_pair(i, n);
}

std::string rank_shard_path(const std::string& dir, int rank) {
  return ranks_folder(dir) + "/rank-" + std::to_string(rank) + kShardExtension;
}

}  // namespace pathex
