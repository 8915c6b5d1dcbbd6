// The ranks' shared deal of an MPI render's passes (schedule/pass_deal.h): whoever is free takes the
// next chunk, so a rank on a faster (or less loaded) core takes more of them than a static share
// would give it, and no rank waits for another at the end for longer than about a chunk.
//
// Rank 0 holds the deal (a LaneDeal: each rank keeps to a share of the batches while it can). Its own render takes chunks from it
// directly; a thread of its own serves the other ranks, which ask for chunks by point-to-point
// messages on a communicator kept for this (MpiCluster's). A rank asks for its next chunk as soon
// as it is handed one, so the answer travels while it renders; when the deal is done (or its
// render stops) it says it leaves, and rank 0's thread ends once every other rank has left.
//
// Why messages and a thread rather than MPI one-sided operations (MPI_Fetch_and_op on a window on
// rank 0): a passive-target operation progresses only when the target calls MPI on some
// transports (Open MPI's osc/pt2pt; osc/rdma over TCP), and rank 0's render calls no MPI; Open
// MPI's osc/ucx is absent or slow on some machines. Messages work over every transport, with any
// MPI that provides MPI_THREAD_SERIALIZED (rank 0 calls MPI from its thread while the deal lives,
// from the main thread otherwise). Without it, MpiCluster deals statically (PassSet::part).
#pragma once

#include <mpi.h>

#include <chrono>
#include <cstdint>
#include <optional>
#include <thread>

#include "schedule/pass_deal.h"

namespace pathex::cli {

// Waits for `request` like MPI_Wait, but asleep between tests (Open MPI's blocking calls poll at
// full speed, taking a core from the renders): polls every 0.25 ms at first, backing off to every
// `longest`. Returns MPI's error code.
int wait_sleeping(MPI_Request* request, MPI_Status* status, std::chrono::microseconds longest);

// Rank 0's side: deals its own render's chunks and, from a thread, the other ranks'.
class RootDeal final : public PassDealer {
 public:
  RootDeal(const PassSet& todo, std::uint64_t chunk, std::uint64_t batches, MPI_Comm comm, int ranks);
  ~RootDeal() override;  // waits until every other rank has left the deal
  RootDeal(const RootDeal&) = delete;
  RootDeal& operator=(const RootDeal&) = delete;
  std::optional<PassRange> next() override { return deal_.next(0); }
  std::uint64_t total() const override { return deal_.total(); }
  std::uint64_t dealt() const override { return deal_.dealt(); }

 private:
  void serve();
  LaneDeal deal_;
  MPI_Comm comm_;
  int ranks_;
  std::thread server_;
};

// Another rank's side: asks rank 0.
class RemoteDeal final : public PassDealer {
 public:
  RemoteDeal(std::uint64_t total, MPI_Comm comm, int rank);
  ~RemoteDeal() override;  // leaves the deal (a chunk asked for and not yet taken is not rendered)
  RemoteDeal(const RemoteDeal&) = delete;
  RemoteDeal& operator=(const RemoteDeal&) = delete;
  std::optional<PassRange> next() override;
  std::uint64_t total() const override { return total_; }
  std::uint64_t dealt() const override { return dealt_; }  // to this rank

 private:
  bool ask();             // sends a request, its answer pending
  bool await();           // receives the pending answer into answer_
  void leave();           // once, with no answer pending
  bool failed(int code);  // reports an MPI error (the rank then leaves the deal)
  MPI_Comm comm_;
  int rank_;
  std::uint64_t total_, dealt_ = 0;
  std::uint64_t answer_[2] = {0, 0};
  MPI_Request pending_ = MPI_REQUEST_NULL;
  bool left_ = false;
};

}  // namespace pathex::cli
