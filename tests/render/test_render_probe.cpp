// The reflection probe under OSMesa: read box-projected, it shows the wall a
// mirror's reflected ray really hits; normalised by the octree's irradiance,
// it adds no light where none arrives.

#include <gtest/gtest.h>

#include <string>

#include "image/image.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

using RenderImage = test::GlTest;

/// Walls of the cube [-1, 1]^3, facing in, that glow in their own colours
/// (black, emissive: +x red, -x green, ceiling blue, +z yellow, -z cyan, and
/// with `floor` a magenta floor), lit by nothing: what the reflection probe
/// shows in the probe tests.
void addGlowingWalls(Scene& scene, bool floor) {
  auto glow = [&scene](const Vec3& radiance) {
    Material m;
    m.baseColor = {0, 0, 0};
    m.emission = radiance;
    scene.materials.push_back(m);
    return int(scene.materials.size()) - 1;
  };
  test::addQuad(scene, {1, -1, -1}, {0, 2, 0}, {0, 0, 2}, {-1, 0, 0}, glow({1, 0, 0}));  // +x
  test::addQuad(scene, {-1, -1, -1}, {0, 2, 0}, {0, 0, 2}, {1, 0, 0}, glow({0, 1, 0}));  // -x
  test::addQuad(scene, {-1, 1, -1}, {2, 0, 0}, {0, 0, 2}, {0, -1, 0}, glow({0, 0, 1}));  // ceiling
  if (floor) {
    test::addQuad(scene, {-1, -1, -1}, {2, 0, 0}, {0, 0, 2}, {0, 1, 0}, glow({1, 0, 1}));
  }
  test::addQuad(scene, {-1, -1, 1}, {2, 0, 0}, {0, 2, 0}, {0, 0, -1}, glow({1, 1, 0}));  // +z
  test::addQuad(scene, {-1, -1, -1}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, glow({0, 1, 1}));  // -z
}

/// Renderer settings under which only the probe sees the glowing walls:
/// emitters are neither area lights nor VPLs.
RendererParams probeOnly() {
  RendererParams rp;
  rp.areaLights = false;
  rp.emitterLights = 0;
  return rp;
}

// Environment reflections: a mirror floor in a box of walls that glow in six
// colours, lit by nothing else (no VDLs, emitters not drawn as lights), shows
// the colour of the wall its reflected ray really hits: the probe at the box's
// centre, read box-projected. Read from the centre without the projection,
// the same ray would show the ceiling's colour.
TEST_F(RenderImage, MirrorReflectsTheWallItsRayHits) {
  Scene scene;
  addGlowingWalls(scene, false);
  Material mirror;
  mirror.baseColor = {1, 1, 1};
  mirror.metallic = 1.0f;
  mirror.roughness = 0.0f;
  scene.materials.push_back(mirror);
  test::addQuad(scene, {-1, -1, -1}, {2, 0, 0}, {0, 0, 2}, {0, 1, 0}, int(scene.materials.size()) - 1);
  Renderer renderer(scene, test::emptyOctree(), probeOnly());
  ASSERT_TRUE(renderer.hasReflectionProbe());
  RenderParams p;
  p.width = p.height = 64;
  p.mode = RenderMode::Full;
  // The centre pixel sees the floor at (0.3, -1, 0.2); its reflection rises
  // along (0, 1.2, 0.8) and meets the +z wall at (0.3, 0.2, 1): yellow. From
  // the box's centre that direction meets the ceiling: blue.
  const PinholeCamera camera =
      PinholeCamera::lookAt({0.3f, 0.2f, -0.6f}, {0.3f, -1.0f, 0.2f}, 50.0f * kPi / 180.0f);
  const RgbImage image = renderer.render(camera, p);
  writePng(test::outputDir("render_mirror") + "/rendered.png", image, 0.0f);
  const float* c = image.pixel(p.width / 2, p.height / 2);
  EXPECT_NEAR(c[0], 1.0f, 0.05f);
  EXPECT_NEAR(c[1], 1.0f, 0.05f);
  EXPECT_LT(c[2], 0.05f) << "the ceiling's blue: the reflection was not box-projected";
  // Without the probe, nothing lights the mirror.
  p.reflections = false;
  const RgbImage dark = renderer.render(camera, p);  // kept: pixel() points into it
  const float* off = dark.pixel(p.width / 2, p.height / 2);
  EXPECT_LT(off[0] + off[1] + off[2], 1e-4f);
}

// Irradiance normalisation of the probe: a face that no light reaches shows
// none, however bright the probe. Around the probe, walls glowing in six
// colours (not drawn as lights, not in the octree: only the probe sees
// them); off the centre, a closet of inward-facing walls inside which
// nothing arrives (the path tracer gives exactly 0 there). Its back wall,
// seen from inside, a rough near-black dielectric (the table's pole: base
// 0.02, roughness 0.5) or a glossy metal (roughness 0.3), stays black with
// the probe on. With light in the octree the same wall does show the probe:
// the normalisation scales its light, it does not switch it off.
TEST_F(RenderImage, ProbeAddsNoLightWhereNoneArrives) {
  struct Case {
    const char* name;
    Vec3 baseColor;
    float metallic, roughness;
  };
  for (const Case& c : {Case{"dielectric", {0.02f, 0.02f, 0.02f}, 0.0f, 0.5f},
                        Case{"metal", {0.9f, 0.9f, 0.9f}, 1.0f, 0.3f}}) {
    SCOPED_TRACE(c.name);
    Scene scene;
    addGlowingWalls(scene, true);
    Material closet;
    closet.baseColor = c.baseColor;
    closet.metallic = c.metallic;
    closet.roughness = c.roughness;
    scene.materials.push_back(closet);
    // Single-sided and facing in: from outside (the probe at the centre) it
    // is culled, so the probe is bright in every direction.
    test::addClosedBox(scene, {0.2f, -0.9f, 0.2f}, {0.9f, -0.2f, 0.9f},
                       int(scene.materials.size()) - 1);
    Renderer renderer(scene, test::emptyOctree(), probeOnly());
    ASSERT_TRUE(renderer.hasReflectionProbe());
    RenderParams p;
    p.width = p.height = 32;
    p.mode = RenderMode::Full;
    // From just inside the closet's front wall at its back wall (z = 0.9,
    // facing -z), which fills the view; the reflected ray leaves along -z
    // and, box-projected, reads the cyan wall at z = -1.
    const PinholeCamera camera = PinholeCamera::lookAt({0.55f, -0.55f, 0.25f},
                                                       {0.55f, -0.55f, 0.9f}, 40.0f * kPi / 180.0f);
    const RgbImage image = renderer.render(camera, p);  // kept: pixel() points into it
    writePng(test::outputDir(std::string("render_probe_no_light_") + c.name) + "/rendered.png",
             image, 0.0f);
    const float* unlit = image.pixel(p.width / 2, p.height / 2);
    EXPECT_LT(unlit[0] + unlit[1] + unlit[2], 1e-4f)
        << "the probe lights a face that no light reaches: " << unlit[0] << " " << unlit[1]
        << " " << unlit[2];
    // One VDL in every voxel, 72 degrees off the back wall's normal (its
    // own GGX response at the centre is small), 16 W/m^2: E(n) = 5 there,
    // more than the probe's own irradiance towards -z (pi x 0.58 = 1.8 in
    // luminance), so the normalisation keeps all of the probe's light.
    renderer.setOctree(test::quadOctree([](const Coord&, Vdl* out) {
      out[0] = {{16, 16, 16}, normalize(Vec3{0, 0.95f, -0.31f})};
      return 1;
    }));
    const RgbImage lit = renderer.render(camera, p);
    p.reflections = false;
    const RgbImage litOff = renderer.render(camera, p);
    const float* on = lit.pixel(p.width / 2, p.height / 2);
    const float* off = litOff.pixel(p.width / 2, p.height / 2);
    EXPECT_GT(on[2], off[2] + 0.01f) << "the probe's cyan is gone where light arrives: " << on[2]
                                     << " with the probe, " << off[2] << " without";
  }
}

}  // namespace
}  // namespace lo
