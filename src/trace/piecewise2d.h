// A piecewise-constant 2D distribution over the unit square: a grid of width × height cells, each
// of constant density proportional to its nonnegative weight. The image infinite light samples
// its directions from one (trace/environment.h): a cell is a texel, its weight the texel's value
// (times sin θ for a latitude-longitude image, whose texels subtend unequal solid angles).
//
// Sampling inverts the marginal CDF over rows, then the chosen row's conditional CDF over its
// columns, each continuously inside the chosen cell (pbrt's PiecewiseConstant2D does the same).
// CDFs are kept in double: an image of 2^26 texels sums without losing its dim cells. A cell of
// weight 0 is never chosen (the search takes the first cell whose CDF interval contains u, and an
// empty interval contains nothing), and a row of weight 0 neither. When every weight is 0 the
// distribution is uniform: a light of zero power still has a density to report.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <glm/vec2.hpp>

namespace pathex {

class Piecewise2D {
 public:
  Piecewise2D() = default;
  // `weights`: width * height values, row-major (row r covers v ∈ [r, r + 1) / height), each
  // finite and ≥ 0 (negative values count as 0).
  Piecewise2D(const std::vector<float>& weights, int width, int height) : width_(width), height_(height) {
    const auto w = static_cast<std::size_t>(width), h = static_cast<std::size_t>(height);
    weights_.resize(w * h);
    row_cdf_.assign(h * (w + 1), 0.0);
    marginal_.assign(h + 1, 0.0);
    for (std::size_t r = 0; r < h; ++r) {
      double* cdf = &row_cdf_[r * (w + 1)];
      for (std::size_t c = 0; c < w; ++c) {
        const float x = std::max(weights[r * w + c], 0.0f);
        weights_[r * w + c] = x;
        cdf[c + 1] = cdf[c] + static_cast<double>(x);
      }
      marginal_[r + 1] = marginal_[r] + cdf[w];
    }
    total_ = marginal_[h];
    if (!(total_ > 0.0)) {  // all zero: uniform
      std::fill(weights_.begin(), weights_.end(), 1.0f);
      for (std::size_t r = 0; r < h; ++r) {
        for (std::size_t c = 0; c <= w; ++c) row_cdf_[r * (w + 1) + c] = static_cast<double>(c);
        marginal_[r + 1] = static_cast<double>((r + 1) * w);
      }
      total_ = static_cast<double>(w * h);
    }
  }

  int width() const { return width_; }
  int height() const { return height_; }

  // A point of the unit square drawn from u ∈ [0,1)², with its density (per unit area of the
  // square) in *pdf; the cell it lies in in *col, *row when given.
  glm::vec2 sample(glm::vec2 u, float* pdf, int* col = nullptr, int* row = nullptr) const {
    double fr = 0.0, fc = 0.0;
    const std::size_t r = pick(marginal_.data(), static_cast<std::size_t>(height_), u.y, &fr);
    const std::size_t w = static_cast<std::size_t>(width_);
    const std::size_t c = pick(&row_cdf_[r * (w + 1)], w, u.x, &fc);
    *pdf = cell_pdf(c, r);
    if (col) *col = static_cast<int>(c);
    if (row) *row = static_cast<int>(r);
    return {inside(c, fc, width_), inside(r, fr, height_)};
  }

  // The density of `p` ∈ [0,1]² per unit area (points on the far edges belong to the last cell).
  float pdf(glm::vec2 p) const {
    const auto c = static_cast<std::size_t>(std::clamp(static_cast<int>(p.x * static_cast<float>(width_)), 0, width_ - 1));
    const auto r = static_cast<std::size_t>(std::clamp(static_cast<int>(p.y * static_cast<float>(height_)), 0, height_ - 1));
    return cell_pdf(c, r);
  }
  // The density of cell (col, row).
  float cell_pdf(std::size_t col, std::size_t row) const {
    return static_cast<float>(static_cast<double>(weights_[row * static_cast<std::size_t>(width_) + col]) *
                              static_cast<double>(width_) * static_cast<double>(height_) / total_);
  }

 private:
  static constexpr float kBelowOne = 0x1.fffffep-1f;
  // (i + frac) / n as a float in cell i as pdf() finds it (static_cast<int>(x · n) == i): the sum
  // and the division may round onto the next cell's edge (1 time in ~30 at 200,000 draws of a 6 × 4
  // grid), where pdf() would report the neighbour's density, 0 for an empty one.
  static float inside(std::size_t i, double frac, int n) {
    const int cell = static_cast<int>(i);
    const float size = static_cast<float>(n);
    float x = std::min((static_cast<float>(i) + static_cast<float>(frac)) / size, kBelowOne);
    while (x > 0.0f && static_cast<int>(x * size) > cell) x = std::nextafter(x, 0.0f);
    while (static_cast<int>(x * size) < cell) x = std::nextafter(x, 1.0f);
    return x;
  }
  // The cell i of cdf[0 … n] (cdf[0] = 0, nondecreasing) whose interval [cdf[i], cdf[i+1]) holds
  // u · cdf[n], never an empty one; *frac: u's offset inside it in [0, 1).
  static std::size_t pick(const double* cdf, std::size_t n, float u, double* frac) {
    const double x = static_cast<double>(u) * cdf[n];
    std::size_t i = static_cast<std::size_t>(std::upper_bound(cdf, cdf + n + 1, x) - cdf);
    i = i == 0 ? 0 : i - 1;
    if (i >= n) i = n - 1;
    while (i > 0 && !(cdf[i + 1] > cdf[i])) --i;  // x rounded onto the total: the last nonempty cell
    while (i + 1 < n && !(cdf[i + 1] > cdf[i])) ++i;
    const double width = cdf[i + 1] - cdf[i];
    *frac = width > 0.0 ? std::clamp((x - cdf[i]) / width, 0.0, 1.0) : 0.0;
    return i;
  }

  int width_ = 0, height_ = 0;
  std::vector<float> weights_;   // clamped to ≥ 0
  std::vector<double> row_cdf_;  // per row: width + 1 entries from 0
  std::vector<double> marginal_; // height + 1 entries from 0
  double total_ = 0.0;
};

}  // namespace pathex
