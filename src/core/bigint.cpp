#include "core/bigint.h"

#include <algorithm>

namespace pathex {

BigUint& BigUint::operator+=(const BigUint& o) {
  if (o.limbs_.size() > limbs_.size()) limbs_.resize(o.limbs_.size(), 0);
  unsigned carry = 0;
  for (std::size_t i = 0; i < limbs_.size(); ++i) {
    const std::uint64_t b = i < o.limbs_.size() ? o.limbs_[i] : 0;
    if (b == 0 && carry == 0 && i >= o.limbs_.size()) break;
    const std::uint64_t s = limbs_[i] + b;
    const unsigned c1 = s < b;
    const std::uint64_t t = s + carry;
    const unsigned c2 = t < s;
    limbs_[i] = t;
    carry = c1 + c2;
  }
  if (carry) limbs_.push_back(carry);
  return *this;
}

bool BigUint::to_u64(std::uint64_t* out) const {
  if (limbs_.size() > 1) return false;
  *out = limbs_.empty() ? 0 : limbs_[0];
  return true;
}

std::string BigUint::to_string() const {
  if (limbs_.empty()) return "0";
  // Repeated division by 10^19 on a copy.
  std::vector<std::uint64_t> n = limbs_;
  std::string digits;
  constexpr std::uint64_t kBase = 10000000000000000000ULL;
  while (!n.empty()) {
    __extension__ typedef unsigned __int128 u128;
    u128 rem = 0;
    for (std::size_t i = n.size(); i-- > 0;) {
      const u128 cur = (rem << 64) | n[i];
      n[i] = static_cast<std::uint64_t>(cur / kBase);
      rem = cur % kBase;
    }
    while (!n.empty() && n.back() == 0) n.pop_back();
    std::string chunk = std::to_string(static_cast<std::uint64_t>(rem));
    if (!n.empty()) chunk.insert(0, 19 - chunk.size(), '0');
    std::reverse(chunk.begin(), chunk.end());
    digits += chunk;
  }
  std::reverse(digits.begin(), digits.end());
  return digits;
}

}  // namespace pathex
