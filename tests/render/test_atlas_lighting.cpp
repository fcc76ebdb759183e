// The lighting a Renderer draws with (render/atlas_lighting.h): nothing to
// prepare for the octree; for the atlas, the pages bakeLightmap gives with
// the frames' lookup settings, set on the renderer.

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace lo
