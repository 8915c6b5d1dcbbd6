// --max-paths: histogram.json lists the largest N paths and sums the rest exactly into one
// "other" row, and says so (max_paths, distinct_paths, the row's path count and note). The row
// must equal, bit for bit, the estimate of the same contributions recorded under one path.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "stats/histogram.h"
#include "io/histogram_json.h"

namespace pathex {
namespace {

HistogramLayout layout() { return HistogramLayout{4, {"nee", "emitter-hit"}}; }

// Path i gets contributions of size about (i + 1) in every batch, so the order is known: the
// largest paths are the last ones.
Histogram render(int paths) {
  Histogram h(layout());
  for (int i = 0; i < paths; ++i) {
    const std::string path = "L" + std::string(static_cast<std::size_t>(4 + i), 'D') + "E";
    for (int b = 0; b < 4; ++b) {
      const double v = (i + 1) * (1.0 + 0.01 * b) + 1e-7 * i;
      EXPECT_TRUE(h.add(h.intern(path), b, Technique{(i + b) % 2, 1, 3, false}.code(), {v, 0.5 * v, 0.25 * v}));
    }
  }
  for (int b = 0; b < 4; ++b) h.add_samples(b, 100);
  return h;
}

TEST(MaxPaths, TheRestIsSummedExactlyIntoOneOtherRow) {
  const Histogram h = render(10);
  Result<HistogramReport> all = make_report(h, RunInfo{}, nullptr, {});
  Result<HistogramReport> cut = make_report(h, RunInfo{}, nullptr, {}, /*max_paths=*/3);
  ASSERT_TRUE(all && cut);
  EXPECT_EQ(all->distinct_paths, 10u);
  EXPECT_EQ(cut->distinct_paths, 10u);
  EXPECT_FALSE(all->other);
  ASSERT_EQ(cut->paths.size(), 3u);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(cut->paths[static_cast<std::size_t>(i)].path, all->paths[static_cast<std::size_t>(i)].path);
  EXPECT_EQ(cut->paths[0].path, "L" + std::string(13, 'D') + "E");  // the largest: path 9
  ASSERT_TRUE(cut->other);
  EXPECT_EQ(cut->other_paths, 7u);
  EXPECT_EQ(cut->other->path, "other");
  // The same contributions with the seven smallest paths (0..6) recorded under one path give
  // exactly the same estimate: the sums are exact.
  Histogram merged(layout());
  for (int i = 0; i < 10; ++i) {
    const std::string path = i < 7 ? "LSSSSE" : "L" + std::string(static_cast<std::size_t>(4 + i), 'D') + "E";
    for (int b = 0; b < 4; ++b) {
      const double v = (i + 1) * (1.0 + 0.01 * b) + 1e-7 * i;
      ASSERT_TRUE(merged.add(merged.intern(path), b, Technique{(i + b) % 2, 1, 3, false}.code(), {v, 0.5 * v, 0.25 * v}));
    }
  }
  for (int b = 0; b < 4; ++b) merged.add_samples(b, 100);
  Result<HistogramReport> m = make_report(merged, RunInfo{}, nullptr, {});
  ASSERT_TRUE(m);
  const PathEstimate* lumped = nullptr;
  for (const PathEstimate& p : m->paths)
    if (p.path == "LSSSSE") lumped = &p;
  ASSERT_NE(lumped, nullptr);
  EXPECT_EQ(cut->other->estimate.rgb, lumped->estimate.rgb);
  EXPECT_EQ(cut->other->estimate.luminance, lumped->estimate.luminance);
  EXPECT_EQ(cut->other->estimate.std_error, lumped->estimate.std_error);
  EXPECT_EQ(cut->other->estimate.samples, 28u);  // 7 paths × 4 batches
  EXPECT_EQ(cut->other->strategies, lumped->strategies);
  // The total does not depend on the cut.
  EXPECT_EQ(cut->total.luminance, all->total.luminance);
}

TEST(MaxPaths, NoOtherRowWhenEveryPathFits) {
  Result<HistogramReport> r = make_report(render(5), RunInfo{}, nullptr, {}, /*max_paths=*/5);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->paths.size(), 5u);
  EXPECT_FALSE(r->other);
  const nlohmann::ordered_json doc = to_json(*r);
  EXPECT_EQ(doc["max_paths"], 5);
  EXPECT_EQ(doc["distinct_paths"], 5);
  EXPECT_EQ(doc["paths"].size(), 5u);
}

TEST(MaxPaths, TheJsonSaysSoAndRoundTrips) {
  Result<HistogramReport> r = make_report(render(10), RunInfo{}, nullptr, {}, /*max_paths=*/3);
  ASSERT_TRUE(r);
  const nlohmann::ordered_json doc = to_json(*r);
  EXPECT_EQ(doc["max_paths"], 3);
  EXPECT_EQ(doc["distinct_paths"], 10);
  ASSERT_EQ(doc["paths"].size(), 4u);
  const auto& other = doc["paths"][3];
  EXPECT_EQ(other["path"], "other");
  EXPECT_EQ(other["paths"], 7);
  EXPECT_EQ(other["note"], "the sum of the 7 paths past the first 3 (--max-paths)");
  Result<HistogramFile> back = parse_histogram_json(histogram_json_text(*r), "h.json");
  ASSERT_TRUE(back) << back.error().render();
  EXPECT_EQ(back->report.paths.size(), 3u);
  ASSERT_TRUE(back->report.other);
  EXPECT_EQ(back->report.other_paths, 7u);
  EXPECT_EQ(back->report.distinct_paths, 10u);
  EXPECT_EQ(back->report.max_paths, std::optional<std::uint64_t>(3));
  EXPECT_EQ(histogram_json_text(back->report), histogram_json_text(*r));
}

TEST(MaxPaths, UnboundedReportWritesNull) {
  Result<HistogramReport> r = make_report(render(2), RunInfo{}, nullptr, {});
  ASSERT_TRUE(r);
  EXPECT_TRUE(to_json(*r)["max_paths"].is_null());
}

}  // namespace
}  // namespace pathex
