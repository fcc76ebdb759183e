// Shadows at any scale: a 7.5 cm block on an 8 m floor under a spot, the
// whole scene scaled by 1e-3, 1 and 1e3, drawn by the renderer's direct light
// and judged per pixel against the analytic answer (a ray cast from the
// floor point to the spot past the block, glTF's cone falloff and the
// inverse-square law). Nothing in the shadow lookup is in scene units: a
// small object in a large scene keeps its shadow, and every scale draws the
// same picture.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <optional>
#include <string>

#include "core/error.h"
#include "image/image.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

using RenderScale = test::GlTest;

constexpr float kAlbedo = 0.6f;

/// Entry distance of the ray o + t d into the box, or nothing.
std::optional<float> hitBox(const Vec3& o, const Vec3& d, const Bounds3& box) {
  float t0 = 0, t1 = 1e30f;
  for (int a = 0; a < 3; ++a) {
    if (std::fabs(d[a]) < 1e-12f) {
      if (o[a] < box.lower[a] || o[a] > box.upper[a]) return std::nullopt;
      continue;
    }
    float ta = (box.lower[a] - o[a]) / d[a], tb = (box.upper[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (t0 > t1) return std::nullopt;
  return t0;
}

struct ScaledSpotScene {
  float s = 1;  // the scale
  Scene scene;
  Bounds3 block;
  Light spot;
  PinholeCamera camera;

  explicit ScaledSpotScene(float scale) : s(scale) {
    Material m;
    m.baseColor = {kAlbedo, kAlbedo, kAlbedo};
    m.roughness = 1.0f;
    scene.materials.push_back(m);
    // The floor: 8 m across, 107 times the block's length.
    test::addQuad(scene, Vec3{-4, -4, 0} * s, Vec3{8, 0, 0} * s, Vec3{0, 8, 0} * s, {0, 0, 1}, 0);
    block = Bounds3{Vec3{-0.0375f, -0.015f, 0} * s, Vec3{0.0375f, 0.015f, 0.03f} * s};
    test::addBlock(scene, block.lower, block.upper, 0);
    spot.type = Light::Type::Spot;
    spot.position = Vec3{-0.15f, 0, 0.2f} * s;
    spot.direction = normalize(Vec3{0.2f, 0, -0.2f});
    spot.innerConeAngle = 25.0f * kPi / 180.0f;
    spot.outerConeAngle = 35.0f * kPi / 180.0f;
    spot.intensity = 0.1f * s * s;  // W/sr: the same irradiance at every scale
    scene.lights.push_back(spot);
    camera = PinholeCamera::lookAt(Vec3{0.06f, -0.22f, 0.22f} * s, Vec3{0.06f, 0, 0} * s,
                                   40.0f * kPi / 180.0f);
    camera.znear = 1e-3f * s;  // a camera made for this scene's size
  }

  /// The ray through image point (x, y) (pixels, row 0 at the top).
  Vec3 rayDirection(float x, float y, int width, int height) const {
    const float tanHalf = std::tan(0.5f * camera.yfov);
    const float aspect = float(width) / float(height);
    const Vec3 right = normalize(cross(camera.forward, camera.up));
    const float u = (x / float(width) * 2.0f - 1.0f) * tanHalf * aspect;
    const float v = (1.0f - y / float(height) * 2.0f) * tanHalf;
    return normalize(camera.forward + right * u + camera.up * v);
  }

  /// The floor point seen through (x, y) and whether the spot reaches it;
  /// nothing where the block is seen, or the floor is not.
  std::optional<bool> floorLit(float x, float y, int width, int height, Vec3& point) const {
    const Vec3 d = rayDirection(x, y, width, height);
    if (hitBox(camera.eye, d, block)) return std::nullopt;
    if (!(d.z < 0)) return std::nullopt;
    point = camera.eye + d * (-camera.eye.z / d.z);
    const Vec3 toLight = spot.position - point;
    const auto blocker = hitBox(point, toLight, block);
    return !(blocker && *blocker < 1.0f);
  }

  /// The analytic direct light leaving floor point p: albedo / pi times the
  /// spot's irradiance (cone falloff of KHR_lights_punctual).
  float radiance(const Vec3& p) const {
    const Vec3 toLight = spot.position - p;
    const float d2 = dot(toLight, toLight);
    const Vec3 l = toLight / std::sqrt(d2);
    const float cd = dot(-l, spot.direction);
    const float cosOuter = std::cos(spot.outerConeAngle), cosInner = std::cos(spot.innerConeAngle);
    const float t = std::clamp((cd - cosOuter) / (cosInner - cosOuter), 0.0f, 1.0f);
    return kAlbedo * kInvPi * spot.intensity * t * t * std::max(l.z, 0.0f) / d2;
  }
};

TEST_F(RenderScale, ASmallObjectInALargeSceneShadowsTheSameAtEveryScale) {
  RenderParams p = test::QuadSetup::directParams();
  p.width = 160;
  p.height = 120;
  const GpuOctree octree = test::emptyOctree();
  const std::string dir = test::outputDir("RenderScale");
  std::optional<RgbImage> unitImage;
  for (float scale : {1e-3f, 1.0f, 1e3f}) {
    SCOPED_TRACE("scale " + std::to_string(scale));
    const ScaledSpotScene s(scale);
    const RgbImage image = Renderer(s.scene, octree).render(s.camera, p);
    int shadowed = 0, lit = 0, wrong = 0;
    for (int y = 0; y < p.height; ++y) {
      for (int x = 0; x < p.width; ++x) {
        // Judged only where the pixel's centre and four points a pixel
        // apart agree (the shadow's edge and the block's outline left out).
        Vec3 centre;
        const auto here = s.floorLit(x + 0.5f, y + 0.5f, p.width, p.height, centre);
        if (!here) continue;
        bool agree = true;
        for (const auto& o : {std::pair{-0.5f, 0.5f}, {1.5f, 0.5f}, {0.5f, -0.5f}, {0.5f, 1.5f}}) {
          Vec3 q;
          const auto there = s.floorLit(x + o.first, y + o.second, p.width, p.height, q);
          agree = agree && there && *there == *here;
        }
        const float expected = s.radiance(centre);
        if (!agree || expected < 0.05f * s.radiance(Vec3{0.06f, 0, 0} * scale)) continue;
        const float got = image.pixel(x, y)[0];
        if (*here) {
          ++lit;
          if (std::fabs(got - expected) > 0.05f * expected) ++wrong;
        } else {
          ++shadowed;
          if (got > 0.05f * expected) {
            if (wrong < 5) ADD_FAILURE() << "lit in the shadow at (" << x << ", " << y << "): " << got;
            ++wrong;
          }
        }
      }
    }
    if (wrong > 0) {
      const std::string file = dir + "/scale-" +
                               std::to_string(int(std::log10(scale))) + ".png";
      writePng(file, image, 4.0f);
      writeExr(file + ".exr", image);
      ADD_FAILURE() << "the picture: " << file;
    }
    EXPECT_GT(shadowed, 100) << "the view should show the block's shadow";
    EXPECT_GT(lit, 1000);
    EXPECT_EQ(wrong, 0) << "of " << shadowed << " shadowed and " << lit << " lit pixels";
    if (!unitImage) {
      unitImage = image;
    } else {
      double diff = 0;
      for (size_t i = 0; i < image.rgb.size(); ++i)
        diff += std::fabs(double(image.rgb[i]) - double(unitImage->rgb[i]));
      diff /= double(image.rgb.size());
      EXPECT_LT(diff, 2e-3 * meanLuminance(*unitImage)) << "the picture changes with the scale";
    }
  }
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

/// QuadSetup's quad under a point light in front of it.
test::QuadSetup litQuad() {
  test::QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));
  return s;
}

// A lit quad with a second one 10^4 and 10^5 units away (a room on a large
// ground): the camera's near plane followed the far plane (1e-4 of it), lay
// beyond the quad, and every pixel was black (H16-4-1). It stays nearer
// than the nearest triangle: the picture is the one without the far quad.
TEST_F(RenderScale, AQuadIsDrawnWithAnotherFarAway) {
  using test::QuadSetup;
  const RenderParams p = QuadSetup::directParams();
  const GpuOctree octree = test::emptyOctree();
  const QuadSetup alone = litQuad();
  const RgbImage near = alone.render(octree, p);
  const float* centre = near.pixel(p.width / 2, p.height / 2);
  ASSERT_GT(centre[0], 0.01f);
  for (float away : {1e4f, 1e5f}) {
    QuadSetup s = alone;
    test::addQuad(s.scene, {away, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 0);
    const RgbImage both = s.render(octree, p);
    const float* c = both.pixel(p.width / 2, p.height / 2);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(c[k], centre[k], 0.02f * centre[k]) << "quad " << away << " away, channel " << k;
    }
  }
}

// The scene's vertices in the GL driver are counted before they are made:
// a scene whose triangles need more than the memory available is refused
// naming them, where the loader's budget (256 bytes a triangle) let it
// through and the driver ran out of memory (H17-5-1). Each quad's two
// triangles take kRenderBytesPerTriangle (396) bytes: 100,000 quads need
// 79 MB, over a 64 MiB limit; the same scene draws under 256 MiB.
TEST_F(RenderScale, AGeometryBeyondTheMemoryIsRefusedBeforeTheDriver) {
  using test::QuadSetup;
  const RenderParams p = QuadSetup::directParams();
  const GpuOctree octree = test::emptyOctree();
  QuadSetup s = litQuad();
  for (int i = 0; i < 100000; ++i) {
    test::addQuad(s.scene, {-1, -1, -1.0f - 1e-4f * float(i)}, {2e-3f, 0, 0}, {0, 2e-3f, 0},
                  {0, 0, 1}, 0);
  }
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "64M", 1);
  try {
    s.render(octree, p);
    ADD_FAILURE() << "200,000 triangles drawn under a 64 MiB limit";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("the scene's 200,002 triangles need about"),
              std::string::npos)
        << e.what();
  }
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "256M", 1);
  EXPECT_NO_THROW(s.render(octree, p));
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
}

}  // namespace
}  // namespace lo
