// The manifold walk (trace/joins/manifold.h): Newton's method on the half-vector constraints.
#include "trace/joins/manifold.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>

#include "trace/differential.h"

namespace pathex {
namespace {

using glm::dvec3;

// The constraint at vertex i of `x` (light end a before x[0], eye end b after x[m-1]): the
// tangential part of the generalized half vector, on the tangent pair (s, t) given. Empty when a
// neighbour coincides with the vertex.
std::optional<glm::dvec2> constraint(const std::vector<ChainVertex>& x, std::size_t i, const dvec3& a, const dvec3& b,
                                     const dvec3& s, const dvec3& t) {
  const dvec3& p = x[i].p;
  const dvec3 prev = i == 0 ? a : x[i - 1].p;
  const dvec3 next = i + 1 == x.size() ? b : x[i + 1].p;
  const dvec3 ei = prev - p, eo = next - p;
  const double li = glm::length(ei), lo = glm::length(eo);
  if (!(li > 0.0) || !(lo > 0.0)) return std::nullopt;
  const dvec3 wi = ei / li, wo = eo / lo;
  const dvec3 n = surface_derivatives(*x[i].shape, x[i].primitive, p).ns;  // the normal the tracer shades with
  dvec3 h = x[i].eta_light * wi + x[i].eta_eye * wo;
  const double lh = glm::length(h);
  if (!(lh > 0.0)) return std::nullopt;
  h /= lh;
  h -= glm::dot(h, n) * n;
  return glm::dvec2(glm::dot(h, s), glm::dot(h, t));
}

// Every vertex's tangent pair at its current position.
struct Frames {
  std::vector<dvec3> s, t;
};
Frames frames_of(const std::vector<ChainVertex>& x) {
  Frames f;
  for (const ChainVertex& v : x) {
    const SurfaceDerivatives d = surface_derivatives(*v.shape, v.primitive, v.p);
    f.s.push_back(d.dpdu);
    f.t.push_back(d.dpdv);
  }
  return f;
}

// All constraints stacked (2 per vertex); empty when one is undefined.
std::optional<std::vector<double>> constraints(const std::vector<ChainVertex>& x, const dvec3& a, const dvec3& b, const Frames& f) {
  std::vector<double> c(2 * x.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    const std::optional<glm::dvec2> ci = constraint(x, i, a, b, f.s[i], f.t[i]);
    if (!ci) return std::nullopt;
    c[2 * i] = ci->x;
    c[2 * i + 1] = ci->y;
  }
  return c;
}

double largest(const std::vector<double>& c) {
  double m = 0.0;
  for (double v : c) m = std::max(m, std::fabs(v));
  return m;
}

// A dense square system solved in place by Gaussian elimination with partial pivoting: `rhs` has
// `cols` columns, row-major. Returns min |pivot| / max |pivot| (0: singular).
double solve_in_place(std::vector<double>& m, std::size_t n, std::vector<double>& rhs, std::size_t cols) {
  double lo = INFINITY, hi = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t piv = k;
    for (std::size_t r = k + 1; r < n; ++r)
      if (std::fabs(m[r * n + k]) > std::fabs(m[piv * n + k])) piv = r;
    if (piv != k) {
      for (std::size_t c = 0; c < n; ++c) std::swap(m[k * n + c], m[piv * n + c]);
      for (std::size_t c = 0; c < cols; ++c) std::swap(rhs[k * cols + c], rhs[piv * cols + c]);
    }
    const double p = m[k * n + k];
    lo = std::min(lo, std::fabs(p));
    hi = std::max(hi, std::fabs(p));
    if (p == 0.0) return 0.0;
    for (std::size_t r = k + 1; r < n; ++r) {
      const double f = m[r * n + k] / p;
      if (f == 0.0) continue;
      for (std::size_t c = k; c < n; ++c) m[r * n + c] -= f * m[k * n + c];
      for (std::size_t c = 0; c < cols; ++c) rhs[r * cols + c] -= f * rhs[k * cols + c];
    }
  }
  for (std::size_t k = n; k-- > 0;)
    for (std::size_t c = 0; c < cols; ++c) {
      double v = rhs[k * cols + c];
      for (std::size_t j = k + 1; j < n; ++j) v -= m[k * n + j] * rhs[j * cols + c];
      rhs[k * cols + c] = v / m[k * n + k];
    }
  return hi > 0.0 && std::isfinite(lo / hi) ? lo / hi : 0.0;
}

// The constraint Jacobian ∂C/∂X (2m × 2m, row-major) by central differences along each vertex's
// tangent pair, step h; and, when `jb` is given, ∂C/∂b (2m × 2) for b moving along (sb, tb).
bool jacobian(const std::vector<ChainVertex>& x, const dvec3& a, const dvec3& b, const Frames& f, double h, std::vector<double>* j,
              const dvec3* sb, const dvec3* tb, std::vector<double>* jb) {
  const std::size_t m = x.size(), n = 2 * m;
  j->assign(n * n, 0.0);
  std::vector<ChainVertex> y = x;
  for (std::size_t v = 0; v < m; ++v)
    for (int axis = 0; axis < 2; ++axis) {
      const dvec3 dir = axis == 0 ? f.s[v] : f.t[v];
      const std::optional<dvec3> plus = move_on_surface(*x[v].shape, x[v].primitive, x[v].p, h * dir);
      const std::optional<dvec3> minus = move_on_surface(*x[v].shape, x[v].primitive, x[v].p, -h * dir);
      if (!plus || !minus) return false;  // at the shape's edge: no two-sided difference
      for (std::size_t i = (v > 0 ? v - 1 : 0); i <= std::min(v + 1, m - 1); ++i) {
        y[v].p = *plus;
        const std::optional<glm::dvec2> cp = constraint(y, i, a, b, f.s[i], f.t[i]);
        y[v].p = *minus;
        const std::optional<glm::dvec2> cm = constraint(y, i, a, b, f.s[i], f.t[i]);
        if (!cp || !cm) return false;
        (*j)[(2 * i) * n + 2 * v + static_cast<std::size_t>(axis)] = (cp->x - cm->x) / (2.0 * h);
        (*j)[(2 * i + 1) * n + 2 * v + static_cast<std::size_t>(axis)] = (cp->y - cm->y) / (2.0 * h);
      }
      y[v].p = x[v].p;
    }
  if (jb) {
    jb->assign(n * 2, 0.0);
    const std::size_t i = m - 1;  // only the last vertex sees b
    for (int axis = 0; axis < 2; ++axis) {
      const dvec3 dir = axis == 0 ? *sb : *tb;
      const std::optional<glm::dvec2> cp = constraint(x, i, a, b + h * dir, f.s[i], f.t[i]);
      const std::optional<glm::dvec2> cm = constraint(x, i, a, b - h * dir, f.s[i], f.t[i]);
      if (!cp || !cm) return false;
      (*jb)[(2 * i) * 2 + static_cast<std::size_t>(axis)] = (cp->x - cm->x) / (2.0 * h);
      (*jb)[(2 * i + 1) * 2 + static_cast<std::size_t>(axis)] = (cp->y - cm->y) / (2.0 * h);
    }
  }
  return true;
}

}  // namespace

ManifoldWalk solve_chain(std::vector<ChainVertex>& x, const dvec3& a, const dvec3& b, const dvec3& nb, double scene_size,
                         const ManifoldOptions& o) {
  ManifoldWalk w;
  const std::size_t m = x.size(), n = 2 * m;
  if (m == 0) {
    w.failure = ManifoldFailure::kNoSolution;
    return w;
  }
  const double h = 1e-7 * std::max(scene_size, 1e-30);  // the difference step
  std::vector<double> j, jb;
  bool solved = false;
  int polish = 0;
  for (w.iterations = 0; w.iterations <= o.max_iterations; ++w.iterations) {
    const Frames f = frames_of(x);
    const std::optional<std::vector<double>> c = constraints(x, a, b, f);
    if (!c) {
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
    const double err = largest(*c);
    // Solved below the threshold; up to three more steps polish it (Newton converges
    // quadratically there), so that the same solution found from two seeds compares equal.
    const bool within = err < o.threshold;
    if (within && (err < 1e-4 * o.threshold || polish == 3)) {
      solved = true;
      break;
    }
    polish += within ? 1 : 0;
    if (w.iterations == o.max_iterations) {
      solved = within;
      break;
    }
    if (!jacobian(x, a, b, f, h, &j, nullptr, nullptr, nullptr)) {
      if (within) { solved = true; break; }
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
    std::vector<double> step(c->begin(), c->end());
    for (double& v : step) v = -v;
    if (solve_in_place(j, n, step, 1) <= o.singular) {
      w.failure = ManifoldFailure::kSingular;
      return w;
    }
    // Step halving: the largest constraint must fall.
    bool moved = false;
    for (double lambda = 1.0; lambda > 1.0 / 1024.0 && !moved; lambda *= 0.5) {
      std::vector<ChainVertex> y = x;
      bool on = true;
      for (std::size_t v = 0; v < m && on; ++v) {
        const std::optional<dvec3> p =
            move_on_surface(*x[v].shape, x[v].primitive, x[v].p, lambda * (step[2 * v] * f.s[v] + step[2 * v + 1] * f.t[v]));
        if (p) y[v].p = *p;
        on = p.has_value();
      }
      if (!on) continue;
      const std::optional<std::vector<double>> cy = constraints(y, a, b, f);
      if (cy && largest(*cy) < err) {
        x = std::move(y);
        moved = true;
      }
    }
    if (!moved) {
      if (within) { solved = true; break; }  // as good as rounding allows
      w.failure = ManifoldFailure::kNoSolution;
      return w;
    }
  }
  if (!solved) {
    w.failure = ManifoldFailure::kIterationLimit;
    return w;
  }
  // --- the solution's type: a refraction's neighbours on opposite sides, a reflection's on one,
  //     the light's on the seed's side ---
  for (std::size_t i = 0; i < m; ++i) {
    const dvec3 nrm = surface_derivatives(*x[i].shape, x[i].primitive, x[i].p).n;
    const dvec3 prev = i == 0 ? a : x[i - 1].p, next = i + 1 == m ? b : x[i + 1].p;
    const double light = glm::dot(prev - x[i].p, nrm), sides = light * glm::dot(next - x[i].p, nrm);
    if ((x[i].reflect ? !(sides > 0.0) : !(sides < 0.0)) || light * x[i].light_side < 0.0) {
      w.failure = ManifoldFailure::kWrongType;
      return w;
    }
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
  const Frames f = frames_of(x);
  dvec3 sb, tb;
  tangent_frame(glm::normalize(nb), &sb, &tb);
  if (!jacobian(x, a, b, f, h, &j, &sb, &tb, &jb)) {
    w.failure = ManifoldFailure::kNoSolution;
    return w;
  }
  for (double& v : jb) v = -v;
  if (solve_in_place(j, n, jb, 2) <= o.singular) {  // jb becomes dX/db (2m × 2)
    w.failure = ManifoldFailure::kSingular;
    return w;
  }
  const dvec3 e = x[0].p - a;
  const double len = glm::length(e);
  const dvec3 wa = e / len;
  dvec3 e1, e2;
  tangent_frame(wa, &e1, &e2);
  double mtx[2][2];
  for (int col = 0; col < 2; ++col) {
    const dvec3 dx0 = jb[0 * 2 + static_cast<std::size_t>(col)] * f.s[0] + jb[1 * 2 + static_cast<std::size_t>(col)] * f.t[0];
    const dvec3 dw = (dx0 - glm::dot(dx0, wa) * wa) / len;
    mtx[0][col] = glm::dot(dw, e1);
    mtx[1][col] = glm::dot(dw, e2);
  }
  w.dw_db = std::fabs(mtx[0][0] * mtx[1][1] - mtx[0][1] * mtx[1][0]);
  if (!std::isfinite(w.dw_db)) {
    w.failure = ManifoldFailure::kSingular;
    return w;
  }
  return w;
}

}  // namespace pathex
