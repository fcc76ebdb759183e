// Renderer::setOctree (the progressive viewer's level swap): an empty octree
// gives no indirect light, and swapping a level in gives the same pixels as a
// renderer built with that level from the start.

#include <gtest/gtest.h>

#include <algorithm>
#include <memory>

#include "bake/bake.h"
#include "core/error.h"
#include "octree/gpu_octree.h"
#include "render/context.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

GpuOctree bakeOctree(const Scene& scene, const std::vector<Photon>& photons, int depth) {
  LevelParams params;
  params.grid.depth = depth;
  params.gather.k = 40;
  return buildGpuOctree(bakeLevel(scene, photons, params));
}

/// `stored` photons traced in `scene`.
std::vector<Photon> photonsIn(const Scene& scene, size_t stored) {
  PhotonParams pp;
  pp.storedPhotons = stored;
  return tracePhotons(scene, pp).photons;
}

/// What the tests draw: `width` x `height` pixels of indirect light.
RenderParams indirectParams(int width, int height) {
  RenderParams params;
  params.width = width;
  params.height = height;
  params.mode = RenderMode::Indirect;
  return params;
}

/// The point-lit room from just inside its front wall.
PinholeCamera roomView() {
  return PinholeCamera::lookAt(Vec3(0.5f, 0.5f, 0.95f), Vec3(0.5f, 0.4f, 0), 1.2f);
}

float maxValue(const RgbImage& image) {
  float m = 0;
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    m = std::max({m, image.rgb[i], image.rgb[i + 1], image.rgb[i + 2]});
  }
  return m;
}

TEST(RendererSetOctree, SwappedLevelRendersLikeAFreshRenderer) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = test::pointLitRoom();
  std::vector<Photon> photons = photonsIn(scene, 20000);
  GpuOctree coarse = bakeOctree(scene, photons, 3);
  GpuOctree fine = bakeOctree(scene, photons, 4);

  const RenderParams params = indirectParams(64, 48);
  const PinholeCamera camera = roomView();

  Renderer swapped(scene, GpuOctree(), {});
  EXPECT_EQ(maxValue(swapped.render(camera, params)), 0.0f) << "empty octree: no indirect light";
  swapped.setOctree(coarse);
  swapped.setOctree(fine);
  RgbImage a = swapped.render(camera, params);
  EXPECT_GT(maxValue(a), 0.0f);

  Renderer fresh(scene, fine, {});
  RgbImage b = fresh.render(camera, params);
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  EXPECT_EQ(a.rgb, b.rgb);

  // Depth 3 and depth 4 differ somewhere: the swap did change the textures.
  swapped.setOctree(coarse);
  EXPECT_NE(swapped.render(camera, params).rgb, b.rgb);
  swapped.setOctree(GpuOctree());
  EXPECT_EQ(maxValue(swapped.render(camera, params)), 0.0f);
}

TEST(RendererSetOctree, TooLargeForTheLimitsKeepsTheOldOctree) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = test::pointLitRoom();
  std::vector<Photon> photons = photonsIn(scene, 5000);
  GpuOctree octree = bakeOctree(scene, photons, 3);
  RendererParams limits;
  limits.max3DTextureSize = std::max({octree.poolWidth(), octree.poolHeight(), octree.poolDepth()});
  limits.max2DTextureSize = 16384;
  Renderer renderer(scene, octree, limits);
  const RenderParams params = indirectParams(32, 24);
  const PinholeCamera camera = roomView();
  RgbImage before = renderer.render(camera, params);
  GpuOctree larger = bakeOctree(scene, photons, 5);
  ASSERT_GT(std::max({larger.poolWidth(), larger.poolHeight(), larger.poolDepth()}),
            limits.max3DTextureSize);
  EXPECT_THROW(renderer.setOctree(larger), InputError);
  EXPECT_EQ(renderer.render(camera, params).rgb, before.rgb);
}

}  // namespace
}  // namespace lo
