// Render to atlas (paper §4.2.3) in the GL renderer: the indirect light read
// from the lightmap atlas the octree was baked into (src/lightmap) agrees with
// the octree lookup per fragment. The bound: 2% relative RMSE on the
// Cornell box (measured 0.8% per pixel in mode indirect).

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "core/error.h"
#include "image/compare.h"
#include "image/image.h"
#include "lightmap/lightmap_bake.h"
#include "octree/gpu_octree.h"
#include "render/context.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

TEST(AtlasRender, CornellBoxAtlasEqualsOctree) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const Scene scene = loadScene(test::dataDir() + "/cornell-box.gltf");
  const GpuOctree octree = test::goldenCornellOctree();
  Renderer renderer(scene, octree);
  EXPECT_FALSE(renderer.hasAtlas());
  const PinholeCamera camera = PinholeCamera::fromScene(scene.cameras.at(0));
  RenderParams p;
  p.width = p.height = 128;
  p.mode = RenderMode::Indirect;
  EXPECT_THROW(
      {
        RenderParams atlas = p;
        atlas.lighting = Lighting::Atlas;
        renderer.render(camera, atlas);
      },
      InputError)
      << "atlas lighting without an atlas";
  const RgbImage fromOctree = renderer.render(camera, p);
  LightmapParams lp;
  lp.atlas.shade.interpolation = p.interpolation;
  const LightmapBake atlas = bakeLightmap(scene, octree, lp);
  renderer.setAtlas(atlas.uvs, atlas.atlas);
  ASSERT_TRUE(renderer.hasAtlas());
  EXPECT_EQ(renderer.atlasBytes(), size_t(atlas.atlas.width) * atlas.atlas.height * 8);
  p.lighting = Lighting::Atlas;
  const RgbImage fromAtlas = renderer.render(camera, p);
  CompareParams cp;
  cp.ignoreBackground = true;
  const CompareResult c = compareImages(fromAtlas, fromOctree, cp);
  if (c.luminance.relRmse > 0.02) {
    const std::string dir = test::outputDir("atlas_render");
    writePng(dir + "/octree.png", fromOctree, 2.0f);
    writePng(dir + "/atlas.png", fromAtlas, 2.0f);
    writePng(dir + "/difference.png", differenceImage(fromAtlas, fromOctree, cp), 0.0f);
    ADD_FAILURE() << "atlas vs octree: " << c.ToString() << " (images in " << dir << ")";
  }
  EXPECT_GT(c.comparedPixels, 128u * 128u / 2);
}

// The atlas UV source: a scene whose TEXCOORD_1 overlaps is refused by
// default, naming the problem and the way out, and charted with --uv auto.
TEST(AtlasRender, BadTexcoord1IsRefusedUnlessAutoIsAsked) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  scene.texcoords1 = {0, 0, 1, 0, 1, 1, 0, 1};
  scene.texcoords1[6] = 1.0f;  // corner 3 at (1, 0.5): triangle 1 folds over triangle 0
  scene.texcoords1[7] = 0.5f;
  scene.lights.push_back(Light{});
  VdlGrid empty;  // no voxels: the UV choice is what is tested
  empty.frame.depth = 2;
  empty.frame.voxelSize = 0.5f;
  const GpuOctree octree = buildGpuOctree(empty);
  // The overlapping TEXCOORD_1 is refused.
  test::expectRefusal([&] { bakeLightmap(scene, octree); }, {"TEXCOORD_1", "--uv auto"});
  LightmapParams automatic;
  automatic.uvSource = UvSource::Charts;
  const LightmapBake charted = bakeLightmap(scene, octree, automatic);
  EXPECT_FALSE(charted.fromTexcoord1);
  EXPECT_EQ(charted.uvs.trianglePage.size(), 2u);
}

}  // namespace
}  // namespace lo
