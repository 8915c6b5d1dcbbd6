// Counting members by length needs exact integers: the universe alone has 2^n strings of n
// scattering letters. BigUint is the smallest thing that does the job: non-negative, addition
// and decimal printing only.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace pathex {

class BigUint {
 public:
  BigUint() = default;
  explicit BigUint(std::uint64_t v) { if (v) limbs_.push_back(v); }
  BigUint& operator+=(const BigUint& o);
  bool is_zero() const { return limbs_.empty(); }
  bool operator==(const BigUint& o) const { return limbs_ == o.limbs_; }
  std::string to_string() const;
  // True and sets *out when the value fits in 64 bits.
  bool to_u64(std::uint64_t* out) const;

 private:
  std::vector<std::uint64_t> limbs_;  // little-endian base 2^64, no trailing zero limbs
};

}  // namespace pathex
