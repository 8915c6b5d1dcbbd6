// Per-sample random numbers for the tracer, and the standard warps of the unit square.
//
// Counter-based, not stateful: the d-th number used by sample s of pixel p under seed k is a pure
// function
//
//     u(k, p, s, d) = top24( splitmix64_output(key(k, p, s), d) ) · 2^-24,
//     key(k, p, s)  = mix(mix(mix(k + C0) ^ (p + C1)) ^ (s + C2)),
//
// where mix is Stafford's "Mix13" 64-bit finaliser (the output function of SplitMix64, a
// bijection with full avalanche) and splitmix64_output(key, d) = mix(key + (d + 1)·γ) with γ the
// golden-ratio increment, i.e. the (d+1)-th output of a SplitMix64 generator seeded with `key`.
// Nothing depends on which thread draws a sample or in which order, so renders are bit-identical
// for every thread count (DESIGN §7: estimates must not depend on how work was split).
//
// Floats are the top 24 bits times 2^-24: every value k / 2^24 is exactly representable, the
// largest is 1 − 2^-24, so 1.0 is never returned and 0.0 is (with probability 2^-24). Callers that
// divide by u or take log(u) must guard 0 themselves.
//
// The second half of this file maps uniform numbers to the distributions the BSDFs, lights and
// sensors sample (cosine hemisphere, sphere, cone, disk, triangle); each comes with its density so
// that sampling and pdf evaluation cannot disagree.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include "trace/sobol.h"

namespace pathex {

// --- counter-based random numbers ---

// Stafford's Mix13, the SplitMix64 finaliser: a bijection on 64-bit words in which every input
// bit affects every output bit with probability close to 1/2. mix64(0) == 0, hence the offsets.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

inline constexpr std::uint64_t kGoldenGamma = 0x9e3779b97f4a7c15ULL;

// The key of one sample's stream. Asymmetric in its arguments: (p, s) and (s, p) differ.
constexpr std::uint64_t stream_key(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample) {
  std::uint64_t h = mix64(seed + 0x243f6a8885a308d3ULL);          // offsets: digits of pi
  h = mix64(h ^ (pixel + 0x13198a2e03707344ULL));
  return mix64(h ^ (sample + 0xa4093822299f31d0ULL));
}

// 64 random bits: dimension `dim` of the stream `key`.
constexpr std::uint64_t stream_bits(std::uint64_t key, std::uint64_t dim) {
  return mix64(key + (dim + 1) * kGoldenGamma);
}

// The top 24 bits as a float in [0, 1): exact, and never 1.0.
constexpr float bits_to_unit_float(std::uint64_t bits) {
  return static_cast<float>(bits >> 40) * 0x1p-24f;
}

inline constexpr float kOneMinusEpsilon = 1.0f - 0x1p-24f;  // the largest float below 1

// Which numbers a Sampler draws (`pathex trace --sampler`): `independent`, the counter-based
// stream above (every number independent of every other), or `sobol`, Owen-scrambled Sobol points
// (trace/sobol.h): each pair of dimensions drawn with get2d() is stratified over a pixel's passes
// of one replicate (the first 2^k points of a replicate's sequence put one point in every elementary
// interval of area 2^-k), each number on its own still uniform and independent across dimension
// pairs. Both are functions of (seed, pixel, pass, dimension) and the replicate count alone.
enum class SamplerKind : std::uint8_t { kIndependent, kSobol };
constexpr const char* to_string(SamplerKind k) { return k == SamplerKind::kSobol ? "sobol" : "independent"; }

// The Sobol stream of pass `pass` of a render of `replicates` replicates per pixel: the renderer
// deals passes to replicates round-robin (replicate = pass mod R, stats/histogram.h "Batches"), and
// each replicate is an independently scrambled sequence whose point index is pass div R —
// randomized quasi-Monte Carlo with R independent replicates per pixel, so that the standard
// error computed from their differences is honest (issue 36: one sequence dealt over the batches
// made them correlated and the stderr overstate the error 1.8–7×), while each replicate keeps the
// gain of spp / R points of one sequence (issue 39). Every replicate still receives a prefix of its
// own sequence from any prefix of the passes (an interrupted render, a shard of whole chunks).
// Returned: the word that keys the scramble (the replicate and the index's bits past 32: passes
// past 2^32 of a replicate start a new scrambled sequence; with one replicate it is pass >> 32, the
// key of the sampler before replicates had sequences of their own) and the point's index.
struct SobolStream {
  std::uint64_t key_word;
  std::uint32_t index;
};
constexpr SobolStream sobol_stream(std::uint64_t pass, std::uint64_t replicates) {
  const std::uint64_t replicate = pass % replicates, i = pass / replicates;
  return {(replicate << 32) | (i >> 32), static_cast<std::uint32_t>(i)};
}

// One sample's random numbers, drawn in order of dimension. Copying a Sampler copies its position;
// set_dimension() gives a strategy a fixed block of dimensions (e.g. 2 per bounce) so that two
// strategies never consume each other's numbers. With `sobol`, get2d() draws the pair (d, d + 1)
// as one stratified 2-D point, so a dimension must always be drawn the same way (as the first of
// a pair, the second, or alone), which a fixed dimension block gives. `replicates` (≥ 1, below
// 2^32) is the render's replicate count per pixel, which `sobol` keys its sequences by (sobol_stream()).
class Sampler {
 public:
  Sampler(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample, SamplerKind kind = SamplerKind::kIndependent,
          std::uint64_t replicates = 1)
      : Sampler(seed, pixel, sample, kind, kind == SamplerKind::kSobol ? sobol_stream(sample, replicates) : SobolStream{sample, 0}) {}

  // Forced inline: a walk draws a few numbers per vertex, and the call (and the test of kind_ in a
  // function the compiler will not inline) cost as much as the independent stream's hashing.
  [[gnu::always_inline]] float get1d() { return at(dim_++); }
  [[gnu::always_inline]] glm::vec2 get2d() {
    const glm::vec2 u = at2d(dim_);
    dim_ += 2;
    return u;
  }
  // get1d() and get2d() for a caller that reads the number only when `read`: the cursor moves the
  // same, but an unread number is not computed (0 is returned). Every number is a function of its
  // dimension, so nothing drawn later changes; what is saved is the number's cost, ~6 ns for a
  // Sobol point (bench/sampler_bench.cpp), which a point light's position, a pinhole's lens, a
  // lone light's pick or a mirror's direction never read. The caller states what its model reads.
  [[gnu::always_inline]] float get1d_if(bool read) {
    const float u = read ? at(dim_) : 0.0f;
    ++dim_;
    return u;
  }
  [[gnu::always_inline]] glm::vec2 get2d_if(bool read) {
    const glm::vec2 u = read ? at2d(dim_) : glm::vec2(0.0f);
    dim_ += 2;
    return u;
  }
  // at2d(), computed where it is called rather than where its value is first used: the compiler
  // may not sink it past a later call. A walk draws a vertex's direction before tracing the ray
  // that finds the vertex, so that the number's chain of dependent multiplies (~100 cycles for a
  // Sobol point) runs while the ray is traced instead of delaying the scattering after it.
  [[gnu::always_inline]] glm::vec2 at2d_now(std::uint64_t dim) const {
    glm::vec2 u = at2d(dim);
#if defined(__GNUC__) && (defined(__x86_64__) || defined(__aarch64__))
    asm volatile("" : "+x"(u.x), "+x"(u.y));  // an opaque use: the value exists here
#endif
    return u;
  }
  void skip(std::uint64_t n) { dim_ += n; }
  // The numbers from here on are those of point `index` of the same scrambled sequences (sobol),
  // or of a stream of their own keyed by `salt` (independent): a split sample's run takes its
  // numbers past the camera's so (trace/accel/first_vertex_split.h).
  void reindex(std::uint32_t index, std::uint64_t salt) {
    if (kind_ == SamplerKind::kSobol) reversed_index_ = sobol::reverse_bits(index);
    else key_ = mix64(key_ ^ (salt + 0x452821e638d01377ULL));
  }
  // The number get1d() would draw at an absolute dimension, without moving the cursor.
  [[gnu::always_inline]] float at(std::uint64_t dim) const {
    if (kind_ == SamplerKind::kIndependent) return bits_to_unit_float(stream_bits(key_, dim));
    return sobol::to_unit_float(sobol::point1(reversed_index_, sobol_seeds(dim, /*pair=*/false)));
  }
  // The pair get2d() would draw at an absolute dimension, without moving the cursor.
  [[gnu::always_inline]] glm::vec2 at2d(std::uint64_t dim) const {
    if (kind_ == SamplerKind::kIndependent) return {at(dim), at(dim + 1)};
    const std::array<std::uint32_t, 2> p = sobol::point2(reversed_index_, sobol_seeds(dim, /*pair=*/true));
    return {sobol::to_unit_float(p[0]), sobol::to_unit_float(p[1])};
  }

  // The same numbers from here on (the same stream at the same dimension).
  friend bool operator==(const Sampler&, const Sampler&) = default;
  std::uint64_t dimension() const { return dim_; }
  void set_dimension(std::uint64_t dim) { dim_ = dim; }
  std::uint64_t key() const { return key_; }
  SamplerKind kind() const { return kind_; }

 private:
  // The scrambling seeds of dimension `dim` of this pixel's replicate (of the pair starting there).
  sobol::Seeds sobol_seeds(std::uint64_t dim, bool pair) const {
    const std::uint64_t h = stream_bits(key_, dim);
    return {static_cast<std::uint32_t>(h), static_cast<std::uint32_t>(h >> 32),
            pair ? static_cast<std::uint32_t>((h * kGoldenGamma) >> 29) : 0u};  // the y seed: another 32 of h's bits, mixed
  }

  // sobol: the key is the replicate's (keyed by stream.key_word; the point's index is stream.index).
  Sampler(std::uint64_t seed, std::uint64_t pixel, std::uint64_t sample, SamplerKind kind, SobolStream stream)
      : kind_(kind),
        key_(stream_key(seed, pixel, kind == SamplerKind::kSobol ? stream.key_word : sample)),
        reversed_index_(sobol::reverse_bits(stream.index)) {}

  SamplerKind kind_;
  std::uint64_t key_;
  std::uint32_t reversed_index_;  // sobol: the point's index in its replicate's sequence, bit-reversed
  std::uint64_t dim_ = 0;
};

// --- warps of the unit square ---

inline constexpr float kPi = std::numbers::pi_v<float>;
inline constexpr float kInvPi = std::numbers::inv_pi_v<float>;

inline float safe_sqrt(float x) { return std::sqrt(std::max(x, 0.0f)); }

// Shirley–Chiu concentric map of [0,1)^2 onto the unit disk: area preserving up to a constant
// (density 1/π on the disk) and low distortion, so stratification survives.
inline glm::vec2 sample_concentric_disk(glm::vec2 u) {
  const float a = 2.0f * u.x - 1.0f;
  const float b = 2.0f * u.y - 1.0f;
  if (a == 0.0f && b == 0.0f) return {0.0f, 0.0f};
  float r, theta;
  if (std::abs(a) > std::abs(b)) {
    r = a;
    theta = (kPi / 4.0f) * (b / a);
  } else {
    r = b;
    theta = kPi / 2.0f - (kPi / 4.0f) * (a / b);
  }
  return {r * std::cos(theta), r * std::sin(theta)};
}

// Cosine-weighted direction about +z (Malley's method); density cos θ / π. z may be 0 at the rim.
inline glm::vec3 sample_cosine_hemisphere(glm::vec2 u) {
  const glm::vec2 d = sample_concentric_disk(u);
  return {d.x, d.y, safe_sqrt(1.0f - d.x * d.x - d.y * d.y)};
}
inline float cosine_hemisphere_pdf(float cos_theta) { return std::max(cos_theta, 0.0f) * kInvPi; }

// Uniform direction on the unit sphere; density 1 / (4π).
inline glm::vec3 sample_uniform_sphere(glm::vec2 u) {
  const float z = 1.0f - 2.0f * u.x;
  const float r = safe_sqrt(1.0f - z * z);
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline constexpr float kUniformSpherePdf = 0.25f * std::numbers::inv_pi_v<float>;

// Uniform direction in the cone about +z whose half-angle θ has 1 − cos θ = `one_minus_cos`
// (given as such, so that a narrow cone keeps its precision); density 1 / (2π (1 − cos θ)).
// 1 − z = u.x (1 − cos θ), and sin² = (1 − z)(1 + z), both without cancellation.
inline glm::vec3 sample_uniform_cone_by_height(glm::vec2 u, float one_minus_cos) {
  const float one_minus_z = u.x * one_minus_cos;
  const float r = safe_sqrt(one_minus_z * (2.0f - one_minus_z));
  const float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), 1.0f - one_minus_z};
}
// The same for the cone of half-angle acos(cos_max); density 1 / (2π(1 − cos_max)).
inline glm::vec3 sample_uniform_cone(glm::vec2 u, float cos_max) { return sample_uniform_cone_by_height(u, 1.0f - cos_max); }
inline float uniform_cone_pdf(float cos_max) { return 1.0f / (2.0f * kPi * (1.0f - cos_max)); }

// Uniform barycentrics (b0, b1) on a triangle, b2 = 1 − b0 − b1 (the square-root-free fold).
inline glm::vec2 sample_uniform_triangle(glm::vec2 u) {
  if (u.x + u.y < 1.0f) return u;
  return {1.0f - u.x, 1.0f - u.y};
}

}  // namespace pathex
