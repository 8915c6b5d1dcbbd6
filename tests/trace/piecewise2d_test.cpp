// The piecewise-constant 2D distribution (trace/piecewise2d.h) that image infinite lights sample
// their directions from: its density integrates to 1, its samples follow it (a histogram within a
// stated number of standard errors, fixed seed), each sample reports the density pdf() gives at
// it, and cells or rows of weight 0 are never drawn.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "support/stat_seed.h"
#include "trace/piecewise2d.h"

namespace pathex {
namespace {

// 6 x 4 cells: a zero row (row 1), zero cells in the others, and a bright one.
std::vector<float> test_weights() {
  return {1, 2, 0, 4, 1, 1,   //
          0, 0, 0, 0, 0, 0,   //
          0.5f, 0, 30, 0, 1, 2,  //
          3, 3, 3, 0, 0, 1};
}

TEST(Piecewise2D, DensityIntegratesToOne) {
  const Piecewise2D d(test_weights(), 6, 4);
  double cells = 0.0;
  for (std::size_t r = 0; r < 4; ++r)
    for (std::size_t c = 0; c < 6; ++c) cells += d.cell_pdf(c, r) / 24.0;  // each cell is 1/24 of the square
  EXPECT_NEAR(cells, 1.0, 1e-6);
  // And pdf() on a fine grid of points (midpoint rule, 10 x 10 points per cell).
  double grid = 0.0;
  for (int y = 0; y < 40; ++y)
    for (int x = 0; x < 60; ++x) grid += d.pdf({(static_cast<float>(x) + 0.5f) / 60.0f, (static_cast<float>(y) + 0.5f) / 40.0f}) / 2400.0;
  EXPECT_NEAR(grid, 1.0, 1e-6);
}

TEST(Piecewise2D, SamplesFollowTheDensityAndReportIt) {
  const std::vector<float> w = test_weights();
  const Piecewise2D d(w, 6, 4);
  std::mt19937_64 rng(test::stat_seed(12345));
  std::uniform_real_distribution<float> uni(0.0f, 1.0f);
  const int n = 200000;
  std::vector<int> count(24, 0);
  for (int i = 0; i < n; ++i) {
    float pdf = 0.0f;
    int col = -1, row = -1;
    const glm::vec2 p = d.sample({uni(rng), uni(rng)}, &pdf, &col, &row);
    ASSERT_GE(p.x, 0.0f);
    ASSERT_LT(p.x, 1.0f);
    ASSERT_GE(p.y, 0.0f);
    ASSERT_LT(p.y, 1.0f);
    // The point lies in the cell reported, and its density is the one pdf() gives there.
    ASSERT_EQ(static_cast<int>(p.x * 6.0f), col);
    ASSERT_EQ(static_cast<int>(p.y * 4.0f), row);
    ASSERT_EQ(pdf, d.pdf(p));
    ASSERT_GT(w[static_cast<std::size_t>(row * 6 + col)], 0.0f) << "a cell of weight 0 was drawn: " << col << ", " << row;
    ++count[static_cast<std::size_t>(row * 6 + col)];
  }
  // Each cell's count is binomial(n, p), near normal at these counts: within k standard errors of
  // n p, k for a family-wise false-failure rate of 0.1 % over the 24 cells (about 3.9).
  const double k = test::family_sigmas(24, 1e-3, 1 << 20);
  for (std::size_t i = 0; i < 24; ++i) {
    const double p = d.cell_pdf(i % 6, i / 6) / 24.0;
    const double sigma = std::sqrt(n * p * (1.0 - p));
    test::stat_log("piecewise2d cell " + std::to_string(i), (count[i] - n * p) / sigma, k);
    EXPECT_LE(std::fabs(count[i] - n * p), k * sigma + 1e-9) << "cell " << i << ": " << count[i] << " of " << n << ", expected " << n * p;
  }
}

// Every u, however near a cell's end, gives a point that pdf() places in the cell sample()
// reports (the offset's sum and division rounded onto the next cell's edge in 3 % of the seeds of
// the test above before they were kept inside): every float u.x near the ends of row 2's cells.
TEST(Piecewise2D, APointStaysInItsCellAtEveryU) {
  const Piecewise2D d(test_weights(), 6, 4);
  // Row 2 (u.y = 0.5): cumulative weights 0.5, 0.5, 30.5, 30.5, 31.5, 33.5 of 33.5.
  int checked = 0;
  for (double end : {0.5, 30.5, 31.5, 33.5})
    for (float u = static_cast<float>(end / 33.5) - 2e-4f; u < static_cast<float>(end / 33.5) + 2e-4f && u < 1.0f;
         u = std::nextafter(u, 1.0f), ++checked) {
      float pdf = 0.0f;
      int col = -1, row = -1;
      const glm::vec2 p = d.sample({u, 0.5f}, &pdf, &col, &row);
      ASSERT_EQ(row, 2);
      ASSERT_EQ(static_cast<int>(p.x * 6.0f), col) << "u " << u << " gives x " << p.x;
      ASSERT_EQ(pdf, d.pdf(p)) << u;
    }
  EXPECT_GT(checked, 10000);
}

TEST(Piecewise2D, ZeroRowsAndCellsAreNeverDrawnEvenAtTheEnds) {
  const std::vector<float> w = test_weights();
  const Piecewise2D d(w, 6, 4);
  const float ends[] = {0.0f, 1e-7f, 0.25f, 0.5f, 0.9999999f, 0x1.fffffep-1f};
  for (float ux : ends)
    for (float uy : ends) {
      float pdf = 0.0f;
      int col = -1, row = -1;
      d.sample({ux, uy}, &pdf, &col, &row);
      EXPECT_NE(row, 1) << ux << ", " << uy;
      EXPECT_GT(w[static_cast<std::size_t>(row * 6 + col)], 0.0f) << ux << ", " << uy;
      EXPECT_GT(pdf, 0.0f);
    }
  EXPECT_EQ(d.pdf({0.5f, 0.3f}), 0.0f);  // row 1
  EXPECT_EQ(d.pdf({0.4f, 0.1f}), 0.0f);  // row 0, column 2
}

TEST(Piecewise2D, AllZeroIsUniform) {
  const Piecewise2D d(std::vector<float>(12, 0.0f), 4, 3);
  EXPECT_FLOAT_EQ(d.pdf({0.1f, 0.9f}), 1.0f);
  float pdf = 0.0f;
  const glm::vec2 p = d.sample({0.3f, 0.7f}, &pdf);
  EXPECT_FLOAT_EQ(pdf, 1.0f);
  EXPECT_NEAR(p.x, 0.3f, 1e-6f);
  EXPECT_NEAR(p.y, 0.7f, 1e-6f);
}

}  // namespace
}  // namespace pathex
