// The oracle: a deliberately naive matcher that decides membership straight from the syntax
// tree, sharing no code with the automata. m(node, i, j) says whether s[i, j) is in the node's
// language, by the definitions: concatenation tries every split, repetition every count,
// complement negates, intersection conjoins. Memoised, so strings of length ≤ 12 are cheap.
#pragma once

#include <string_view>

#include "regex/ast.h"

namespace pathex::oracle {

bool naive_match(const Regex& r, std::string_view s);

}  // namespace pathex::oracle
