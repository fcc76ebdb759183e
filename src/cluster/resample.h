#pragma once
/// @file cluster/resample.h
/// @brief Converting a baked VDL grid to another depth or VDL count without the
/// photon map: merging child voxels into coarser ones, interpolating parent
/// voxels onto a finer surface grid, and re-clustering each voxel's VDLs.
/// See docs/convert.md for the methods and measured differences.

#include <cstddef>

#include "cluster/vdl_cluster.h"
#include "grid/surface_grid.h"

namespace lo {

/// @brief Merges the grid into depth `depth` < grid.frame.depth. Coarse voxel
/// C holds the fine voxels c with (c >> levels) == C, levels = d_in - depth.
///
/// - irradiance: area-weighted mean of the children's totals (W/m^2), so that
///   Σ irradiance · area over the coarse grid equals the fine grid's sum.
///   Children with zero total area are averaged with equal weights.
/// - VDLs: power-weighted K-means (clusterDirections, stream = coarse index)
///   of the children's VDLs, each VDL's irradiance scaled by its child's weight.
/// - normal = normalize(Σ area · normal); area = Σ area; photon_count = Σ;
///   radius = weighted mean; angular_error combines the clustering's error
///   with the children's (square root of the summed weighted variances).
/// - frame: same origin, voxel size · 2^levels.
/// TBB-parallel over coarse voxels, deterministic.
/// @throws InputError if depth is not in [1, grid.frame.depth) or params.vdls
/// outside [1, kMaxVdls].
VdlGrid coarsenVdlGrid(const VdlGrid& grid, int depth, const ClusterParams& params);

/// What refineVdlGrid did besides the grid itself.
struct RefineStats {
  size_t voxels = 0;         ///< active voxels of the finer geometry
  size_t withoutParent = 0;  ///< fine voxels none of whose 8 parents is active (left dark)
};

/// @brief Interpolates the grid onto the active voxels of `finerGeometry`, a
/// surface grid of the same scene at a finer depth (same origin, voxel size
/// grid.voxelSize / 2^levels; InputError naming both frames otherwise).
///
/// Each fine voxel's centre, expressed in the parent grid's index space, has up
/// to 8 nearest parent voxel centres; their trilinear weights are kept for the
/// active parents only and renormalised. The fine voxel's irradiance is the
/// weighted sum of the parents' irradiance; its VDLs are the parents' VDLs
/// (irradiance scaled by the weight) re-clustered to params.vdls with
/// clusterDirections (stream = fine index). Normal and area come from the finer
/// geometry; photon_count, radius and angular_error are interpolated the same way.
VdlGrid refineVdlGrid(const VdlGrid& grid, const SurfaceGrid& finerGeometry,
                      const ClusterParams& params, RefineStats* stats = nullptr);

/// @brief Same voxels, VDLs re-clustered to params.vdls (or auto under that
/// cap): each voxel's VDLs are the samples. Irradiance, normal, area, counts
/// and radius are kept; angular_error combines the old error with the new
/// clustering's (see coarsenVdlGrid). maxVdls becomes params.vdls. Surface
/// layers are kept, their VDLs re-clustered the same way. (coarsenVdlGrid
/// and refineVdlGrid return grids without layers: a new depth needs a new
/// bake for them.)
VdlGrid reclusterVdlGrid(const VdlGrid& grid, const ClusterParams& params);

/// @brief Checks that `b` is the frame of `a` refined (or coarsened) to b.depth:
/// same origin, voxel size scaled by 2^(a.depth - b.depth), both up to a
/// relative 1e-5 of the larger voxel size. @throws InputError describing both.
void checkNestedFrames(const GridFrame& a, const GridFrame& b, const char* what);

}  // namespace lo
