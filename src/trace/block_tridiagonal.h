// A block-tridiagonal linear system in 2 × 2 blocks, solved by block elimination: the Newton step and
// the chain's derivatives of the manifold walk (trace/joins/manifold.cpp), whose constraint Jacobian
// has this form (a vertex's two constraints see its own move and its two neighbours').
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>

#include <glm/mat2x2.hpp>
#include <glm/matrix.hpp>

namespace pathex {

// Row v's blocks (glm: [column][row]) against unknown v - 1 (l), v (d) and v + 1 (u), for up to Cap
// rows; `b`: the last row's against an extra unknown past the end (the chain's eye end, for ∂C/∂b).
template <std::size_t Cap>
struct TridiagonalBlocks {
  std::array<glm::dmat2, Cap> l, d, u;
  glm::dmat2 b{0.0};
};

// The system Σ J_vw x_w = r_v solved in place of r (a dvec2 or, for two right-hand sides, a dmat2
// per row) by block elimination, each pivot block factored with partial pivoting within it:
// returns min |pivot| / max |pivot| (0: singular).
template <std::size_t Cap, class R>
double solve_blocks(const TridiagonalBlocks<Cap>& j, std::size_t m, R* r) {
  std::array<glm::dmat2, Cap> inv;
  double lo = INFINITY, hi = 0.0;
  for (std::size_t v = 0; v < m; ++v) {
    glm::dmat2 s = j.d[v];
    if (v > 0) {
      const glm::dmat2 f = j.l[v] * inv[v - 1];
      s -= f * j.u[v - 1];
      r[v] -= f * r[v - 1];
    }
    const double p = std::max(std::fabs(s[0][0]), std::fabs(s[0][1])), det = glm::determinant(s);
    if (!(p > 0.0) || !(det != 0.0)) return 0.0;
    lo = std::min({lo, p, std::fabs(det) / p});
    hi = std::max({hi, p, std::fabs(det) / p});
    inv[v] = glm::inverse(s);
  }
  for (std::size_t v = m; v-- > 0;) r[v] = inv[v] * (v + 1 < m ? r[v] - j.u[v] * r[v + 1] : r[v]);
  return std::isfinite(lo / hi) ? lo / hi : 0.0;
}

}  // namespace pathex
