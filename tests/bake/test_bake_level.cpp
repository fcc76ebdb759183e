// bakeLevel (cluster/bake_level.h): the one-level bake every caller shares is
// exactly voxelize + splat + gather + cluster, and is deterministic.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstring>

#include "bake/bake.h"
#include "test_util.h"

namespace lo {
namespace {

/// A level at `depth`, gathering `k` photons per voxel.
LevelParams levelParams(int depth, int k) {
  LevelParams params;
  params.grid.depth = depth;
  params.gather.k = k;
  return params;
}

const PhotonMap& photons(const Scene& scene) {
  static const PhotonMap map = [&] {
    PhotonParams p;
    p.storedPhotons = 40000;
    p.seed = 5;
    return tracePhotons(scene, p);
  }();
  return map;
}

void expectSameGrid(const VdlGrid& a, const VdlGrid& b) {
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.frame.depth, b.frame.depth);
  EXPECT_EQ(a.frame.voxelSize, b.frame.voxelSize);
  EXPECT_EQ(a.frame.origin, b.frame.origin);
  EXPECT_EQ(a.maxVdls, b.maxVdls);
  EXPECT_EQ(a.coords, b.coords);
  EXPECT_EQ(a.vdlCount, b.vdlCount);
  ASSERT_EQ(a.vdls.size(), b.vdls.size());
  ASSERT_EQ(a.irradiance.size(), b.irradiance.size());
  EXPECT_EQ(std::memcmp(a.vdls.data(), b.vdls.data(), a.vdls.size() * sizeof(Vdl)), 0);
  EXPECT_EQ(
      std::memcmp(a.irradiance.data(), b.irradiance.data(), a.irradiance.size() * sizeof(Vec3)), 0);
}

TEST(BakeLevel, IsTheStagesInSequence) {
  Scene scene = test::pointLitRoom();
  const PhotonMap& map = photons(scene);
  LevelParams params = levelParams(4, 60);
  params.cluster.vdls = 3;
  params.cluster.seed = 9;
  params.occlusion = false;  // the ray tracer's segment test is the bake module's own wiring
  params.smoothing = false;  // a pass after buildVdlGrid (tests/cluster)
  LevelStats stats;
  VdlGrid level = bakeLevel(scene, map.photons, params, nullptr, &stats);

  SurfaceGrid grid = buildSurfaceGrid(scene, params.grid);
  size_t dropped = splatPhotons(grid, map.photons);
  const LayerParams layers;
  VdlGrid direct =
      buildVdlGrid(grid, map.photons, params.gather, params.cluster, nullptr, nullptr, &layers);
  EXPECT_EQ(level.layers.voxel, direct.layers.voxel);
  EXPECT_GT(level.layers.size(), 0u) << "the room's edges have layers";
  expectSameGrid(level, direct);
  EXPECT_GT(level.size(), 0u);
  EXPECT_EQ(stats.activeVoxels, grid.size());
  EXPECT_EQ(stats.droppedPhotons, dropped);
  EXPECT_EQ(stats.radius, resolveRadius(params.gather, grid.frame));
  EXPECT_GE(stats.voxelizeSeconds, 0.0);
  EXPECT_NEAR(stats.seconds(),
              stats.voxelizeSeconds + stats.splatSeconds + stats.gatherClusterSeconds, 1e-12);
}

TEST(BakeLevel, SameBytesWhateverTheThreadCount) {
  Scene scene = test::pointLitRoom();
  const PhotonMap& map = photons(scene);
  LevelParams params = levelParams(5, 40);
  VdlGrid many = bakeLevel(scene, map.photons, params);
  tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
  VdlGrid single = bakeLevel(scene, map.photons, params);
  expectSameGrid(many, single);
}

}  // namespace
}  // namespace lo
