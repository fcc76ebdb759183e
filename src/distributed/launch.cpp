// mpiLaunchSize: how mpirun / mpiexec tells a process it is one of several.

#include <cstdlib>
#include <string>

#include "distributed/mpi_session.h"

namespace lo {

int mpiLaunchSize() {
  // OpenMPI, then MPICH / Hydra (PMI), then PMIx alone.
  for (const char* name : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_SIZE"}) {
    const char* value = std::getenv(name);
    if (value && *value) {
      char* end = nullptr;
      const long n = std::strtol(value, &end, 10);
      if (end && *end == 0 && n >= 1 && n < 1000000) return int(n);
    }
  }
  return 0;
}

}  // namespace lo
