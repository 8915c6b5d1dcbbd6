// JSON forms of the checker's answers, at the edge so that reach/ does not include nlohmann.
// Keys are stable and documented in README "Output formats".
#pragma once

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

}  // namespace pathex
