// What lets light and the view through, in the renderer under OSMesa: glass
// panes (thin and with KHR_materials_volume), glTF MASK and BLEND, and
// single-sided surfaces culled from behind.

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

using RenderImage = test::GlTest;
using test::QuadSetup;

/// QuadSetup's quad under a point light, drawn (Direct) without and with a
/// clear glass pane at z = 0.8 covering the view (`thickness` > 0: a
/// KHR_materials_volume pane).
struct PaneRenders {
  RenderParams params = QuadSetup::directParams();
  RgbImage open, through;
};
PaneRenders renderWithAndWithoutAPane(const Vec3& lightAt, float intensity, float thickness) {
  PaneRenders r;
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight(lightAt, intensity));
  const GpuOctree octree = test::emptyOctree();
  r.open = s.render(octree, r.params);
  Material glass;
  glass.baseColor = {1, 1, 1};
  glass.roughness = 0.05f;
  glass.transmission = 1.0f;
  glass.thickness = thickness;
  s.scene.materials.push_back(glass);
  test::addQuad(s.scene, {-1, -1, 0.8f}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 1);
  r.through = s.render(octree, r.params);
  return r;
}

// Glass (KHR_materials_transmission): a clear pane between the camera and a
// lit quad shows the quad through it, dimmed only by the Fresnel reflectance
// at normal incidence (4%), where it used to be drawn as an opaque white
// surface; and it casts no shadow on the quad under it.
TEST_F(RenderImage, GlassShowsWhatIsBehindAndCastsNoShadow) {
  // The thin pane lies between the light (off to the side: no highlight on
  // the pane at the centre) and the centre of the quad.
  const PaneRenders r = renderWithAndWithoutAPane({0.6f, 0.5f, 1.5f}, 4.0f, 0.0f);
  const RenderParams& p = r.params;
  const float* a = r.open.pixel(p.width / 2, p.height / 2);
  const float* b = r.through.pixel(p.width / 2, p.height / 2);
  ASSERT_GT(a[0], 0.01f);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(b[c] / a[c], 0.96f, 0.01f) << "channel " << c << ": " << b[c] << " vs " << a[c];
  }
}

TEST_F(RenderImage, AFlatGlassVolumeIsSeenStraightThroughTwoInterfaces) {
  // A pane with KHR_materials_volume (thickness 0.05, as exporters give
  // panes) is flat on the scale of its thickness: the view goes straight
  // through (not bent as through a ball of that diameter), losing the
  // Fresnel reflectance at both faces, 1 - 0.04 each at normal incidence.
  // The light is under the pane: it casts no shadow here.
  const PaneRenders r = renderWithAndWithoutAPane({0.6f, 0.5f, 0.5f}, 1.0f, 0.05f);
  const RenderParams& p = r.params;
  for (int px : {p.width / 2, p.width / 2 + 12}) {  // the centre, and 7 degrees off it
    const float* a = r.open.pixel(px, p.height / 2);
    const float* b = r.through.pixel(px, p.height / 2);
    ASSERT_GT(a[0], 0.01f);
    EXPECT_NEAR(b[0] / a[0], 0.96f * 0.96f, 0.01f) << "pixel " << px;
  }
}

// Snell's law for unit `d` meeting a surface of unit normal `n` (against
// d), eta = n_from / n_to; false past the critical angle.
bool refracted(const Vec3& d, const Vec3& n, float eta, Vec3& t) {
  const float c = -dot(d, n);
  const float k = 1.0f - eta * eta * (1.0f - c * c);
  if (k < 0.0f) return false;
  t = d * eta + n * (eta * c - std::sqrt(k));
  return true;
}

// Thick glass (KHR_materials_volume): a clear block 0.4 thick in front of a
// card, red left of x = 0 and blue right of it, seen 31 degrees off its
// normal. Each ray refracts into the front face, out of the back face and on
// to the card, shifted sideways by 0.4 sin(theta_i - theta_t) / cos(theta_t)
// (8 cm here, 5 pixels): the colour of every pixel of the middle row is the
// one Snell's law gives, where a view straight through (the pane model the
// block was drawn with) puts the edge elsewhere.
TEST_F(RenderImage, AGlassBlockShiftsWhatIsBehindItAsSnellsLawDoes) {
  Scene scene;
  Material redCard, blueCard, glass;
  redCard.unlit = blueCard.unlit = true;
  redCard.baseColor = {0.8f, 0.05f, 0.05f};
  blueCard.baseColor = {0.05f, 0.05f, 0.8f};
  glass.baseColor = {1, 1, 1};
  glass.roughness = 0.0f;
  glass.transmission = 1.0f;
  glass.thickness = 0.4f;
  glass.ior = 1.5f;
  scene.materials = {redCard, blueCard, glass};
  test::addQuad(scene, {-2, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 0);
  test::addQuad(scene, {0, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 1);
  const Vec3 lo(-1.0f, -0.5f, 0.2f), hi(1.5f, 0.5f, 0.6f);
  const Vec3 size = hi - lo;
  test::addQuad(scene, {lo.x, lo.y, hi.z}, {size.x, 0, 0}, {0, size.y, 0}, {0, 0, 1}, 2);
  test::addQuad(scene, {lo.x, lo.y, lo.z}, {0, size.y, 0}, {size.x, 0, 0}, {0, 0, -1}, 2);
  test::addQuad(scene, {lo.x, lo.y, lo.z}, {0, 0, size.z}, {0, size.y, 0}, {-1, 0, 0}, 2);
  test::addQuad(scene, {hi.x, lo.y, lo.z}, {0, size.y, 0}, {0, 0, size.z}, {1, 0, 0}, 2);
  test::addQuad(scene, {lo.x, lo.y, lo.z}, {size.x, 0, 0}, {0, 0, size.z}, {0, -1, 0}, 2);
  test::addQuad(scene, {lo.x, hi.y, lo.z}, {0, 0, size.z}, {size.x, 0, 0}, {0, 1, 0}, 2);
  const PinholeCamera camera =
      PinholeCamera::lookAt({1.2f, 0.0f, 2.0f}, {0.0f, 0.0f, 0.0f}, 36.0f * kPi / 180.0f);
  RenderParams p = QuadSetup::directParams();
  p.width = 128;
  p.height = 96;
  const RgbImage image = Renderer(scene, test::emptyOctree()).render(camera, p);
  const Vec3 right = normalize(cross(camera.forward, camera.up));
  const float tanHalf = std::tan(0.5f * camera.yfov);
  const int row = p.height / 2;
  // Per column of the middle row: -1 off the block, else whether the card
  // is red where the ray lands, refracted and straight through.
  std::vector<int> red(size_t(p.width), -1), redStraight(size_t(p.width), -1);
  for (int x = 0; x < p.width; ++x) {
    const float sx = (2.0f * (float(x) + 0.5f) / float(p.width) - 1.0f) * tanHalf * p.width / p.height;
    const float sy = (1.0f - 2.0f * (float(row) + 0.5f) / float(p.height)) * tanHalf;
    const Vec3 d = normalize(camera.forward + right * sx + camera.up * sy);
    // Into the front face (z = 0.6), out of the back (z = 0.2), on to z = 0.
    const Vec3 front = camera.eye + d * ((hi.z - camera.eye.z) / d.z);
    if (front.x < lo.x || front.x > hi.x) continue;
    Vec3 inside, out;
    ASSERT_TRUE(refracted(d, {0, 0, 1}, 1.0f / 1.5f, inside));
    const Vec3 back = front + inside * ((lo.z - front.z) / inside.z);
    if (back.x < lo.x + 0.05f || back.x > hi.x - 0.05f) continue;  // it leaves by a side
    ASSERT_TRUE(refracted(inside, {0, 0, 1}, 1.5f, out));
    red[size_t(x)] = (back + out * (-back.z / out.z)).x < 0.0f;
    redStraight[size_t(x)] = (front + d * (-front.z / d.z)).x < 0.0f;
  }
  int edge = -1, straightEdge = -1, mismatches = 0, compared = 0;
  for (size_t x = 1; x < red.size(); ++x) {
    if (red[x] >= 0 && red[x - 1] >= 0 && red[x] != red[x - 1]) edge = int(x);
    if (redStraight[x] >= 0 && redStraight[x - 1] >= 0 && redStraight[x] != redStraight[x - 1]) {
      straightEdge = int(x);
    }
  }
  for (int x = 0; x < p.width; ++x) {
    if (red[size_t(x)] < 0 || std::abs(x - edge) <= 1) continue;  // off the block; the edge
    const float* px = image.pixel(x, row);
    ASSERT_GT(px[0] + px[2], 0.1f) << "column " << x << " shows nothing";
    ++compared;
    if ((px[0] > px[2]) != (red[size_t(x)] == 1)) ++mismatches;
  }
  ASSERT_GT(edge, 0);
  EXPECT_GE(std::abs(edge - straightEdge), 3) << "the test tells refraction from a straight view";
  EXPECT_GT(compared, p.width / 2);
  EXPECT_EQ(mismatches, 0) << "edge by Snell's law at column " << edge << ", straight through at "
                           << straightEdge;
}

// glTF MASK: the cut-out half of a card neither hides the quad behind it nor
// shadows it; the other half does both.
TEST_F(RenderImage, MaskedCardCutsOutTheViewAndTheShadow) {
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));
  Texture half = Texture::fromLinear(2, 1, {Vec3{1, 1, 1}, Vec3{1, 1, 1}},
                                     {0.0f, 1.0f});  // u < 0.5 (x < 0) cut out
  s.scene.textures.push_back(half);
  Material card;
  card.baseColor = {1, 1, 1};
  card.baseColorTexture = 0;
  card.alphaMode = AlphaMode::Mask;
  s.scene.materials.push_back(card);
  test::addQuad(s.scene, {-1, -1, 0.5f}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 1);
  s.scene.texcoords0.assign(2 * s.scene.positions.size(), 0.0f);
  for (size_t v = 0; v < s.scene.positions.size(); ++v) {
    s.scene.texcoords0[2 * v] = 0.5f * (s.scene.positions[v].x + 1.0f);
  }
  const RenderParams p = QuadSetup::directParams();
  const GpuOctree octree = test::constantOctree();
  const RgbImage masked = s.render(octree, p);
  writePng(test::outputDir("render_mask") + "/rendered.png", masked, 1.0f);
  // x = -0.4 on the quad: seen through the cut-out, lit through it (the
  // light's ray crosses the card at x = -0.15).
  const float* behind = masked.pixel(test::columnAt(s, p, -0.4f, 0.0f), p.height / 2);
  EXPECT_GT(behind[0], 0.02f) << "lit through the cut-out";
  EXPECT_NEAR(behind[0] / behind[2], s.albedo.x / s.albedo.z, 0.03f) << "the quad's colour";
  // x = 0.4 on the card: the card (white).
  const float* cardPixel = masked.pixel(test::columnAt(s, p, 0.4f, 0.5f), p.height / 2);
  EXPECT_NEAR(cardPixel[0] / cardPixel[2], 1.0f, 0.03f) << "the card's colour";
  // Opaque, the card hides the quad everywhere.
  s.scene.materials[1].alphaMode = AlphaMode::Opaque;
  const RgbImage opaque = s.render(octree, p);
  const float* hidden = opaque.pixel(test::columnAt(s, p, -0.4f, 0.0f), p.height / 2);
  EXPECT_NEAR(hidden[0] / hidden[2], 1.0f, 0.03f);
}

// Opaque surfaces at one depth (coplanar copies, H15-5-1: 3,000 of them took
// 140 s a frame) shade a pixel once: the first drawn (the lower material
// index) alone is shaded and shows, where every copy was shaded and the
// last one showed. A masked card on the same plane (a decal) still shows
// over the opaque surface, and the surface through its cut-out half.
TEST_F(RenderImage, CoplanarOpaqueSurfacesShadeAPixelOnceUnderAMaskedDecal) {
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));
  Material green;
  green.baseColor = {0.2f, 0.9f, 0.1f};
  green.roughness = 1.0f;
  s.scene.materials.push_back(green);
  test::addQuad(s.scene, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 1);
  const RenderParams p = QuadSetup::directParams();
  const GpuOctree octree = test::emptyOctree();
  auto ratio = [&](const RgbImage& image, float x) {
    const float* c = image.pixel(test::columnAt(s, p, x, 0.0f), p.height / 2);
    return c[0] / c[2];
  };
  const float first = s.albedo.x / s.albedo.z;                // 0.625
  const float decal = green.baseColor.x / green.baseColor.z;  // 2
  const RgbImage both = s.render(octree, p);
  for (float x : {-0.4f, 0.4f}) EXPECT_NEAR(ratio(both, x), first, 0.02f) << "x " << x;
  // The second quad masked, its half x < 0 cut out.
  s.scene.textures.push_back(
      Texture::fromLinear(2, 1, {Vec3{1, 1, 1}, Vec3{1, 1, 1}}, {0.0f, 1.0f}));
  s.scene.materials[1].baseColorTexture = 0;
  s.scene.materials[1].alphaMode = AlphaMode::Mask;
  s.scene.texcoords0.assign(2 * s.scene.positions.size(), 0.0f);
  for (size_t v = 0; v < s.scene.positions.size(); ++v) {
    s.scene.texcoords0[2 * v] = 0.5f * (s.scene.positions[v].x + 1.0f);
  }
  const RgbImage masked = s.render(octree, p);
  EXPECT_NEAR(ratio(masked, -0.4f), first, 0.02f) << "through the cut-out";
  EXPECT_NEAR(ratio(masked, 0.4f), decal, 0.05f) << "the decal";
}

// glTF BLEND: a pane of alpha 1/4 over the lit quad shows 1/4 of its own
// radiance and 3/4 of the quad's; below 1/2 it casts no shadow.
TEST_F(RenderImage, BlendedPaneCoversItsAlphaOfWhatIsBehind) {
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.6f, 0.5f, 1.5f}, 4.0f));
  const RenderParams p = QuadSetup::directParams();
  const GpuOctree octree = test::constantOctree();
  const RgbImage open = s.render(octree, p);
  Material pane;
  pane.baseColor = {1, 1, 1};
  pane.baseAlpha = 0.25f;
  s.scene.materials.push_back(pane);
  test::addQuad(s.scene, {-1, -1, 0.8f}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 1);
  const RgbImage paneImage = s.render(octree, p);  // opaque
  s.scene.materials[1].alphaMode = AlphaMode::Blend;
  const RgbImage blended = s.render(octree, p);
  writePng(test::outputDir("render_blend") + "/rendered.png", blended, 1.0f);
  for (int x : {p.width / 4, p.width / 2, 3 * p.width / 4}) {
    const float* a = open.pixel(x, p.height / 2);
    const float* b = paneImage.pixel(x, p.height / 2);
    const float* c = blended.pixel(x, p.height / 2);
    ASSERT_GT(a[0], 0.01f);
    for (int k = 0; k < 3; ++k) {
      const float expected = 0.25f * b[k] + 0.75f * a[k];
      EXPECT_NEAR(c[k], expected, 0.01f * expected) << "pixel " << x << " channel " << k;
    }
  }
}

// glTF doubleSided false: a surface seen from behind is culled (the quad
// behind it shows); doubleSided true: it is drawn.
TEST_F(RenderImage, SingleSidedSurfaceIsCulledFromBehind) {
  // With and without the depth pre-pass (interpolation or direct light on):
  // the pre-pass culls what the colour pass culls, so the culled pane's
  // depth never hides the quad behind it (a black hole).
  for (bool prePass : {false, true}) {
    SCOPED_TRACE(prePass ? "with the depth pre-pass" : "without it");
    QuadSetup s;
    Material pane;
    pane.baseColor = {1, 1, 1};
    s.scene.materials.push_back(pane);
    // Its winding faces -z, away from the camera.
    test::addQuad(s.scene, {-1, -1, 0.5f}, {2, 0, 0}, {0, 2, 0}, {0, 0, -1}, 1);
    const RenderParams p = QuadSetup::params(prePass);
    const GpuOctree octree = test::constantOctree();
    const RgbImage culled = s.render(octree, p);
    const float* c = culled.pixel(p.width / 2, p.height / 2);
    EXPECT_GT(c[2], 0.0f) << "not the background";
    EXPECT_NEAR(c[0] / c[2], s.albedo.x / s.albedo.z, 0.02f) << "the quad behind shows";
    s.scene.materials[1].doubleSided = true;
    const RgbImage drawn = s.render(octree, p);
    const float* d = drawn.pixel(p.width / 2, p.height / 2);
    EXPECT_NEAR(d[0] / d[2], 1.0f, 0.02f) << "the pane shows";
    // A face of a format without single-sided faces (OBJ) shows from both
    // sides too.
    s.scene.materials[1].doubleSided = false;
    s.scene.materials[1].backFaceCulling = false;
    const RgbImage obj = s.render(octree, p);
    const float* o = obj.pixel(p.width / 2, p.height / 2);
    EXPECT_NEAR(o[0] / o[2], 1.0f, 0.02f) << "the OBJ pane shows";
  }
}

// Emission shows on an emitter's front only (its winding's side, where the
// tracers emit it) unless it is double-sided: an OBJ lamp seen from behind
// (never culled) is its dark base colour, not a glowing square.
TEST_F(RenderImage, AOneSidedEmitterShowsNoLightFromBehind) {
  QuadSetup s;
  Material lamp;
  lamp.baseColor = {0, 0, 0};
  lamp.emission = {5, 5, 5};
  lamp.backFaceCulling = false;
  s.scene.materials.push_back(lamp);
  // Its winding faces -z, away from the camera, towards the quad.
  test::addQuad(s.scene, {-1, -1, 0.5f}, {2, 0, 0}, {0, 2, 0}, {0, 0, -1}, 1);
  const RenderParams p = QuadSetup::directParams();
  const GpuOctree octree = test::emptyOctree();
  const RgbImage back = s.render(octree, p);
  EXPECT_LT(back.pixel(p.width / 2, p.height / 2)[0], 0.05f) << "its back: no emission";
  s.scene.materials[1].doubleSided = true;
  const RgbImage both = s.render(octree, p);
  EXPECT_NEAR(both.pixel(p.width / 2, p.height / 2)[0], 5.0f, 0.05f) << "double-sided: its emission";
}

}  // namespace
}  // namespace lo
