#pragma once
/// @file cluster/vdl_grid.h
/// @brief K-means of photon directions into virtual directional lights
/// (paper §3.1.2), and the per-voxel VDL grid the bake produces.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "gather/gather.h"
#include "grid/surface_grid.h"
#include "photon/photon_map.h"

namespace lo {

constexpr int kMaxVdls = 8;  ///< paper §3.1.2: "we fixed the maximum number of VDLs to 8"

/// A virtual directional light: irradiance arriving from one direction.
struct Vdl {
  Vec3 irradiance{0, 0, 0};  ///< RGB, W/m^2
  Vec3 direction{0, 0, 0};   ///< unit, world space, towards the light (like wi)
};

struct ClusterParams {
  int vdls = 4;               ///< clusters per voxel, 1..kMaxVdls (paper: 4)
  bool autoCount = false;     ///< fewest clusters (<= vdls... up to kMaxVdls) whose angular error is under autoThreshold
  float autoThreshold = 0.35f;  ///< chord-length standard deviation (0.35 ~ 20 degrees, paper §5.3.2)
  int maxIterations = 20;
  uint64_t seed = 1;
};

/// One weighted direction to cluster: a photon (value = its share of the
/// irradiance estimate) or, when merging voxels, a VDL.
struct DirectionSample {
  Vec3 direction;  ///< unit
  Vec3 value;      ///< RGB; the K-means weight is average(value)
};

struct ClusterResult {
  int count = 0;                 ///< VDLs produced (0 when there is no power)
  std::array<Vdl, kMaxVdls> vdls{};  ///< sorted by decreasing average irradiance
  float angularError = 0.0f;     ///< weighted std. deviation of chord length to the cluster centroid
};

/// Weighted K-means with the chord-length distance (k-means++ seeding from
/// Rng(params.seed, stream)). VDL irradiance = sum of member values, so the VDLs
/// sum to the total exactly up to rounding; direction = normalized weighted mean.
/// Handles n < k, identical directions, empty clusters and zero weights.
ClusterResult clusterDirections(const DirectionSample* samples, size_t n, int k,
                                const ClusterParams& params, uint64_t stream);

/// The bake's result: per active voxel, the total irradiance and up to
/// `maxVdls` VDLs (unused slots are zero).
struct VdlGrid {
  GridFrame frame;
  int maxVdls = 4;
  std::vector<Coord> coords;
  std::vector<Vec3> normals;        ///< unit (oriented towards the light), or zero
  std::vector<float> areas;         ///< geometry area in the voxel
  std::vector<Vec3> irradiance;     ///< total RGB irradiance, W/m^2 (= sum of the VDLs)
  std::vector<float> photonCount;   ///< photons gathered for the estimate
  std::vector<float> radius;        ///< r_k reached, world units
  std::vector<float> angularError;
  std::vector<uint8_t> vdlCount;
  std::vector<Vdl> vdls;            ///< coords.size() * maxVdls

  size_t size() const { return coords.size(); }
  const Vdl* vdlsOf(size_t v) const { return vdls.data() + v * size_t(maxVdls); }
};

struct BakeTimings {
  double gatherSeconds = 0;   ///< summed over threads
  double clusterSeconds = 0;  ///< summed over threads
};

/// Gathers and clusters every active voxel (TBB over blocks of voxels,
/// deterministic: each voxel's K-means stream is its index).
VdlGrid buildVdlGrid(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                     const GatherParams& gather, const ClusterParams& cluster,
                     ProgressSink* progress = nullptr, BakeTimings* timings = nullptr);

}  // namespace lo
