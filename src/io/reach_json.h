// JSON forms of the checker's answers, at the edge so that reach/ does not include nlohmann.
// Keys are stable and documented in README "Output formats".
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "reach/profile.h"
#include "reach/query.h"

namespace pathex {

nlohmann::json to_json(const QueryResult& q);
nlohmann::json to_json(const ChainEvidence& c);
// {path, chains, strategies} for a reachable witness, {path, chains, reason} for an unreachable one.
nlohmann::json to_json(const Witness& w);
nlohmann::json to_json(const Strategy& s);
// A decimal count: a number when it fits 64 bits, else a string of digits.
nlohmann::json count_json(const BigUint& b);

// `pathex query --json`: every result, row by row (a class against each renderer), each with
// "scene" when one was given.
std::string query_json_text(const std::vector<std::vector<QueryResult>>& rows, const std::string& scene);

// What `pathex renderers` says of one profile: its strategies and what it reaches.
struct ProfileReach {
  const Profile* profile = nullptr;
  int dfa_states = 0;                 // of its reachable language
  std::string relation;               // to the local paths L.*DD.*E, in words
  bool equals_local = false;
  std::vector<std::string> shortest_unreachable;
};
// `pathex renderers --json`: [{name, description, source, max_bounces, strategies, reachable
// {dfa_states, relation, equals_local, shortest_unreachable}}].
std::string renderers_json_text(const std::vector<ProfileReach>& profiles);

}  // namespace pathex
