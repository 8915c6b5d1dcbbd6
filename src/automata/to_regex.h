// DFA -> regular expression, by state elimination (Brzozowski and McCluskey): the way back from
// an automaton to something a person can read or paste into another tool.
//
// The automaton's live states become a generalised NFA whose edges carry expressions; a new start
// and a new final state are added, and the other states are removed one at a time, cheapest first
// (fewest in x out edges, weighted by the size of the expressions they carry), each removal
// rerouting p -> q -> r as p (q-loop)* r. What is left on the edge from start to final denotes
// exactly the automaton's language. The smart constructors simplify as they build (sets merge,
// x x* becomes x+, ε absorbs into ?), so small automata give small expressions; the result is
// correct whatever their order, and the tests compile it back and compare minimal DFAs.
//
// Printing is separate: to_full_notation() writes pathex syntax (grammar/pathex.ebnf); the LPE
// emitter (language/lpe_emit.h) writes the same tree as LPE events.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "alphabet/alphabet.h"
#include "automata/dfa.h"
#include "core/error.h"

namespace pathex {

struct Expr {
  enum class Kind : std::uint8_t {
    kEmpty,  // ∅ (only ever the whole expression: the empty language)
    kEps,    // the empty string
    kSet,    // one letter from `mask`
    kCat,    // the kids in sequence (at least two)
    kAlt,    // union of the kids (at least two; none nullable: ε is written as kOpt)
    kStar,   // kid*
    kPlus,   // kid+
    kOpt,    // kid? (kid not nullable)
  };
  Kind kind = Kind::kEmpty;
  LetterMask mask = 0;
  std::vector<Expr> kids;
  int size = 1;  // nodes in the tree

  bool operator==(const Expr& o) const { return kind == o.kind && mask == o.mask && kids == o.kids; }
};

bool nullable(const Expr& e);

// The language of `d` as an expression. Fails with kLimit when the automaton has more than
// `max_states` live states or an intermediate expression grows past `max_nodes` nodes.
Result<Expr> dfa_to_expr(const Dfa& d, int max_states, int max_nodes);

// How a printer writes the tree. One printer serves both notations; the style says what differs.
struct ExprStyle {
  std::string (*atom)(LetterMask mask) = nullptr;  // the text of a letter set, one item
  bool alternation_binds_items = false;  // LPE: '|' joins single items, so every union is (a|b)
  const char* optional = "?";            // the suffix of kOpt ("{0,1}" where '?' does not exist)
  int min_run = 5;                       // runs of at least this many equal items print as x{n}
};
std::string print_expr(const Expr& e, const ExprStyle& style);

// Pathex syntax, fewest parentheses: `L..S+D.*..E`. Runs of five or more equal items print as
// x{n} (x{n,} when a + or * follows). An ε-only or empty expression prints as "".
std::string to_full_notation(const Expr& e);

}  // namespace pathex
