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

/// Every rank calls it with its own settings, scene and `outputs` (the
/// files rank 0 writes, as this rank was told: ranks given another -o saw
/// rank 0's written without a word); returns when all agree.
/// @throws InputError on every rank (the same message) when a rank's
/// settings, scene or outputs differ from rank 0's.
void checkRanksAgree(const Scene& scene, const BakeParams& params, const TileParams& tiles,
                     Communicator& comm, const std::string& outputs = {});

}  // namespace lo
