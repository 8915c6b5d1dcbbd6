// The ranks of an MPI job as a Cluster (output/render_job.h); see mpi_cluster.cpp.
#pragma once

#include <mpi.h>

#include <functional>
#include <memory>
#include <vector>

#include "output/render_job.h"

namespace pathex::cli {

class MpiCluster final : public Cluster {
 public:
  MpiCluster();  // after MPI_Init
  ~MpiCluster() override;
  MpiCluster(const MpiCluster&) = delete;
  MpiCluster& operator=(const MpiCluster&) = delete;

  int rank() const override { return rank_; }
  int size() const override { return size_; }
  std::unique_ptr<PassDealer> deal(const PassSet& todo, std::uint64_t chunk, int batches) override;
  Result<bool> reduce(RenderSums* sums, PassSet* passes, ShardRun* run, const std::function<void()>& before_changing) override;
  int count_failures(bool ok) override;

 private:
  Result<bool> check(int code, const char* what) const;
  // Returns once every rank has called it, sleeping (not spinning) while it waits (wait_sleeping,
  // mpi_deal.h): OpenMPI's blocking collectives poll at full speed, so a rank done first would take
  // a core from the ranks still rendering, and every rank one from rank 0 writing the outputs.
  Result<bool> wait_for_all(const char* what);
  // `any`[i] = the bitwise or of every rank's `flags`[i] (both of one size on every rank).
  Result<bool> or_all(const std::vector<std::uint64_t>& flags, std::vector<std::uint64_t>* any);
  // `all` = every rank's `mine` one after the other, in rank order, on rank 0 (others: emptied).
  template <typename T>
  Result<bool> gather_to_root(const std::vector<T>& mine, MPI_Datatype type, std::vector<T>* all);
  // Rank 0's `v` on every rank.
  template <typename T>
  Result<bool> broadcast(std::vector<T>* v, MPI_Datatype type);
  // The 128-bit sums of `size` words (pairs of low, high words) over the ranks, into rank 0's
  // `words`, which must hold zeros (the others' are left as they were).
  Result<bool> sum_to_root(std::uint64_t* words, std::size_t size);

  int rank_ = 0, size_ = 1;
  bool serialized_ = false;         // MPI_THREAD_SERIALIZED provided: the deal is shared (mpi_deal.h)
  MPI_Comm deal_comm_ = MPI_COMM_NULL;  // the deal's messages
  MPI_Datatype u128_{};
  MPI_Op add_{};
};

}  // namespace pathex::cli
