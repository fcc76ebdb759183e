// PNG in memory and RGBM (image/image.h): the bytes decode back to the 8-bit
// sRGB values writePng has always written, and RGBM round trips within the
// bound its header states.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"
#include "image/image.h"

namespace lo {
namespace {

TEST(Png, EncodedBytesDecodeToTheSrgbValues) {
  RgbImage img(7, 3);
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = float(i) / float(img.rgb.size());
  img.rgb[5] = 2.0f;   // clamps to 255
  img.rgb[6] = -1.0f;  // clamps to 0
  const std::vector<unsigned char> png = encodePng(img, 1.0f);
  const DecodedImage d = decodeImageBytes(png.data(), png.size());
  ASSERT_EQ(d.width, 7);
  ASSERT_EQ(d.height, 3);
  ASSERT_EQ(d.channels, 3);
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    ASSERT_EQ(int(std::lround(d.values[i] * 255.0f)), int(encodeSrgb8(img.rgb[i] * 2.0f))) << i;
  }
  EXPECT_THROW(encodePng(RgbImage()), InputError);
  EXPECT_THROW(encodePng8(2, 2, 5, png.data()), InputError);
}

// |c' - c| <= 0.5 / 255 * (A / 255) * range <= (0.5 / 255) (max(c) + range / 255)
// per channel, over values spread across 9 decades, exact zeros and values
// beyond the range (which clamp to it).
TEST(Rgbm, RoundTripStaysWithinTheStatedBound) {
  constexpr float kRange = 8.0f;
  RgbImage img(64, 48);
  Rng rng(7, 0);
  for (size_t i = 0; i < img.pixelCount(); ++i) {
    const float scale = std::pow(10.0f, -8.0f + 9.0f * rng.uniform());
    img.set(i, {scale * rng.uniform(), scale * rng.uniform(), scale * rng.uniform()});
  }
  img.set(0, {0, 0, 0});
  img.set(1, {kRange, 0, 0});
  img.set(2, {20.0f, 1.0f, -3.0f});  // clamped to (8, 1, 0)
  img.set(3, {1e-3f, 5.0f, 7.99f});
  const std::vector<unsigned char> png = encodeRgbmPng(img, kRange);
  const DecodedImage d = decodeImageBytes(png.data(), png.size());
  ASSERT_EQ(d.channels, 4);
  const RgbImage back = decodeRgbm(d, kRange);
  ASSERT_EQ(back.width, img.width);
  double worstRatio = 0;
  for (size_t i = 0; i < img.pixelCount(); ++i) {
    Vec3 c = img.at(i);
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(c[k], 0.0f, kRange);
    const float m = maxComponent(c);
    const double bound = 0.5 / 255.0 * (double(m) + kRange / 255.0) * (1 + 1e-5);
    const double alphaBound = 0.5 / 255.0 * double(d.values[4 * i + 3]) * kRange * (1 + 1e-5);
    for (int k = 0; k < 3; ++k) {
      const double err = std::fabs(double(back.at(i)[k]) - double(c[k]));
      ASSERT_LE(err, alphaBound) << "pixel " << i << " channel " << k << ": " << c[k] << " -> "
                                 << back.at(i)[k];
      ASSERT_LE(err, bound) << i;
      worstRatio = std::max(worstRatio, err / bound);
    }
  }
  // The bound is tight enough to mean something: some texel uses over a
  // quarter of it.
  EXPECT_GT(worstRatio, 0.25);
  EXPECT_EQ(back.at(0), Vec3(0, 0, 0));
  EXPECT_NEAR(back.at(1).x, kRange, 1e-5f);
  EXPECT_NEAR(back.at(2).x, kRange, 1e-5f);
  EXPECT_EQ(back.at(2).z, 0.0f);

  // The file says what it holds: linear data, RGBM, and its range.
  const std::string bytes(png.begin(), png.end());
  EXPECT_EQ(bytes.find("gAMA"), 37u) << "right after IHDR";
  EXPECT_NE(bytes.find(std::string("lightoctree:rgbmRange") + '\0' + "8"), std::string::npos);
  EXPECT_NE(bytes.find(std::string("lightoctree:encoding") + '\0' + "rgbm"), std::string::npos);

  EXPECT_THROW(encodeRgbmPng(img, 0.0f), InputError);
  EXPECT_THROW(encodeRgbmPng(img, NAN), InputError);
  const std::vector<unsigned char> plain = encodePng(img);
  const DecodedImage rgb = decodeImageBytes(plain.data(), plain.size());
  EXPECT_THROW(decodeRgbm(rgb, kRange), InputError);
}

// Unit vectors round trip within 0.5 / 127 per component; (0, 0, 0) is
// exactly 128 and back to 0; the PNG says it holds data.
TEST(UnitVectorPng, RoundTripsWithinHalfAStep) {
  RgbImage img(16, 9);
  Rng rng(3, 0);
  for (size_t i = 0; i < img.pixelCount(); ++i) {
    Vec3 d{rng.uniform() * 2 - 1, rng.uniform() * 2 - 1, rng.uniform() * 2 - 1};
    d = i % 5 == 0 ? Vec3{0, 0, 0} : normalize(d);
    for (int k = 0; k < 3; ++k) img.rgb[3 * i + size_t(k)] = d[k];
  }
  img.rgb[3] = NAN;  // encodes as 0
  const std::vector<unsigned char> png = encodeUnitVectorPng(img);
  const std::string text(png.begin(), png.end());
  EXPECT_NE(text.find("gAMA"), std::string::npos);
  EXPECT_NE(text.find("lightoctree:encoding"), std::string::npos);
  const DecodedImage d = decodeImageBytes(png.data(), png.size());
  ASSERT_EQ(d.channels, 3);
  const RgbImage back = decodeUnitVectors(d);
  ASSERT_EQ(back.width, 16);
  ASSERT_EQ(back.height, 9);
  for (size_t i = 0; i < img.rgb.size(); ++i) {
    const float want = std::isfinite(img.rgb[i]) ? img.rgb[i] : 0.0f;
    ASSERT_LE(std::fabs(back.rgb[i] - want), 0.5f / 127.0f + 1e-6f) << i;
    if (want == 0.0f) {
      ASSERT_EQ(back.rgb[i], 0.0f) << i;
    }
  }
  EXPECT_THROW(encodeUnitVectorPng(RgbImage()), InputError);
  DecodedImage grey = d;
  grey.channels = 1;
  EXPECT_THROW(decodeUnitVectors(grey), InputError);
}

}  // namespace
}  // namespace lo
