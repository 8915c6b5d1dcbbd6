// histogram.json writer and reader. The reader checks every value's type and reports the first
// problem with the JSON pointer of the value, like the other JSON readers of pathex.
#include "io/histogram_json.h"

#include <algorithm>
#include <cmath>
#include <string_view>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "io/json_reader.h"

namespace pathex {
namespace {

using json = nlohmann::ordered_json;

// The objects below are built member by member and moved into place: nlohmann's
// initializer-list constructor copies every element and first checks whether the list reads as an
// object, which made the techniques' objects 60 % of the report's JSON building (same bytes).
json rgb_json(const Rgb& c) {
  json a = json::array();
  a.get_ref<json::array_t&>().reserve(3);
  for (double v : c) a.push_back(v);
  return a;
}
json exact_rgb_json(const ExactRgb& c) {
  return json::array({exact_to_string(c[0]), exact_to_string(c[1]), exact_to_string(c[2])});
}
json stderr_json(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

json techniques_json(const std::vector<TechniqueEstimate>& ts) {
  // As `out[t.name] = …` for each in turn (a repeated name keeps its first place and its last
  // value), without searching the object for every name: a class lists hundreds of techniques.
  json out = json::object();
  json::object_t& members = out.get_ref<json::object_t&>();
  members.reserve(ts.size());
  std::unordered_map<std::string_view, std::size_t> at;
  at.reserve(ts.size());
  for (const TechniqueEstimate& t : ts) {
    json v = json::object();
    v["share"] = t.share;
    v["samples"] = t.samples;
    v["variance_share"] = stderr_json(t.variance_share);
    v["correlation"] = stderr_json(t.correlation);
    if (const auto [it, added] = at.emplace(t.name, members.size()); !added)
      (members.begin() + static_cast<std::ptrdiff_t>(it->second))->second = std::move(v);
    else
      members.emplace_back(t.name, std::move(v));
  }
  return out;
}

void put_estimate(json& j, const Estimate& e) {
  j["estimate"] = rgb_json(e.rgb);
  j["luminance"] = e.luminance;
  j["stderr"] = stderr_json(e.std_error);
  j["samples"] = e.samples;
}

// Reads typed values out of a document, remembering the first error (with its JSON pointer).
class Reader {
 public:
  explicit Reader(const std::string& filename) : filename_(filename) {}

  bool failed() const { return error_.has_value(); }
  const Error& error() const { return *error_; }

  void fail(const std::string& pointer, const std::string& message) {
    if (error_) return;
    Error e = make_error(ErrorCode::kBadFile, message);
    e.where = filename_ + ":" + (pointer.empty() ? "/" : pointer);
    error_ = std::move(e);
  }

  const json* field(const json& obj, const std::string& ptr, const char* key) {
    if (!obj.is_object()) {
      fail(ptr, "expected an object");
      return nullptr;
    }
    auto it = obj.find(key);
    if (it == obj.end()) {
      fail(ptr, std::string("missing key \"") + key + "\"");
      return nullptr;
    }
    return &*it;
  }
  std::string str(const json& obj, const std::string& ptr, const char* key) {
    const json* v = field(obj, ptr, key);
    if (v == nullptr) return {};
    if (!v->is_string()) {
      fail(ptr + "/" + key, "expected a string");
      return {};
    }
    return v->get<std::string>();
  }
  std::uint64_t uint(const json& v, const std::string& ptr) {
    // Integers parsed from text are unsigned when non-negative; built in memory they may be signed.
    if (v.is_number_unsigned()) return v.get<std::uint64_t>();
    if (v.is_number_integer() && v.get<std::int64_t>() >= 0) return static_cast<std::uint64_t>(v.get<std::int64_t>());
    fail(ptr, "expected a non-negative integer");
    return 0;
  }
  std::uint64_t uint(const json& obj, const std::string& ptr, const char* key) {
    const json* v = field(obj, ptr, key);
    return v != nullptr ? uint(*v, ptr + "/" + key) : 0;
  }
  double number(const json& v, const std::string& ptr) {
    if (!v.is_number()) {
      fail(ptr, "expected a number");
      return 0;
    }
    return v.get<double>();
  }
  double number(const json& obj, const std::string& ptr, const char* key) {
    const json* v = field(obj, ptr, key);
    return v != nullptr ? number(*v, ptr + "/" + key) : 0;
  }
  bool boolean(const json& obj, const std::string& ptr, const char* key) {
    const json* v = field(obj, ptr, key);
    if (v == nullptr) return false;
    if (!v->is_boolean()) {
      fail(ptr + "/" + key, "expected true or false");
      return false;
    }
    return v->get<bool>();
  }
  const json* array(const json& obj, const std::string& ptr, const char* key, std::size_t size = kAnySize) {
    const json* v = field(obj, ptr, key);
    if (v == nullptr) return nullptr;
    if (!v->is_array() || (size != kAnySize && v->size() != size)) {
      fail(ptr + "/" + key,
           size == kAnySize ? "expected an array" : "expected an array of " + std::to_string(size) + " elements");
      return nullptr;
    }
    return v;
  }
  ExactSum exact(const json& v, const std::string& ptr) {
    std::optional<ExactSum> e;
    if (v.is_string()) e = exact_from_string(v.get<std::string>());
    if (!e) {
      fail(ptr, "expected an exact sum: \"0\" or a signed hexadecimal string such as \"0x1f\" or \"-0x1f\"");
      return 0;
    }
    return *e;
  }
  ExactRgb exact_rgb(const json& v, const std::string& ptr) {
    if (!v.is_array() || v.size() != 3) {
      fail(ptr, "expected an array of 3 exact sums");
      return {};
    }
    return {exact(v[0], ptr + "/0"), exact(v[1], ptr + "/1"), exact(v[2], ptr + "/2")};
  }

  Estimate estimate(const json& obj, const std::string& ptr, bool samples_required) {
    Estimate e;
    if (const json* rgb = array(obj, ptr, "estimate", 3))
      for (std::size_t i = 0; i < 3; ++i) e.rgb[i] = number((*rgb)[i], ptr + "/estimate/" + std::to_string(i));
    e.luminance = number(obj, ptr, "luminance");
    if (const json* se = field(obj, ptr, "stderr"); se != nullptr && !se->is_null())
      e.std_error = number(*se, ptr + "/stderr");
    if (samples_required || (obj.is_object() && obj.contains("samples"))) e.samples = uint(obj, ptr, "samples");
    // The total's and the classes' (optional: added by the twenty-third session's format).
    if (obj.is_object() && obj.contains("stderr_stability") && !obj["stderr_stability"].is_null())
      e.stability = number(obj["stderr_stability"], ptr + "/stderr_stability");
    return e;
  }

  // {name: {share, samples, variance_share, correlation}, …} (TechniqueEstimate); optional under `key`.
  std::vector<TechniqueEstimate> techniques(const json& obj, const std::string& ptr, const char* key) {
    std::vector<TechniqueEstimate> out;
    if (!obj.is_object() || !obj.contains(key)) return out;
    const json& s = obj[key];
    const std::string sp = ptr + "/" + key;
    if (!s.is_object()) {
      fail(sp, "expected an object of techniques");
      return out;
    }
    for (const auto& [name, tj] : s.items()) {
      TechniqueEstimate t;
      t.name = name;
      const std::string tp = sp + "/" + name;
      t.share = number(tj, tp, "share");
      t.samples = uint(tj, tp, "samples");
      if (const json* v = field(tj, tp, "variance_share"); v != nullptr && !v->is_null())
        t.variance_share = number(*v, tp + "/variance_share");
      if (const json* v = field(tj, tp, "correlation"); v != nullptr && !v->is_null())
        t.correlation = number(*v, tp + "/correlation");
      out.push_back(std::move(t));
    }
    return out;
  }

  static constexpr std::size_t kAnySize = static_cast<std::size_t>(-1);

 private:
  const std::string& filename_;
  std::optional<Error> error_;
};

}  // namespace

json to_json(const HistogramReport& r, const Histogram* raw) {
  json doc = json::object();
  doc["scene"] = r.run.scene;
  doc["renderer"] = r.run.renderer;
  doc["spp"] = r.run.spp;
  doc["spp_requested"] = r.run.spp_requested;
  doc["seed"] = r.run.seed;
  doc["complete"] = r.run.complete;
  doc["nonfinite_samples"] = r.nonfinite_samples;
  doc["distinct_paths"] = r.distinct_paths;
  doc["max_paths"] = r.max_paths ? json(*r.max_paths) : json(nullptr);
  json total = json::object();
  put_estimate(total, r.total);
  total["stderr_stability"] = stderr_json(r.total.stability);
  doc["total"] = std::move(total);
  json classes = json::array();
  for (const ClassEstimate& c : r.classes) {
    json j = json::object();
    j["name"] = c.name;
    j["expr"] = c.expr;
    if (!c.rendered) {  // pathex trace --only asked for other classes: no estimate, never a 0
      j["rendered"] = false;
      j["note"] = "not rendered: only the requested classes were estimated (--only, \"render\")";
      classes.push_back(std::move(j));
      continue;
    }
    put_estimate(j, c.estimate);
    j["stderr_stability"] = stderr_json(c.estimate.stability);
    j["share"] = c.share;
    j["strategies"] = techniques_json(c.strategies);
    classes.push_back(std::move(j));
  }
  doc["classes"] = std::move(classes);
  json paths = json::array();
  auto put_path = [&](const PathEstimate& p, std::optional<std::uint64_t> summed) {
    json j = json::object();
    j["path"] = p.path;
    if (summed) {
      j["paths"] = *summed;
      j["note"] = "the sum of the " + std::to_string(*summed) + " paths past the first " +
                  std::to_string(r.paths.size()) + " (--max-paths)";
    }
    put_estimate(j, p.estimate);
    j["strategies"] = techniques_json(p.strategies);
    paths.push_back(std::move(j));
  };
  for (const PathEstimate& p : r.paths) put_path(p, std::nullopt);
  if (r.other) put_path(*r.other, r.other_paths);
  doc["paths"] = std::move(paths);
  if (raw != nullptr) doc["raw"] = raw_to_json(*raw);
  return doc;
}

std::string histogram_json_text(const HistogramReport& report, const Histogram* raw) {
  return to_json(report, raw).dump(2) + "\n";
}

json raw_to_json(const Histogram& h) {
  json raw = json::object();
  raw["format"] = 2;
  raw["fraction_bits"] = kFractionBits;
  raw["batches"] = h.num_batches();
  raw["replicates"] = h.layout().replicates();
  raw["strategies"] = h.layout().strategies;
  json batch_samples = json::array();
  for (int b = 0; b < h.num_batches(); ++b) batch_samples.push_back(h.batch_samples(b));
  raw["batch_samples"] = std::move(batch_samples);
  raw["nonfinite"] = h.nonfinite();
  raw["magnitude"] = exact_to_string(h.magnitude());
  // Paths by string, so that the section is the same whatever order the paths were first seen in.
  std::vector<Histogram::PathId> order(static_cast<std::size_t>(h.num_paths()));
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<Histogram::PathId>(i);
  std::sort(order.begin(), order.end(), [&](auto a, auto b) { return h.path(a) < h.path(b); });
  json paths = json::array();
  for (Histogram::PathId p : order) {
    json j = json::object();
    j["path"] = h.path(p);
    json counts = json::array(), sums = json::array(), techniques = json::array();
    for (int b = 0; b < h.num_batches(); ++b) {
      counts.push_back(h.cell(p, b).contributions);
      sums.push_back(exact_rgb_json(h.cell(p, b).sum));
    }
    for (int r : h.sorted_rows(p)) {
      const Technique t = Technique::from_code(h.row(r).technique);
      json tsums = json::array();
      for (int b = 0; b < h.num_batches(); ++b) tsums.push_back(exact_to_string(h.row_sum(r, b)));
      techniques.push_back({{"strategy", t.strategy}, {"s", t.s}, {"t", t.t}, {"connector", t.connector},
                            {"contributions", h.row(r).contributions}, {"sums", std::move(tsums)}});
    }
    j["contributions"] = std::move(counts);
    j["sums"] = std::move(sums);
    j["techniques"] = std::move(techniques);
    paths.push_back(std::move(j));
  }
  raw["paths"] = std::move(paths);
  return raw;
}

Result<Histogram> raw_from_json(const json& raw, const std::string& filename, const std::string& ptr) {
  Reader rd(filename);
  if (!raw.is_object()) rd.fail(ptr, "expected an object");
  if (!rd.failed() && rd.uint(raw, ptr, "format") != 2)
    rd.fail(ptr + "/format", "expected format 2 (format 1, without per-technique sums, was written by an older pathex)");
  if (!rd.failed() && rd.uint(raw, ptr, "fraction_bits") != static_cast<std::uint64_t>(kFractionBits))
    rd.fail(ptr + "/fraction_bits", "expected " + std::to_string(kFractionBits));
  HistogramLayout layout;
  const std::uint64_t batches = rd.failed() ? 0 : rd.uint(raw, ptr, "batches");
  if (!rd.failed() && (batches < 1 || batches > 1000000)) rd.fail(ptr + "/batches", "expected 1 to 1000000 batches");
  layout.num_batches = static_cast<int>(batches);
  // Absent in files written before issue 39's pixel groups: every batch a replicate (plain batch means).
  const std::uint64_t replicates = rd.failed() || !raw.contains("replicates") ? batches : rd.uint(raw, ptr, "replicates");
  if (!rd.failed() && (replicates < 1 || batches % replicates != 0))
    rd.fail(ptr + "/replicates", "expected a divisor of the batch count " + std::to_string(batches));
  else if (!rd.failed()) layout.groups = static_cast<int>(batches / replicates);
  if (const json* s = rd.failed() ? nullptr : rd.array(raw, ptr, "strategies")) {
    for (std::size_t i = 0; i < s->size(); ++i) {
      if (!(*s)[i].is_string()) rd.fail(ptr + "/strategies/" + std::to_string(i), "expected a strategy name");
      else layout.strategies.push_back((*s)[i].get<std::string>());
    }
  }
  if (rd.failed()) return rd.error();
  const std::size_t B = static_cast<std::size_t>(batches);
  const std::size_t S = layout.strategies.size();
  Histogram h(layout);
  if (const json* n = rd.array(raw, ptr, "batch_samples", B))
    for (std::size_t b = 0; b < B; ++b)
      h.add_samples(static_cast<int>(b), rd.uint((*n)[b], ptr + "/batch_samples/" + std::to_string(b)));
  h.add_nonfinite(rd.uint(raw, ptr, "nonfinite"));
  if (const json* m = rd.field(raw, ptr, "magnitude")) h.add_magnitude(rd.exact(*m, ptr + "/magnitude"));
  if (const json* paths = rd.array(raw, ptr, "paths")) {
    for (std::size_t i = 0; i < paths->size() && !rd.failed(); ++i) {
      const json& pj = (*paths)[i];
      const std::string pp = ptr + "/paths/" + std::to_string(i);
      const std::string path = rd.str(pj, pp, "path");
      if (rd.failed()) break;
      if (h.find(path)) {
        rd.fail(pp + "/path", "path \"" + path + "\" appears twice");
        break;
      }
      const Histogram::PathId id = h.intern(path);
      const json* counts = rd.array(pj, pp, "contributions", B);
      const json* sums = rd.array(pj, pp, "sums", B);
      const json* techniques = rd.array(pj, pp, "techniques");
      if (rd.failed()) break;
      for (std::size_t b = 0; b < B; ++b) {
        const std::string bs = std::to_string(b);
        h.add_cell(id, static_cast<int>(b), rd.exact_rgb((*sums)[b], pp + "/sums/" + bs),
                   rd.uint((*counts)[b], pp + "/contributions/" + bs));
      }
      for (std::size_t k = 0; k < techniques->size() && !rd.failed(); ++k) {
        const json& tj = (*techniques)[k];
        const std::string tp = pp + "/techniques/" + std::to_string(k);
        Technique t;
        const std::uint64_t strategy = rd.uint(tj, tp, "strategy"), s = rd.uint(tj, tp, "s"), tt = rd.uint(tj, tp, "t");
        if (!rd.failed() && strategy >= S) rd.fail(tp + "/strategy", "expected a strategy index below " + std::to_string(S));
        if (!rd.failed() && (s > Technique::kMaxSplit || tt > Technique::kMaxSplit))
          rd.fail(tp, "expected s and t of at most " + std::to_string(Technique::kMaxSplit));
        t.strategy = static_cast<int>(strategy);
        t.s = static_cast<int>(s);
        t.t = static_cast<int>(tt);
        t.connector = rd.boolean(tj, tp, "connector");
        const std::uint64_t n = rd.uint(tj, tp, "contributions");
        std::vector<ExactSum> tsums(B);
        if (const json* sj = rd.array(tj, tp, "sums", B))
          for (std::size_t b = 0; b < B; ++b) tsums[b] = rd.exact((*sj)[b], tp + "/sums/" + std::to_string(b));
        if (rd.failed()) break;
        const std::vector<int> seen = h.sorted_rows(id);
        if (std::any_of(seen.begin(), seen.end(), [&](int r) { return h.row(r).technique == t.code(); })) {
          rd.fail(tp, "technique appears twice");
          break;
        }
        h.add_technique(id, t.code(), n, tsums.data());
      }
    }
  }
  if (rd.failed()) return rd.error();
  return h;
}

Result<HistogramFile> histogram_from_json(const json& doc, const std::string& filename) {
  Reader rd(filename);
  HistogramFile file;
  HistogramReport& r = file.report;
  if (!doc.is_object()) {
    rd.fail("", "expected a JSON object (a histogram.json document)");
    return rd.error();
  }
  r.run.scene = rd.str(doc, "", "scene");
  r.run.renderer = rd.str(doc, "", "renderer");
  r.run.spp = rd.uint(doc, "", "spp");
  // Keys added after the first format are optional, so older files still read.
  if (doc.contains("spp_requested")) r.run.spp_requested = rd.uint(doc, "", "spp_requested");
  r.run.seed = rd.uint(doc, "", "seed");
  r.run.complete = rd.boolean(doc, "", "complete");
  r.nonfinite_samples = rd.uint(doc, "", "nonfinite_samples");
  if (doc.contains("distinct_paths")) r.distinct_paths = rd.uint(doc, "", "distinct_paths");
  if (doc.contains("max_paths") && !doc["max_paths"].is_null()) r.max_paths = rd.uint(doc, "", "max_paths");
  if (const json* t = rd.field(doc, "", "total")) r.total = rd.estimate(*t, "/total", /*samples_required=*/false);
  if (doc.contains("only") && doc["only"].is_array())  // pathex trace --only
    for (std::size_t i = 0; i < doc["only"].size(); ++i) r.only.push_back(rd.str(doc["only"][i], "/only/" + std::to_string(i), "name"));
  if (const json* classes = rd.array(doc, "", "classes")) {
    for (std::size_t i = 0; i < classes->size() && !rd.failed(); ++i) {
      const json& cj = (*classes)[i];
      const std::string cp = "/classes/" + std::to_string(i);
      ClassEstimate c;
      c.name = rd.str(cj, cp, "name");
      c.expr = rd.str(cj, cp, "expr");
      if (cj.contains("rendered")) c.rendered = rd.boolean(cj, cp, "rendered");
      if (!c.rendered) {
        r.classes.push_back(std::move(c));
        continue;
      }
      c.estimate = rd.estimate(cj, cp, /*samples_required=*/true);
      c.share = rd.number(cj, cp, "share");
      c.strategies = rd.techniques(cj, cp, "strategies");
      r.classes.push_back(std::move(c));
    }
  }
  if (const json* paths = rd.array(doc, "", "paths")) {
    for (std::size_t i = 0; i < paths->size() && !rd.failed(); ++i) {
      const json& pj = (*paths)[i];
      const std::string pp = "/paths/" + std::to_string(i);
      PathEstimate p;
      p.path = rd.str(pj, pp, "path");
      const bool other = p.path == "other";  // the sum of the rows past max_paths; never a full path
      if (other) r.other_paths = rd.uint(pj, pp, "paths");
      p.estimate = rd.estimate(pj, pp, /*samples_required=*/true);
      p.strategies = rd.techniques(pj, pp, "strategies");
      if (other) r.other = std::move(p);
      else r.paths.push_back(std::move(p));
    }
  }
  if (!doc.contains("distinct_paths")) r.distinct_paths = r.paths.size();
  if (rd.failed()) return rd.error();
  if (auto it = doc.find("raw"); it != doc.end()) {
    Result<Histogram> h = raw_from_json(*it, filename, "/raw");
    if (!h) return h.error();
    file.raw = std::move(h).value();
  }
  return file;
}

Result<HistogramFile> parse_histogram_json(const std::string& text, const std::string& filename) {
  Result<json> doc = parse_ordered_json(text, filename);
  if (!doc) return doc.error();
  return histogram_from_json(*doc, filename);
}

}  // namespace pathex
