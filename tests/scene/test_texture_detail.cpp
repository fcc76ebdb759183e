// Texture detail for fixed views (scene/texture_detail.h): the mip level a
// view can sample, by hand for a quad facing the camera, and a texture's
// reduced levels against the means of their blocks.

#include <gtest/gtest.h>

#include <cmath>

#include "image/image.h"
#include "scene/texture_detail.h"
#include "test_util.h"

namespace lo {
namespace {

/// A unit quad in z = 0 facing +z, UVs 0..1 across it, its base colour
/// (and, when `emissive`, its emission) read from a `size`^2 texture.
Scene texturedQuad(int size, bool emissive = false) {
  Scene scene;
  Material m;
  m.baseColorTexture = 0;
  if (emissive) {
    m.emission = Vec3(1.0f);
    m.emissiveTexture = 0;
  }
  scene.materials.push_back(m);
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  scene.texcoords0 = {0, 0, 1, 0, 1, 1, 0, 1};
  scene.textures.push_back(
      Texture::fromLinear(size, size, std::vector<Vec3>(size_t(size) * size, Vec3(0.5f))));
  return scene;
}

/// A view of the quad from `distance` in front of its centre, the frustum
/// one scene unit high at distance 1 (tan(yfov / 2) = 0.5), `pixels` square.
TextureViews viewFrom(float distance, int pixels) {
  TextureViews views;
  const PinholeCamera camera =
      PinholeCamera::lookAt({0.5f, 0.5f, distance}, {0.5f, 0.5f, 0}, 2.0f * std::atan(0.5f));
  views.cameras.push_back({camera, pixels, pixels});
  return views;
}

TEST(TextureDetail, TheLevelIsTheTexelsPerPixelOfTheNearestPoint) {
  // 1024 texels per unit; at distance 2, 64 pixels span 2 units: 32 pixels
  // per unit, 32 texels per pixel, level 5; half a level of margin: 4.
  const Scene quad = texturedQuad(1024);
  TextureLevels levels = textureLevelsFor(quad, viewFrom(2.0f, 64));
  ASSERT_EQ(levels.drawn.size(), 1u);
  EXPECT_EQ(levels.drawn[0], 4);
  EXPECT_EQ(levels.kept[0], 4);
  // Twice the pixels: one level finer; twice as far: one coarser.
  EXPECT_EQ(textureLevelsFor(quad, viewFrom(2.0f, 128)).drawn[0], 3);
  EXPECT_EQ(textureLevelsFor(quad, viewFrom(4.0f, 64)).drawn[0], 5);
  // Two views: the finer one wins.
  TextureViews both = viewFrom(4.0f, 64);
  both.cameras.push_back(viewFrom(2.0f, 128).cameras[0]);
  EXPECT_EQ(textureLevelsFor(quad, both).drawn[0], 3);
  // Close enough to magnify: the full image.
  EXPECT_EQ(textureLevelsFor(quad, viewFrom(0.05f, 512)).drawn[0], 0);
}

TEST(TextureDetail, WhatNoViewSeesGoesDownToOneTexel) {
  const Scene quad = texturedQuad(256);
  TextureViews away;
  away.cameras.push_back({PinholeCamera::lookAt({0.5f, 0.5f, 2}, {0.5f, 0.5f, 4}, 1.0f), 64, 64});
  EXPECT_EQ(textureLevelsFor(quad, away).drawn[0], 8);
  // Beside the frustum.
  TextureViews aside;
  aside.cameras.push_back({PinholeCamera::lookAt({5, 0.5f, 2}, {5, 0.5f, 0}, 0.5f), 64, 64});
  EXPECT_EQ(textureLevelsFor(quad, aside).drawn[0], 8);
  // Degenerate UVs show one line of texels at any level: they ask for none.
  Scene line = texturedQuad(256);
  line.texcoords0 = {0, 0.5f, 1, 0.5f, 1, 0.5f, 0, 0.5f};
  EXPECT_EQ(textureLevelsFor(line, viewFrom(2.0f, 64)).drawn[0], 8);
}

TEST(TextureDetail, TheProbeAtTheSurfaceAsksForTheFullImage) {
  const Scene quad = texturedQuad(1024);
  TextureViews views = viewFrom(8.0f, 16);
  const int cameraOnly = textureLevelsFor(quad, views).drawn[0];
  EXPECT_GT(cameraOnly, 4);
  views.cubeCentre = {0.5f, 0.5f, 0.01f};
  views.cubeFaceSize = 128;
  EXPECT_EQ(textureLevelsFor(quad, views).drawn[0], 0);
  // Far away, the probe's 128 texels per face ask for little.
  views.cubeCentre = {0.5f, 0.5f, 50.0f};
  EXPECT_EQ(textureLevelsFor(quad, views).drawn[0], cameraOnly);
}

TEST(TextureDetail, TexelsTheLightsReadAreKeptWhole) {
  // An emissive map places the emitters' light: the views may draw it
  // coarser, the scene keeps it whole.
  const TextureLevels levels = textureLevelsFor(texturedQuad(1024, true), viewFrom(2.0f, 64));
  EXPECT_EQ(levels.drawn[0], 4);
  EXPECT_EQ(levels.kept[0], 0);
  // So does a blended material's alpha, which the shadow maps cut.
  Scene blended = texturedQuad(1024);
  blended.materials[0].alphaMode = AlphaMode::Blend;
  EXPECT_EQ(textureLevelsFor(blended, viewFrom(2.0f, 64)).kept[0], 0);
}

TEST(TextureDetail, AReducedTextureHoldsItsBlocksMeansInLinearLight) {
  // 8-bit sRGB RGBA, 4 x 2: columns alternate black and white, alpha 0 and 255.
  Texture t;
  t.width = 4;
  t.height = 2;
  t.channels = 4;
  t.format = TexelFormat::Unorm8;
  t.srgb = true;
  t.encoded = std::make_shared<const std::vector<uint8_t>>(std::vector<uint8_t>{1, 2, 3});
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 4; ++x) {
      const uint8_t v = x % 2 ? 255 : 0;
      t.unorm8.insert(t.unorm8.end(), {v, v, v, v});
    }
  }
  const Texture half = reducedTexture(t, 1);
  ASSERT_EQ(half.width, 2);
  ASSERT_EQ(half.height, 1);
  ASSERT_EQ(half.unorm8.size(), 8u);
  // Linear 0.5 is sRGB 0.7354, 187.5 of 255; alpha stays linear: 127.5.
  EXPECT_EQ(half.unorm8[0], uint8_t(std::lround(linearToSrgb(0.5f) * 255.0f)));
  EXPECT_NEAR(half.texel(0, 0).x, 0.5f, 0.003f);
  EXPECT_EQ(half.unorm8[3], 128);
  EXPECT_FALSE(half.encoded) << "the file's bytes no longer describe the texels";
  EXPECT_EQ(half.sampler.wrapS, t.sampler.wrapS);
  // Past the last level: one texel, the mean of all.
  const Texture one = reducedTexture(t, 9);
  EXPECT_EQ(one.width, 1);
  EXPECT_EQ(one.height, 1);
  EXPECT_NEAR(one.texel(0, 0).x, 0.5f, 0.003f);
  // An odd size: the last block reaches the edge (5 x 3 -> 2 x 1; the
  // second texel is the mean of columns 2..4, rows 0..2).
  const std::vector<Vec3> ramp = {Vec3(0.0f), Vec3(0.1f), Vec3(0.2f), Vec3(0.3f), Vec3(0.4f)};
  std::vector<Vec3> rows;
  for (int y = 0; y < 3; ++y) rows.insert(rows.end(), ramp.begin(), ramp.end());
  const Texture odd = reducedTexture(Texture::fromLinear(5, 3, rows), 1);
  ASSERT_EQ(odd.width, 2);
  ASSERT_EQ(odd.height, 1);
  EXPECT_NEAR(odd.texel(0, 0).x, 0.05f, 1e-6f);
  EXPECT_NEAR(odd.texel(1, 0).x, 0.3f, 1e-6f);
}

TEST(TextureDetail, ReleasedTexelsLeaveEmptyTexturesWithTheirSamplers) {
  Scene quad = texturedQuad(64);
  quad.textures[0].sampler.wrapS = 33071;  // GL_CLAMP_TO_EDGE
  releaseTexels(quad);
  ASSERT_EQ(quad.textures.size(), 1u);
  EXPECT_TRUE(quad.textures[0].empty());
  EXPECT_EQ(quad.textures[0].byteSize(), 0u);
  EXPECT_EQ(quad.textures[0].sampler.wrapS, 33071);
}

}  // namespace
}  // namespace lo
