// pathex-mpi: the pathex command line inside an MPI job. `mpirun -n N pathex-mpi trace …` renders
// one image across the N ranks (mpi_cluster.cpp) and writes the outputs of one process on rank 0;
// every other command runs as in pathex, on every rank.
#include <mpi.h>

#include <cstdio>

#include "cli/common.h"
#include "cli/mpi/mpi_cluster.h"

int main(int argc, char** argv) {
  int provided = 0;
  // Only the main thread calls MPI (the TBB workers never do).
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided) != MPI_SUCCESS) {
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
