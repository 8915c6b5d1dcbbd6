// A witness path's chains as `query` and `bias` print them: "SD(0..1) DSD(1..3)[ortho-projection]",
// each chain with its first and last letter positions and the connectors that could join it
// (`check` prints them without the connectors).
#pragma once

#include <string>
#include <vector>

#include "reach/query.h"

namespace pathex::cli {

inline std::string chains_text(const std::vector<ChainEvidence>& chains, bool connectors = true) {
  std::string s;
  for (const ChainEvidence& c : chains) {
    if (!s.empty()) s += ' ';
    s += c.chain.letters + "(" + std::to_string(c.chain.from) + ".." + std::to_string(c.chain.to) + ")";
    if (connectors && !c.connectors.empty()) {
      s += "[";
      for (std::size_t i = 0; i < c.connectors.size(); ++i) s += (i ? "|" : "") + to_string(c.connectors[i]);
      s += "]";
    }
  }
  return s;
}

}  // namespace pathex::cli
