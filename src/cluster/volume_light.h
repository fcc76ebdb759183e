#pragma once
/// @file cluster/volume_light.h
/// @brief The free-space light (lightgrid/volume_light.h) from the photon
/// paths: the track length of every ray whose light the octree holds
/// (PhotonSegment) through each voxel of a coarser grid, projected on SH.

#include <vector>

#include "core/progress.h"
#include "lightgrid/grid_frame.h"
#include "lightgrid/photon.h"
#include "lightgrid/volume_light.h"

namespace lo {

struct VolumeLightParams {
  /// Levels coarser than the surface grid (its depth minus these, at least
  /// 1): 2 gives a voxel 4 surface voxels wide.
  int levels = 2;
  int shTerms = 4;  ///< 4 (order 1) or 9 (order 2)
  /// Slabs of voxels walked in parallel; 0 = one per thread. The bytes do
  /// not depend on it (tests set it).
  int slabs = 0;
};

/// The track-length estimate of the light in each voxel: a ray of power P
/// crossing a voxel of volume V over a length l adds P l / V of radiance
/// times solid angle from the direction it came from (an unbiased estimate
/// of the fluence, and per direction of the radiance: docs/render.md "Light
/// for what moves"). Light only goes where the rays went, so no voxel inside
/// a closed solid, or in a room the light never reached, is lit. Parallel
/// over slabs of voxels, each reading its rays in order: the same bytes
/// whatever the thread count. `surface`: the light grid's frame.
/// @throws InputError for levels < 0 or shTerms other than 4 or 9.
VolumeLight buildVolumeLight(const std::vector<PhotonSegment>& segments, const GridFrame& surface,
                             const VolumeLightParams& params = {},
                             ProgressSink* progress = nullptr);

}  // namespace lo
