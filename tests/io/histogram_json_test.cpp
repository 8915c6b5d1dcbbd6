// histogram.json: the documented keys in their order, a round trip of the report and of the raw
// accumulator (merging parsed shard outputs equals the whole render), and errors that name the
// JSON pointer of the offending value.
#include "io/histogram_json.h"

#include <gtest/gtest.h>

#include <cmath>

#include <nlohmann/json.hpp>

namespace pathex {
namespace {

using json = nlohmann::ordered_json;

Rgb gray(double v) { return {v, v, v}; }

HistogramLayout layout() { return HistogramLayout{4, {"nee", "emitter-hit"}}; }

// A small render's worth of contributions, over samples [begin, end) of a fixed stream.
Histogram shard(int begin, int end) {
  Histogram h(layout());
  const char* paths[] = {"LDDDSE", "LSDDSE", "LDDSDDSE"};
  for (int i = begin; i < end; ++i) {
    const int batch = i * 4 / 40;
    const double v = 0.1 * (i % 7) + 1e-6 * i;
    h.add(h.intern(paths[i % 3]), batch, Technique{i % 2, 1 - i % 2, 3}.code(), {v, 2 * v, 0.5 * v});
    h.add_samples(batch, 1);
  }
  return h;
}

struct Fixture {
  ClassTable table;
  std::vector<ClassInfo> info;
  std::optional<Classifier> classifier;
  Fixture() {
    std::vector<const PathClass*> list;
    for (auto [name, expr] : {std::pair{"point", "LS.*E"}, std::pair{"area", "LD.*E"}}) {
      list.push_back(table.add(name, expr, ClassOptions{}).expect("a test input"));
      info.push_back({name, expr});
    }
    classifier = Classifier::build(list, Limits{}).expect("a test input");
  }
  HistogramReport report(const Histogram& h) {
    RunInfo run{"scenes/cornell.json", "bdpt", 64, 7, true};
    Result<HistogramReport> r = make_report(h, run, &*classifier, info);
    EXPECT_TRUE(r) << r.error().render();
    return *r;
  }
};

std::vector<std::string> keys(const json& j) {
  std::vector<std::string> out;
  for (const auto& [k, v] : j.items()) out.push_back(k);
  return out;
}

void expect_same_estimate(const Estimate& a, const Estimate& b) {
  EXPECT_EQ(a.rgb, b.rgb);
  EXPECT_EQ(a.luminance, b.luminance);
  EXPECT_TRUE(a.std_error == b.std_error || (std::isnan(a.std_error) && std::isnan(b.std_error)));
  EXPECT_EQ(a.samples, b.samples);
}

TEST(HistogramJson, HasTheDocumentedKeysInOrder) {
  Fixture f;
  const json doc = to_json(f.report(shard(0, 40)));
  EXPECT_EQ(keys(doc), (std::vector<std::string>{"scene", "renderer", "spp", "spp_requested", "seed", "complete",
                                                  "nonfinite_samples", "distinct_paths", "max_paths", "total",
                                                  "classes", "paths"}));
  EXPECT_EQ(doc["scene"], "scenes/cornell.json");
  EXPECT_EQ(doc["renderer"], "bdpt");
  EXPECT_EQ(doc["spp"], 64);
  EXPECT_EQ(doc["complete"], true);
  EXPECT_EQ(doc["nonfinite_samples"], 0);
  EXPECT_EQ(keys(doc["total"]), (std::vector<std::string>{"estimate", "luminance", "stderr", "samples", "stderr_stability"}));
  ASSERT_EQ(doc["classes"].size(), 2u);
  EXPECT_EQ(keys(doc["classes"][0]), (std::vector<std::string>{"name", "expr", "estimate", "luminance", "stderr",
                                                                "samples", "stderr_stability", "share", "strategies"}));
  EXPECT_EQ(keys(doc["classes"][0]["strategies"]), (std::vector<std::string>{"nee (1, DD, 3)", "emitter-hit (0, DD, 3)"}));
  EXPECT_EQ(doc["classes"][1]["name"], "area");
  EXPECT_EQ(doc["classes"][1]["expr"], "LD.*E");
  ASSERT_EQ(doc["paths"].size(), 3u);
  EXPECT_EQ(keys(doc["paths"][0]),
            (std::vector<std::string>{"path", "estimate", "luminance", "stderr", "samples", "strategies"}));
  EXPECT_EQ(keys(doc["paths"][0]["strategies"]), (std::vector<std::string>{"nee (1, DD, 3)", "emitter-hit (0, DD, 3)"}));
  EXPECT_EQ(keys(doc["paths"][0]["strategies"]["nee (1, DD, 3)"]),
            (std::vector<std::string>{"share", "samples", "variance_share", "correlation"}));
  for (std::size_t i = 1; i < doc["paths"].size(); ++i)
    EXPECT_GE(doc["paths"][i - 1]["luminance"].get<double>(), doc["paths"][i]["luminance"].get<double>());
  EXPECT_FALSE(doc.contains("raw"));
}

TEST(HistogramJson, ReportRoundTrips) {
  Fixture f;
  const HistogramReport r = f.report(shard(0, 40));
  Result<HistogramFile> back = parse_histogram_json(histogram_json_text(r), "h.json");
  ASSERT_TRUE(back) << back.error().render();
  const HistogramReport& b = back->report;
  EXPECT_EQ(b.run, r.run);
  EXPECT_EQ(b.nonfinite_samples, r.nonfinite_samples);
  expect_same_estimate(b.total, r.total);
  // The total's and the classes' stderr stability are written and read back (not the paths').
  ASSERT_TRUE(std::isfinite(r.total.stability));
  EXPECT_EQ(b.total.stability, r.total.stability);
  ASSERT_EQ(b.classes.size(), r.classes.size());
  for (std::size_t i = 0; i < r.classes.size(); ++i) {
    EXPECT_EQ(b.classes[i].name, r.classes[i].name);
    EXPECT_EQ(b.classes[i].expr, r.classes[i].expr);
    EXPECT_EQ(b.classes[i].share, r.classes[i].share);
    EXPECT_EQ(b.classes[i].strategies, r.classes[i].strategies);
    expect_same_estimate(b.classes[i].estimate, r.classes[i].estimate);
    const double s = r.classes[i].estimate.stability;
    EXPECT_TRUE(b.classes[i].estimate.stability == s || (std::isnan(s) && std::isnan(b.classes[i].estimate.stability)));
  }
  ASSERT_EQ(b.paths.size(), r.paths.size());
  for (std::size_t i = 0; i < r.paths.size(); ++i) {
    EXPECT_EQ(b.paths[i].path, r.paths[i].path);
    EXPECT_EQ(b.paths[i].strategies, r.paths[i].strategies);
    expect_same_estimate(b.paths[i].estimate, r.paths[i].estimate);
  }
  EXPECT_FALSE(back->raw);
  EXPECT_EQ(histogram_json_text(b), histogram_json_text(r));
}

TEST(HistogramJson, UnknownStandardErrorIsNull) {
  Histogram h(HistogramLayout{4, {}});
  ASSERT_TRUE(h.add(h.intern("LDDDSE"), 0, Histogram::kNoStrategy, gray(1)));
  h.add_samples(0, 5);
  Result<HistogramReport> r = make_report(h, RunInfo{}, nullptr, {});
  ASSERT_TRUE(r);
  const json doc = to_json(*r);
  EXPECT_TRUE(doc["total"]["stderr"].is_null());
  Result<HistogramFile> back = histogram_from_json(doc, "h.json");
  ASSERT_TRUE(back);
  EXPECT_TRUE(std::isnan(back->report.total.std_error));
}

// Three processes each write their shard with the raw section; parsing and merging the files
// gives exactly the histogram of the whole render.
TEST(HistogramJson, RawShardsParseBackAndMergeExactly) {
  Fixture f;
  const Histogram whole = shard(0, 40);
  Histogram merged(layout());
  for (auto [begin, end] : {std::pair{0, 13}, std::pair{13, 14}, std::pair{14, 40}}) {
    const Histogram part = shard(begin, end);
    Result<HistogramFile> back = parse_histogram_json(histogram_json_text(f.report(part), &part), "shard.json");
    ASSERT_TRUE(back) << back.error().render();
    ASSERT_TRUE(back->raw);
    ASSERT_TRUE(merged.merge(*back->raw));
  }
  EXPECT_EQ(raw_to_json(merged).dump(), raw_to_json(whole).dump());
  EXPECT_EQ(histogram_json_text(f.report(merged), &merged), histogram_json_text(f.report(whole), &whole));
  const json raw = raw_to_json(whole);
  EXPECT_EQ(raw["batches"], 4);
  EXPECT_EQ(raw["batch_samples"], json::array({10, 10, 10, 10}));
  EXPECT_EQ(raw["paths"][0]["path"], "LDDDSE") << "sorted by path string";
}

TEST(HistogramJson, ErrorsNameTheJsonPointer) {
  Fixture f;
  const json good = to_json(f.report(shard(0, 40)), nullptr);
  struct Case {
    const char* pointer;
    json value;
    const char* where;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"/spp", -1, "h.json:/spp", "expected a non-negative integer"},
      {"/scene", 3, "h.json:/scene", "expected a string"},
      {"/complete", "yes", "h.json:/complete", "expected true or false"},
      {"/total/estimate", json::array({1, 2}), "h.json:/total/estimate", "expected an array of 3 elements"},
      {"/classes/1/share", "half", "h.json:/classes/1/share", "expected a number"},
      {"/paths/2/luminance", nullptr, "h.json:/paths/2/luminance", "expected a number"},
      {"/paths/0/strategies/nee (1, DD, 3)/share", json::array(), "h.json:/paths/0/strategies/nee (1, DD, 3)/share",
       "expected a number"},
      {"/classes/0/strategies/nee (1, DD, 3)/samples", -2, "h.json:/classes/0/strategies/nee (1, DD, 3)/samples",
       "expected a non-negative integer"},
      {"/paths/1/strategies", 1, "h.json:/paths/1/strategies", "expected an object of techniques"},
  };
  for (const Case& c : cases) {
    json doc = good;
    doc[json::json_pointer(c.pointer)] = c.value;
    Result<HistogramFile> r = histogram_from_json(doc, "h.json");
    ASSERT_FALSE(r) << c.pointer;
    EXPECT_EQ(r.error().code, ErrorCode::kBadFile);
    EXPECT_EQ(r.error().where, c.where);
    EXPECT_EQ(r.error().message, c.message);
  }
  json missing = good;
  missing["classes"][0].erase("expr");
  Result<HistogramFile> r = histogram_from_json(missing, "h.json");
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().where, "h.json:/classes/0");
  EXPECT_EQ(r.error().message, "missing key \"expr\"");

  Result<HistogramFile> text = parse_histogram_json("{\"scene\": ", "h.json");
  ASSERT_FALSE(text);
  EXPECT_EQ(text.error().where, "h.json:/scene");  // the value being read when the text ran out
  EXPECT_EQ(text.error().message.rfind("not valid JSON: ", 0), 0u);
}

TEST(HistogramJson, RawErrorsNameTheJsonPointer) {
  Fixture f;
  const Histogram h = shard(0, 40);
  const json good = to_json(f.report(h), &h);
  struct Case {
    const char* pointer;
    json value;
    const char* where;
    const char* message;
  };
  const std::vector<Case> cases = {
      {"/raw/format", 1, "h.json:/raw/format",
       "expected format 2 (format 1, without per-technique sums, was written by an older pathex)"},
      {"/raw/fraction_bits", 32, "h.json:/raw/fraction_bits", "expected 64"},
      {"/raw/batch_samples", json::array({1, 2}), "h.json:/raw/batch_samples", "expected an array of 4 elements"},
      {"/raw/paths/1/sums/2/1", "0x1g", "h.json:/raw/paths/1/sums/2/1",
       "expected an exact sum: \"0\" or a signed hexadecimal string such as \"0x1f\" or \"-0x1f\""},
      {"/raw/paths/2/path", "LDDDSE", "h.json:/raw/paths/2/path", "path \"LDDDSE\" appears twice"},
      {"/raw/paths/0/techniques/0/sums", json::array(), "h.json:/raw/paths/0/techniques/0/sums",
       "expected an array of 4 elements"},
      {"/raw/paths/0/techniques/1/strategy", 2, "h.json:/raw/paths/0/techniques/1/strategy",
       "expected a strategy index below 2"},
  };
  for (const Case& c : cases) {
    json doc = good;
    doc[json::json_pointer(c.pointer)] = c.value;
    Result<HistogramFile> r = histogram_from_json(doc, "h.json");
    ASSERT_FALSE(r) << c.pointer;
    EXPECT_EQ(r.error().where, c.where);
    EXPECT_EQ(r.error().message, c.message);
  }
}

}  // namespace
}  // namespace pathex
