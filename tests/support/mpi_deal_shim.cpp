// A test hook that lives in the tests: an LD_PRELOAD library that holds back one MPI rank in the
// ranks' deal of the passes (src/cli/mpi/mpi_deal.h), through MPI's profiling interface. A rank
// other than 0 sends rank 0 nothing but the deal's messages (asks for a chunk, and its leaving), with
// MPI_Send; this library's MPI_Send
//   waits, the first time, until every file of PATHEX_DEAL_AWAIT (separated by ':') exists, and
//   sleeps PATHEX_DEAL_SLEEP_MS milliseconds every time (a rank that asks that much more slowly),
// then sends. Used by tests/cli/shard_cli_test.cpp (MpiUnevenDeal).
#include <mpi.h>
#include <sys/stat.h>

#include <cstdlib>
#include <ctime>
#include <string>

namespace {

void pause_ms(long ms) {
  const timespec t{ms / 1000, (ms % 1000) * 1'000'000};
  ::nanosleep(&t, nullptr);
}

void await_files() {
  const char* list = std::getenv("PATHEX_DEAL_AWAIT");
  if (list == nullptr) return;
  std::string rest = list;
  while (!rest.empty()) {
    const std::size_t colon = rest.find(':');
    const std::string file = rest.substr(0, colon);
    rest = colon == std::string::npos ? "" : rest.substr(colon + 1);
    struct stat st {};
    while (!file.empty() && ::stat(file.c_str(), &st) != 0) pause_ms(10);
  }
}

bool g_awaited = false;

}  // namespace

extern "C" int MPI_Send(const void* buf, int count, MPI_Datatype type, int dest, int tag, MPI_Comm comm) {
  if (!g_awaited) {
    await_files();
    g_awaited = true;
  }
  if (const char* ms = std::getenv("PATHEX_DEAL_SLEEP_MS")) pause_ms(std::atol(ms));
  return PMPI_Send(buf, count, type, dest, tag, comm);
}
