// JSON forms of what the commands that read path classes print (`pathex explain --json`, `explain
// --emit lpe --json`, `pathex classify --json`), at the edge so that classify/ and language/ do not
// include nlohmann. Keys are stable and documented in docs/expressions.md.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/bigint.h"
#include "language/lpe_emit.h"

namespace pathex {

// What `pathex explain` knows about one class.
struct ClassFacts {
  std::string expression;   // as written
  std::string normal_form;  // the class as an expression (for an LPE: the full-path form)
  std::string notation;     // "full", "heckbert" or "lpe"
  bool eye_first = false;
  int dfa_states = 0;
  int live_states = 0;
  bool empty = false;
  bool finite = false;
  std::vector<BigUint> counts;  // members by length, index = letters, up to max_len
  int max_len = 0;
  std::vector<std::string> shortest_members;
};

// {expression, normal_form, notation, eye_first, dfa_states, live_states, empty, finite,
// counts_by_length [{length, count}], max_len, shortest_members [{path, chains [{letters, from, to}]}]}.
std::string explain_json_text(const ClassFacts& facts);

// {expression, notation, lpe (null for an empty class), exact, losses, example}.
std::string lpe_json_text(const std::string& expression, const std::string& notation, const LpeEmission& emission);

// One line of `classify --json` (no newline): {line, path, classes} or, for a malformed path,
// {line, path, error}. Bytes of `path` that are not UTF-8 are written as U+FFFD.
std::string classify_json_line(std::size_t line, const std::string& path, const std::vector<std::string>& classes);
std::string classify_error_json_line(std::size_t line, const std::string& path, const std::string& error);

}  // namespace pathex
