// Explicit size limits. Every stage that could grow without bound checks one of these and fails
// with ErrorCode::kLimit naming the limit and the CLI option that raises it, instead of hanging or
// exhausting memory. Defaults are chosen so that every realistic path class fits with room to spare
// while a pathological one, such as (S|D)*S(S|D){40} whose DFA has 2^41 states, fails in well
// under a second.
#pragma once

#include <cstddef>
#include <string>

namespace pathex {

struct Limits {
  std::size_t max_states = 100000;   // --max-states: states of any NFA or DFA built
  int max_depth = 100;               // --max-depth: nesting depth of parentheses and operators
  int max_repeat = 1000;             // --max-repeat: the largest n or m in {n}, {n,}, {n,m}
  std::size_t max_length = 100000;   // --max-length: letters in one full-path string
};

// "the DFA exceeds the limit of 100000 states (raise it with --max-states)" and friends.
std::string limit_message(const std::string& what, std::size_t limit, const std::string& unit,
                          const std::string& option);

}  // namespace pathex
