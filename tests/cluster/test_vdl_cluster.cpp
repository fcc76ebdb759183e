#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <vector>

#include "test_util.h"
#include "cluster/vdl_cluster.h"
#include "lightgrid/light_grid_schema.h"
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
    Scene scene = test::oneMaterialScene();
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

namespace lo {
namespace {

// Smoothing averages a voxel with its neighbours, whose gathers share
// photons where their discs overlap: with discs too small to overlap the
// noise falls as for independent estimates (sqrt(sum w^2) / sum w, at most
// that of the 3x3 in-plane neighbourhood: 0.354), with discs far larger
// than the voxels (every photon shared) it does not fall at all.
TEST(Smoothing, NoiseFallsByWhatTheNeighboursDoNotShare) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {0, 0.01f, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);
  GridParams gp;
  gp.depth = 4;
  const SurfaceGrid grid = buildSurfaceGrid(scene, gp);
  const size_t n = grid.size();
  VdlGrid g;
  g.frame = grid.frame;
  g.maxVdls = 1;
  g.coords = grid.coords;
  resizeVoxelArrays(g);
  g.normals = grid.normals;
  g.points = grid.centroids;
  g.areas = grid.areas;
  for (size_t v = 0; v < n; ++v) {
    g.irradiance[v] = Vec3(1.0f);
    g.vdls[v] = Vdl{Vec3(1.0f), {0, 1, 0}};
    g.vdlCount[v] = 1;
    g.photonCount[v] = 100;
    g.noise[v] = 0.1f;
  }
  // An interior voxel of the plane.
  size_t middle = n;
  for (size_t v = 0; v < n; ++v) {
    const Vec3 c = grid.centroids[v];
    if (std::fabs(c.x - 0.5f) < 0.07f && std::fabs(c.z - 0.5f) < 0.07f) middle = v;
  }
  ASSERT_LT(middle, n);
  const float h = grid.frame.voxelSize;
  VdlGrid apart = g, shared = g;
  std::fill(apart.radius.begin(), apart.radius.end(), 1e-3f * h);
  std::fill(shared.radius.begin(), shared.radius.end(), 1e4f * h);
  smoothVdlGrid(grid, apart);
  smoothVdlGrid(grid, shared);
  const double w1 = std::exp(-0.5), w2 = std::exp(-1.0);
  const double independent9 =
      0.1 * std::sqrt(1 + 4 * w1 * w1 + 4 * w2 * w2) / (1 + 4 * w1 + 4 * w2);
  EXPECT_LE(apart.noise[middle], independent9 * 1.001);
  EXPECT_GT(apart.noise[middle], 0.1 / std::sqrt(27.0));
  EXPECT_NEAR(shared.noise[middle], 0.1, 1e-3);
  EXPECT_EQ(apart.irradiance[middle], Vec3(1.0f));
}

// Layer-aware smoothing (smoothVdlGrid) on a floor and a wall meeting at an
// edge, with made-up estimates: on the floor a uniform light with 8% noise
// around a shadow step of 5x; the wall a different level. Smoothing shrinks
// the noise, keeps the step (far beyond what the noise explains), never mixes
// wall into floor, keeps each voxel's VDL sum equal to its irradiance and
// its VDL directions, and leaves layered voxels alone.
TEST(Smoothing, ShrinksNoiseKeepsStepsAndSurfaces) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);  // floor
  test::addQuad(scene, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 0);  // wall at x = 0
  GridParams gp;
  gp.depth = 5;
  const SurfaceGrid grid = buildSurfaceGrid(scene, gp);
  VdlGrid g;
  g.frame = grid.frame;
  g.maxVdls = 2;
  g.coords = grid.coords;
  const size_t n = grid.size();
  g.normals = grid.normals;
  g.points = grid.centroids;
  g.areas = grid.areas;
  g.photonCount.assign(n, 150.0f);  // noise 1/sqrt(150) = 8%
  g.radius.assign(n, 0.05f);
  g.angularError.assign(n, 0.0f);
  g.vdlCount.assign(n, 2);
  g.irradiance.resize(n);
  g.vdls.resize(2 * n);
  Rng rng(3, 0);
  auto truth = [](const Vec3& p, const Vec3& normal) {
    if (normal.x > 0.5f) return 3.0f;       // the wall
    return p.z < 0.5f ? 1.0f : 0.2f;        // the floor, a shadow over z > 0.5
  };
  std::vector<float> exact(n);
  for (size_t v = 0; v < n; ++v) {
    exact[v] = truth(grid.centroids[v], grid.normals[v]);
    const float e = exact[v] * (1.0f + 0.08f * (2.0f * rng.uniform() - 1.0f) * 1.7f);
    g.vdls[2 * v] = Vdl{Vec3(0.75f * e), normalize(Vec3{0.3f, 1, 0})};
    g.vdls[2 * v + 1] = Vdl{Vec3(0.25f * e), normalize(Vec3{-0.5f, 1, 0.2f})};
    g.irradiance[v] = Vec3(e);
  }
  // The edge voxels (floor and wall in one) have layers: left alone.
  std::vector<uint32_t> layered;
  for (size_t v = 0; v < n; ++v) {
    if (grid.orientationStart[v + 1] != grid.orientationStart[v]) layered.push_back(uint32_t(v));
  }
  ASSERT_FALSE(layered.empty());
  for (uint32_t v : layered) {
    g.layers.voxel.push_back(v);
    g.layers.normals.push_back({1, 0, 0});
    g.layers.points.push_back(grid.centroids[v]);
    g.layers.irradiance.push_back(Vec3(3.0f));
    g.layers.photonCount.push_back(150);
    g.layers.radius.push_back(0.05f);
    g.layers.noise.push_back(0.08f);
    g.layers.reflectance.push_back({0.4f, 0.4f, 0.4f});
    g.layers.angularError.push_back(0);
    g.layers.vdlCount.push_back(0);
    g.layers.vdls.resize(g.layers.vdls.size() + 2);
  }
  const VdlGrid before = g;
  EXPECT_GT(smoothVdlGrid(grid, g), n / 2);
  double errBefore = 0, errAfter = 0;
  int samples = 0;
  for (size_t v = 0; v < n; ++v) {
    const bool isLayered = std::binary_search(layered.begin(), layered.end(), uint32_t(v));
    if (isLayered) {
      EXPECT_EQ(g.irradiance[v], before.irradiance[v]);
      continue;
    }
    // VDLs still sum to the irradiance; directions unchanged.
    const Vec3 sum = g.vdls[2 * v].irradiance + g.vdls[2 * v + 1].irradiance;
    EXPECT_NEAR(length(sum - g.irradiance[v]), 0.0f, 1e-5f * length(sum));
    EXPECT_EQ(g.vdls[2 * v].direction, before.vdls[2 * v].direction);
    const float e = g.irradiance[v].x, x = exact[v];
    // Never pulled towards another surface or across the step.
    EXPECT_NEAR(e, x, 0.25f * x) << grid.centroids[v].ToString();
    const Vec3 c = grid.centroids[v];
    if (std::fabs(c.z - 0.5f) > 0.05f && c.y < 0.01f && c.x > 0.1f) {
      errBefore += std::pow(before.irradiance[v].x / x - 1.0, 2.0);
      errAfter += std::pow(e / x - 1.0, 2.0);
      ++samples;
    }
  }
  ASSERT_GT(samples, 100);
  const double rmsBefore = std::sqrt(errBefore / samples), rmsAfter = std::sqrt(errAfter / samples);
  std::printf("smoothing: relative RMS error on the floor %.4f -> %.4f\n", rmsBefore, rmsAfter);
  EXPECT_LT(rmsAfter, 0.6 * rmsBefore);
}

}  // namespace
}  // namespace lo
