// Verdicts against brute force. For random path classes and every built-in profile, with the
// bound max_bounces = 4 (so every path in play has at most 10 letters), enumerate every valid full
// path up to length 10 and decide membership in the class with the naive AST matcher and
// reachability straight from the strategy definition (s letters, a chain the chain's AST
// matches, t letters; the bound), sharing no automata code with the checker. The verdict the
// checker computes from languages must equal the one the enumeration gives.
#include <gtest/gtest.h>

#include <random>

#include "io/profile_json.h"
#include "oracle/naive_matcher.h"
#include "reach/query.h"
#include "regex/parser.h"

namespace pathex {
namespace {

const Limits kLimits;
constexpr int kBound = 4;  // interior vertices; paths of at most kBound + 6 = 10 letters

std::vector<std::string> valid_paths_up_to_10() {
  std::vector<std::string> out;
  for (int n = 4; n <= 8; ++n)
    for (int bits = 0; bits < (1 << n); ++bits) {
      std::string p = "L";
      for (int i = 0; i < n; ++i) p += (bits >> (n - 1 - i)) & 1 ? 'S' : 'D';
      out.push_back(p + "E");
    }
  return out;
}

// The definition of DESIGN §4, decided directly.
bool samples_directly(const Strategy& st, const Regex& chain, const std::string& path) {
  const int letters = static_cast<int>(path.size()) - 2;
  if (letters - 4 > kBound) return false;
  for (int s = 0; s <= letters; ++s)
    for (int t = 0; s + t <= letters; ++t)
      if (st.s.contains(s) && st.t.contains(t) &&
          oracle::naive_match(chain, path.substr(static_cast<std::size_t>(s) + 1, static_cast<std::size_t>(letters - s - t))))
        return true;
  return false;
}

std::string random_middle(std::mt19937_64& rng, int depth) {
  std::uniform_int_distribution<int> pick(0, depth <= 0 ? 3 : 9);
  switch (pick(rng)) {
    case 0: return "S";
    case 1: return "D";
    case 2: return ".";
    case 3: return "[SD]";
    case 4: return random_middle(rng, depth - 1) + random_middle(rng, depth - 1);
    case 5: return "(" + random_middle(rng, depth - 1) + "|" + random_middle(rng, depth - 1) + ")";
    case 6: return "(" + random_middle(rng, depth - 1) + ")*";
    case 7: return "(" + random_middle(rng, depth - 1) + "){1,3}";
    case 8: return "(" + random_middle(rng, depth - 1) + "&" + random_middle(rng, depth - 1) + ")";
    default: return "~(" + random_middle(rng, depth - 1) + ")";
  }
}

TEST(BruteForce, VerdictsAgreeWithStrategyDefinitions) {
  std::mt19937_64 rng(20261122);
  const std::vector<std::string> paths = valid_paths_up_to_10();
  Result<std::vector<Profile>> parsed = builtin_profiles(kLimits);
  ASSERT_TRUE(parsed.ok());
  const std::vector<Profile>& profiles = *parsed;
  ASSERT_GE(profiles.size(), 13u);
  std::vector<CompiledProfile> compiled;
  std::vector<std::vector<Regex>> chains;
  for (const Profile& p : profiles) {
    compiled.push_back(compile_profile(p, kBound, kLimits).expect("a test input"));
    chains.emplace_back();
    for (const Strategy& st : p.strategies) chains.back().push_back(parse(st.chain, kLimits).expect("a test input"));
  }
  // R itself, path by path, for every profile.
  for (std::size_t i = 0; i < profiles.size(); ++i)
    for (const std::string& path : paths) {
      bool direct = false;
      for (std::size_t j = 0; j < profiles[i].strategies.size(); ++j)
        direct = direct || samples_directly(profiles[i].strategies[j], chains[i][j], path);
      ASSERT_EQ(compiled[i].reachable.accepts(path), direct) << profiles[i].name << " " << path;
    }
  // Verdicts of random classes.
  QueryOptions qo;
  qo.max_bounces = kBound;
  qo.witnesses = 0;
  qo.max_len = 0;
  int partial = 0, reachable = 0, unreachable = 0, empty = 0;
  for (int n = 0; n < 300; ++n) {
    const std::string expr = "L" + random_middle(rng, 3) + "E";
    Result<PathClass> pc = compile_class(expr, ClassOptions{});
    ASSERT_TRUE(pc.ok()) << expr;
    for (std::size_t i = 0; i < profiles.size(); ++i) {
      bool any_in = false, any_out = false;
      for (const std::string& path : paths) {
        if (!oracle::naive_match(pc->ast, path)) continue;
        bool direct = false;
        for (std::size_t j = 0; j < profiles[i].strategies.size() && !direct; ++j)
          direct = samples_directly(profiles[i].strategies[j], chains[i][j], path);
        (direct ? any_in : any_out) = true;
      }
      const Verdict want = !any_in && !any_out ? Verdict::kEmpty
                           : !any_out          ? Verdict::kReachable
                           : !any_in           ? Verdict::kUnreachable
                                               : Verdict::kPartial;
      const Verdict got = query(*pc, compiled[i], qo).expect("a test input").verdict;
      ASSERT_EQ(got, want) << expr << " with " << profiles[i].name;
      (want == Verdict::kPartial ? partial : want == Verdict::kReachable ? reachable : want == Verdict::kUnreachable ? unreachable : empty)++;
    }
  }
  // The generator must exercise every verdict, or the test proves little.
  EXPECT_GT(partial, 50);
  EXPECT_GT(reachable, 50);
  EXPECT_GT(unreachable, 50);
  EXPECT_GT(empty, 10);
}

}  // namespace
}  // namespace pathex
