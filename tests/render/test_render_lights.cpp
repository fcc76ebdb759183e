// The renderer's direct light under OSMesa, against analytic answers on the
// Lambertian quad: a point light's inverse-square law and shadow, a spot's
// glTF cone, unlit surfaces, the sky behind the scene, area lights' exact
// rectangle irradiance and their soft shadows.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "image/image.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

using RenderImage = test::GlTest;
using test::QuadSetup;

TEST_F(RenderImage, DirectPointLightMatchesInverseSquareLaw) {
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));  // W/sr
  const GpuOctree octree = test::emptyOctree();
  const RenderParams p = QuadSetup::directParams();
  RgbImage image = s.render(octree, p);
  // Center pixel sees the point right below the light: E = I / h^2.
  const float* c = image.pixel(p.width / 2, p.height / 2);
  float tanHalf = std::tan(0.5f * s.camera.yfov);
  // The pixel centre's offset from the view axis, in world units on the quad.
  float py = (0.5f / (p.height / 2.0f)) * tanHalf * 2.0f;
  float px = py;
  float r2 = 1.0f + px * px + py * py;
  float expected = s.albedo.x * kInvPi * 2.0f / r2 * (1.0f / std::sqrt(r2));
  EXPECT_NEAR(c[0], expected, 2e-3f * expected);
  // A small blocker just below the light casts a shadow on the quad about
  // 1 unit wide (x in [-0.4, 0.6]); the camera sees the blocker only near the
  // centre (within ~0.05 units at the quad's depth).
  test::addQuad(s.scene, {0.05f, -0.1f, 0.9f}, {0.1f, 0, 0}, {0, 0.1f, 0}, {0, 0, 1}, 0);
  RgbImage dark = s.render(octree, p);
  float worldPerPixel = s.worldPerPixel(p, 2.0f);
  int inShadow = p.width / 2 + int(0.3f / worldPerPixel);  // x = 0.4 on the quad
  int lit = p.width / 2 + int(0.75f / worldPerPixel);      // x = 0.85
  EXPECT_LT(dark.pixel(inShadow, p.height / 2)[0], 1e-4f);
  EXPECT_GT(dark.pixel(lit, p.height / 2)[0], 0.05f);
}

TEST_F(RenderImage, SpotPoolFollowsTheGltfConeFalloff) {
  // A spot 1 unit above the quad, pointing down, inner 15 and outer 30
  // degrees: along a row through the pool's centre the radiance is
  // albedo / pi * I * falloff(cos) * cos / r^2, falloff =
  // ((cos - cosOuter) / (cosInner - cosOuter))^2 clamped (glTF), the
  // profile the photon tracer and the path tracer follow.
  QuadSetup s;
  Light spot;
  spot.type = Light::Type::Spot;
  spot.position = {0.1f, -0.05f, 1};  // above the view's centre
  spot.direction = {0, 0, -1};
  spot.intensity = 2.0f;
  spot.innerConeAngle = 15.0f * kPi / 180.0f;
  spot.outerConeAngle = 30.0f * kPi / 180.0f;
  s.scene.lights.push_back(spot);
  const RenderParams p = QuadSetup::directParams();
  const RgbImage image = s.render(test::emptyOctree(), p);
  const float worldPerPixel = s.worldPerPixel(p, 2.0f);
  const float cosInner = std::cos(spot.innerConeAngle), cosOuter = std::cos(spot.outerConeAngle);
  int checked = 0, inPenumbra = 0;
  for (int px = p.width / 2; px < p.width; ++px) {
    const float x = (float(px) + 0.5f - 0.5f * float(p.width)) * worldPerPixel;
    const float y = 0.5f * worldPerPixel;  // the row just off the centre
    const float r2 = 1.0f + x * x + y * y, cosTheta = 1.0f / std::sqrt(r2);
    if (std::fabs(x) > 0.85f) break;  // the quad's edge
    const float t = std::clamp((cosTheta - cosOuter) / (cosInner - cosOuter), 0.0f, 1.0f);
    const float expected = s.albedo.x * kInvPi * spot.intensity * t * t * cosTheta / r2;
    const float got = image.pixel(px, p.height / 2)[0];
    EXPECT_NEAR(got, expected, 3e-3f * expected + 1e-4f) << "x = " << x;
    ++checked;
    inPenumbra += cosTheta < cosInner && cosTheta > cosOuter;
  }
  EXPECT_GT(checked, 10);
  EXPECT_GT(inPenumbra, 3);
}

TEST_F(RenderImage, UnlitIsSeenAsItsColourAndCastsNoShadow) {
  // KHR_materials_unlit as Blender imports it: a small unlit card between a
  // point light and the quad shows its base colour exactly and leaves the
  // quad's direct light where its shadow would fall untouched.
  QuadSetup with, without;
  const Light point = test::pointLight({0.1f, -0.05f, 1}, 2.0f);
  with.scene.lights.push_back(point);
  without.scene.lights.push_back(point);
  Material card;
  card.baseColor = {0.2f, 0.6f, 0.9f};
  card.unlit = true;
  with.scene.materials.push_back(card);
  test::addQuad(with.scene, {0.2f, -0.2f, 0.5f}, {0.2f, 0, 0}, {0, 0.4f, 0}, {0, 0, 1}, 1);
  const GpuOctree octree = test::emptyOctree();
  const RenderParams p = QuadSetup::directParams();
  const RgbImage a = with.render(octree, p);
  const RgbImage b = without.render(octree, p);
  // Pixel of a point at depth `distance` from the camera, (x, y) from the view's centre.
  const float perPixel = 2.0f * std::tan(0.5f * with.camera.yfov) / float(p.height);
  auto pixel = [&](float x, float y, float distance, int& px, int& py) {
    px = int(x / (perPixel * distance) + 0.5f * float(p.width));
    py = int(0.5f * float(p.height) - y / (perPixel * distance));
  };
  int px = 0, py = 0;
  pixel(0.2f, 0.05f, 1.5f, px, py);  // the card's centre (0.3, 0, 0.5)
  const Vec3 seen = a.at(size_t(py) * size_t(p.width) + size_t(px));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(seen[c], card.baseColor[c], 1e-3f) << c;
  // The quad at (0.6, 0, 0): behind the card as the light sees it, beside
  // it as the camera does.
  pixel(0.5f, 0.05f, 2.0f, px, py);
  EXPECT_GT(b.pixel(px, py)[0], 0.05f);
  EXPECT_NEAR(a.pixel(px, py)[0], b.pixel(px, py)[0], 1e-3f * b.pixel(px, py)[0]);
}

// The sky is drawn behind the scene where the view looks above the horizon,
// black below, as the path tracer sees it where a ray escapes.
TEST_F(RenderImage, SkyIsTheBackgroundAboveTheHorizon) {
  QuadSetup s;  // the quad stands at z = 0, facing +z; the camera looks past it
  s.scene.sky.radiance = {0.2f, 0.4f, 0.8f};
  Renderer renderer(s.scene, test::emptyOctree());
  const RenderParams p = QuadSetup::directParams();
  const PinholeCamera level = PinholeCamera::lookAt({5, 0, 5}, {10, 0, 5}, 0.8f);
  const RgbImage image = renderer.render(level, p);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(image.pixel(p.width / 2, 1)[c], s.scene.sky.radiance[c], 1e-5f);
    EXPECT_EQ(image.pixel(p.width / 2, p.height - 2)[c], 0.0f);
  }
}

/// Form factor from a point to the rectangle [0, x] x [0, y] in a parallel
/// plane at height h above it (the point below the corner (0, 0)); odd in x
/// and in y, so rectangles anywhere are sums of four of these.
double cornerFormFactor(double x, double y, double h) {
  const double a = x / h, b = y / h;
  return (a / std::sqrt(1 + a * a) * std::atan(b / std::sqrt(1 + a * a)) +
          b / std::sqrt(1 + b * b) * std::atan(a / std::sqrt(1 + b * b))) /
         (2 * kPi);
}

/// A square emitter of side `side` centred over (cx, cy) at height z = h,
/// facing down onto the quad of QuadSetup (z = 0), as two triangles.
void addSquareEmitter(Scene& scene, float cx, float cy, float h, float side, const Vec3& radiance) {
  Material e;
  e.baseColor = {0, 0, 0};
  e.emission = radiance;
  scene.materials.push_back(e);
  test::addQuad(scene, {cx - 0.5f * side, cy - 0.5f * side, h}, {side, 0, 0}, {0, side, 0},
                {0, 0, -1}, int(scene.materials.size()) - 1);
}

// Area lights: an emissive square over a Lambertian quad lights it with the
// exact irradiance of a rectangle, E = pi L F (F the form factor, summed
// from corner form factors), so each pixel is albedo L F; no shadows here.
TEST_F(RenderImage, AreaLightGivesTheExactIrradianceOfTheRectangle) {
  QuadSetup s;
  const float h = 0.6f, side = 0.4f, cx = 0.1f, cy = -0.05f;
  const Vec3 radiance{3.0f, 3.0f, 3.0f};
  addSquareEmitter(s.scene, cx, cy, h, side, radiance);
  s.camera = PinholeCamera::lookAt({0.1f, -0.05f, 0.5f}, {0.1f, -0.05f, 0.0f}, 36.0f * kPi / 180.0f);
  Renderer renderer(s.scene, test::emptyOctree());
  ASSERT_EQ(renderer.areaLightCount(), 2);
  const RenderParams p = QuadSetup::directParams();
  const RgbImage image = renderer.render(s.camera, p);
  const float worldPerPixel = s.worldPerPixel(p, 0.5f);
  for (int px : {p.width / 2, p.width / 2 + 10, p.width / 2 - 20}) {
    // World position of the pixel centre on the quad (x right, y up).
    const double x = 0.1 + (px + 0.5 - 0.5 * p.width) * worldPerPixel;
    const double y = -0.05 - (p.height / 2 + 0.5 - 0.5 * p.height) * worldPerPixel;
    const double x0 = cx - 0.5 * side - x, x1 = cx + 0.5 * side - x;
    const double y0 = cy - 0.5 * side - y, y1 = cy + 0.5 * side - y;
    const double F = cornerFormFactor(x1, y1, h) - cornerFormFactor(x0, y1, h) -
                     cornerFormFactor(x1, y0, h) + cornerFormFactor(x0, y0, h);
    const double expected = s.albedo.x * radiance.x * F;
    EXPECT_NEAR(image.pixel(px, p.height / 2)[0], expected, 2e-3 * expected) << "pixel " << px;
  }
}

// An emissive mesh is an area light too: a glowing cube of 12 triangles
// (more than a handful of points could stand for) lights the quad below it
// with the exact irradiance of its faces, E = sum over the faces p sees of
// L integral cos(theta) cos(theta') / r^2 dA, here integrated by brute force
// over a fine grid of each face (a convex emitter: p sees exactly the faces
// whose planes it is in front of), so each pixel is albedo E / pi. The
// cube's own faces surround its shadow cube's centre and must cast no
// shadow on it.
TEST_F(RenderImage, AGlowingCubeLightsLikeTheIntegralOfItsFaces) {
  QuadSetup s;
  Material e;
  e.baseColor = Vec3(0.0f);
  const Vec3 radiance{2.0f, 1.0f, 3.0f};
  e.emission = radiance;
  s.scene.materials.push_back(e);
  const int material = int(s.scene.materials.size()) - 1;
  const Vec3 lo{0.0f, -0.15f, 0.05f};  // just above the quad: its faces are near
  const float side = 0.2f;
  const Vec3 ex{side, 0, 0}, ey{0, side, 0}, ez{0, 0, side};
  struct Face {
    Vec3 corner, u, v, normal;
  };
  const Face faces[6] = {{lo, ex, ey, {0, 0, -1}},      {lo + ez, ex, ey, {0, 0, 1}},
                         {lo, ey, ez, {-1, 0, 0}},      {lo + ex, ey, ez, {1, 0, 0}},
                         {lo, ex, ez, {0, -1, 0}},      {lo + ey, ex, ez, {0, 1, 0}}};
  for (const Face& f : faces) test::addQuad(s.scene, f.corner, f.u, f.v, f.normal, material);
  Renderer renderer(s.scene, test::emptyOctree());
  ASSERT_EQ(renderer.areaLightCount(), 12);
  ASSERT_EQ(renderer.areaLightGroups(), 1);
  const RenderParams p = QuadSetup::directParams();
  const RgbImage image = renderer.render(s.camera, p);
  const float worldPerPixel = s.worldPerPixel(p, 2.0f);
  // Columns beside the cube's image (it hides x in about [-0.02, 0.22]).
  for (int offset : {-20, -12, -6, 6, 9, 14, 22}) {
    const int px = p.width / 2 + offset, py = p.height / 2 + 3;
    const double x = 0.1 + (px + 0.5 - 0.5 * p.width) * worldPerPixel;
    const double y = -0.05 - (py + 0.5 - 0.5 * p.height) * worldPerPixel;
    double E = 0;  // per unit radiance
    const int n = 400;
    for (const Face& f : faces) {
      const double front = (x - f.corner.x) * f.normal.x + (y - f.corner.y) * f.normal.y +
                           (0.0 - f.corner.z) * f.normal.z;
      if (front <= 0) continue;
      const double dA = double(side) * side / (double(n) * n);
      for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j) {
          const Vec3 q = f.corner + f.u * float((i + 0.5) / n) + f.v * float((j + 0.5) / n);
          const double dx = q.x - x, dy = q.y - y, dz = q.z;
          const double r2 = dx * dx + dy * dy + dz * dz;
          const double cosReceiver = dz / std::sqrt(r2);
          const double cosEmitter = -(dx * f.normal.x + dy * f.normal.y + dz * f.normal.z) /
                                    std::sqrt(r2);
          if (cosReceiver > 0 && cosEmitter > 0) E += cosReceiver * cosEmitter / r2 * dA;
        }
      }
    }
    for (int c = 0; c < 3; ++c) {
      const double expected = s.albedo[c] * radiance[c] * E / kPi;
      EXPECT_NEAR(image.pixel(px, py)[c], expected, 5e-3 * expected)
          << "pixel " << px << ", channel " << c;
    }
  }
}

// Soft shadows: a straight blocker edge under the square light casts a
// penumbra in which the visible fraction of the light (the image over the
// image without the blocker) rises without steps (no bands) from the umbra
// to full light, over as many pixels as the light's size says.
TEST_F(RenderImage, AreaLightPenumbraIsSmoothAndMonotonic) {
  QuadSetup s;
  const float h = 0.6f, side = 0.4f;
  addSquareEmitter(s.scene, 0.1f, -0.05f, h, side, {3.0f, 3.0f, 3.0f});
  s.camera = PinholeCamera::lookAt({0.1f, -0.05f, 0.25f}, {0.1f, -0.05f, 0.0f}, 60.0f * kPi / 180.0f);
  const GpuOctree octree = test::emptyOctree();
  RenderParams p = QuadSetup::directParams();
  p.width = 160;
  p.height = 120;
  const RgbImage open = s.render(octree, p);
  // Blocker: the half plane x < 0.1 at z = 0.3 (halfway), facing up.
  test::addQuad(s.scene, {-1.0f, -1.0f, 0.3f}, {1.1f, 0, 0}, {0, 2.0f, 0}, {0, 0, 1}, 0);
  const RgbImage image = s.render(octree, p);
  writePng(test::outputDir("render_penumbra") + "/rendered.png", image, 0.0f);
  // Along the row through the centre: x from -0.04 to 0.24 on the quad.
  const int y = p.height / 2;
  std::vector<float> visible;
  for (int x = 0; x < p.width; ++x) visible.push_back(image.pixel(x, y)[0] / open.pixel(x, y)[0]);
  EXPECT_LT(visible.front(), 0.5f) << "the left end is in the shadow's inner half";
  EXPECT_GT(visible.back(), 0.9f) << "the right end sees nearly all the light";
  int rising = 0;
  for (size_t x = 1; x < visible.size(); ++x) {
    EXPECT_GE(visible[x], visible[x - 1] - 1e-3f) << "step down at pixel " << x;
    EXPECT_LE(visible[x] - visible[x - 1], 0.05f) << "a band edge at pixel " << x;
    if (visible[x] > 0.1f && visible[x] < 0.9f) ++rising;
  }
  // The geometric penumbra here is side * (h - 0.3) / 0.3 = 0.4 units wide
  // on the quad: tens of pixels, not a hard edge.
  EXPECT_GE(rising, 10) << "pixels between 10% and 90% of the light";
}

}  // namespace
}  // namespace lo
