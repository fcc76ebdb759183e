#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include "test_util.h"
#include "core/error.h"
#include "core/rng.h"
#include "grid/surface_grid.h"

namespace lo {
namespace {

// ---------------------------------------------------------------------------
// Exact reference for triangle/box overlap: clip the triangle polygon by the
// six closed half-spaces of the box (Sutherland-Hodgman, double precision);
// the closed sets intersect iff something survives.

using P3 = std::array<double, 3>;

std::vector<P3> clipByBox(std::vector<P3> poly, const P3& lo, const P3& hi) {
  for (int axis = 0; axis < 3; ++axis) {
    for (int side = 0; side < 2; ++side) {
      const double sign = side == 0 ? 1.0 : -1.0;
      const double bound = side == 0 ? hi[size_t(axis)] : -lo[size_t(axis)];
      std::vector<P3> out;
      for (size_t i = 0; i < poly.size(); ++i) {
        const P3& a = poly[i];
        const P3& b = poly[(i + 1) % poly.size()];
        const double da = sign * a[size_t(axis)] - bound, db = sign * b[size_t(axis)] - bound;
        if (da <= 0) out.push_back(a);
        if ((da < 0 && db > 0) || (da > 0 && db < 0)) {
          const double t = da / (da - db);
          P3 x;
          for (size_t c = 0; c < 3; ++c) x[c] = a[c] + t * (b[c] - a[c]);
          out.push_back(x);
        }
      }
      poly = out;
    }
  }
  return poly;
}

bool referenceOverlap(const Vec3& a, const Vec3& b, const Vec3& c, const P3& lo, const P3& hi) {
  std::vector<P3> poly = {P3{a.x, a.y, a.z}, P3{b.x, b.y, b.z}, P3{c.x, c.y, c.z}};
  return !clipByBox(poly, lo, hi).empty();
}

Bounds3 unitBox() {
  Bounds3 b;
  b.lower = {0, 0, 0};
  b.upper = {1, 1, 1};
  return b;
}

TEST(TriangleBox, HandMadeCases) {
  const Bounds3 box = unitBox();
  auto ov = [&](Vec3 a, Vec3 b, Vec3 c) { return triangleOverlapsBox(a, b, c, box); };
  // In the plane of a face, overlapping it: touching counts.
  EXPECT_TRUE(ov({-1, -1, 1}, {3, -1, 1}, {-1, 3, 1}));
  EXPECT_FALSE(ov({-1, -1, 1.0001f}, {3, -1, 1.0001f}, {-1, 3, 1.0001f}));
  // Plane x + y = 2 touches the edge x = y = 1 only.
  EXPECT_TRUE(ov({2, 0, -1}, {0, 2, -1}, {1, 1, 5}));
  EXPECT_FALSE(ov({2.001f, 0, -1}, {0, 2.001f, -1}, {1.0005f, 1.0005f, 5}));
  // Plane x + y + z = 3 touches the corner (1,1,1) only; its AABB covers the box.
  EXPECT_TRUE(ov({3, 0, 0}, {0, 3, 0}, {0, 0, 3}));
  EXPECT_FALSE(ov({3.001f, 0, 0}, {0, 3.001f, 0}, {0, 0, 3.001f}));
  // A small triangle sharing only a vertex with the box's corner.
  EXPECT_TRUE(ov({1, 1, 1}, {2, 1, 1}, {1, 2, 1.5f}));
  // A triangle containing the box's corner (0,0,0) in its interior.
  EXPECT_TRUE(ov({-1, -1, 0}, {1, -1, 0}, {0, 1, 0}));
  // The box inside a huge triangle through its centre.
  EXPECT_TRUE(ov({-100, -100, 0.5f}, {100, -100, 0.5f}, {0, 100, 0.5f}));
  // Huge triangle whose AABB contains the box but whose plane misses it.
  EXPECT_FALSE(ov({10, -5, -1.5f}, {-5, 10, -1.5f}, {-5, -5, 12}));
  // Degenerate: points.
  EXPECT_TRUE(ov({0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}, {0.5f, 0.5f, 0.5f}));
  EXPECT_TRUE(ov({1, 1, 1}, {1, 1, 1}, {1, 1, 1}));
  EXPECT_FALSE(ov({1.001f, 1, 1}, {1.001f, 1, 1}, {1.001f, 1, 1}));
  // Degenerate: segments. x + y = 2.2 in z = 0.5 misses the edge x = y = 1
  // though its AABB overlaps the box (only a cross-product axis separates).
  EXPECT_FALSE(ov({2.2f, 0, 0.5f}, {0, 2.2f, 0.5f}, {1.1f, 1.1f, 0.5f}));
  EXPECT_TRUE(ov({2, 0, 0.5f}, {0, 2, 0.5f}, {1, 1, 0.5f}));
  EXPECT_TRUE(ov({-1, 0.5f, 0.5f}, {2, 0.5f, 0.5f}, {2, 0.5f, 0.5f}));
  EXPECT_FALSE(ov({-1, 1.5f, 0.5f}, {2, 1.5f, 0.5f}, {2, 1.5f, 0.5f}));
  // An empty box overlaps nothing.
  EXPECT_FALSE(triangleOverlapsBox({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, Bounds3{}));
}

// Random triangles of all sizes (some degenerate) against boxes: the SAT agrees
// with the clipping reference; where they could differ by rounding (the
// reference flips when the box grows or shrinks by 1e-6) either answer passes.
TEST(TriangleBox, AgreesWithClippingReference) {
  size_t hits = 0, misses = 0;
  for (uint64_t i = 0; i < 200000; ++i) {
    Rng rng(3, i);
    const float scale = std::pow(10.0f, rng.uniform() * 2.0f - 1.0f);
    auto point = [&] {
      return Vec3(0.5f, 0.5f, 0.5f) +
             Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * 3.0f;
    };
    Vec3 a = point();
    Vec3 b = a + (point() - a) * scale;
    Vec3 c = a + (point() - a) * scale;
    if (i % 10 == 0) c = a + (b - a) * rng.uniform();  // collinear
    if (i % 50 == 0) b = c = a;                        // a point
    const Bounds3 box = unitBox();
    const bool sat = triangleOverlapsBox(a, b, c, box);
    const bool grown =
        referenceOverlap(a, b, c, {-1e-6, -1e-6, -1e-6}, {1 + 1e-6, 1 + 1e-6, 1 + 1e-6});
    const bool shrunk =
        referenceOverlap(a, b, c, {1e-6, 1e-6, 1e-6}, {1 - 1e-6, 1 - 1e-6, 1 - 1e-6});
    if (shrunk) {
      ASSERT_TRUE(sat) << i << " " << a.ToString() << b.ToString() << c.ToString();
    }
    if (!grown) {
      ASSERT_FALSE(sat) << i << " " << a.ToString() << b.ToString() << c.ToString();
    }
    (sat ? hits : misses) += 1;
  }
  EXPECT_GT(hits, 20000u);
  EXPECT_GT(misses, 20000u);
}

// ---------------------------------------------------------------------------
// Frame

TEST(GridFrame, MakeGridFrame) {
  Bounds3 b;
  b.lower = {-1, 2, 3};
  b.upper = {1, 2.5f, 7};
  GridFrame f = makeGridFrame(b, 5, 0.01f);
  EXPECT_EQ(f.depth, 5);
  EXPECT_EQ(f.resolution(), 32);
  EXPECT_NEAR(f.voxelSize, 4.0f * 1.02f / 32.0f, 1e-6f);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(f.origin[a], b.lower[a]);
    EXPECT_GE(f.origin[a] + 32 * f.voxelSize, b.upper[a]);
    EXPECT_NEAR(f.origin[a] + 16 * f.voxelSize, b.center()[a], 1e-5f);
  }
  const Coord c{3, 17, 31};
  EXPECT_EQ(f.coordOf(f.voxelCenter(c)), c);
  const Bounds3 vb = f.voxelBounds(c);
  EXPECT_NEAR(vb.upper.x - vb.lower.x, f.voxelSize, 1e-6f);
  EXPECT_EQ(f.coordOf(Vec3{1e30f, -1e30f, 0}).x > 1000000, true);

  EXPECT_THROW(makeGridFrame(b, 0), InputError);
  EXPECT_THROW(makeGridFrame(b, 13), InputError);
  EXPECT_THROW(makeGridFrame(Bounds3{}, 4), InputError);
  Bounds3 point;
  point.extend({1, 2, 3});
  EXPECT_THROW(makeGridFrame(point, 4), InputError);
  Bounds3 nan = b;
  nan.upper.y = NAN;
  EXPECT_THROW(makeGridFrame(nan, 4), InputError);
  EXPECT_THROW(makeGridFrame(b, 4, -0.1f), InputError);
  // Zero padding still covers the bounds after rounding to float.
  Bounds3 far;
  far.lower = {1e5f, 1e5f, 1e5f};
  far.upper = {1e5f + 0.3f, 1e5f + 0.1f, 1e5f + 0.2f};
  GridFrame g = makeGridFrame(far, 12, 0.0f);
  for (int a = 0; a < 3; ++a) {
    EXPECT_LE(double(g.origin[a]), double(far.lower[a]));
    EXPECT_GE(double(g.origin[a]) + 4096.0 * g.voxelSize, double(far.upper[a]));
  }
}

// ---------------------------------------------------------------------------
// Scenes

Scene cornellLikeBox(float scale = 1.0f, Vec3 offset = {}) {
  // Multiples of 1/64: exact in float even 1e5 away from the origin.
  Scene scene = test::boxWithTwoBlocks({{9 / 64.0f, 0, 7 / 64.0f}, {27 / 64.0f, 19 / 64.0f, 25 / 64.0f}},
                                       {{37 / 64.0f, 0, 34 / 64.0f}, {53 / 64.0f, 39 / 64.0f, 52 / 64.0f}});
  for (Vec3& p : scene.positions) p = p * scale + offset;
  return scene;
}

Scene randomScene(size_t count, uint64_t seed) {
  Scene scene = test::oneMaterialScene();
  for (size_t t = 0; t < count; ++t) {
    Rng rng(seed, t);
    const Vec3 a{rng.uniform(), rng.uniform(), rng.uniform()};
    const float s = 0.02f + 0.4f * rng.uniform();
    Vec3 b = a + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * s;
    Vec3 c = a + Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() - 0.5f) * s;
    if (t % 17 == 0) c = a + (b - a) * 0.3f;  // zero area
    for (const Vec3& p : {a, b, c}) {
      scene.indices.push_back(uint32_t(scene.positions.size()));
      scene.positions.push_back(p);
    }
    scene.triangleMaterial.push_back(0);
  }
  return scene;
}

std::set<Coord> bruteForceActive(const Scene& scene, const GridFrame& f) {
  std::set<Coord> active;
  const int n = f.resolution();
  for (int x = 0; x < n; ++x) {
    for (int y = 0; y < n; ++y) {
      for (int z = 0; z < n; ++z) {
        const Bounds3 box = f.voxelBounds({x, y, z});
        for (size_t t = 0; t < scene.triangleCount(); ++t) {
          const Vec3& a = scene.positions[scene.indices[3 * t]];
          const Vec3& b = scene.positions[scene.indices[3 * t + 1]];
          const Vec3& c = scene.positions[scene.indices[3 * t + 2]];
          if (triangleOverlapsBox(a, b, c, box)) {
            active.insert({x, y, z});
            break;
          }
        }
      }
    }
  }
  return active;
}

double totalArea(const Scene& scene) {
  double a = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) a += scene.triangleArea(t);
  return a;
}

void expectConsistent(const Scene& scene, const SurfaceGrid& grid) {
  const size_t n = grid.size();
  ASSERT_EQ(grid.normals.size(), n);
  ASSERT_EQ(grid.centroids.size(), n);
  ASSERT_EQ(grid.areas.size(), n);
  double area = 0;
  for (size_t v = 0; v < n; ++v) {
    area += grid.areas[v];
    ASSERT_GE(grid.areas[v], 0.0f);
    ASSERT_TRUE(isFinite(grid.normals[v]) && isFinite(grid.centroids[v]));
    const float nl = length(grid.normals[v]);
    ASSERT_TRUE(nl == 0 || std::abs(nl - 1) < 1e-5f) << nl;
    // The centroid lies in its (closed) voxel.
    Bounds3 b = grid.frame.voxelBounds(grid.coords[v]);
    const float eps = 1e-5f * grid.frame.voxelSize;
    for (int a = 0; a < 3; ++a) {
      ASSERT_GE(grid.centroids[v][a], b.lower[a] - eps);
      ASSERT_LE(grid.centroids[v][a], b.upper[a] + eps);
    }
    ASSERT_EQ(grid.find(grid.coords[v]), int64_t(v));
    if (v > 0) {  // canonical order: by 8^3 block, then offset in the block
      const Coord p = grid.coords[v - 1], c = grid.coords[v];
      const Coord pb{p.x >> 3, p.y >> 3, p.z >> 3}, cb{c.x >> 3, c.y >> 3, c.z >> 3};
      if (pb == cb) {
        ASSERT_LT(((p.x & 7) << 6) | ((p.y & 7) << 3) | (p.z & 7),
                  ((c.x & 7) << 6) | ((c.y & 7) << 3) | (c.z & 7));
      } else {
        ASSERT_LT(pb, cb);
      }
    }
  }
  EXPECT_NEAR(area, totalArea(scene), 1e-4 * totalArea(scene));
}

/// A grid and the active set a scan of every voxel gives.
struct CheckedGrid {
  SurfaceGrid grid;
  std::set<Coord> expected;
};

/// The grid of `scene` at `depth`, checked: its active voxels are the brute
/// force's, and it is consistent.
CheckedGrid checkedGrid(const Scene& scene, int depth) {
  GridParams p;
  p.depth = depth;
  CheckedGrid c{buildSurfaceGrid(scene, p), {}};
  c.expected = bruteForceActive(scene, c.grid.frame);
  std::set<Coord> got(c.grid.coords.begin(), c.grid.coords.end());
  EXPECT_TRUE(got == c.expected) << got.size() << " vs " << c.expected.size();
  expectConsistent(scene, c.grid);
  return c;
}

TEST(SurfaceGrid, ActiveSetEqualsBruteForceOnRandomTriangles) {
  Scene scene = randomScene(40, 5);
  for (int depth : {4, 5}) {
    SCOPED_TRACE(depth);
    const SurfaceGrid grid = checkedGrid(scene, depth).grid;
    EXPECT_EQ(std::set<Coord>(grid.coords.begin(), grid.coords.end()).size(), grid.size());
  }
}

TEST(SurfaceGrid, ActiveSetEqualsBruteForceInCornellLikeBox) {
  Scene scene = cornellLikeBox();
  for (int depth : {4, 5}) {
    SCOPED_TRACE(depth);
    const CheckedGrid checked = checkedGrid(scene, depth);
    const SurfaceGrid& grid = checked.grid;
    const std::set<Coord>& expected = checked.expected;
    // find(): -1 for every inactive voxel and outside the grid.
    const int n = grid.frame.resolution();
    for (int x = -1; x <= n; ++x) {
      for (int y = -1; y <= n; ++y) {
        for (int z = -1; z <= n; ++z) {
          const int64_t v = grid.find({x, y, z});
          if (expected.count({x, y, z})) {
            ASSERT_GE(v, 0);
            ASSERT_EQ(grid.coords[size_t(v)], (Coord{x, y, z}));
          } else {
            ASSERT_EQ(v, -1);
          }
        }
      }
    }
  }
}

// An axis-aligned plane: every voxel's normal is exactly the plane's; clipped
// areas add up to the plane's area, and the area-weighted centroids to its
// centre (first moment).
TEST(SurfaceGrid, AxisAlignedPlaneNormalsAndMoments) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {0.1f, 0.37f, 0.2f}, {0.8f, 0, 0}, {0, 0, 0.7f}, {0, -1, 0}, 0);
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);  // gives the frame depth
  GridParams p;
  p.depth = 5;
  SurfaceGrid grid = buildSurfaceGrid(scene, p);
  double area = 0, mx = 0, mz = 0;
  size_t planeVoxels = 0;
  for (size_t v = 0; v < grid.size(); ++v) {
    const Bounds3 b = grid.frame.voxelBounds(grid.coords[v]);
    if (b.lower.y > 0.37f || b.upper.y < 0.37f || b.lower.z < 0.05f) continue;
    ++planeVoxels;
    EXPECT_EQ(grid.normals[v], Vec3(0, -1, 0)) << grid.coords[v].ToString();
    area += grid.areas[v];
    mx += double(grid.areas[v]) * grid.centroids[v].x;
    mz += double(grid.areas[v]) * grid.centroids[v].z;
    EXPECT_EQ(grid.centroids[v].y, 0.37f);
  }
  EXPECT_GT(planeVoxels, 100u);
  EXPECT_NEAR(area, 0.56, 1e-5);
  EXPECT_NEAR(mx / area, 0.5, 1e-5);
  EXPECT_NEAR(mz / area, 0.55, 1e-5);
}

// A slab thinner than a voxel: each voxel holds both faces, which cancel.
// Coincident triangles of opposite winding (as in the dragon scene) too.
TEST(SurfaceGrid, OppositeFacesGiveAZeroNormal) {
  Scene scene = test::oneMaterialScene();
  const float vs = 1.02f / 16.0f;
  const float x0 = 0.5f + 0.3f * vs;
  test::addQuad(scene, {x0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, 0);
  test::addQuad(scene, {x0 + 0.2f * vs, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 0);
  test::addQuad(scene, {0, 0, 0.3f}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  test::addQuad(scene, {0, 0, 0.3f}, {1, 0, 0}, {0, 1, 0}, {0, 0, -1}, 0);
  GridParams p;
  p.depth = 4;
  SurfaceGrid grid = buildSurfaceGrid(scene, p);
  ASSERT_NEAR(grid.frame.voxelSize, vs, 1e-6f);
  size_t slab = 0, panel = 0;
  for (size_t v = 0; v < grid.size(); ++v) {
    const Vec3 c = grid.centroids[v];
    const bool inSlab = std::abs(c.x - (x0 + 0.1f * vs)) < 0.11f * vs;
    const bool inPanel = c.z == 0.3f;
    if (inSlab && std::abs(c.z - 0.3f) > vs && c.y > 0.05f && c.y < 0.95f) {
      ++slab;
      EXPECT_EQ(grid.normals[v], Vec3{}) << grid.coords[v].ToString();
    }
    if (inPanel && std::abs(c.x - x0) > vs) {
      ++panel;
      EXPECT_EQ(grid.normals[v], Vec3{}) << grid.coords[v].ToString();
    }
  }
  EXPECT_GT(slab, 50u);
  EXPECT_GT(panel, 50u);
}

TEST(SurfaceGrid, SameBytesForAnyThreadCount) {
  Scene scene = randomScene(3000, 9);
  GridParams p;
  p.depth = 6;
  auto build = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    return buildSurfaceGrid(scene, p);
  };
  SurfaceGrid a = build(1), b = build(2), c = build(3);
  for (const SurfaceGrid* g : {&b, &c}) {
    ASSERT_EQ(a.coords, g->coords);
    ASSERT_EQ(a.normals, g->normals);
    ASSERT_EQ(a.centroids, g->centroids);
    ASSERT_EQ(a.areas, g->areas);
  }
  expectConsistent(scene, a);
}

// Far from the origin (1e5) or tiny (1e-4): the same voxels, normals and,
// up to the float frame's rounding, the same areas and centroids.
TEST(SurfaceGrid, FarAndTinyScenesVoxelizeConsistently) {
  GridParams p;
  p.depth = 4;
  const Scene base = cornellLikeBox();
  const SurfaceGrid ref = buildSurfaceGrid(base, p);
  // Precondition: no wall within 0.05 voxel of a voxel plane, so that the
  // float frame's rounding at 1e5 (< 0.004) cannot move a wall across one.
  for (const Vec3& q : base.positions) {
    for (int a = 0; a < 3; ++a) {
      const float t = (q[a] - ref.frame.origin[a]) / ref.frame.voxelSize;
      ASSERT_GT(std::abs(t - std::round(t)), 0.05f) << q.ToString();
    }
  }
  expectConsistent(base, ref);
  struct Case {
    float scale;
    Vec3 offset;
    float centroidTol;
    float normalTol;  ///< voxels holding several faces mix them by area
  };
  for (const Case& k :
       {Case{1.0f, Vec3(1e5f, -1e5f, 1e5f), 0.01f, 0.15f}, Case{1e-4f, Vec3{}, 1e-9f, 1e-5f}}) {
    SCOPED_TRACE(k.scale);
    const Scene scene = cornellLikeBox(k.scale, k.offset);
    const SurfaceGrid g = buildSurfaceGrid(scene, p);
    ASSERT_EQ(g.coords, ref.coords);
    size_t exact = 0;
    for (size_t v = 0; v < g.size(); ++v) {
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(g.normals[v][a], ref.normals[v][a], k.normalTol) << v;
      exact += g.normals[v] == ref.normals[v];
    }
    EXPECT_GT(exact, g.size() * 3 / 4);  // single-face voxels: exactly the face normal
    const float s2 = k.scale * k.scale;
    const float areaTol = k.scale == 1.0f ? 0.02f * ref.frame.voxelSize : 1e-4f * s2;
    for (size_t v = 0; v < g.size(); ++v) {
      ASSERT_NEAR(g.areas[v], ref.areas[v] * s2, areaTol) << v;
      for (int a = 0; a < 3; ++a) {
        ASSERT_NEAR(g.centroids[v][a] - k.offset[a], ref.centroids[v][a] * k.scale,
                    k.centroidTol + 1e-7f * std::abs(k.offset[a]))
            << v;
      }
    }
    double area = 0;
    for (float a : g.areas) area += a;
    EXPECT_NEAR(area, totalArea(scene), 1e-4 * totalArea(scene));
  }
}

TEST(SurfaceGrid, MovesAndRebuildIndex) {
  Scene scene = cornellLikeBox();
  GridParams p;
  p.depth = 3;
  SurfaceGrid a = buildSurfaceGrid(scene, p);
  const Coord c = a.coords[5];
  SurfaceGrid b = std::move(a);
  EXPECT_EQ(b.find(c), 5);
  EXPECT_EQ(a.find(c), -1);  // NOLINT(bugprone-use-after-move): moved-from is empty
  std::reverse(b.coords.begin(), b.coords.end());
  b.rebuildIndex();
  EXPECT_EQ(b.find(c), int64_t(b.size() - 6));
}

TEST(SurfaceGrid, BadSceneThrows) {
  Scene scene;
  GridParams p;
  EXPECT_THROW(buildSurfaceGrid(scene, p), InputError);  // no triangles
  scene = randomScene(3, 1);
  scene.indices[4] = 99;
  EXPECT_THROW(buildSurfaceGrid(scene, p), InputError);
  scene = randomScene(3, 1);
  scene.positions[2].x = NAN;
  EXPECT_THROW(buildSurfaceGrid(scene, p), InputError);
  scene = randomScene(3, 1);
  p.depth = 13;
  EXPECT_THROW(buildSurfaceGrid(scene, p), InputError);
}


}  // namespace
}  // namespace lo

namespace lo {
namespace {

// The shared Cornell box scene, through the scene loader.
TEST(SurfaceGrid, ActiveSetEqualsBruteForceInCornellBoxScene) {
  const std::string path = test::sharedScenesDir() + "/composed/cornell-box.glb";
  Scene scene = loadScene(path);
  GridParams p;
  p.depth = 4;
  SurfaceGrid grid = buildSurfaceGrid(scene, p);
  std::set<Coord> expected = bruteForceActive(scene, grid.frame);
  std::set<Coord> got(grid.coords.begin(), grid.coords.end());
  EXPECT_TRUE(got == expected) << got.size() << " vs " << expected.size();
  expectConsistent(scene, grid);
}

}  // namespace
}  // namespace lo
