// Owen-scrambled Sobol points: the numbers of the tracer's `sobol` sampler (trace/rng.h, Sampler).
//
// The sampler is padded, as pbrt-v4's PaddedSobolSampler and Burley's "Practical Hash-based Owen
// Scrambling" (JCGT 2020): the integrator draws its numbers one or two at a time (get1d, get2d),
// and every pair of dimensions (d, d+1) it draws together is a point of the first two Sobol
// dimensions, a (0,2)-sequence in base 2; every single dimension is the first Sobol dimension (the
// van der Corput sequence). No table of direction numbers past the second dimension is needed,
// and a dimension block at 2048 (render.cpp's kJoinDims) is as good as dimension 0. What makes the
// pairs of one sample independent of each other is randomisation keyed by a hash of (seed,
// pixel, replicate, dimension):
//
//   - the index of the point (the pass div the replicate count) is shuffled by a nested scramble of
//     its bits (each bit flipped by a hash of the bits above it). That maps every aligned block of
//     2^k indices onto an aligned block of 2^k indices, so the first 2^k points take 2^k consecutive points
//     of the sequence, which form a (0,k,2)-net; different dimension pairs take different blocks in
//     different orders, so they are not correlated with each other;
//   - each coordinate is Owen-scrambled (each bit flipped by a hash of the bits above it), which
//     keeps the net property and makes every point, on its own, uniform on [0,1)².
//
// The sequence is that of one replicate of a pixel (trace/rng.h, sobol_stream()): the render's
// replicates are independent, each scrambled with its own seeds, whose point index is the
// pass div the replicate count. So for every pixel, replicate and pair of dimensions the first 2^k points
// put exactly one point in each elementary interval of area 2^-k (tests/trace/sampler_test.cpp),
// while each pass on its own is a
// uniform point independent across dimension pairs: estimates stay unbiased for any integrand.
// Nothing depends on the number of passes asked for, on threads or on the order of drawing: the
// number is a function of (seed, pixel, pass, dimension) and the replicate count, as the independent
// sampler's is of the first four, so renders stay bit-identical across thread counts and shards.
//
// The scramble is the hash-based one of Laine and Karras (2011) with Vegdahl's constants (as
// pbrt-v4's FastOwenScrambler): on the bit-reversed word, every step (x ^= x·even, x += seed,
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

// reverse_bits() of both halves of a 64-bit word at once, the halves swapped: the high half of the
// result is the low half reversed. (One 64-bit reversal costs as many instructions as one 32-bit.)
constexpr std::uint64_t reverse_bits_of_halves(std::uint64_t v) {
  v = __builtin_bswap64(v);
  v = ((v >> 4) & 0x0f0f0f0f0f0f0f0full) | ((v & 0x0f0f0f0f0f0f0f0full) << 4);
  v = ((v >> 2) & 0x3333333333333333ull) | ((v & 0x3333333333333333ull) << 2);
  return ((v >> 1) & 0x5555555555555555ull) | ((v & 0x5555555555555555ull) << 1);
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
// more significant than it. Applied to a point's coordinate it is an Owen scramble; applied to an
// index it permutes every aligned block of 2^k indices onto an aligned block of 2^k indices.
constexpr std::uint32_t nested_scramble(std::uint32_t v, std::uint32_t seed) {
  return reverse_bits(laine_karras(reverse_bits(v), seed));
}

// The first Sobol dimension: the van der Corput radical inverse, as 32 bits of binary fraction.
constexpr std::uint32_t dimension0(std::uint32_t index) { return reverse_bits(index); }

namespace detail {
// Direction numbers of the second Sobol dimension (primitive polynomial x + 1): v_0 = 1/2,
// v_k = v_(k-1) xor v_(k-1)/2. Point i is the xor of v_k over the set bits k of i. The table
// holds those xors, bit-reversed (the form the scramble takes them in), per byte of the index
// bit-reversed: the form point2() has the index in before it reverses it, so that the lookups do
// not wait for that reversal.
constexpr std::array<std::array<std::uint32_t, 256>, 4> dimension1_tables() {
  std::array<std::uint32_t, 32> v{};
  v[0] = 0x80000000u;
  for (int k = 1; k < 32; ++k) v[static_cast<std::size_t>(k)] = v[static_cast<std::size_t>(k - 1)] ^ (v[static_cast<std::size_t>(k - 1)] >> 1);
  std::array<std::array<std::uint32_t, 256>, 4> t{};
  for (std::size_t byte = 0; byte < 4; ++byte)
    for (std::uint32_t b = 0; b < 256; ++b) {
      const std::uint32_t index = reverse_bits(b << (8 * byte));  // the index bits this byte of the reversed word holds
      std::uint32_t x = 0;
      for (std::size_t k = 0; k < 32; ++k)
        if ((index >> k) & 1u) x ^= v[k];
      t[byte][b] = reverse_bits(x);
    }
  return t;
}
inline constexpr std::array<std::array<std::uint32_t, 256>, 4> kDimension1OfReversed = dimension1_tables();
// dimension1_reversed() of the index whose bit reversal is `reversed`.
[[gnu::always_inline]] constexpr std::uint32_t dimension1_of_reversed(std::uint32_t reversed) {
  return kDimension1OfReversed[0][reversed & 0xffu] ^ kDimension1OfReversed[1][(reversed >> 8) & 0xffu] ^
         kDimension1OfReversed[2][(reversed >> 16) & 0xffu] ^ kDimension1OfReversed[3][reversed >> 24];
}
}  // namespace detail

// The second Sobol dimension, bit-reversed, and as it is: with dimension0 a (0,2)-sequence in
// base 2.
constexpr std::uint32_t dimension1_reversed(std::uint32_t index) { return detail::dimension1_of_reversed(reverse_bits(index)); }
constexpr std::uint32_t dimension1(std::uint32_t index) { return reverse_bits(dimension1_reversed(index)); }

// 32 bits of binary fraction as a float in [0, 1): the top 24 bits, exact, never 1.0.
constexpr float to_unit_float(std::uint32_t bits) { return static_cast<float>(bits >> 8) * 0x1p-24f; }

// The scrambling seeds of one dimension (or pair of dimensions starting there) of one pixel,
// from a 64-bit hash of (seed, pixel, dimension): the index shuffle and one Owen seed per
// coordinate.
struct Seeds {
  std::uint32_t shuffle, x, y;
};

// Point `index` of the scrambled sequence, one coordinate (dimension 0) or two (dimensions 0, 1):
//   i = nested_scramble(index, shuffle),
//   x = nested_scramble(dimension0(i), s.x),  y = nested_scramble(dimension1(i), s.y),
// computed with three bit reversals instead of seven (dimension0 is a reversal, and a nested
// scramble is a reversal on each side of laine_karras); `reversed_index` is reverse_bits(index),
// the same for every dimension of a sample. Test Sobol.PointsAreTheScrambledSequence.
[[gnu::always_inline]] constexpr std::uint32_t point1(std::uint32_t reversed_index, const Seeds& s) {
  const std::uint32_t i = reverse_bits(laine_karras(reversed_index, s.shuffle));
  return reverse_bits(laine_karras(i, s.x));
}
// (point2 looks dimension 1 up from the shuffled index before its reversal, detail::
// dimension1_of_reversed, so that the two coordinates' chains start together, and reverses both
// scrambled coordinates in one 64-bit word; bench/sampler_bench.cpp measures the draw.)
[[gnu::always_inline]] constexpr std::array<std::uint32_t, 2> point2(std::uint32_t reversed_index, const Seeds& s) {
  const std::uint32_t w = laine_karras(reversed_index, s.shuffle);  // the shuffled index, bit-reversed
  const std::uint64_t both = reverse_bits_of_halves(
      (std::uint64_t{laine_karras(detail::dimension1_of_reversed(w), s.y)} << 32) | laine_karras(reverse_bits(w), s.x));
  return {static_cast<std::uint32_t>(both >> 32), static_cast<std::uint32_t>(both)};
}

}  // namespace pathex::sobol
