// Result<T> refuses to be read before it was checked (issue 17: no unchecked dereference), and
// the abort names the caller's file and line, so the first test that runs a misuse points at it.
#include <gtest/gtest.h>

#include <string>

#include "core/error.h"

namespace pathex {
namespace {

Result<int> fails() { return make_error(ErrorCode::kLimit, "too big"); }
Result<int> works() { return 7; }

TEST(Result, CheckedAccessReadsTheValueOrTheError) {
  Result<int> ok = works();
  ASSERT_TRUE(ok.ok());
  EXPECT_EQ(ok.value(), 7);
  EXPECT_EQ(*ok, 7);
  Result<int> bad = fails();
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message, "too big");
}

TEST(ResultDeathTest, AnUncheckedReadAbortsNamingTheCaller) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  // The expected line is the one of the read, whichever compiler built the test (the call site
  // comes from __builtin_FILE/__builtin_LINE, which GCC and clang-14 both provide).
  const int line = __LINE__ + 1;
  EXPECT_DEATH((void)works().value(), "value of a Result read before ok\\(\\) was checked \\(.*result_test\\.cpp:" +
                                          std::to_string(line) + "\\)");
  EXPECT_DEATH(
      {
        Result<int> r = fails();
        if (!r) (void)r.value();
      },
      "value of a Result read although it holds an error \\(.*result_test\\.cpp:[0-9]+\\)");
  EXPECT_DEATH(
      {
        Result<int> r = works();
        if (r) (void)r.error();
      },
      "error of a Result read although it holds a value \\(.*result_test\\.cpp:[0-9]+\\)");
  EXPECT_DEATH((void)*works(), "value of a Result read before ok\\(\\) was checked \\(through operator\\* or ->\\)");
}

}  // namespace
}  // namespace pathex
