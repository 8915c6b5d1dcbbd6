// The expression syntax tree: one central representation, stored in an arena (a vector of nodes
// addressed by index) so that trees are plain values that copy, compare and free as a whole.
//
// Every node denotes a language over the four letters D E L S. The universe U = L[SD]{4,}E is
// applied later, when an expression becomes a path class; here `~x` is the complement over all
// strings of the four letters.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "alphabet/alphabet.h"

namespace pathex {

enum class NodeKind : std::uint8_t {
  kSet,     // one letter from `mask`: a letter `S`, `.` (= [SD]), a set `[SD]` or `[^S]`
  kConcat,  // the children in sequence; at least two
  kAlt,     // union of the children `a|b|…`; at least two
  kAnd,     // intersection of the children `a&b&…`; at least two
  kNot,     // complement `~a` of the single child over all strings of D E L S
  kRepeat,  // the single child repeated min..max times; max = kUnbounded for `*`, `+`, `{n,}`
};

inline constexpr int kUnbounded = -1;

struct Node {
  NodeKind kind = NodeKind::kSet;
  LetterMask mask = 0;         // kSet only
  int min = 0, max = 0;        // kRepeat only
  std::vector<int> kids;       // indices into Regex::nodes
  int column = 0;              // 1-based column of the token that made the node (0 if synthetic)
  int height = 1;              // 1 + the largest child height; bounded by Limits::max_depth
};

struct Regex {
  std::vector<Node> nodes;
  int root = -1;
  std::string source;  // the text it was parsed from

  const Node& at(int i) const { return nodes[static_cast<std::size_t>(i)]; }
  int add(Node n);
  // Copies the tree of `other` rooted at `other_root` into this arena; returns the new index.
  int graft(const Regex& other, int other_root);
};

// The tree of the reversed language: concatenations run backwards, everything else is kept
// (reversal commutes with union, intersection, complement and repetition).
Regex reversed(const Regex& r);

// An S-expression dump that shows the tree's exact shape, for the grammar corpus and tests:
// `LD*E` -> `cat{L star{D} E}`; sets print as `[DS]`, `.` as `[DS]`, repeats as `rep{2,4 x}`.
std::string dump(const Regex& r);
std::string dump(const Regex& r, int node);

// The expression re-printed with whitespace removed and the fewest parentheses that keep its
// meaning: the normal form `pathex explain` shows. Parsing the result gives an equal dump.
std::string to_string(const Regex& r);

}  // namespace pathex
