#pragma once
/// @file lightgrid/grid_frame.h
/// @brief Index space <-> world space of the cubic voxel grid every stage
/// shares: the surface grid voxelizes in it, the light grid is stored in it,
/// the GPU octree is built on it. Plain data, no third-party library.

#include <cstdint>

#include "core/math.h"

namespace lo {

/// Index space <-> world space of a cubic grid. Voxel (i,j,k) covers the world
/// box [origin + (i,j,k) * voxelSize, origin + (i+1,j+1,k+1) * voxelSize].
/// World positions are computed in double from these float members, so that a
/// grid far from the origin maps voxels to positions without drift.
struct GridFrame {
  Vec3 origin{0, 0, 0};   ///< world position of the lower corner of voxel (0,0,0)
  float voxelSize = 1.0f; ///< world units (edge length of the cube / 2^depth)
  int depth = 0;          ///< 2^depth voxels per axis
  /// The origin of the scene's coordinates in the file's world (Scene::origin):
  /// `origin` and every position above are relative to it; the .vdb's
  /// transform adds it back (0 unless the scene was rebased).
  Vec3d offset;

  int resolution() const { return 1 << depth; }
  Vec3 voxelCenter(const Coord& c) const;
  Bounds3 voxelBounds(const Coord& c) const;
  /// Voxel containing world point p (may lie outside [0, resolution)); points
  /// beyond +-1e9 voxels, and NaN, are clamped to +-1e9.
  Coord coordOf(const Vec3& p) const;
  std::string ToString() const;
};

/// The canonical order of a grid's voxels, as an integer: the 8^3 block
/// (OpenVDB leaf, coord >> 3) in x-major order, then the voxel's offset in the
/// block, (x&7)<<6 | (y&7)<<3 | (z&7). Every voxel array of the bake (the
/// surface grid, the light grid) is sorted by it; it also names a voxel
/// independently of which other voxels exist (the K-means streams, the
/// merge of a distributed bake's tiles). Coordinates must lie in
/// [0, 2^kMaxGridDepth): blocks take 9 bits per axis, 36 bits in all.
inline uint64_t canonicalVoxelKey(const Coord& c) {
  const uint64_t bx = uint64_t(c.x >> 3), by = uint64_t(c.y >> 3), bz = uint64_t(c.z >> 3);
  const uint64_t offset = uint64_t(((c.x & 7) << 6) | ((c.y & 7) << 3) | (c.z & 7));
  return (((bx << 9 | by) << 9 | bz) << 9) | offset;
}
/// Bits of canonicalVoxelKey.
constexpr int kCanonicalKeyBits = 36;

/// Deepest grid the project builds (2^12 = 4096 voxels per axis: the 24-bit
/// addresses of the GPU octree and int32 coordinates both hold it).
constexpr int kMaxGridDepth = 12;

/// The padded bounding cube of `sceneBounds` (edge = largest extent * (1 + 2 * padding),
/// centred on the scene) divided into 2^depth voxels per axis. The origin does
/// not depend on the depth, so frames of one scene at two depths nest.
/// @throws InputError if depth is outside [1, kMaxGridDepth] or the bounds are
/// empty/degenerate.
GridFrame makeGridFrame(const Bounds3& sceneBounds, int depth, float padding = 0.01f);

}  // namespace lo
