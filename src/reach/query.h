// Verdicts and evidence (DESIGN §5). For a class C, a renderer profile with reachable language R
// and a universe U_s, with P = C ∩ U_s:
//   empty (P = ∅), reachable (P ⊆ R), unreachable (P ∩ R = ∅), otherwise partial,
// together with shortest witnesses on each side, counts by length, finiteness of each side, and
// for each witness the reason: the strategies that sample a reachable one; the chains of an
// unreachable one, which connectors of the catalogue could join them, and a one-line reason.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "alphabet/alphabet.h"
#include "automata/dfa.h"
#include "classify/pathclass.h"
#include "core/bigint.h"
#include "reach/profile.h"

namespace pathex {

enum class Verdict { kEmpty, kReachable, kPartial, kUnreachable };
std::string to_string(Verdict v);  // "empty", "reachable", "partial", "unreachable"

struct QueryOptions {
  std::optional<int> max_bounces;  // bounds P and overrides the profile's own bound
  std::optional<Dfa> universe;     // U_s; all of U when unset
  int witnesses = 3;               // per side
  int max_len = -1;                // counts up to this many letters; -1: max_bounces + 6, or 14
  Limits limits;
};

struct ChainEvidence {
  Chain chain;
  std::vector<ConnectorKind> connectors;  // catalogue connectors that join this chain here
};

struct Witness {
  std::string path;
  std::vector<ChainEvidence> chains;
  std::vector<std::string> strategies;  // reachable witnesses: the strategies that sample it
  std::string reason;                   // unreachable witnesses: why no strategy samples it
};

struct QueryResult {
  std::string expression;
  std::string renderer;
  Verdict verdict = Verdict::kEmpty;
  std::vector<Witness> reachable;
  std::vector<Witness> unreachable;
  int max_len = 0;
  std::vector<BigUint> counts_class, counts_reachable, counts_unreachable;  // index = letters
  bool finite_class = true, finite_reachable = true, finite_unreachable = true;
  std::optional<int> max_bounces;  // the bound in force
};

// The analysed profile: its strategies' languages and their union, under a bound.
struct CompiledProfile {
  const Profile* profile = nullptr;
  std::optional<int> max_bounces;
  std::vector<Dfa> strategy_languages;
  Dfa reachable;
};
Result<CompiledProfile> compile_profile(const Profile& p, std::optional<int> max_bounces, const Limits& limits);

Result<QueryResult> query(const PathClass& c, const CompiledProfile& r, const QueryOptions& options);

// Evidence for one path: its chains with the connectors that could join each.
std::vector<ChainEvidence> chain_evidence(const std::string& path);
// Why `path` (valid, not in R) is not sampled by the profile.
std::string unreachable_reason(const std::string& path, const CompiledProfile& r);

}  // namespace pathex
