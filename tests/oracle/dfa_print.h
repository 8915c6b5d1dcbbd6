// How GoogleTest prints a Dfa in a failed EXPECT_EQ: the table, one state per line, instead of
// the default byte dump. Found by argument-dependent lookup, hence in namespace pathex.
#pragma once

#include <ostream>

#include "automata/dfa.h"

namespace pathex {

inline void PrintTo(const Dfa& d, std::ostream* os) {
  *os << "Dfa with " << d.num_states << " states, start " << d.start << ":";
  for (int s = 0; s < d.num_states; ++s) {
    *os << "\n    " << s << (d.accept[static_cast<std::size_t>(s)] ? " accept:" : ":");
    for (int l = 0; l < kNumLetters; ++l) *os << " " << letter_char(l) << "->" << d.step(s, l);
  }
}

}  // namespace pathex
