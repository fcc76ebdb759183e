// The free-space light drawn through its octree (buildVolumeOctree,
// volumeIrradiance: the shader's loVolumeIndirect): values, the lit box
// against thin walls, and a whole bake of a sealed room behind a divider.

#include <gtest/gtest.h>
#include <octree_layout.h>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "bake/convert.h"
#include "core/error.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "test_util.h"

namespace lo {
namespace {

/// A 4^3 grid of unit voxels, each lit by E(n) = 1 from every direction,
/// but for the row x = 0 (no light: the far side of a wall at x = 1.5) and
/// the row x = 1, whose light fills only x >= 1.5 (the wall cuts it).
VolumeLight walledVolume() {
  VolumeLight v;
  v.frame.origin = Vec3{0, 0, 0};
  v.frame.voxelSize = 1.0f;
  v.frame.depth = 2;
  v.shTerms = 9;
  const float y0 = layout::loShBasis(0u, 0, 0, 1);
  for (int x = 1; x < 4; ++x) {
    for (int y = 0; y < 4; ++y) {
      for (int z = 0; z < 4; ++z) {
        v.coords.push_back(Coord{x, y, z});
        v.irradiance.push_back(Vec3(1.0f));
        for (int i = 0; i < 9; ++i) v.sh.push_back(i == 0 ? Vec3(1.0f / y0) : Vec3(0.0f));
        v.segments.push_back(100);
        v.litLower.push_back(Vec3{x == 1 ? 0.5f : 0.0f, 0, 0});
        v.litUpper.push_back(Vec3(1.0f));
      }
    }
  }
  return v;
}

TEST(VolumeOctree, ReadsEachVoxelsLightAndNotBeyondItsLitBox) {
  for (const bool compact : {false, true}) {
    GpuOctreeParams params;
    params.compact = compact;
    const GpuOctree octree = buildVolumeOctree(walledVolume(), params);
    EXPECT_EQ(octree.leafCount, 48u);
    EXPECT_EQ(octree.vdlCount, 48u * 10u);  // a header and 9 SH terms per leaf
    for (const Vec3& n : {Vec3{1, 0, 0}, Vec3{0, -1, 0}, Vec3{0, 0.6f, 0.8f}}) {
      // Lit side: E = 1 from every normal.
      EXPECT_NEAR(volumeIrradiance(octree, Vec3{2.5f, 2, 2}, n).x, 1.0f, 2e-3f);
      EXPECT_NEAR(volumeIrradiance(octree, Vec3{1.8f, 2, 2}, n).y, 1.0f, 2e-3f);
      // Behind the wall, even within the wall's voxel: no light.
      EXPECT_EQ(volumeIrradiance(octree, Vec3{1.2f, 2, 2}, n), Vec3(0.0f));
      EXPECT_EQ(volumeIrradiance(octree, Vec3{0.5f, 2, 2}, n), Vec3(0.0f));
      // Outside the cube: nothing.
      EXPECT_EQ(volumeIrradiance(octree, Vec3{9, 2, 2}, n), Vec3(0.0f));
    }
  }
}

TEST(VolumeOctree, LeavesWhoseLightAgreesMergeAndReadTheSame) {
  GpuOctreeParams params;
  params.volumeTolerance = 0.1f;
  const GpuOctree merged = buildVolumeOctree(walledVolume(), params);
  // The 32 voxels of x = 2, 3 merge into 4 leaves (the rows x = 1 and 0
  // cannot: their parents lack the dark row's children).
  EXPECT_EQ(merged.collapsedVoxels, 32u);
  EXPECT_EQ(merged.leafCount, 16u + 4u);
  for (const Vec3& n : {Vec3{1, 0, 0}, Vec3{0, 0.6f, 0.8f}}) {
    EXPECT_NEAR(volumeIrradiance(merged, Vec3{2.5f, 2, 2}, n).x, 1.0f, 2e-3f);
    EXPECT_NEAR(volumeIrradiance(merged, Vec3{3.9f, 0.1f, 3.9f}, n).x, 1.0f, 2e-3f);
    EXPECT_EQ(volumeIrradiance(merged, Vec3{1.2f, 2, 2}, n), Vec3(0.0f));
  }
  // Light that differs by more than the tolerance keeps its leaves.
  VolumeLight v = walledVolume();
  v.sh[v.sh.size() - 9] = v.sh[v.sh.size() - 9] * 2.0f;  // the last voxel twice as bright
  EXPECT_EQ(buildVolumeOctree(v, params).collapsedVoxels, 24u);
}

TEST(VolumeOctree, AMergedLeafCutByAWallOnItsOutsideKeepsBothSidesRight) {
  // A 4^3 grid lit everywhere with E = 1, but for a wall at x = 0.6 inside
  // the row x = 0 (its light only beyond it). The row merges with x = 1: the
  // joined box starts at 0.3 of the merged leaf.
  VolumeLight v = walledVolume();
  const float y0 = layout::loShBasis(0u, 0, 0, 1);
  for (size_t k = 0; k < v.size(); ++k) v.litLower[k] = Vec3(0.0f);
  for (int y = 0; y < 4; ++y) {
    for (int z = 0; z < 4; ++z) {
      v.coords.push_back(Coord{0, y, z});
      v.irradiance.push_back(Vec3(1.0f));
      for (int i = 0; i < 9; ++i) v.sh.push_back(i == 0 ? Vec3(1.0f / y0) : Vec3(0.0f));
      v.segments.push_back(100);
      v.litLower.push_back(Vec3{0.6f, 0, 0});
      v.litUpper.push_back(Vec3(1.0f));
    }
  }
  GpuOctreeParams params;
  params.volumeTolerance = 0.1f;
  const GpuOctree merged = buildVolumeOctree(v, params);
  EXPECT_EQ(merged.collapsedVoxels, 64u);
  const Vec3 n{0, 1, 0};
  EXPECT_NEAR(volumeIrradiance(merged, Vec3{1.2f, 1.5f, 1.5f}, n).y, 1.0f, 2e-3f);  // lit
  EXPECT_NEAR(volumeIrradiance(merged, Vec3{0.7f, 1.5f, 1.5f}, n).y, 1.0f, 2e-3f);  // just past the wall
  EXPECT_EQ(volumeIrradiance(merged, Vec3{0.3f, 1.5f, 1.5f}, n), Vec3(0.0f));      // behind it
}

TEST(VolumeOctree, RefusesArraysOfOtherLengths) {
  VolumeLight v = walledVolume();
  v.litUpper.pop_back();
  EXPECT_THROW(buildVolumeOctree(v), InputError);
}

TEST(FreeSpace, AnObjectBehindTheDividerOfASealedRoomStaysDark) {
  BakeParams params = test::smallBake(5, 60000);
  const BakeResult baked = bake(test::sealedRooms(), params);
  const VolumeLight& v = baked.grid.volume;
  ASSERT_FALSE(v.empty());
  EXPECT_EQ(v.frame.depth, 3);
  const GpuOctree octree = buildVolumeOctree(v);
  const Vec3 normals[] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  // In the lit room the bounced light reaches every side of an object...
  for (const Vec3& n : normals) {
    EXPECT_GT(volumeIrradiance(octree, Vec3{0.5f, 0.4f, 0.5f}, n).y, 0.0f);
    EXPECT_GT(volumeIrradiance(octree, Vec3{0.95f, 0.5f, 0.5f}, n).y, 0.0f);
  }
  // ...behind the divider nothing does, even right next to it.
  for (const float x : {1.02f, 1.06f, 1.15f, 1.5f, 1.9f}) {
    for (const Vec3& n : normals) {
      EXPECT_EQ(volumeIrradiance(octree, Vec3{x, 0.5f, 0.5f}, n), Vec3(0.0f)) << "x = " << x;
    }
  }
}

TEST(FreeSpace, ConvertKeepsItWhileItIsNoFinerThanTheNewGrid) {
  BakeParams params = test::smallBake(5, 20000);
  const BakeResult baked = bake(test::pointLitRoom(), params);
  ASSERT_EQ(baked.grid.volume.frame.depth, 3);
  ConvertParams to4;
  to4.depth = 4;
  const ConvertResult coarser = convertLightGrid(baked.grid, baked.metadata, to4);
  EXPECT_EQ(coarser.grid.volume.coords, baked.grid.volume.coords);
  EXPECT_EQ(coarser.grid.volume.sh, baked.grid.volume.sh);
  ConvertParams to2;
  to2.depth = 2;
  const ConvertResult tooCoarse = convertLightGrid(baked.grid, baked.metadata, to2);
  EXPECT_TRUE(tooCoarse.grid.volume.empty());
  EXPECT_NE(tooCoarse.method.find("free-space light"), std::string::npos) << tooCoarse.method;
}

}  // namespace
}  // namespace lo
