// The tracer's one strategy table, keyed by (s, chain, t): built from a profile's strategy list,
// or from any sublist of it (a pruned profile), it answers which strategy runs each join.
#include "trace/strategy_table.h"

#include <gtest/gtest.h>

#include "io/profile_json.h"

namespace pathex {
namespace {

Profile profile(const char* name) { return resolve_profile(name, Limits{}).expect("a built-in profile"); }

TEST(StrategyTable, KeysPlainJoinsAndConnectorsApart) {
  const Profile p = profile("bdpt+mirror");  // bdpt (0.., DD, 0..), mirror (1.., DSD, 1..)
  const StrategyTable table(p.strategies);
  EXPECT_EQ(table.plain(0, 2), 0);
  EXPECT_EQ(table.plain(3, 0), 0);
  EXPECT_EQ(table.at(1, ConnectorKind::kMirror, 1), 1);
  EXPECT_EQ(table.at(4, ConnectorKind::kMirror, 7), 1);
  // Where the profile says a mirror cannot stand: on the light's or the sensor's letters.
  EXPECT_EQ(table.at(0, ConnectorKind::kMirror, 3), -1);
  EXPECT_EQ(table.at(3, ConnectorKind::kMirror, 0), -1);
  EXPECT_EQ(table.at(2, ConnectorKind::kDistantProjection, 2), -1);
  EXPECT_TRUE(table.runs(ConnectorKind::kMirror));
  EXPECT_FALSE(table.runs(ConnectorKind::kOrthoProjection));
  // Outside the table: no strategy, no out-of-range read.
  EXPECT_EQ(table.plain(-1, 2), -1);
  EXPECT_EQ(table.plain(2, StrategyTable::kMaxSide), -1);
  EXPECT_EQ(table.at(1, ConnectorKind::kManifold, 1), -1);
}

TEST(StrategyTable, PlainSplitsAreThePlainJoinsOfAPathsLength) {
  // pt-nee joins a path of n vertices at s = 0 (its last vertex on a light) and s = 1 (next-event
  // estimation); bdpt at every split, t = 0 (a light path on the lens) included.
  EXPECT_EQ(StrategyTable(profile("pt-nee").strategies).plain_splits(4), 0b11u);
  EXPECT_EQ(StrategyTable(profile("bdpt").strategies).plain_splits(3), 0b1111u);
  for (const char* name : {"pt-nee", "bdpt", "lt", "bdpt+mirror"}) {
    const StrategyTable table(profile(name).strategies);
    for (int n = 0; n < StrategyTable::kMaxSplits; ++n)
      for (int s = 0; s < StrategyTable::kMaxSplits; ++s)
        EXPECT_EQ((table.plain_splits(n) >> s) & 1, s <= n && table.plain(s, n - s) >= 0 ? 1u : 0u) << name << " n " << n << " s " << s;
  }
}

TEST(StrategyTable, ManifoldChainsAreKeyedByTheirEnds) {
  const Profile p = profile("pt-nee+manifold");  // emitter-hit, nee, manifold-nee (1, DS+D, 2..)
  const StrategyTable table(p.strategies);
  EXPECT_EQ(table.at(1, ConnectorKind::kManifold, 2), 2);
  EXPECT_EQ(table.at(1, ConnectorKind::kManifold, 9), 2);
  EXPECT_EQ(table.at(1, ConnectorKind::kManifold, 1), -1);
  EXPECT_EQ(table.at(2, ConnectorKind::kManifold, 2), -1);
  EXPECT_TRUE(table.runs(ConnectorKind::kManifold));
  EXPECT_FALSE(table.runs(ConnectorKind::kMirror));
}

TEST(StrategyTable, ProjectionConnectorsSitAtThePathsEnds) {
  const Profile p = profile("pt-nee+distant");  // emitter-hit (0, DD, 2..), nee (1, DD, 2..), (0, DSD, 2..)
  const StrategyTable table(p.strategies);
  EXPECT_EQ(table.plain(0, 2), 0);
  EXPECT_EQ(table.plain(1, 5), 1);
  EXPECT_EQ(table.plain(2, 2), -1);
  EXPECT_EQ(table.at(0, ConnectorKind::kDistantProjection, 2), 2);
  EXPECT_EQ(table.at(0, ConnectorKind::kDistantProjection, 1), -1);
  EXPECT_EQ(table.at(1, ConnectorKind::kDistantProjection, 2), -1);
}

TEST(StrategyTable, AReducedStrategyListRunsOnlyWhatItKeeps) {
  Profile p = profile("bdpt");
  const StrategyTable full(p.strategies);
  ASSERT_GE(full.plain(2, 2), 0);
  // A pruned profile: bdpt without the joins of two or more light vertices.
  for (Strategy& st : p.strategies) st.s = Range{0, 1};
  const StrategyTable reduced(p.strategies);
  EXPECT_EQ(reduced.plain(1, 2), full.plain(1, 2));
  EXPECT_EQ(reduced.plain(2, 2), -1);
  EXPECT_EQ(reduced.plain(5, 0), -1);
}

}  // namespace
}  // namespace pathex
