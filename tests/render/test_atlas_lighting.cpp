// The lighting a Renderer draws with (render/atlas_lighting.h): nothing to
// prepare for the octree; for the atlas, the pages bakeLightmap gives with
// the frames' lookup settings, set on the renderer.

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "lightmap/lightmap_bake.h"
#include "octree/gpu_octree.h"
#include "render/atlas_lighting.h"
#include "render/context.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

TEST(AtlasLighting, ShadeParamsAreTheFrames) {
  RenderParams frame;
  frame.interpolation = false;
  frame.maxVdls = 2;
  frame.normalOffset = 0.25f;
  const OctreeShadeParams s = shadeParamsOf(frame);
  EXPECT_FALSE(s.interpolation);
  EXPECT_EQ(s.maxVdls, 2);
  EXPECT_EQ(s.normalOffset, 0.25f);
}

TEST(AtlasLighting, AtlasIsBakedWithTheGivenSettingsAndSet) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const Scene scene = loadScene(test::dataDir() + "/cornell-box.gltf");
  const GpuOctree octree = test::goldenCornellOctree();
  Renderer renderer(scene, octree);
  LightingParams p;
  EXPECT_FALSE(prepareLighting(renderer, scene, octree, p).has_value());
  EXPECT_FALSE(renderer.hasAtlas());

  p.lighting = Lighting::Atlas;
  p.shade.interpolation = false;
  p.stitchSeams = false;
  const std::optional<LightmapBake> atlas = prepareLighting(renderer, scene, octree, p);
  ASSERT_TRUE(atlas.has_value());
  ASSERT_TRUE(renderer.hasAtlas());
  RenderParams frame;
  frame.width = frame.height = 16;
  frame.lighting = Lighting::Atlas;
  EXPECT_NO_THROW(renderer.render(PinholeCamera::fromScene(scene.cameras.at(0)), frame))
      << "a frame drawn from the atlas set";
  LightmapParams lp;
  lp.atlas.shade.interpolation = false;
  lp.atlas.stitchSeams = false;
  const LightmapBake expected = bakeLightmap(scene, octree, lp);
  ASSERT_EQ(atlas->atlas.pageCount, expected.atlas.pageCount);
  for (int i = 0; i < expected.atlas.pageCount; ++i) {
    EXPECT_EQ(atlas->atlas.irradiance[size_t(i)].rgb, expected.atlas.irradiance[size_t(i)].rgb);
  }
}

TEST(AtlasLighting, PagesBeyondTheCapTakeACoarserTexelAndSaySo) {
  // The Cornell box on pages of 128^2 at the default quarter-voxel texel
  // takes several; capped at 2 pages, the texel grows to fit and no further
  // than the area ratio calls for (H13-5-20: stacked floors grew without
  // bound in `render --lighting atlas`).
  const Scene scene = loadScene(test::dataDir() + "/cornell-box.gltf");
  const GpuOctree octree = test::goldenCornellOctree();
  LightmapParams lp;
  lp.uv.atlasSize = 128;
  const LightmapBake free = bakeLightmap(scene, octree, lp);
  ASSERT_GT(free.uvs.pageCount, 3);
  EXPECT_TRUE(free.note.empty());
  EXPECT_FLOAT_EQ(free.uvs.texelSize, defaultLightmapTexel(octree));
  lp.maxPages = 2;
  const LightmapBake capped = bakeLightmap(scene, octree, lp);
  EXPECT_LE(capped.uvs.pageCount, 2);
  EXPECT_EQ(capped.atlas.pageCount, capped.uvs.pageCount);
  EXPECT_GT(capped.uvs.texelSize, free.uvs.texelSize);
  const float areaRatio = std::sqrt(float(free.uvs.pageCount) / 2.0f);
  EXPECT_LT(capped.uvs.texelSize, 1.5f * areaRatio * free.uvs.texelSize)
      << "no coarser than the pages' area calls for";
  EXPECT_NE(capped.note.find(std::to_string(free.uvs.pageCount) + " pages"), std::string::npos)
      << capped.note;
  // A cap the default already meets changes nothing.
  lp.maxPages = free.uvs.pageCount;
  const LightmapBake met = bakeLightmap(scene, octree, lp);
  EXPECT_TRUE(met.note.empty());
  EXPECT_EQ(met.uvs.texelSize, free.uvs.texelSize);
}

}  // namespace
}  // namespace lo
