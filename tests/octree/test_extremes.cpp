// Numerical stability of the whole bake at the extremes: every stage from
// photons to the GPU octree textures, asserting no NaN or Inf anywhere,
// conserved energy (the VDLs of a voxel sum to its estimate) and bounded error.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cluster/vdl_cluster.h"
#include "core/error.h"
#include "grid/surface_grid.h"
#include "octree/gpu_octree.h"
#include "photon/photon_map.h"
#include "test_util.h"

namespace lo {
namespace {

/// A closed room of albedo 0.5 lit by a downward-facing emissive quad under the
/// ceiling, with a block on the floor; `scale` and `offset` move it in space.
Scene litRoom(float emission = 10.0f, float scale = 1.0f, Vec3 offset = {}) {
  Scene scene;
  Material wall;
  wall.baseColor = Vec3(0.5f);
  Material light;
  light.baseColor = Vec3(0.0f);
  light.emission = Vec3(emission);
  scene.materials = {wall, light};
  test::addClosedBox(scene, {0, 0, 0}, {1, 1, 1}, 0);
  test::addBlock(scene, {0.2f, 0, 0.3f}, {0.45f, 0.4f, 0.6f}, 0);
  test::addQuad(scene, {0.4f, 0.99f, 0.4f}, {0.2f, 0, 0}, {0, 0, 0.2f}, {0, -1, 0}, 1);
  for (Vec3& p : scene.positions) p = p * scale + offset;
  return scene;
}

struct Bake {
  SurfaceGrid grid;
  PhotonMap photons;
  VdlGrid vdls;
};

Bake bake(const Scene& scene, int depth, size_t photons, int vdls = 4, int knn = 100) {
  Bake b;
  PhotonParams pp;
  pp.storedPhotons = photons;
  b.photons = tracePhotons(scene, pp);
  GridParams gp;
  gp.depth = depth;
  b.grid = buildSurfaceGrid(scene, gp);
  splatPhotons(b.grid, b.photons.photons);
  GatherParams gather;
  gather.k = knn;
  ClusterParams cluster;
  cluster.vdls = vdls;
  b.vdls = buildVdlGrid(b.grid, b.photons.photons, gather, cluster);
  return b;
}

bool finite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// No NaN/Inf anywhere; directions unit; VDLs sum to the voxel's irradiance.
void expectSane(const VdlGrid& g, float energyTolerance = 1e-4f) {
  for (size_t v = 0; v < g.size(); ++v) {
    ASSERT_TRUE(finite(g.irradiance[v])) << "voxel " << v << " " << g.irradiance[v].ToString();
    ASSERT_TRUE(finite(g.normals[v])) << "voxel " << v;
    ASSERT_TRUE(std::isfinite(g.angularError[v])) << "voxel " << v;
    ASSERT_TRUE(std::isfinite(g.radius[v])) << "voxel " << v;
    ASSERT_LE(int(g.vdlCount[v]), g.maxVdls);
    Vec3 sum{0, 0, 0};
    for (int i = 0; i < g.maxVdls; ++i) {
      const Vdl& l = g.vdlsOf(v)[i];
      ASSERT_TRUE(finite(l.irradiance) && finite(l.direction)) << "voxel " << v << " VDL " << i;
      if (i < g.vdlCount[v]) {
        ASSERT_NEAR(length(l.direction), 1.0f, 1e-4f) << "voxel " << v << " VDL " << i;
        ASSERT_GE(std::min({l.irradiance.x, l.irradiance.y, l.irradiance.z}), 0.0f);
      }
      sum += l.irradiance;
    }
    for (int c = 0; c < 3; ++c) {
      float e = g.irradiance[v][c];
      ASSERT_NEAR(sum[c], e, energyTolerance * std::max(std::fabs(e), 1e-30f))
          << "voxel " << v << " channel " << c;
    }
  }
}

void expectSaneTextures(const GpuOctree& o) {
  for (float f : o.vdlTexels) ASSERT_TRUE(std::isfinite(f));
  // Half texels: RGB are half bits, A is the packed direction as an integer.
  for (size_t i = 0; i < o.vdlTexelsHalf.size(); ++i) {
    if (i % 4 != 3) {
      ASSERT_TRUE(std::isfinite(halfToFloat(o.vdlTexelsHalf[i]))) << i;
    }
  }
}

/// Area-weighted mean irradiance (luminance) of a bake: the scene-level figure
/// that must not depend on where the scene sits or how big it is.
double meanIrradiance(const VdlGrid& g) {
  double sum = 0, area = 0;
  for (size_t v = 0; v < g.size(); ++v) {
    sum += double(g.areas[v]) * luminance(g.irradiance[v]);
    area += g.areas[v];
  }
  return area > 0 ? sum / area : 0;
}

TEST(Extremes, DepthOneWorksAndDepthThirteenIsRefused) {
  Scene scene = litRoom();
  Bake b = bake(scene, 1, 20000);
  EXPECT_EQ(b.vdls.size(), 8u);  // the room's walls touch all 2x2x2 voxels
  expectSane(b.vdls);
  GridParams gp;
  gp.depth = 13;
  test::expectRefusal([&] { buildSurfaceGrid(scene, gp); }, {"13"});
}

TEST(Extremes, LargestDepthOnASparseScene) {
  // Two small lit patches far apart: depth 12 (4096^3 voxels) stays sparse.
  Scene scene;
  Material wall;
  Material light;
  light.emission = Vec3(5.0f);
  scene.materials = {wall, light};
  test::addQuad(scene, {0, 0, 0}, {0.002f, 0, 0}, {0, 0, 0.002f}, {0, 1, 0}, 0);
  test::addQuad(scene, {0, 0.001f, 0}, {0.002f, 0, 0}, {0, 0, 0.002f}, {0, -1, 0}, 1);
  test::addQuad(scene, {1, 1, 1}, {0.002f, 0, 0}, {0, 0, 0.002f}, {0, 1, 0}, 0);
  Bake b = bake(scene, 12, 2000, 4, 20);
  EXPECT_GT(b.grid.size(), 0u);
  EXPECT_LT(b.grid.size(), 2000u);
  expectSane(b.vdls);
  GpuOctree o = buildGpuOctree(b.vdls);
  EXPECT_EQ(o.depth, 12);
  expectSaneTextures(o);
}

TEST(Extremes, ZeroAndOnePhoton) {
  Scene scene = litRoom();
  GridParams gp;
  gp.depth = 4;
  SurfaceGrid grid = buildSurfaceGrid(scene, gp);
  std::vector<Photon> none;
  splatPhotons(grid, none);
  VdlGrid empty = buildVdlGrid(grid, none, GatherParams{}, ClusterParams{});
  ASSERT_EQ(empty.size(), grid.size());
  expectSane(empty);
  for (size_t v = 0; v < empty.size(); ++v) {
    EXPECT_EQ(empty.vdlCount[v], 0);
    EXPECT_EQ(empty.irradiance[v], Vec3(0, 0, 0));
  }
  GpuOctree o = buildGpuOctree(empty);
  EXPECT_EQ(o.leafCount, 0u);  // unlit voxels are stored as empty

  // One photon on the floor, arriving straight down: the voxels that gather it
  // get one VDL pointing up with E = power / (pi r^2), r the search radius.
  Photon p;
  p.position = {0.5f, 0.0f, 0.5f};
  p.direction = {0, 1, 0};
  p.normal = {0, 1, 0};
  p.power = {1, 2, 3};
  p.bounce = 1;
  std::vector<Photon> one{p};
  splatPhotons(grid, one);
  GatherParams gather;
  // The plain estimate: some of these voxels' discs reach past the block
  // beside the photon, which the edge correction would count.
  gather.edgeCorrection = false;
  VdlGrid single = buildVdlGrid(grid, one, gather, ClusterParams{});
  expectSane(single);
  float r = resolveRadius(gather, grid.frame);
  size_t lit = 0;
  for (size_t v = 0; v < single.size(); ++v) {
    if (single.vdlCount[v] == 0) continue;
    ++lit;
    EXPECT_EQ(single.vdlCount[v], 1);
    EXPECT_NEAR(single.vdlsOf(v)[0].direction.y, 1.0f, 1e-6f);
    EXPECT_NEAR(single.irradiance[v].z, 3.0f / (kPi * r * r), 1e-3f * 3.0f / (kPi * r * r));
  }
  EXPECT_GT(lit, 0u);
}

TEST(Extremes, MoreClustersThanPhotonsOneDirectionAndAntipodes) {
  std::vector<DirectionSample> samples = {{{0, 1, 0}, {1, 1, 1}}, {{0, 1, 0}, {2, 2, 2}}};
  ClusterParams params;
  ClusterResult one = clusterDirections(samples.data(), samples.size(), 8, params, 0);
  EXPECT_EQ(one.count, 1);  // identical directions: one VDL
  EXPECT_NEAR(one.vdls[0].irradiance.x, 3.0f, 1e-6f);
  EXPECT_NEAR(one.angularError, 0.0f, 1e-6f);

  std::vector<DirectionSample> antipodes = {
      {{0, 0, 1}, {1, 0, 0}}, {{0, 0, -1}, {0, 1, 0}}, {{0, 0, 1}, {1, 0, 0}}};
  ClusterResult two = clusterDirections(antipodes.data(), antipodes.size(), 8, params, 0);
  ASSERT_EQ(two.count, 2);
  Vec3 sum = two.vdls[0].irradiance + two.vdls[1].irradiance;
  EXPECT_NEAR(sum.x, 2.0f, 1e-6f);
  EXPECT_NEAR(sum.y, 1.0f, 1e-6f);
  for (int i = 0; i < 2; ++i) EXPECT_NEAR(std::fabs(two.vdls[i].direction.z), 1.0f, 1e-6f);
  // One cluster forced over antipodes: the weighted mean direction is well
  // defined (2:1 weight towards +z) and the angular error is the analytic one:
  // chord lengths 0 (weight 2) and 2 (weight 1): sqrt(4 / 3).
  ClusterResult forced = clusterDirections(antipodes.data(), antipodes.size(), 1, params, 0);
  ASSERT_EQ(forced.count, 1);
  EXPECT_NEAR(forced.vdls[0].direction.z, 1.0f, 1e-6f);
  EXPECT_NEAR(forced.angularError, std::sqrt(4.0f / 3.0f), 1e-5f);
}

TEST(Extremes, LightPowerFromTinyToHugeScalesLinearly) {
  Bake base = bake(litRoom(1.0f), 4, 20000);
  double baseMean = meanIrradiance(base.vdls);
  ASSERT_GT(baseMean, 0.0);
  for (float scale : {1e-20f, 1e-10f, 1e10f, 1e20f}) {
    Bake b = bake(litRoom(scale), 4, 20000);
    expectSane(b.vdls, 1e-4f);
    // Same seed, same paths: the estimate scales exactly up to float rounding.
    EXPECT_NEAR(meanIrradiance(b.vdls) / (baseMean * double(scale)), 1.0, 1e-4) << scale;
    GpuOctreeParams half;
    half.halfFloat = true;
    expectSaneTextures(buildGpuOctree(b.vdls, half));  // clamps to 65504, flushes tiny values
    expectSaneTextures(buildGpuOctree(b.vdls));
  }
}

TEST(Extremes, FarFromTheOriginAndTinyScenesGiveTheSameIrradiance) {
  // Irradiance from a fixed emitted radiance does not depend on position or
  // scale; the photon paths are the same up to rounding, so the bakes agree
  // closely (a few photons may take a different branch after rounding).
  Bake base = bake(litRoom(), 4, 30000);
  double baseMean = meanIrradiance(base.vdls);
  Bake far = bake(litRoom(10.0f, 1.0f, {1e5f, -1e5f, 1e5f}), 4, 30000);
  Bake tiny = bake(litRoom(10.0f, 1e-4f), 4, 30000);
  expectSane(far.vdls);
  expectSane(tiny.vdls);
  EXPECT_EQ(far.grid.size(), base.grid.size());
  EXPECT_EQ(tiny.grid.size(), base.grid.size());
  EXPECT_NEAR(meanIrradiance(far.vdls) / baseMean, 1.0, 0.05);
  EXPECT_NEAR(meanIrradiance(tiny.vdls) / baseMean, 1.0, 0.05);
}

TEST(Extremes, ZeroAreaTrianglesAndOppositeFacesInOneVoxel) {
  Scene scene = litRoom();
  // Degenerate triangles: a point and a segment.
  uint32_t base = uint32_t(scene.positions.size());
  scene.positions.push_back({0.3f, 0.3f, 0.3f});
  scene.positions.push_back({0.6f, 0.5f, 0.4f});
  for (uint32_t t : {base, base, base, base, base, base + 1}) scene.indices.push_back(t);
  scene.triangleMaterial.push_back(0);
  scene.triangleMaterial.push_back(0);
  // A zero-thickness double-sided panel: two coincident quads facing away from
  // each other, so their voxels' normals average to zero.
  test::addQuad(scene, {0.7f, 0.1f, 0.1f}, {0, 0.5f, 0}, {0, 0, 0.5f}, {1, 0, 0}, 0);
  test::addQuad(scene, {0.7f, 0.1f, 0.1f}, {0, 0.5f, 0}, {0, 0, 0.5f}, {-1, 0, 0}, 0);
  Bake b = bake(scene, 5, 30000);
  expectSane(b.vdls);
  size_t zeroNormal = 0;
  for (const Vec3& n : b.grid.normals) zeroNormal += (n == Vec3(0, 0, 0));
  EXPECT_GT(zeroNormal, 0u);
  expectSaneTextures(buildGpuOctree(b.vdls));
}

}  // namespace
}  // namespace lo
