// report.html (see report_html.h): reading a render folder, then writing the page. The reading
// goes through the one JSON reader (parse_json, JsonReader), the histogram's own parser, the EXR
// reader and the PNG encoder; the page is plain HTML with a short script for the hover.
#include "output/report_html.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "io/atomic_file.h"
#include "io/estimate_text.h"
#include "io/histogram_json.h"
#include "io/image_io.h"
#include "io/input_file.h"
#include "io/json_reader.h"
#include "io/junit.h"
#include "io/output_set.h"
#include "io/profile_json.h"
#include "output/shard.h"

namespace pathex {
namespace fs = std::filesystem;

std::string base64(std::string_view bytes) {
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const auto b0 = static_cast<unsigned char>(bytes[i]), b1 = static_cast<unsigned char>(bytes[i + 1]),
               b2 = static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[b0 >> 2];
    out += kAlphabet[((b0 & 3) << 4) | (b1 >> 4)];
    out += kAlphabet[((b1 & 15) << 2) | (b2 >> 6)];
    out += kAlphabet[b2 & 63];
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    const auto b0 = static_cast<unsigned char>(bytes[i]);
    const auto b1 = rest == 2 ? static_cast<unsigned char>(bytes[i + 1]) : 0;
    out += kAlphabet[b0 >> 2];
    out += kAlphabet[((b0 & 3) << 4) | (b1 >> 4)];
    out += rest == 2 ? kAlphabet[(b1 & 15) << 2] : '=';
    out += '=';
  }
  return out;
}

namespace {

using json = nlohmann::json;

Error folder_error(const std::string& where, std::string message) {
  Error e = make_error(ErrorCode::kBadFile, std::move(message));
  e.where = where;
  return e;
}

std::string join_path(const std::string& dir, const std::string& name) { return (fs::path(dir) / name).string(); }

bool exists_file(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

// --- small readers over an already parsed document (JsonReader names the pointer) ---

std::optional<double> optional_number(const json& j, const char* key) {
  if (!j.is_object() || !j.contains(key) || !j[key].is_number()) return std::nullopt;
  return j[key].get<double>();
}

// Each of `keys` of `j` is absent, null (unknown) or a number: anything else is refused, naming it.
Result<bool> numbers_or_null(const JsonReader& r, const json& j, const std::string& ptr, std::initializer_list<const char*> keys) {
  for (const char* key : keys)
    if (j.is_object() && j.contains(key) && !j[key].is_null() && !j[key].is_number())
      return r.fail(ptr + "/" + key, "found " + JsonReader::kind(j[key]) + ", expected a number or null");
  return true;
}

Result<std::string> optional_string(const JsonReader& r, const json& j, const char* key, const std::string& ptr) {
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return std::string();
  return r.string(j, key, ptr);
}

Result<const json*> array_of(const JsonReader& r, const json& j, const char* key, const std::string& ptr) {
  static const json empty = json::array();
  if (!j.is_object() || !j.contains(key) || j[key].is_null()) return &empty;
  if (!j[key].is_array()) return r.fail(ptr + "/" + key, "found " + JsonReader::kind(j[key]) + ", expected an array");
  return &j[key];
}

Result<json> read_json_file(const std::string& path, const ReportOptions& o) {
  Result<std::string> text = read_input_file(path, o.max_file_bytes);
  if (!text) return text.error();
  return parse_json(*text, path);
}

// --- run.json ---

Result<bool> read_run(const std::string& path, const ReportOptions& o, ReportData* d) {
  Result<json> doc = read_json_file(path, o);
  if (!doc) return doc.error();
  const JsonReader r(path);
  if (!doc->is_object()) return r.fail("", "found " + JsonReader::kind(*doc) + ", expected an object");
  if (Result<bool> ok = numbers_or_null(r, *doc, "", {"time_s", "cpu_s", "threads"}); !ok) return ok;
  d->time_s = optional_number(*doc, "time_s");
  d->cpu_s = optional_number(*doc, "cpu_s");
  if (const auto t = optional_number(*doc, "threads")) d->threads = static_cast<int>(*t);
  Result<const json*> pruned = array_of(r, *doc, "pruned", "");
  if (!pruned) return pruned.error();
  for (std::size_t i = 0; i < (*pruned)->size(); ++i) {
    const json& p = (**pruned)[i];
    const std::string ptr = "/pruned/" + std::to_string(i);
    ReportData::Pruned q;
    Result<std::string> strategy = r.string(p, "strategy", ptr);
    if (!strategy) return strategy.error();
    Result<std::string> profile = optional_string(r, p, "profile", ptr);
    if (!profile) return profile.error();
    Result<std::string> runs = optional_string(r, p, "runs", ptr);
    if (!runs) return runs.error();
    Result<std::string> reason = optional_string(r, p, "reason", ptr);
    if (!reason) return reason.error();
    d->pruned.push_back({*strategy, *profile, *runs, *reason});
  }
  return true;
}

// --- bias.json / missed.json ---

Result<bool> read_missed(const std::string& path, const ReportOptions& o, ReportData* d) {
  Result<json> doc = read_json_file(path, o);
  if (!doc) return doc.error();
  const JsonReader r(path);
  const json& j = *doc;
  ReportData::Missed m;
  m.file = fs::path(path).filename().string();
  Result<std::string> renderer = r.string(j, "renderer", "");
  if (!renderer) return renderer.error();
  m.renderer = *renderer;
  if (j.contains("reference") && j["reference"].is_object()) {
    Result<std::string> ref = r.string(j["reference"], "name", "/reference");
    if (!ref) return ref.error();
    m.reference = *ref;
  }
  if (!j.contains("missed") || !j["missed"].is_object()) return r.fail("/missed", "missing missed, expected an object");
  const json& jm = j["missed"];
  Result<double> lum = r.number(jm, "luminance", "/missed", -1e300, 1e300);
  if (!lum) return lum.error();
  Result<double> share = r.number(jm, "share", "/missed", -1e300, 1e300);
  if (!share) return share.error();
  m.luminance = *lum;
  m.share = *share;
  if (Result<bool> ok = numbers_or_null(r, jm, "/missed", {"share_stderr"}); !ok) return ok;
  m.share_stderr = optional_number(jm, "share_stderr").value_or(0.0);
  m.exact = jm.contains("exact") && jm["exact"].is_boolean() && jm["exact"].get<bool>();
  Result<const json*> classes = array_of(r, j, "classes", "");
  if (!classes) return classes.error();
  for (std::size_t i = 0; i < (*classes)->size(); ++i) {
    const json& c = (**classes)[i];
    const std::string ptr = "/classes/" + std::to_string(i);
    ReportData::MissedClass mc;
    Result<std::string> name = r.string(c, "name", ptr);
    if (!name) return name.error();
    Result<std::string> verdict = r.string(c, "verdict", ptr);
    if (!verdict) return verdict.error();
    mc.name = *name;
    mc.verdict = *verdict;
    if (Result<bool> ok = numbers_or_null(r, c, ptr, {"missed_share_of_class", "missed_share_of_image"}); !ok) return ok;
    if (c.contains("missed") && c["missed"].is_object()) mc.missed = optional_number(c["missed"], "luminance").value_or(0.0);
    mc.share_of_class = optional_number(c, "missed_share_of_class").value_or(0.0);
    mc.share_of_image = optional_number(c, "missed_share_of_image").value_or(0.0);
    if (c.contains("witness") && c["witness"].is_object()) {
      Result<std::string> w = optional_string(r, c["witness"], "path", ptr + "/witness");
      if (!w) return w.error();
      Result<std::string> why = optional_string(r, c["witness"], "reason", ptr + "/witness");
      if (!why) return why.error();
      mc.witness = *w;
      mc.reason = *why;
    }
    d->verdicts[mc.name] = mc.verdict;
    m.classes.push_back(std::move(mc));
  }
  d->verdict_renderer = m.renderer;
  Result<const json*> paths = array_of(r, j, "paths", "");
  if (!paths) return paths.error();
  for (std::size_t i = 0; i < (*paths)->size(); ++i) {
    const json& p = (**paths)[i];
    const std::string ptr = "/paths/" + std::to_string(i);
    Result<std::string> path_text = r.string(p, "path", ptr);
    if (!path_text) return path_text.error();
    Result<std::string> reason = optional_string(r, p, "reason", ptr);
    if (!reason) return reason.error();
    if (Result<bool> ok = numbers_or_null(r, p, ptr, {"share", "luminance"}); !ok) return ok;
    m.paths.push_back({*path_text, optional_number(p, "share").value_or(0.0), optional_number(p, "luminance").value_or(0.0), *reason});
  }
  d->missed = std::move(m);
  return true;
}

// --- converge.json ---

Result<bool> read_converge(const std::string& dir, const ReportOptions& o, ReportData* d) {
  const std::string path = join_path(dir, "converge.json");
  Result<json> doc = read_json_file(path, o);
  if (!doc) return doc.error();
  const JsonReader r(path);
  const json& j = *doc;
  const bool by_time = j.contains("budget") && j["budget"] == "time";
  ReportData::Converge c;
  Result<const json*> renderers = array_of(r, j, "renderers", "");
  if (!renderers) return renderers.error();
  for (std::size_t k = 0; k < (*renderers)->size(); ++k) {
    const json& jr = (**renderers)[k];
    const std::string rptr = "/renderers/" + std::to_string(k);
    Result<std::string> name = r.string(jr, "name", rptr);
    if (!name) return name.error();
    Result<const json*> classes = array_of(r, jr, "classes", rptr);
    if (!classes) return classes.error();
    for (std::size_t i = 0; i < (*classes)->size(); ++i) {
      const json& jc = (**classes)[i];
      const std::string cptr = rptr + "/classes/" + std::to_string(i);
      Result<std::string> cname = r.string(jc, "name", cptr);
      if (!cname) return cname.error();
      if (Result<bool> ok = numbers_or_null(r, jc, cptr, {"slope", "efficiency"}); !ok) return ok;
      ReportData::ConvergeRow row{*name, *cname, {}, optional_number(jc, "slope"), optional_number(jc, "efficiency"), {}};
      Result<std::string> warning = optional_string(r, jc, "warning", cptr);
      if (!warning) return warning.error();
      row.warning = *warning;
      Result<const json*> rungs = array_of(r, jc, "rungs", cptr);
      if (!rungs) return rungs.error();
      for (std::size_t g_i = 0; g_i < (*rungs)->size(); ++g_i) {
        const json& g = (**rungs)[g_i];
        if (Result<bool> ok = numbers_or_null(r, g, cptr + "/rungs/" + std::to_string(g_i), {"budget", "spp", "cpu_s", "estimate", "stderr", "error"}); !ok)
          return ok;
        ReportData::Rung rung;
        const double spp = optional_number(g, "spp").value_or(0.0);
        std::ostringstream budget;
        if (by_time) budget << optional_number(g, "budget").value_or(0.0) << " s (" << spp << " spp)";
        else budget << spp << " spp";
        rung.budget = budget.str();
        rung.cpu_s = optional_number(g, "cpu_s").value_or(0.0);
        rung.estimate = optional_number(g, "estimate").value_or(0.0);
        rung.std_error = optional_number(g, "stderr");
        rung.error = optional_number(g, "error");
        row.rungs.push_back(rung);
      }
      c.rows.push_back(std::move(row));
    }
  }
  Result<const json*> best = array_of(r, j, "best", "");
  if (!best) return best.error();
  for (const json& b : **best) {
    // converge.json's "best" entries: {class, renderer, ...}; shown as "class: renderer".
    if (b.is_object() && b.contains("class") && b.contains("renderer") && b["class"].is_string() && b["renderer"].is_string())
      c.best.push_back(b["class"].get<std::string>() + ": " + b["renderer"].get<std::string>());
  }
  if (const std::string png = join_path(dir, "converge.png"); exists_file(png)) {
    Result<std::string> bytes = read_input_file(png, o.max_file_bytes);
    if (!bytes) return bytes.error();
    c.png = std::move(*bytes);
  }
  d->converge = std::move(c);
  if (d->command.empty()) {  // converge's own command line, from what converge.json records
    std::string cmd = "pathex converge";
    if (j.contains("scene") && j["scene"].is_string()) cmd += " " + j["scene"].get<std::string>();
    for (const json& jr : **renderers)
      if (jr.contains("name") && jr["name"].is_string()) cmd += " --renderer " + jr["name"].get<std::string>();
    if (j.contains("ladder") && j["ladder"].is_array()) {
      std::string ladder;
      for (const json& l : j["ladder"]) ladder += (ladder.empty() ? "" : ",") + l.dump();
      cmd += (by_time ? " --time " : " --spp ") + ladder;
    }
    if (j.contains("seed") && j["seed"].is_number_unsigned()) cmd += " --seed " + j["seed"].dump();
    if (j.contains("max_bounces") && j["max_bounces"].is_number()) cmd += " --max-bounces " + j["max_bounces"].dump();
    if (j.contains("resolution") && j["resolution"].is_array() && j["resolution"].size() == 2)
      cmd += " --resolution " + j["resolution"][0].dump() + "x" + j["resolution"][1].dump();
    d->command = cmd;
  }
  return true;
}

// --- histogram.json (with its connectors and --only, which HistogramReport does not keep) ---

Result<bool> read_histogram(const std::string& path, const ReportOptions& o, ReportData* d) {
  Result<std::string> text = read_input_file(path, o.max_file_bytes);
  if (!text) return text.error();
  Result<nlohmann::ordered_json> doc = parse_ordered_json(*text, path);
  if (!doc) return doc.error();
  Result<HistogramFile> h = histogram_from_json(*doc, path);
  if (!h) return h.error();
  d->histogram = std::move(h->report);
  const JsonReader r(path);
  if (doc->contains("connectors") && (*doc)["connectors"].is_array()) {
    const json conn = json::parse((*doc)["connectors"].dump());  // the reader's document type
    for (std::size_t i = 0; i < conn.size(); ++i) {
      const json& c = conn[i];
      const std::string ptr = "/connectors/" + std::to_string(i);
      ReportData::Connector rc;
      Result<std::string> strategy = r.string(c, "strategy", ptr);
      if (!strategy) return strategy.error();
      Result<std::string> connector = r.string(c, "connector", ptr);
      if (!connector) return connector.error();
      Result<std::uint64_t> attempts = r.unsigned_integer(c, "attempts", ptr, UINT64_MAX);
      if (!attempts) return attempts.error();
      Result<std::uint64_t> successes = r.unsigned_integer(c, "successes", ptr, UINT64_MAX);
      if (!successes) return successes.error();
      rc.strategy = *strategy;
      rc.connector = *connector;
      rc.attempts = *attempts;
      rc.successes = *successes;
      if (c.contains("failures") && c["failures"].is_object())
        for (auto it = c["failures"].begin(); it != c["failures"].end(); ++it)
          if (it.value().is_number_unsigned()) rc.failures[it.key()] = it.value().get<std::uint64_t>();
      d->connectors.push_back(std::move(rc));
    }
  }
  if (doc->contains("only") && (*doc)["only"].is_array())
    for (const auto& e : (*doc)["only"])
      if (e.is_object() && e.contains("name") && e["name"].is_string() && e.contains("expr") && e["expr"].is_string())
        d->only.emplace_back(e["name"].get<std::string>(), e["expr"].get<std::string>());
  return true;
}

// --- the command that reproduces a trace folder (render.shard's header) ---

std::string shell_word(const std::string& s) {
  const bool plain = !s.empty() && std::all_of(s.begin(), s.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("-_./,:+=@%").find(c) != std::string_view::npos;
  });
  if (plain) return s;
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

std::string trace_command(const RenderIdentity& id, std::uint64_t spp) {
  std::string cmd = "pathex trace";
  if (!id.scene_file.empty()) cmd += " " + shell_word(id.scene);
  cmd += " --renderer " + shell_word(id.renderer_source) + " --spp " + std::to_string(spp) + " --seed " + std::to_string(id.seed);
  if (!id.classes_file.empty()) cmd += " --classes " + shell_word(id.classes_file);
  for (const std::string& e : id.only) cmd += " --only " + shell_word(e);
  cmd += " --max-bounces " + std::to_string(id.max_bounces) + " --sampler " + id.sampler + " --batches " +
         std::to_string(id.batches) + " --replicates " + std::to_string(id.replicates) + " --resolution " + std::to_string(id.width) + "x" + std::to_string(id.height);
  const RenderIdentity defaults;
  if (id.light_sampling != defaults.light_sampling) cmd += " --light-sampling " + id.light_sampling;
  if (id.rr_depth != defaults.rr_depth) cmd += " --rr-depth " + std::to_string(id.rr_depth);
  if (id.rr_threshold != defaults.rr_threshold) cmd += " --rr-threshold " + nlohmann::json(id.rr_threshold).dump();
  if (id.rr_light_threshold != defaults.rr_light_threshold)
    cmd += " --rr-light-threshold " + nlohmann::json(id.rr_light_threshold).dump();
  if (id.rr_join_threshold != defaults.rr_join_threshold)
    cmd += " --rr-join-threshold " + nlohmann::json(id.rr_join_threshold).dump();
  // Always: its default depends on the profile (resolved_splits()), and the header records it resolved.
  cmd += " --splits " + (id.splits == 0 ? std::string("auto") : std::to_string(id.splits));
  if (id.max_paths != defaults.max_paths) cmd += " --max-paths " + std::to_string(id.max_paths);
  if (!id.images) cmd += " --no-images";
  return cmd;
}

// --- images ---

// The luminance of `image` on a grid of cells `factor` pixels on a side (box mean of the pixels in it).
std::vector<float> downsample_luminance(const RgbImage& image, int factor, int gw, int gh) {
  std::vector<double> sum(static_cast<std::size_t>(gw) * static_cast<std::size_t>(gh), 0.0);
  std::vector<int> count(sum.size(), 0);
  for (int y = 0; y < image.height; ++y)
    for (int x = 0; x < image.width; ++x) {
      const std::size_t cell = static_cast<std::size_t>(y / factor) * static_cast<std::size_t>(gw) + static_cast<std::size_t>(x / factor);
      sum[cell] += luminance({image.at(x, y, 0), image.at(x, y, 1), image.at(x, y, 2)});
      ++count[cell];
    }
  std::vector<float> out(sum.size());
  for (std::size_t i = 0; i < sum.size(); ++i) out[i] = count[i] > 0 ? static_cast<float>(sum[i] / count[i]) : 0.0f;
  return out;
}

Result<bool> read_images(const std::string& dir, const std::string& exr_name, const ReportOptions& o, ReportData* d) {
  std::vector<ImageLayer> layers;
  if (const std::string exr = join_path(dir, exr_name); exists_file(exr)) {
    Result<std::vector<ImageLayer>> read = read_exr_layers(exr);
    if (!read) return read.error();
    layers = std::move(*read);
  }
  if (const std::string missed = join_path(dir, "missed.exr"); exists_file(missed)) {
    Result<std::vector<ImageLayer>> read = read_exr_layers(missed);
    if (!read) return read.error();
    for (ImageLayer& l : *read) layers.push_back(std::move(l));
  }
  if (layers.empty()) return true;
  // The order of the page: the total, the classes as histogram.json lists them, then the rest.
  const auto rank = [&](const ImageLayer& l) -> std::size_t {
    if (l.name == "total") return 0;
    if (d->histogram)
      for (std::size_t i = 0; i < d->histogram->classes.size(); ++i)
        if (d->histogram->classes[i].name == l.name) return 1 + i;
    return SIZE_MAX;
  };
  std::stable_sort(layers.begin(), layers.end(), [&](const ImageLayer& a, const ImageLayer& b) { return rank(a) < rank(b); });
  const auto total = std::find_if(layers.begin(), layers.end(), [](const ImageLayer& l) { return l.name == "total"; });
  const RgbImage& reference = total != layers.end() ? total->image : layers.front().image;
  d->exposure = preview_exposure(reference);
  d->width = reference.width;
  d->height = reference.height;
  const int side = std::max(d->width, d->height);
  d->hover_factor = std::max(1, (side + o.hover_max - 1) / o.hover_max);
  d->hover_width = (d->width + d->hover_factor - 1) / d->hover_factor;
  d->hover_height = (d->height + d->hover_factor - 1) / d->hover_factor;
  for (const ImageLayer& l : layers) {
    if (l.image.width != d->width || l.image.height != d->height) continue;
    // The folder's preview when it has one (the same bytes pathex wrote), else one made here.
    const std::string png_file = join_path(dir, l.name + ".png");
    if (exists_file(png_file)) {
      Result<std::string> bytes = read_input_file(png_file, o.max_file_bytes);
      if (!bytes) return bytes.error();
      d->png[l.name] = std::move(*bytes);
    } else {
      Result<std::string> png = encode_png(l.image.width, l.image.height, tonemap_srgb8(l.image, *d->exposure));
      if (!png) return png.error();
      d->png[l.name] = std::move(*png);
    }
    d->hover.emplace_back(l.name, downsample_luminance(l.image, d->hover_factor, d->hover_width, d->hover_height));
  }
  return true;
}

}  // namespace

std::vector<ReportData::Connector> report_connectors(const std::vector<ConnectorStats>& stats) {
  std::vector<ReportData::Connector> out;
  for (const ConnectorStats& c : stats) {
    ReportData::Connector r{c.strategy, c.connector, c.attempts, c.successes, {}};
    r.failures = {{"occluded", c.occluded}, {"no_transport", c.no_transport}};
    if (c.connector == "manifold")  // render_job's histogram.json keys: the Newton walk's reasons
      r.failures.insert({{"no_solution", c.no_solution}, {"singular", c.singular}, {"wrong_type", c.wrong_type},
                         {"too_short", c.too_short}, {"iteration_limit", c.iteration_limit}});
    else
      r.failures["outside"] = c.outside;
    out.push_back(std::move(r));
  }
  return out;
}

Result<ReportData> load_report_folder(const std::string& dir, const ReportOptions& o, const KnownRender* known) {
  ReportData d;
  d.folder = known != nullptr && !known->folder.empty() ? known->folder : dir;
  std::error_code ec;
  const fs::file_status st = fs::status(dir, ec);
  if (!fs::exists(st)) return folder_error(dir, "no such folder; expected the output folder of pathex trace, bias or converge");
  if (!fs::is_directory(st)) return folder_error(dir, "is not a folder; expected the output folder of pathex trace, bias or converge");

  const std::string histogram = join_path(dir, "histogram.json");
  const bool converge = exists_file(join_path(dir, "converge.json"));
  d.kind = exists_file(join_path(dir, "bias.json")) ? "bias" : converge ? "converge" : "trace";
  std::string exr = "classes.exr";
  if (exists_file(histogram)) {
    d.histogram_file = "histogram.json";
  } else if (converge && exists_file(join_path(dir, "reference.json"))) {
    d.histogram_file = "reference.json";  // converge's reference run
    exr = "reference.exr";
  } else if (!converge) {
    return folder_error(histogram, "no such file; expected the histogram.json that pathex trace or pathex bias writes into its output folder");
  }
  if (known != nullptr && known->histogram != nullptr) {
    d.histogram = *known->histogram;
    d.connectors = known->connectors;
    d.only = known->only;
  } else if (!d.histogram_file.empty()) {
    if (Result<bool> r = read_histogram(join_path(dir, d.histogram_file), o, &d); !r) return r.error();
  }
  if (const std::string run = join_path(dir, "run.json"); exists_file(run))
    if (Result<bool> r = read_run(run, o, &d); !r) return r.error();
  if (known != nullptr && known->identity != nullptr) {
    d.command = trace_command(*known->identity, known->spp);
    d.identity = *known->identity;
  } else if (const std::string shard = join_path(dir, "render.shard"); exists_file(shard)) {
    Result<ShardFile> file = read_shard(shard);
    if (!file) return file.error();
    d.command = trace_command(file->header.identity, file->header.spp);
    d.identity = file->header.identity;
  }
  for (const char* name : {"bias.json", "missed.json"})
    if (const std::string m = join_path(dir, name); exists_file(m)) {
      if (Result<bool> r = read_missed(m, o, &d); !r) return r.error();
      break;
    }
  if (d.kind == "bias" && d.missed && d.histogram) {
    // bias's own command line, from what bias.json and histogram.json record
    // The reference by name when it is a built-in profile; otherwise it was bias's default (made
    // for the scene, named after its strategies, chosen again the same way) or a file bias.json does
    // not name.
    const bool builtin = std::any_of(builtin_profile_texts().begin(), builtin_profile_texts().end(),
                                     [&](const BuiltinProfileText& t) { return d.missed->reference == t.name; });
    d.command = "pathex bias " + shell_word(d.histogram->run.scene) + " --renderer " + shell_word(d.missed->renderer) +
                (builtin ? " --reference " + shell_word(d.missed->reference) : "") + " --spp " +
                std::to_string(d.histogram->run.spp) + " --seed " + std::to_string(d.histogram->run.seed);
  }
  if (converge)
    if (Result<bool> r = read_converge(dir, o, &d); !r) return r.error();
  if (Result<bool> r = read_images(dir, exr, o, &d); !r) return r.error();
  if (d.kind == "bias" && d.width > 0) d.command += " --resolution " + std::to_string(d.width) + "x" + std::to_string(d.height);
  return d;
}

// --- the page ---

namespace {

// Text and attribute values, escaped by the one XML escape (io/junit.h; HTML5 knows &apos; too).
std::string esc(std::string_view s) { return xml_escape(std::string(s)); }

// The exact value for data-* attributes: histogram.json's own text of the double.
std::string exact(double x) { return std::isfinite(x) ? nlohmann::json(x).dump() : "null"; }

std::string fixed(double x, const char* format) {
  if (!std::isfinite(x)) return "—";
  char buf[64];
  std::snprintf(buf, sizeof buf, format, x);
  return buf;
}
std::string pct(double share, int decimals = 1) {
  if (!std::isfinite(share)) return "—";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f %%", decimals, 100.0 * share);
  return buf;
}
// data-stderr-stability="…" (histogram.json's stderr_stability), or nothing where it is unknown.
std::string stability_attr(const Estimate& e) {
  return std::isfinite(e.stability) ? " data-stderr-stability=\"" + exact(e.stability) + "\"" : "";
}
std::string lum(const Estimate& e) {
  std::string s = fixed(e.luminance, "%.5g");
  if (std::isfinite(e.std_error)) s += " ± " + fixed(e.std_error, "%.2g");
  return s;
}

// The `most` techniques carrying the largest shares, as text: "bdpt (1, DD, 1) 46.7 %, …, and N more".
std::string top_strategies(const std::vector<TechniqueEstimate>& ts, std::size_t most) {
  std::vector<const TechniqueEstimate*> order;
  for (const TechniqueEstimate& t : ts) order.push_back(&t);
  std::stable_sort(order.begin(), order.end(), [](const TechniqueEstimate* a, const TechniqueEstimate* b) { return a->share > b->share; });
  std::string out;
  for (std::size_t i = 0; i < order.size() && i < most; ++i)
    out += (i ? ", " : "") + order[i]->name + " " + pct(order[i]->share);
  if (order.size() > most) out += ", and " + std::to_string(order.size() - most) + " more";
  return out.empty() ? "—" : out;
}

std::string img(const ReportData& d, const std::string& layer, const std::string& alt, const std::string& css = "px") {
  const auto it = d.png.find(layer);
  if (it == d.png.end()) return "<p class=\"noimg\">no image (" + esc(layer) + ")</p>";
  return "<img class=\"" + css + "\" data-layer=\"" + esc(layer) + "\" width=\"" + std::to_string(d.width) + "\" height=\"" +
         std::to_string(d.height) + "\" alt=\"" + esc(alt) + "\" src=\"data:image/png;base64," + base64(it->second) + "\">";
}

constexpr const char* kStyle = R"css(
body{font-family:system-ui,sans-serif;margin:1.5em;max-width:1200px;color:#222;background:#fff}
h1{font-size:1.4em}h2{font-size:1.15em;margin-top:1.6em;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;padding:.2em .5em;text-align:left;vertical-align:top}
td.n,th.n{text-align:right;font-variant-numeric:tabular-nums;white-space:nowrap}
.top{display:flex;flex-wrap:wrap;gap:1.5em;align-items:flex-start}figure{margin:0}
code,.mono{font-family:ui-monospace,monospace}
img.px{width:256px;height:auto;image-rendering:pixelated;background:#000;display:block}
.render img.px{width:384px}.render figcaption{max-width:384px;font-size:.85em}
.tiles{display:flex;flex-wrap:wrap;gap:12px}
.tile{border:1px solid #ccc;padding:8px;width:258px;font-size:.9em}
.tile h3{margin:.1em 0 .3em;font-size:1em}
.tile dl{margin:.3em 0}.tile dt{font-weight:600;display:inline}.tile dd{display:inline;margin:0 0 0 .3em}
.tile dd:after{content:"";display:block}
.overlay{position:relative;width:384px}.overlay img.px{width:384px}
.overlay img.top{position:absolute;left:0;top:0;mix-blend-mode:screen}
#hover{position:fixed;right:1em;top:1em;background:#fffe;border:1px solid #888;padding:.4em .6em;font-size:.85em;min-width:14em}
.verdict-reachable{color:#060}.verdict-unreachable{color:#a00}.verdict-partial{color:#a60}.unstable{color:#a00}
pre.cmd{background:#f4f4f4;padding:.5em;white-space:pre-wrap;word-break:break-all}
)css";

// Reads the embedded per-class luminances and shows, for the pixel under the pointer on any
// tile, each class's value and share of that pixel's total. Marks <body data-hover="ready"> once read.
constexpr const char* kScript = R"js(
(function(){
  var el=document.getElementById('hover-data');if(!el)return;
  var meta=JSON.parse(el.textContent),layers={};
  meta.layers.forEach(function(l){
    var bin=atob(l.data),bytes=new Uint8Array(bin.length);
    for(var i=0;i<bin.length;i++)bytes[i]=bin.charCodeAt(i);
    layers[l.name]=new Float32Array(bytes.buffer);
  });
  var box=document.getElementById('hover');
  function h(s){return s.replace(/[&<>"']/g,function(c){return '&#'+c.charCodeAt(0)+';';});}
  function fmt(v){return v===0?'0':Math.abs(v)>=1e-3?v.toPrecision(4):v.toExponential(3);}
  function show(ev){
    var img=ev.currentTarget,r=img.getBoundingClientRect();
    pixel(Math.floor((ev.clientX-r.left)/r.width*meta.width),Math.floor((ev.clientY-r.top)/r.height*meta.height));
  }
  function pixel(px,py){
    px=Math.min(Math.max(px,0),meta.width-1);py=Math.min(Math.max(py,0),meta.height-1);
    var c=Math.floor(py/meta.factor)*meta.grid[0]+Math.floor(px/meta.factor);
    var total=layers.total?layers.total[c]:0,rows='';
    meta.layers.forEach(function(l){
      var v=layers[l.name][c];
      rows+='<tr data-layer="'+h(l.name)+'"><td>'+h(l.name)+'</td><td class="n">'+fmt(v)+'</td><td class="n">'+(total>0?(100*v/total).toFixed(1)+' %':'')+'</td></tr>';
    });
    box.innerHTML='<b>pixel ('+px+', '+py+')</b>'+(meta.factor>1?' (cell of '+meta.factor+'×'+meta.factor+')':'')+
      '<table><tr><th>layer</th><th>luminance</th><th>of total</th></tr>'+rows+'</table>';
  }
  Array.prototype.forEach.call(document.querySelectorAll('img[data-layer]'),function(img){
    img.addEventListener('mousemove',show);
  });
  box.textContent='hover a pixel of any image: its luminance per class';
  var m=/^#pixel=(\d+),(\d+)$/.exec(location.hash);  // a link to a pixel: report.html#pixel=X,Y
  if(m)pixel(+m[1],+m[2]);
  document.body.setAttribute('data-hover','ready');
  document.body.setAttribute('data-hover-layers',String(meta.layers.length));
})();
)js";

void render_section(std::ostringstream& h, const ReportData& d) {
  const HistogramReport& rep = *d.histogram;
  h << "<section id=\"render\" class=\"render\"><h2>The render</h2>\n<div class=\"top\">\n";
  if (d.png.count("total")) {
    h << "<figure>" << img(d, "total", "the rendered image, tone-mapped");
    h << "<figcaption>tone-mapped: linear values × " << fixed(*d.exposure, "%.4g")
      << " (the 99th percentile of the total's luminance maps to 1), sRGB, clamped; the linear data is in "
      << (d.histogram_file == "reference.json" ? "reference.exr" : "classes.exr") << "</figcaption></figure>\n";
  } else {
    h << "<p>no images in this folder (rendered with --no-images)</p>\n";
  }
  h << "<table id=\"run\"><tbody>\n";
  const auto row = [&](const std::string& key, const std::string& value, const std::string& attr = "") {
    h << "<tr><th>" << key << "</th><td" << attr << ">" << value << "</td></tr>\n";
  };
  row("scene", esc(rep.run.scene));
  row("renderer", esc(rep.run.renderer));
  row("samples per pixel", std::to_string(rep.run.spp) + (rep.run.complete ? "" : " of " + std::to_string(rep.run.spp_requested) + " (interrupted)"),
      " data-spp=\"" + std::to_string(rep.run.spp) + "\"");
  row("seed", std::to_string(rep.run.seed));
  if (d.width > 0) row("resolution", std::to_string(d.width) + " × " + std::to_string(d.height));
  if (d.time_s) {
    std::string t = fixed(*d.time_s, "%.3f") + " s";
    if (d.cpu_s) t += " (" + fixed(*d.cpu_s, "%.3f") + " CPU s";
    if (d.threads) t += std::string(d.cpu_s ? ", " : " (") + std::to_string(*d.threads) + " threads";
    if (d.cpu_s || d.threads) t += ")";
    row("render time", t);
  }
  row("non-finite samples", std::to_string(rep.nonfinite_samples) + (rep.nonfinite_samples ? " (any is a bug)" : ""),
      " data-nonfinite=\"" + std::to_string(rep.nonfinite_samples) + "\"");
  row(d.only.empty() ? "image mean luminance" : "luminance of the requested paths",
      esc(lum(rep.total)) + (stderr_unstable(rep.total) ? " <span class=\"unstable\">its stderr is unstable (" + esc(unstable_reason(rep.total)) + ")</span>" : ""),
      " data-luminance=\"" + exact(rep.total.luminance) + "\" data-stderr=\"" + exact(rep.total.std_error) + "\"" +
          stability_attr(rep.total));
  row("distinct paths", std::to_string(rep.distinct_paths));
  h << "</tbody></table>\n</div>\n";
  if (!d.command.empty())
    h << "<p>The command that reproduces it:</p><pre class=\"cmd\" id=\"command\">" << esc(d.command) << "</pre>\n";
  h << "</section>\n";
}

void class_tiles(std::ostringstream& h, const ReportData& d) {
  const HistogramReport& rep = *d.histogram;
  h << "<section id=\"classes\"><h2>Where the light goes: one tile per class</h2>\n"
    << "<p>Share of the " << (d.only.empty() ? "image" : "requested paths'") << " luminance ± its standard error, the absolute luminance "
    << "(comparable between renderers), the checker's verdict"
    << (d.verdict_renderer.empty() ? "" : " for " + esc(d.verdict_renderer)) << " and the strategies that carry the class. "
    << "The images share the render's exposure.</p>\n<div class=\"tiles\">\n";
  for (const ClassEstimate& c : rep.classes) {
    h << "<div class=\"tile\" data-class=\"" << esc(c.name) << "\" data-rendered=\"" << (c.rendered ? "true" : "false") << "\"";
    if (c.rendered)
      h << " data-share=\"" << exact(c.share) << "\" data-luminance=\"" << exact(c.estimate.luminance) << "\" data-stderr=\""
        << exact(c.estimate.std_error) << "\"" << stability_attr(c.estimate);
    h << ">\n<h3>" << esc(c.name) << " <code>" << esc(c.expr) << "</code></h3>\n";
    if (!c.rendered) {
      h << "<p>not rendered: only the requested classes were estimated (--only)</p></div>\n";
      continue;
    }
    h << img(d, c.name, "class " + c.name + " (" + c.expr + "): its part of the image");
    const double err = rep.total.luminance > 0 ? c.estimate.std_error / rep.total.luminance : NAN;
    const auto v = d.verdicts.find(c.name);
    h << "<dl><dt>share</dt><dd>" << pct(c.share) << " ± " << pct(err, 2) << "</dd>"
      << "<dt>luminance</dt><dd>" << esc(lum(c.estimate)) << "</dd>"
      << (stderr_unstable(c.estimate) ? "<dt>stderr</dt><dd class=\"unstable\">unstable: " + esc(unstable_reason(c.estimate)) + "</dd>" : "")
      << "<dt>verdict</dt><dd class=\"verdict-" << (v != d.verdicts.end() ? esc(v->second) : "unknown") << "\">"
      << (v != d.verdicts.end() ? esc(v->second)
          : d.verdicts.empty()   ? "not known (the scene could not be read)"
                                 : "— (not a class the checker was asked about)")
      << "</dd>"
      << "<dt>strategies</dt><dd>" << esc(top_strategies(c.strategies, 3)) << "</dd></dl>\n</div>\n";
  }
  h << "</div>\n</section>\n";
}

void paths_table(std::ostringstream& h, const ReportData& d, const ReportOptions& o) {
  const HistogramReport& rep = *d.histogram;
  h << "<section id=\"paths\"><h2>The most important exact paths</h2>\n"
    << "<table id=\"paths-table\"><thead><tr><th>path</th><th class=\"n\">share</th><th class=\"n\">± stderr</th><th class=\"n\">luminance</th>"
       "<th class=\"n\">samples</th><th>strategies</th></tr></thead><tbody>\n";
  const auto row = [&](const PathEstimate& p, const std::string& label) {
    const double share = rep.total.luminance > 0 ? p.estimate.luminance / rep.total.luminance : 0.0;
    const double err = rep.total.luminance > 0 ? p.estimate.std_error / rep.total.luminance : NAN;
    h << "<tr data-path=\"" << esc(p.path) << "\" data-luminance=\"" << exact(p.estimate.luminance) << "\" data-stderr=\""
      << exact(p.estimate.std_error) << "\"><td class=\"mono\">" << esc(label) << "</td><td class=\"n\">" << pct(share) << "</td><td class=\"n\">"
      << pct(err, 2) << "</td><td class=\"n\">" << esc(lum(p.estimate)) << "</td><td class=\"n\">" << p.estimate.samples << "</td><td>"
      << esc(top_strategies(p.strategies, 3)) << "</td></tr>\n";
  };
  for (std::size_t i = 0; i < rep.paths.size() && static_cast<int>(i) < o.top_paths; ++i) row(rep.paths[i], rep.paths[i].path);
  if (rep.paths.size() > static_cast<std::size_t>(o.top_paths) || rep.other)
    h << "<tr><td colspan=\"6\">" << (rep.paths.size() > static_cast<std::size_t>(o.top_paths) ? rep.paths.size() - static_cast<std::size_t>(o.top_paths) : 0)
      << " more paths listed in " << esc(d.histogram_file) << (rep.other ? " and " + std::to_string(rep.other_paths) + " summed in its \"other\" row" : "")
      << "; " << rep.distinct_paths << " distinct paths in all</td></tr>\n";
  h << "</tbody></table>\n</section>\n";
}

void missed_section(std::ostringstream& h, const ReportData& d) {
  const ReportData::Missed& m = *d.missed;
  h << "<section id=\"missed\"><h2>The light " << esc(m.renderer) << " misses</h2>\n<p>" << esc(m.renderer)
    << " cannot sample " << pct(m.share) << " ± " << pct(m.share_stderr, 2) << " of what " << esc(m.reference)
    << " finds (luminance " << fixed(m.luminance, "%.5g") << ")" << (m.exact ? ": exactly 0, the checker proves it samples every path" : "")
    << "; from " << esc(m.file) << ".</p>\n";
  if (d.png.count("missed") && d.png.count("total"))
    h << "<figure><div class=\"overlay\">" << img(d, "total", "the rendered image")
      << img(d, "missed", "the missed light alone, on the render's exposure", "px top")
      << "</div><figcaption>missed.png over the render (added light: where it brightens, " << esc(m.renderer)
      << " misses light)</figcaption></figure>\n";
  h << "<table id=\"missed-classes\"><thead><tr><th>class</th><th class=\"n\">missed luminance</th><th class=\"n\">of the class</th>"
       "<th class=\"n\">of the image</th><th>verdict</th><th>shortest path it cannot sample, and why</th></tr></thead><tbody>\n";
  for (const ReportData::MissedClass& c : m.classes)
    h << "<tr data-class=\"" << esc(c.name) << "\"><td>" << esc(c.name) << "</td><td class=\"n\">" << fixed(c.missed, "%.5g") << "</td><td class=\"n\">"
      << pct(c.share_of_class) << "</td><td class=\"n\">" << pct(c.share_of_image) << "</td><td class=\"verdict-" << esc(c.verdict) << "\">"
      << esc(c.verdict) << "</td><td>" << (c.witness.empty() ? "—" : "<span class=\"mono\">" + esc(c.witness) + "</span>: " + esc(c.reason))
      << "</td></tr>\n";
  h << "</tbody></table>\n";
  if (!m.paths.empty()) {
    h << "<table id=\"missed-paths\"><thead><tr><th>missed path</th><th class=\"n\">share of the image</th><th class=\"n\">luminance</th>"
         "<th>why it cannot be sampled</th></tr></thead><tbody>\n";
    for (std::size_t i = 0; i < m.paths.size() && i < 20; ++i)
      h << "<tr><td class=\"mono\">" << esc(m.paths[i].path) << "</td><td class=\"n\">" << pct(m.paths[i].share) << "</td><td class=\"n\">"
        << fixed(m.paths[i].luminance, "%.5g") << "</td><td>" << esc(m.paths[i].reason) << "</td></tr>\n";
    h << "</tbody></table>\n";
  }
  h << "</section>\n";
}

void converge_section(std::ostringstream& h, const ReportData& d) {
  const ReportData::Converge& c = *d.converge;
  h << "<section id=\"converge\"><h2>What accuracy costs: error against time</h2>\n";
  if (!d.histogram && !d.command.empty())
    h << "<p>The command that reproduces it:</p><pre class=\"cmd\" id=\"command\">" << esc(d.command) << "</pre>\n";
  if (!c.png.empty())
    h << "<figure><img class=\"plot\" style=\"max-width:100%\" alt=\"log-log plot of each renderer's error and reported standard error "
         "against CPU time, one panel per class\" src=\"data:image/png;base64,"
      << base64(c.png) << "\"><figcaption>converge.png: true error (solid) and reported stderr (dotted) against CPU time</figcaption></figure>\n";
  h << "<table id=\"converge-table\"><thead><tr><th>renderer</th><th>class</th><th>budget</th><th class=\"n\">CPU s</th>"
       "<th class=\"n\">estimate</th><th class=\"n\">stderr</th><th class=\"n\">error</th></tr></thead><tbody>\n";
  for (const ReportData::ConvergeRow& r : c.rows) {
    for (const ReportData::Rung& g : r.rungs)
      h << "<tr><td>" << esc(r.renderer) << "</td><td>" << esc(r.class_name) << "</td><td>" << esc(g.budget) << "</td><td class=\"n\">"
        << fixed(g.cpu_s, "%.3f") << "</td><td class=\"n\">" << fixed(g.estimate, "%.6g") << "</td><td class=\"n\">"
        << (g.std_error ? fixed(*g.std_error, "%.3g") : "—") << "</td><td class=\"n\">" << (g.error ? fixed(*g.error, "%.3g") : "—") << "</td></tr>\n";
    h << "<tr><td>" << esc(r.renderer) << "</td><td>" << esc(r.class_name) << "</td><td colspan=\"5\">error slope against time "
      << (r.slope ? fixed(*r.slope, "%.2f") : "—") << " (1/√t: −0.5), efficiency " << (r.efficiency ? fixed(*r.efficiency, "%.3g") : "—")
      << (r.warning.empty() ? "" : "; WARNING: " + esc(r.warning)) << "</td></tr>\n";
  }
  h << "</tbody></table>\n";
  if (!c.best.empty()) {
    h << "<p>Most efficient renderer per class:</p><ul>";
    for (const std::string& b : c.best) h << "<li>" << esc(b) << "</li>";
    h << "</ul>\n";
  }
  h << "</section>\n";
}

void narrowing_section(std::ostringstream& h, const ReportData& d) {
  if (d.only.empty() && d.pruned.empty()) return;
  h << "<section id=\"narrowing\"><h2>What was simulated</h2>\n";
  if (!d.only.empty()) {
    h << "<p>Rendered only (--only):</p><ul id=\"only\">";
    for (const auto& [name, expr] : d.only) h << "<li>" << esc(name) << " <code>" << esc(expr) << "</code></li>";
    h << "</ul><p>Shares are of the requested paths' total; classes outside them are not rendered.</p>\n";
  }
  if (!d.pruned.empty()) {
    h << "<table id=\"pruned\"><thead><tr><th>strategy</th><th>profile</th><th>runs</th><th>why</th></tr></thead><tbody>\n";
    for (const ReportData::Pruned& p : d.pruned)
      h << "<tr><td>" << esc(p.strategy) << "</td><td class=\"mono\">" << esc(p.profile) << "</td><td class=\"mono\">"
        << (p.runs.empty() ? "not run" : esc(p.runs)) << "</td><td>" << esc(p.reason) << "</td></tr>\n";
    h << "</tbody></table>\n";
  }
  h << "</section>\n";
}

void connectors_section(std::ostringstream& h, const ReportData& d) {
  if (d.connectors.empty()) return;
  std::set<std::string> keys;
  for (const ReportData::Connector& c : d.connectors)
    for (const auto& [k, v] : c.failures) keys.insert(k);
  h << "<section id=\"connectors\"><h2>Connectors</h2>\n<table id=\"connectors-table\"><thead><tr><th>strategy</th><th>connector</th>"
       "<th class=\"n\">attempts</th><th class=\"n\">successes</th>";
  for (const std::string& k : keys) h << "<th class=\"n\">" << esc(k) << "</th>";
  h << "</tr></thead><tbody>\n";
  for (const ReportData::Connector& c : d.connectors) {
    h << "<tr><td>" << esc(c.strategy) << "</td><td>" << esc(c.connector) << "</td><td class=\"n\">" << c.attempts << "</td><td class=\"n\">"
      << c.successes << "</td>";
    for (const std::string& k : keys) {
      const auto it = c.failures.find(k);
      h << "<td class=\"n\">" << (it != c.failures.end() ? std::to_string(it->second) : "—") << "</td>";
    }
    h << "</tr>\n";
  }
  h << "</tbody></table>\n</section>\n";
}

void hover_data(std::ostringstream& h, const ReportData& d) {
  if (d.hover.empty()) return;
  nlohmann::json meta;
  meta["width"] = d.width;
  meta["height"] = d.height;
  meta["factor"] = d.hover_factor;
  meta["grid"] = {d.hover_width, d.hover_height};
  meta["layers"] = nlohmann::json::array();
  for (const auto& [name, values] : d.hover) {
    // Little-endian float32, as JavaScript's Float32Array reads them on every current platform.
    std::string bytes(values.size() * 4, '\0');
    for (std::size_t i = 0; i < values.size(); ++i) {
      std::uint32_t u;
      std::memcpy(&u, &values[i], 4);
      for (int b = 0; b < 4; ++b) bytes[i * 4 + static_cast<std::size_t>(b)] = static_cast<char>((u >> (8 * b)) & 0xff);
    }
    meta["layers"].push_back({{"name", name}, {"data", base64(bytes)}});
  }
  // In a JSON script element; "</" cannot occur (names are escaped by dump's \u003c? no: escape '<').
  std::string text = meta.dump();
  std::string safe;
  safe.reserve(text.size());
  for (char c : text) safe += c == '<' ? std::string("\\u003c") : std::string(1, c);
  h << "<script type=\"application/json\" id=\"hover-data\">" << safe << "</script>\n";
}

}  // namespace

std::string report_html(const ReportData& d, const ReportOptions& o) {
  std::ostringstream h;
  const std::string title = d.histogram ? d.histogram->run.scene + ", " + d.histogram->run.renderer : d.folder;
  h << "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n"
    << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n"
    << "<title>pathex report: " << esc(title) << "</title>\n<style>" << kStyle << "</style>\n</head>\n"
    << "<body data-hover=\"none\" data-kind=\"" << esc(d.kind) << "\">\n"
    << "<h1>pathex report: " << esc(title) << "</h1>\n"
    << "<p>A view of the folder <code>" << esc(d.folder) << "</code> (pathex " << esc(d.kind) << "): the linear data stays in "
    << esc(d.histogram_file.empty() ? "converge.json" : d.histogram_file) << (d.png.empty() ? "" : " and the EXR files") << ".</p>\n";
  if (!d.hover.empty()) h << "<div id=\"hover\" aria-live=\"polite\">hover data not loaded (JavaScript is off)</div>\n";
  if (d.histogram) {
    render_section(h, d);
    class_tiles(h, d);
    paths_table(h, d, o);
  }
  if (d.missed) missed_section(h, d);
  narrowing_section(h, d);
  connectors_section(h, d);
  if (d.converge) converge_section(h, d);
  hover_data(h, d);
  if (!d.hover.empty()) h << "<script>" << kScript << "</script>\n";
  h << "</body>\n</html>\n";
  return h.str();
}

Result<bool> write_report(const std::string& dir, const std::string& html) {
  // An output set lists every file pathex wrote into it (io/output_set.h): report.html joins the
  // list before it is written, so that a failure leaves at worst a listed name without its file,
  // which the next run tolerates, never a file the list does not name, which it refuses.
  const std::string manifest = join_path(dir, kManifestName);
  if (exists_file(manifest)) {
    std::ifstream in(manifest, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    std::string text = ss.str();
    bool listed = false;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);) listed = listed || line == kReportName;
    if (!listed) {
      if (!text.empty() && text.back() != '\n') text += '\n';
      text += std::string(kReportName) + "\n";
      if (Result<bool> w = write_file_atomic(manifest, text); !w) return w;
    }
  }
  return write_file_atomic(join_path(dir, kReportName), html);
}

}  // namespace pathex
