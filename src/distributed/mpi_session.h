#pragma once
/// @file distributed/mpi_session.h
/// @brief MPI_COMM_WORLD as a Communicator, for the lifetime of an
/// MpiSession. MPI itself is seen by mpi_session.cpp alone, built when the
/// project is configured with -DLO_WITH_MPI=ON; without it the session
/// refuses to start, saying so (docs/scale.md).

#include <memory>

#include "distributed/communicator.h"

namespace lo {

/// The number of processes mpirun / mpiexec started this one among
/// (OpenMPI's, PMIx's or MPICH's environment), or 0 when it was started
/// some other way.
int mpiLaunchSize();

/// Whether this build can run a distributed bake (LO_WITH_MPI).
bool mpiAvailable();

class MpiSession {
 public:
  /// Initialises MPI (thread level FUNNELED: only the thread that made the
  /// session communicates; the TBB workers never do).
  /// @throws InputError when built without MPI.
  MpiSession();
  /// Finalises MPI.
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;

  Communicator& world();
  /// Ends every process of the job with `code` (MPI_Abort): what a rank
  /// that failed does, so that no other one waits for it forever.
  [[noreturn]] void abort(int code);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace lo
