// Voxelization of the scene's triangles into the sparse surface grid (paper
// §4.1: the octree "built on the whole scene, using a geometric subdivision
// criterion") and the photon bins the KNN gather reads (§3.1.1).
//
// Precision: the frame is stored in float (it is part of the output), but every
// index computation and every triangle/voxel test is done in double, with the
// triangle translated to the voxel's centre first, so that a scene far from the
// origin or a few micrometres across voxelizes like the same scene at unit scale.

#include "grid/surface_grid.h"

#include <openvdb/openvdb.h>
#include <openvdb/tree/ValueAccessor.h>
#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "core/error.h"

namespace lo {

namespace surface_grid_internal {

using D3 = Vec3d;  // core/math.h

/// Separating axis test (Akenine-Möller 2001) of the triangle v[0..2], given
/// relative to the box centre, against the closed box [-h, h]. An axis
/// separates only with a strict gap, so touching counts as overlap. Degenerate
/// triangles need no special case: for a segment or a point the zero axes
/// (normal, cross products with a zero edge) never separate, and the remaining
/// axes are the face normals of the Minkowski sum of the segment/point and the
/// box, so the test stays exact.
bool overlapsCentered(const D3 v[3], const D3& h) {
  for (int i = 0; i < 3; ++i) {
    double lo = std::min({v[0][i], v[1][i], v[2][i]});
    double hi = std::max({v[0][i], v[1][i], v[2][i]});
    if (lo > h[i] || hi < -h[i]) return false;
  }
  const D3 e[3] = {v[1] - v[0], v[2] - v[1], v[0] - v[2]};
  const D3 n = cross(e[0], e[1]);
  const double rn = h.x * std::abs(n.x) + h.y * std::abs(n.y) + h.z * std::abs(n.z);
  if (std::abs(dot(n, v[0])) > rn) return false;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      D3 unit(0, 0, 0);
      unit[j] = 1;
      const D3 a = cross(unit, e[i]);
      const double p0 = dot(a, v[0]), p1 = dot(a, v[1]), p2 = dot(a, v[2]);
      const double r = h.x * std::abs(a.x) + h.y * std::abs(a.y) + h.z * std::abs(a.z);
      if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r) return false;
    }
  }
  return true;
}

/// Convex polygon, at most 3 + 6 vertices after clipping a triangle by a box.
struct Polygon {
  std::array<D3, 12> p;
  int n = 0;
};

/// Sutherland-Hodgman clip of `in` against the closed half-space
/// sign * x[axis] <= bound. Points exactly on the plane are kept, so a triangle
/// lying in a box face keeps its (zero-thickness) polygon.
void clipPlane(const Polygon& in, int axis, double sign, double bound, Polygon& out) {
  out.n = 0;
  if (in.n == 0) return;
  for (int i = 0; i < in.n; ++i) {
    const D3& a = in.p[size_t(i)];
    const D3& b = in.p[size_t((i + 1) % in.n)];
    const double da = sign * a[axis] - bound, db = sign * b[axis] - bound;
    if (da <= 0) out.p[size_t(out.n++)] = a;
    if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
      const double t = da / (da - db);
      D3 x = a + (b - a) * t;
      x[axis] = sign * bound;  // exactly on the plane
      out.p[size_t(out.n++)] = x;
    }
  }
}

/// Clips the triangle (relative to the box centre) to [-h, h] and returns the
/// clipped area and area-weighted centroid (relative to the box centre).
double clippedArea(const D3 v[3], const D3& h, D3& areaCentroid) {
  Polygon a, b;
  a.n = 3;
  a.p[0] = v[0];
  a.p[1] = v[1];
  a.p[2] = v[2];
  for (int axis = 0; axis < 3; ++axis) {
    clipPlane(a, axis, 1.0, h[axis], b);
    clipPlane(b, axis, -1.0, h[axis], a);
  }
  areaCentroid = D3(0, 0, 0);
  double area = 0;
  for (int i = 1; i + 1 < a.n; ++i) {
    const D3& p0 = a.p[0];
    const D3& p1 = a.p[size_t(i)];
    const D3& p2 = a.p[size_t(i + 1)];
    const double t = 0.5 * length(cross(p1 - p0, p2 - p0));
    area += t;
    areaCentroid += (p0 + p1 + p2) * (t / 3.0);
  }
  return area;
}

inline Coord coordFromKey(uint64_t key) {
  const int offset = int(key & 511);
  const int bz = int((key >> 9) & 511), by = int((key >> 18) & 511), bx = int((key >> 27) & 511);
  return {bx << 3 | (offset >> 6), by << 3 | ((offset >> 3) & 7), bz << 3 | (offset & 7)};
}

/// One triangle's share of one voxel.
struct Contribution {
  uint64_t key;  ///< canonicalVoxelKey of the voxel
  uint32_t triangle;
  double area;  ///< clipped area, world units^2
  D3 centroid;  ///< area * clipped centroid, or (area 0) the voxel-clamped triangle centroid;
                ///< relative to the voxel centre
  bool operator<(const Contribution& o) const {
    return key != o.key ? key < o.key : triangle < o.triangle;
  }
};

inline D3 unitFaceNormal(const D3 v[3]) {
  const D3 n = cross(v[1] - v[0], v[2] - v[0]);
  const double l = length(n);
  return l > 0 ? n * (1.0 / l) : D3(0, 0, 0);
}

/// Frame constants in double, used by every index computation.
struct FrameD {
  D3 origin;
  double voxelSize;
  int resolution;
  explicit FrameD(const GridFrame& f)
      : origin(f.origin), voxelSize(f.voxelSize), resolution(f.resolution()) {}
  D3 center(const Coord& c) const {
    return {origin.x + (c.x + 0.5) * voxelSize, origin.y + (c.y + 0.5) * voxelSize,
            origin.z + (c.z + 0.5) * voxelSize};
  }
};

inline int32_t clampedFloor(double t) {
  // Keeps far-away or non-finite points representable as int32 coordinates.
  if (!(t > -1e9)) return -1000000000;
  if (t > 1e9) return 1000000000;
  return int32_t(std::floor(t));
}

struct VoxelizeBody {
  const Scene& scene;
  const FrameD& frame;
  const GridParams& params;
  tbb::enumerable_thread_specific<std::vector<Contribution>>& out;
  Progress& progress;

  void operator()(const tbb::blocked_range<size_t>& range) const {
    std::vector<Contribution>& local = out.local();
    const double vs = frame.voxelSize;
    const D3 h(0.5 * vs, 0.5 * vs, 0.5 * vs);
    // Index-space slack so that a vertex exactly on a voxel face (or a rounding
    // error away from it) tests both voxels; the exact test then decides.
    constexpr double kSlack = 1e-6;
    const int clipLo[3] = {params.clipLower.x, params.clipLower.y, params.clipLower.z};
    const int clipHi[3] = {params.clipUpper.x, params.clipUpper.y, params.clipUpper.z};
    for (size_t t = range.begin(); t != range.end(); ++t) {
      D3 w[3];
      for (int i = 0; i < 3; ++i) w[i] = D3(scene.positions[scene.indices[3 * t + size_t(i)]]);
      int lo[3], hi[3];
      bool outside = false;
      for (int a = 0; a < 3; ++a) {
        const double mn = std::min({w[0][a], w[1][a], w[2][a]});
        const double mx = std::max({w[0][a], w[1][a], w[2][a]});
        lo[a] = std::max({0, clampedFloor((mn - frame.origin[a]) / vs - kSlack),
                          clipLo[a]});
        hi[a] = std::min({frame.resolution - 1, clampedFloor((mx - frame.origin[a]) / vs + kSlack),
                          clipHi[a]});
        outside |= lo[a] > hi[a];
      }
      if (outside) continue;
      const D3 triCentroid = (w[0] + w[1] + w[2]) * (1.0 / 3.0);
      for (int x = lo[0]; x <= hi[0]; ++x) {
        for (int y = lo[1]; y <= hi[1]; ++y) {
          for (int z = lo[2]; z <= hi[2]; ++z) {
            const Coord c{x, y, z};
            if (params.keepBlock && !params.keepBlock(Coord{x >> 3, y >> 3, z >> 3})) continue;
            const D3 center = frame.center(c);
            const D3 v[3] = {w[0] - center, w[1] - center, w[2] - center};
            if (!overlapsCentered(v, h)) continue;
            Contribution k;
            k.key = canonicalVoxelKey(c);
            k.triangle = uint32_t(t);
            k.area = clippedArea(v, h, k.centroid);
            if (!(k.area > 0)) {
              k.area = 0;
              const D3 rel = triCentroid - center;
              k.centroid = D3(std::clamp(rel.x, -h.x, h.x), std::clamp(rel.y, -h.y, h.y),
                              std::clamp(rel.z, -h.z, h.z));
            }
            local.push_back(k);
          }
        }
      }
    }
    progress.advance(range.size());
  }
};

}  // namespace surface_grid_internal


// ---------------------------------------------------------------------------
// SurfaceGrid

struct SurfaceGrid::Index {
  openvdb::Int32Tree tree{-1};
};

SurfaceGrid::SurfaceGrid() : index_(std::make_unique<Index>()) {}
SurfaceGrid::~SurfaceGrid() = default;
SurfaceGrid::SurfaceGrid(SurfaceGrid&&) noexcept = default;
SurfaceGrid& SurfaceGrid::operator=(SurfaceGrid&&) noexcept = default;

int64_t SurfaceGrid::find(const Coord& c) const {
  if (!index_) return -1;
  // Tree::getValue walks from the root without caching, so concurrent const
  // calls are safe. Measured against a per-call ValueAccessor: the same cost
  // (a fresh accessor has nothing cached either).
  return index_->tree.getValue(openvdb::Coord(c.x, c.y, c.z));
}

void SurfaceGrid::rebuildIndex() {
  if (!index_) index_ = std::make_unique<Index>();
  index_->tree.clear();
  LO_CHECK_LE(coords.size(), size_t(std::numeric_limits<int32_t>::max()));
  openvdb::tree::ValueAccessor<openvdb::Int32Tree> acc(index_->tree);
  for (size_t i = 0; i < coords.size(); ++i) {
    acc.setValueOn(openvdb::Coord(coords[i].x, coords[i].y, coords[i].z), int32_t(i));
  }
}

bool triangleOverlapsBox(const Vec3& a, const Vec3& b, const Vec3& c, const Bounds3& box) {
  using namespace surface_grid_internal;
  if (box.empty()) return false;
  const D3 lo(box.lower), hi(box.upper);
  const D3 center = (lo + hi) * 0.5;
  const D3 h = (hi - lo) * 0.5;
  const D3 v[3] = {D3(a) - center, D3(b) - center, D3(c) - center};
  return overlapsCentered(v, h);
}

SurfaceGrid buildSurfaceGrid(const Scene& scene, const GridParams& params, ProgressSink* progress) {
  using namespace surface_grid_internal;
  const size_t triangles = scene.triangleCount();
  checkSceneIndices(scene);

  SurfaceGrid grid;
  grid.frame = makeGridFrame(params.region.empty() ? scene.bounds() : params.region, params.depth,
                             params.padding);
  grid.frame.offset = scene.origin;  // the grid in the scene's (rebased) coordinates
  const FrameD frame(grid.frame);

  tbb::enumerable_thread_specific<std::vector<Contribution>> perThread;
  {
    Progress bar(progress, "voxelize", triangles);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles, 256),
                      VoxelizeBody{scene, frame, params, perThread, bar});
  }
  std::vector<Contribution> all;
  {
    size_t total = 0;
    for (const auto& v : perThread) total += v.size();
    all.reserve(total);
    for (auto& v : perThread) {
      all.insert(all.end(), v.begin(), v.end());
      std::vector<Contribution>().swap(v);
    }
  }
  // (voxel, triangle) pairs are unique, so the sorted order - and with it every
  // sum below - does not depend on how the triangles were split among threads.
  tbb::parallel_sort(all.begin(), all.end());

  std::vector<D3> faceNormals(triangles);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, triangles, 1024),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t t = r.begin(); t != r.end(); ++t) {
                        D3 w[3];
                        for (int i = 0; i < 3; ++i) {
                          w[i] = D3(scene.positions[scene.indices[3 * t + size_t(i)]]);
                        }
                        faceNormals[t] = unitFaceNormal(w);
                      }
                    });

  grid.orientationStart.push_back(0);
  constexpr int kMaxClusters = 16;
  struct Cluster {
    D3 normal{0, 0, 0}, centroid{0, 0, 0};
    double area = 0;
  };
  Cluster clusters[kMaxClusters];
  for (size_t i = 0; i < all.size();) {
    size_t j = i;
    double area = 0;
    D3 normal(0, 0, 0), areaCentroid(0, 0, 0), zeroCentroid(0, 0, 0);
    int clusterCount = 0;
    for (; j < all.size() && all[j].key == all[i].key; ++j) {
      const Contribution& k = all[j];
      area += k.area;
      normal += faceNormals[k.triangle] * k.area;
      if (k.area > 0) {
        areaCentroid += k.centroid;
        // Orientation clusters (in (voxel, triangle) order: deterministic).
        const D3& fn = faceNormals[k.triangle];
        int m = 0;
        for (; m < clusterCount; ++m) {
          const double l = length(clusters[m].normal);
          if (l > 0 && dot(clusters[m].normal, fn) > 0.5 * l) break;
        }
        if (m == clusterCount && clusterCount < kMaxClusters) clusters[clusterCount++] = Cluster{};
        if (m < clusterCount) {
          clusters[m].normal += fn * k.area;
          clusters[m].centroid += k.centroid;
          clusters[m].area += k.area;
        }
      } else {
        zeroCentroid += k.centroid;
      }
    }
    const Coord c = coordFromKey(all[i].key);
    const D3 center = frame.center(c);
    {
      int order[kMaxClusters];
      int kept = 0;
      for (int m = 0; m < clusterCount; ++m) {
        if (clusters[m].area >= 0.02 * area && length(clusters[m].normal) > 1e-6 * clusters[m].area) {
          order[kept++] = m;
        }
      }
      std::stable_sort(order, order + kept,
                       [&](int a, int b) { return clusters[a].area > clusters[b].area; });
      kept = std::min(kept, SurfaceGrid::kMaxOrientations);
      if (kept >= 2) {
        for (int o = 0; o < kept; ++o) {
          const Cluster& k = clusters[order[o]];
          grid.orientations.push_back({(k.normal * (1.0 / length(k.normal))).toVec3(),
                                       (center + k.centroid * (1.0 / k.area)).toVec3(),
                                       float(k.area)});
        }
      }
      grid.orientationStart.push_back(uint32_t(grid.orientations.size()));
    }
    grid.coords.push_back(c);
    grid.areas.push_back(float(area));
    // Opposite faces in one voxel (both sides of a thin wall, or coincident
    // triangles of opposite winding) cancel; their sum is then rounding noise,
    // so anything below 1e-6 of the area counts as zero.
    const double nl = length(normal);
    grid.normals.push_back(nl > 1e-6 * area ? (normal * (1.0 / nl)).toVec3() : Vec3{});
    const D3 rel = area > 0 ? areaCentroid * (1.0 / area) : zeroCentroid * (1.0 / double(j - i));
    grid.centroids.push_back((center + rel).toVec3());
    i = j;
  }
  grid.rebuildIndex();
  return grid;
}


}  // namespace lo
