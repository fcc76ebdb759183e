#pragma once
/// @file octree/adaptive_leaves.h
/// @brief Adaptive leaves (docs/octree.md, "Adaptive leaves"): siblings whose
/// light agrees within a tolerance collapse into one coarser leaf of the GPU
/// octree, which already descends to leaves at any level (paper §4.2.1).
/// The .vdb keeps every voxel; the adaptive tree is derived from it and the
/// tolerance when the octree is built (GpuOctreeParams::tolerance).

#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/math.h"
#include "lightgrid/vdl_grid.h"

namespace lo {

/// One leaf above the grid's depth: the node at `level` (coordinates at that
/// level's resolution) standing for every voxel of the grid below it.
struct CollapsedLeaf {
  Coord coord;      ///< node coordinate at `level`: voxel c >> (depth - level)
  int level = 0;    ///< 1 .. depth - 1
  /// The light the shader reads, as stored texels: VDLs whose irradiance is
  /// the *intensity* the shader multiplies by max(0, n . d) (the cosine
  /// correction already applied, GpuOctreeParams::cosineCorrection), or SH
  /// terms (VdlGrid::shTerms of them).
  std::vector<Vdl> vdls;
  std::vector<Vec3> sh;
  /// Its surface texel (GpuOctree::surfaceTexels): its voxels' reflectance
  /// and unit normal, means weighted by their areas.
  Vec3 reflectance{0, 0, 0}, normal{0, 0, 0};
  /// A free-space leaf (buildVolumeOctree): the box its voxels' light
  /// filled, in its own units (VolumeLight::litLower / litUpper).
  Vec3 litLower{0, 0, 0}, litUpper{1, 1, 1};
};

/// The adaptive tree of a grid: the collapsed leaves, and per voxel of the
/// grid whether a collapsed leaf holds it (`collapsed[v]`: the voxel is not
/// a leaf of its own).
struct AdaptiveLeaves {
  std::vector<CollapsedLeaf> leaves;
  std::vector<char> collapsed;
  size_t voxelsCollapsed = 0;
};

/// Collapses, bottom-up, every node whose lit children (voxels, or nodes
/// collapsed already) all hold plain light (no surface layers) into one leaf
/// whose light is the area-weighted mean of theirs (SH: the mean of the
/// terms; VDLs: all the children's, weighted, then the two closest in
/// direction merged until no more than the most any child had remain), when at every
/// voxel below it, at the voxel's own normal, the merged light's irradiance
/// differs from the voxel's own by at most `tolerance` times the larger of
/// the voxel's brightest channel and a floor (kAdaptiveFloorShare of the
/// grid's mean brightest channel: dark voxels merge on absolute
/// differences). Voxels without a normal never collapse. Deterministic.
/// `cosineCorrection`: as GpuOctreeParams' (the intensities the shader reads).
AdaptiveLeaves collapseLeaves(const VdlGrid& grid, float tolerance, bool cosineCorrection);

/// The floor under the tolerance's scale, as a share of the grid's mean
/// brightest irradiance channel.
constexpr float kAdaptiveFloorShare = 0.05f;

/// A surface's reflectance as the octree stores it (its surface texel): each
/// channel clamped to 0..1, since a file's values are only known finite and
/// one beyond that range would add light, or take it.
inline Vec3 storedReflectance(const Vec3& r) {
  return {std::clamp(r.x, 0.0f, 1.0f), std::clamp(r.y, 0.0f, 1.0f), std::clamp(r.z, 0.0f, 1.0f)};
}

/// A VDL's intensity as the octree stores it: c / max(|n . d|,
/// kMinCorrectionCosine) with the correction (and a unit normal n), else c.
Vec3 vdlIntensity(const Vdl& vdl, const Vec3& normal, bool cosineCorrection);

}  // namespace lo
