// The way back from a path class to a light path expression, for an Arnold, RenderMan or Karma AOV,
// and to a readable full-path expression.
//
// An LPE's C and L stand for every sensor and light type, so what an LPE can say about a full path
// L c0 c1 w c(k+1) c(k+2) E is its interior w alone. The closest LPE to a class is therefore the
// one whose interior language is the union, over the class's light and sensor pairs, of the
// interiors the class allows: the smallest LPE language that contains the class. It is built on
// the class's minimal DFA (the interiors read camera first, as an automaton), written out by state
// elimination (automata/to_regex.h) with D as [DG] (diffuse or glossy: both are pathex's D) and S
// as S, and ended by [LO] when the class has area lights (a renderer may count an emissive
// surface as a light or as an emissive object) or by L otherwise.
//
// The result is checked the way a user would check it: the LPE is read back with
// `--notation lpe` (all light and sensor types) and its class compared with the original. Equal
// minimal DFAs make it exact; otherwise it is approximate, and the losses say which light or
// sensor types, or which ties between interior letters and end types, the LPE cannot keep.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "core/error.h"
#include "core/limits.h"

namespace pathex {

struct LpeEmission {
  bool empty = false;                      // the class has no path: there is nothing to select
  std::string lpe;                         // camera first, e.g. C[DGS]*[DG]S+[LO]
  bool exact = false;                      // read back, it is the same class
  std::vector<std::string> losses;         // one sentence per thing lost (approximate only)
  std::optional<std::string> example;      // the shortest path the LPE adds (approximate only)
};

// Limits bound the automata built; the expression is refused past 2000 live states or 100000
// nodes (errors say so).
Result<LpeEmission> emit_lpe(const Dfa& cls, const Limits& limits);

// The class as a full-path expression written from its DFA, with the light and sensor letter
// pairs factored out of the interior: `L..S+D.*..E` rather than an automaton's tangle of the
// last two letters. What `explain --notation lpe` shows as an LPE's translation. "" when empty.
Result<std::string> full_path_expression(const Dfa& cls, const Limits& limits);

}  // namespace pathex
