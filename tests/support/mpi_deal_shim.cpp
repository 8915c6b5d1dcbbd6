// A test hook that lives in the tests: an LD_PRELOAD library that holds back one MPI rank in the
// ranks' deal of the passes (src/cli/mpi/mpi_deal.h), through MPI's profiling interface. A rank
// other than 0 sends rank 0 nothing but the deal's messages (asks for a chunk, and its leaving), with
// MPI_Send; this library's MPI_Send
//   waits, the first time, until every file of PATHEX_DEAL_AWAIT (separated by ':') exists, and
//   sleeps PATHEX_DEAL_SLEEP_MS milliseconds every time (a rank that asks that much more slowly),
// then sends. Used by tests/cli/shard_cli_test.cpp (MpiUnevenDeal).
#include <mpi.h>

#include <cstdlib>

#include "await_files.h"

namespace {

bool g_awaited = false;

}  // namespace

extern "C" int MPI_Send(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
  if (!g_awaited) {
    pathex_test::await_files("PATHEX_DEAL_AWAIT");
    g_awaited = true;
  }
  if (const char* ms = std::getenv("PATHEX_DEAL_SLEEP_MS")) pathex_test::pause_ms(std::atol(ms));
  return PMPI_Send(buf, count, type, dest, tag, comm);
}
