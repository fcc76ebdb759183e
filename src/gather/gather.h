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
  /// Photons within r as (float bits of d^2) << 32 | photon index, so that one
  /// integer comparison orders by distance with ties broken by index; split by
  /// the side they arrived from relative to the unoriented voxel normal.
  std::vector<uint64_t> candidates_;
  std::vector<uint64_t> backCandidates_;

  /// The photons of the active voxels near the 8^3 block of the last gathered
  /// voxel, copied contiguously once per block (grid.find + bins) and scanned
  /// by every voxel of the block: the scan then reads cache-resident memory
  /// instead of photons scattered over the whole map.
  struct LocalPhoton {
    Vec3 position;
    Vec3 normal;
    Vec3 power;
    uint32_t index;
  };
  struct Neighbour {
    Coord coord;
    uint32_t begin, end;  ///< range in blockPhotons_
  };
  void updateBlock(const Coord& voxelCoord);
  Coord blockCoord_{};
  bool blockValid_ = false;
  std::vector<Neighbour> blockNeighbours_;
  std::vector<LocalPhoton> blockPhotons_;
};

/// Reference: the same selection by scanning every photon. For tests.
GatherResult gatherBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                              size_t voxel, const GatherParams& params);

}  // namespace lo
