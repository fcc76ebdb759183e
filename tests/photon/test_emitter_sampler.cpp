// The one emitter sampler: analytic powers (pi L A per emitting side), picks
// in proportion to power, and the photon tracer emitting exactly its total.

#include "scene/emitter_sampler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

#include "core/rng.h"
#include "photon/photon_map.h"
#include "test_util.h"

namespace lo {
namespace {

/// A closed grey box with three emissive quads inside: one single-sided
/// (radiance 1, area 0.25), one double-sided (radiance 2, area 0.16) and one
/// single-sided red one (radiance (3, 0, 0), area 0.09).
Scene threeLamps() {
  Scene scene;
  Material grey;
  grey.baseColor = {0.5f, 0.5f, 0.5f};
  scene.materials.push_back(grey);
  test::addClosedBox(scene, {-2, -2, -2}, {2, 2, 2}, 0);
  const std::vector<Vec3> radiance = {{1, 1, 1}, {2, 2, 2}, {3, 0, 0}};
  const std::vector<float> side = {0.5f, 0.4f, 0.3f};
  for (int i = 0; i < 3; ++i) {
    Material lamp;
    lamp.name = "lamp" + std::to_string(i);
    lamp.emission = radiance[size_t(i)];
    lamp.doubleSided = i == 1;
    scene.materials.push_back(lamp);
    const float s = side[size_t(i)];
    test::addQuad(scene, {-1.5f + 1.0f * float(i), 1.0f, 0}, {s, 0, 0}, {0, 0, s}, {0, -1, 0},
                  int(scene.materials.size()) - 1);
  }
  return scene;
}

TEST(EmitterSampler, PowerIsPiLAPerEmittingSide) {
  const Scene scene = threeLamps();
  const EmitterSampler s = buildEmitterSampler(scene);
  ASSERT_EQ(s.size(), 6u);  // two triangles per quad
  const std::vector<Vec3> expected = {Vec3{1, 1, 1} * float(kPi * 0.25),
                                      Vec3{2, 2, 2} * float(2 * kPi * 0.16),
                                      Vec3{3, 0, 0} * float(kPi * 0.09)};
  for (size_t k = 0; k < s.size(); ++k) {
    const Vec3 quad = s.power[k] + s.power[k ^ 1u];
    const Vec3& want = expected[k / 2];
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(quad[c], want[c], 1e-5 * (1 + want[c])) << k;
  }
  double sum = 0;
  for (const Vec3& p : s.power) sum += double(average(p));
  EXPECT_NEAR(s.total(), sum, 1e-9 * sum);
}

TEST(EmitterSampler, PicksInProportionToPower) {
  const Scene scene = threeLamps();
  const EmitterSampler s = buildEmitterSampler(scene);
  const int n = 100000;
  std::vector<int> count(s.size(), 0);
  for (int i = 0; i < n; ++i) ++count[s.pick((i + 0.5) / n)];
  double probabilitySum = 0;
  for (size_t k = 0; k < s.size(); ++k) {
    // Stratified picks: each entry's count is its share of n, to one stratum.
    EXPECT_NEAR(count[k], s.pickProbability(k) * n, 1.0) << k;
    probabilitySum += s.pickProbability(k);
  }
  EXPECT_NEAR(probabilitySum, 1.0, 1e-12);
  // The area density: pick probability over the triangle's area.
  const std::vector<float> pdf = s.areaPdfs(scene);
  ASSERT_EQ(pdf.size(), scene.triangleCount());
  for (size_t k = 0; k < s.size(); ++k)
    EXPECT_NEAR(pdf[s.triangles[k]] * scene.triangleArea(s.triangles[k]), s.pickProbability(k),
                1e-6);
  EXPECT_EQ(pdf[0], 0.0f);  // a wall of the box
}

// The photon tracer emits the sampler's power: its emitted power is the sum
// of the triangles' (there are no punctual lights), double-sided lamps twice.
TEST(EmitterSampler, PhotonTracerEmitsItsPower) {
  const Scene scene = threeLamps();
  const EmitterSampler s = buildEmitterSampler(scene);
  Vec3 total{0, 0, 0};
  for (const Vec3& p : s.power) total += p;
  PhotonParams params;
  params.storedPhotons = 1000;
  const PhotonMap map = tracePhotons(scene, params);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(map.emittedPower[c], total[c], 1e-5 * total[c]);
}

TEST(EmitterSampler, NoEmitterIsEmpty) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  const EmitterSampler s = buildEmitterSampler(scene);
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(s.total(), 0.0);
  EXPECT_EQ(s.areaPdfs(scene), std::vector<float>(1 * 2, 0.0f));
}

// Points on an emissive-textured triangle: inside it, drawn mostly where the
// texture is bright (no point in the black half but for the even share),
// and unbiased: the mean of weight x emission over the draws is the
// triangle's mean emission (a brute-force average over a fine grid of
// barycentrics), for a texture the 64 cells' centroids see only in part.
TEST(EmitterSampler, TexturedPointsFollowTheTextureWithoutBias) {
  Scene scene;
  Material lamp;
  lamp.emission = {1, 1, 1};
  lamp.emissiveTexture = 0;
  scene.materials.push_back(lamp);
  // u < 0.5 black, u >= 0.5 a ramp of 32 texels (nearest: sharp steps).
  std::vector<Vec3> texels;
  for (int x = 0; x < 64; ++x) texels.push_back(Vec3(x < 32 ? 0.0f : float(x - 31) / 32.0f));
  Texture tex = Texture::fromLinear(64, 1, texels);
  tex.sampler.magFilter = TextureSampler::kNearest;
  scene.textures.push_back(tex);
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);
  for (size_t v = 0; v < scene.positions.size(); ++v) {
    scene.texcoords0.push_back(scene.positions[v].x);
    scene.texcoords0.push_back(scene.positions[v].z);
  }
  const EmitterSampler s = buildEmitterSampler(scene);
  ASSERT_EQ(s.size(), 2u);
  for (size_t k = 0; k < s.size(); ++k) {
    SCOPED_TRACE(k);
    ASSERT_GE(s.cellTable[k], 0);
    const uint32_t t = s.triangles[k];
    // The brute-force mean over the triangle (barycentric grid, 400 x 400).
    double exact = 0, blackArea = 0;
    int count = 0;
    for (int i = 0; i < 400; ++i)
      for (int j = 0; i + j < 400; ++j) {
        const float e = scene.emission(t, (float(i) + 0.33f) / 400, (float(j) + 0.33f) / 400).x;
        exact += double(e);
        blackArea += e == 0 ? 1.0 : 0.0;
        ++count;
      }
    exact /= count;
    blackArea /= count;
    Rng rng(7, k);
    double sum = 0;
    int dark = 0;
    constexpr int kDraws = 400000;
    for (int n = 0; n < kDraws; ++n) {
      float b1 = 0, b2 = 0, w = 0;
      s.samplePoint(k, rng.uniform(), rng.uniform(), rng.uniform(), b1, b2, w);
      ASSERT_GE(b1, -1e-6f);
      ASSERT_GE(b2, -1e-6f);
      ASSERT_LE(b1 + b2, 1.0f + 1e-5f);
      ASSERT_LE(w, 4.0f + 1e-5f);
      const float e = scene.emission(t, b1, b2).x;
      if (e == 0) ++dark;
      sum += double(w) * double(e);
    }
    const double mean = sum / kDraws;
    std::printf("triangle %zu: mean emission %.5f by the sampler, %.5f brute force; %.1f%% of "
                "points on black texels, %.1f%% of its area\n",
                k, mean, exact, 100.0 * dark / kDraws, 100.0 * blackArea);
    EXPECT_NEAR(mean, exact, 0.01 * exact);
    // Uniform points would land on black texels as often as they cover the
    // triangle; a quarter of the draws are even, the rest find the light
    // (but in the few cells the texture's edge crosses).
    EXPECT_LT(double(dark) / kDraws, 0.25 * blackArea + 0.05);
  }
}

}  // namespace
}  // namespace lo
