// The per-thread table from (packed path, technique) to histogram ids and technique rows
// (trace/accel/path_ids.h): the ids and rows are the histogram's own, given in order of first
// sight, and every contribution counted in a slot reaches the histogram's row exactly once.
#include "trace/accel/path_ids.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

namespace pathex::accel {
namespace {

// "L" + n letters (bit i of `bits`: S, else D) + "E".
std::string path_of(int n, unsigned bits) {
  std::string s = "L";
  for (int i = 0; i < n; ++i) s += ((bits >> i) & 1u) ? 'S' : 'D';
  return s + "E";
}

template <typename Ids>
void check_against_histogram(Ids& ids) {
  Histogram hist;
  Histogram reference;
  std::vector<std::vector<int>> expected_rows;
  // 600 strings of 3 to 9 letters, each seen under three techniques, every pair many times: the
  // table grows past its first 256 slots several times.
  const int techniques[] = {Technique{0, 1, 2, false}.code(), Technique{0, 2, 1, false}.code(), Technique{1, 1, 1, true}.code()};
  std::vector<std::uint64_t> counts;
  for (int round = 0; round < 5; ++round)
    for (int p = 0; p < 600; ++p) {
      const std::string path = path_of(3 + p % 7, static_cast<unsigned>(p * 37));
      for (int k = 0; k < 3; ++k) {
        const auto [id, row] = ids.get(hist, pack(path), techniques[k]);
        const Histogram::PathId ref_id = reference.intern(path);
        const int ref_row = reference.technique_row(ref_id, techniques[k]);
        ASSERT_EQ(id, ref_id) << path;
        ASSERT_EQ(row, ref_row) << path;
        if (static_cast<std::size_t>(ref_row) >= counts.size()) counts.resize(static_cast<std::size_t>(ref_row) + 1, 0);
        ++counts[static_cast<std::size_t>(ref_row)];
      }
    }
  ids.flush(hist);
  ASSERT_EQ(hist.num_paths(), reference.num_paths());
  ASSERT_EQ(hist.num_rows(), reference.num_rows());
  for (int r = 0; r < hist.num_rows(); ++r) {
    EXPECT_EQ(hist.row(r).technique, reference.row(r).technique);
    EXPECT_EQ(hist.row(r).contributions, counts[static_cast<std::size_t>(r)]) << r;
  }
  // A second flush adds nothing.
  ids.flush(hist);
  for (int r = 0; r < hist.num_rows(); ++r) EXPECT_EQ(hist.row(r).contributions, counts[static_cast<std::size_t>(r)]);
}

TEST(PathIds, GivesTheHistogramsIdsAndRowsAndCountsEveryContributionOnce) {
  PathIds ids;
  check_against_histogram(ids);
}

TEST(PathIds, HandsCountsOverBeforeTheyWrap) {
  // A slot that reaches its limit hands its count to the histogram at once (the default limit is
  // 2^32 - 1, which a test cannot reach): the totals are the same.
  PathIds ids(/*flush_at=*/2);
  check_against_histogram(ids);
}

TEST(PathIds, UnpackInvertsPack) {
  for (const std::string s : {"LDE", "LSDSE", "LDDDDDDDDDSE", "LSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSSE"})
    EXPECT_EQ(unpack(pack(s)), s);
}

}  // namespace
}  // namespace pathex::accel
