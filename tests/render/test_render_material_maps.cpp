// Material maps and vertex data in the renderer under OSMesa: normal maps in
// the derived and the file's tangent frame, metallic-roughness and occlusion
// maps (float and 8-bit), vertex colours.

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

/// QuadSetup's quad (u along +x) with a constant normal map tilting the
/// normal by `theta` towards +u, under a sun of 2 W/m^2 coming from
/// (sunX, 0, cos theta).
QuadSetup normalMappedQuad(float theta, float sunX) {
  QuadSetup s;
  Texture map = Texture::fromLinear(
      1, 1, {Vec3{0.5f * (std::sin(theta) + 1.0f), 0.5f, 0.5f * (std::cos(theta) + 1.0f)}});
  s.scene.textures.push_back(map);
  s.scene.materials[0].normalTexture = 0;
  s.scene.texcoords0 = {0, 0, 1, 0, 1, 1, 0, 1};  // u along +x
  Light sun;
  sun.type = Light::Type::Directional;
  sun.direction = -Vec3{sunX, 0.0f, std::cos(theta)};  // the way the light travels
  sun.intensity = 2.0f;                                 // W/m^2
  s.scene.lights.push_back(sun);
  return s;
}

/// The brightness (red) of the centre pixel of `s` in direct light.
float centreBrightness(const QuadSetup& s) {
  const RenderParams p = QuadSetup::directParams();
  return s.render(test::emptyOctree(), p).pixel(p.width / 2, p.height / 2)[0];
}

// Normal maps: a constant map tilting the normal by theta towards +u (the
// quad's +x, where u grows) makes the quad as bright as a surface facing a
// sun that comes from that tilted direction, and cos(2 theta) as bright when
// the sun comes from the mirrored direction: the map is read, in the right
// frame and with the right sign.
TEST_F(RenderImage, NormalMapTiltsTheShadingNormal) {
  const float theta = 0.4f;
  float brightness[2];
  for (int side = 0; side < 2; ++side) {
    const float sx = side == 0 ? std::sin(theta) : -std::sin(theta);
    brightness[side] = centreBrightness(normalMappedQuad(theta, sx));
  }
  const float facing = 0.5f * kInvPi * 2.0f;  // albedo.x / pi * E
  EXPECT_NEAR(brightness[0], facing, 0.01f * facing);
  EXPECT_NEAR(brightness[1], facing * std::cos(2.0f * theta), 0.01f * facing);
}

// glTF TANGENT: a file tangent along -u turns the map's tilt around: the
// sun the derived frame faced is now the mirrored one (cos 2 theta), and
// Scene::shadingNormal (the path tracer's) tilts the same way.
TEST_F(RenderImage, FileTangentsOrientTheNormalMap) {
  const float theta = 0.4f;
  QuadSetup s = normalMappedQuad(theta, std::sin(theta));
  s.scene.tangents.clear();
  for (size_t v = 0; v < s.scene.positions.size(); ++v) {
    s.scene.tangents.insert(s.scene.tangents.end(), {-1.0f, 0.0f, 0.0f, 1.0f});
  }
  const float brightness = centreBrightness(s);
  const float facing = 0.5f * kInvPi * 2.0f;
  EXPECT_NEAR(brightness, facing * std::cos(2.0f * theta), 0.01f * facing);
  // The path tracer's shading normal: tilted towards -x.
  const Vec3 n = s.scene.shadingNormal(0, 0.3f, 0.3f, Vec3{0, 0, 1});
  EXPECT_NEAR(n.x, -std::sin(theta), 1e-3f);
  EXPECT_NEAR(n.z, std::cos(theta), 1e-3f);
}

/// The quad of the material map tests: QuadSetup's, u along +x, under a
/// point light of intensity 2 at (0.3, 0.1, 1); their indirect light is
/// test::constantOctree (one white VDL along +z in every voxel).
QuadSetup mapTestQuad() {
  QuadSetup s;
  s.scene.texcoords0 = {0, 0, 1, 0, 1, 1, 0, 1};
  s.scene.lights.push_back(test::pointLight({0.3f, 0.1f, 1.0f}, 2.0f));
  return s;
}

/// What they draw: QuadSetup::params(false) with specular, in `mode`.
RenderParams mapTestParams(RenderMode mode) {
  RenderParams p = QuadSetup::params(false);
  p.specular = true;
  p.mode = mode;
  return p;
}

// metallicRoughnessTexture: B scales metallic, G roughness. A metal material
// (factor 1) whose map says metallic 0 renders as the dielectric of the same
// roughness; and occlusionTexture darkens the octree's light only: R = 0.25
// at strength 1 leaves a quarter of the indirect image and all of the direct.
TEST_F(RenderImage, MetallicRoughnessAndOcclusionMaps) {
  auto render = [](bool metalWithMap, float occlusion, RenderMode mode) {
    QuadSetup s = mapTestQuad();
    Material& m = s.scene.materials[0];
    m.roughness = 0.6f;
    m.metallic = metalWithMap ? 1.0f : 0.0f;
    if (metalWithMap) {
      Texture mr = Texture::fromLinear(1, 1, {Vec3{0.0f, 1.0f, 0.0f}});  // roughness x1, metallic x0
      s.scene.textures.push_back(mr);
      m.metallicRoughnessTexture = int(s.scene.textures.size()) - 1;
    }
    if (occlusion < 1.0f) {
      Texture ao = Texture::fromLinear(1, 1, {Vec3{occlusion, 0.0f, 0.0f}});
      s.scene.textures.push_back(ao);
      m.occlusionTexture = int(s.scene.textures.size()) - 1;
    }
    return s.render(test::constantOctree(), mapTestParams(mode));
  };
  const RgbImage dielectric = render(false, 1.0f, RenderMode::Full);
  const RgbImage mapped = render(true, 1.0f, RenderMode::Full);
  const int x = 32, y = 24;
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(mapped.pixel(x, y)[c], dielectric.pixel(x, y)[c], 2e-3f * dielectric.pixel(x, y)[c]);
  }
  const float indirect = render(false, 1.0f, RenderMode::Indirect).pixel(x, y)[0];
  EXPECT_NEAR(render(false, 0.25f, RenderMode::Indirect).pixel(x, y)[0], 0.25f * indirect,
              2e-3f * indirect);
  const float direct = render(false, 1.0f, RenderMode::Direct).pixel(x, y)[0];
  EXPECT_NEAR(render(false, 0.25f, RenderMode::Direct).pixel(x, y)[0], direct, 1e-6f + 1e-4f * direct);
}

// 8-bit data maps go up as the channels the shader reads of them (occlusion
// as one, R8; metallic-roughness as two, RG8 swizzled back to .gb): each
// renders as its float twin, which goes up whole. R of the
// metallic-roughness map and G, B of the occlusion map are 1 where the
// shader must not read them, so a channel read wrongly shows. The caller
// may free each texture's texels once its copy is made: the image stays.
TEST_F(RenderImage, EightBitDataMapsRenderAsTheirFloatTwins) {
  auto unorm8 = [](uint8_t r, uint8_t g, uint8_t b) {
    Texture t;
    t.width = t.height = 1;
    t.channels = 3;
    t.format = TexelFormat::Unorm8;
    t.unorm8 = {r, g, b};
    return t;
  };
  enum class Maps { None, Float, EightBit, EightBitReleased };
  auto render = [&](Maps maps) {
    QuadSetup s = mapTestQuad();
    Material& m = s.scene.materials[0];
    m.metallic = 1.0f;
    if (maps != Maps::None) {
      const bool eightBit = maps != Maps::Float;
      s.scene.textures.push_back(eightBit ? unorm8(255, 153, 51)
                                          : Texture::fromLinear(1, 1, {Vec3{1.0f, 0.6f, 0.2f}}));
      m.metallicRoughnessTexture = 0;  // roughness 0.6, metallic 0.2
      s.scene.textures.push_back(eightBit ? unorm8(64, 255, 255)
                                          : Texture::fromLinear(1, 1, {Vec3{64 / 255.0f, 1, 1}}));
      m.occlusionTexture = 1;
    }
    std::vector<int> uploaded;
    Renderer renderer(s.scene, test::constantOctree(), {}, [&](int texture) {
      uploaded.push_back(texture);
      if (maps == Maps::EightBitReleased) s.scene.releaseTexels(size_t(texture));
    });
    std::sort(uploaded.begin(), uploaded.end());
    EXPECT_EQ(uploaded.size(), s.scene.textures.size()) << "each texture reported once";
    for (size_t i = 0; i < uploaded.size(); ++i) EXPECT_EQ(uploaded[i], int(i));
    return renderer.render(s.camera, mapTestParams(RenderMode::Full));
  };
  const RgbImage unmapped = render(Maps::None);
  const RgbImage twin = render(Maps::Float);
  const RgbImage eightBit = render(Maps::EightBit);
  const RgbImage released = render(Maps::EightBitReleased);
  double mapEffect = 0;
  int offTwin = 0, offReleased = 0;
  for (int y = 0; y < twin.height; ++y) {
    for (int x = 0; x < twin.width; ++x) {
      for (int c = 0; c < 3; ++c) {
        const float t = twin.pixel(x, y)[c], e = eightBit.pixel(x, y)[c];
        offTwin += std::fabs(e - t) > 1e-4f + 3e-3f * t;
        offReleased += released.pixel(x, y)[c] != e;
        mapEffect = std::max(mapEffect, double(std::fabs(t - unmapped.pixel(x, y)[c]) /
                                               std::max(unmapped.pixel(x, y)[c], 1e-3f)));
      }
    }
  }
  EXPECT_EQ(offTwin, 0) << "pixel channels of the 8-bit maps' image off their float twins' by > 0.3%";
  EXPECT_EQ(offReleased, 0) << "pixel channels that changed when the texels were freed";
  EXPECT_GT(mapEffect, 0.2) << "the maps change the image (the comparison is not of equals)";
}

// Vertex colours (COLOR_0) multiply the base colour as a factor does: a
// quad whose corners all carry (0.5, 1, 0.25) draws as the quad whose factor
// holds that colour; a masked quad whose vertex alpha is 0 is cut out.
TEST_F(RenderImage, VertexColoursMultiplyTheBaseColour) {
  const GpuOctree octree = test::constantOctree();
  const RenderParams p = QuadSetup::params(false);
  QuadSetup tinted;
  for (size_t v = 0; v < tinted.scene.positions.size(); ++v) {
    tinted.scene.colors.insert(tinted.scene.colors.end(), {0.5f, 1.0f, 0.25f, 1.0f});
  }
  QuadSetup factor;
  factor.scene.materials[0].baseColor = factor.albedo * Vec3(0.5f, 1.0f, 0.25f);
  const RgbImage a = tinted.render(octree, p);
  const RgbImage b = factor.render(octree, p);
  const float centre = b.pixel(32, 24)[0];
  EXPECT_GT(centre, 0.01f) << "the quad is lit";
  int off = 0;
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      for (int c = 0; c < 3; ++c) off += std::fabs(a.pixel(x, y)[c] - b.pixel(x, y)[c]) > 1e-5f;
    }
  }
  EXPECT_EQ(off, 0) << "pixel channels where the vertex colour differs from the factor";

  QuadSetup cut = tinted;
  cut.scene.materials[0].alphaMode = AlphaMode::Mask;
  for (size_t v = 0; v < cut.scene.positions.size(); ++v) cut.scene.colors[4 * v + 3] = 0.0f;
  EXPECT_EQ(cut.render(octree, p).pixel(32, 24)[0], 0.0f)
      << "vertex alpha 0 under a mask: no surface";
}

}  // namespace
}  // namespace lo
