// pathex-mpi: the pathex command line inside an MPI job. `mpirun -n N pathex-mpi trace …` renders
// one image across the N ranks (mpi_cluster.cpp) and writes the outputs of one process on rank 0;
// every other command runs as in pathex, on every rank. As in pathex, the whole of it runs on a
// thread with an explicit stack (core/stack.h); MPI is initialised on that thread too. Only it calls
// MPI, except on rank 0 while the ranks deal the passes, when a thread of the deal does
// (mpi_deal.h): MPI_THREAD_SERIALIZED.
#include <mpi.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "cli/common.h"
#include "cli/mpi/mpi_cluster.h"
#include "core/stack.h"

namespace {

// Open MPI's default point-to-point layer (on Debian's build) is UCX, whose start-up probes the
// machine's network devices: some 0.2 s of MPI_Init on every run (bench/README.md, "issue 16,
// sixth session"), paid by every rank before it renders. Ranks on one host need none of it: Open
// MPI's ob1 layer over shared memory (btl vader, self) carries their messages. So when Open MPI's
// launcher says every rank of the job is on this host (OMPI_COMM_WORLD_LOCAL_SIZE equals
// OMPI_COMM_WORLD_SIZE) and the user chose no layer (no OMPI_MCA_pml or OMPI_MCA_btl, which
// `mpirun --mca pml …` and `-x` set), pathex-mpi asks for ob1 with shared memory (and TCP, should
// shared memory be unavailable). A job across hosts keeps Open MPI's defaults (UCX where it is
// built). The variables are read by MPI_Init, in this process, before it opens any component.
// PATHEX_MPI_DEFAULTS=0 keeps Open MPI's defaults on one host too.
void prefer_shared_memory_on_one_host() {
  const char* size = std::getenv("OMPI_COMM_WORLD_SIZE");
  const char* local = std::getenv("OMPI_COMM_WORLD_LOCAL_SIZE");
  const char* off = std::getenv("PATHEX_MPI_DEFAULTS");
  if (size == nullptr || local == nullptr || std::strcmp(size, local) != 0) return;
  if (off != nullptr && std::strcmp(off, "0") == 0) return;
  if (std::getenv("OMPI_MCA_pml") != nullptr || std::getenv("OMPI_MCA_btl") != nullptr) return;
  ::setenv("OMPI_MCA_pml", "ob1", 0);
  ::setenv("OMPI_MCA_btl", "self,vader,tcp", 0);
}

int run_mpi_command_line(int argc, char** argv) {
  prefer_shared_memory_on_one_host();
  int provided = 0;
  // One thread at a time calls MPI (the TBB workers never do).
  if (MPI_Init_thread(&argc, &argv, MPI_THREAD_SERIALIZED, &provided) != MPI_SUCCESS) {
    std::fprintf(stderr, "pathex: error: MPI_Init failed\n");
    return pathex::cli::kExitBadInput;
  }
  int code = 0;
  {
    pathex::cli::MpiCluster cluster;
    pathex::set_cluster(&cluster);
    code = pathex::cli::run_command_line(argc, argv);
    pathex::set_cluster(nullptr);
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
