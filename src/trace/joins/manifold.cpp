// The manifold walk (trace/joins/manifold.h): Newton's method on the half-vector constraints.
#include "trace/joins/manifold.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>

#include "trace/block_tridiagonal.h"
#include "trace/differential.h"
#include "trace/joins/join.h"

namespace pathex {
namespace {

using glm::dvec3;
constexpr std::size_t kCap = static_cast<std::size_t>(tracer::kMaxChain);  // vertices of a chain, at most
using Blocks = TridiagonalBlocks<kCap>;  // ∂C/∂X: vertex v's constraint against v - 1 (l), v (d), v + 1 (u); b: ∂C/∂b
constexpr std::size_t kDim = 2 * kCap;                                    // its unknowns

// One vertex's local state at given positions: its surface's derivatives, the unit directions to
// its neighbours and their lengths, and the normalised generalized half vector.
struct Local {
  SurfaceDerivatives g;
  dvec3 wi{0.0}, wo{0.0}, h{0.0};
  double li = 0.0, lo = 0.0, lh = 0.0;
};

// A vertex's constraint: ĥ's part along the surface, on the tangent pair (s, t).
void constraint(const Local& l, const dvec3& s, const dvec3& t, double* c) {
  const dvec3 tangential = l.h - glm::dot(l.h, l.g.ns) * l.g.ns;
  c[0] = glm::dot(tangential, s);
  c[1] = glm::dot(tangential, t);
}

// Every vertex's local state and the constraints (2 per vertex, on the tangent pairs `s`, `t`
// given, or the vertex's own when null): false when one is undefined (a neighbour coincides with
// the vertex, or the half vector vanishes).
bool evaluate(const std::vector<ChainVertex>& x, const dvec3* p, const dvec3& a, const dvec3& b, const dvec3* s, const dvec3* t,
              Local* loc, double* c) {
  const std::size_t m = x.size();
  for (std::size_t i = 0; i < m; ++i) {
    Local& l = loc[i];
    l.g = surface_derivatives(*x[i].shape, x[i].primitive, p[i]);
    const dvec3 ei = (i == 0 ? a : p[i - 1]) - p[i], eo = (i + 1 == m ? b : p[i + 1]) - p[i];
    l.li = glm::length(ei);
    l.lo = glm::length(eo);
    if (!(l.li > 0.0) || !(l.lo > 0.0)) return false;
    l.wi = ei / l.li;
    l.wo = eo / l.lo;
    const dvec3 h = x[i].eta_light * l.wi + x[i].eta_eye * l.wo;
    l.lh = glm::length(h);
    if (!(l.lh > 0.0)) return false;
    l.h = h / l.lh;
    constraint(l, s ? s[i] : l.g.dpdu, t ? t[i] : l.g.dpdv, c + 2 * i);
  }
  return true;
}

double largest(const double* c, std::size_t n) {
  double m = 0.0;
  for (std::size_t i = 0; i < n; ++i) m = std::max(m, std::fabs(c[i]));
  return m;
}

// The constraint Jacobian (Jakob and Marschner 2012), analytic: each vertex moves along its tangent
// pair (dp/du = dpdu, dn/du = dndu, as trace/differential.h), which changes its own constraint and
// its neighbours'; ∂C/∂b for b moving along (sb, tb) when given. The constraints are on each
// vertex's own tangent pair r: C_r = ĥ · r (n · r = 0 at the vertex), so with ĥ = h / |h| a change
// dh of h changes C_r by dh · a_r, a_r = (r - ĥ (ĥ·r)) / |h|; a neighbour at w = e / |e| moving by d
// turns w by (d - w (w·d)) / |e|, which changes C_r by d · g, g = η (a_r - w (w·a_r)) / |e| (gi: the
// light side's, go: the eye side's); the vertex's own move by d turns both directions the other way
// and the normal by dn: -(gi + go) · d - (ĥ·n)(dn · r).
void jacobian(const std::vector<ChainVertex>& x, const Local* loc, Blocks& j, const dvec3* sb = nullptr, const dvec3* tb = nullptr) {
  const std::size_t m = x.size();
  const auto axes = [&](std::size_t v) { return std::array<dvec3, 2>{loc[v].g.dpdu, loc[v].g.dpdv}; };
  for (std::size_t v = 0; v < m; ++v) {
    const Local& l = loc[v];
    const std::array<dvec3, 2> r = axes(v), dn = {l.g.dndu, l.g.dndv};
    // (l of the first vertex and, without sb, b are not used)
    const std::array<dvec3, 2> before = v > 0 ? axes(v - 1) : r, after = v + 1 < m ? axes(v + 1) : sb ? std::array<dvec3, 2>{*sb, *tb} : r;
    const double hn = glm::dot(l.h, l.g.ns);
    for (int k = 0; k < 2; ++k) {
      const dvec3 a = (r[k] - l.h * glm::dot(l.h, r[k])) / l.lh;
      const dvec3 gi = (x[v].eta_light / l.li) * (a - l.wi * glm::dot(l.wi, a)), go = (x[v].eta_eye / l.lo) * (a - l.wo * glm::dot(l.wo, a));
      for (int axis = 0; axis < 2; ++axis) {
        j.d[v][axis][k] = -glm::dot(gi + go, r[axis]) - hn * glm::dot(dn[axis], r[k]);
        j.l[v][axis][k] = glm::dot(gi, before[axis]);
        (v + 1 < m ? j.u[v] : j.b)[axis][k] = glm::dot(go, after[axis]);
      }
    }
  }
}

}  // namespace

double chain_dw_db(const std::vector<ChainVertex>& x, const dvec3& a, const dvec3& b, const dvec3& nb, double singular) {
  const std::size_t m = x.size();
  if (m == 0 || m > kCap) return 0.0;
  struct Scratch {
    std::array<dvec3, kCap> p;
    std::array<Local, kCap> loc;
    std::array<double, kDim> c;
    Blocks j;
    std::array<glm::dmat2, kCap> dx;
  };
  static thread_local Scratch scratch;
  auto& [p, loc, c, j, dx] = scratch;
  for (std::size_t i = 0; i < m; ++i) p[i] = x[i].p;
  if (!evaluate(x, p.data(), a, b, nullptr, nullptr, loc.data(), c.data())) return 0.0;
  // dX/db = -(∂C/∂X)⁻¹ ∂C/∂b for b moving along a tangent pair (sb, tb) of its plane.
  dvec3 sb, tb;
  tangent_frame(glm::normalize(nb), &sb, &tb);
  jacobian(x, loc.data(), j, &sb, &tb);
  std::fill(dx.begin(), dx.begin() + static_cast<std::ptrdiff_t>(m), glm::dmat2(0.0));
  dx[m - 1] = -j.b;
  if (solve_blocks(j, m, dx.data()) <= singular) return 0.0;  // dx becomes dX/db
  // The first vertex's move turns the direction leaving a: the 2 × 2 map from b's tangent plane
  // to the plane across w_a, whose determinant is the solid angle per area.
  const dvec3 e = x[0].p - a;
  const double len = glm::length(e);
  const dvec3 wa = e / len;
  dvec3 e1, e2;
  tangent_frame(wa, &e1, &e2);
  double mtx[2][2];
  for (int col = 0; col < 2; ++col) {
    const dvec3 dx0 = dx[0][col][0] * loc[0].g.dpdu + dx[0][col][1] * loc[0].g.dpdv;
    const dvec3 dw = (dx0 - glm::dot(dx0, wa) * wa) / len;
    mtx[0][col] = glm::dot(dw, e1);
    mtx[1][col] = glm::dot(dw, e2);
  }
  const double dw_db = std::fabs(mtx[0][0] * mtx[1][1] - mtx[0][1] * mtx[1][0]);
  return std::isfinite(dw_db) ? dw_db : 0.0;
}

ManifoldWalk solve_chain(std::vector<ChainVertex>& x, const dvec3& a, const dvec3& b, const dvec3& nb, double scene_size,
                         const ManifoldOptions& o, bool term) {
  ManifoldWalk w;
  const std::size_t m = x.size(), n = 2 * m;
  if (m == 0 || m > kCap) {
    w.failure = ManifoldFailure::kNoSolution;
    return w;
  }
  // Fixed-size scratch, one per thread and reused: a walk allocates and clears nothing.
  struct Scratch {
    std::array<dvec3, kCap> p, y, s, t;
    std::array<Local, kCap> loc, trial;
    std::array<double, kDim> c, cy;
    std::array<glm::dvec2, kCap> step;
    Blocks j;
  };
  static thread_local Scratch scratch;
  auto& [p, y, s, t, loc_store, trial_store, c, cy, step, j] = scratch;
  // The local state at p, and at a step's trial point (which becomes p's when the step is taken).
  Local* loc = loc_store.data();
  Local* trial = trial_store.data();
  for (std::size_t i = 0; i < m; ++i) p[i] = x[i].p;
  // The solution's type at positions q: a refraction's neighbours on opposite sides, a reflection's
  // on one, the light's on the seed's side.
  const auto right_type = [&](const dvec3* q) {  // (loc holds q's local state)
    for (std::size_t i = 0; i < m; ++i) {
      const dvec3& nrm = loc[i].g.n;
      const dvec3 prev = i == 0 ? a : q[i - 1], next = i + 1 == m ? b : q[i + 1];
      const double light = glm::dot(prev - q[i], nrm), sides = light * glm::dot(next - q[i], nrm);
      if ((x[i].reflect ? !(sides > 0.0) : !(sides < 0.0)) || light * x[i].light_side < 0.0) return false;
    }
    return true;
  };
  bool solved = false;
  int polish = 0;
  const double root = std::max(1e-4 * o.threshold, 1e-12);  // what polishing reaches at a root (rounding bounds it)
  bool evaluated = false;  // loc holds p's state (a step taken: its trial's), c still to be put on p's own tangent pairs
  for (w.iterations = 0; w.iterations <= o.max_iterations; ++w.iterations) {
    if (evaluated) {
      for (std::size_t i = 0; i < m; ++i) constraint(loc[i], loc[i].g.dpdu, loc[i].g.dpdv, c.data() + 2 * i);
    } else if (!evaluate(x, p.data(), a, b, nullptr, nullptr, loc, c.data())) {
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
    evaluated = false;
    const double err = largest(c.data(), n);
    // Solved below the threshold; up to three more steps polish it (Newton converges
    // quadratically there), so that the same solution found from two seeds compares equal. A
    // point whose polishing stalls above `root` is no root but a near miss: beyond
    // a fold of the chains (a caustic's edge) the constraints' smallest value is small, not zero,
    // and such points, their |dω_a/dA_b| near the fold's divergence, were counted as chains (a
    // bias: issue 40, twelfth session, bench/README.md).
    const bool within = err < o.threshold;
    // Solved to the wrong type: polishing moves it by about the threshold, which keeps its type
    // (a neighbour that close to a vertex's tangent plane aside), so it is not polished.
    if (within && polish == 0 && !right_type(p.data())) {
      w.failure = ManifoldFailure::kWrongType;
      return w;
    }
    if (within && err < root) {
      solved = true;
      break;
    }
    if (polish == 3) {  // a polish that stalled: no root (above)
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
    polish += within ? 1 : 0;
    if (w.iterations == o.max_iterations) break;  // (not solved)
    jacobian(x, loc, j);
    for (std::size_t v = 0; v < m; ++v) step[v] = -glm::dvec2(c[2 * v], c[2 * v + 1]);
    if (solve_blocks(j, m, step.data()) <= o.singular) {
      w.failure = ManifoldFailure::kSingular;
      return w;
    }
    for (std::size_t i = 0; i < m; ++i) {
      s[i] = loc[i].g.dpdu;
      t[i] = loc[i].g.dpdv;
    }
    // Step halving: the largest constraint (on the current tangent pairs) must fall.
    bool moved = false;
    for (double lambda = 1.0; lambda > 1.0 / 1024.0 && !moved; lambda *= 0.5) {
      bool on = true;
      for (std::size_t v = 0; v < m && on; ++v) {
        const std::optional<dvec3> q = move_on_surface(*x[v].shape, x[v].primitive, p[v], lambda * (step[v].x * s[v] + step[v].y * t[v]));
        if (q) y[v] = *q;
        on = q.has_value();
      }
      if (!on) continue;
      if (evaluate(x, y.data(), a, b, s.data(), t.data(), trial, cy.data()) && largest(cy.data(), n) < err) {
        std::copy(y.begin(), y.begin() + static_cast<std::ptrdiff_t>(m), p.begin());
        std::swap(loc, trial);  // the trial's local state is the new p's: not evaluated again
        moved = evaluated = true;
      }
    }
    if (!moved) {
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
  }
  for (std::size_t i = 0; i < m; ++i) x[i].p = p[i];
  if (!solved) {
    w.failure = ManifoldFailure::kIterationLimit;
    return w;
  }
  // --- the solution's type, polished ---
  if (!right_type(p.data())) {
    w.failure = ManifoldFailure::kWrongType;
    return w;
  }
  // --- its segments ---
  const double shortest = o.min_segment * scene_size;
  for (std::size_t i = 0; i <= m; ++i) {
    const dvec3 from = i == 0 ? a : x[i - 1].p, to = i == m ? b : x[i].p;
    if (!(glm::length(to - from) >= shortest)) {
      w.failure = ManifoldFailure::kTooShort;
      return w;
    }
  }
  // --- the generalized geometry term |dω_a / dA_b| ---
  if (!term) return w;
  w.dw_db = chain_dw_db(x, a, b, nb, o.singular);
  if (!(w.dw_db > 0.0)) w.failure = ManifoldFailure::kSingular;
  return w;
}

}  // namespace pathex
