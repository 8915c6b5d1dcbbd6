#include "schedule/pass_deal.h"

#include <algorithm>
#include <numeric>

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

LaneDeal::LaneDeal(const PassSet& passes, std::uint64_t chunk, std::uint64_t batches, int takers)
    : ranges_(passes.ranges()), chunk_(chunk), batches_(batches), cursors_(batches), left_(batches, 0),
      takers_(static_cast<std::size_t>(takers)) {
  // The first passes of a range's chunks, first + j·chunk, repeat mod B with period B / gcd(chunk, B):
  // a lane's count in a range is read off one period.
  const std::uint64_t period = batches_ / std::gcd(chunk_ % batches_, batches_);
  for (const PassRange& r : ranges_) {
    const std::uint64_t n = (r.last - r.first + chunk_ - 1) / chunk_;
    for (std::uint64_t j = 0; j < std::min(n, period); ++j)
      left_[(r.first + j * chunk_) % batches_] += (n - j + period - 1) / period;
    total_ += r.last - r.first;
  }
  for (std::size_t lane = 0; lane < batches_; ++lane) {
    seek(lane, cursors_[lane]);
    // Batch b is taker ⌊b·n/B⌋'s.
    takers_[static_cast<std::size_t>(lane * takers_.size() / batches_)].lanes.push_back(lane);
  }
}

void LaneDeal::seek(std::size_t lane, Cursor& c) const {
  for (; c.range < ranges_.size(); ++c.range, c.chunk = 0) {
    const PassRange& r = ranges_[c.range];
    const std::uint64_t n = (r.last - r.first + chunk_ - 1) / chunk_;
    // Within one period (at most B chunks) of the cursor, or not in this range.
    for (const std::uint64_t end = std::min(n, c.chunk + batches_); c.chunk < end; ++c.chunk)
      if ((r.first + c.chunk * chunk_) % batches_ == lane) return;
  }
}

std::optional<PassRange> LaneDeal::take(std::size_t lane) {
  if (left_[lane] == 0) return std::nullopt;
  Cursor& c = cursors_[lane];
  const PassRange& r = ranges_[c.range];
  const std::uint64_t first = r.first + c.chunk * chunk_;
  const PassRange got{first, std::min(first + chunk_, r.last)};
  --left_[lane];
  ++c.chunk;
  seek(lane, c);
  dealt_.fetch_add(got.last - got.first, std::memory_order_relaxed);
  return got;
}

std::optional<PassRange> LaneDeal::next(int taker) {
  const std::lock_guard lock(mutex_);
  Taker& t = takers_[static_cast<std::size_t>(taker)];
  for (std::size_t k = 0; k < t.lanes.size(); ++k) {
    const std::size_t i = (t.turn + k) % t.lanes.size();
    if (std::optional<PassRange> got = take(t.lanes[i])) {
      t.turn = (i + 1) % t.lanes.size();
      return got;
    }
  }
  // Its lanes are done: it joins the lane with the most chunks left.
  const auto most = static_cast<std::size_t>(std::max_element(left_.begin(), left_.end()) - left_.begin());
  if (left_[most] == 0) return std::nullopt;
  t.lanes.push_back(most);
  t.turn = 0;
  return take(most);
}

}  // namespace pathex
