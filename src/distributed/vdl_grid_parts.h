#pragma once
/// @file distributed/vdl_grid_parts.h
/// @brief A light grid in parts: the voxels one rank of a distributed bake
/// owns, as bytes to send, and the parts merged back into one grid in
/// canonical voxel order (canonicalVoxelKey), with their surface layers.

#include <cstdint>
#include <vector>

#include "lightgrid/vdl_grid.h"

namespace lo {

/// The voxels `voxels` (ascending indices) of `grid` with their layers, in
/// that order. Frame, VDL slots and SH terms are kept.
VdlGrid selectVoxels(const VdlGrid& grid, const std::vector<uint32_t>& voxels);

/// `grid` as bytes (this build's layout: for the ranks of one job only).
std::vector<char> serializeVdlGrid(const VdlGrid& grid);
/// @throws IoError when the bytes are not a serializeVdlGrid of this build.
VdlGrid deserializeVdlGrid(const std::vector<char>& bytes);

/// One grid of every voxel of `parts` (disjoint voxel sets of one frame,
/// the same VDL slots and SH terms), in canonical voxel order, each voxel's
/// layers after it in their order.
/// @throws IoError when the parts disagree or share a voxel.
VdlGrid mergeVdlGrids(std::vector<VdlGrid> parts);

}  // namespace lo
