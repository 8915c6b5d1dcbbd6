// Sets of passes. A pass is one sample of every pixel (pass p of pixel x draws its random numbers
// from (seed, x, p, dimension)), so a render is fully described by the passes it took: a sharded,
// interrupted or resumed render is a set of passes, and renders merge exactly when their sets are
// disjoint. A PassSet holds ascending, disjoint, non-adjacent half-open ranges [first, last).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pathex {

struct PassRange {
  std::uint64_t first = 0;
  std::uint64_t last = 0;  // one past the last pass
  bool operator==(const PassRange&) const = default;
};

class PassSet {
 public:
  PassSet() = default;
  static PassSet range(std::uint64_t first, std::uint64_t last);  // [first, last)

  // Part `index` of `count` (index < count): with the set's passes numbered 0 … m−1 in order,
  // those numbered ⌊i·m/n⌋ to ⌊(i+1)·m/n⌋ − 1. The parts are disjoint, cover the set, differ in
  // size by at most one, and may be empty when count > m. Shard i/n of a render is
  // range(0, spp).part(i, n). (MPI ranks deal their passes as they go, schedule/pass_deal.h; rank r of
  // n takes part(r, n) only where MPI cannot serve the deal from a thread.)
  PassSet part(std::uint64_t index, std::uint64_t count) const;

  // Adds [first, last), joining it with the ranges it touches.
  void add(std::uint64_t first, std::uint64_t last);
  void add(const PassSet& other);

  const std::vector<PassRange>& ranges() const { return ranges_; }
  bool empty() const { return ranges_.empty(); }
  std::uint64_t count() const;  // passes in the set
  std::uint64_t end() const { return ranges_.empty() ? 0 : ranges_.back().last; }  // one past the largest

  // The ranges cut into pieces of at most n passes, in order (a render's chunks).
  std::vector<PassRange> chunks(std::uint64_t n) const;

  PassSet intersect(const PassSet& other) const;
  PassSet minus(const PassSet& other) const;

  // "0-3, 8, 12-15" (inclusive), "none" when empty.
  std::string to_string() const;

  bool operator==(const PassSet&) const = default;

 private:
  std::vector<PassRange> ranges_;
};

}  // namespace pathex
