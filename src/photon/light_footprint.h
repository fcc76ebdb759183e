#pragma once
/// @file photon/light_footprint.h
/// @brief Where a directional light's photons can land: the scene's shadow
/// outline seen from the light, as the cells of a grid in the plane
/// perpendicular to the light that some triangle's projection overlaps
/// (conservative rasterisation). Photons started uniformly over those cells,
/// behind the scene, hit geometry unless they start in a cell's uncovered
/// corner; started over the covered box's silhouette instead, an open
/// scene's photons pass beside a tall box's ground (docs/photon.md).

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "scene/scene.h"

namespace lo {

class LightFootprint {
 public:
  /// Cells per side of the grid over the projected bounds.
  static constexpr int kResolution = 256;

  LightFootprint() = default;
  /// The footprint along `direction` (unit, the way the light travels) of
  /// the triangles of `scene` that touch `region` (empty: every triangle),
  /// clipped to the region's own silhouette. Starts lie `margin` behind the
  /// scene's bounds.
  LightFootprint(const Scene& scene, const Vec3& direction, const Bounds3& region, float margin);

  /// Total area of the covered cells, scene units^2 (0: nothing to light).
  double area() const { return double(covered_) * double(cellSize_) * double(cellSize_); }
  bool empty() const { return covered_ == 0; }
  /// Bytes it holds: a bit a cell and a count a 64 cells, 12 KiB (a list of
  /// the covered cells took up to 256 KiB: 10,000 suns baked at 2.6 GB).
  size_t bytes() const;
  /// A start uniform over the covered cells, behind the scene; the ray from
  /// it along the direction crosses the whole scene.
  Vec3 sample(float u0, float u1, float u2) const;

 private:
  Vec3 direction_{0, 0, -1}, tangent_, bitangent_;
  Vec3 planeOrigin_;  ///< the start plane's point at 2D (0, 0)
  float minU_ = 0, minV_ = 0, cellSize_ = 1;
  /// Covered cells, a bit each at index v * kResolution + u, and how many
  /// are covered before each word: the k-th covered cell in index order is
  /// found by a binary search and a walk over one word's bits.
  std::vector<uint64_t> bits_;
  std::vector<uint32_t> coveredBefore_;
  size_t covered_ = 0;
};

}  // namespace lo
