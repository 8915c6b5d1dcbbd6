// DFA: the automaton every analysis runs on.
//
// A Dfa is always complete (every state has a transition on each of the four letters; a dead
// state absorbs what can no longer match) and, once it leaves this module, minimal and
// canonically numbered: states are numbered in breadth-first order from the start, visiting
// letters in ASCII order D E L S. Minimal complete DFAs are unique up to renumbering, so with
// this numbering two expressions denote the same language exactly when their Dfas compare
// equal. The transition table has four columns, one dependent load per letter.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "core/limits.h"
#include "automata/nfa.h"
#include "regex/ast.h"

namespace pathex {

struct Dfa {
  int num_states = 0;
  int start = 0;
  std::vector<std::int32_t> next;    // next[s * 4 + letter]
  std::vector<std::uint8_t> accept;  // 1 if s is accepting

  int step(int s, int letter) const { return next[static_cast<std::size_t>(s) * kNumLetters + letter]; }
  bool accepts(std::string_view letters) const;  // characters outside D E L S are rejected
  bool operator==(const Dfa& o) const {
    return num_states == o.num_states && start == o.start && next == o.next && accept == o.accept;
  }
  // States from which an accepting state can be reached ("live"); the rest are dead.
  std::vector<std::uint8_t> live() const;
  int live_count() const;
};

// Subset construction, stopping with a kLimit error past limits.max_states DFA states.
Result<Dfa> determinize(const Nfa& n, const Limits& limits);
// Partition refinement: the coarsest partition of states 0..n-1 that refines `labels` and is
// respected by the transition table `next` (stride kNumLetters). Returns each state's block;
// *blocks receives the number of blocks. minimize() and the multi-class classifier share it.
std::vector<int> refine_partition(const std::vector<std::int32_t>& next, const std::vector<int>& labels,
                                  int* blocks);
// Minimisation by partition refinement, then canonical renumbering (see above).
Dfa minimize(const Dfa& d);
// AST -> Thompson NFA -> subset DFA -> minimal canonical DFA: the language of the expression as
// written, over all strings of the four letters (no universe applied).
Result<Dfa> compile(const Regex& r, const Limits& limits);

// Graphviz of the DFA; the dead state and edges into it are left out.
std::string to_dot(const Dfa& d, const std::string& title);

}  // namespace pathex
