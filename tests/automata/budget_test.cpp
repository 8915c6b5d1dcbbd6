// The engine's limits as counters (issue 17): the work budget (core/budget.h) and the state cap
// stop pathological inputs after a bounded amount of work, and linear inputs cost linear work.
// Every assertion is on WorkBudget::spent(), never on a clock: a timed test measures the
// machine, not the limit.
#include <gtest/gtest.h>

#include <string>

#include "automata/dfa.h"
#include "automata/ops.h"
#include "classify/pathclass.h"
#include "core/budget.h"
#include "io/profile_json.h"
#include "reach/query.h"
#include "regex/parser.h"

namespace pathex {
namespace {

// Work units of compile_class(text) under default limits, and whether it succeeded.
std::size_t work_of(const std::string& text, bool* ok, const Limits& limits = Limits{}) {
  WorkBudget budget(limits.max_work);
  ClassOptions o;
  o.limits = limits;
  Result<PathClass> c = compile_class(text, o);
  *ok = c.ok();
  return budget.spent();
}

TEST(WorkBudget, ChargesOnlyInsideAnOperationAndSaturates) {
  WorkBudget::charge(1000000000);  // no budget in force: nothing happens
  WorkBudget budget(10);
  WorkBudget::charge(4);
  EXPECT_EQ(budget.spent(), 4u);
  EXPECT_THROW(WorkBudget::charge(7), WorkBudgetExceeded);
  EXPECT_TRUE(budget.exhausted());
  EXPECT_THROW(WorkBudget::charge(0), WorkBudgetExceeded);  // once over, every charge unwinds
  {
    ExemptFromBudget exempt;
    WorkBudget::charge(1000000000);  // the engine's constants are not charged
  }
}

TEST(WorkBudget, OverrunIsTheLimitErrorNamingTheOption) {
  Limits small;
  small.max_work = 1000;
  ClassOptions o;
  o.limits = small;
  Result<PathClass> c = compile_class("L.{40}E", o);
  ASSERT_FALSE(c.ok());
  EXPECT_EQ(c.error().code, ErrorCode::kLimit);
  EXPECT_EQ(c.error().render(),
            "column 1: the work of this operation exceeds the limit of 1000 units (raise it with --max-work)\n"
            "  L.{40}E\n"
            "  ^");
}

// (S|D)*S(S|D){40} has a DFA of 2^41 states: the state cap stops the subset construction after
// about 100,000 states, before the work budget, and what it spent is bounded by the cap.
TEST(WorkBudget, ExponentialDfaStopsAtTheStateCap) {
  bool ok = true;
  const std::size_t spent = work_of("(S|D)*S(S|D){40}", &ok);
  EXPECT_FALSE(ok);
  EXPECT_GT(spent, Limits{}.max_states);  // it did build up to the cap…
  EXPECT_LT(spent, Limits{}.max_work);    // …and stopped there, within the budget
}

// A literal compiles in linear work: three times the letters, about three times the units.
TEST(WorkBudget, LiteralsCompileInLinearWork) {
  bool ok10 = false, ok30 = false;
  const std::size_t w10 = work_of("L" + std::string(10000, 'D') + "E", &ok10);
  const std::size_t w30 = work_of("L" + std::string(30000, 'D') + "E", &ok30);
  ASSERT_TRUE(ok10);
  ASSERT_TRUE(ok30);
  EXPECT_GT(w30, 2.9 * static_cast<double>(w10));
  EXPECT_LT(w30, 3.1 * static_cast<double>(w10));
  EXPECT_LT(w30, 100u * 30000u);  // a few dozen units per letter
}

// The issue's hangs, each now a bounded amount of work with its exact answer.
TEST(WorkBudget, RepeatedIntersectionIsCompiledOnce) {
  bool ok = false;
  const std::size_t once = work_of("(S{1000}&D*)", &ok);
  ASSERT_TRUE(ok);
  const std::size_t repeated = work_of("(S{1000}&D*){1000}", &ok);
  ASSERT_TRUE(ok);
  // S{1000}&D* is empty; its DFA is built once, then embedded as two states per copy.
  EXPECT_LT(repeated, once + 1000u * 100u);
  Result<PathClass> c = compile_class("(S{1000}&D*){1000}", ClassOptions{});
  ASSERT_TRUE(c.ok());
  EXPECT_TRUE(is_empty(c->dfa));
}

TEST(WorkBudget, LongRepetitionsOfSmallGroupsAreLinear) {
  bool ok = false;
  const std::size_t dots = work_of("L(.{7}){1000}E", &ok);
  ASSERT_TRUE(ok);
  EXPECT_LT(dots, 2000000u);
  const std::size_t direct = work_of("$direct{1000}", &ok);
  ASSERT_TRUE(ok);
  EXPECT_LT(direct, 2000000u);
  Result<PathClass> c = compile_class("L(.{7}){1000}E", ClassOptions{});
  ASSERT_TRUE(c.ok());
  EXPECT_EQ(shortest_member(c->dfa), "L" + std::string(7000, 'D') + "E");
  Result<PathClass> d = compile_class("$direct{1000}", ClassOptions{});
  ASSERT_TRUE(d.ok());
  EXPECT_TRUE(is_empty(d->dfa));  // ∩ U: a full path has one L
}

// A profile of 400 strategies: 400 small languages and unions, well within the budget.
TEST(WorkBudget, FourHundredStrategies) {
  std::string json = R"({"name": "many", "strategies": [)";
  for (int i = 0; i < 400; ++i) json += std::string(i ? "," : "") + R"({"s": )" + std::to_string(i) + R"(, "t": "0.."})";
  json += "]}";
  WorkBudget budget(Limits{}.max_work);
  Result<Profile> p = parse_profile(json, "many.json", Limits{});
  ASSERT_TRUE(p.ok());
  Result<CompiledProfile> c = compile_profile(*p, std::nullopt, Limits{});
  ASSERT_TRUE(c.ok());
  EXPECT_LT(budget.spent(), Limits{}.max_work);
  // (s, DD, 0..) for s = 0..399 reaches every local path whose first DD starts within 400 letters.
  EXPECT_TRUE(c->reachable.accepts("LDDDDE"));
  EXPECT_FALSE(c->reachable.accepts("LSDSDE"));
}

// The bounded universe is built directly: any bound up to the ceiling, no expression to parse
// (--max-bounces 997..1000 used to overflow --max-repeat inside it and abort).
TEST(WorkBudget, BoundedUniverseAtEveryBound) {
  for (int n : {0, 1, 996, 997, 1000, kMaxBouncesCeiling}) {
    const Dfa u = dfa_universe_bounded(n);
    EXPECT_EQ(u.num_states, n + 8) << n;  // start, n + 5 letter counts, accept, dead: all distinct
    EXPECT_TRUE(u.accepts("L" + std::string(static_cast<std::size_t>(n) + 4, 'S') + "E")) << n;
    EXPECT_FALSE(u.accepts("L" + std::string(static_cast<std::size_t>(n) + 5, 'S') + "E")) << n;
    EXPECT_FALSE(u.accepts("LSSSE")) << n;
  }
}

}  // namespace
}  // namespace pathex
