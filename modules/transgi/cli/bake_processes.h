#pragma once
// The processes a `transgi bake` runs on: one alone, or, when an MPI launcher
// (mpirun, srun) started it and the build has MPI (TRANSGI_WITH_MPI), the
// ranks of MPI_COMM_WORLD. Only the bake uses this: the rest of the module
// never links MPI.
#include <memory>
#include <string>

#include "bake/communicator.h"

namespace transgi::cli {

struct BakeProcesses {
  bake::Communicator* comm = &bake::solo();
  int ranks_on_this_machine = 1;  // to share its cores between them
  std::shared_ptr<void> owner;    // keeps MPI initialised while the bake runs
};

// Throws std::runtime_error, saying what to do, when a launcher started
// several processes but this build has no MPI (each would bake alone and
// all would write the same files).
BakeProcesses join_bake_processes();

// Ends every rank of the job with exit code `code` after this rank printed
// why; with one process, does nothing.
void abort_bake_processes(const BakeProcesses& p, int code);

// "MPI (Open MPI 4.1.4)" or "no MPI in this build".
std::string mpi_description();

}  // namespace transgi::cli
