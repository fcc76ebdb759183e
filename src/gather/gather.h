#pragma once
/// @file gather/gather.h
/// @brief KNN filtering per voxel (paper §3.1.1): the k nearest photons within
/// radius r, distances measured in an ellipsoid aligned with the voxel normal.

#include <cmath>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/math.h"
#include "grid/surface_grid.h"
#include "lightgrid/photon.h"

namespace lo {

/// Whether geometry blocks the straight segment between two points (world
/// space). The bake answers it with the scene's ray tracer (src/photon); the
/// gather uses it to leave out photons behind a wall.
using SegmentBlocked = std::function<bool(const Vec3& from, const Vec3& to)>;

/// Whether a surface facing within 60 degrees of n (either way) crosses the
/// segment from p - n h to p + n h: the edge correction's look at the
/// scene itself, where the grid only knows which voxels hold such geometry.
using SurfaceProbe = std::function<bool(const Vec3& p, const Vec3& n, float h)>;

struct GatherParams {
  int k = 300;  ///< nearest neighbours (paper: 300)
  /// Gathering radius in world units; 0 = kDefaultRadiusVoxels * voxel size.
  float radius = 0.0f;
  /// Ellipsoid axis ratio: a photon's offset along the voxel normal counts
  /// `normalSquash` times its length, so photons on a perpendicular wall or
  /// behind a thin wall fall outside the search region.
  float normalSquash = 4.0f;
  /// Photons of a surface layer (Gatherer::gatherLayer) face within this
  /// cosine of the layer's normal: 0.5 = 60 degrees, so the faces of a box
  /// edge (90 degrees) and the two sides of a thin wall stay apart.
  float layerCosine = 0.5f;
  /// Set: photon bins (per group of photons sharing a normal) that a
  /// segment from the query point to them crosses geometry are left out: no
  /// light is gathered through a thin wall. Both ends are lifted off their
  /// surfaces by occlusionLift voxels along their normals, so that a
  /// segment along a plane does not graze it.
  SegmentBlocked blocked;
  float occlusionLift = 0.6f;
  /// Edge correction: divide the photons' power by the part of the disc
  /// pi r_k^2 that lies on the surface (surfaceCoverage in gather.cpp), not
  /// the whole disc: next to an edge, where the disc reaches past the
  /// surface, the plain estimate is too dark by up to half.
  bool edgeCorrection = true;
  /// Set: the edge correction asks the scene (a ray along the normal through
  /// each of its disc points, as long as the gather's ellipsoid is thick
  /// there) whether surface lies there; unset: whether the point's voxel
  /// holds such geometry (a railing or a stair's edge in a voxel counts its
  /// whole voxel as floor: the estimate divides by too much and is dark).
  SurfaceProbe surfaceAt;
  /// Caustics apart (the classic caustic map): photons that reached their
  /// surface through mirrors and glass alone (Photon::caustic) are not
  /// gathered with the smooth light but by Gatherer::gatherCaustics, within
  /// causticRadius, so that a caustic stays sharp and its few bright photons
  /// do not blot the smooth light around it.
  bool separateCaustics = true;
  /// The caustic gather's radius, world units; 0 = kDefaultCausticRadiusVoxels voxel sizes.
  float causticRadius = 0.0f;
};

/// Default caustic gather radius in voxels: a caustic is kept to about its
/// own voxel, where the smooth light's 1.5-voxel disc spreads it over three.
constexpr float kDefaultCausticRadiusVoxels = 0.75f;

/// One surface of a voxel facing one way (Gatherer::findSurfaceLayers).
struct SurfaceLayer {
  Vec3 normal{0, 0, 0};  ///< unit, facing the side its light arrives from
  Vec3 point{0, 0, 0};   ///< a point of the surface (its centroid in the voxel), world space
  double weight = 0;     ///< summed average(power) of the voxel's photons on that side
  uint32_t photons = 0;
  /// Where the layer's light landed: the power-weighted mean position of
  /// the voxel's own photons facing its way (`point` when none did). What
  /// the renderer's side test measures (VdlGrid::points): a floor cut by a
  /// thin wall and lit on one side has its light on that side, wherever
  /// the floor's centroid in the voxel falls.
  Vec3 lit{0, 0, 0};
};

/// Criteria of findSurfaceLayers.
struct LayerParams {
  int maxLayers = 3;          ///< at most this many (kMaxLayers)
  float splitCosine = 0.5f;   ///< a photon is on a surface's side within this cosine (60 deg)
  float minShare = 0.1f;      ///< a lit side holds at least this share of the voxel's photon weight
  uint32_t minPhotons = 4;    ///< and at least this many photons
  /// A surface of the voxel other than its largest whose clipped area is
  /// below this share of a voxel face (voxel size^2), and on neither side
  /// of which light landed (minShare, minPhotons), is no layer: a step's
  /// few-centimetre riser or a tile's edge would otherwise split its voxel
  /// with its plane, and the floor beyond it, on the far side of that plane
  /// from where the floor's photons landed, would find no layer at all.
  float minArea = 0.1f;
};

/// Fills grid.binStart / grid.binPhotons / grid.binMargin: the photons whose
/// position lies in each active voxel, in photon order. Photons outside any
/// active voxel are put in the nearest active voxel of their 3x3x3
/// neighbourhood, or dropped (counted in the return value). Deterministic.
size_t splatPhotons(SurfaceGrid& grid, const std::vector<Photon>& photons);

/// Puts `photons` in the order of the grid's bins (those splatPhotons just
/// filled from them; the dropped ones after them, in their order) and makes
/// grid.binPhotons the identity, so that the gather reads the array itself
/// front to back instead of a copy (binPhotonsForGather). Bins keep their
/// photons' order. In place, with one bit per photon besides. Deterministic.
void sortPhotonsByBin(SurfaceGrid& grid, std::vector<Photon>& photons);

/// Default radius in voxels. Chosen from the measured sweeps (docs/accuracy.md):
/// at the paper's settings (600k photons, depth 6, k = 300) a 1.5-voxel radius
/// was both faster to bake and more accurate than 3 voxels on all three test
/// scenes (irradiance rel. RMSE 10.7 / 11.8 / 14.3% against 11.6 / 13.5 /
/// 16.8%): on a plane it holds ~160 photons there, so the estimate is mostly
/// a fixed-radius one and blurs less across edges and corners.
constexpr float kDefaultRadiusVoxels = 1.5f;

float resolveRadius(const GatherParams& params, const GridFrame& frame);

/// How far (world units) from its query point a gather reads photons: the
/// radius along the ellipsoid's widest axis. It reads the bins of the voxels
/// within that distance grown by SurfaceGrid::binMargin, which is at most
/// kMaxBinMarginVoxels voxel sizes: what a tile of a distributed bake must
/// hold around its voxels (src/distributed).
double gatherReach(const GatherParams& params, const GridFrame& frame);
/// splatPhotons moves a photon only to a voxel of its 3x3x3 neighbourhood,
/// so at most a voxel's diagonal from that voxel's box: sqrt(3) voxel sizes.
constexpr double kMaxBinMarginVoxels = 1.7320508075688772;

struct GatherResult {
  std::vector<uint32_t> photons;  ///< indices of the gathered photons (<= k), in no particular (but
                                  ///< deterministic) order
  float radius =
      0.0f;  ///< r_k: distance (ellipsoid metric) of the k-th photon, or r if fewer found
  Vec3 normal{0, 0, 0};      ///< voxel normal oriented towards the side the light arrives from
  Vec3 irradiance{0, 0, 0};  ///< sum(power) / (pi r_k^2 coverage), W/m^2
  /// The gathered photons' Photon::reflectance, weighted per channel by
  /// their power: the share of `irradiance` the surface reflects (0 without
  /// photons).
  Vec3 reflectance{0, 0, 0};
  /// Share of the disc pi r_k^2 on the surface (GatherParams::edgeCorrection), else 1.
  float coverage = 1.0f;
  /// The estimate's relative standard error, sqrt(sum y_i^2) / sum y_i over
  /// the gathered photons' luminances y_i: photons arriving as a Poisson
  /// process whose powers vary (1/sqrt(n) for equal powers). 0 without
  /// photons. What it leaves out: the blur of the disc (bias) and the
  /// correlation of photons from one path.
  float noise = 0.0f;
};

/// GatherResult::noise of photon luminances summed as `sum` and their squares as `sumSquares`.
inline float relativeNoise(double sum, double sumSquares) {
  return sum > 0 ? float(std::sqrt(sumSquares) / sum) : 0.0f;
}

/// The photons of a surface grid's bins in bin order (grid.binPhotons order:
/// bin v is slots grid.binStart[v] .. grid.binStart[v + 1]), with what the
/// gather reads beside them. The photon array itself when it is already in
/// that order (sortPhotonsByBin: no copy, which at depth 8 was a quarter of a
/// bake's peak memory), else a copy. Built once per (grid, photons) and
/// shared read-only by the gatherers of all threads; it points into both,
/// which must outlive it.
struct BinnedPhotons {
  /// Slot j's photon, and its index in the photon array.
  const Photon& photon(uint32_t j) const { return inBinOrder[j]; }
  uint32_t index(uint32_t j) const { return indices[j]; }
  /// average(power), W: the orientation vote's weight.
  static float weight(const Photon& p) { return average(p.power); }
  const Photon* inBinOrder = nullptr;
  const uint32_t* indices = nullptr;  ///< grid.binPhotons
  std::vector<Photon> copy;           ///< when the array is not in bin order
  /// Per slot: its bin's group of equal normals, kNoGroup when the bin has none.
  std::vector<uint16_t> group;
  static constexpr uint16_t kNoGroup = 0xffffu;
  size_t causticPhotons = 0;  ///< photons with caustic set
  /// Per bin (grid voxel): the bounds of its photons' positions and, when its
  /// photons carry at most kMaxGroups distinct normals, their summed weight
  /// per normal. A bin whose bounds lie wholly within the gather radius then
  /// votes per normal instead of per photon.
  static constexpr int kMaxGroups = 4;
  struct Bin {
    Vec3 lower{0, 0, 0}, upper{0, 0, 0};
    int groups = 0;  ///< 0: vote per photon
    Vec3 normal[kMaxGroups];
    double weight[kMaxGroups] = {0, 0, 0, 0};
    /// Mean photon position per group (groups > 0), else of the whole bin
    /// (point[0]), and for a bin without groups its mean photon normal
    /// (unnormalised): where GatherParams::blocked aims.
    Vec3 point[kMaxGroups];
    Vec3 normalSum{0, 0, 0};
  };
  std::vector<Bin> bins;
};

/// @throws InputError if splatPhotons has not filled the grid's bins.
std::shared_ptr<const BinnedPhotons> binPhotonsForGather(const SurfaceGrid& grid,
                                                         const std::vector<Photon>& photons);

/// Grid-coherent gatherer: candidates come from the photon bins of the voxels
/// within the radius, so no kd-tree is built. One per thread (holds scratch).
/// See docs/grid-and-gather.md for the two passes (orientation vote over the
/// radius, then nearest bins first until the k-th distance is bounded).
class Gatherer {
 public:
  /// Builds its own BinnedPhotons (one thread, or tests).
  Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons, const GatherParams& params);
  /// Shares `binned` (from binPhotonsForGather on the same grid and photons).
  Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons,
           std::shared_ptr<const BinnedPhotons> binned, const GatherParams& params);
  void gather(size_t voxel, GatherResult& out);
  /// One surface layer of `voxel` (findSurfaceLayers): the k nearest photons
  /// to `point` whose normals lie within GatherParams::layerCosine of
  /// `normal` (unit, already oriented: no vote), in the ellipsoid along it.
  void gatherLayer(size_t voxel, const Vec3& point, const Vec3& normal, GatherResult& out);
  /// The caustic photons (Photon::caustic) near `point` on the side of
  /// `normal` (unit, oriented: the smooth gather's), within the caustic
  /// radius: what separateCaustics leaves out of gather and gatherLayer.
  /// Empty (irradiance 0) when the map holds no caustic photon.
  void gatherCaustics(size_t voxel, const Vec3& point, const Vec3& normal, GatherResult& out);
  /// Whether the photon map holds caustic photons to gather apart.
  bool hasCaustics() const { return params_.separateCaustics && binned_->causticPhotons > 0; }
  /// The surface layers of `voxel`: its geometric orientations
  /// (SurfaceGrid::orientations, the largest first), else its one normal,
  /// each facing the side its photons arrived on (the photons of the voxel's
  /// own bin within params.splitCosine of its front or back; the winding's
  /// side when none did), or two layers facing away from each other when
  /// both sides hold params.minShare of the bin's weight and
  /// params.minPhotons. At most params.maxLayers; a point of each is the
  /// orientation's centroid. Fewer than 2: the voxel needs no layers.
  int findSurfaceLayers(size_t voxel, const LayerParams& params, SurfaceLayer* out) const;

 private:
  const SurfaceGrid& grid_;
  const std::vector<Photon>& photons_;
  std::shared_ptr<const BinnedPhotons> binned_;
  GatherParams params_;
  float radius_;
  int reachVoxels_;
  /// The k nearest so far as (float bits of d^2) << 32 | photon index (one
  /// integer comparison orders by distance with ties broken by index).
  std::vector<uint64_t> keys_;

  /// Active voxels with photons near the 8^3 block of the last gathered voxel
  /// (looked up once per block with grid.find); each voxel prunes them by the
  /// distance from its query point to their box.
  struct Neighbour {
    Coord coord;
    uint32_t voxel;       ///< grid index = bin
    uint32_t begin, end;  ///< range of binned_ slots
  };
  struct Near {
    double bound2;  ///< lower bound of d^2 (world units^2) of any photon in the bin
    uint32_t neighbour;
    uint32_t blocked = 0;  ///< bit g: group g is behind geometry (bit 0 alone for a bin without groups)
    bool operator<(const Near& o) const {
      return bound2 < o.bound2 || (bound2 == o.bound2 && neighbour < o.neighbour);
    }
  };
  void updateBlock(const Coord& voxelCoord);
  /// near_ for a query point: the neighbour bins within reach.
  void findNear(const Vec3& point);
  /// Sets Near::blocked by GatherParams::blocked from `point` lifted along
  /// `normal` (skipping `ownVoxel`'s bin and groups the kept side rejects).
  void markBlocked(size_t ownVoxel, const Vec3& point, const Vec3& normal, float sideCosine);
  /// gather and gatherLayer: `fixedNormal` skips the orientation vote;
  /// photons are kept when dot(photon normal, n) > sideCosine.
  /// `caustic`: -1 every photon, 0 all but caustic ones, 1 caustic ones
  /// alone, within `radius`.
  void gatherAt(size_t voxel, const Vec3& point, const Vec3& normal, bool fixedNormal,
                float sideCosine, int caustic, float radius, GatherResult& out);
  float causticRadius_ = 0;
  Coord blockCoord_{};
  bool blockValid_ = false;
  std::vector<Neighbour> blockNeighbours_;
  std::vector<Near> near_;  ///< this voxel's neighbours within reach, nearest first
};

/// Reference: the same selection by scanning every photon, for tests
/// (without GatherParams::blocked, which works on bins).
GatherResult gatherBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                              size_t voxel, const GatherParams& params);
/// Reference of Gatherer::gatherLayer, likewise.
GatherResult gatherLayerBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                                   const Vec3& point, const Vec3& normal,
                                   const GatherParams& params);

}  // namespace lo
