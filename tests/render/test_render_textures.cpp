// Textures in the renderer under OSMesa: base colour sampled per pixel as the
// bake's own lookup reads it, KHR_texture_transform, the glTF sampler's
// filter, the emissive texture.

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

/// QuadSetup's quad, white but for its base colour texture `texture` read
/// at `texcoords` (its four corners' UVs), under a point light of 2 W/sr
/// right above the view's centre.
QuadSetup texturedQuad(const Texture& texture, const std::vector<float>& texcoords) {
  QuadSetup s;
  s.scene.textures.push_back(texture);
  s.scene.materials[0].baseColor = {1, 1, 1};
  s.scene.materials[0].baseColorTexture = 0;
  s.scene.texcoords0 = texcoords;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));
  return s;
}

/// Renders QuadSetup's quad with a red/blue checker (16x16 texels, cells of
/// 4x4) repeated twice across it under a point light, and checks that the
/// centres of two neighbouring cells show the colours the bake's own lookup
/// (Scene::albedo) gives there. Returns which of the two was red.
std::vector<bool> checkCheckerQuad(const TextureTransform& transform, const std::string& name) {
  const Vec3 red{0.8f, 0.1f, 0.1f}, blue{0.1f, 0.1f, 0.8f};
  std::vector<Vec3> squares;
  for (int y = 0; y < 16; ++y) {
    for (int x = 0; x < 16; ++x) squares.push_back((x / 4 + y / 4) % 2 ? blue : red);
  }
  // The quad's corners (-1,-1), (1,-1), (1,1), (-1,1): UV = (x + 1, y + 0.675),
  // 8 cells per world unit; the row y = -0.05 through the view centre is at
  // v = 0.625, a cell centre, and so are x = -0.0625 and x = 0.0625. Cell
  // centres lie two texels from any border, where bilinear filtering
  // returns the cell's colour.
  QuadSetup s = texturedQuad(Texture::fromLinear(16, 16, squares),
                             {0, -0.325f, 2, -0.325f, 2, 1.675f, 0, 1.675f});
  s.scene.materials[0].baseColorTransform = transform;
  RenderParams p = QuadSetup::directParams();
  p.width = 128;
  p.height = 96;
  const RgbImage image = s.render(test::emptyOctree(), p);
  const std::string dir = test::outputDir(name);
  writePng(dir + "/rendered.png", image, 1.0f);
  const float worldPerPixel = s.worldPerPixel(p, 2.0f);
  std::vector<bool> isRed;
  for (float x : {-0.0625f, 0.0625f}) {
    const float y = -0.05f;
    const int px = p.width / 2 + int(std::floor((x - 0.1f) / worldPerPixel));
    const float* c = image.pixel(px, p.height / 2);
    // Triangle 0 of the quad (corners 0, 1, 2) holds (x, y) when y < x,
    // triangle 1 (corners 0, 2, 3) otherwise; barycentrics of the point.
    const Vec3 albedo = y < x ? s.scene.albedo(0, 0.5f * (x - y), 0.5f * (y + 1.0f))
                              : s.scene.albedo(1, 0.5f * (x + 1.0f), 0.5f * (y - x));
    isRed.push_back(albedo.x > albedo.z);
    const float ratio = c[0] / c[2], expected = albedo.x / albedo.z;
    EXPECT_NEAR(ratio, expected, 0.02f * expected)
        << "at x = " << x << ": rendered " << c[0] << " " << c[1] << " " << c[2] << " (" << dir
        << "/rendered.png)";
  }
  return isRed;
}

// The glTF sampler reaches the GL texture: a NEAREST magnification filter
// keeps a two-texel texture's halves sharp where LINEAR blends them, as the
// tracers' Texture::lookup does.
TEST_F(RenderImage, GltfSamplerFiltersTheTexture) {
  for (int filter : {TextureSampler::kNearest, TextureSampler::kLinear}) {
    // red | blue along u
    Texture halves = Texture::fromLinear(2, 1, {Vec3{0.8f, 0.1f, 0.1f}, Vec3{0.1f, 0.1f, 0.8f}});
    halves.sampler.magFilter = filter;
    halves.sampler.wrapS = halves.sampler.wrapT = TextureSampler::kClampToEdge;
    // u = (x + 1) / 2 across the quad's corners (-1,-1), (1,-1), (1,1), (-1,1).
    const QuadSetup s = texturedQuad(halves, {0, 0.5f, 1, 0.5f, 1, 0.5f, 0, 0.5f});
    const RenderParams p = QuadSetup::directParams();
    const RgbImage image = s.render(test::emptyOctree(), p);
    // x = -0.1 on the quad: u = 0.45, 0.9 texels from the left edge.
    const float worldPerPixel = s.worldPerPixel(p, 2.0f);
    const int px = p.width / 2 + int(std::floor((-0.1f - 0.1f) / worldPerPixel));
    const float* c = image.pixel(px, p.height / 2);
    const float x = 0.1f + (float(px) + 0.5f - 0.5f * float(p.width)) * worldPerPixel;
    const Vec3 expected = halves.lookup(0.5f * (x + 1.0f), 0.5f);
    SCOPED_TRACE(filter == TextureSampler::kNearest ? "nearest" : "linear");
    EXPECT_NEAR(c[0] / c[2], expected.x / expected.z, 0.03f * expected.x / expected.z);
    if (filter == TextureSampler::kNearest) {
      EXPECT_NEAR(c[0] / c[2], 8.0f, 0.1f);
    } else {
      EXPECT_LT(c[0] / c[2], 3.0f);
    }
  }
}

// glTF base colour textures are sampled per pixel (they were sampled at the
// vertices, so a checker floor came out one colour).
TEST_F(RenderImage, BaseColorTextureIsSampledPerPixel) {
  const std::vector<bool> red = checkCheckerQuad(TextureTransform{}, "render_checker");
  EXPECT_NE(red[0], red[1]) << "one red and one blue cell: the checker appears";
}

// KHR_texture_transform: an offset of one cell (0.25 in u) swaps the colours
// of the two cells, in the renderer and in the bake's lookup alike.
TEST_F(RenderImage, TextureTransformMovesTheTexture) {
  TextureTransform shift;
  shift.offset[0] = 0.25f;
  const std::vector<bool> plain = checkCheckerQuad(TextureTransform{}, "render_checker_plain");
  const std::vector<bool> moved = checkCheckerQuad(shift, "render_checker_moved");
  EXPECT_NE(plain[0], moved[0]);
  EXPECT_NE(plain[1], moved[1]);
}

// The emissive texture multiplies the emissive factor per pixel.
TEST_F(RenderImage, EmissiveTextureMultipliesTheEmission) {
  QuadSetup s;
  // 16 texels: red on the left half, green on the right (bilinear filtering
  // reads one colour away from the middle).
  std::vector<Vec3> halves;
  for (int x = 0; x < 16; ++x) halves.push_back(x < 8 ? Vec3{1, 0, 0} : Vec3{0, 0.5f, 0});
  s.scene.textures.push_back(Texture::fromLinear(16, 1, halves));
  s.scene.materials[0].emission = {2, 2, 2};
  s.scene.materials[0].emissiveTexture = 0;
  for (const Vec3& v : s.scene.positions) {
    s.scene.texcoords0.push_back(0.5f * (v.x + 1.0f));
    s.scene.texcoords0.push_back(0.5f);
  }
  const RenderParams p = QuadSetup::directParams();
  const RgbImage image = s.render(test::constantOctree(), p);
  const float* left = image.pixel(test::columnAt(s, p, -0.4f, 0.0f), p.height / 2);
  const float* right = image.pixel(test::columnAt(s, p, 0.6f, 0.0f), p.height / 2);
  EXPECT_NEAR(left[0], 2.0f, 2e-3f);
  EXPECT_NEAR(left[1], 0.0f, 2e-3f);
  EXPECT_NEAR(right[0], 0.0f, 2e-3f);
  EXPECT_NEAR(right[1], 1.0f, 2e-3f);
}

}  // namespace
}  // namespace lo
