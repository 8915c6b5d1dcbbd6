// NFA: the intermediate form between the syntax tree and the DFA.
//
// Thompson's construction turns each regular operator (letter sets, concatenation, alternation,
// repetition) into a fragment with one entry and one exit joined by ε-edges. The two operators
// that are not regular-expression primitives, intersection `&` and complement `~`, are compiled
// by first building the minimal DFA of each operand, combining those DFAs (product, complement),
// and embedding the result back as a fragment. Every state is counted against Limits::max_states
// before it is created, so `((S{1000}){1000}){1000}` stops with an error instead of allocating.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "alphabet/alphabet.h"
#include "core/error.h"
#include "core/limits.h"
#include "regex/ast.h"

namespace pathex {

struct Dfa;

struct Nfa {
  struct State {
    std::vector<std::pair<LetterMask, int>> edges;  // on any letter in the mask, go to the state
    std::vector<int> eps;                           // ε-edges
  };
  std::vector<State> states;
  int start = 0;
  int accept = 0;  // Thompson NFAs have exactly one accepting state
};

// Thompson's construction for the tree rooted at r.root.
Result<Nfa> build_nfa(const Regex& r, const Limits& limits);

// The NFA of a DFA's language read backwards (edges reversed, a new start joined to every
// accepting state): determinising it gives the reversal.
Nfa reversed_nfa(const Dfa& d);

// The image of a DFA's language under the substitution of `letter` by the alternatives `words`
// (every other letter maps to itself). Heckbert notation uses it to expand L and E.
Nfa substituted_nfa(const Dfa& d, Letter letter, const std::vector<std::string>& words);

}  // namespace pathex
