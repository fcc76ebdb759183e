// Objects added after the bake (render --add): lit by the free-space light
// in the GL renderer as the C++ lookup says, and moved (view's M keys) to
// the picture of a scene that placed them there from the start.

#include <gtest/gtest.h>

#include <cmath>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "core/error.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "raytrace/ray_tracer.h"
#include "reference/path_tracer.h"
#include "render/context.h"
#include "render/renderer.h"
#include "scene/place_model.h"
#include "test_util.h"

namespace lo {
namespace {

/// `scene` with the project's sphere (radius `r`) added at `at`.
Scene withSphere(Scene scene, const Vec3& at, float r) {
  Placement p;
  p.at = Vec3d(at);
  p.scale = r;
  placeModel(scene, loadScene(test::dataDir() + "/models/sphere.obj"), p);
  return scene;
}

/// The point-lit unit room with the sphere at `at`.
Scene roomWithSphere(const Vec3& at, float r) { return withSphere(test::pointLitRoom(), at, r); }

double meanAbs(const RgbImage& a, const RgbImage& b) {
  double sum = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i) sum += std::fabs(double(a.rgb[i]) - double(b.rgb[i]));
  return sum / double(a.rgb.size());
}

double mean(const RgbImage& a) {
  double sum = 0;
  for (float v : a.rgb) sum += double(v);
  return sum / double(a.rgb.size());
}

/// A bake of `scene` and the octrees the renderer draws it with: the
/// surfaces' light and the free-space light the added objects read.
struct BakedOctrees {
  BakeResult baked;
  GpuOctree surface, volume;
};

BakedOctrees bakeOctrees(const Scene& scene, int depth, size_t photons) {
  BakeParams bp = test::smallBake(depth, photons);
  BakedOctrees b{bake(scene, bp), {}, {}};
  b.surface = buildGpuOctree(b.baked.grid);
  b.volume = buildVolumeOctree(b.baked.grid.volume);
  return b;
}

/// What the tests draw: `width` x `height` pixels without reflections.
RenderParams viewParams(int width, int height) {
  RenderParams params;
  params.width = width;
  params.height = height;
  params.reflections = false;
  return params;
}

TEST(AddedObjects, PlacementJoinsTheModelAndMarksItsMaterials) {
  const Scene room = test::pointLitRoom();
  const Scene scene = roomWithSphere(Vec3(0.7f, 0.3f, 0.6f), 0.1f);
  EXPECT_EQ(scene.movingMaterialsFrom, room.materials.size());
  EXPECT_GT(scene.triangleCount(), room.triangleCount());
  Bounds3 sphere;
  for (size_t v = room.positions.size(); v < scene.positions.size(); ++v) sphere.extend(scene.positions[v]);
  EXPECT_NEAR(sphere.lower.x, 0.6f, 1e-4f);
  EXPECT_NEAR(sphere.upper.y, 0.4f, 1e-4f);
  EXPECT_EQ(scene.lights.size(), room.lights.size());
  EXPECT_THROW(parsePlacement("1,2"), InputError);
  EXPECT_THROW(parsePlacement("1,2,nan"), InputError);
  EXPECT_THROW(parsePlacement("1,2,3,0,-1"), InputError);
  EXPECT_NEAR(parsePlacement("1,2,3,90,2").yawDegrees, 90.0f, 0.0f);
}

// Each part of --at is checked by itself, and named (N12, N13 of the seventh
// hostile list): a scale of 1e-300 was taken (0 in single precision, a model
// of no size), and a yaw of 1e300 was refused as "a vertex at [-nan, 0, -nan]".
TEST(AddedObjects, EachPartOfThePlacementIsCheckedByName) {
  auto refusal = [](const std::string& text) -> std::string {
    try {
      parsePlacement(text);
    } catch (const InputError& e) {
      return e.what();
    }
    return "taken";
  };
  EXPECT_EQ(refusal("0,0,0,0,1e-300"), "--at '0,0,0,0,1e-300': the scale 1e-300 must lie in "
                                        "(0, 1e6], at least 1.2e-38 (what single precision holds)");
  EXPECT_EQ(refusal("0,0,0,1e300"),
            "--at '0,0,0,1e300': the yaw 1e300 must lie from -360 to 360 degrees");
  EXPECT_EQ(refusal("0,-2e12,0"), "--at '0,-2e12,0': y -2e12 lies beyond 1e+12 scene units");
  // Decimal only, as every numeric flag (strtod read "0x10" as a scale of 16).
  EXPECT_EQ(refusal("0,0.2,0,0,0x10"), "--at '0,0.2,0,0,0x10': '0x10' is not a finite decimal number");
  EXPECT_EQ(refusal("0x1p3,0,0"), "--at '0x1p3,0,0': '0x1p3' is not a finite decimal number");
  EXPECT_EQ(refusal("1,2,3,-360,1e-30"), "taken");
  EXPECT_EQ(parsePlacement("1,2,3,-360,1e-30").scale, 1e-30f);
}

TEST(AddedObjects, MovedObjectsDrawAsIfPlacedThere) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const BakedOctrees b = bakeOctrees(test::pointLitRoom(), 4, 30000);
  ASSERT_FALSE(b.baked.grid.volume.empty());
  const GpuOctree& octree = b.surface;
  const GpuOctree& volume = b.volume;

  const RenderParams params = viewParams(64, 48);
  const PinholeCamera camera =
      PinholeCamera::lookAt(Vec3(0.5f, 0.5f, 0.98f), Vec3(0.5f, 0.35f, 0), 1.2f);
  // Opaque; and see-through with both sides drawn, moved from in front of
  // a see-through pane to behind it: the sphere's own triangles are drawn
  // back to front, sorted each frame by centroids that must move with them.
  // (Blended ranges are sorted within themselves and drawn in material
  // order, so the pane and the sphere keep their order wherever they are.)
  for (const bool blended : {false, true}) {
    auto sphereAt = [blended](const Vec3& at) {
      Scene room = test::pointLitRoom();
      if (blended) {
        Material pane;
        pane.baseColor = Vec3(0.9f, 0.1f, 0.1f);
        pane.alphaMode = AlphaMode::Blend;
        pane.baseAlpha = 0.5f;
        pane.doubleSided = true;
        room.materials.push_back(pane);
        test::addQuad(room, {0.05f, 0.05f, 0.6f}, {0.9f, 0, 0}, {0, 0.9f, 0}, {0, 0, 1},
                      int(room.materials.size()) - 1);
      }
      Scene scene = withSphere(room, at, 0.1f);
      if (blended) {
        Material& m = scene.materials[scene.movingMaterialsFrom];
        m.baseColor = Vec3(0.1f, 0.1f, 0.9f);
        m.alphaMode = AlphaMode::Blend;
        m.baseAlpha = 0.5f;
        m.doubleSided = true;  // its far side seen through its near side
      }
      return scene;
    };
    // Blended: moved across the view by more than a right angle as the eye
    // sees it (a convex object's triangles sort differently only then).
    const Vec3 from = blended ? Vec3(0.15f, 0.85f, 0.88f) : Vec3(0.75f, 0.25f, 0.3f);
    const Vec3 offset = blended ? Vec3(0.6f, -0.55f, -0.38f) : Vec3(-0.1f, 0.05f, 0.25f);
    Renderer moved(sphereAt(from), octree, {});
    moved.setFreeSpaceLight(volume);
    ASSERT_TRUE(moved.hasAddedObjects());
    const RgbImage before = moved.render(camera, params);
    moved.moveAddedObjects(offset);
    const RgbImage after = moved.render(camera, params);

    Renderer placed(sphereAt(from + offset), octree, {});
    placed.setFreeSpaceLight(volume);
    const RgbImage there = placed.render(camera, params);
    // The same picture up to the rounding of two render spaces (the scene's
    // bounds, and so their centre, differ by the sphere's place).
    EXPECT_LT(meanAbs(after, there), 1e-3 * mean(there)) << (blended ? "blended" : "opaque");
    EXPECT_GT(meanAbs(after, before), 0.02 * mean(there)) << "the sphere did not move";
  }
}

TEST(AddedObjects, TheFreeSpaceLightLightsThemAsTheCppLookupSays) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const BakedOctrees b = bakeOctrees(test::pointLitRoom(), 4, 30000);
  const GpuOctree& volume = b.volume;
  // A large white sphere filling the view: its indirect radiance is a / pi
  // times the free-space irradiance at its surface (diffuse, albedo 0.8).
  const Vec3 centre(0.5f, 0.5f, 0.5f);
  const float r = 0.15f;
  Renderer renderer(roomWithSphere(centre, r), b.surface, {});
  renderer.setFreeSpaceLight(volume);
  RenderParams params = viewParams(32, 32);
  params.mode = RenderMode::Indirect;
  params.specular = false;
  const Vec3 eye(0.5f, 0.5f, 0.95f);
  const RgbImage image = renderer.render(PinholeCamera::lookAt(eye, centre, 0.2f), params);
  // The pixel at the centre sees the sphere's point nearest the eye.
  const Vec3 p = centre + Vec3(0, 0, r);
  const Vec3 e = volumeIrradiance(volume, p, Vec3(0, 0, 1));
  ASSERT_GT(e.y, 0.0f);
  const Vec3 expected = e * (0.8f / float(kPi));
  const Vec3 got = image.at(size_t(16) * 32 + 16);
  EXPECT_NEAR(got.y, expected.y, 0.03f * expected.y);
}

TEST(AddedObjects, ASphereBehindTheDividerOfASealedRoomIsBlack) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const Scene rooms = test::sealedRooms();
  const BakedOctrees b = bakeOctrees(rooms, 5, 60000);
  const GpuOctree& octree = b.surface;
  const GpuOctree& volume = b.volume;
  RenderParams params = viewParams(48, 48);
  for (const float x : {1.12f, 1.5f}) {  // 2 cm from the divider, and mid-room
    const Scene scene = withSphere(rooms, Vec3(x, 0.5f, 0.5f), 0.1f);
    Renderer renderer(scene, octree, {});
    renderer.setFreeSpaceLight(volume);
    // From the dark room's far wall, the sphere fills the middle of the view.
    const RgbImage image = renderer.render(
        PinholeCamera::lookAt(Vec3(1.95f, 0.5f, 0.5f), Vec3(x, 0.5f, 0.5f), 0.6f), params);
    for (size_t i = 0; i < image.pixelCount(); ++i) {
      ASSERT_EQ(image.at(i), Vec3(0.0f)) << "pixel " << i << " with the sphere at x = " << x;
    }
    // The same sphere in the lit room is lit.
  }
  const Scene lit = withSphere(rooms, Vec3(0.5f, 0.4f, 0.5f), 0.1f);
  Renderer renderer(lit, octree, {});
  renderer.setFreeSpaceLight(volume);
  params.mode = RenderMode::Indirect;
  const RgbImage image = renderer.render(
      PinholeCamera::lookAt(Vec3(0.5f, 0.4f, 0.95f), Vec3(0.5f, 0.4f, 0.5f), 0.3f), params);
  EXPECT_GT(image.at(size_t(24) * 48 + 24).y, 0.0f);
}

TEST(AddedObjects, ThePathTracerCanLetThemOnlyReceiveLight) {
  // A sphere between the point light (0.5, 0.8, 0.5) and the wall x = 1,
  // which it shadows around (1, 0.3, 0.5), where the camera sees it.
  const Vec3 at(0.8f, 0.5f, 0.5f);
  const float r = 0.08f;
  const Scene room = test::pointLitRoom();
  const Scene scene = withSphere(room, at, r);
  // A ray at the sphere meets it; through the scene as baked, the wall.
  Hit hit;
  ASSERT_TRUE(RayTracer(scene).intersect({0.2f, 0.5f, 0.5f}, {1, 0, 0}, hit));
  EXPECT_NEAR(hit.t, 0.6f - r, 0.01f);
  ASSERT_TRUE(RayTracer(scene, RayTracer::Objects::AsBaked).intersect({0.2f, 0.5f, 0.5f}, {1, 0, 0}, hit));
  EXPECT_NEAR(hit.t, 0.8f, 1e-5f);

  ReferenceParams params;
  params.width = params.height = 24;
  params.samplesPerPixel = 16;
  const PinholeCamera camera = PinholeCamera::lookAt({0.1f, 0.5f, 0.15f}, {1, 0.35f, 0.5f}, 1.0f);
  const ReferenceImage without = renderReference(room, camera, params);
  params.addedOnlyReceive = true;
  const ReferenceImage receiving = renderReference(scene, camera, params);
  params.addedOnlyReceive = false;
  params.part = ReferencePart::Direct;
  const ReferenceImage directWithout = renderReference(room, camera, params);
  const ReferenceImage added = renderReference(scene, camera, params);
  // The pixels whose rays pass well clear of the sphere (by more than
  // two pixels) see the room as if the sphere were not there, to the byte;
  // with the sphere in the scene, its shadow darkens some of them.
  const float tanHalf = std::tan(0.5f);
  const Vec3 right = normalize(cross(camera.forward, camera.up));
  const float pixel = 2.0f * tanHalf / float(params.width) * length(at - camera.eye);
  int clear = 0, shadowed = 0, sphere = 0;
  for (int y = 0; y < params.height; ++y) {
    for (int x = 0; x < params.width; ++x) {
      const float sx = (2.0f * (float(x) + 0.5f) / float(params.width) - 1.0f) * tanHalf;
      const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(params.height)) * tanHalf;
      const Vec3 d = normalize(camera.forward + right * sx + camera.up * sy);
      const Vec3 toCentre = at - camera.eye;
      const float miss = length(toCentre - d * dot(toCentre, d));
      const size_t i = size_t(y) * size_t(params.width) + size_t(x);
      if (miss > r + 2.0f * pixel) {
        ++clear;
        ASSERT_EQ(receiving.image.at(i), without.image.at(i)) << "pixel " << x << ", " << y;
        if (added.image.at(i).y < 0.5f * directWithout.image.at(i).y) ++shadowed;
      } else if (miss < 0.8f * r) {
        ++sphere;
        EXPECT_GT(receiving.image.at(i).y, 0.0f) << "pixel " << x << ", " << y;
      }
    }
  }
  EXPECT_GT(clear, params.width * params.height / 2);
  EXPECT_GT(shadowed, 5);
  EXPECT_GT(sphere, 5);
}

// An object added far from the room, out of the camera's view, changes
// nothing the path tracer draws of the room: its ray offsets followed the
// whole scene's size, 2 units in this 1-unit room for a sphere 10^5 away,
// and the picture went 44% dark. The offsets now follow the baked part's
// size and each point's own precision: the same bytes as without it.
TEST(AddedObjects, OneFarAwayChangesNothingThePathTracerDrawsOfTheRoom) {
  const Scene room = test::pointLitRoom();
  ReferenceParams params;
  params.width = params.height = 16;
  params.samplesPerPixel = 8;
  const PinholeCamera camera = PinholeCamera::lookAt({0.1f, 0.5f, 0.15f}, {1, 0.35f, 0.5f}, 1.0f);
  const ReferenceImage without = renderReference(room, camera, params);
  ASSERT_GT(mean(without.image), 0.0);
  for (float far : {1e3f, 1e5f, 1e9f}) {
    SCOPED_TRACE(far);
    const ReferenceImage with = renderReference(withSphere(room, {far, 0.5f, 0.5f}, 0.5f), camera, params);
    EXPECT_EQ(with.image.rgb, without.image.rgb) << "mean " << mean(with.image) << " against "
                                                 << mean(without.image);
  }
}

}  // namespace
}  // namespace lo
