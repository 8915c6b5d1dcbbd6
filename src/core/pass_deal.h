// Dealing a render's passes chunk by chunk. render() (trace/render.h) takes its chunks from a
// PassDealer: by default a ChunkDeal of its own passes; an MPI rank from the deal its ranks share
// (cli/mpi/mpi_deal.h), where whoever is free takes the next chunk, so a faster rank takes more.
// A pass's numbers depend on (seed, pixel, pass) alone and its sums are exact integers, so which
// process takes a chunk does not change the render's outputs.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <vector>

#include "core/pass_set.h"

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
// atomic counter, so that several threads may take from it (an MPI job's rank 0 deals from one
// for its own render and for the other ranks', cli/mpi/mpi_deal.cpp).
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

}  // namespace pathex
