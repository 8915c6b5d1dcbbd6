// Both oracles of naive_matcher.h. Neither uses the automata; the parser's tree is all they read.
#include "oracle/naive_matcher.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <functional>

namespace pathex::oracle {

// --- the per-string matcher: top-down, memoised ---

bool naive_match(const Regex& r, std::string_view s) {
  const std::size_t n = s.size() + 1;
  // memo[node][i][j]: -1 unknown, 0 no, 1 yes.
  std::vector<signed char> memo(r.nodes.size() * n * n, -1);
  std::function<bool(int, std::size_t, std::size_t)> m = [&](int node, std::size_t i, std::size_t j) -> bool {
    signed char& slot = memo[(static_cast<std::size_t>(node) * n + i) * n + j];
    if (slot >= 0) return slot != 0;
    const Node& nd = r.at(node);
    bool res = false;
    switch (nd.kind) {
      case NodeKind::kSet: {
        if (j == i + 1) {
          const auto l = letter_from_char(s[i]);
          res = l && (nd.mask & (1u << *l));
        }
        break;
      }
      case NodeKind::kAlt:
        for (int k : nd.kids) res = res || m(k, i, j);
        break;
      case NodeKind::kAnd:
        res = true;
        for (int k : nd.kids) res = res && m(k, i, j);
        break;
      case NodeKind::kNot: res = !m(nd.kids[0], i, j); break;
      case NodeKind::kConcat: {
        // Split s[i, j) among the children, left to right.
        std::function<bool(std::size_t, std::size_t)> rest = [&](std::size_t kid, std::size_t from) -> bool {
          if (kid + 1 == nd.kids.size()) return m(nd.kids[kid], from, j);
          for (std::size_t mid = from; mid <= j; ++mid)
            if (m(nd.kids[kid], from, mid) && rest(kid + 1, mid)) return true;
          return false;
        };
        res = rest(0, i);
        break;
      }
      case NodeKind::kRepeat: {
        // reach[c][p]: s[i, p) is c copies. Copies may be empty, so counts above the length
        // only matter up to min; cap the count at max(min, length) + 1.
        const int len = static_cast<int>(j - i);
        const int cap = nd.max == kUnbounded ? std::max(nd.min, len) + 1 : nd.max;
        std::vector<std::vector<char>> reach(static_cast<std::size_t>(cap) + 1, std::vector<char>(n, 0));
        reach[0][i] = 1;
        for (int c = 0; c < cap && !res; ++c) {
          for (std::size_t p = i; p <= j; ++p) {
            if (!reach[static_cast<std::size_t>(c)][p]) continue;
            for (std::size_t q = p; q <= j; ++q)
              if (m(nd.kids[0], p, q)) reach[static_cast<std::size_t>(c) + 1][q] = 1;
          }
        }
        for (int c = nd.min; c <= cap && !res; ++c) res = reach[static_cast<std::size_t>(c)][j] != 0;
        break;
      }
    }
    slot = res ? 1 : 0;
    return res;
  };
  return m(r.root, 0, s.size());
}

// --- the incremental matcher ---
//
// A row is one relation "s[i, j) is in some language X", stored as X[j] = the set of i ≤ j
// (bit i) for which it holds. The operations and why each is X's definition:
//
//   kSet  {letters}:  s[i, j) is one letter of the set  ⇔  i = j − 1 and s[j − 1] ∈ set.
//   kOr   A ∪ B:      X[j] = A[j] | B[j].           kAnd  A ∩ B:  X[j] = A[j] & B[j].
//   kNot  ~A:         X[j] = {i ≤ j} \ A[j]         (complement over all strings).
//   kCat  A · B:      s[i, j) ∈ AB ⇔ ∃ m, i ≤ m ≤ j: s[i, m) ∈ A and s[m, j) ∈ B,
//                     so X[j] = ∪ over m ∈ B[j] of A[m]  (A[m] only holds i ≤ m).
//   kEps  {ε}:        X[j] = {j}.
//   kStar A*:         s[i, j) ∈ A* ⇔ i = j, or ∃ m, i ≤ m < j: s[i, m) ∈ A* and s[m, j) ∈ A
//                     (drop empty copies; take the last non-empty one), so
//                     X[j] = {j} ∪ ∪ over m ∈ A[j], m < j, of X[m] — earlier columns only.
//
// Repetition x{n,m} is the union of the exact powers x^c = x^(c−1) · x for n ≤ c ≤ m (x^0 = ε,
// x^1 = x), and x{n,} is x^n · x* (x* itself for n = 0). Powers saturate: on strings of at most
// L letters, x^c = x^c' for all c, c' ≥ L + 1. (A string of at most L letters written as c copies
// has at most L non-empty ones, so some copy is empty and ε ∈ x; dropping the empty copies and
// padding with new ones writes it as exactly c' copies.) Hence counts are clamped to L + 1, which
// keeps S{1000} to a dozen rows.

std::uint32_t TrieMatcher::emit(Op op, std::uint32_t a, std::uint32_t b, std::uint8_t mask) {
  const auto out = static_cast<std::uint32_t>(ops_.size());  // one row per operation
  ops_.push_back(Instr{op, mask, out, a, b});
  return out;
}

std::uint32_t TrieMatcher::compile(const Regex& r, int node) {
  const Node& n = r.at(node);
  const auto fold = [&](Op op) {
    std::uint32_t acc = compile(r, n.kids[0]);
    for (std::size_t k = 1; k < n.kids.size(); ++k) acc = emit(op, acc, compile(r, n.kids[k]));
    return acc;
  };
  switch (n.kind) {
    case NodeKind::kSet: return emit(Op::kSet, 0, 0, n.mask);
    case NodeKind::kAlt: return fold(Op::kOr);
    case NodeKind::kAnd: return fold(Op::kAnd);
    case NodeKind::kConcat: return fold(Op::kCat);
    case NodeKind::kNot: return emit(Op::kNot, compile(r, n.kids[0]), 0);
    case NodeKind::kRepeat: {
      const int saturate = max_length_ + 1;
      const std::uint32_t x = compile(r, n.kids[0]);
      const int lo = std::min(n.min, saturate);
      // x^lo, starting from x^1 = x rather than ε · x when lo ≥ 1.
      std::uint32_t power = lo == 0 ? emit(Op::kEps, 0, 0) : x;
      for (int c = 2; c <= lo; ++c) power = emit(Op::kCat, power, x);
      if (n.max == kUnbounded) {
        const std::uint32_t star = emit(Op::kStar, x, 0);
        return lo == 0 ? star : emit(Op::kCat, power, star);  // x{0,} = x*
      }
      const int hi = std::min(n.max, saturate);
      std::uint32_t acc = power;  // x^lo ∪ … ∪ x^c
      for (int c = lo + 1; c <= hi; ++c) {
        power = emit(Op::kCat, power, x);
        acc = emit(Op::kOr, acc, power);
      }
      return acc;
    }
  }
  return 0;
}

TrieMatcher::TrieMatcher(const Regex& r, int max_length)
    : max_length_(std::clamp(max_length, 0, kMaxLength)), letters_(static_cast<std::size_t>(max_length_), 0) {
  root_ = compile(r, r.root);
  num_rows_ = ops_.size();
  const std::size_t columns = static_cast<std::size_t>(max_length_) + 1;
  rows_.assign(columns * num_rows_, 0);
  lanes_.assign(columns * num_rows_ * 16, 0);
  shared_.assign(columns * num_rows_ * 16, 0);
  letter_is_.assign(2 * 16 * 16, 0);
  for (std::size_t mask = 0; mask < 16; ++mask)
    for (std::size_t x = 0; x < 16; ++x) {
      view(letter_is_, mask)[x] = static_cast<std::uint16_t>((mask >> (x / 4)) & 1);
      view(letter_is_, 16 + mask)[x] = static_cast<std::uint16_t>((mask >> (x % 4)) & 1);
    }
  column(0);
  for (std::uint32_t row = 0; row < num_rows_; ++row) broadcast(shared(row, 0), at(row, 0));
}

void TrieMatcher::push(int p, Letter letter) {
  letters_[static_cast<std::size_t>(p)] = letter;
  column(p + 1);
}

void TrieMatcher::column(int j) {
  const auto all_starts = static_cast<std::uint16_t>((2u << j) - 1);  // i = 0..j
  for (const Instr& in : ops_) {
    std::uint16_t v = 0;
    switch (in.op) {
      case Op::kSet:
        if (j > 0 && (in.mask >> letters_[static_cast<std::size_t>(j) - 1]) & 1u) v = static_cast<std::uint16_t>(1u << (j - 1));
        break;
      case Op::kOr: v = at(in.a, j) | at(in.b, j); break;
      case Op::kAnd: v = at(in.a, j) & at(in.b, j); break;
      case Op::kNot: v = static_cast<std::uint16_t>(~at(in.a, j) & all_starts); break;
      case Op::kEps: v = static_cast<std::uint16_t>(1u << j); break;
      case Op::kCat:
        for (unsigned ms = at(in.b, j); ms; ms &= ms - 1) v |= at(in.a, std::countr_zero(ms));
        break;
      case Op::kStar:
        v = static_cast<std::uint16_t>(1u << j);
        for (unsigned ms = at(in.a, j) & ~(1u << j); ms; ms &= ms - 1) v |= at(in.out, std::countr_zero(ms));
        break;
    }
    at(in.out, j) = v;
  }
}

// The same program on sixteen strings at once: every operation is the scalar one of column()
// applied lane by lane. Vector | & ~ and shifts are lane-wise; -((x >> m) & 1) is 0xFFFF in the
// lanes whose bit m is set, so `-((x >> m) & 1) & v` keeps v in exactly those lanes, with v the
// shared column m (m ≤ q, the prefix's, broadcast to every lane) or the lanes' own column m.
// Compiled twice, with and without AVX2 (the 16 lanes are one AVX2 register); the loader picks.
__attribute__((target_clones("avx2", "default"))) void TrieMatcher::column16(int j, int q) {
  Lanes all_starts, bit_j;
  broadcast(all_starts, static_cast<std::uint16_t>((2u << j) - 1));
  broadcast(bit_j, static_cast<std::uint16_t>(1u << j));
  const int which = j - 1 == q ? 0 : 1;  // the letter at j − 1 is a (x / 4) or b (x % 4)
  for (const Instr& in : ops_) {
    Lanes v{};
    switch (in.op) {
      case Op::kSet: v = view(letter_is_, static_cast<std::size_t>(16 * which + in.mask)) << (j - 1); break;
      case Op::kOr: v = lanes(in.a, j) | lanes(in.b, j); break;
      case Op::kAnd: v = lanes(in.a, j) & lanes(in.b, j); break;
      case Op::kNot: v = ~lanes(in.a, j) & all_starts; break;
      case Op::kEps: v = bit_j; break;
      case Op::kCat: {
        const Lanes b = lanes(in.b, j);
        for (unsigned ms = any_lane(b); ms; ms &= ms - 1) {
          const int m = std::countr_zero(ms);
          v |= -((b >> m) & 1) & (m <= q ? shared(in.a, m) : lanes(in.a, m));
        }
        break;
      }
      case Op::kStar: {
        const Lanes a = lanes(in.a, j);
        v = bit_j;
        for (unsigned ms = any_lane(a) & ~(1u << j); ms; ms &= ms - 1) {
          const int m = std::countr_zero(ms);
          v |= -((a >> m) & 1) & (m <= q ? shared(in.out, m) : lanes(in.out, m));
        }
        break;
      }
    }
    lanes(in.out, j) = v;
  }
}

unsigned TrieMatcher::any_lane(const Lanes& x) {
  std::uint64_t w[4];
  std::memcpy(w, &x, sizeof w);
  const std::uint64_t o = w[0] | w[1] | w[2] | w[3];
  return static_cast<unsigned>((o | o >> 16 | o >> 32 | o >> 48) & 0xFFFFu);
}

void TrieMatcher::select(int q, int x) {
  letters_[static_cast<std::size_t>(q)] = static_cast<std::uint8_t>(x / 4);
  letters_[static_cast<std::size_t>(q) + 1] = static_cast<std::uint8_t>(x % 4);
  for (int j = q + 1; j <= q + 2; ++j)
    for (std::size_t r = 0; r < num_rows_; ++r) {
      const auto row = static_cast<std::uint32_t>(r);
      at(row, j) = lanes(row, j)[x];
      broadcast(shared(row, j), at(row, j));
    }
}

// --- shortlex indexing and whole-language tables ---

std::size_t shortlex_index(std::string_view s) {
  std::size_t value = 0;
  for (char c : s) value = value * 4 + *letter_from_char(c);
  return strings_up_to(static_cast<int>(s.size()) - 1) + value;
}

std::string shortlex_string(std::size_t index) {
  int n = 0;
  while (strings_up_to(n) <= index) ++n;
  std::size_t value = index - strings_up_to(n - 1);
  std::string s(static_cast<std::size_t>(n), 'D');
  for (int k = n; k-- > 0; value /= 4) s[static_cast<std::size_t>(k)] = letter_char(static_cast<int>(value % 4));
  return s;
}

std::vector<std::uint8_t> members_up_to(const Regex& r, int max_len) {
  std::vector<std::uint8_t> out(strings_up_to(max_len), 0);
  // value[len] = the current string of that length as a base-4 number.
  std::vector<std::size_t> value(static_cast<std::size_t>(max_len) + 1, 0);
  TrieMatcher(r, max_len).walk([&](int len, Letter last, bool member) {
    const auto n = static_cast<std::size_t>(len);
    if (n > 0) value[n] = value[n - 1] * 4 + last;
    out[strings_up_to(len - 1) + value[n]] = member ? 1 : 0;
  });
  return out;
}

}  // namespace pathex::oracle
