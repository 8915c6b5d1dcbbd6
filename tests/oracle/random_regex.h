// Random path expressions for the oracle and law tests: every node kind the grammar has (letters,
// `.`, positive and negated sets including the empty one, concatenation, `|`, `&`, `~`, and all
// six postfix forms with small counts), nested to a bounded depth. Output is text, so a failing
// case prints as something a person can paste into `pathex explain`, and the parser is exercised
// on the way. Deterministic: the same engine state gives the same expression on every platform
// (only std::mt19937_64 output is used, never the implementation-defined distributions).
#pragma once

#include <cstdint>
#include <random>
#include <string>

namespace pathex::oracle {

class RandomRegex {
 public:
  explicit RandomRegex(std::uint64_t seed) : rng_(seed) {}

  // An expression nested at most `depth` operators deep. Leaves get likelier towards the
  // bottom only, and concatenation and repetition dominate, so that most languages have
  // members and non-members at every length up to 10 rather than being ∅, a letter or all.
  std::string expression(int depth) { return node(depth, depth); }

 private:
  std::string node(int depth, int top) {
    if (depth <= 0 || (depth < top && below(100) < 30)) return atom();
    const std::uint64_t pick = below(100);
    if (pick < 35) return join(depth, top, "", 2 + below(2));  // concatenation of 2-3
    if (pick < 50) return join(depth, top, "|", 2 + below(2));
    if (pick < 58) return join(depth, top, "&", 2);
    if (pick < 66) return "~" + operand(depth - 1, top);
    return operand(depth - 1, top) + suffix();
  }

  std::uint64_t below(std::uint64_t n) { return rng_() % n; }

  std::string atom() {
    // Weighted by repetition; the empty set [^SD] is rare because it empties any concatenation.
    static constexpr const char* kAtoms[] = {"D", "D", "D", "S", "S", "S", "E", "L", ".", ".", ".", "[SD]",
                                             "[LE]", "[DEL]", "[^S]", "[^D]", "[^L]", "[LESD]", "[^SD]"};
    if (below(4) != 0) return kAtoms[below(std::size(kAtoms) - 1)];
    return kAtoms[below(std::size(kAtoms))];
  }
  // A sub-expression safe to put next to another or under a prefix/postfix operator.
  std::string operand(int depth, int top) {
    const std::string e = node(depth, top);
    return e.size() == 1 || e.front() == '[' ? e : "(" + e + ")";
  }
  std::string join(int depth, int top, const char* sep, std::uint64_t n) {
    std::string out = operand(depth - 1, top);
    for (std::uint64_t k = 1; k < n; ++k) out += sep + operand(depth - 1, top);
    return out;
  }
  std::string suffix() {
    const std::uint64_t n = below(4), m = n + below(3);
    const std::uint64_t kind = below(20);
    if (kind < 5) return "*";
    if (kind < 9) return "+";
    if (kind < 11) return "?";
    if (kind < 14) return "{" + std::to_string(n) + "}";
    if (kind < 17) return "{" + std::to_string(n) + ",}";
    return "{" + std::to_string(n) + "," + std::to_string(m) + "}";
  }

  std::mt19937_64 rng_;
};

}  // namespace pathex::oracle
