// The free-space light's estimator (cluster/volume_light.h): track lengths
// checked against hand-computed values, and its bytes against the threads.

#include <gtest/gtest.h>
#include <octree_layout.h>

#include <cmath>
#include <vector>

#include "cluster/volume_light.h"
#include "core/error.h"
#include "core/rng.h"
#include "core/threads.h"

namespace lo {
namespace {

GridFrame unitFrame(int depth) {
  GridFrame f;
  f.origin = Vec3{0, 0, 0};
  f.voxelSize = 1.0f;
  f.depth = depth;
  return f;
}

TEST(VolumeLight, OneRayLeavesItsTrackLengthInEachVoxelItCrosses) {
  // A ray along +x through the row y = z = 0 of a 4^3 grid of unit voxels:
  // each voxel holds P * 1 / 1 of fluence from -x, whatever lies beyond.
  const std::vector<PhotonSegment> rays = {{{-3, 0.5f, 0.25f}, {9, 0.5f, 0.25f}, {2, 1, 0.5f}}};
  VolumeLightParams params;
  params.levels = 0;
  const VolumeLight v = buildVolumeLight(rays, unitFrame(2), params);
  ASSERT_EQ(v.size(), 4u);
  const float y0 = layout::loShBasis(0u, 1, 0, 0), y3 = layout::loShBasis(3u, -1, 0, 0);
  for (size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(v.coords[k], (Coord{int(k), 0, 0}));
    EXPECT_NEAR(v.irradiance[k].x, 2.0f / 4, 1e-5f);  // fluence / 4
    EXPECT_NEAR(v.irradiance[k].z, 0.5f / 4, 1e-5f);
    EXPECT_NEAR(v.shOf(k)[0].x, 2.0f * y0 * float(kPi), 1e-4f);
    EXPECT_NEAR(v.shOf(k)[3].x, 2.0f * y3 * float(2 * kPi / 3), 1e-4f);
    EXPECT_EQ(v.segments[k], 1.0f);
    // The lit box: the whole x extent, the ray's y and z.
    EXPECT_NEAR(v.litLower[k].x, 0.0f, 1e-6f);
    EXPECT_NEAR(v.litUpper[k].x, 1.0f, 1e-6f);
    EXPECT_NEAR(v.litLower[k].y, 0.5f, 1e-6f);
    EXPECT_NEAR(v.litUpper[k].z, 0.25f, 1e-6f);
  }
}

TEST(VolumeLight, ARayEndingInAVoxelLightsItUpToItsEnd) {
  // From a surface at x = 1.5 up to a wall at x = 2.75: voxel 1 holds half
  // a voxel of track, voxel 2 three quarters, and their boxes stop there.
  const std::vector<PhotonSegment> rays = {{{1.5f, 0.5f, 0.5f}, {2.75f, 0.5f, 0.5f}, {1, 1, 1}}};
  VolumeLightParams params;
  params.levels = 0;
  const VolumeLight v = buildVolumeLight(rays, unitFrame(2), params);
  ASSERT_EQ(v.size(), 2u);
  EXPECT_NEAR(v.irradiance[0].x, 0.5f / 4, 1e-5f);
  EXPECT_NEAR(v.irradiance[1].x, 0.75f / 4, 1e-5f);
  EXPECT_NEAR(v.litLower[0].x, 0.5f, 1e-6f);
  EXPECT_NEAR(v.litUpper[1].x, 0.75f, 1e-6f);
}

TEST(VolumeLight, TheFluenceOfAVoxelIsTheTrackLengthOverItsVolume) {
  // Many random rays through a coarse grid: the sum over voxels of fluence
  // times volume is the sum of power times length inside the cube.
  Rng rng(7, 0);
  std::vector<PhotonSegment> rays;
  double expected = 0;
  for (int i = 0; i < 2000; ++i) {
    Vec3 a{rng.uniform() * 8, rng.uniform() * 8, rng.uniform() * 8};
    Vec3 b{rng.uniform() * 8, rng.uniform() * 8, rng.uniform() * 8};
    rays.push_back({a, b, {1, 1, 1}});
    expected += double(length(b - a));  // both ends inside the 8^3 cube
  }
  VolumeLightParams params;
  params.levels = 1;
  GridFrame surface = unitFrame(3);  // 8 voxels of 1; the free-space grid: 4 of 2
  const VolumeLight v = buildVolumeLight(rays, surface, params);
  EXPECT_EQ(v.frame.depth, 2);
  EXPECT_EQ(v.frame.voxelSize, 2.0f);
  double sum = 0;
  for (const Vec3& e : v.irradiance) sum += 4.0 * double(e.x) * 8.0;
  EXPECT_NEAR(sum, expected, 1e-4 * expected);
}

TEST(VolumeLight, SameBytesWhateverTheThreadsAndSlabs) {
  Rng rng(3, 0);
  std::vector<PhotonSegment> rays;
  for (int i = 0; i < 20000; ++i) {
    rays.push_back({{rng.uniform() * 20 - 2, rng.uniform() * 20 - 2, rng.uniform() * 20 - 2},
                    {rng.uniform() * 20 - 2, rng.uniform() * 20 - 2, rng.uniform() * 20 - 2},
                    {rng.uniform(), rng.uniform(), rng.uniform()}});
  }
  // The slabs follow the machine's cores (tbb::this_task_arena), which a
  // thread limit does not change: both are varied.
  auto bake = [&](int threads, int slabs) {
    ThreadLimit limit(threads);
    VolumeLightParams params;
    params.shTerms = 9;
    params.slabs = slabs;
    return buildVolumeLight(rays, unitFrame(5), params);
  };
  const VolumeLight one = bake(1, 1), many = bake(4, 7);
  const VolumeLight other = bake(2, 32);
  ASSERT_EQ(other.sh, one.sh);
  ASSERT_EQ(other.litUpper, one.litUpper);
  ASSERT_EQ(one.size(), many.size());
  ASSERT_GT(one.size(), 100u);
  for (size_t k = 0; k < one.size(); ++k) {
    ASSERT_EQ(one.coords[k], many.coords[k]);
    ASSERT_EQ(one.irradiance[k], many.irradiance[k]);
    ASSERT_EQ(one.litLower[k], many.litLower[k]);
  }
  ASSERT_EQ(one.sh, many.sh);
}

TEST(VolumeLight, RefusesBadSettings) {
  VolumeLightParams params;
  params.shTerms = 5;
  EXPECT_THROW(buildVolumeLight({}, unitFrame(3), params), InputError);
}

}  // namespace
}  // namespace lo
