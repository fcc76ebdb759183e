#pragma once
/// @file gather/gather.h
/// @brief KNN filtering per voxel (paper §3.1.1): the k nearest photons within
/// radius r, distances measured in an ellipsoid aligned with the voxel normal.

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "grid/surface_grid.h"
#include "photon/photon_map.h"

namespace lo {

struct GatherParams {
  int k = 300;           ///< nearest neighbours (paper: 300)
  /// Gathering radius in world units; 0 = kDefaultRadiusVoxels * voxel size.
  float radius = 0.0f;
  /// Ellipsoid axis ratio: a photon's offset along the voxel normal counts
  /// `normalSquash` times its length, so photons on a perpendicular wall or
  /// behind a thin wall fall outside the search region.
  float normalSquash = 4.0f;
};

/// Default radius in voxels: large enough that k = 300 photons are reached on a
/// plane at the paper's photon density (600k photons, depth 6).
constexpr float kDefaultRadiusVoxels = 3.0f;

float resolveRadius(const GatherParams& params, const GridFrame& frame);

struct GatherResult {
  std::vector<uint32_t> photons;  ///< indices of the gathered photons (<= k), nearest first not required
  float radius = 0.0f;            ///< r_k: distance (ellipsoid metric) of the k-th photon, or r if fewer found
  Vec3 normal{0, 0, 0};           ///< voxel normal oriented towards the side the light arrives from
  Vec3 irradiance{0, 0, 0};       ///< sum(power) / (pi r_k^2), W/m^2
};

/// Grid-coherent gatherer: candidates come from the photon bins of the voxels
/// within the radius, so no kd-tree is built. One per thread (holds scratch).
class Gatherer {
 public:
  Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons, const GatherParams& params);
  void gather(size_t voxel, GatherResult& out);

 private:
  const SurfaceGrid& grid_;
  const std::vector<Photon>& photons_;
  GatherParams params_;
  float radius_;
  int reachVoxels_;
  std::vector<std::pair<float, uint32_t>> candidates_;
};

/// Reference: the same selection by scanning every photon. For tests.
GatherResult gatherBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                              size_t voxel, const GatherParams& params);

}  // namespace lo
