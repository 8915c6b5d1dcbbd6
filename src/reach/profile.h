// Strategies and renderer profiles (DESIGN §4).
//
// A strategy (s, chain, t) builds a light subpath and an eye subpath by local sampling and joins
// them across `chain`: s letters before it, t letters after it. Its language is
//     L [SD]{s} chain [SD]{t} E   ∩ U,
// with s and t ranges. A plain join is the chain DD (a shadow ray or a subpath hitting the other
// end); a connector joins two separators across a run of specular vertices that it constructs
// (chains DS+D). A renderer profile is data: a list of strategies and an optional bound on the
// number of interior vertices. Its reachable language R is the union of its strategies' languages
// under the bound. The tracer runs the same Profile object that the checker analyses.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "core/error.h"
#include "core/limits.h"

namespace pathex {

// A closed range lo..hi of non-negative integers; hi = kOpen for "lo..".
struct Range {
  static constexpr int kOpen = -1;
  int lo = 0;
  int hi = kOpen;
  bool contains(int v) const { return v >= lo && (hi == kOpen || v <= hi); }
  std::string to_string() const;  // "2", "0..1", "2.."
};
// Parses "3", "0..1" or "2.."; errors say what was expected.
Result<Range> parse_range(const std::string& text);

// The connector catalogue (DESIGN §5). Each entry says which chains it joins and where.
enum class ConnectorKind { kNone, kMirror, kDistantProjection, kOrthoProjection, kManifold };
std::string to_string(ConnectorKind k);  // "", "mirror", "distant-projection", "ortho-projection", "manifold"
std::optional<ConnectorKind> connector_from_string(const std::string& s);
inline constexpr ConnectorKind kCatalogue[] = {ConnectorKind::kMirror, ConnectorKind::kDistantProjection,
                                               ConnectorKind::kOrthoProjection, ConnectorKind::kManifold};
// One line: what the connector does.
std::string connector_summary(ConnectorKind k);
// Whether connector `k` can join the chain c[from..to] of a full path with k_edges edges:
//   mirror: DSD whose S is an interior vertex (planar mirror, image method);
//   distant-projection: c0..c2 = DSD (a distant light's fixed direction);
//   ortho-projection: ck..c(k+2) = DSD (an orthographic sensor's fixed direction);
//   manifold: DS+D whose S letters are all interior vertices (smooth specular surfaces).
bool connector_handles(ConnectorKind k, const std::string& chain_letters, int from, int to, int k_edges);

struct Strategy {
  std::string name;     // e.g. "emitter-hit", "nee", "light-splat", "lens-hit", "bdpt"
  Range s;              // letters before the chain
  std::string chain = "DD";  // an expression whose language is within DS*D
  Range t;              // letters after the chain
  ConnectorKind connector = ConnectorKind::kNone;
  Dfa chain_dfa;        // compiled `chain`
  std::string describe() const;  // "(0, DD, 2..)" plus the connector, if any
};

struct Profile {
  std::string name;
  std::string description;
  std::string source;             // what documented behaviour the profile models, with citations
  std::vector<Strategy> strategies;
  std::optional<int> max_bounces; // the largest k - 1
};

// Compiles a strategy's chain and checks it (chain ⊆ DS*D; S letters need a connector that
// handles such chains; connector position constraints). Errors name the offending field via
// Error::where set to the given JSON pointer prefix.
Result<bool> check_strategy(Strategy* st, const Limits& limits, const std::string& pointer);

// L [SD]{s} chain [SD]{t} E ∩ U, optionally with at most max_bounces interior vertices.
Result<Dfa> strategy_language(const Strategy& st, std::optional<int> max_bounces, const Limits& limits);
// The union of the strategies' languages: what the profile can sample.
Result<Dfa> reachable_language(const Profile& p, std::optional<int> max_bounces, const Limits& limits);
// Full paths with at most `max_bounces` interior vertices: L[SD]{4, max_bounces + 4}E.
Dfa bounded_universe(std::optional<int> max_bounces);

// Strategy membership decided directly from the definition (no automata): does the strategy
// sample this valid full path? (Used by tests as a brute-force oracle and by `query` evidence.)
bool strategy_samples(const Strategy& st, const std::string& path, std::optional<int> max_bounces);

}  // namespace pathex
