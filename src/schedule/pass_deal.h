// Dealing a render's passes chunk by chunk. render() (trace/render.h) takes its chunks from a
// PassDealer: by default a ChunkDeal of its own passes; an MPI rank from the deal its ranks share
// (a LaneDeal held by rank 0, cli/mpi/mpi_deal.h), where whoever is free takes a next chunk, so a
// faster rank takes more.
// A pass's numbers depend on (seed, pixel, pass) alone and its sums are exact integers, so which
// process takes a chunk does not change the render's outputs.
#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <optional>
#include <vector>

#include "schedule/pass_set.h"

namespace pathex {

class PassDealer {
 public:
  virtual ~PassDealer() = default;
  // The next chunk for the caller to render (whole: every pass of it over every pixel), or none
  // when the deal is done. Once it has returned none it returns none.
  virtual std::optional<PassRange> next() = 0;
  virtual std::uint64_t total() const = 0;  // passes in the whole deal, every taker's
  virtual std::uint64_t dealt() const = 0;  // passes handed out so far, as far as this process knows
};

// The chunks of a pass set in order (PassSet::chunks, not materialised), to whoever asks: one
// atomic counter, so that several threads may take from it.
class ChunkDeal final : public PassDealer {
 public:
  ChunkDeal(const PassSet& passes, std::uint64_t chunk);  // chunk > 0
  std::optional<PassRange> next() override;
  std::uint64_t total() const override { return total_; }
  std::uint64_t dealt() const override;

 private:
  std::vector<PassRange> ranges_;
  std::vector<std::uint64_t> first_chunk_;  // the index of each range's first chunk; then their number
  std::vector<std::uint64_t> first_pass_;   // the passes before each range
  std::uint64_t chunk_ = 1, total_ = 0;
  std::atomic<std::uint64_t> next_{0};
};

// The chunks of a pass set dealt among several takers (an MPI job's ranks), each keeping to a
// share of the B batches. A render lays out a batch's cells and row sums (one per path seen so
// far, stats/histogram.h) the first time it adds to that batch, and passes go to batches
// round-robin (pass mod B): a rank that takes every other chunk of the plain order touches all B
// batches, as one process does, so two ranks lay out, fault in, write to their rank files and
// reduce twice the histogram of one process. Here the chunks form lanes by their first pass mod
// B; taker t of n starts with the lanes of batches [t·B/n, (t+1)·B/n) and takes its lanes' chunks
// round-robin, each lane in order; once its lanes are done it joins the lane with the most chunks
// left (shared from then on), so a faster taker still takes more chunks and every chunk is dealt
// once. Which taker renders a chunk does not change the render's sums (schedule/pass_deal.h, above).
class LaneDeal {
 public:
  LaneDeal(const PassSet& passes, std::uint64_t chunk, std::uint64_t batches, int takers);  // chunk, batches, takers > 0
  // The next chunk for taker `taker` (0 ≤ taker < takers), or none when every chunk is dealt.
  // Safe to call from several threads.
  std::optional<PassRange> next(int taker);
  std::uint64_t total() const { return total_; }
  std::uint64_t dealt() const { return dealt_.load(std::memory_order_relaxed); }

 private:
  struct Cursor {  // a lane's next chunk: chunk `chunk` of range `range`
    std::size_t range = 0;
    std::uint64_t chunk = 0;
  };
  struct Taker {
    std::vector<std::size_t> lanes;  // the lanes it takes from, in order
    std::size_t turn = 0;            // the lane (index into lanes) it takes from next
  };
  // Moves `c` to the first chunk at or after it whose first pass is in `lane`; past the last range
  // when there is none.
  void seek(std::size_t lane, Cursor& c) const;
  std::optional<PassRange> take(std::size_t lane);  // the lane's next chunk, if any

  std::vector<PassRange> ranges_;
  std::uint64_t chunk_, batches_, total_ = 0;
  std::vector<Cursor> cursors_;        // per lane (lanes are not materialised: B cursors)
  std::vector<std::uint64_t> left_;    // chunks not yet dealt, per lane
  std::vector<Taker> takers_;
  std::mutex mutex_;
  std::atomic<std::uint64_t> dealt_{0};
};

}  // namespace pathex
