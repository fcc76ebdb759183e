#pragma once
/// @file cluster/bake_level.h
/// @brief One octree level of the bake from a traced photon map: voxelize the
/// scene at `depth`, splat the photons into the voxels, gather and cluster
/// (paper §3.1). The same photon map serves every level, so `bake` runs this
/// once and the progressive preview (octree/progressive_bake.h) once per depth.

#include <cstddef>
#include <vector>

#include "cluster/vdl_grid.h"
#include "core/progress.h"
#include "gather/gather.h"
#include "grid/surface_grid.h"
#include "photon/photon_map.h"
#include "scene/scene.h"

namespace lo {

struct LevelParams {
  GridParams grid;        ///< depth (paper's delta) and padding of the bounding cube
  GatherParams gather;    ///< KNN k, radius (0 = kDefaultRadiusVoxels voxels at this depth)
  ClusterParams cluster;  ///< VDLs per voxel, seed
};

/// What bakeLevel did, for reports and benchmarks. Seconds are wall time.
struct LevelStats {
  size_t activeVoxels = 0;    ///< voxels that touch geometry
  size_t droppedPhotons = 0;  ///< photons outside every active voxel's neighbourhood
  float radius = 0;           ///< gathering radius used, world units
  double voxelizeSeconds = 0, splatSeconds = 0, gatherClusterSeconds = 0;
  BakeTimings threadSeconds;  ///< gather / K-means split, summed over threads
  double seconds() const { return voxelizeSeconds + splatSeconds + gatherClusterSeconds; }
};

/// Voxelizes `scene` (buildSurfaceGrid), splats `photons` (splatPhotons) and
/// gathers + clusters every active voxel (buildVdlGrid). Deterministic: the
/// same inputs give the same grid whatever the thread count. `progress` gets
/// the voxelize and gather + cluster tasks; a sink may throw to abandon the
/// bake (the exception propagates, nothing is left behind).
VdlGrid bakeLevel(const Scene& scene, const std::vector<Photon>& photons, const LevelParams& params,
                  ProgressSink* progress = nullptr, LevelStats* stats = nullptr);

}  // namespace lo
