// Adaptive leaves (octree/adaptive_leaves.h) against answers known in
// advance: a plane under one constant light collapses to the coarsest leaves
// that cover it and the lookup returns the same irradiance everywhere; a
// shadow's edge keeps its voxels; surface layers and dark voxels are never
// covered; SH grids collapse the same way; a lit plane whose light changes
// smoothly collapses only as far as the tolerance allows.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/error.h"
#include "octree/adaptive_leaves.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"

namespace lo {
namespace {

constexpr float kVoxel = 0.25f;

/// A floor of depth-`depth` voxels at z = 0, voxel (x, y) lit by light(x, y)
/// arriving from `direction` (one VDL), normal +z.
template <class LightFn>
VdlGrid floorGrid(int depth, const Vec3& direction, LightFn light) {
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = kVoxel;
  g.frame.depth = depth;
  g.maxVdls = 4;
  const int res = 1 << depth;
  for (int y = 0; y < res; ++y) {
    for (int x = 0; x < res; ++x) {
      const Vec3 e = light(x, y);
      g.coords.push_back({x, y, 0});
      g.normals.push_back({0, 0, 1});
      g.areas.push_back(kVoxel * kVoxel);
      g.irradiance.push_back(e);
      g.photonCount.push_back(300);
      g.radius.push_back(kVoxel);
      g.noise.push_back(0.05f);
      g.reflectance.push_back({0.5f, 0.5f, 0.5f});
      g.angularError.push_back(0);
      g.vdlCount.push_back(e.x > 0 ? 1 : 0);
      for (int i = 0; i < g.maxVdls; ++i) {
        g.vdls.push_back(i == 0 && e.x > 0 ? Vdl{e, normalize(direction)} : Vdl{});
      }
    }
  }
  return g;
}

Vec3 centre(int x, int y) { return Vec3{(float(x) + 0.5f) * kVoxel, (float(y) + 0.5f) * kVoxel, 0.1f * kVoxel}; }

void expectSameIrradiance(const GpuOctree& a, const GpuOctree& b, int res, float tolerance) {
  for (int y = 0; y < res; ++y) {
    for (int x = 0; x < res; ++x) {
      for (const Vec3& n : {Vec3{0, 0, 1}, normalize(Vec3{1, 1, 3})}) {
        const Vec3 ea = octreeIrradiance(a, centre(x, y), n), eb = octreeIrradiance(b, centre(x, y), n);
        for (int c = 0; c < 3; ++c) {
          ASSERT_NEAR(ea[c], eb[c], tolerance * std::max(1e-6f, eb[c])) << x << ", " << y;
        }
      }
    }
  }
}

TEST(AdaptiveLeaves, ConstantLightCollapsesToTheCoarsestLeaves) {
  const VdlGrid g = floorGrid(4, {0.3f, 0.1f, 1}, [](int, int) { return Vec3{2, 1, 0.5f}; });
  GpuOctreeParams adaptive;
  adaptive.tolerance = 0.01f;
  const GpuOctree uniform = buildGpuOctree(g), collapsed = buildGpuOctree(g, adaptive);
  // 16 x 16 voxels of a depth-4 grid: level-1 nodes hold 8 x 8 x 8, so four of them cover it.
  EXPECT_EQ(uniform.leafCount, 256u);
  EXPECT_EQ(collapsed.leafCount, 4u);
  EXPECT_EQ(collapsed.collapsedLeaves, 4u);
  EXPECT_EQ(collapsed.collapsedVoxels, 256u);
  EXPECT_EQ(collapsed.vdlCount, 4u * 2u);  // per leaf its VDL and its surface texel
  EXPECT_EQ(collapsed.nodeCount, 1u);  // the root tile alone
  expectSameIrradiance(collapsed, uniform, 16, 1e-5f);
  // Tolerance 0: the uniform tree, byte for byte.
  GpuOctreeParams off;
  off.tolerance = 0;
  const GpuOctree same = buildGpuOctree(g, off);
  EXPECT_EQ(same.pool, uniform.pool);
  EXPECT_EQ(same.vdlTexels, uniform.vdlTexels);
}

TEST(AdaptiveLeaves, AShadowsEdgeKeepsItsVoxels) {
  // Light 1 for x <= 4, 3 beyond: the nodes across x = 4 | 5 cannot merge.
  const VdlGrid g = floorGrid(4, {0, 0, 1}, [](int x, int) {
    return x <= 4 ? Vec3{1, 1, 1} : Vec3{3, 3, 3};
  });
  const AdaptiveLeaves a = collapseLeaves(g, 0.1f, true);
  for (size_t v = 0; v < g.size(); ++v) {
    const int x = g.coords[v].x;
    if (x == 4 || x == 5) {
      EXPECT_FALSE(a.collapsed[v]) << "voxel at x = " << x << " collapsed across the edge";
    }
  }
  EXPECT_GT(a.voxelsCollapsed, g.size() / 2);
  GpuOctreeParams adaptive;
  adaptive.tolerance = 0.1f;
  // Flat light on either side: the picture is the uniform tree's.
  expectSameIrradiance(buildGpuOctree(g, adaptive), buildGpuOctree(g), 16, 1e-5f);
}

TEST(AdaptiveLeaves, SmoothLightCollapsesAsFarAsTheToleranceAllows) {
  // Irradiance 1 + x / 15 along x: neighbours differ by 1/15 ~ 4-7%.
  const VdlGrid g = floorGrid(4, {0, 0, 1}, [](int x, int) {
    const float e = 1.0f + float(x) / 15.0f;
    return Vec3{e, e, e};
  });
  size_t previous = 0;
  for (float tolerance : {0.01f, 0.05f, 0.2f, 0.6f}) {
    GpuOctreeParams p;
    p.tolerance = tolerance;
    const GpuOctree o = buildGpuOctree(g, p);
    const AdaptiveLeaves a = collapseLeaves(g, tolerance, true);
    EXPECT_GE(a.voxelsCollapsed, previous) << tolerance;
    previous = a.voxelsCollapsed;
    // At every voxel's own surface the error stays within the tolerance.
    const GpuOctree uniform = buildGpuOctree(g);
    OctreeShadeParams nearest;
    nearest.interpolation = false;
    for (int x = 0; x < 16; ++x) {
      const float own = octreeIrradiance(uniform, centre(x, 3), {0, 0, 1}, nearest).x;
      const float adaptiveE = octreeIrradiance(o, centre(x, 3), {0, 0, 1}, nearest).x;
      EXPECT_LE(std::fabs(adaptiveE - own), tolerance * own * 1.0001f) << tolerance << " at x = " << x;
    }
  }
  EXPECT_EQ(collapseLeaves(g, 0.01f, true).voxelsCollapsed, 0u);
  EXPECT_EQ(collapseLeaves(g, 0.6f, true).voxelsCollapsed, g.size());
}

TEST(AdaptiveLeaves, LayersAndDarkVoxelsAreNeverCovered) {
  VdlGrid g = floorGrid(3, {0, 0, 1}, [](int x, int y) {
    return x == 6 && y == 6 ? Vec3{0, 0, 0} : Vec3{1, 1, 1};  // one dark voxel
  });
  // Voxel (1, 1) holds a second surface layer.
  const size_t layered = 1 * 8 + 1;
  g.points.assign(g.size(), Vec3{0, 0, 0});
  for (size_t v = 0; v < g.size(); ++v) g.points[v] = centre(g.coords[v].x, g.coords[v].y);
  VdlLayers& L = g.layers;
  L.voxel.push_back(uint32_t(layered));
  L.normals.push_back({0, 0, -1});
  L.points.push_back(centre(1, 1));
  L.irradiance.push_back({1, 1, 1});
  L.photonCount.push_back(100);
  L.radius.push_back(kVoxel);
  L.noise.push_back(0.05f);
  L.reflectance.push_back({0.5f, 0.5f, 0.5f});
  L.angularError.push_back(0);
  L.vdlCount.push_back(1);
  for (int i = 0; i < g.maxVdls; ++i) L.vdls.push_back(i == 0 ? Vdl{{1, 1, 1}, {0, 0, -1}} : Vdl{});
  const AdaptiveLeaves a = collapseLeaves(g, 0.5f, true);
  for (size_t v = 0; v < g.size(); ++v) {
    const Coord c = g.coords[v];
    const bool nearLayer = c.x / 2 == 0 && c.y / 2 == 0;  // shares the level-2 parent
    const bool nearDark = c.x / 2 == 3 && c.y / 2 == 3;
    if (nearLayer || nearDark) {
      EXPECT_FALSE(a.collapsed[v]) << c.ToString();
    }
  }
  // Everything else collapses: two level-1 nodes (4 x 4 voxels) whole, and
  // in the other two the three level-2 nodes (2 x 2) beside the layered and
  // the dark voxel's.
  EXPECT_EQ(a.voxelsCollapsed, g.size() - 8u);
  // The layered voxel still picks its layers in the octree.
  GpuOctreeParams p;
  p.tolerance = 0.5f;
  const GpuOctree o = buildGpuOctree(g, p);
  EXPECT_NEAR(octreeIrradiance(o, centre(1, 1), {0, 0, -1}, OctreeShadeParams{false}).x, 1.0f, 1e-3f);
}

TEST(AdaptiveLeaves, ShTermsCollapseToo) {
  VdlGrid g = floorGrid(3, {0, 0, 1}, [](int, int) { return Vec3{1, 2, 3}; });
  g.shTerms = 4;
  g.sh.clear();
  for (size_t v = 0; v < g.size(); ++v) {
    g.vdlCount[v] = 0;
    const Vec3 terms[4] = {{1, 2, 3}, {0.1f, 0.1f, 0.1f}, {0.5f, 1, 1.5f}, {0, 0.2f, 0}};
    g.sh.insert(g.sh.end(), terms, terms + 4);
  }
  for (Vdl& v : g.vdls) v = Vdl{};
  GpuOctreeParams p;
  p.tolerance = 0.01f;
  const GpuOctree o = buildGpuOctree(g, p);
  EXPECT_EQ(o.leafCount, 4u);  // an 8 x 8 floor at depth 3: four level-1 nodes of 4 x 4
  // Each leaf's four terms and its surface texel (the floor reflects).
  EXPECT_TRUE(o.surfaceTexels);
  EXPECT_EQ(o.vdlCount, 4u * (4u + 1u));
  expectSameIrradiance(o, buildGpuOctree(g), 8, 1e-5f);
}

TEST(AdaptiveLeaves, BadToleranceIsRefused) {
  const VdlGrid g = floorGrid(2, {0, 0, 1}, [](int, int) { return Vec3{1, 1, 1}; });
  EXPECT_THROW(collapseLeaves(g, -0.1f, true), InputError);
  EXPECT_THROW(collapseLeaves(g, NAN, true), InputError);
}

}  // namespace
}  // namespace lo
