#pragma once
/// @file cluster/vdl_cluster.h
/// @brief K-means of photon directions into virtual directional lights
/// (paper §3.1.2), and the gather + cluster pass over every voxel that fills
/// a VdlGrid (lightgrid/vdl_grid.h).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "gather/gather.h"
#include "grid/surface_grid.h"
#include "lightgrid/photon.h"
#include "lightgrid/vdl_grid.h"

namespace lo {

struct ClusterParams {
  int vdls = 4;               ///< clusters per voxel, 1..kMaxVdls (paper: 4)
  bool autoCount = false;     ///< fewest clusters (<= vdls... up to kMaxVdls) whose angular error is under autoThreshold
  float autoThreshold = 0.35f;  ///< chord-length standard deviation (0.35 ~ 20 degrees, paper §5.3.2)
  int maxIterations = 20;
  uint64_t seed = 1;
  /// VDLs (K-means, the fields above), or SH of order 1 or 2 (projectSh).
  LightRepresentation representation = LightRepresentation::Vdl;
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

/// Smallest cosine to the voxel's normal projectSh divides by: the
/// GpuOctreeParams::cosineCorrection of the VDLs (kMinCorrectionCosine),
/// applied at the bake.
constexpr float kShMinCosine = 0.25f;

/// The SH representation of one voxel (or layer) from its gathered samples:
/// each sample (value c_k on the voxel's surface, direction d_k) is a
/// directional light of intensity c_k / max(|n . d_k|, kShMinCosine), n =
/// `normal`; their radiance is projected on the `terms` (4 or 9) real SH of
/// shaders/octree_layout.h and convolved with the clamped cosine, giving
/// irradiance coefficients E_i (out[0 .. terms)). Each channel is then
/// scaled so that E(n) = sum_i E_i Y_i(n) equals the samples' sum, the
/// gathered estimate, where both are positive: the truncated series keeps
/// the voxel's own irradiance and adds the change with the normal (a normal
/// map's). Where the series is not positive at the normal (a few photons
/// from grazing directions ring below zero there) the channel is kept as a
/// constant equal to the estimate. `normal` zero: no division, no scaling.
void projectSh(const DirectionSample* samples, size_t n, const Vec3& normal, int terms, Vec3* out);

struct BakeTimings {
  double gatherSeconds = 0;   ///< summed over threads
  double clusterSeconds = 0;  ///< summed over threads
};

/// Gathers and clusters every active voxel (TBB over blocks of voxels,
/// deterministic: each voxel's K-means stream is its canonicalVoxelKey), or
/// only the voxels `subset` lists (ascending indices; the others stay unlit
/// and empty: a tile of a distributed bake). With `layers`,
/// a voxel whose own photons face clearly different ways
/// (Gatherer::findSurfaceLayers) gets one gather and one set of VDLs per
/// orientation: layer 0 in the grid's arrays, the others in
/// VdlGrid::layers (docs/accuracy.md, "Surface layers").
VdlGrid buildVdlGrid(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                     const GatherParams& gather, const ClusterParams& cluster,
                     ProgressSink* progress = nullptr, BakeTimings* timings = nullptr,
                     const LayerParams* layers = nullptr,
                     const std::vector<uint32_t>* subset = nullptr);

/// Layer-aware smoothing of the estimates (docs/accuracy.md, "Less noise"):
/// each voxel of one layer takes the weighted mean of its own irradiance and
/// that of its 26 neighbours that face the same way (normals within
/// acos(minCosine)) and lie in its plane (within planeVoxels of it along its
/// normal). Weights: a Gaussian of the distance (sigmaVoxels) times a range
/// term exp(-(dY / (rangeSigmas * noise))^2 / 2), noise = Y / sqrt(photons
/// gathered): differences the photon noise explains are smoothed, larger
/// ones (a shadow's edge) kept. The voxel's VDLs are scaled per channel to
/// the new irradiance (directions unchanged). Voxels with layers are left as
/// they are and lend nothing. Deterministic (reads the unsmoothed values).
struct SmoothParams {
  float sigmaVoxels = 1.0f;
  float rangeSigmas = 2.0f;
  float minCosine = 0.8f;
  float planeVoxels = 0.3f;
};
/// @returns the number of voxels changed.
size_t smoothVdlGrid(const SurfaceGrid& grid, VdlGrid& out, const SmoothParams& params = {});

}  // namespace lo
