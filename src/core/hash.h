// FNV-1a hashes. IntVectorHash keys the subset construction (sets of NFA states) and the
// classifier's product construction (tuples of DFA states); Fnv64 is a streaming 64-bit FNV-1a
// over bytes, for content hashes that name what a render was made from (scene, profile, classes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <vector>

namespace pathex {

struct IntVectorHash {
  std::size_t operator()(const std::vector<int>& v) const {
    std::size_t h = 1469598103934665603ULL;
    for (int x : v) h = (h ^ static_cast<std::size_t>(x)) * 1099511628211ULL;
    return h;
  }
};

class Fnv64 {
 public:
  void bytes(const void* data, std::size_t n) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < n; ++i) h_ = (h_ ^ p[i]) * 1099511628211ULL;
  }
  // A trivially copyable value by its bytes (floats by their bit pattern).
  template <class T>
    requires std::is_trivially_copyable_v<T>
  void add(const T& v) {
    bytes(&v, sizeof v);
  }
  // A string with its length, so that ("ab", "c") and ("a", "bc") differ.
  void add(std::string_view s) {
    add(static_cast<std::uint64_t>(s.size()));
    bytes(s.data(), s.size());
  }
  std::uint64_t value() const { return h_; }
  // 16 lowercase hexadecimal digits.
  std::string hex() const {
    static const char* digits = "0123456789abcdef";
    std::string s(16, '0');
    for (int i = 0; i < 16; ++i) s[static_cast<std::size_t>(15 - i)] = digits[(h_ >> (4 * i)) & 15];
    return s;
  }

 private:
  std::uint64_t h_ = 1469598103934665603ULL;
};

}  // namespace pathex
