// Surface layers (gather/gather.h): the gather of one layer against the
// brute force, the layers a voxel's photons give, and the occlusion test
// that keeps photons behind a wall out of a layer's disc.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "gather/gather.h"
#include "gather/gather_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

using namespace test;  // gather_fixture.h, test_util.h

// Surface layers: the gather of one layer (fixed normal, photons within the
// layer cosine) equals the brute force over every photon, at the layers the
// voxels' own photons give.
TEST_F(GatherLayers, LayerGatherMatchesBruteForce) {
  scene = cornellLikeBox();
  spreadPhotons(60000, 5, 5);
  GatherParams p;
  p.k = 60;
  Gatherer gatherer(grid, photons, p);
  LayerParams lp;
  lp.minPhotons = 3;  // about 8 photons per voxel face here
  SurfaceLayer layers[3];
  size_t checked = 0, layered = 0;
  GatherResult g;
  for (size_t v = 0; v < grid.size(); v += 3) {
    const int n = gatherer.findSurfaceLayers(v, lp, layers);
    layered += n >= 2;
    for (int l = 0; l < n; ++l) {
      gatherer.gatherLayer(v, layers[l].point, layers[l].normal, g);
      const GatherResult b =
          gatherLayerBruteForce(grid, photons, layers[l].point, layers[l].normal, p);
      ASSERT_EQ(sorted(g.photons), sorted(b.photons)) << "voxel " << v << " layer " << l;
      EXPECT_EQ(g.radius, b.radius);
      EXPECT_EQ(g.normal, layers[l].normal);
      for (uint32_t i : g.photons) {
        ASSERT_GT(dot(photons[i].normal, layers[l].normal), p.layerCosine);
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 100u);
  EXPECT_GT(layered, 10u) << "the box's edges give voxels with two layers";
}

// Layer detection in one voxel holding a floor and a thin wall (two quads
// facing away from each other): the floor is one layer; the wall one per lit
// side (both here); a surface whose photons are too few keeps the side its
// winding faces.
TEST_F(GatherLayers, FindsTheSurfacesOfAVoxelAndTheirLitSides) {
  scene = oneMaterialScene();
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);           // floor
  test::addQuad(scene, {0.53f, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 0);       // wall, +x face
  test::addQuad(scene, {0.53f, 0, 0}, {0, 0, 1}, {0, 1, 0}, {-1, 0, 0}, 0);      // wall, -x face
  auto add = [&](Vec3 p, Vec3 n, int count) {
    for (int i = 0; i < count; ++i) {
      Photon ph;
      ph.position = p + Vec3{0, 0.001f * float(i % 7), 0.001f * float(i % 5)};
      ph.normal = n;
      ph.direction = n;
      ph.power = Vec3(1.0f);
      photons.push_back(ph);
    }
  };
  // Voxel size 1.02 / 16: all in the voxel holding (0.52, 0.01, 0.51).
  add({0.52f, 0.0f, 0.51f}, {0, 1, 0}, 40);   // floor
  add({0.53f, 0.02f, 0.51f}, {1, 0, 0}, 30);  // wall, lit from +x
  add({0.53f, 0.02f, 0.51f}, {-1, 0, 0}, 20); // and from -x
  grid = gridFor(scene, 4, photons);
  const int64_t voxel = grid.find(grid.frame.coordOf({0.52f, 0.01f, 0.51f}));
  ASSERT_GE(voxel, 0);
  ASSERT_EQ(grid.orientationStart[size_t(voxel) + 1] - grid.orientationStart[size_t(voxel)], 3u)
      << "floor, and the wall's two faces";
  Gatherer gatherer(grid, photons, GatherParams{});
  SurfaceLayer layers[3];
  LayerParams lp;
  auto normals = [&](int n) {
    std::vector<Vec3> out;
    for (int l = 0; l < n; ++l) out.push_back(layers[l].normal);
    return out;
  };
  auto has = [](const std::vector<Vec3>& v, Vec3 n) {
    return std::any_of(v.begin(), v.end(), [&](const Vec3& m) { return length(m - n) < 1e-5f; });
  };
  int n = gatherer.findSurfaceLayers(size_t(voxel), lp, layers);
  ASSERT_EQ(n, 3);
  EXPECT_TRUE(has(normals(n), {0, 1, 0}));
  EXPECT_TRUE(has(normals(n), {1, 0, 0}));
  EXPECT_TRUE(has(normals(n), {-1, 0, 0}));
  for (int l = 0; l < n; ++l) {
    // Each layer's point lies on its surface.
    if (layers[l].normal.y > 0.5f) {
      EXPECT_NEAR(layers[l].point.y, 0.0f, 1e-5f);
    }
    if (std::fabs(layers[l].normal.x) > 0.5f) {
      EXPECT_NEAR(layers[l].point.x, 0.53f, 1e-5f);
    }
  }
  lp.maxLayers = 2;
  EXPECT_EQ(gatherer.findSurfaceLayers(size_t(voxel), lp, layers), 2);
  lp.maxLayers = 3;
  lp.minShare = 0.4f;  // neither side of the wall holds 40%: it keeps one layer
  n = gatherer.findSurfaceLayers(size_t(voxel), lp, layers);
  EXPECT_EQ(n, 2);
  EXPECT_TRUE(has(normals(n), {0, 1, 0}));
}

// Gather occlusion: a floor split by a thin wall, photons on one side only.
// Without the occlusion test the dark side's voxels next to the wall gather
// the lit side's photons; with it (a segment test that knows the wall plane
// x = 0.5) they gather none.
TEST_F(GatherLayers, OcclusionKeepsPhotonsBehindAWallOut) {
  scene = unitFloor();
  test::addQuad(scene, {0.5f, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 0);
  for (const Photon& p : uniformPhotons(scene, 40000, 9)) {
    if (p.position.x > 0.5f && p.normal.y > 0.5f) photons.push_back(p);  // the lit floor
  }
  grid = gridFor(scene, 5, photons);
  GatherParams p;
  p.k = 100;
  p.radius = 0.08f;  // 2.5 voxels: reaches across the wall
  auto crossesWall = [](const Vec3& a, const Vec3& b) {
    return (a.x - 0.5f) * (b.x - 0.5f) < 0 && std::min(a.y, b.y) < 1.0f;
  };
  size_t leaking = 0, blocked = 0, dark = 0;
  GatherResult g;
  for (int occlusion = 0; occlusion < 2; ++occlusion) {
    GatherParams q = p;
    if (occlusion) q.blocked = crossesWall;
    Gatherer gatherer(grid, photons, q);
    for (size_t v = 0; v < grid.size(); ++v) {
      const Vec3& c = grid.centroids[v];
      if (!(c.x < 0.49f && c.y < 0.01f && grid.normals[v].y > 0.9f)) continue;  // dark floor
      gatherer.gather(v, g);
      if (occlusion) {
        blocked += g.photons.empty();
        ++dark;
      } else {
        leaking += !g.photons.empty();
      }
    }
  }
  EXPECT_GT(leaking, 10u) << "without occlusion the radius reaches across the wall";
  EXPECT_EQ(blocked, dark) << "with it, no dark voxel gathers a lit photon";
}

}  // namespace
}  // namespace lo
