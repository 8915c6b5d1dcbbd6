// A value per key and batch (the histogram's cells: a path's exact sum in each batch; its row
// sums: a technique row's luminance sum in each batch), stored sparse while a key has been met in
// few batches and dense once it has been met in more.
//
// Why: a render meets most of its distinct paths a few times (bdpt on the Cornell box at 32 spp:
// 42 % of 6,729 paths once, 73 % at most four times), but a dense [batch][key] table gives every
// key all B batches, zero-filled as keys arrive: 32 × 64 bytes a path and 32 × 16 bytes a row,
// most of it zeros that the process must fault in and clear. Under pixel groups a thread's
// samples visit every batch within a row, so the whole table is live at once; on this VM its page
// faults and clearing were ~8 % of a bdpt render (bench/README.md, "Issue 37, thirteenth session").
// A key here first holds one (batch, value) pair, then up to kSparse, then a block of B values.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace pathex {

template <class T>
class BatchStore {
 public:
  static constexpr int kSparse = 4;  // pairs a key holds before its block of B values

  explicit BatchStore(int batches = 0) : batches_(batches > 0 ? batches : 0) {}

  int batches() const { return batches_; }
  // Keys 0 … keys - 1 exist (a key is its caller's dense id); more are added by at().
  std::size_t keys() const { return slots_.size(); }
  // Makes room for `keys` keys met in few batches each, without reallocation (address space only).
  void reserve(std::size_t keys) {
    slots_.reserve(keys);
    values_.reserve(keys * (1 + kSparse));
    sparse_batch_.reserve(keys * (1 + kSparse));
  }

  // The value of (key, batch), or nullptr where nothing was ever stored (a zero).
  const T* find(std::size_t key, int batch) const {
    if (key >= slots_.size()) return nullptr;
    const Slot& s = slots_[key];
    if (s.count == kDense) return &values_[s.index + static_cast<std::size_t>(batch)];
    for (std::size_t i = s.index; i < s.index + s.count; ++i)
      if (sparse_batch_[i] == batch) return &values_[i];
    return nullptr;
  }

  // Calls f(batch, value) for every value kept for `key`, in ascending batch order: its pairs, or
  // its block's B values (zeros among them). A batch not visited holds zero for the key.
  template <class F>
  void for_each(std::size_t key, F&& f) const {
    if (key >= slots_.size()) return;
    const Slot& s = slots_[key];
    if (s.count == kDense) {
      for (int b = 0; b < batches_; ++b) f(b, values_[s.index + static_cast<std::size_t>(b)]);
      return;
    }
    std::array<std::size_t, kSparse> order{};  // the pairs in batch order (insertion sort of at most kSparse)
    for (std::uint32_t n = 0; n < s.count; ++n) {
      std::uint32_t j = n;
      for (; j > 0 && sparse_batch_[order[j - 1]] > sparse_batch_[s.index + n]; --j) order[j] = order[j - 1];
      order[j] = s.index + n;
    }
    for (std::uint32_t n = 0; n < s.count; ++n) f(static_cast<int>(sparse_batch_[order[n]]), values_[order[n]]);
  }

  // The value of (key, batch), value-initialised on first use. The reference lasts until the next
  // call of at() (a new pair may move the values).
  T& at(std::size_t key, int batch) {
    if (key >= slots_.size()) [[unlikely]]
      slots_.resize(key + 1);
    Slot& s = slots_[key];
    if (s.count == kDense) return values_[s.index + static_cast<std::size_t>(batch)];
    for (std::size_t i = s.index; i < s.index + s.count; ++i)
      if (sparse_batch_[i] == batch) return values_[i];
    return add(s, batch);
  }

 private:
  static constexpr std::uint32_t kDense = 0xffffffffu;  // Slot::count of a key with a block of B values
  struct Slot {
    std::size_t index = 0;       // the first of its values in values_
    std::uint32_t count = 0;     // its pairs (0 … kSparse), or kDense
    std::uint32_t capacity = 0;  // its run's length: 0, 1 or kSparse
  };

  // A new pair for a key that lacks `batch`: in its run while there is room; a key's first pair
  // gets a run of one (most keys never get a second), its second a run of kSparse; past that its
  // block. (A moved run's place stays unused.)
  [[gnu::noinline]] T& add(Slot& s, int batch) {
    if (s.count == s.capacity) {
      if (s.capacity == static_cast<std::uint32_t>(kSparse)) return to_block(s, batch);
      const std::uint32_t capacity = s.capacity == 0 ? 1 : kSparse;
      const std::size_t run = values_.size();
      values_.resize(run + capacity);
      sparse_batch_.resize(values_.size(), -1);
      for (std::uint32_t i = 0; i < s.count; ++i) {
        values_[run + i] = values_[s.index + i];
        sparse_batch_[run + i] = sparse_batch_[s.index + i];
      }
      s.index = run;
      s.capacity = capacity;
    }
    const std::size_t i = s.index + s.count++;
    sparse_batch_[i] = static_cast<std::int16_t>(batch);
    return values_[i];
  }

  // The run is full: a block of B values, the run's moved into it.
  T& to_block(Slot& s, int batch) {
    const std::size_t block = values_.size();
    values_.resize(block + static_cast<std::size_t>(batches_));
    sparse_batch_.resize(values_.size(), -1);
    for (std::size_t i = s.index; i < s.index + kSparse; ++i)
      values_[block + static_cast<std::size_t>(sparse_batch_[i])] = values_[i];
    s.index = block;
    s.count = kDense;
    return values_[block + static_cast<std::size_t>(batch)];
  }

  int batches_ = 0;
  std::vector<Slot> slots_;
  std::vector<T> values_;           // runs of kSparse values and blocks of B values
  std::vector<std::int16_t> sparse_batch_;  // parallel to values_: a run's pairs' batches (-1 elsewhere)
};

}  // namespace pathex
