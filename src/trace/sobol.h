// Randomised Sobol points: the numbers of the tracer's `sobol` sampler (trace/rng.h, Sampler).
//
// The sampler is padded, as pbrt-v4's PaddedSobolSampler and Burley's "Practical Hash-based Owen
// Scrambling" (JCGT 2020): the integrator draws its numbers one or two at a time (get1d, get2d),
// and every pair of dimensions (d, d+1) it draws together is a point of the first two Sobol
// dimensions, a (0,2)-sequence in base 2; every single dimension is the first Sobol dimension (the
// van der Corput sequence). No table of direction numbers past the second dimension is needed,
// and a dimension block at 2048 (render.cpp's kJoinDims) is as good as dimension 0. What makes the
// pairs of one sample independent of each other is randomisation keyed by a hash of (seed,
// pixel, dimension):
//
//   - the index of the point, the pass, is shuffled by a nested (Owen) scramble of its bits (each
//     bit flipped by a hash of the bits above it). That maps every aligned block of 2^k indices
//     onto an aligned block of 2^k indices, so the first 2^k passes of a pixel take 2^k
//     consecutive points of the sequence, which form a (0,k,2)-net; different dimension pairs take
//     different blocks in different orders, so they are not correlated with each other;
//   - each coordinate is xor-ed with a random word (a random digital shift), which keeps the net
//     property and makes every point, on its own, uniform on [0,1)² (at 2^-32, past a float's 24
//     bits).
//
// So for every pixel and pair of dimensions the first 2^k passes put exactly one point in each
// elementary interval of area 2^-k (tests/trace/sampler_test.cpp), while each pass on its own is a
// uniform point independent across dimension pairs: estimates stay unbiased for any integrand.
// Nothing depends on the number of passes asked for, on threads or on the order of drawing: the
// number is a function of (seed, pixel, pass, dimension), as the independent sampler's is, so
// renders stay bit-identical across thread counts and shards.
//
// Why a digital shift and not an Owen scramble of the coordinates too (pbrt-v4's default): the
// scramble needs the coordinate bit-reversed and back, three reversals and three hashes per pair,
// 7.0 ns a number against 1.8 ns now (build/bench/sampler_bench; the independent stream 1.05 ns);
// with the shift, the first Sobol dimension of the shuffled index is the shuffle's own
// (bit-reversed) output and the second a table lookup on it, so no bit is reversed per number.
// On the Cornell box the Owen variant's error was no lower (pt-nee 64 spp, bench/README.md), and
// the CPU it cost made it less efficient.
//
// The index shuffle is the hash-based scramble of Laine and Karras (2011) with Vegdahl's constants
// (as pbrt-v4's FastOwenScrambler): on the bit-reversed word, every step (x ^= x·even, x += seed,
// x *= odd) changes a bit only as a function of the bits below it, which is a nested (Owen)
// permutation of the digits.
#pragma once

#include <array>
#include <cstdint>

namespace pathex::sobol {

// The bytes swapped in one instruction, then the bits within each byte.
constexpr std::uint32_t reverse_bits(std::uint32_t v) {
  v = __builtin_bswap32(v);
  v = ((v >> 4) & 0x0f0f0f0fu) | ((v & 0x0f0f0f0fu) << 4);
  v = ((v >> 2) & 0x33333333u) | ((v & 0x33333333u) << 2);
  return ((v >> 1) & 0x55555555u) | ((v & 0x55555555u) << 1);
}

// The scramble on the bit-reversed word: each bit changed as a function of `seed` and of the bits
// below it.
constexpr std::uint32_t laine_karras(std::uint32_t v, std::uint32_t seed) {
  v ^= v * 0x3d20adeau;
  v += seed;
  v *= (seed >> 16) | 1u;
  v ^= v * 0x05526c56u;
  v ^= v * 0x53a22864u;
  return v;
}

// A nested scramble of the bits of v: each bit flipped by a function of `seed` and of the bits
// more significant than it. Applied to an index it permutes every aligned block of 2^k indices
// onto an aligned block of 2^k indices.
constexpr std::uint32_t nested_scramble(std::uint32_t v, std::uint32_t seed) {
  return reverse_bits(laine_karras(reverse_bits(v), seed));
}

// The first Sobol dimension: the van der Corput radical inverse, as 32 bits of binary fraction.
constexpr std::uint32_t dimension0(std::uint32_t index) { return reverse_bits(index); }

namespace detail {
// Direction numbers of the second Sobol dimension (primitive polynomial x + 1): v_0 = 1/2,
// v_k = v_(k-1) xor v_(k-1)/2. Point i is the xor of v_k over the set bits k of i. The tables take
// the index bit-reversed (r = reverse_bits(i), the form the index shuffle leaves it in), a byte at
// a time: bit j of r's byte b is bit 31 - (8b + j) of i.
constexpr std::array<std::array<std::uint32_t, 256>, 4> dimension1_tables() {
  std::array<std::uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (std::size_t k = 1; k < 32; ++k) v[k] = v[k - 1] ^ (v[k - 1] >> 1);
  std::array<std::array<std::uint32_t, 256>, 4> t{};
  for (std::size_t byte = 0; byte < 4; ++byte)
    for (std::uint32_t b = 0; b < 256; ++b) {
      std::uint32_t x = 0;
      for (std::size_t j = 0; j < 8; ++j)
        if ((b >> j) & 1u) x ^= v[31 - (8 * byte + j)];
      t[byte][b] = x;
    }
  return t;
}
inline constexpr std::array<std::array<std::uint32_t, 256>, 4> kDimension1 = dimension1_tables();
}  // namespace detail

// The second Sobol dimension of index reverse_bits(r); with dimension0 a (0,2)-sequence in base 2.
constexpr std::uint32_t dimension1_of_reversed(std::uint32_t r) {
  return detail::kDimension1[0][r & 0xffu] ^ detail::kDimension1[1][(r >> 8) & 0xffu] ^
         detail::kDimension1[2][(r >> 16) & 0xffu] ^ detail::kDimension1[3][r >> 24];
}
constexpr std::uint32_t dimension1(std::uint32_t index) { return dimension1_of_reversed(reverse_bits(index)); }

// 32 bits of binary fraction as a float in [0, 1): the top 24 bits, exact, never 1.0.
constexpr float to_unit_float(std::uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1p-24f; }

// The randomisation of one dimension (or pair of dimensions starting there) of one pixel, from a
// 64-bit hash of (seed, pixel, dimension): the index shuffle and one digital shift per coordinate.
struct Seeds {
  std::uint32_t shuffle, x, y;
};

// Point `index` of the randomised sequence, one coordinate (dimension 0) or two (dimensions 0, 1):
//   i = nested_scramble(index, shuffle),  x = dimension0(i) ^ s.x,  y = dimension1(i) ^ s.y.
// `reversed_index` is reverse_bits(index), the same for every dimension of a sample; since
// nested_scramble is laine_karras between two reversals and dimension0 is a reversal,
// dimension0(i) = laine_karras(reversed_index, shuffle): no bit reversal per number.
// Test Sobol.PointsAreTheRandomisedSequence.
constexpr std::uint32_t point1(std::uint32_t reversed_index, const Seeds& s) {
  return laine_karras(reversed_index, s.shuffle) ^ s.x;
}
constexpr std::array<std::uint32_t, 2> point2(std::uint32_t reversed_index, const Seeds& s) {
  const std::uint32_t r = laine_karras(reversed_index, s.shuffle);  // reverse_bits(i)
  return {r ^ s.x, dimension1_of_reversed(r) ^ s.y};
}

}  // namespace pathex::sobol
