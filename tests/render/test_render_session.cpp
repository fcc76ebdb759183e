// The render session (render/render_session.h): the one assembly of a render
// that the commands, the benchmarks, the sweep and Python share. Checked
// against the same render assembled by hand from the stages below it, and on
// what it refuses and frees.

#include <gtest/gtest.h>

#include <cstring>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "core/error.h"
#include "octree/gpu_octree.h"
#include "reference/first_hit.h"
#include "render/context.h"
#include "render/render_session.h"
#include "scene/place_model.h"
#include "test_util.h"

namespace lo {
namespace {

const BakeResult& roomBake() {
  static const BakeResult baked = [] {
    BakeParams bp = test::smallBake(4, 20000);
    return bake(test::pointLitRoom(), bp);
  }();
  return baked;
}

PinholeCamera roomCamera() {
  return PinholeCamera::lookAt(Vec3(0.5f, 0.5f, 0.98f), Vec3(0.5f, 0.35f, 0), 1.2f);
}

double total(const RgbImage& image) {
  double sum = 0;
  for (float v : image.rgb) sum += double(v);
  return sum;
}

RenderSettings smallFrames() {
  RenderSettings s;
  s.frame.width = 48;
  s.frame.height = 36;
  return s;
}

TEST(RenderSession, DefaultsAreTheCommandLines) {
  const RenderSettings s;
  // The defaults docs/render.md documents for `render` and `view`.
  EXPECT_TRUE(s.octree.compact);
  EXPECT_FALSE(s.octree.halfFloat);
  EXPECT_TRUE(s.octree.cosineCorrection);
  EXPECT_FLOAT_EQ(s.octree.tolerance, 0.1f);
  EXPECT_FLOAT_EQ(s.octree.volumeTolerance, 0.4f);
  EXPECT_TRUE(s.frame.interpolation && s.frame.specular && s.frame.reflections);
  EXPECT_EQ(s.frame.lighting, Lighting::Octree);
  // The context's limits reach the octree's parameters.
  GlInfo limits;
  limits.max3DTextureSize = 123;
  limits.max2DTextureSize = 456;
  EXPECT_EQ(s.octreeParams(&limits).max3DTextureSize, 123);
  EXPECT_EQ(s.octreeParams(&limits).max2DTextureSize, 456);
  EXPECT_EQ(s.octreeParams().max3DTextureSize, GpuOctreeParams{}.max3DTextureSize);
}

TEST(RenderSession, DrawsWhatTheStagesAssembledByHandDraw) {
  GlContext* context = test::osmesaContext();
  if (!context) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = test::pointLitRoom();
  const RenderSettings settings = smallFrames();
  RgbImage byHand;
  {
    const GpuOctree octree = buildGpuOctree(roomBake().grid, settings.octreeParams(&context->info()));
    Renderer renderer(scene, octree, settings.renderer);
    byHand = renderer.render(roomCamera(), settings.frame);
  }
  RenderSessionOptions options;
  options.keepOctree = true;
  RenderSession session(scene, roomBake().grid, *context, settings, options);
  const RgbImage viaSession = session.render(roomCamera());
  ASSERT_EQ(viaSession.rgb.size(), byHand.rgb.size());
  EXPECT_EQ(0, std::memcmp(viaSession.rgb.data(), byHand.rgb.data(), byHand.rgb.size() * sizeof(float)));
  EXPECT_GT(total(viaSession), 0.0) << "the room is lit";
  // The kept octree is the one built with the context's limits.
  EXPECT_EQ(session.octreeDepth(), roomBake().grid.frame.depth);
  EXPECT_GT(session.octree().leafCount, 0u);
  EXPECT_FALSE(session.stages().empty());
  EXPECT_EQ(session.stages().front().name, "octree");
}

TEST(RenderSession, FreesTheOctreeAndTheTexelsItIsAllowedTo) {
  GlContext* context = test::osmesaContext();
  if (!context) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = test::pointLitRoom();
  RenderSession session(scene, roomBake().grid, *context, smallFrames());
  EXPECT_EQ(session.octree().leafCount, 0u) << "the CPU copy was kept without keepOctree";
  EXPECT_EQ(session.atlas(), nullptr);
  EXPECT_GT(session.octreeDepth(), 0);
  // The GPU copy draws on.
  EXPECT_GT(total(session.render(roomCamera(), RenderMode::Indirect)), 0.0);
}

TEST(RenderSession, AnEmptyGridDrawsDirectLightAlone) {
  GlContext* context = test::osmesaContext();
  if (!context) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = test::pointLitRoom();
  RenderSession session(scene, VdlGrid{}, *context, smallFrames());
  EXPECT_EQ(session.octreeDepth(), 0);
  const RgbImage indirect = session.render(roomCamera(), RenderMode::Indirect);
  for (float v : indirect.rgb) ASSERT_EQ(v, 0.0f);  // not merely a zero total
  // A level arriving later (a progressive bake) lights it.
  session.setGrid(roomBake().grid, session.settings().octree);
  EXPECT_EQ(session.octreeDepth(), roomBake().grid.frame.depth);
  EXPECT_GT(total(session.render(roomCamera(), RenderMode::Indirect)), 0.0);
}

TEST(RenderSession, AddedObjectsRefuseTheAtlasAndTakeTheFreeSpaceLight) {
  GlContext* context = test::osmesaContext();
  if (!context) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = test::pointLitRoom();
  Placement p;
  p.at = Vec3d(0.5, 0.3, 0.5);
  p.scale = 0.1f;
  placeModel(scene, loadScene(test::dataDir() + "/models/sphere.obj"), p);
  RenderSettings atlas = smallFrames();
  atlas.frame.lighting = Lighting::Atlas;
  EXPECT_THROW(RenderSession(scene, roomBake().grid, *context, atlas), InputError);

  ASSERT_FALSE(roomBake().grid.volume.empty());
  RenderSession lit(scene, roomBake().grid, *context, smallFrames());
  EXPECT_TRUE(lit.renderer().hasFreeSpaceLight());
  EXPECT_TRUE(lit.warnings().empty());
  VdlGrid noVolume = roomBake().grid;
  noVolume.volume = {};
  RenderSessionOptions options;
  options.gridName = "old.vdb";
  RenderSession unlit(scene, noVolume, *context, smallFrames(), options);
  EXPECT_FALSE(unlit.renderer().hasFreeSpaceLight());
  ASSERT_EQ(unlit.warnings().size(), 1u);
  EXPECT_NE(unlit.warnings()[0].find("old.vdb holds no free-space light"), std::string::npos);
  // The sphere takes another light in each.
  const PinholeCamera atSphere = PinholeCamera::lookAt(Vec3(0.5f, 0.5f, 0.98f), Vec3(0.5f, 0.3f, 0.5f), 0.3f);
  const RgbImage withVolume = lit.render(atSphere, RenderMode::Indirect);
  const RgbImage withoutVolume = unlit.render(atSphere, RenderMode::Indirect);
  EXPECT_NE(0, std::memcmp(withVolume.rgb.data(), withoutVolume.rgb.data(),
                           withVolume.rgb.size() * sizeof(float)));

  // The CPU lookup reads the same two octrees.
  const LookupOctrees octrees = buildLookupOctrees(scene, roomBake().grid, smallFrames());
  EXPECT_GT(octrees.surface.leafCount, 0u);
  EXPECT_GT(octrees.volume.depth, 0);
  EXPECT_TRUE(buildLookupOctrees(test::pointLitRoom(), roomBake().grid, smallFrames()).volume.depth == 0);
}

}  // namespace
}  // namespace lo
