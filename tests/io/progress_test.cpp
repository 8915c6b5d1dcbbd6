// The progress line fits the terminal: a line that wraps leaves a new line behind at every
// update. progress_line() is checked at every width here; tests/cli/new_user_test.cpp runs
// `pathex trace` on a 40-column pseudo-terminal.
#include "io/progress.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

namespace pathex {
namespace {

TEST(Progress, FullLineOnAWideTerminal) {
  const Progress p{0.5, 1.23e6, 12};
  EXPECT_EQ(progress_line(p, 80), "[###############               ]  50.0%  1.23 M samples/s  12 s left");
  EXPECT_EQ(progress_line(Progress{1.0, 2e6, 0}, 200),
            "[##############################] 100.0%  2.00 M samples/s  0 s left");
}

TEST(Progress, DropsTheRateThenTheTimeThenShrinksTheBar) {
  const Progress p{0.5, 1.23e6, 75};
  EXPECT_EQ(progress_line(p, 60), "[#######        ]  50.0%  1.23 M samples/s  1 min 15 s left");
  EXPECT_EQ(progress_line(p, 50), "[###########            ]  50.0%  1 min 15 s left");
  EXPECT_EQ(progress_line(p, 30), "[##########          ]  50.0%");
  EXPECT_EQ(progress_line(p, 15), " 50.0%");
  EXPECT_EQ(progress_line(p, 7), "");
}

TEST(Progress, NeverReachesTheLastColumn) {
  for (double f : {0.0, 0.333, 1.0})
    for (double left : {0.0, 59.0, 3599.0, 1e7})
      for (int columns = 0; columns <= 200; ++columns) {
        const std::string line = progress_line(Progress{f, 9.99e8, left}, columns);
        EXPECT_LE(static_cast<int>(line.size()), std::max(columns - 1, 0)) << columns << ": " << line;
        EXPECT_EQ(line.find_first_of("\r\n\t"), std::string::npos);
      }
}

TEST(Progress, NonFiniteInputsPrintAsZero) {
  EXPECT_EQ(progress_line(Progress{std::nan(""), std::nan(""), -1}, 80),
            "[                              ]   0.0%  0.00 M samples/s  0 s left");
}

}  // namespace
}  // namespace pathex
