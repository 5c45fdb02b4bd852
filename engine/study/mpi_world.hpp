#pragma once
/// The processes of a sweep: the ranks of an MPI job when started by mpirun/mpiexec, else one.
/// MPI is joined only when the launcher's environment says so (OMPI_COMM_WORLD_SIZE, PMIX_RANK,
/// PMI_SIZE), so a plain run never starts MPI's runtime.
namespace vb {

class MpiWorld {
 public:
  /// Joins MPI when launched by an MPI launcher. Throws vb::Error when launched so but this
  /// build has no MPI (each rank would run every case).
  MpiWorld();
  /// Leaves MPI (MPI_Finalize) when it was joined.
  ~MpiWorld();
  MpiWorld(const MpiWorld&) = delete;
  MpiWorld& operator=(const MpiWorld&) = delete;

  int rank() const { return rank_; }
  int size() const { return size_; }
  /// Rank among the processes on this machine (to spread them over its devices).
  int local_rank() const { return local_rank_; }

  /// true on every rank when `mine` is true on every rank; also a barrier.
  bool all(bool mine) const;

  /// Leaves MPI now (before e.g. starting other programs); later calls of all() return `mine`.
  void finalize();

  /// true when the environment shows an MPI launcher.
  static bool launched_by_mpi();
  /// true when this build can join MPI.
  static bool built_with_mpi();

 private:
  int rank_ = 0, size_ = 1, local_rank_ = 0;
  bool joined_ = false;
};

}  // namespace vb
