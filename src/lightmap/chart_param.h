#pragma once
/// @file lightmap/chart_param.h
/// @brief Internal to src/lightmap (not part of the stage's API): the scene's
/// edge topology, charts grown over it, and each chart flattened to 2D
/// (projection or LSCM) at world scale. lightmap_uv.cpp packs the results.
///
/// All geometry here is in double precision: the scene's float positions
/// converted once, so that welding (exact float equality) and the flattening's
/// checks do not depend on the order of float operations.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "scene/scene.h"

namespace lo::lightmap_internal {

/// The flattening's arithmetic is in double (core/math.h).
using D3 = Vec3d;

/// Per-triangle geometry: unit normal (from the winding), area, and whether
/// the triangle is degenerate. Degenerate = zero area, or a height (twice the
/// area over the longest edge) at most kDegenerateHeight times the largest
/// coordinate magnitude of the scene: a few float ulps of its own positions,
/// where the normal and any flattening are rounding noise.
struct TriangleGeometry {
  std::vector<D3> normal;  ///< zero for degenerate triangles
  std::vector<double> area;
  std::vector<uint8_t> degenerate;
};
constexpr double kDegenerateHeight = 1e-6;
TriangleGeometry triangleGeometry(const Scene& scene);

/// The scene as a surface: triangles that share an edge. The scene is a
/// triangle soup that may duplicate vertices at material or UV seams, so
/// vertices are welded by exact position first. Two triangles are neighbours
/// across an edge when exactly two non-degenerate triangles use it and they
/// run it in opposite directions (consistently oriented, manifold); any other
/// edge is a seam.
struct ChartTopology {
  TriangleGeometry geometry;
  std::vector<int32_t> weld;       ///< per scene vertex: the id of its position
  std::vector<int32_t> neighbour;  ///< 3 per triangle: across edge (corner k, k+1); -1 = seam
  std::vector<int32_t> seedOrder;  ///< non-degenerate triangles, largest area first, ties by index
  std::vector<int32_t> seedRank;   ///< per triangle: its place in seedOrder; -1 if degenerate
};
ChartTopology buildChartTopology(const Scene& scene);

/// One chart flattened at world scale (2D area == 3D area) and turned into its
/// minimal-area bounding rectangle [0, width] x [0, height], width >= height.
struct FlatChart {
  std::vector<int32_t> triangles;  ///< scene triangle indices
  std::vector<double> uv;          ///< 6 per triangle: corners (x, y), world units
  double width = 0, height = 0;    ///< world units
  double area = 0;                 ///< 3D area == 2D area, world units^2
  double stretch = 1;              ///< L2 stretch (Sander et al. 2001), >= 1
};

/// Squared L2 stretch of one triangle's map from 2D (p: x0 y0 x1 y1 x2 y2) to
/// 3D (q): the mean of the squared singular values of its Jacobian (Sander et
/// al. 2001, §3). A chart's stretch is sqrt(sum(L2^2 * area3D) / sum(area3D))
/// with its 2D area scaled to the 3D one. Mirrored triangles count as their
/// mirror image. The 2D triangle must have non-zero area.
double triangleStretchSquared(const D3 q[3], const double p[6]);

/// Rotates a flattened chart (x, y per vertex) into its minimal-area
/// bounding rectangle (one side along an edge of the convex hull, Freeman &
/// Shapira 1975) [0, width] x [0, height], width >= height; rotations keep
/// the orientation. The rectangle is found by rotating calipers: O(hull)
/// point projections, added to `projections` when given (each hull point
/// projected for each hull edge was hull^2: hours for a chart outlined by
/// 10^6 vertices).
void orientChart(std::vector<double>& xy, double& width, double& height,
                 size_t* projections = nullptr);

/// Grows, flattens and (where needed) splits charts. Holds scratch arrays the
/// size of the scene; not thread-safe.
class ChartFlattener {
 public:
  ChartFlattener(const Scene& scene, const ChartTopology& topology, double maxStretch);

  /// Charts over all non-degenerate triangles: region growing with the given
  /// cone (degrees), each flattened; splits come out in place of their parent.
  std::vector<FlatChart> run(double coneDegrees);

  /// Cuts a chart in two along the principal axis of its triangle centroids
  /// (for a chart larger than a page) and flattens the pieces (each connected
  /// piece is a chart). The chart must hold at least two triangles.
  std::vector<FlatChart> splitInHalves(const std::vector<int32_t>& triangles, double coneDegrees);

 private:
  struct LocalMesh;
  std::vector<std::vector<int32_t>> grow(const std::vector<int32_t>& faces, double cosCone);
  void absorbSingles(std::vector<std::vector<int32_t>>& charts, double cosCone) const;
  void flatten(const std::vector<int32_t>& faces, double coneDegrees, std::vector<FlatChart>& out);
  void split(const std::vector<int32_t>& faces, double coneDegrees, std::vector<FlatChart>& out);
  std::vector<std::vector<int32_t>> principalHalves(const std::vector<int32_t>& faces);
  void buildLocalMesh(const std::vector<int32_t>& faces, LocalMesh& mesh);
  void sortBySeedRank(std::vector<int32_t>& faces) const;
  int32_t newStamp();

  const Scene& scene_;
  const ChartTopology& topo_;
  double maxStretch_;
  std::vector<int32_t> member_;    ///< stamp: triangle belongs to the current face set
  std::vector<int32_t> assigned_;  ///< stamp: triangle already taken by a grown chart
  std::vector<int32_t> local_;     ///< triangle -> its index in the current face set
  int32_t stamp_ = 0;
};

}  // namespace lo::lightmap_internal
