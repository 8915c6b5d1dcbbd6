// FNV-1a over a vector of ints: the key hash of the subset construction (sets of NFA states) and
// of the classifier's product construction (tuples of DFA states).
#pragma once

#include <cstddef>
#include <vector>

namespace pathex {

struct IntVectorHash {
  std::size_t operator()(const std::vector<int>& v) const {
    std::size_t h = 1469598103934665603ULL;
    for (int x : v) h = (h ^ static_cast<std::size_t>(x)) * 1099511628211ULL;
    return h;
  }
};

}  // namespace pathex
