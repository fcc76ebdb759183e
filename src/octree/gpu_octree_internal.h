#pragma once
/// @file octree/gpu_octree_internal.h
/// @brief What gpu_octree.cpp shares with the files beside it (internal to
/// src/octree: nothing outside it includes this header): collapseVolume,
/// defined in collapse_volume.cpp.

#include "lightgrid/vdl_grid.h"
#include "octree/adaptive_leaves.h"

namespace lo::gpu_octree_internal {

/// The free-space leaves that merge (GpuOctreeParams::volumeTolerance > 0):
/// eight siblings whose light reaches every face they share (a wall may cut
/// them on the parent's outside only), and whose irradiance, for each of 14
/// normals (the axes and the cube's diagonals), lies within `tolerance` of
/// their mean's, the mean of the eight taken over all those normals, become
/// one leaf holding their mean SH terms and their boxes joined (in its own
/// units); level by level up to level 1, as long as all eight children of a
/// node are leaves.
AdaptiveLeaves collapseVolume(const VolumeLight& v, float tolerance);

}  // namespace lo::gpu_octree_internal
