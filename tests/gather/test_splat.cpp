// splatPhotons (gather/gather.h): the photon bins of the surface grid.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "gather/gather.h"
#include "test_util.h"

namespace lo {
namespace {

TEST(Splat, BinsPhotonsInActiveVoxels) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {0, 0.45f, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  GridParams gp;
  gp.depth = 4;
  SurfaceGrid grid = buildSurfaceGrid(scene, gp);
  const float vs = grid.frame.voxelSize;
  std::vector<Photon> photons;
  for (size_t i = 0; i < 5000; ++i) {
    Rng rng(2, i);
    Photon ph;
    ph.position = {rng.uniform(), 0.45f, 0.1f + 0.9f * rng.uniform()};
    photons.push_back(ph);
  }
  // Off the surface into an inactive voxel (0.3 voxel above the plane's voxel
  // layer), and far away / non-finite: the first moves, the others drop.
  const Coord planeVoxel = grid.frame.coordOf({0.41f, 0.45f, 0.63f});
  const Bounds3 pb = grid.frame.voxelBounds(planeVoxel);
  Photon stray;
  stray.position = {0.41f, pb.upper.y + 0.3f * vs, 0.63f};
  ASSERT_EQ(grid.find(grid.frame.coordOf(stray.position)), -1);
  photons.push_back(stray);
  Photon far;
  far.position = {0.41f, pb.upper.y + 1.5f * vs, 0.63f};
  photons.push_back(far);
  Photon nan;
  nan.position = {NAN, 0, 0};
  photons.push_back(nan);

  EXPECT_EQ(splatPhotons(grid, photons), 2u);
  ASSERT_EQ(grid.binStart.size(), grid.size() + 1);
  EXPECT_EQ(grid.binStart.back(), photons.size() - 2);
  EXPECT_NEAR(grid.binMargin, 0.3f * vs, 1e-3f * vs);
  std::vector<int> seen(photons.size(), 0);
  for (size_t v = 0; v < grid.size(); ++v) {
    for (uint32_t j = grid.binStart[v]; j < grid.binStart[v + 1]; ++j) {
      const uint32_t i = grid.binPhotons[j];
      if (j > grid.binStart[v]) {
        ASSERT_LT(grid.binPhotons[j - 1], i);  // photon order
      }
      ++seen[i];
      if (i < 5000) {
        ASSERT_EQ(grid.frame.coordOf(photons[i].position), grid.coords[v]);
      } else {
        EXPECT_EQ(grid.coords[v], planeVoxel);
      }
    }
  }
  for (size_t i = 0; i < photons.size(); ++i) EXPECT_EQ(seen[i], i < 5001 ? 1 : 0) << i;
}

}  // namespace
}  // namespace lo
