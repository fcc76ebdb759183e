#include "gather/gather_fixture.h"

#include <gtest/gtest.h>

#include <algorithm>

#include "core/rng.h"
#include "test_util.h"

namespace lo::test {

Scene unitFloor() {
  Scene scene = oneMaterialScene();
  addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);
  return scene;
}

Scene cornellLikeBox() {
  return boxWithTwoBlocks({{0.13f, 0.0f, 0.097f}, {0.43f, 0.3f, 0.41f}},
                          {{0.551f, 0.0f, 0.523f}, {0.847f, 0.61f, 0.83f}});
}

std::vector<Photon> uniformPhotons(const Scene& scene, size_t count, uint64_t seed) {
  std::vector<double> cdf;
  double total = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    total += scene.triangleArea(t);
    cdf.push_back(total);
  }
  std::vector<Photon> photons(count);
  for (size_t i = 0; i < count; ++i) {
    Rng rng(seed, i);
    double u = double(rng.uniform()) * total;
    size_t t = size_t(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin());
    t = std::min(t, scene.triangleCount() - 1);
    float b1 = rng.uniform(), b2 = rng.uniform();
    if (b1 + b2 > 1) {
      b1 = 1 - b1;
      b2 = 1 - b2;
    }
    const Vec3& a = scene.positions[scene.indices[3 * t]];
    const Vec3& b = scene.positions[scene.indices[3 * t + 1]];
    const Vec3& c = scene.positions[scene.indices[3 * t + 2]];
    Photon& p = photons[i];
    p.position = a + (b - a) * b1 + (c - a) * b2;
    p.normal = scene.faceNormal(t);
    p.direction = p.normal;
    p.power = Vec3(1.0f / float(count));
    p.bounce = 1;
  }
  return photons;
}

SurfaceGrid gridFor(const Scene& scene, int depth, const std::vector<Photon>& photons) {
  GridParams gp;
  gp.depth = depth;
  SurfaceGrid grid = buildSurfaceGrid(scene, gp);
  EXPECT_EQ(splatPhotons(grid, photons), 0u);
  return grid;
}

std::vector<uint32_t> sorted(std::vector<uint32_t> v) {
  std::sort(v.begin(), v.end());
  return v;
}

void GatherTest::spreadPhotons(size_t count, uint64_t seed, int depth) {
  photons = uniformPhotons(scene, count, seed);
  grid = gridFor(scene, depth, photons);
}

}  // namespace lo::test
