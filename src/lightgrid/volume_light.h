#pragma once
/// @file lightgrid/volume_light.h
/// @brief The octree's free-space light: incident light in the voxels of a
/// coarser grid over the whole cube, surfaces or not, so that an object that
/// was not baked (a car driven through a building) is lit where it stands.
/// Made by cluster/volume_light.h from the photon paths' segments, drawn
/// through the octree's own lookup (octree/gpu_octree.h buildVolumeOctree),
/// stored in the .vdb as the `volume_*` grids (docs/vdb-contract.md).

#include <cstddef>
#include <vector>

#include "core/math.h"
#include "lightgrid/grid_frame.h"

namespace lo {

struct VolumeLight {
  /// The same cube as the surface grid's, `levels` coarser; depth 0: no
  /// free-space light was baked.
  GridFrame frame{{0, 0, 0}, 1.0f, 0, {}};
  int shTerms = 4;  ///< SH terms per voxel: 4 (order 1) or 9 (order 2)
  /// Voxels light passed through, in canonical order (canonicalVoxelKey).
  std::vector<Coord> coords;
  /// The irradiance a surface in the voxel receives, averaged over its
  /// orientations: a quarter of the fluence, W/m^2 (what a viewer shows).
  std::vector<Vec3> irradiance;
  /// Irradiance SH terms E_i, shTerms per voxel: E(n) = sum_i E_i Y_i(n)
  /// (shaders/octree_layout.h's basis), light from every direction.
  std::vector<Vec3> sh;
  std::vector<float> segments;  ///< light rays that crossed the voxel
  /// The box the light filled inside the voxel, in voxel units from its
  /// lower corner ([0, 1] per axis): where a wall cuts the voxel, the lit
  /// side. The renderer does not take a voxel's light to points beyond it
  /// (no light through a thin wall).
  std::vector<Vec3> litLower, litUpper;

  size_t size() const { return coords.size(); }
  bool empty() const { return coords.empty(); }
  const Vec3* shOf(size_t v) const { return sh.data() + v * size_t(shTerms); }
};

}  // namespace lo
