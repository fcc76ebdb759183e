#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

#include "test_util.h"
#include "cluster/vdl_cluster.h"
#include "core/error.h"
#include "core/rng.h"

namespace lo {
namespace {

// A unit square on y = 0 lit by photons arriving from two directions in the
// x-y plane, uniformly spread over the square. Every gathered voxel's VDLs must
// add up to its irradiance estimate, and (k = 2) recover the two directions.
struct PlaneBake {
  SurfaceGrid grid;
  std::vector<Photon> photons;
  Vec3 dirA = normalize(Vec3(1, 1, 0));
  Vec3 dirB = normalize(Vec3(-1, 2, 0));
  float powerPerPhoton = 0;

  explicit PlaneBake(size_t count) {
    Scene scene;
    scene.materials.push_back(Material{});
    test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);
    GridParams gp;
    gp.depth = 4;
    grid = buildSurfaceGrid(scene, gp);
    Rng rng(1, 0);
    // Total flux 1 W per channel on 1 m^2: irradiance 1 W/m^2.
    powerPerPhoton = 1.0f / float(count);
    for (size_t i = 0; i < count; ++i) {
      Photon p;
      p.position = {rng.uniform(), 0.0f, rng.uniform()};
      p.direction = i % 3 == 0 ? dirB : dirA;  // B carries 1/3 of the power
      p.power = Vec3(powerPerPhoton);
      p.normal = {0, 1, 0};
      p.bounce = 1;
      photons.push_back(p);
    }
    splatPhotons(grid, photons);
  }
};

TEST(VdlGrid, PlaneOfUniformPhotonsSplitsIntoTwoLights) {
  PlaneBake bake(200000);
  GatherParams gather;
  ClusterParams cluster;
  cluster.vdls = 2;
  BakeTimings timings;
  VdlGrid g = buildVdlGrid(bake.grid, bake.photons, gather, cluster, nullptr, &timings);
  ASSERT_GT(g.size(), 0u);
  ASSERT_EQ(g.vdls.size(), g.size() * 2);
  EXPECT_EQ(g.coords, bake.grid.coords);
  EXPECT_GE(timings.gatherSeconds, 0.0);
  EXPECT_GE(timings.clusterSeconds, 0.0);
  int interior = 0;
  for (size_t v = 0; v < g.size(); ++v) {
    const Vdl* vdls = g.vdlsOf(v);
    Vec3 sum;
    for (int i = 0; i < g.vdlCount[v]; ++i) sum += vdls[i].irradiance;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(sum[c], g.irradiance[v][c], 1e-4f * (1.0f + g.irradiance[v][c])) << v;
    }
    if (g.photonCount[v] < float(gather.k)) continue;
    // A voxel whose gather disc lies inside the square sees the true density.
    Vec3 c = g.frame.voxelCenter(g.coords[v]);
    float r = g.radius[v];
    if (c.x - r < 0 || c.x + r > 1 || c.z - r < 0 || c.z + r > 1) continue;
    ++interior;
    // k = 300 photons: relative standard deviation ~ 1/sqrt(300) ~ 6%.
    EXPECT_NEAR(g.irradiance[v].x, 1.0f, 0.25f) << v;
    ASSERT_EQ(g.vdlCount[v], 2);
    EXPECT_GT(dot(vdls[0].direction, bake.dirA), 0.9999f);
    EXPECT_GT(dot(vdls[1].direction, bake.dirB), 0.9999f);
    EXPECT_NEAR(vdls[1].irradiance.x / g.irradiance[v].x, 1.0f / 3.0f, 0.1f);
    EXPECT_NEAR(g.angularError[v], 0.0f, 1e-3f);
  }
  EXPECT_GT(interior, 10);
}

TEST(VdlGrid, SameBytesWhateverTheThreadCount) {
  PlaneBake bake(20000);
  GatherParams gather;
  ClusterParams cluster;
  cluster.vdls = 4;
  VdlGrid a = buildVdlGrid(bake.grid, bake.photons, gather, cluster);
  VdlGrid b;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    b = buildVdlGrid(bake.grid, bake.photons, gather, cluster);
  }
  ASSERT_EQ(a.size(), b.size());
  for (size_t v = 0; v < a.size(); ++v) {
    EXPECT_EQ(a.irradiance[v], b.irradiance[v]);
    EXPECT_EQ(a.angularError[v], b.angularError[v]);
    EXPECT_EQ(a.vdlCount[v], b.vdlCount[v]);
    for (int i = 0; i < a.maxVdls; ++i) {
      EXPECT_EQ(a.vdlsOf(v)[i].irradiance, b.vdlsOf(v)[i].irradiance);
      EXPECT_EQ(a.vdlsOf(v)[i].direction, b.vdlsOf(v)[i].direction);
    }
  }
}

TEST(VdlGrid, RejectsBadVdlCount) {
  SurfaceGrid grid;
  std::vector<Photon> photons;
  ClusterParams cluster;
  cluster.vdls = 9;
  EXPECT_THROW(buildVdlGrid(grid, photons, {}, cluster), InputError);
}

}  // namespace
}  // namespace lo
