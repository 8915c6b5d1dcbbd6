// Packed full-path strings and the per-thread table from them to histogram ids: a speed-up of the
// estimator's bookkeeping, kept out of render.cpp.
//
// A full-path string L c0 … c(k+2) E is packed into 128 bits: bit i is set when c_i is S, and the
// number of scattering letters (k + 3) sits in the top byte. Strings of up to kLengthShift − 1
// letters pack (the tracer clamps its paths so).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "classify/histogram.h"
#include "trace/rng.h"

namespace pathex::accel {

__extension__ typedef unsigned __int128 PathKey;
inline constexpr int kLengthShift = 120;
inline constexpr PathKey bit(int i) { return static_cast<PathKey>(1) << i; }
inline constexpr PathKey letter_bit(char c, int i) { return c == 'S' ? bit(i) : 0; }
inline int packed_length(PathKey key) { return static_cast<int>(key >> kLengthShift); }
inline bool packed_is_d(PathKey key, int i) { return ((key >> i) & 1) == 0; }

inline std::string unpack(PathKey key) {
  const int n = packed_length(key);
  std::string out(static_cast<std::size_t>(n) + 2, 'D');
  out.front() = 'L';
  out.back() = 'E';
  for (int i = 0; i < n; ++i)
    if (!packed_is_d(key, i)) out[static_cast<std::size_t>(i) + 1] = 'S';
  return out;
}
inline PathKey pack(const std::string& letters) {  // "L c0 … E"
  PathKey key = static_cast<PathKey>(letters.size() - 2) << kLengthShift;
  for (std::size_t i = 1; i + 1 < letters.size(); ++i) key |= letter_bit(letters[i], static_cast<int>(i) - 1);
  return key;
}

// Per-thread map from (packed string, technique) to the histogram's path id and technique row,
// so that recording a contribution hashes three words instead of a string and walks no list;
// Histogram::intern() and technique_row() run once per new pair and thread. The contributions
// of each pair are counted here, in the slot just read, and handed to the histogram by flush().
class PathIds {
 public:
  struct Ids {
    Histogram::PathId path = -1;
    int row = -1;  // Histogram::technique_row() of the technique
  };
  Ids get(Histogram& hist, PathKey key, int technique) {
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(key, technique) & mask;; i = (i + 1) & mask) {
      Slot& slot = slots_[i];
      if (slot.key == key && slot.technique == technique) {
        ++slot.contributions;
        return slot.ids;
      }
      if (slot.key == 0) return insert(hist, slot, key, technique);
    }
  }
  // Adds the contributions counted since the last flush to the histogram's technique rows.
  void flush(Histogram& hist) {
    for (Slot& slot : slots_)
      if (slot.key != 0 && slot.contributions != 0) {
        hist.add_technique(slot.ids.path, slot.technique, slot.contributions, nullptr);
        slot.contributions = 0;
      }
  }

 private:
  struct Slot {
    PathKey key = 0;  // 0: empty (a real key has a nonzero length)
    int technique = 0;
    Ids ids;
    std::uint64_t contributions = 0;  // nonzero contributions of the pair since the last flush
  };
  // A pair's first sight, out of line: the lookup above stays small enough to inline.
  [[gnu::noinline]] Ids insert(Histogram& hist, Slot& slot, PathKey key, int technique) {
    const Histogram::PathId id = hist.intern(unpack(key));
    slot = {key, technique, {id, hist.technique_row(id, technique)}, 1};
    const Ids ids = slot.ids;
    if (2 * ++used_ > slots_.size()) grow();
    return ids;
  }
  // One finaliser over the three words, each spread by its own odd multiplier first (ids do not
  // depend on the hash: they are given in order of first sight).
  static std::size_t hash(PathKey key, int technique) {
    return static_cast<std::size_t>(mix64(static_cast<std::uint64_t>(key) + static_cast<std::uint64_t>(key >> 64) * kGoldenGamma +
                                          static_cast<std::uint64_t>(technique) * 0xd6e8feb86659fd93ULL));
  }
  void grow() {
    std::vector<Slot> old(slots_.size() * 2);
    old.swap(slots_);
    const std::size_t mask = slots_.size() - 1;
    for (const Slot& slot : old) {
      if (slot.key == 0) continue;
      std::size_t i = hash(slot.key, slot.technique) & mask;
      while (slots_[i].key != 0) i = (i + 1) & mask;
      slots_[i] = slot;
    }
  }
  std::vector<Slot> slots_ = std::vector<Slot>(256);
  std::size_t used_ = 0;
};

}  // namespace pathex::accel
