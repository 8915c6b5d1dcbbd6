// Language operations on minimal DFAs: the boolean algebra (product construction), reversal,
// the decision questions (emptiness, inclusion, equivalence, finiteness) and the ones that
// produce evidence (shortest member, members in shortlex order, exact counts by length).
//
// Every result is minimal and canonically numbered. "Shortlex" is the order of all answers:
// shorter strings first, ties broken by ASCII order of the letters (D < E < L < S).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "core/bigint.h"

namespace pathex {

Dfa dfa_empty();                   // ∅
Dfa dfa_all();                     // every string of D E L S, ε included
Dfa dfa_universe();                // U = L[SD]{4,}E, the valid full paths
Dfa dfa_universe_bounded(int max_bounces);  // L[SD]{4, max_bounces + 4}E: at most max_bounces interior vertices
Dfa dfa_word(std::string_view w);  // {w}

Dfa dfa_union(const Dfa& a, const Dfa& b);
Dfa dfa_intersect(const Dfa& a, const Dfa& b);
Dfa dfa_difference(const Dfa& a, const Dfa& b);
Dfa dfa_complement(const Dfa& a);  // over all strings of the four letters
Result<Dfa> dfa_concat(const Dfa& a, const Dfa& b, const Limits& limits);
// Reversal can grow exponentially, so it takes the limits and may fail.
Result<Dfa> dfa_reverse(const Dfa& a, const Limits& limits);

bool is_empty(const Dfa& a);
bool is_subset(const Dfa& a, const Dfa& b);     // L(a) ⊆ L(b)
bool is_equivalent(const Dfa& a, const Dfa& b); // identical canonical minimal DFAs
bool is_finite(const Dfa& a);

// The shortlex-least member, or nullopt for the empty language.
std::optional<std::string> shortest_member(const Dfa& a);
// Members of length ≤ max_len in shortlex order, at most max_count of them.
std::vector<std::string> enumerate_members(const Dfa& a, int max_len, std::size_t max_count);
// counts[n] = exact number of members of length n, for n = 0..max_len.
std::vector<BigUint> count_by_length(const Dfa& a, int max_len);

}  // namespace pathex
