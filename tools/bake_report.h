#pragma once
/// @file tools/bake_report.h
/// @brief What `bake` reports of a distributed bake (src/distributed): the
/// per-rank table on the terminal and the "distributed" section of
/// --stats-json (bake/stats_json.h holds the rest of that file's schema).

#include <cstdint>
#include <string>

#include "distributed/tiled_bake.h"

namespace lo::tool {

/// One row per rank, with the tiles, the halo and the bytes exchanged per
/// stored photon (none when `storedPhotons` is 0).
void printRanks(const DistributedStats& d, size_t storedPhotons);

/// The "distributed" section of the bake's statistics file as JSON text:
/// ranks, tiles, halo, attempts, bytes exchanged per stored photon, per-rank
/// figures and the tile owner and work tables (docs/scale.md).
std::string distributedStatsJson(const DistributedStats& d, int ranks, size_t storedPhotons);

}  // namespace lo::tool
