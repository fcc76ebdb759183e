// MpiSession in a build without MPI (LO_WITH_MPI=OFF): it refuses to start.

#include <cstdlib>

#include "core/error.h"
#include "distributed/mpi_session.h"

namespace lo {

struct MpiSession::State {};

bool mpiAvailable() { return false; }

MpiSession::MpiSession() {
  throw InputError(
      "this lightoctree was built without MPI: rebuild with -DLO_WITH_MPI=ON (tools/build.sh "
      "does) to bake on several processes");
}

MpiSession::~MpiSession() = default;

Communicator& MpiSession::world() { std::abort(); }

void MpiSession::abort(int code) { std::_Exit(code); }

}  // namespace lo
