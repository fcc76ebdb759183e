#pragma once
/// @file bake/stats_json.h
/// @brief The figures of a bake as a JSON file (`lightoctree bake
/// --stats-json`, read by the benchmark scripts): the schema in one place.
///
/// The document, keys in alphabetical order (as nlohmann-json writes them):
///   scene, output            the files as the command named them
///   parameters               depth, photons (null for a target bake),
///                            target_error, max_photons (null for a fixed
///                            budget), knn (the one gathered with), radius (the
///                            gathering radius used, world units), vdls ("4" or "auto"),
///                            representation, seed, threads, include_direct,
///                            layers, gather_occlusion, edge_correction,
///                            smoothing ("on" / "off")
///   counts                   triangles, stored_photons, emitted_paths,
///                            empty_paths (paths that stored no photon),
///                            active_voxels, dense_voxels,
///                            photons_outside_grid, vdb_bytes
///   noise                    the grid's noise figure (noiseSummaryJson), or null
///   target                   a target bake's passes (photons, paths, noise,
///                            seconds each) and why it stopped; absent otherwise
///   thread_seconds           gather, cluster: summed over threads
///   stages                   per row: name, seconds, rss_bytes, peak_rss_bytes
///   total_seconds            the rows' seconds summed
///   peak_rss_bytes           of the process
/// and the sections a later stage adds (the distributed bake's
/// "distributed").

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "bake/bake.h"
#include "core/resources.h"

namespace lo {

/// What the file records besides BakeStats: the run around the bake.
struct BakeStatsRecord {
  std::string scene;   ///< the scene file, as given
  std::string output;  ///< the .vdb written, as given
  BakeParams params;   ///< the settings the bake was asked for
  float radius = 0;    ///< gathering radius used, world units (BakeMetadata::radius)
  int threads = 0;     ///< worker threads asked for; 0 = all cores
  uint64_t vdbBytes = 0;            ///< size of the .vdb written, bytes
  std::vector<StageReport> stages;  ///< every row the command reports, in order
  uint64_t peakRssBytes = 0;        ///< of the process, bytes
  /// Further top-level members, (key, JSON text): the figures of stages
  /// after this one, whose types this stage cannot see (the distributed
  /// bake's per-rank figures). @throws InputError from bakeStatsJson when a
  /// text is not JSON or a key is one of the document's own.
  std::vector<std::pair<std::string, std::string>> sections;
};

/// @brief The document described above for `stats` and `record`: indented
/// by 2 spaces, ending in a newline. Deterministic (the same values give the
/// same bytes).
std::string bakeStatsJson(const BakeStats& stats, const BakeStatsRecord& record);

/// A noise figure as JSON text: quantile, median, lit, unlit,
/// mean_irradiance; "null" when not recorded. The one spelling of it
/// (`bake --stats-json` and `inspect --json`).
std::string noiseSummaryJson(const NoiseSummary& noise);

}  // namespace lo
