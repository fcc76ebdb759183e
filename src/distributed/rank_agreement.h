#pragma once
/// @file distributed/rank_agreement.h
/// @brief Before a distributed bake does any work, its ranks agree on what
/// they bake: the same settings and the same scene. Ranks started with
/// different flags (`mpirun -np 1 ... --photons 1e5 : -np 1 ... --photons
/// 2e5`) hung in their first collective of unequal sizes or failed deep in
/// OpenMPI (MPI_ERR_TRUNCATE); a rank that read another copy of the scene
/// gave exit 0 and a grid mixed from both. Now every rank refuses, with one
/// message naming what differs and which ranks.

#include <string>

#include "bake/bake.h"
#include "core/error.h"
#include "distributed/communicator.h"
#include "distributed/tiled_bake.h"
#include "scene/scene.h"

namespace lo {

/// A 64-bit fingerprint (FNV-1a) of every setting that decides a bake's
/// result: equal settings, equal fingerprints.
uint64_t bakeSettingsFingerprint(const BakeParams& params, const TileParams& tiles);

/// A 64-bit fingerprint (FNV-1a) of a loaded scene's content: its
/// triangles, their materials, the lights and the sky.
uint64_t sceneFingerprint(const Scene& scene);

/// An error every rank of a bake throws at once, after they agreed on it:
/// each may end normally (rank 0 saying it), where an error of one rank
/// alone ends them all through MPI_Abort.
struct RanksRefuseError : InputError {
  using InputError::InputError;
};

/// Every rank calls it after a step each runs on its own (loading the
/// scene), with what the step threw there ("" when it succeeded); returns
/// when every rank succeeded. A rank whose copy of the scene was damaged
/// aborted the job before it said why (rank 0's copy read well, and only
/// rank 0 speaks): now every rank throws RanksRefuseError with the first
/// failing rank's message, "rank N: ..." where rank 0 itself succeeded.
void checkRanksSucceeded(Communicator& comm, const std::string& failure);

/// Under mpirun, what a rank that runs anything but `bake` (`given`:
/// "--version", "inspect") does: it starts MPI and joins the bake ranks'
/// first step (checkRanksSucceeded) as a rank that failed, so that every
/// rank refuses at once. A bake rank waited for it in MPI_Init forever
/// (H10-3-23). Returns false where MPI finds this process alone (a size
/// variable left in the environment of a job script: nothing to refuse),
/// else true with `message` what rank 0 says ("" on other ranks).
bool refuseBakeRanks(const std::string& given, std::string& message);

/// Every rank calls it with its own settings, scene and `outputs` (the
/// files rank 0 writes, as this rank was told: ranks given another -o saw
/// rank 0's written without a word); returns when all agree.
/// @throws RanksRefuseError on every rank (the same message) when a rank's
/// settings, scene or outputs differ from rank 0's.
void checkRanksAgree(const Scene& scene, const BakeParams& params, const TileParams& tiles,
                     Communicator& comm, const std::string& outputs = {});

}  // namespace lo
