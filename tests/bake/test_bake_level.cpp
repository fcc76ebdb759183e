// bakeLevel (cluster/bake_level.h): the one-level bake every caller shares is
// exactly voxelize + splat + gather + cluster, and is deterministic.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cstdlib>
#include <cstring>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "bake/convert.h"
#include "core/error.h"
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

namespace lo {
namespace {

// 2,000 coincident unit quads (20,000 instanced nodes of a glTF, G06 of the
// seventh hostile list) have the area of 2,000 quads but cross only the
// voxels of one: the estimate from their area, uncapped, gave a depth-4 grid
// of 4,096 voxels "about 29,527,106 voxels ... 27.51 GiB" and refused it.
TEST(BakeMemory, TheVoxelEstimateIsAtMostTheGridsVoxels) {
  Scene scene = test::oneMaterialScene();
  for (int i = 0; i < 2000; ++i) {
    test::addQuad(scene, Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 0);
  }
  const GridFrame frame = makeGridFrame(scene.bounds(), 2);
  const double cells = 4.0 * 4.0 * 4.0;
  EXPECT_LE(estimateActiveVoxels(scene, frame, Bounds3()), cells);
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "1M", 1);  // 64 voxels x 1000 B fit in 1 MiB
  EXPECT_NO_THROW(checkVoxelMemory(scene, frame, Bounds3(), 0));
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  // One quad is still estimated from its area: about 16 voxels of a quarter.
  Scene one = test::oneMaterialScene();
  test::addQuad(one, Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 0);
  EXPECT_NEAR(estimateActiveVoxels(one, frame, Bounds3()), 16.0, 2.0);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

/// A square floor `size` scene units wide, its corner at the origin.
Scene floorScene(float size) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, Vec3(0.0f), Vec3(size, 0, 0), Vec3(0, 0, size), Vec3(0, 1, 0), 0);
  return scene;
}

// --depth auto: the paper's 6 where its voxels are at most a scene unit (a
// metre) wide, else 7; 7 at most, and 6 where 7's memory is not there.
TEST(BakeDepth, AutoIsSixUnlessItsVoxelsAreWiderThanAMetre) {
  Bounds3 box;
  box.extend(Vec3(0.0f));
  for (float size : {0.01f, 2.0f, 60.0f, 70.0f, 100.0f, 1e4f}) {
    SCOPED_TRACE(size);
    Bounds3 b = box;
    b.extend(Vec3(size));
    // 2^6 voxels across the padded cube: 64 m of scene hold 1 m voxels.
    const int expected = size <= 60.0f ? 6 : 7;
    EXPECT_EQ(autoDepth(b), expected);
  }
  EXPECT_EQ(BakeParams{}.depth, kAutoDepth);
  BakeParams params;
  params.photons = 1000;
  EXPECT_EQ(checkedBakeParams(floorScene(2.0f), params).depth, 6);
  EXPECT_EQ(checkedBakeParams(floorScene(100.0f), params).depth, 7);
  // A depth given is the depth taken.
  params.depth = 5;
  EXPECT_EQ(checkedBakeParams(floorScene(100.0f), params).depth, 5);
  // Where depth 7's voxels do not fit in memory and depth 6's do, auto is 6.
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "12M", 1);
  params.depth = 7;
  EXPECT_THROW(checkedBakeParams(floorScene(100.0f), params), InputError);
  params.depth = 6;
  EXPECT_EQ(checkedBakeParams(floorScene(100.0f), params).depth, 6);
  params.depth = kAutoDepth;
  EXPECT_EQ(checkedBakeParams(floorScene(100.0f), params).depth, 6);
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  // A scene of half a millimetre: depth 6's voxels (7.9e-6) are finer than
  // a .vdb stores (kMinStorableVoxel): auto takes the finest that it does.
  const Scene tiny = floorScene(5e-4f);
  EXPECT_THROW(checkedBakeParams(tiny, test::smallBake(6, 1000)), InputError);
  const int depth = checkedBakeParams(tiny, params).depth;
  EXPECT_EQ(depth, 5);
  EXPECT_GE(makeGridFrame(tiny.bounds(), depth).voxelSize, kMinStorableVoxel);
}

TEST(BakeDepth, ParsedAsAutoOrAWholeNumberFrom1To12) {
  EXPECT_EQ(parseDepth("auto"), kAutoDepth);
  EXPECT_EQ(parseDepth("1"), 1);
  EXPECT_EQ(parseDepth("12"), 12);
  for (const char* bad : {"0", "13", "-1", "6.5", "6x", "", "AUTO", "nan"}) {
    SCOPED_TRACE(bad);
    EXPECT_THROW(parseDepth(bad), InputError);
    EXPECT_FALSE(depthError(bad).empty());
  }
  EXPECT_TRUE(depthError("auto").empty());
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// A fixed budget spread thinner than a photon per ten voxels over a million
// of them is warned before the work (H14-5-3: --depth 10, 100,000 photons,
// 78 s and 6.2 GB). A floor of one unit at depth 10 crosses 1024^2 voxels.
TEST(BakeDepth, PhotonsSpreadThinOverAMillionVoxelsAreWarned) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 0);
  BakeParams p;
  p.depth = 10;
  setPhotonBudget(p, 50000, 0);
  const std::string warning = sparsePhotonsWarning(scene, p);
  EXPECT_NE(warning.find("--depth 10: the surfaces cross about 1,0"), std::string::npos) << warning;
  EXPECT_NE(warning.find("--photons 50,000 are 0.05 a voxel"), std::string::npos) << warning;
  setPhotonBudget(p, 200000, 0);  // 0.19 a voxel
  EXPECT_EQ(sparsePhotonsWarning(scene, p), "");
  p.depth = 9;  // 262,144 voxels
  setPhotonBudget(p, 1000, 0);
  EXPECT_EQ(sparsePhotonsWarning(scene, p), "");
  p.depth = kAutoDepth;
  EXPECT_EQ(sparsePhotonsWarning(scene, p), "");
  p.depth = 10;
  setPhotonBudget(p, 0, 0.05);  // a target fits the photons to the voxels
  EXPECT_EQ(sparsePhotonsWarning(scene, p), "");
}

// The same warning before `convert --photon-map` re-gathers a small photon
// map at a fine depth (list 14: --depth 10 from a small map, no word).
TEST(BakeDepth, ARegatherOfFewPhotonsOverAMillionVoxelsIsWarned) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, Vec3(0.0f), Vec3(1, 0, 0), Vec3(0, 0, 1), Vec3(0, 1, 0), 0);
  VdlGrid grid;
  grid.frame = makeGridFrame(scene.bounds(), 4);
  const std::vector<Photon> photons(50000);
  ConvertParams params;
  params.scene = &scene;
  params.photons = &photons;
  params.depth = 10;
  const std::string warning = sparseRegatherWarning(grid, BakeMetadata{}, params);
  EXPECT_NE(warning.find("--depth 10: the surfaces cross about 1,0"), std::string::npos) << warning;
  EXPECT_NE(warning.find("the 50,000 photons of --photon-map are 0.05 a voxel"), std::string::npos)
      << warning;
  EXPECT_NE(warning.find("a coarser --depth"), std::string::npos) << warning;
  params.depth = 9;  // 262,144 voxels
  EXPECT_EQ(sparseRegatherWarning(grid, BakeMetadata{}, params), "");
  params.depth = 0;  // the input's depth, 4
  EXPECT_EQ(sparseRegatherWarning(grid, BakeMetadata{}, params), "");
  params.depth = 10;
  params.photons = nullptr;  // merged or interpolated, not gathered
  EXPECT_EQ(sparseRegatherWarning(grid, BakeMetadata{}, params), "");
}

}  // namespace
}  // namespace lo
