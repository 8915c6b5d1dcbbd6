// The oracle: membership decided straight from the syntax tree by the definitions of the
// operators, sharing no code with the automata. Two formulations that check each other:
//
// - naive_match(r, s): one string at a time. m(node, i, j) says whether s[i, j) is in the node's
//   language; concatenation tries every split, repetition every count, complement negates,
//   intersection conjoins. Memoised, so strings of length ≤ 12 are cheap.
//
// - TrieMatcher: the same relation, computed bottom-up and incrementally so that every string up
//   to length 10 (1,398,101 of them) can be checked against an automaton in seconds. For each
//   node it keeps, per end position j, a bitmask over start positions i of "s[i, j) is in the
//   node's language". Appending the letter at position p computes column p + 1 of every node
//   from the children's columns ≤ p + 1; columns ≤ p stay valid, so a depth-first walk over the
//   trie of all strings does one column of work per trie edge.
//
// The tree is compiled into a straight-line program over such rows, one operation per
// definition (set, or, and, not, concatenation of two rows, the empty word, Kleene star); the
// comment on each operation in naive_matcher.cpp is its proof. push() runs it one string at a
// time. walk() visits every string up to the maximum length and runs the same operations on
// sixteen strings at once (a trie node's 16 grandchildren, in the 16 lanes of a vector), which is
// what makes 2000 expressions × 1.4 M strings affordable. The tests check walk() against push()
// and push() against naive_match().
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "regex/ast.h"

namespace pathex::oracle {

bool naive_match(const Regex& r, std::string_view s);

class TrieMatcher {
 public:
  static constexpr int kMaxLength = 15;  // start positions 0..15 fit a 16-bit mask

  // Strings up to `max_length` letters (≤ kMaxLength). Counted repetition saturates at
  // max_length + 1 copies, which is exact for strings that short (see the .cpp).
  TrieMatcher(const Regex& r, int max_length);

  // The string is now s[0, p] with s[p] = `letter`: computes column p + 1. Columns 0..p must be
  // those of the current prefix s[0, p), i.e. the previous call was for p - 1 (or p = 0).
  void push(int p, Letter letter);
  // Whether s[0, len) is in the language; len ≤ 1 + the p of the last push (len = 0: the empty
  // string).
  bool matches(int len) const { return (rows_[static_cast<std::size_t>(len) * num_rows_ + root_] & 1u) != 0; }
  // Every string of length ≤ max_length in depth-first (prefix) order, ε first, each one
  // extending the previously visited string of length len − 1 by `last`:
  // visit(len, last, member). For len = 0, `last` is meaningless. Uses the columns that push()
  // uses, so mixing the two needs a push from p = 0 again afterwards.
  template <class Visit>
  void walk(Visit&& visit) {
    visit(0, kD, matches(0));
    if (max_length_ > 0) walk_from(0, visit);
  }
  // Number of program operations (for tests and cost estimates).
  std::size_t program_size() const { return ops_.size(); }

 private:
  enum class Op : std::uint8_t { kSet, kOr, kAnd, kNot, kCat, kEps, kStar };
  struct Instr {
    Op op;
    std::uint8_t mask;     // kSet: letters
    std::uint32_t out;     // row written
    std::uint32_t a, b;    // rows read (kCat: out[j] = OR over m in b[j] of a[m]; kStar: a = child)
  };
  std::uint32_t emit(Op op, std::uint32_t a, std::uint32_t b, std::uint8_t mask = 0);
  std::uint32_t compile(const Regex& r, int node);
  std::uint16_t& at(std::uint32_t row, int j) {
    return rows_[static_cast<std::size_t>(j) * num_rows_ + row];
  }
  void column(int j);

  // --- walk(): sixteen strings at once ---
  // A trie node at depth q (the current string P = s[0, q), columns 0..q in rows_) computes
  // columns q + 1 and q + 2 for the strings P a b, a and b over D E L S, lane 4a + b; in column
  // q + 1 the four lanes of one a are equal (the strings P a). Columns ≤ q are shared by all
  // lanes and read from rows_; columns q + 1, q + 2 are read lane-wise from lanes_.
  // A view of 16 consecutive words of a std::vector<std::uint16_t>: hence under-aligned
  // (unaligned loads and stores) and may_alias.
  typedef std::uint16_t Lanes __attribute__((vector_size(32), aligned(2), may_alias));
  static Lanes& view(std::vector<std::uint16_t>& words, std::size_t i) {
    return *reinterpret_cast<Lanes*>(words.data() + 16 * i);
  }
  Lanes& lanes(std::uint32_t row, int j) { return view(lanes_, static_cast<std::size_t>(j) * num_rows_ + row); }
  // Column j ≤ q of the current string, broadcast to all lanes.
  Lanes& shared(std::uint32_t row, int j) { return view(shared_, static_cast<std::size_t>(j) * num_rows_ + row); }
  static unsigned any_lane(const Lanes& x);  // bit m set if some lane has bit m
  static void broadcast(Lanes& out, std::uint16_t v) {
    for (int x = 0; x < 16; ++x) out[x] = v;
  }
  void column16(int j, int q);
  // Makes P a b (lane x = 4a + b) the current string: copies lane x of columns q + 1, q + 2.
  void select(int q, int x);
  bool member16(int j, int x) { return (lanes(static_cast<std::uint32_t>(root_), j)[x] & 1u) != 0; }
  template <class Visit>
  void walk_from(int q, Visit& visit) {
    const bool two = q + 2 <= max_length_;
    column16(q + 1, q);
    if (two) column16(q + 2, q);
    for (int a = 0; a < kNumLetters; ++a) {
      visit(q + 1, static_cast<Letter>(a), member16(q + 1, 4 * a));
      if (!two) continue;
      for (int b = 0; b < kNumLetters; ++b) {
        visit(q + 2, static_cast<Letter>(b), member16(q + 2, 4 * a + b));
        if (q + 2 == max_length_) continue;
        select(q, 4 * a + b);
        walk_from(q + 2, visit);
      }
    }
  }

  int max_length_;
  std::size_t num_rows_ = 0;
  std::size_t root_ = 0;
  std::vector<Instr> ops_;
  std::vector<std::uint16_t> rows_;    // column j of row r at rows_[j * num_rows_ + r]
  std::vector<std::uint16_t> lanes_;   // the same layout, sixteen lanes per entry (walk())
  std::vector<std::uint16_t> shared_;  // rows_ broadcast to sixteen lanes (walk())
  // letter_is_ entry 16 · which + mask: lane x is 1 if letter x / 4 (which = 0) or x % 4 (1) is in
  // the mask.
  std::vector<std::uint16_t> letter_is_;
  std::vector<std::uint8_t> letters_;  // letters_[p] = s[p]
};

// Index of a string of D E L S in shortlex order (ε = 0, "D" = 1, …, "S" = 4, "DD" = 5, …):
// (4^n − 1) / 3 plus the string read as a base-4 number with D = 0 < E < L < S = 3.
std::size_t shortlex_index(std::string_view s);
std::string shortlex_string(std::size_t index);
inline std::size_t strings_up_to(int max_len) { return ((std::size_t{1} << (2 * (max_len + 1))) - 1) / 3; }

// Membership of every string of length ≤ max_len, indexed by shortlex_index (one trie walk).
std::vector<std::uint8_t> members_up_to(const Regex& r, int max_len);

}  // namespace pathex::oracle
