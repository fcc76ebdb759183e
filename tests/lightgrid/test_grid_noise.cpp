// summarizeNoise: the bake's noise figure, by area, with the floor that
// keeps nearly black voxels from counting their relative noise in full.

#include <gtest/gtest.h>

#include "lightgrid/grid_noise.h"
#include "lightgrid/light_grid_schema.h"

namespace lo {
namespace {

VdlGrid gridOf(const std::vector<float>& luminances, const std::vector<float>& noise,
               const std::vector<float>& areas) {
  VdlGrid g;
  for (size_t v = 0; v < luminances.size(); ++v) g.coords.push_back({int(v), 0, 0});
  resizeVoxelArrays(g);
  for (size_t v = 0; v < luminances.size(); ++v) {
    g.irradiance[v] = Vec3(luminances[v]);  // grey: luminance = the value
    g.noise[v] = noise[v];
    g.areas[v] = areas[v];
  }
  return g;
}

TEST(GridNoise, QuantilesAreByArea) {
  // Ten voxels of noise 1%..10%, equal areas: the 90% quantile is the 9th.
  std::vector<float> y(10, 1.0f), n, a(10, 1.0f);
  for (int i = 1; i <= 10; ++i) n.push_back(0.01f * float(i));
  NoiseSummary s = summarizeNoise(gridOf(y, n, a));
  EXPECT_TRUE(s.recorded);
  EXPECT_EQ(s.lit, 10u);
  EXPECT_NEAR(s.quantile, 0.09, 1e-6);
  EXPECT_NEAR(s.median, 0.05, 1e-6);
  // The noisiest voxel holding half the area moves the 90% quantile to it.
  a[9] = 9.0f;
  s = summarizeNoise(gridOf(y, n, a));
  EXPECT_NEAR(s.quantile, 0.10, 1e-6);
  EXPECT_NEAR(s.median, 0.09, 1e-6);
}

TEST(GridNoise, DarkVoxelsCountAgainstAFloorAndUnlitOnesApart) {
  // Nine voxels at 1 with noise 2%; one at 0.001 (a thousandth of the
  // rest) with noise 50%: its standard deviation, 0.0005, counts against
  // kNoiseFloorShare of the mean (~0.09), i.e. as 0.6%, not 50%.
  std::vector<float> y(9, 1.0f), n(9, 0.02f), a(11, 1.0f);
  y.push_back(0.001f);
  n.push_back(0.5f);
  y.push_back(0.0f);  // unlit
  n.push_back(0.0f);
  const NoiseSummary s = summarizeNoise(gridOf(y, n, a));
  EXPECT_EQ(s.lit, 10u);
  EXPECT_EQ(s.unlit, 1u);
  EXPECT_NEAR(s.meanLuminance, 9.001 / 10, 1e-5);
  EXPECT_NEAR(s.quantile, 0.02, 1e-6);
}

TEST(GridNoise, AGridWithoutNoiseSaysSo) {
  VdlGrid g;
  EXPECT_FALSE(summarizeNoise(g).recorded);
  EXPECT_EQ(summarizeNoise(g).ToString(), "noise not recorded");
}


TEST(GridNoise, TheLightSeenWeighsTheIndirectNoiseAgainstDirectPlusIndirect) {
  // Ten voxels of indirect light 1 and noise 1%..10%. Direct light 3 on the
  // first five, none on the rest: the first five count a quarter of their
  // noise (0.25%..1.25%), the rest in full, so the 90% quantile stays the
  // 9th voxel's 9% and the median becomes the 5th's 1.25%, not 5%.
  std::vector<float> y(10, 1.0f), n, a(10, 1.0f);
  for (int i = 1; i <= 10; ++i) n.push_back(0.01f * float(i));
  const VdlGrid g = gridOf(y, n, a);
  std::vector<float> direct(10, 0.0f);
  for (int i = 0; i < 5; ++i) direct[size_t(i)] = 3.0f;
  NoiseSummary s = summarizeNoise(g, &direct);
  EXPECT_TRUE(s.seen);
  EXPECT_NEAR(s.quantile, 0.09, 1e-6);
  EXPECT_NEAR(s.median, 0.0125, 1e-6);
  EXPECT_NEAR(s.meanLuminance, 1.0, 1e-6) << "the mean stays the indirect light's";
  EXPECT_NE(s.ToString().find("of the light seen"), std::string::npos) << s.ToString();
  // Direct light 9 everywhere: every voxel a tenth of its noise.
  direct.assign(10, 9.0f);
  s = summarizeNoise(g, &direct);
  EXPECT_NEAR(s.quantile, 0.009, 1e-6);
  // No direct light: the indirect figure; a list of the wrong size is ignored.
  direct.assign(10, 0.0f);
  EXPECT_NEAR(summarizeNoise(g, &direct).quantile, summarizeNoise(g).quantile, 1e-12);
  direct.assign(3, 9.0f);
  EXPECT_FALSE(summarizeNoise(g, &direct).seen);
  EXPECT_FALSE(summarizeNoise(g).seen);
}

}  // namespace
}  // namespace lo
