// Named classes stand for their language: an eye-first class used in a later expression brings
// its reversed (light-first) strings; class files are full notation unless an entry says
// otherwise; and repetition budgets count what the NFA really builds.
#include <gtest/gtest.h>

#include "automata/ops.h"
#include "classify/pathclass.h"
#include "io/class_file.h"

namespace pathex {
namespace {

TEST(Names, EyeFirstClassIsReversedWhereItIsUsed) {
  ClassTable table;
  ASSERT_TRUE(load_class_file(R"({"classes": [{"name": "cam", "expr": "ED*SL"},
                                                {"name": "both", "expr": "$cam | LDDDDE"}]})",
                              "c.json", ClassOptions{}, &table)
                  .ok());
  const PathClass* both = table.find("both");
  ASSERT_NE(both, nullptr);
  EXPECT_FALSE(both->eye_first);
  EXPECT_EQ(enumerate_members(both->dfa, 7, 10), std::vector<std::string>({"LDDDDE", "LSDDDE", "LSDDDDE"}));
  EXPECT_TRUE(is_equivalent(table.find("cam")->dfa, compile_class("LSD*E", ClassOptions{}).expect("a test input").dfa));
}

TEST(Names, ClassFilesAreFullNotationUnlessAnEntrySaysSo) {
  ClassOptions heckbert;
  heckbert.notation = Notation::kHeckbert;
  ClassTable table;
  Result<bool> r = load_class_file(R"({"classes": [{"name": "c", "expr": "$caustic"},
                                                   {"name": "h", "expr": "LDE", "notation": "heckbert"}]})",
                                   "c.json", heckbert, &table);
  ASSERT_TRUE(r.ok()) << r.error().render();
  EXPECT_EQ(table.find("h")->notation, Notation::kHeckbert);
  EXPECT_EQ(table.find("c")->notation, Notation::kFull);
}

TEST(Limits, StackedStarsCostOneCopyEach) {
  // Fifteen stars build fifteen loops, not 2^15 copies: the budget must not refuse it.
  Result<PathClass> c = compile_class("LS***************E", ClassOptions{});
  ASSERT_TRUE(c.ok()) << c.error().render();
  EXPECT_EQ(*shortest_member(c->dfa), "LSSSSE");
}

TEST(Finiteness, UnreachableCyclesDoNotCount) {
  // A hand-built DFA: start 0 accepts "D" then dies; state 2 loops on itself, live but unreachable.
  Dfa d;
  d.num_states = 4;
  d.start = 0;
  d.next = {1, 3, 3, 3, 3, 3, 3, 3, 2, 2, 2, 2, 3, 3, 3, 3};
  d.accept = {0, 1, 1, 0};
  EXPECT_TRUE(is_finite(d));
  d.next[0] = 2;  // now "D" leads into the loop
  EXPECT_FALSE(is_finite(d));
}

}  // namespace
}  // namespace pathex
