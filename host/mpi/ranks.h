// The run's MPI ranks (issue 19): `mpirun -n R sigmafem estimate ...` starts R processes, and
// the sigma points are split over them (host/mpi/distributed_ensemble.h). Outside mpirun, or in
// a build without MPI (CMake found none), there is one rank and MPI is never started, so the
// other commands and the tests pay nothing for it.
#pragma once

#include <string>

namespace sigmafem {

struct RankInfo {
  int rank = 0;    // this process's rank in MPI_COMM_WORLD
  int size = 1;    // ranks in all
  int local_size = 1;   // ranks on this machine (they share its cores)
  bool distributed() const { return size > 1; }
  // This machine's cores divided among its ranks (at least 1): a rank's CPU threads.
  int cores_per_rank() const;
};

// Starts MPI when the process was launched by mpirun (Open MPI's OMPI_COMM_WORLD_SIZE, or
// PMI_SIZE / PMIX_RANK of other launchers) and the build has MPI. Launched with more than one
// rank by a build without MPI, it throws InputError: R copies of the whole run would each
// write the same outputs.
void start_ranks(int* argc, char*** argv);
// Ends MPI if start_ranks started it (every rank calls it once, at exit).
void finish_ranks();
const RankInfo& ranks();
// "sigmafem" on one rank, "sigmafem (rank 2 of 3)" on several: how messages begin.
std::string program_name();

}  // namespace sigmafem
