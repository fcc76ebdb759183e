#pragma once
/// @file grid/surface_grid.h
/// @brief The sparse voxel grid of the scene's surfaces (paper §4.1: the octree
/// "built on the whole scene, using a geometric subdivision criterion").
///
/// The scene's bounding cube, padded, is divided into 2^depth voxels per axis;
/// a voxel is active exactly when its closed box intersects a triangle. OpenVDB
/// holds the sparse index internally; the public data are plain arrays so that
/// later stages do not compile OpenVDB headers.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "lightgrid/grid_frame.h"
#include "scene/scene.h"

namespace lo {

struct GridParams {
  int depth = 6;          ///< 2^depth voxels per axis (paper's delta)
  float padding = 0.01f;  ///< fraction of the largest extent added on each side
  /// The grid covers this box (a region of interest) instead of the scene's
  /// bounds; geometry outside it has no voxels. Empty = the scene's bounds.
  Bounds3 region;
  /// Voxelize only the voxels of the 8^3 blocks (coord >> 3) this accepts
  /// and that lie in [clipLower, clipUpper] (inclusive voxel indices): a tile
  /// of a distributed bake with its halo. Each kept voxel gets exactly what
  /// the whole grid gives it. Empty / default: every voxel.
  std::function<bool(const Coord& block)> keepBlock;
  Coord clipLower{0, 0, 0};
  Coord clipUpper{1 << 30, 1 << 30, 1 << 30};
};

/// Active voxels in canonical order: sorted by 8^3 block (OpenVDB leaf), then
/// by position inside the block, so that neighbouring voxels are close in memory.
class SurfaceGrid {
 public:
  GridFrame frame;
  std::vector<Coord> coords;     ///< active voxels
  std::vector<Vec3> normals;     ///< area-weighted mean geometric normal; unit, or zero when faces cancel
  std::vector<Vec3> centroids;   ///< area-weighted centroid of the geometry inside the voxel, world space
  std::vector<float> areas;      ///< area of the geometry clipped to the voxel, world units^2

  /// The ways the geometry inside a voxel faces, where there is more than one
  /// (an edge, a corner, a curved or folded surface): the triangles clipped
  /// to the voxel clustered by their winding normals (a triangle joins the
  /// first cluster whose running area-weighted mean lies within 60 degrees,
  /// else starts one; clusters under 2% of the voxel's area dropped; at most
  /// kMaxOrientations, the largest first). Voxel v's are
  /// orientations[orientationStart[v] .. orientationStart[v + 1]); none for a
  /// voxel of one orientation. Empty orientationStart: not computed.
  struct Orientation {
    Vec3 normal;    ///< unit, area-weighted mean of the cluster's winding normals
    Vec3 centroid;  ///< area-weighted centroid of its geometry in the voxel, world space
    float area;     ///< its clipped area, world units^2
  };
  static constexpr int kMaxOrientations = 4;
  std::vector<uint32_t> orientationStart;
  std::vector<Orientation> orientations;

  /// Photon bins (CSR), filled by the gather's splatPhotons (gather/gather.h): the photons whose position lies
  /// in voxel v are binPhotons[binStart[v] .. binStart[v+1]), in photon order.
  std::vector<uint32_t> binStart;
  std::vector<uint32_t> binPhotons;
  /// Largest distance (world units) from a binned photon to the box of the voxel
  /// whose bin holds it: 0 unless a photon was moved to a neighbouring voxel.
  /// A gather that prunes bins by their voxel box grows the box by this much.
  float binMargin = 0.0f;

  size_t size() const { return coords.size(); }
  /// Index of the active voxel at c, or -1. Thread-safe.
  int64_t find(const Coord& c) const;

  SurfaceGrid();
  ~SurfaceGrid();
  SurfaceGrid(SurfaceGrid&&) noexcept;
  SurfaceGrid& operator=(SurfaceGrid&&) noexcept;

  /// Rebuilds the internal index from `coords` (after coords changed).
  void rebuildIndex();

 private:
  struct Index;
  std::unique_ptr<Index> index_;
};

/// Voxelizes the scene: exact triangle/box overlap (separating axis test),
/// per-voxel clipped area, normal and centroid. TBB-parallel, deterministic.
SurfaceGrid buildSurfaceGrid(const Scene& scene, const GridParams& params,
                             ProgressSink* progress = nullptr);

/// Exact overlap test of a triangle and a closed axis-aligned box
/// (Akenine-Möller's separating axis theorem). Exposed for tests.
bool triangleOverlapsBox(const Vec3& a, const Vec3& b, const Vec3& c, const Bounds3& box);

}  // namespace lo
