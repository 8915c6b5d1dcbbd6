// The strategies a render runs, as one table keyed by (s, chain, t) (DESIGN §4, §7).
//
// A strategy of a profile joins s letters' worth of light subpath to t letters' worth of eye
// subpath by a chain: the plain join DD (ConnectorKind::kNone) or a connector's DSD (mirror,
// distant projection, ortho projection) or the manifold's DS+D. The tracer asks, for every join it could make, which
// strategy of the profile runs it; the answer is an index into the strategy list the table was
// built from, or -1. Build it from a reduced strategy list (a pruned profile) and the tracer runs
// only those strategies: nothing else in the tracer knows which strategies exist.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "reach/profile.h"

namespace pathex {

class StrategyTable {
 public:
  // s and t range over 0 … kMaxSide - 1 (a full path's letters are bounded well below it).
  static constexpr int kMaxSide = 128;

  StrategyTable() : slots_(kChains * kMaxSide * kMaxSide, -1) {}
  // The first strategy in `strategies` whose chain, s range and t range contain each key.
  explicit StrategyTable(const std::vector<Strategy>& strategies) : StrategyTable() {
    for (const ConnectorKind chain : {ConnectorKind::kNone, ConnectorKind::kMirror, ConnectorKind::kDistantProjection,
                                      ConnectorKind::kOrthoProjection, ConnectorKind::kManifold})
      for (int s = 0; s < kMaxSide; ++s)
        for (int t = 0; t < kMaxSide; ++t)
          for (std::size_t i = 0; i < strategies.size(); ++i) {
            const Strategy& st = strategies[i];
            if (st.connector != chain || !st.s.contains(s) || !st.t.contains(t)) continue;
            slots_[index(s, chain, t)] = static_cast<std::int16_t>(i);
            break;
          }
    for (int n = 0; n < kMaxSplits; ++n)
      for (int s = 0; s <= n; ++s)
        if (plain(s, n - s) >= 0) splits_[static_cast<std::size_t>(n)] |= std::uint64_t{1} << s;
  }

  // The strategy running `chain` with s letters before it and t after it, or -1 (also for s or t
  // outside the table).
  int at(int s, ConnectorKind chain, int t) const {
    return static_cast<unsigned>(s) < kMaxSide && static_cast<unsigned>(t) < kMaxSide && static_cast<std::size_t>(chain) < kChains
               ? slots_[index(s, chain, t)]
               : -1;
  }
  // Shorthand for the plain join (s, DD, t).
  int plain(int s, int t) const { return at(s, ConnectorKind::kNone, t); }
  // The plain joins of a path of n < kMaxSplits vertices: bit s set when (s, DD, n - s) is run.
  static constexpr int kMaxSplits = 64;
  std::uint64_t plain_splits(int n) const { return splits_[static_cast<std::size_t>(n)]; }
  // Whether any (s, chain, t) is run, and any (s, chain, t) for this t.
  bool runs(ConnectorKind chain) const {
    for (int t = 0; t < kMaxSide; ++t)
      if (runs_at_t(chain, t)) return true;
    return false;
  }
  bool runs_at_t(ConnectorKind chain, int t) const {
    for (int s = 0; s < kMaxSide; ++s)
      if (at(s, chain, t) >= 0) return true;
    return false;
  }

 private:
  static constexpr std::size_t kChains = 5;  // kNone, kMirror, kDistantProjection, kOrthoProjection, kManifold
  static std::size_t index(int s, ConnectorKind chain, int t) {
    return (static_cast<std::size_t>(chain) * kMaxSide + static_cast<std::size_t>(s)) * kMaxSide + static_cast<std::size_t>(t);
  }
  static_assert(static_cast<std::size_t>(ConnectorKind::kManifold) + 1 == kChains, "one slot block per keyed chain");
  std::vector<std::int16_t> slots_;  // [chain][s][t]
  std::array<std::uint64_t, kMaxSplits> splits_{};
};

}  // namespace pathex
