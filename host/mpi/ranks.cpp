#include "host/mpi/ranks.h"

#include <algorithm>
#include <cstdlib>
#include <thread>

#include "host/common/input_error.h"
#if SIGMAFEM_HAVE_MPI
#  include <mpi.h>
#endif

namespace sigmafem {
namespace {

RankInfo world;
bool started = false;

// The ranks that mpirun (or another launcher) says this process belongs to: 0 when none.
int launched_ranks() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE"})
    if (const char* value = std::getenv(name)) return std::atoi(value);
  return std::getenv("PMIX_RANK") ? 1 : 0;
}

}  // namespace

void start_ranks(int* argc, char*** argv) {
  const int launched = launched_ranks();
#if SIGMAFEM_HAVE_MPI
  if (launched == 0) return;
  MPI_Init(argc, argv);
  started = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &world.rank);
  MPI_Comm_size(MPI_COMM_WORLD, &world.size);
  MPI_Comm machine;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &machine);
  MPI_Comm_size(machine, &world.local_size);
  MPI_Comm_free(&machine);
#else
  (void)argc;
  (void)argv;
  if (launched > 1)
    throw InputError("launched on " + std::to_string(launched) + " MPI ranks, but this sigmafem was built "
                     "without MPI (install libopenmpi-dev and build again; README, \"Over MPI ranks\")");
#endif
}

void finish_ranks() {
#if SIGMAFEM_HAVE_MPI
  if (started) MPI_Finalize();
  started = false;
#endif
}

int RankInfo::cores_per_rank() const {
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()) / local_size);
}

const RankInfo& ranks() { return world; }

std::string program_name() {
  if (!world.distributed()) return "sigmafem";
  return "sigmafem (rank " + std::to_string(world.rank) + " of " + std::to_string(world.size) + ")";
}

}  // namespace sigmafem
