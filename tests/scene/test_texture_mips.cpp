// mipLevels (scene/texture_mips.h): the mip chain the renderer uploads, against
// means worked out by hand and an sRGB encoding found by brute force.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "core/rng.h"
#include "scene/texture_mips.h"

namespace lo {
namespace {

double srgbToLinear(int code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

/// The code whose linear value lies nearest v, by trying all 256.
int nearestCode(double v) {
  int best = 0;
  for (int i = 1; i < 256; ++i) {
    if (std::abs(srgbToLinear(i) - v) < std::abs(srgbToLinear(best) - v)) best = i;
  }
  return best;
}

TEST(TextureMips, SidesHalveDownToOneTexelAsGlSizesThem) {
  const std::vector<uint8_t> image(size_t(5) * 12 * 2, 7);
  const auto levels = mipLevels(image.data(), 5, 12, 2, false);
  const int expected[][2] = {{2, 6}, {1, 3}, {1, 1}};
  ASSERT_EQ(levels.size(), 3u);
  for (size_t l = 0; l < levels.size(); ++l) {
    EXPECT_EQ(levels[l].width, expected[l][0]);
    EXPECT_EQ(levels[l].height, expected[l][1]);
    const size_t values = size_t(expected[l][0] * expected[l][1] * 2);
    EXPECT_EQ(levels[l].texels, std::vector<uint8_t>(values, 7));
  }
  EXPECT_TRUE(mipLevels(image.data(), 1, 1, 2, false).empty());
}

TEST(TextureMips, LinearTexelsAreTheRoundedMeanOfTheFourAbove) {
  // 4 x 2, one channel: level 1 is 2 x 1, level 2 1 x 1.
  const std::vector<uint8_t> image = {0, 1, 200, 201,  //
                                      2, 2, 255, 254};
  const auto levels = mipLevels(image.data(), 4, 2, 1, false);
  ASSERT_EQ(levels.size(), 2u);
  EXPECT_EQ(levels[0].texels, (std::vector<uint8_t>{1, 228}));  // 5/4 -> 1, 910/4 -> 228 (227.5 up)
  EXPECT_EQ(levels[1].texels, (std::vector<uint8_t>{115}));     // 229/2 = 114.5 -> 115
  // An odd side leaves its last column out: 3 x 2 -> 1 x 1 from the first 2 x 2.
  const std::vector<uint8_t> odd = {10, 20, 250, 30, 40, 250};
  EXPECT_EQ(mipLevels(odd.data(), 3, 2, 1, false)[0].texels, (std::vector<uint8_t>{25}));
}

TEST(TextureMips, SrgbColourIsAveragedAsLightAndAlphaAsItIs) {
  // 2 x 2 RGBA: black and white in R, a ramp in G and B, alpha 0 and 255.
  const std::vector<uint8_t> image = {0,   10, 100, 0,    255, 30, 120, 255,  //
                                      255, 50, 140, 0,    0,   70, 160, 255};
  const auto levels = mipLevels(image.data(), 2, 2, 4, true);
  ASSERT_EQ(levels.size(), 1u);
  const std::vector<uint8_t>& t = levels[0].texels;
  EXPECT_EQ(t[0], nearestCode(0.5));  // 188, where the codes' mean would be 128
  EXPECT_EQ(t[1], nearestCode((srgbToLinear(10) + srgbToLinear(30) + srgbToLinear(50) +
                               srgbToLinear(70)) / 4));
  EXPECT_EQ(t[2], nearestCode((srgbToLinear(100) + srgbToLinear(120) + srgbToLinear(140) +
                               srgbToLinear(160)) / 4));
  EXPECT_EQ(t[3], 128);  // 510 / 4 = 127.5 -> 128: alpha is not light
  // A three-channel image is colour in all three.
  const std::vector<uint8_t> rgb = {0, 0, 0, 255, 255, 255, 0, 0, 0, 255, 255, 255};
  EXPECT_EQ(mipLevels(rgb.data(), 2, 2, 3, true)[0].texels,
            (std::vector<uint8_t>(3, uint8_t(nearestCode(0.5)))));
}

TEST(TextureMips, FloatTexelsAreThePlainMean) {
  const std::vector<float> image = {1.0f, -2.0f, 0.5f, 4.0f,  //
                                    3.0f, 10.0f, 1.5f, 8.0f};
  const auto levels = mipLevels(image.data(), 2, 2, 2);
  ASSERT_EQ(levels.size(), 1u);
  EXPECT_EQ(levels[0].texels, (std::vector<float>{1.5f, 5.0f}));
}

TEST(TextureMips, TheSameBytesWhateverTheThreadCount) {
  const int w = 517, h = 300;
  std::vector<uint8_t> image(size_t(w) * size_t(h) * 4);
  Rng rng(5, 0);
  for (uint8_t& v : image) v = uint8_t(rng.uniform() * 256.0f);
  std::vector<MipLevel<uint8_t>> one;
  {
    tbb::global_control single(tbb::global_control::max_allowed_parallelism, 1);
    one = mipLevels(image.data(), w, h, 4, true);
  }
  const std::vector<MipLevel<uint8_t>> many = mipLevels(image.data(), w, h, 4, true);
  ASSERT_EQ(one.size(), many.size());
  for (size_t l = 0; l < one.size(); ++l) EXPECT_EQ(one[l].texels, many[l].texels) << l;
}

}  // namespace
}  // namespace lo
