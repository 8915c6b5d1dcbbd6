// The laws of the language operations (src/automata/ops.h) on random expressions, each checked
// two ways: as an identity between minimal canonical DFAs (which, by canonicity, must then be
// equal as values), and against the AST oracle on every string up to length 8 (87,381 strings).
// Where a law is a bounded statement only (inclusion, equivalence, shortest member), the
// engine's witness is checked with the per-string oracle at whatever length it has.
//
// Random cases come from oracle::RandomRegex with fixed seeds, so every run checks the same
// expressions and a failure prints the seed and the text. To explore other cases, set
// PATHEX_LAWS_SEED=<n> in the environment (the seeds then start at n instead of 5000).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "automata/dfa.h"
#include "automata/ops.h"
#include "core/bigint.h"
#include "oracle/dfa_print.h"
#include "oracle/naive_matcher.h"
#include "oracle/random_regex.h"
#include "regex/parser.h"

namespace pathex {
namespace {

constexpr int kLen = 8;
const Limits kLimits;
const std::size_t kStrings = oracle::strings_up_to(kLen);

std::uint64_t seed_base() {
  const char* env = std::getenv("PATHEX_LAWS_SEED");
  return env ? std::strtoull(env, nullptr, 10) : 5000;
}

// One expression: its text, tree, compiled DFA and oracle table up to length 8.
struct Case {
  std::string text;
  Regex ast;
  Dfa dfa;
  std::vector<std::uint8_t> table;
  bool has(std::string_view s) const { return oracle::naive_match(ast, s); }
};

Case make_case(const std::string& text) {
  Case c;
  c.text = text;
  Result<Regex> r = parse(text, kLimits);
  EXPECT_TRUE(r.ok()) << text;
  if (!r.ok()) return c;
  c.ast = std::move(*r);
  Result<Dfa> d = compile(c.ast, kLimits);
  EXPECT_TRUE(d.ok()) << text;
  if (d.ok()) c.dfa = std::move(*d);
  c.table = oracle::members_up_to(c.ast, kLen);
  return c;
}

std::string random_text(std::uint64_t seed) { return oracle::RandomRegex(seed).expression(seed % 2 ? 3 : 4); }
Case random_case(std::uint64_t seed) { return make_case(random_text(seed)); }
std::string label(std::uint64_t seed, const Case& c) { return "seed " + std::to_string(seed) + " '" + c.text + "'"; }

// Membership of every string up to length 8 by walking the DFA level by level in shortlex order:
// the string with index strings_up_to(n − 1) + v extends the one with index
// strings_up_to(n − 2) + v / 4 by letter v % 4.
std::vector<std::uint8_t> dfa_table(const Dfa& d) {
  std::vector<int> state(kStrings);
  std::vector<std::uint8_t> out(kStrings);
  state[0] = d.start;
  for (int n = 1; n <= kLen; ++n) {
    const std::size_t base = oracle::strings_up_to(n - 1), prev = oracle::strings_up_to(n - 2);
    for (std::size_t v = 0; v < (std::size_t{1} << (2 * n)); ++v)
      state[base + v] = d.step(state[prev + v / 4], static_cast<int>(v % 4));
  }
  for (std::size_t i = 0; i < kStrings; ++i) out[i] = d.accept[static_cast<std::size_t>(state[i])];
  return out;
}

template <class F>
std::vector<std::uint8_t> combine(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, F f) {
  std::vector<std::uint8_t> out(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) out[i] = f(a[i] != 0, b[i] != 0) ? 1 : 0;
  return out;
}

// The first string (shortlex) on which two tables differ, or "" with *none = true.
std::string first_difference(const std::vector<std::uint8_t>& a, const std::vector<std::uint8_t>& b, bool* none) {
  for (std::size_t i = 0; i < a.size(); ++i)
    if ((a[i] != 0) != (b[i] != 0)) {
      *none = false;
      return "'" + oracle::shortlex_string(i) + "'";
    }
  *none = true;
  return "";
}

#define EXPECT_TABLE_EQ(got, want, what)                                           \
  do {                                                                             \
    bool same_ = true;                                                             \
    const std::string at_ = first_difference((got), (want), &same_);                \
    EXPECT_TRUE(same_) << what << ": differs from the oracle first on " << at_;    \
  } while (0)

// Independent of minimize(): complete, every state reachable, numbered breadth-first from 0 with
// letters in order D E L S, and minimal by the table-filling algorithm (every pair of states is
// told apart by some word).
::testing::AssertionResult canonical(const Dfa& d) {
  const auto n = static_cast<std::size_t>(d.num_states);
  if (n == 0 || d.start != 0 || d.next.size() != n * kNumLetters || d.accept.size() != n)
    return ::testing::AssertionFailure() << "malformed: " << n << " states, start " << d.start;
  for (auto t : d.next)
    if (t < 0 || static_cast<std::size_t>(t) >= n) return ::testing::AssertionFailure() << "transition to " << t;
  std::vector<int> order{0};
  std::vector<std::uint8_t> seen(n, 0);
  seen[0] = 1;
  for (std::size_t q = 0; q < order.size(); ++q)
    for (int l = 0; l < kNumLetters; ++l) {
      const int t = d.step(order[q], l);
      if (seen[static_cast<std::size_t>(t)]) continue;
      seen[static_cast<std::size_t>(t)] = 1;
      if (t != static_cast<int>(order.size()))
        return ::testing::AssertionFailure() << "state " << t << " is discovered " << order.size() << "th";
      order.push_back(t);
    }
  if (order.size() != n) return ::testing::AssertionFailure() << n - order.size() << " unreachable states";
  std::vector<std::uint8_t> apart(n * n, 0);
  for (std::size_t p = 0; p < n; ++p)
    for (std::size_t q = 0; q < n; ++q) apart[p * n + q] = d.accept[p] != d.accept[q];
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t p = 0; p < n; ++p)
      for (std::size_t q = 0; q < n; ++q) {
        if (apart[p * n + q]) continue;
        for (int l = 0; l < kNumLetters; ++l)
          if (apart[static_cast<std::size_t>(d.step(static_cast<int>(p), l)) * n + static_cast<std::size_t>(d.step(static_cast<int>(q), l))]) {
            apart[p * n + q] = 1;
            changed = true;
            break;
          }
      }
  }
  for (std::size_t p = 0; p < n; ++p)
    for (std::size_t q = p + 1; q < n; ++q)
      if (!apart[p * n + q]) return ::testing::AssertionFailure() << "states " << p << " and " << q << " are equivalent";
  return ::testing::AssertionSuccess();
}

constexpr std::uint64_t kCases = 300;

// --- the oracle's view of the DFA walk, and the shape of every result ---

TEST(Laws, CompiledDfasAreCanonicalAndAgreeWithAccepts) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case c = random_case(seed);
    EXPECT_TRUE(canonical(c.dfa)) << label(seed, c);
    const std::vector<std::uint8_t> t = dfa_table(c.dfa);
    EXPECT_TABLE_EQ(t, c.table, label(seed, c));
    for (std::size_t i = 0; i < kStrings; i += 97)
      EXPECT_EQ(c.dfa.accepts(oracle::shortlex_string(i)), t[i] != 0) << label(seed, c);
    EXPECT_EQ(minimize(c.dfa), c.dfa) << label(seed, c) << ": minimize() of a minimal DFA is itself";
  }
}

TEST(Laws, ConstantsAndWords) {
  EXPECT_EQ(dfa_empty().num_states, 1);
  EXPECT_EQ(dfa_empty().accept, std::vector<std::uint8_t>{0});
  EXPECT_EQ(dfa_all().accept, std::vector<std::uint8_t>{1});
  EXPECT_EQ(dfa_all().next, (std::vector<std::int32_t>{0, 0, 0, 0}));
  for (const Dfa& d : {dfa_empty(), dfa_all(), dfa_universe(), dfa_word(""), dfa_word("LDSE"), dfa_word("SSSS")})
    EXPECT_TRUE(canonical(d));
  EXPECT_EQ(dfa_universe(), compile(parse("L[SD]{4,}E", kLimits).expect("a test input"), kLimits).expect("a test input"));
  EXPECT_EQ(dfa_universe().num_states, 8) << "start; after L with 0, 1, 2, 3, 4+ letters; after E; dead";
  for (const char* w : {"", "D", "LDSE", "SSSSSSSS"}) {
    const Dfa d = dfa_word(w);
    EXPECT_EQ(enumerate_members(d, 10, 10), std::vector<std::string>{w});
    EXPECT_EQ(d.num_states, static_cast<int>(std::string_view(w).size()) + 2);
  }
}

// --- the boolean algebra ---

TEST(Laws, DeMorgan) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed), b = random_case(seed + 100000);
    const std::string what = label(seed, a) + " and '" + b.text + "'";
    const Dfa not_or = dfa_complement(dfa_union(a.dfa, b.dfa));
    const Dfa not_and = dfa_complement(dfa_intersect(a.dfa, b.dfa));
    EXPECT_EQ(not_or, dfa_intersect(dfa_complement(a.dfa), dfa_complement(b.dfa))) << what;
    EXPECT_EQ(not_and, dfa_union(dfa_complement(a.dfa), dfa_complement(b.dfa))) << what;
    // The same laws through the parser and compile().
    const std::string x = "(" + a.text + ")", y = "(" + b.text + ")";
    EXPECT_EQ(compile(parse("~(" + x + "|" + y + ")", kLimits).expect("a test input"), kLimits).expect("a test input"), not_or) << what;
    EXPECT_EQ(compile(parse("~" + x + "&~" + y, kLimits).expect("a test input"), kLimits).expect("a test input"), not_or) << what;
    EXPECT_EQ(compile(parse("~(" + x + "&" + y + ")", kLimits).expect("a test input"), kLimits).expect("a test input"), not_and) << what;
    EXPECT_EQ(compile(parse("~" + x + "|~" + y, kLimits).expect("a test input"), kLimits).expect("a test input"), not_and) << what;
    EXPECT_TABLE_EQ(dfa_table(not_or), combine(a.table, b.table, [](bool p, bool q) { return !(p || q); }), what);
    EXPECT_TABLE_EQ(dfa_table(not_and), combine(a.table, b.table, [](bool p, bool q) { return !(p && q); }), what);
  }
}

TEST(Laws, ComplementIsAnInvolutionAndPartitionsEverything) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    const Dfa na = dfa_complement(a.dfa);
    EXPECT_TRUE(canonical(na)) << label(seed, a);
    EXPECT_EQ(dfa_complement(na), a.dfa) << label(seed, a);
    EXPECT_EQ(dfa_intersect(a.dfa, na), dfa_empty()) << label(seed, a);
    EXPECT_TRUE(is_empty(dfa_intersect(a.dfa, na))) << label(seed, a);
    EXPECT_EQ(dfa_union(a.dfa, na), dfa_all()) << label(seed, a);
    const std::string x = "(" + a.text + ")";
    EXPECT_EQ(compile(parse("~~" + x, kLimits).expect("a test input"), kLimits).expect("a test input"), a.dfa) << label(seed, a);
    EXPECT_EQ(compile(parse(x + "&~" + x, kLimits).expect("a test input"), kLimits).expect("a test input"), dfa_empty()) << label(seed, a);
    EXPECT_EQ(compile(parse(x + "|~" + x, kLimits).expect("a test input"), kLimits).expect("a test input"), dfa_all()) << label(seed, a);
    EXPECT_TABLE_EQ(dfa_table(na), combine(a.table, a.table, [](bool p, bool) { return !p; }), label(seed, a));
  }
}

TEST(Laws, UnionIntersectionDifferenceConcatAgreeWithTheOracle) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed), b = random_case(seed + 200000);
    const std::string what = label(seed, a) + " and '" + b.text + "'";
    const Dfa u = dfa_union(a.dfa, b.dfa), i = dfa_intersect(a.dfa, b.dfa), d = dfa_difference(a.dfa, b.dfa);
    for (const Dfa* r : {&u, &i, &d}) EXPECT_TRUE(canonical(*r)) << what;
    EXPECT_TABLE_EQ(dfa_table(u), combine(a.table, b.table, [](bool p, bool q) { return p || q; }), "union of " + what);
    EXPECT_TABLE_EQ(dfa_table(i), combine(a.table, b.table, [](bool p, bool q) { return p && q; }), "intersection of " + what);
    EXPECT_TABLE_EQ(dfa_table(d), combine(a.table, b.table, [](bool p, bool q) { return p && !q; }), "difference of " + what);
    // Concatenation: s ∈ AB iff some split has its prefix in A and its suffix in B.
    Result<Dfa> cat = dfa_concat(a.dfa, b.dfa, kLimits);
    ASSERT_TRUE(cat.ok()) << what;
    EXPECT_TRUE(canonical(*cat)) << what;
    std::vector<std::uint8_t> want(kStrings, 0);
    for (std::size_t k = 0; k < kStrings; ++k) {
      const std::string s = oracle::shortlex_string(k);
      for (std::size_t m = 0; m <= s.size() && !want[k]; ++m)
        want[k] = a.table[oracle::shortlex_index(s.substr(0, m))] && b.table[oracle::shortlex_index(s.substr(m))];
    }
    EXPECT_TABLE_EQ(dfa_table(*cat), want, "concatenation of " + what);
    EXPECT_EQ(*cat, compile(parse("(" + a.text + ")(" + b.text + ")", kLimits).expect("a test input"), kLimits).expect("a test input")) << what;
  }
}

// --- decisions ---

TEST(Laws, InclusionThreeWays) {
  int included = 0, witnessed_short = 0;
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    // Every fourth pair is unrelated; the others are built so that inclusion often holds.
    const std::string p = random_text(seed), q = random_text(seed + 300000);
    std::string a = p, b = q;
    switch (seed % 4) {
      case 1: b = "(" + p + ")|(" + q + ")"; break;
      case 2: a = "(" + p + ")&(" + q + ")"; b = p; break;
      case 3: b = "(" + p + ")*"; break;
      default: break;
    }
    const Case ca = make_case(a), cb = make_case(b);
    const std::string what = "seed " + std::to_string(seed) + " '" + a + "' ⊆ '" + b + "'";
    const bool sub = is_subset(ca.dfa, cb.dfa);
    EXPECT_EQ(sub, is_empty(dfa_intersect(ca.dfa, dfa_complement(cb.dfa)))) << what;
    const std::vector<std::uint8_t> outside = combine(ca.table, cb.table, [](bool x, bool y) { return x && !y; });
    const auto first_outside = std::find(outside.begin(), outside.end(), 1);
    if (sub) {
      ++included;
      EXPECT_EQ(first_outside, outside.end()) << what << ": the oracle finds "
                                               << oracle::shortlex_string(static_cast<std::size_t>(first_outside - outside.begin()));
      continue;
    }
    // Not included: the engine's shortest counterexample is one by the oracle, and up to length
    // 8 it is the oracle's first one.
    const std::optional<std::string> w = shortest_member(dfa_difference(ca.dfa, cb.dfa));
    ASSERT_TRUE(w.has_value()) << what;
    EXPECT_TRUE(ca.has(*w) && !cb.has(*w)) << what << ": witness '" << *w << "'";
    if (w->size() <= kLen) {
      ++witnessed_short;
      ASSERT_NE(first_outside, outside.end()) << what;
      EXPECT_EQ(*w, oracle::shortlex_string(static_cast<std::size_t>(first_outside - outside.begin()))) << what;
    } else {
      EXPECT_EQ(first_outside, outside.end()) << what;
    }
  }
  EXPECT_GT(included, static_cast<int>(kCases / 2)) << "the law must be exercised on both sides";
  EXPECT_GT(witnessed_short, 20);
}

// Rewritings that never change the language.
std::vector<std::string> rewrites(const std::string& t, const std::string& other) {
  const std::string x = "(" + t + ")", y = "(" + other + ")";
  return {x + "|" + x,       x + "&" + x,       "~~" + x,           x + "S{0}",        "S{0}" + x,
          x + "|[^SD]",      x + "{1}",         x + "|(" + x + "&" + y + ")",         "(" + x + "|" + y + ")&" + x,
          "(" + x + "&" + y + ")|(" + x + "&~" + y + ")"};
}

TEST(Laws, EquivalenceIsIdenticalMinimalDfas) {
  int equal = 0, different = 0;
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    const std::string other = random_text(seed + 400000);
    const std::vector<std::string> forms = rewrites(a.text, other);
    const Case b = make_case(forms[seed % forms.size()]);
    EXPECT_EQ(b.dfa, a.dfa) << label(seed, a) << " rewritten as '" << b.text << "'";
    EXPECT_TRUE(is_equivalent(a.dfa, b.dfa)) << label(seed, a);
    // Against an unrelated expression: equivalent exactly when the DFAs are equal; if not, the
    // shortest member of the symmetric difference tells them apart in the oracle too.
    const Case c = make_case(other);
    const bool same = is_equivalent(a.dfa, c.dfa);
    EXPECT_EQ(same, a.dfa == c.dfa);
    if (same) {
      ++equal;
      EXPECT_TABLE_EQ(a.table, c.table, label(seed, a) + " ≡ '" + c.text + "'");
      continue;
    }
    ++different;
    const std::optional<std::string> w =
        shortest_member(dfa_union(dfa_difference(a.dfa, c.dfa), dfa_difference(c.dfa, a.dfa)));
    ASSERT_TRUE(w.has_value()) << label(seed, a);
    EXPECT_NE(a.has(*w), c.has(*w)) << label(seed, a) << " vs '" << c.text << "' on '" << *w << "'";
  }
  EXPECT_GT(different, static_cast<int>(kCases / 2));
  EXPECT_GT(equal, 0) << "some random pairs are equivalent (both empty, for one)";
}

TEST(Laws, CanonicalNumberingMakesEqualLanguagesEqualValues) {
  const std::vector<std::vector<std::string>> groups = {
      {"L(S|D)*E", "L[SD]*E", "L(D|S)*E", "L(S*D*)*E", "L(S|D)*(S|D)*E", "L~([DELS]*[LE][DELS]*)E", "L[^LE]*E",
       "L.*E&L[^L]*E"},
      {"L.*DD.*E", "L(S|D)*DD(S|D)*E", "L.*DD.*E&L.*E", "~~(L.*DD.*E)", "L.*DD.*E|L.*DDD.*E"},
      {"S*", "(S*)*", "(S+)?", "S*S*", "~~(S*)", "(S{0,}){2}", "(SS)*|S(SS)*"},
      {"[^SD]", "S&D", "S[^SD]", "~(.*)&S", "(S&D)*&S"},
      {"(S&D)*", "S{0}", "~~(S{0})", "[^SD]*", "S?&D?"},
      {"~(.*)", "~([SD]*)", ".*[LE](~(.*)|.*)", "(.*[LE][^SD]*)+.*"},
  };
  std::vector<Dfa> firsts;
  for (const auto& group : groups) {
    const Dfa first = compile(parse(group[0], kLimits).expect("a test input"), kLimits).expect("a test input");
    EXPECT_TRUE(canonical(first)) << group[0];
    for (const std::string& t : group) {
      const Case c = make_case(t);
      EXPECT_EQ(c.dfa, first) << "'" << t << "' and '" << group[0] << "'";
      EXPECT_TABLE_EQ(dfa_table(c.dfa), c.table, t);
    }
    for (const Dfa& earlier : firsts) EXPECT_NE(first, earlier) << group[0];
    firsts.push_back(first);
  }
}

TEST(Laws, FinitenessMatchesCounts) {
  // A DFA with n states accepts an infinite language iff it accepts a word of length in [n, 2n).
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    const int n = a.dfa.num_states;
    const std::vector<BigUint> counts = count_by_length(a.dfa, 2 * n);
    bool long_member = false, beyond = false;
    for (int k = n; k < 2 * n; ++k) long_member = long_member || !counts[static_cast<std::size_t>(k)].is_zero();
    for (int k = n; k <= 2 * n; ++k) beyond = beyond || !counts[static_cast<std::size_t>(k)].is_zero();
    EXPECT_EQ(is_finite(a.dfa), !long_member) << label(seed, a);
    EXPECT_EQ(long_member, beyond) << label(seed, a);
  }
  for (const char* t : {"S{3}", "~(.*)&.{0,5}", "(S|D){0,5}", "S&D", "S{0}", "LDDDSE|LSDSDE"})
    EXPECT_TRUE(is_finite(make_case(t).dfa)) << t;
  for (const char* t : {"S*", "~(S*)", "L.*DD.*E", "~(.*)", "(S{2}){3,}", "S*&(SS)+"})
    EXPECT_FALSE(is_finite(make_case(t).dfa)) << t;
}

// --- reversal ---

TEST(Laws, ReversalIsAnInvolutionAndReadsStringsBackwards) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    Result<Dfa> r = dfa_reverse(a.dfa, kLimits);
    ASSERT_TRUE(r.ok()) << label(seed, a);
    EXPECT_TRUE(canonical(*r)) << label(seed, a);
    Result<Dfa> rr = dfa_reverse(*r, kLimits);
    ASSERT_TRUE(rr.ok()) << label(seed, a);
    EXPECT_EQ(*rr, a.dfa) << label(seed, a);
    std::vector<std::uint8_t> want(kStrings);
    for (std::size_t k = 0; k < kStrings; ++k) {
      const std::string s = oracle::shortlex_string(k);
      want[k] = a.table[oracle::shortlex_index(std::string(s.rbegin(), s.rend()))];
    }
    EXPECT_TABLE_EQ(dfa_table(*r), want, "reversal of " + label(seed, a));
    // The tree of the reversed language (regex/ast.h) compiles to the same automaton.
    EXPECT_EQ(compile(reversed(a.ast), kLimits).expect("a test input"), *r) << label(seed, a);
  }
}

TEST(Laws, ReversalStopsAtTheStateLimit) {
  // (S|D){12}S(S|D)* needs 15 states (12 counted letters, the S, the accepting loop, dead); its
  // reversal (S|D)*S(S|D){12} must remember the last 13 letters: 2^13 states plus the dead one.
  const Dfa d = compile(parse("(S|D){12}S(S|D)*", kLimits).expect("a test input"), kLimits).expect("a test input");
  EXPECT_EQ(d.num_states, 15);
  Result<Dfa> full = dfa_reverse(d, kLimits);
  ASSERT_TRUE(full.ok());
  EXPECT_EQ(full->num_states, 8193);
  Limits small;
  small.max_states = 1000;
  Result<Dfa> r = dfa_reverse(d, small);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().code, ErrorCode::kLimit);
  EXPECT_EQ(r.error().message, "the DFA exceeds the limit of 1000 states (raise it with --max-states)");
}

// --- evidence: shortest member, enumeration, counts ---

TEST(Laws, ShortestMemberIsTheShortlexFirst) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    const std::optional<std::string> w = shortest_member(a.dfa);
    const auto first = std::find(a.table.begin(), a.table.end(), 1);
    EXPECT_EQ(w.has_value(), !is_empty(a.dfa)) << label(seed, a);
    if (first != a.table.end()) {
      ASSERT_TRUE(w.has_value()) << label(seed, a);
      EXPECT_EQ(*w, oracle::shortlex_string(static_cast<std::size_t>(first - a.table.begin()))) << label(seed, a);
    } else if (w) {
      // No member up to length 8: the engine's is longer and a member by the oracle.
      EXPECT_GT(w->size(), static_cast<std::size_t>(kLen)) << label(seed, a);
      EXPECT_TRUE(a.has(*w)) << label(seed, a) << " on '" << *w << "'";
    }
  }
  EXPECT_EQ(shortest_member(make_case("L.*DD.*E").dfa), "LDDE");
  EXPECT_EQ(shortest_member(make_case("S{9}|D{10}").dfa), "SSSSSSSSS");
  EXPECT_EQ(shortest_member(make_case("(S{9}|D{9})E").dfa), "DDDDDDDDDE");
  EXPECT_EQ(shortest_member(make_case("S&D").dfa), std::nullopt);
  EXPECT_EQ(shortest_member(make_case("S*").dfa), "");
}

TEST(Laws, EnumerationIsShortlexAndComplete) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    std::vector<std::string> want;
    for (std::size_t k = 0; k < kStrings; ++k)
      if (a.table[k]) want.push_back(oracle::shortlex_string(k));
    EXPECT_EQ(enumerate_members(a.dfa, kLen, std::numeric_limits<std::size_t>::max()), want) << label(seed, a);
    const std::vector<std::string> few = enumerate_members(a.dfa, kLen, 5);
    EXPECT_EQ(few, std::vector<std::string>(want.begin(), want.begin() + static_cast<std::ptrdiff_t>(std::min<std::size_t>(5, want.size()))))
        << label(seed, a);
    // Shorter bounds give prefixes of the same list.
    std::vector<std::string> upto3;
    for (const std::string& s : want)
      if (s.size() <= 3) upto3.push_back(s);
    EXPECT_EQ(enumerate_members(a.dfa, 3, 1000), upto3) << label(seed, a);
  }
  EXPECT_TRUE(enumerate_members(dfa_all(), -1, 10).empty());
  EXPECT_TRUE(enumerate_members(dfa_all(), 5, 0).empty());
  EXPECT_EQ(enumerate_members(dfa_all(), 1, 10), (std::vector<std::string>{"", "D", "E", "L", "S"}));
}

TEST(Laws, CountsByLengthMatchBruteForce) {
  for (std::uint64_t seed = seed_base(); seed < seed_base() + kCases; ++seed) {
    const Case a = random_case(seed);
    const std::vector<BigUint> counts = count_by_length(a.dfa, kLen);
    ASSERT_EQ(counts.size(), static_cast<std::size_t>(kLen) + 1);
    for (int n = 0; n <= kLen; ++n) {
      std::uint64_t brute = 0;
      for (std::size_t k = oracle::strings_up_to(n - 1); k < oracle::strings_up_to(n); ++k) brute += a.table[k];
      EXPECT_EQ(counts[static_cast<std::size_t>(n)].to_string(), std::to_string(brute)) << label(seed, a) << " length " << n;
    }
  }
  EXPECT_TRUE(count_by_length(dfa_all(), -1).empty());
}

// 2^k in decimal by schoolbook doubling, independent of BigUint.
std::string power_of_two(int k) {
  std::string digits = "1";  // least significant first
  for (int i = 0; i < k; ++i) {
    int carry = 0;
    for (char& d : digits) {
      const int v = (d - '0') * 2 + carry;
      d = static_cast<char>('0' + v % 10);
      carry = v / 10;
    }
    if (carry) digits += static_cast<char>('0' + carry);
  }
  return std::string(digits.rbegin(), digits.rend());
}

TEST(Laws, UniverseCountsAreExactPowersOfTwo) {
  // U = L[SD]{4,}E: 2^(n−2) members of length n ≥ 6, none shorter.
  const std::vector<BigUint> counts = count_by_length(dfa_universe(), 202);
  ASSERT_EQ(counts.size(), 203u);
  for (int n = 0; n < 6; ++n) EXPECT_EQ(counts[static_cast<std::size_t>(n)].to_string(), "0") << n;
  for (int n = 6; n <= 202; ++n) EXPECT_EQ(counts[static_cast<std::size_t>(n)].to_string(), power_of_two(n - 2)) << n;
  EXPECT_EQ(counts[202].to_string(), "1606938044258990275541962092341162602522202993782792835301376");
  // Every string: 4^n = 2^(2n).
  const std::vector<BigUint> all = count_by_length(dfa_all(), 100);
  for (int n = 0; n <= 100; ++n) EXPECT_EQ(all[static_cast<std::size_t>(n)].to_string(), power_of_two(2 * n)) << n;
  std::uint64_t v = 0;
  EXPECT_TRUE(all[31].to_u64(&v));
  EXPECT_EQ(v, std::uint64_t{1} << 62);
  EXPECT_FALSE(all[32].to_u64(&v)) << "4^32 = 2^64 does not fit";
}

TEST(BigUintTest, AdditionCarriesAcrossLimbs) {
  BigUint x(std::numeric_limits<std::uint64_t>::max());
  x += BigUint(1);
  EXPECT_EQ(x.to_string(), "18446744073709551616");
  x += BigUint(std::numeric_limits<std::uint64_t>::max());
  EXPECT_EQ(x.to_string(), "36893488147419103231");
  BigUint y;
  EXPECT_TRUE(y.is_zero());
  EXPECT_EQ(y.to_string(), "0");
  y += x;
  EXPECT_EQ(y, x);
  BigUint ten19(10000000000000000000ULL);
  EXPECT_EQ(ten19.to_string(), "10000000000000000000");
  ten19 += ten19;
  EXPECT_EQ(ten19.to_string(), "20000000000000000000");
}

}  // namespace
}  // namespace pathex
