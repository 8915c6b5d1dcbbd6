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

#include "stats/histogram.h"
#include "trace/rng.h"

namespace pathex::accel {

__extension__ typedef unsigned __int128 PathKey;
inline constexpr int kLengthShift = 120;
inline constexpr int kMaxPackedLetters = kLengthShift;  // a key holds the letters c0 … c(k+2) in its low bits
inline constexpr PathKey bit(int i) { return static_cast<PathKey>(1) << i; }
inline constexpr PathKey letter_bit(char c, int i) { return static_cast<PathKey>(c == 'S') << i; }  // no branch on the letter
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
// Histogram::intern() runs once per new string and thread, technique_row() once per new pair. The
// contributions of each pair are counted here, in the slot just read, and handed to the histogram
// by flush().
//
// Layout, for the hot lookup: a slot is 32 bytes (two per cache line; the key as two words, the
// count in 32 bits, handed over before it can wrap), and the strings seen so far have a table of
// their own, read only when a pair is new, so that a string's second technique does not unpack it
// and hash it as a string again. (`flush_at` is the count at which a slot hands its contributions
// over before its 32 bits wrap: 2^32 - 1 unless given, which a test lowers.)
class PathIds {
 public:
  PathIds() = default;
  explicit PathIds(std::uint32_t flush_at) : flush_at_(flush_at) {}
  struct Ids {
    Histogram::PathId path = -1;
    int row = -1;  // Histogram::technique_row() of the technique
  };
  Ids get(Histogram& hist, PathKey key, int technique) {
    const std::uint64_t lo = static_cast<std::uint64_t>(key), hi = static_cast<std::uint64_t>(key >> 64);
    const std::size_t mask = slots_.size() - 1;
    for (std::size_t i = hash(lo, hi, technique) & mask;; i = (i + 1) & mask) {
      Slot& slot = slots_[i];
      if (slot.lo == lo && slot.hi == hi && slot.technique == technique) {
        if (++slot.contributions >= flush_at_) [[unlikely]]
          hand_over(hist, slot);
        return slot.ids;
      }
      if (slot.hi == 0) return insert(hist, slot, key, technique);
    }
  }
  // Adds the contributions counted since the last flush to the histogram's technique rows.
  void flush(Histogram& hist) {
    for (Slot& slot : slots_)
      if (slot.hi != 0 && slot.contributions != 0) hand_over(hist, slot);
  }

 private:
  struct Slot {
    std::uint64_t lo = 0, hi = 0;  // the key's words; hi == 0: empty (a real key's length byte is nonzero)
    int technique = 0;
    Ids ids;
    std::uint32_t contributions = 0;  // nonzero contributions of the pair since they were last handed over
  };
  static_assert(sizeof(Slot) == 32, "two slots per cache line");
  struct PathSlot {
    PathKey key = 0;  // 0: empty
    Histogram::PathId id = -1;
  };

  [[gnu::noinline]] static void hand_over(Histogram& hist, Slot& slot) {
    hist.add_technique(slot.ids.path, slot.technique, slot.contributions, nullptr);
    slot.contributions = 0;
  }
  // A pair's first sight, out of line: the lookup above stays small enough to inline.
  [[gnu::noinline]] Ids insert(Histogram& hist, Slot& slot, PathKey key, int technique) {
    const Histogram::PathId id = path_id(hist, key);
    slot = {static_cast<std::uint64_t>(key), static_cast<std::uint64_t>(key >> 64), technique, {id, hist.technique_row(id, technique)}, 1};
    const Ids ids = slot.ids;
    if (2 * ++used_ > slots_.size()) grow();
    return ids;
  }
  // The histogram's id of the string, interned on its first sight in this thread.
  Histogram::PathId path_id(Histogram& hist, PathKey key) {
    const std::uint64_t lo = static_cast<std::uint64_t>(key), hi = static_cast<std::uint64_t>(key >> 64);
    const std::size_t mask = paths_.size() - 1;
    for (std::size_t i = hash(lo, hi, -1) & mask;; i = (i + 1) & mask) {
      PathSlot& p = paths_[i];
      if (p.key == key) return p.id;
      if (p.key == 0) {
        p = {key, hist.intern(unpack(key))};
        const Histogram::PathId id = p.id;
        if (2 * ++paths_used_ > paths_.size()) grow_paths();
        return id;
      }
    }
  }
  // One finaliser over the three words, each spread by its own odd multiplier first (ids do not
  // depend on the hash: they are given in order of first sight).
  static std::size_t hash(std::uint64_t lo, std::uint64_t hi, int technique) {
    return static_cast<std::size_t>(mix64(lo + hi * kGoldenGamma + static_cast<std::uint64_t>(technique) * 0xd6e8feb86659fd93ULL));
  }
  void grow() {
    std::vector<Slot> old(slots_.size() * 2);
    old.swap(slots_);
    const std::size_t mask = slots_.size() - 1;
    for (const Slot& slot : old) {
      if (slot.hi == 0) continue;
      std::size_t i = hash(slot.lo, slot.hi, slot.technique) & mask;
      while (slots_[i].hi != 0) i = (i + 1) & mask;
      slots_[i] = slot;
    }
  }
  void grow_paths() {
    std::vector<PathSlot> old(paths_.size() * 2);
    old.swap(paths_);
    const std::size_t mask = paths_.size() - 1;
    for (const PathSlot& p : old) {
      if (p.key == 0) continue;
      std::size_t i = hash(static_cast<std::uint64_t>(p.key), static_cast<std::uint64_t>(p.key >> 64), -1) & mask;
      while (paths_[i].key != 0) i = (i + 1) & mask;
      paths_[i] = p;
    }
  }
  std::vector<Slot> slots_ = std::vector<Slot>(256);
  std::size_t used_ = 0;
  std::vector<PathSlot> paths_ = std::vector<PathSlot>(256);
  std::size_t paths_used_ = 0;
  std::uint32_t flush_at_ = 0xffffffffu;
};

}  // namespace pathex::accel
