#include "output/render_job.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <future>
#include <optional>

#include <nlohmann/json.hpp>
#include <tbb/task_group.h>

#include "automata/ops.h"
#include "core/version.h"
#include "io/atomic_file.h"
#include "io/class_file.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/input_file.h"

namespace pathex {

Result<std::unique_ptr<RenderClasses>> compile_render_classes(const std::string& text, const std::string& filename,
                                                              const RenderIdentity& identity, const Limits& limits) {
  ClassOptions copts;
  copts.limits = limits;
  for (const std::string& l : identity.lights) {
    const std::optional<LightType> t = light_type_from_string(l);
    if (!t) return make_error(ErrorCode::kBadValue, "unknown light type \"" + l + "\"");
    copts.ends.lights.push_back(*t);
  }
  const std::optional<SensorType> sensor = sensor_type_from_string(identity.sensor);
  if (!sensor) return make_error(ErrorCode::kBadValue, "unknown sensor type \"" + identity.sensor + "\"");
  copts.ends.sensors = {*sensor};
  auto out = std::make_unique<RenderClasses>();
  if (!filename.empty()) {
    Result<bool> r = load_class_file(text, filename, copts, &out->table);
    if (!r) return r.error();
    for (const auto& c : out->table.user_classes()) out->classes.push_back(c.get());
  } else {
    for (const auto& c : ClassTable::builtins().builtin_classes())
      if (c->name != "all") out->classes.push_back(c.get());
  }
  // --- the requested classes: "render": true entries, then --only (DESIGN §11) ---
  for (const PathClass* c : out->classes)
    if (c->render) out->requested.push_back(c);
  for (std::size_t i = 0; i < identity.only.size(); ++i) {
    const std::string& expr = identity.only[i];
    const PathClass* same = nullptr;
    for (const PathClass* c : out->classes)
      if (!expr.empty() && expr[0] == '$' && c->name == expr.substr(1)) same = c;
    if (same == nullptr) {
      Result<const PathClass*> added = out->table.add("only-" + std::to_string(i + 1), expr, copts);
      if (!added) {
        Error e = added.error();
        e.message = "--only '" + expr + "': " + e.message;
        return e;
      }
      same = *added;
      out->classes.push_back(same);
    }
    if (std::find(out->requested.begin(), out->requested.end(), same) == out->requested.end()) out->requested.push_back(same);
  }
  out->estimated.assign(out->classes.size(), 1);
  if (!out->requested.empty()) {
    Dfa r = dfa_empty();
    for (const PathClass* c : out->requested) r = dfa_union(r, c->dfa);
    const Dfa paths = dfa_intersect(ends_universe(copts.ends), dfa_universe_bounded(identity.max_bounces));
    for (std::size_t i = 0; i < out->classes.size(); ++i)
      out->estimated[i] = is_subset(dfa_intersect(out->classes[i]->dfa, paths), r) ? 1 : 0;
    out->requested_language = std::move(r);
  }
  Result<Classifier> classifier = Classifier::build(out->classes, limits);
  if (!classifier) return classifier.error();
  out->classifier = std::make_unique<Classifier>(std::move(*classifier));
  for (const PathClass* c : out->classes) out->infos.push_back({c->name, c->text});
  return out;
}

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

RenderSums empty_sums(const RenderIdentity& identity, const RenderClasses& classes) {
  HistogramLayout layout;
  layout.num_batches = identity.batches;
  layout.groups = identity.batches / identity.replicates;
  layout.strategies = identity.strategies;
  std::vector<int> layers;
  if (identity.images)
    for (int i = 0; i < classes.classifier->num_classes(); ++i) layers.push_back(i);
  std::vector<ConnectorStats> connectors;
  for (const ConnectorStrategy& c : identity.connectors) connectors.push_back({c.strategy, c.connector});
  return {Histogram(layout, classes.classifier.get()),
          identity.images ? ClassImages(identity.width, identity.height, classes.classifier.get(), layers)
                          : ClassImages(0, 0, nullptr, {}),
          std::move(connectors)};
}

// run.json's "efficiency": Veach's efficiency of the image-mean estimate, 1 / (relative variance ×
// CPU seconds of rendering), `per_cpu_s`, with the relative variance (the total's squared
// standard error over its squared luminance). It does not depend on the spp (the variance falls
// as the time grows), so two settings compare without a reference. Null when the total has no
// finite relative error (a black image, fewer than two batches of passes) or no CPU time.
static nlohmann::ordered_json efficiency_json(const Estimate& total, double cpu_s) {
  const double rel = total.luminance > 0.0 ? total.std_error / total.luminance : 0.0;
  const double rel_var = rel * rel;
  nlohmann::ordered_json e;
  const bool defined = std::isfinite(rel_var) && rel_var > 0.0 && cpu_s > 0.0;
  e["relative_variance"] = defined ? nlohmann::ordered_json(rel_var) : nlohmann::ordered_json(nullptr);
  e["per_cpu_s"] = defined ? nlohmann::ordered_json(1.0 / (rel_var * cpu_s)) : nlohmann::ordered_json(nullptr);
  return e;
}

Result<WrittenReport> render_report(const ShardHeader& header, const RenderSums& sums, const RenderClasses& classes) {
  const RenderIdentity& id = header.identity;
  const std::vector<ConnectorStats>& connectors = sums.connectors;
  RunInfo info;
  info.scene = id.scene;
  info.renderer = id.renderer;
  info.spp = header.passes.count();
  info.seed = id.seed;
  info.complete = header.passes == header.share;
  info.spp_requested = header.spp;
  Result<HistogramReport> rep = make_report(sums.histogram, info, classes.classifier.get(), classes.infos, id.max_paths);
  if (!rep) return rep.error();

  WrittenReport out{std::move(*rep), {}};
  for (std::size_t i = 0; i < out.report.classes.size() && i < classes.estimated.size(); ++i)
    out.report.classes[i].rendered = classes.estimated[i] != 0;
  nlohmann::ordered_json doc = to_json(out.report);
  if (!classes.requested.empty()) {  // pathex trace --only, "render": the classes whose paths were estimated
    nlohmann::ordered_json only = nlohmann::ordered_json::array();
    for (const PathClass* c : classes.requested) only.push_back({{"name", c->name}, {"expr", c->text}});
    doc["only"] = std::move(only);
  }
  if (!connectors.empty()) {
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const ConnectorStats& c : connectors) {
      nlohmann::ordered_json entry = {{"strategy", c.strategy},
                                      {"connector", c.connector},
                                      {"attempts", c.attempts},
                                      {"successes", c.successes},
                                      {"failures", {{"outside", c.outside}, {"occluded", c.occluded}, {"no_transport", c.no_transport}}}};
      if (c.connector == "manifold") {  // the Newton walk's own reasons (trace/joins/manifold.h)
        nlohmann::ordered_json& f = entry["failures"];
        f.erase("outside");
        f["no_solution"] = c.no_solution;
        f["singular"] = c.singular;
        f["wrong_type"] = c.wrong_type;
        f["too_short"] = c.too_short;
        f["iteration_limit"] = c.iteration_limit;
        entry["repeats"] = c.repeats;
        entry["truncated"] = c.truncated;
        entry["walks"] = c.walks;
        entry["mean_iterations"] = c.walks > 0 ? nlohmann::ordered_json(static_cast<double>(c.iterations) / static_cast<double>(c.walks))
                                               : nlohmann::ordered_json(nullptr);
      }
      list.push_back(std::move(entry));
    }
    doc["connectors"] = std::move(list);
  }
  out.json_text = doc.dump(2) + "\n";
  return out;
}

namespace {

// histogram.json and run.json (which reads the report's total).
Result<WrittenReport> write_histogram_and_run_json(const std::string& dir, const ShardHeader& header, const RenderSums& sums,
                                                   const RenderClasses& classes, const std::vector<PrunedStrategy>& not_run) {
  Result<WrittenReport> made = render_report(header, sums, classes);
  if (!made) return made.error();
  WrittenReport& out = *made;
  if (Result<bool> w = write_file_atomic(dir + "/histogram.json", out.json_text); !w) return w.error();
  nlohmann::ordered_json run = nlohmann::ordered_json::object();
  run["time_s"] = header.run.time_s;
  run["threads"] = header.run.threads;
  run["rays"] = header.run.rays;
  run["passes"] = header.passes.to_string();
  run["cpu_s"] = header.run.cpu_s;
  run["efficiency"] = efficiency_json(out.report.total, header.run.cpu_s);
  if (!not_run.empty()) {  // what this run did not simulate (a merge does not know: it has no scene)
    nlohmann::ordered_json list = nlohmann::ordered_json::array();
    for (const PrunedStrategy& p : not_run) {
      nlohmann::ordered_json e = {{"strategy", p.strategy}, {"profile", p.was}};
      e["runs"] = p.now.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(p.now);
      e["reason"] = p.reason;
      list.push_back(std::move(e));
    }
    run["pruned"] = std::move(list);
  }
  if (Result<bool> w = write_file_atomic(dir + "/run.json", run.dump(2) + "\n"); !w) return w.error();
  return made;
}

// The layers of the rendered classes (and the total), a band of rows at a time from the exact sums.
class RenderBands final : public LayerBands {
 public:
  RenderBands(const ClassImages& images, const RenderClasses& classes, double scale) : images_(images), scale_(scale) {
    for (int l = 0; l < images.num_layers(); ++l) {
      // A class that was not rendered has no image (its layer holds at most the requested part of it).
      bool rendered = true;
      for (std::size_t i = 0; i < classes.classes.size(); ++i)
        if (classes.classes[i]->name == images.layer_name(l)) rendered = classes.estimated[i] != 0;
      if (rendered) layers_.push_back(l);
    }
  }
  int width() const override { return images_.width(); }
  int height() const override { return images_.height(); }
  std::size_t num_layers() const override { return layers_.size(); }
  const std::string& name(std::size_t layer) const override { return images_.layer_name(layers_[layer]); }
  void fill(std::size_t layer, int y0, int rows, float* out) const override { images_.layer_rows(layers_[layer], scale_, y0, rows, out); }
  bool same_pixels(std::size_t a, std::size_t b) const override { return images_.same_sums(layers_[a], layers_[b]); }

 private:
  const ClassImages& images_;
  double scale_;
  std::vector<int> layers_;
};

// classes.exr and the PNG previews.
Result<bool> write_images(const std::string& dir, const ShardHeader& header, const RenderSums& sums, const RenderClasses& classes) {
  const std::uint64_t spp = header.passes.count();
  const RenderBands bands(sums.images, classes, spp ? 1.0 / static_cast<double>(spp) : 0.0);
  return write_image_files(bands, ImageFiles{dir + "/classes.exr", {}, dir});
}

}  // namespace

Result<WrittenReport> write_render_outputs(const std::string& dir, const ShardHeader& header, const RenderSums& sums,
                                           const RenderClasses& classes, const std::vector<PrunedStrategy>& not_run) {
  // The files are independent and read the sums only: the shard file (the largest), the report
  // and the images are made and written as concurrent tasks, so the wall time is the longest of
  // them rather than their sum. The bytes do not depend on it; the first failure in the order
  // report, images, shard is the one returned.
  std::optional<Result<bool>> shard, images;
  tbb::task_group group;
  group.run([&] { shard.emplace(write_shard(dir + "/" + kRenderShardName, header, sums)); });
  if (header.identity.images) group.run([&] { images.emplace(write_images(dir, header, sums, classes)); });
  Result<WrittenReport> report = write_histogram_and_run_json(dir, header, sums, classes, not_run);
  group.wait();
  if (!report) return report.error();
  if (images && !*images) return images->error();
  if (!*shard) return shard->error();
  return report;
}

std::string ranks_folder(const std::string& dir) {
  std::string d = dir;
  while (d.size() > 1 && d.back() == '/') d.pop_back();
  return d + ".ranks";
}

Result<std::vector<std::string>> render_folder_shards(const std::string& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  bool any_folder = false;
  for (const std::string& d : {dir, ranks_folder(dir)}) {
    if (!std::filesystem::is_directory(d, ec)) continue;
    any_folder = true;
    std::vector<std::string> here;
    for (const auto& entry : std::filesystem::directory_iterator(d, ec))
      if (entry.path().extension() == kShardExtension) here.push_back(entry.path().string());
    if (ec) {
      Error e = make_error(ErrorCode::kBadFile, "cannot list the folder: " + ec.message());
      e.where = d;
      return e;
    }
    std::sort(here.begin(), here.end());
    names.insert(names.end(), here.begin(), here.end());
  }
  if (names.empty()) {
    Error e = make_error(ErrorCode::kBadFile, any_folder ? std::string("no shard file (*") + kShardExtension +
                                                               ") in the folder: is it a pathex trace output folder?"
                                                         : std::string("not a render folder (no such directory)"));
    e.where = dir;
    return e;
  }
  return names;
}

Result<CombinedRender> combine_shards(const std::vector<std::string>& paths, const Limits& limits) {
  std::optional<CombinedRender> out;
  std::vector<std::pair<std::string, PassSet>> seen;  // each file's passes, for naming an overlap
  // The next file is read and checked (its CRC-32 over every byte) on another thread while this
  // one is added. Each read goes into the bytes of the file added before the one in hand, whose
  // pages are mapped already (a merge of 16 files of 11 MB spent 0.45 s of CPU faulting in fresh
  // ones). Errors are still reported in the order of the files.
  std::string spare;
  const auto read_ahead = [&](std::size_t i) {
    return std::async(std::launch::async, [path = paths[i], buffer = std::move(spare)]() mutable {
      return read_shard(path, std::move(buffer));
    });
  };
  std::future<Result<ShardFile>> next;
  if (!paths.empty()) next = read_ahead(0);
  for (std::size_t i = 0; i < paths.size(); ++i) {
    const std::string& path = paths[i];
    Result<ShardFile> file = next.get();
    if (i + 1 < paths.size()) next = read_ahead(i + 1);
    if (!file) return file.error();
    const ShardHeader& h = file->header;
    if (h.identity.pathex != pathex_version())
      return make_error(ErrorCode::kUsage, path + " was rendered by another pathex version (" + h.identity.pathex + " against " +
                                               pathex_version() + ")");
    if (!out) {
      // The first file fixes the render: its classes are compiled and its layout laid out.
      Result<std::unique_ptr<RenderClasses>> classes =
          compile_render_classes(h.identity.classes_text, h.identity.classes_file, h.identity, limits);
      if (!classes) {
        Error e = classes.error();
        e.message = "the class file recorded in " + path + " does not compile: " + e.message;
        return e;
      }
      RenderSums sums = empty_sums(h.identity, **classes);
      ShardHeader header;
      header.identity = h.identity;
      out.emplace(CombinedRender{std::move(header), std::move(*classes), std::move(sums)});
    } else {
      if (std::optional<std::string> d = identity_difference(h.identity, out->header.identity))
        return make_error(ErrorCode::kUsage, path + " and " + seen.front().first + " are not of one render: " + *d);
      for (const auto& [other, passes] : seen)
        if (const PassSet both = passes.intersect(h.passes); !both.empty())
          return make_error(ErrorCode::kUsage, "passes " + both.to_string() + " are in both " + other + " and " + path +
                                                   ": the renders to merge must hold disjoint passes");
    }
    const std::size_t files_left = paths.size() - seen.size();  // this one included
    if (Result<bool> r = add_shard_sums(*file, &out->sums, files_left); !r) return r.error();
    ShardHeader& header = out->header;
    header.spp = std::max(header.spp, h.spp);
    header.share.add(h.share);
    header.passes.add(h.passes);
    header.run.time_s += h.run.time_s;
    header.run.threads = std::max(header.run.threads, h.run.threads);
    header.run.rays += h.run.rays;
    header.run.cpu_s += h.run.cpu_s;
    seen.emplace_back(path, h.passes);
    spare = std::move(file->bytes);
  }
  if (!out) return make_error(ErrorCode::kUsage, "no shard files to combine");
  return std::move(*out);
}

}  // namespace pathex

namespace pathex {
namespace {
Cluster* g_cluster = nullptr;
}  // namespace

Cluster* current_cluster() { return g_cluster; }
void set_cluster(Cluster* cluster) { g_cluster = cluster; }

}  // namespace pathex
