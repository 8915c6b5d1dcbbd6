// A vertex of a subpath as the tracer keeps it (DESIGN §7): where it is, how it was sampled (its
// letter and its two area densities), and the throughput that reached it.
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace pathex::tracer {

using glm::vec3;
inline constexpr int kMaxVertices = 64;  // per subpath; max_bounces is clamped so paths fit

enum class Kind : std::uint8_t { kCamera, kLight, kSurface, kLens };

struct Vertex {
  Kind kind = Kind::kSurface;
  char letter = 'D';     // scattering letter: surface c_i; light c1 (direction); sensor c(k+1)
  char pos_letter = 'D'; // lights c0 and sensors c(k+2)
  bool finite = true;    // can be a join end: not a surface, or a surface with a finite BSDF part
  vec3 p{0.0f};
  vec3 n{0.0f};          // geometric normal (unit); zero for points (point, spot, pinhole, laser)
  vec3 err{0.0f};        // bound on p's rounding error (Hit::error): how far a ray leaving p is offset
  vec3 ns{0.0f};         // shading normal
  vec3 beta{1.0f};       // throughput up to and including this vertex
  float rr_throughput = 1.0f;  // beta's largest channel relative to the subpath's start, as Russian roulette measures it
  vec3 sigma{0.0f};      // σa of the medium the segment that reached this vertex crossed (trace/media.h)
  vec3 wo{0.0f};         // unit direction to the vertex before it on its subpath (zero for the first)
  float d2_wo = 0.0f;    // squared distance to that vertex
  float pdf_fwd = 0.0f;  // area density of sampling this vertex in its subpath's direction
  float pdf_rev = 0.0f;  // area density of sampling it from the other direction
  int shape = -1;        // surfaces and area-light points
  int primitive = 0;     // surfaces: the hit's triangle of a mesh (a chain's derivatives need it: chain_densities())
  glm::vec2 uv{0.0f};    // surfaces: the hit's surface parameters when the scene has textures (Hit::uv), else zero
  int light = -1;        // light vertices
  // Without short-circuits: which components are zero follows the scene's orientation, which no
  // branch predictor guesses (this test was an eighth of the tracer's mispredicted branches). On
  // the bits, signs cleared: a component is != 0 exactly when it has a bit besides its sign (NaN
  // too), and three float comparisons cost twice the instructions (each needs its NaN test).
  bool has_normal() const {
    return ((std::bit_cast<std::uint32_t>(n.x) | std::bit_cast<std::uint32_t>(n.y) | std::bit_cast<std::uint32_t>(n.z)) & 0x7fffffffu) != 0;
  }
};

// Sets v.wo and v.d2_wo from its predecessor's position.
inline void link(Vertex& v, const Vertex& pred) {
  const vec3 e = pred.p - v.p;
  v.d2_wo = glm::dot(e, e);
  v.wo = v.d2_wo > 0.0f ? e / std::sqrt(v.d2_wo) : vec3(0.0f);
}

// A throughput or contribution that carries nothing.
inline bool is_black(const vec3& v) { return v.x == 0.0f && v.y == 0.0f && v.z == 0.0f; }

// A vertex's density as the MIS ratios use it, a Dirac's densities (stored as 0) counting as 1.
// Branch-free (0 + 1 is exact, and f + 0 is f): Dirac vertices come and go along a path
// unpredictably. (Added in float, then widened: the same value, fewer instructions.)
inline double remap_density(float f) { return static_cast<double>(f + static_cast<float>(f == 0.0f)); }

// |cos| at `v` towards `w` (1 for vertices without a surface, such as point lights).
inline float abs_cos(const Vertex& v, const vec3& w) {
  // Arithmetic, not a choice (which compiled to a branch that mispredicted at every point vertex):
  // a point's n is zero, so its |cos| term is 0 and the added 1 is the whole value.
  return std::fabs(glm::dot(v.n, w)) + static_cast<float>(!v.has_normal());
}

// Density of the far end of a parallel beam per unit area there, relative to the near end's:
// points x and y on one line along w, with unit normals (zero: no surface), map areas as
// dA_x |cos θ_x| = dA_y |cos θ_y|.
inline float parallel_jacobian(const Vertex& far, const Vertex& near, const vec3& w) {
  const float c = abs_cos(near, w);
  return c > 0.0f ? abs_cos(far, w) / c : 0.0f;
}

// |cos| at `v` towards `w` with its shading normal: the BSDF's own cosine, which a join puts at
// both its ends (Veach's thesis §5.3; pbrt-v3's bdpt G with the shading normals). At the light
// subpath's end end_f() multiplies f by the adjoint's correction |wo·ns| |w·ng| / (|wo·ng| |w·ns|),
// so that end's factor is |w·ng| |wo·ns| / |wo·ng|: the area measure's geometric cosine and the
// correction of the segment the light came in on, as the random walk applies it. 1 for vertices
// without a surface; abs_cos(v, w) wherever ns == n (every surface but a smooth-shaded mesh).
inline float shading_cos(const Vertex& v, const vec3& w) {
  return std::fabs(glm::dot(v.ns, w)) + static_cast<float>(!v.has_normal());
}

// A full path x0 … xk in light-to-eye order as the integrator's joins form it, without copying a
// vertex: s light vertices (y0 replaced by a fresh sample light0 when given), the m vertices a
// connector constructs, t eye vertices in reverse (z0 replaced by eye0 when given).
struct PathView {
  const Vertex* light = nullptr;
  const Vertex* light0 = nullptr;
  const Vertex* chain = nullptr;
  const Vertex* eye = nullptr;
  const Vertex* eye0 = nullptr;
  int s = 0, m = 0, t = 0;
  int size() const { return s + m + t; }
  const Vertex& operator[](int i) const {
    if (i < s) return light_at(i);
    if (i < s + m) return chain[i - s];
    return eye_at(s + m + t - 1 - i);
  }
  // Light subpath vertex x_i (i < s), and eye subpath vertex j, x(s+m+t-1-j) (j < t): where a
  // caller knows which side a vertex is on, without operator[]'s two tests.
  const Vertex& light_at(int i) const { return i == 0 && light0 ? *light0 : light[i]; }
  const Vertex& eye_at(int j) const { return j == 0 && eye0 ? *eye0 : eye[j]; }
};

}  // namespace pathex::tracer
