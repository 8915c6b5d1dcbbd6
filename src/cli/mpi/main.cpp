// pathex-mpi: the pathex command line inside an MPI job. `mpirun -n N pathex-mpi trace …` renders
// one image across the N ranks (mpi_cluster.cpp) and writes the outputs of one process on rank 0;
// every other command runs as in pathex, on every rank. As in pathex, the whole of it runs on a
// thread with an explicit stack (core/stack.h); MPI is initialised on that thread too. Only it calls
// MPI, except on rank 0 while the ranks deal the passes, when a thread of the deal does
// (mpi_deal.h): MPI_THREAD_SERIALIZED.
#include <mpi.h>

#include <cstdio>

#include "cli/common.h"
#include "cli/mpi/mpi_cluster.h"
#include "core/stack.h"

namespace {

int run_mpi_command_line(int argc, char** argv) {
  int provided = 0;
  // One thread at a time calls MPI (the TBB workers never do).
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
    std::fprintf(stderr, "pathex: error: MPI_Init failed\n");
    return pathex::cli::kExitBadInput;
  }
  int code = 0;
  {
    pathex::cli::MpiCluster cluster;
    pathex::cli::set_cluster(&cluster);
    code = pathex::cli::run_command_line(argc, argv);
    pathex::cli::set_cluster(nullptr);
  }
  MPI_Finalize();
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  int code = pathex::cli::kExitBadInput;
  if (!pathex::run_on_stack(pathex::kCommandLineStackBytes, [&] { code = run_mpi_command_line(argc, argv); })) {
    std::fprintf(stderr, "pathex: error: cannot start the command line's thread (a %zu MiB stack)\n",
                 pathex::kCommandLineStackBytes >> 20);
  }
  return code;
}
