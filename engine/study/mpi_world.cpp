#include "engine/study/mpi_world.hpp"

#include <cstdlib>

#include "engine/error.hpp"

#ifdef VOXBREAST_HAVE_MPI
#include <mpi.h>
#endif

namespace vb {

bool MpiWorld::launched_by_mpi() {
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE", "PMI_RANK"})
    if (std::getenv(name)) return true;
  return false;
}

bool MpiWorld::built_with_mpi() {
#ifdef VOXBREAST_HAVE_MPI
  return true;
#else
  return false;
#endif
}

MpiWorld::MpiWorld() {
  if (!launched_by_mpi()) return;
#ifdef VOXBREAST_HAVE_MPI
  int provided = 0;
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  joined_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, rank_, MPI_INFO_NULL, &node);
  MPI_Comm_rank(node, &local_rank_);
  MPI_Comm_free(&node);
#else
  throw Error("started by an MPI launcher, but this build of voxbreast has no MPI", "mpirun",
              "rebuild with libopenmpi-dev installed (cmake -DVOXBREAST_MPI=ON), or run without mpirun");
#endif
}

MpiWorld::~MpiWorld() { finalize(); }

void MpiWorld::finalize() {
#ifdef VOXBREAST_HAVE_MPI
  if (joined_) MPI_Finalize();
#endif
  joined_ = false;
}

bool MpiWorld::all(bool mine) const {
#ifdef VOXBREAST_HAVE_MPI
  if (joined_) {
    int in = mine ? 1 : 0, out = 0;
    MPI_Allreduce(&in, &out, 1, MPI_INT, MPI_MIN, MPI_COMM_WORLD);
    return out == 1;
  }
#endif
  return mine;
}

}  // namespace vb
