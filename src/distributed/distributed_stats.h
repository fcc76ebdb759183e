#pragma once
/// @file distributed/distributed_stats.h
/// @brief What a distributed bake reports: the per-rank table for the
/// terminal and the "distributed" section of `bake --stats-json`
/// (bake/stats_json.h holds the rest of that file's schema, and takes this
/// section as text through BakeStatsRecord::sections).

#include <cstdint>
#include <string>

#include "distributed/tiled_bake.h"

namespace lo {

/// The per-rank table as text: the tiles and the halo, one row per rank,
/// then the bytes exchanged per stored photon (left out when
/// `storedPhotons` is 0). Starts with a blank line, ends with a newline.
std::string ranksTable(const DistributedStats& d, size_t storedPhotons);

/// The "distributed" section of the bake's statistics file as JSON text:
/// ranks, tiles, halo, attempts, bytes exchanged per stored photon, per-rank
/// figures and the tile owner and work tables (docs/scale.md).
std::string distributedStatsJson(const DistributedStats& d, int ranks, size_t storedPhotons);

}  // namespace lo
