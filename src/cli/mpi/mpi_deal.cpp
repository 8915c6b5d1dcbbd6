#include "cli/mpi/mpi_deal.h"

#include <algorithm>
#include <cstdio>
#include <string>

namespace pathex::cli {
namespace {

// A rank's messages to rank 0 (one 64-bit word each); rank 0 answers an ask with {first, last},
// {0, 0} when no chunk is left.
constexpr std::uint64_t kAsk = 0, kLeave = 1;
constexpr int kTag = 0;  // the deal's communicator carries nothing else

// How long the waits sleep at most: rank 0's thread waits for asks, which come about once a chunk
// per rank, and each wake-up takes some 30 µs of the core rank 0 renders on; its answer is needed
// only when the asking rank finishes its current chunk. A rank waits for an answer only when it
// did not come during a whole chunk (a very short one), so it looks often.
constexpr std::chrono::microseconds kServerLongest(4000), kRemoteLongest(1000);

void report_mpi_error(int rank, int code) {
  char text[MPI_MAX_ERROR_STRING];
  int len = 0;
  MPI_Error_string(code, text, &len);
  std::fprintf(stderr, "pathex: error: rank %d: MPI failed while dealing the passes: %.*s\n", rank, len, text);
}

}  // namespace

int wait_sleeping(MPI_Request* request, MPI_Status* status, std::chrono::microseconds longest) {
  for (std::chrono::microseconds pause(250);; pause = std::min(2 * pause, longest)) {
    int done = 0;
    if (const int code = MPI_Test(request, &done, status); code != MPI_SUCCESS) return code;
    if (done != 0) return MPI_SUCCESS;
    std::this_thread::sleep_for(pause);
  }
}

RootDeal::RootDeal(const PassSet& todo, std::uint64_t chunk, std::uint64_t batches, MPI_Comm comm, int ranks)
    : deal_(todo, chunk, batches, ranks), comm_(comm), ranks_(ranks) {
  if (ranks_ > 1) server_ = std::thread([this] { serve(); });
}

RootDeal::~RootDeal() {
  if (server_.joinable()) server_.join();
}

void RootDeal::serve() {
  for (int present = ranks_ - 1; present > 0;) {
    std::uint64_t message = 0;
    MPI_Request request{};
    MPI_Status status{};
    int code = MPI_Irecv(&message, 1, MPI_UINT64_T, MPI_ANY_SOURCE, kTag, comm_, &request);
    if (code == MPI_SUCCESS) code = wait_sleeping(&request, &status, kServerLongest);
    if (code == MPI_SUCCESS && message == kLeave) {
      --present;
      continue;
    }
    if (code == MPI_SUCCESS) {
      const std::optional<PassRange> c = deal_.next(status.MPI_SOURCE);
      const std::uint64_t answer[2] = {c ? c->first : 0, c ? c->last : 0};
      code = MPI_Send(answer, 2, MPI_UINT64_T, status.MPI_SOURCE, kTag, comm_);
    }
    if (code != MPI_SUCCESS) return report_mpi_error(0, code);
  }
}

RemoteDeal::RemoteDeal(std::uint64_t total, MPI_Comm comm, int rank) : comm_(comm), rank_(rank), total_(total) {}

RemoteDeal::~RemoteDeal() {
  if (!left_ && pending_ != MPI_REQUEST_NULL) await();
  leave();
}

std::optional<PassRange> RemoteDeal::next() {
  if (left_ || (pending_ == MPI_REQUEST_NULL && !ask()) || !await()) return std::nullopt;
  const PassRange chunk{answer_[0], answer_[1]};
  if (chunk.first >= chunk.last) {
    leave();
    return std::nullopt;
  }
  dealt_ += chunk.last - chunk.first;
  ask();  // the next chunk, while this one renders (should it fail, the next call returns none)
  return chunk;
}

bool RemoteDeal::ask() {
  int code = MPI_Irecv(answer_, 2, MPI_UINT64_T, 0, kTag, comm_, &pending_);
  if (code == MPI_SUCCESS) code = MPI_Send(&kAsk, 1, MPI_UINT64_T, 0, kTag, comm_);
  return !failed(code);
}

bool RemoteDeal::await() {
  const int code = wait_sleeping(&pending_, MPI_STATUS_IGNORE, kRemoteLongest);
  pending_ = MPI_REQUEST_NULL;
  return !failed(code);
}

void RemoteDeal::leave() {
  if (left_) return;
  left_ = true;
  failed(MPI_Send(&kLeave, 1, MPI_UINT64_T, 0, kTag, comm_));
}

bool RemoteDeal::failed(int code) {
  if (code == MPI_SUCCESS) return false;
  report_mpi_error(rank_, code);
  left_ = true;  // MPI is broken: no more messages
  pending_ = MPI_REQUEST_NULL;
  return true;
}

}  // namespace pathex::cli
