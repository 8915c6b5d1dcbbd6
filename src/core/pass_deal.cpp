#include "core/pass_deal.h"

#include <algorithm>

namespace pathex {

ChunkDeal::ChunkDeal(const PassSet& passes, std::uint64_t chunk) : ranges_(passes.ranges()), chunk_(chunk) {
  std::uint64_t chunks = 0;
  for (const PassRange& r : ranges_) {
    first_chunk_.push_back(chunks);
    first_pass_.push_back(total_);
    chunks += (r.last - r.first + chunk_ - 1) / chunk_;
    total_ += r.last - r.first;
  }
  first_chunk_.push_back(chunks);
}

std::optional<PassRange> ChunkDeal::next() {
  const std::uint64_t k = next_.fetch_add(1, std::memory_order_relaxed);
  if (k >= first_chunk_.back()) return std::nullopt;
  // The range holding chunk k: the last whose first chunk is at most k.
  const auto i = static_cast<std::size_t>(std::upper_bound(first_chunk_.begin(), first_chunk_.end(), k) - first_chunk_.begin() - 1);
  const std::uint64_t first = ranges_[i].first + (k - first_chunk_[i]) * chunk_;
  return PassRange{first, std::min(first + chunk_, ranges_[i].last)};
}

std::uint64_t ChunkDeal::dealt() const {
  const std::uint64_t k = std::min(next_.load(std::memory_order_relaxed), first_chunk_.back());
  if (k == first_chunk_.back()) return total_;
  const auto i = static_cast<std::size_t>(std::upper_bound(first_chunk_.begin(), first_chunk_.end(), k) - first_chunk_.begin() - 1);
  return first_pass_[i] + (k - first_chunk_[i]) * chunk_;
}

}  // namespace pathex
