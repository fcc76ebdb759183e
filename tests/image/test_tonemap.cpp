// Tone mapping for pictures (image/tonemap.h): PBR Neutral against its
// published specification, the automatic exposure on images whose key is
// known, clipped shares counted on handcrafted pixels.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "image/image.h"
#include "image/tonemap.h"
#include "test_util.h"

namespace lo {
namespace {

RgbImage constantImage(int w, int h, const Vec3& c) {
  RgbImage img(w, h);
  for (size_t i = 0; i < img.pixelCount(); ++i) img.set(i, c);
  return img;
}

/// PBR Neutral as the Khronos README's specification writes it (a second,
/// independent arrangement of the GLSL), in double: with F90 = 0.04,
/// Ks = 0.8 - F90, Kd = 0.15, x = min(c), f = x - x^2 / (4 F90) for
/// x <= 2 F90 else F90, p = max(c - f), pn = 1 - (1 - Ks)^2 / (p + 1 - 2 Ks),
/// g = 1 / (Kd (p - pn) + 1); out = c - f for p <= Ks, else
/// (c - f) pn / p g + pn (1 - g).
void specNeutral(const double c[3], double out[3]) {
  const double f90 = 0.04, ks = 0.8 - f90, kd = 0.15;
  const double x = std::min({c[0], c[1], c[2]});
  const double f = x <= 2 * f90 ? x - x * x / (4 * f90) : f90;
  const double p = std::max({c[0] - f, c[1] - f, c[2] - f});
  if (p <= ks) {
    for (int k = 0; k < 3; ++k) out[k] = c[k] - f;
    return;
  }
  const double pn = 1 - (1 - ks) * (1 - ks) / (p + 1 - 2 * ks);
  const double g = 1 / (kd * (p - pn) + 1);
  for (int k = 0; k < 3; ++k) out[k] = (c[k] - f) * pn / p * g + pn * (1 - g);
}

TEST(ToneMap, ParseAndToString) {
  EXPECT_EQ(parseToneMap("clamp"), ToneMap::Clamp);
  EXPECT_EQ(parseToneMap("neutral"), ToneMap::Neutral);
  EXPECT_EQ(toString(ToneMap::Clamp), "clamp");
  EXPECT_EQ(toString(ToneMap::Neutral), "neutral");
  test::expectRefusal([] { parseToneMap("filmic"); }, {"'filmic'"});
}

TEST(ToneMap, NeutralBelowCompressionTakesTheOffsetOnly) {
  // Greys below 0.08: x - (x - 6.25 x^2) = 6.25 x^2.
  for (float x : {0.0f, 0.01f, 0.05f, 0.079f}) {
    const Vec3 out = pbrNeutral(Vec3(x));
    EXPECT_NEAR(out.x, 6.25f * x * x, 1e-7f) << x;
    EXPECT_EQ(out.x, out.y);
    EXPECT_EQ(out.x, out.z);
  }
  // Greys from 0.08 to 0.8 (peak below 0.76): x - 0.04.
  for (float x : {0.08f, 0.18f, 0.5f, 0.79f})
    EXPECT_NEAR(pbrNeutral(Vec3(x)).y, x - 0.04f, 1e-6f) << x;
  // Colours: the offset follows the smallest channel.
  const Vec3 a = pbrNeutral({0.3f, 0.5f, 0.7f});  // x = 0.3: offset 0.04
  EXPECT_NEAR(a.x, 0.26f, 1e-6f);
  EXPECT_NEAR(a.y, 0.46f, 1e-6f);
  EXPECT_NEAR(a.z, 0.66f, 1e-6f);
  const Vec3 b = pbrNeutral({0.02f, 0.3f, 0.5f});  // x = 0.02: offset 0.02 - 6.25 * 0.0004 = 0.0175
  EXPECT_NEAR(b.x, 0.0025f, 1e-6f);
  EXPECT_NEAR(b.y, 0.2825f, 1e-6f);
  EXPECT_NEAR(b.z, 0.4825f, 1e-6f);
}

TEST(ToneMap, NeutralCompressionByHand) {
  // Grey 2: p = 1.96, pn = 1 - 0.24^2 / (1.96 + 0.24 - 0.76) = 1 - 0.0576 / 1.44 = 0.96.
  const Vec3 grey = pbrNeutral(Vec3(2.0f));
  EXPECT_NEAR(grey.x, 0.96f, 1e-6f);
  EXPECT_NEAR(grey.z, 0.96f, 1e-6f);
  // (2, 1, 0.5): c - f = (1.96, 0.96, 0.46), pn = 0.96, scaled by 0.96 / 1.96,
  // then moved towards 0.96 by 1 - 1 / (0.15 (1.96 - 0.96) + 1) = 0.15 / 1.15.
  const Vec3 c = pbrNeutral({2.0f, 1.0f, 0.5f});
  const double s = 0.96 / 1.96, t = 0.15 / 1.15;
  EXPECT_NEAR(c.x, 0.96, 1e-6);
  EXPECT_NEAR(c.y, 0.96 * s + (0.96 - 0.96 * s) * t, 1e-6);
  EXPECT_NEAR(c.z, 0.46 * s + (0.96 - 0.46 * s) * t, 1e-6);
  EXPECT_NEAR(c.y, 0.5340905, 1e-6);
  EXPECT_NEAR(c.z, 0.3211357, 1e-6);
}

TEST(ToneMap, NeutralMatchesTheSpecification) {
  const float values[] = {0.0f, 0.003f, 0.04f, 0.0799f, 0.08f, 0.2f,  0.5f,  0.75f,
                          0.8f, 0.81f,  1.0f,  1.7f,    4.0f,  25.0f, 900.0f};
  for (float r : values) {
    for (float g : values) {
      for (float b : values) {
        const Vec3 out = pbrNeutral({r, g, b});
        const double in[3] = {r, g, b};
        double expected[3];
        specNeutral(in, expected);
        for (int k = 0; k < 3; ++k) {
          ASSERT_NEAR(out[k], expected[k], 2e-6)
              << "(" << r << ", " << g << ", " << b << ")[" << k << "]";
          ASSERT_GE(out[k], 0.0f);
          ASSERT_LT(out[k], 1.0f);
        }
      }
    }
  }
}

TEST(ToneMap, NeutralIsMonotoneAndBelowWhite) {
  // Greys from 0 to 10^4 in steps of 1/64 of a stop, through both seams
  // (0.08 and 0.8); a grey stays grey.
  float previous = -1.0f;
  for (int i = -16 * 64; i <= 14 * 64; ++i) {
    const float x = std::exp2(float(i) / 64.0f);
    const Vec3 out = pbrNeutral(Vec3(x));
    ASSERT_GE(out.y, previous) << x;
    ASSERT_LT(out.y, 1.0f) << x;
    ASSERT_EQ(out.x, out.y);
    previous = out.y;
  }
  // Continuous at the seams.
  EXPECT_NEAR(pbrNeutral(Vec3(0.08f)).x, pbrNeutral(Vec3(std::nextafter(0.08f, 0.0f))).x, 1e-6f);
  EXPECT_NEAR(pbrNeutral(Vec3(0.8f)).x, 0.76f, 1e-6f);
  EXPECT_NEAR(pbrNeutral(Vec3(std::nextafter(0.8f, 1.0f))).x, 0.76f, 1e-6f);
  // Large values roll off towards white without reaching it, and keep the
  // brightest channel brightest (no hue flip).
  EXPECT_GT(pbrNeutral(Vec3(100.0f)).x, 0.999f);
  EXPECT_LT(pbrNeutral(Vec3(100.0f)).x, 1.0f);
  const Vec3 red = pbrNeutral({50.0f, 5.0f, 1.0f});
  EXPECT_GT(red.x, red.y);
  EXPECT_GT(red.y, red.z);
  EXPECT_LT(red.x, 1.0f);
}

TEST(ToneMap, PixelSanitisesAndClamps) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  EXPECT_EQ(toneMapPixel({nan, inf, -2.0f}, ToneMap::Clamp), Vec3(0.0f));
  EXPECT_EQ(toneMapPixel({nan, inf, -2.0f}, ToneMap::Neutral), Vec3(0.0f));
  EXPECT_EQ(toneMapPixel({0.25f, 1.5f, 7.0f}, ToneMap::Clamp), Vec3(0.25f, 1.0f, 1.0f));
  const Vec3 huge = toneMapPixel(Vec3(std::numeric_limits<float>::max()), ToneMap::Neutral);
  EXPECT_TRUE(isFinite(huge));
  EXPECT_LE(huge.x, 1.0f);
  EXPECT_GT(huge.x, 0.999f);
}

TEST(AutoExposure, ConstantImageLandsOnMiddleGrey) {
  for (float l : {1e-3f, 0.18f, 3.7f, 250.0f}) {
    EXPECT_NEAR(autoExposureEv(constantImage(5, 3, Vec3(l))), std::log2(0.18 / l), 1e-5) << l;
  }
  // A coloured constant: its Rec. 709 luminance is the key.
  const Vec3 c(0.3f, 0.6f, 0.9f);
  const double y = 0.2126 * 0.3 + 0.7152 * 0.6 + 0.0722 * 0.9;
  EXPECT_NEAR(autoExposureEv(constantImage(4, 4, c)), std::log2(0.18 / y), 1e-5);
  // Another key.
  AutoExposureParams params;
  params.key = 0.5f;
  EXPECT_NEAR(autoExposureEv(constantImage(4, 4, Vec3(2.0f)), params), -2.0, 1e-5);
}

TEST(AutoExposure, BlackEmptyAndNonFiniteGiveZero) {
  EXPECT_EQ(autoExposureEv(RgbImage()), 0.0f);
  EXPECT_EQ(autoExposureEv(RgbImage(6, 4)), 0.0f);
  EXPECT_EQ(autoExposureEv(constantImage(3, 3, Vec3(std::numeric_limits<float>::quiet_NaN()))),
            0.0f);
  EXPECT_EQ(autoExposureEv(constantImage(3, 3, Vec3(-1.0f))), 0.0f);
}

TEST(AutoExposure, IgnoresNonFiniteZeroAndNegativePixels) {
  RgbImage img = constantImage(10, 10, Vec3(0.5f));
  img.set(3, Vec3(std::numeric_limits<float>::quiet_NaN()));
  img.set(17, Vec3(std::numeric_limits<float>::infinity(), 0.5f, 0.5f));
  img.set(40, Vec3(0.0f));
  img.set(41, Vec3(0.0f));
  img.set(77, Vec3(-3.0f));
  EXPECT_NEAR(autoExposureEv(img), std::log2(0.18 / 0.5), 1e-5);
}

TEST(AutoExposure, DarkPixelsCountAtTheFloor) {
  // 99 pixels at 1 and one at 1e-30: the highlight quantile (rank
  // floor(0.99 * 99) = 98 of 100) is 1, so the dark pixel counts as 2^-13.
  RgbImage img = constantImage(10, 10, Vec3(1.0f));
  img.set(55, Vec3(1e-30f));
  EXPECT_NEAR(autoExposureEv(img), std::log2(0.18) + 13.0 / 100.0, 1e-5);
}

TEST(AutoExposure, HighlightLimitLowersTheExposure) {
  // 90 pixels at 0.1, 10 at 5: the key asks for evKey, which takes the
  // highlights (5) past 4; the limit lowers the exposure to log2(4 / 5),
  // less than a stop below evKey.
  RgbImage img = constantImage(10, 10, Vec3(0.1f));
  for (size_t i = 90; i < 100; ++i) img.set(i, Vec3(5.0f));
  const double evKey = std::log2(0.18) - (0.9 * std::log2(0.1) + 0.1 * std::log2(5.0));
  ASSERT_GT(5.0 * std::exp2(evKey), 4.0);
  ASSERT_LT(evKey - 1.0, std::log2(4.0 / 5.0));
  EXPECT_NEAR(autoExposureEv(img), std::log2(4.0 / 5.0), 1e-5);
  // Without the limit, the key alone.
  AutoExposureParams params;
  params.maxHighlightStops = 0;
  EXPECT_NEAR(autoExposureEv(img, params), evKey, 1e-5);
}

TEST(AutoExposure, HighlightLimitDarkensAtMostMaxStops) {
  // Half at 0.02, half at 50 (11.3 stops apart: above the floor): key 1,
  // evKey = log2(0.18); the highlights would need log2(4 / 50), 3.6 stops
  // down, but the room keeps its view: one stop below evKey.
  RgbImage img = constantImage(10, 10, Vec3(0.02f));
  for (size_t i = 0; i < 100; i += 2) img.set(i, Vec3(50.0f));
  EXPECT_NEAR(autoExposureEv(img), std::log2(0.18) - 1.0, 1e-5);
  AutoExposureParams params;
  params.maxHighlightStops = 10;
  EXPECT_NEAR(autoExposureEv(img, params), std::log2(4.0 / 50.0), 1e-5);
}

TEST(AutoExposure, FiniteForExtremeValues) {
  const float tiny = std::numeric_limits<float>::denorm_min();
  const float big = std::numeric_limits<float>::max();
  const RgbImage denormals = constantImage(4, 4, Vec3(tiny));
  const float ev = autoExposureEv(denormals);
  EXPECT_TRUE(std::isfinite(ev));
  EXPECT_NEAR(ev, std::log2(0.18) + 149.0, 1e-3);
  EXPECT_NEAR(autoExposureEv(constantImage(4, 4, Vec3(big))),
              std::log2(0.18) - std::log2(double(big)), 1e-3);
  RgbImage both = constantImage(4, 4, Vec3(tiny));
  both.set(0, Vec3(big));
  EXPECT_TRUE(std::isfinite(autoExposureEv(both)));
  // The picture of the denormal image is middle grey through PBR Neutral
  // (0.18 - 0.04), not lost to an exposure of 2^146 overflowing a float.
  const RgbImage picture = toneMapped(denormals);
  EXPECT_NEAR(picture.rgb[0], 0.14f, 1e-3f);
}

TEST(AutoExposure, BadParamsAreNamed) {
  AutoExposureParams params;
  params.highlightQuantile = 1.5f;
  test::expectRefusal([&] { autoExposureEv(constantImage(2, 2, Vec3(1.0f)), params); },
                      {"highlightQuantile"});
  params = {};
  params.key = 0;
  EXPECT_THROW(autoExposureEv(constantImage(2, 2, Vec3(1.0f)), params), InputError);
}

/// 4 x 1: a red channel over white, a mid grey, white, a near-white red
/// (0.99 encodes to 254, not 255).
RgbImage clipImage() {
  RgbImage img(4, 1);
  img.set(0, {2.0f, 0.0f, 0.0f});
  img.set(1, Vec3(0.5f));
  img.set(2, Vec3(1.0f));
  img.set(3, {0.99f, 0.2f, 0.2f});
  return img;
}

TEST(ToneMapped, ClippedShareOnHandcraftedPixels) {
  ASSERT_EQ(encodeSrgb8(0.99f), 254);
  ToneParams params;
  params.autoExposure = false;
  params.curve = ToneMap::Clamp;
  ToneReport report;
  RgbImage out = toneMapped(clipImage(), params, &report);
  EXPECT_EQ(report.exposureEv, 0.0f);
  EXPECT_FALSE(report.autoExposure);
  EXPECT_DOUBLE_EQ(report.clippedShare, 2.0 / 4.0);  // pixels 0 and 2
  EXPECT_DOUBLE_EQ(report.whiteShare, 1.0 / 4.0);    // pixel 2
  EXPECT_EQ(out.at(0), Vec3(1.0f, 0.0f, 0.0f));
  EXPECT_EQ(out.at(1), Vec3(0.5f));

  // One stop up: the grey turns white, the near-white red clips in red.
  params.exposureEv = 1.0f;
  out = toneMapped(clipImage(), params, &report);
  EXPECT_EQ(report.exposureEv, 1.0f);
  EXPECT_DOUBLE_EQ(report.clippedShare, 1.0);
  EXPECT_DOUBLE_EQ(report.whiteShare, 2.0 / 4.0);
  EXPECT_EQ(out.at(3), Vec3(1.0f, 0.4f, 0.4f));

  // PBR Neutral at the same exposure keeps every channel below 255 ...
  params.curve = ToneMap::Neutral;
  toneMapped(clipImage(), params, &report);
  EXPECT_DOUBLE_EQ(report.clippedShare, 0.0);
  EXPECT_DOUBLE_EQ(report.whiteShare, 0.0);
  // ... until the light is far past white, where it desaturates to white,
  // the pure red too (g -> 1 pulls every channel to the peak).
  params.exposureEv = 20.0f;
  out = toneMapped(clipImage(), params, &report);
  EXPECT_DOUBLE_EQ(report.clippedShare, 1.0);
  EXPECT_DOUBLE_EQ(report.whiteShare, 1.0);
  // Six stops up, the greys are white; the reds clip in red alone (the red
  // (128, 0, 0) has G = B = pn g = 0.95, the other 0.92).
  params.exposureEv = 6.0f;
  out = toneMapped(clipImage(), params, &report);
  EXPECT_EQ(encodeSrgb8(out.at(0).x), 255);
  EXPECT_NEAR(out.at(0).y, 0.9497f, 1e-3f);
  EXPECT_LT(encodeSrgb8(out.at(0).y), 255);
  EXPECT_DOUBLE_EQ(report.clippedShare, 1.0);
  EXPECT_DOUBLE_EQ(report.whiteShare, 2.0 / 4.0);
  for (float v : out.rgb) {
    EXPECT_GE(v, 0.0f);
    EXPECT_LE(v, 1.0f);
  }
}

TEST(ToneMapped, AutoExposurePlusCompensation) {
  RgbImage img = constantImage(3, 2, Vec3(0.5f));
  img.set(4, Vec3(std::numeric_limits<float>::quiet_NaN()));
  ToneParams params;
  params.exposureEv = 1.5f;
  ToneReport report;
  const RgbImage out = toneMapped(img, params, &report);
  EXPECT_TRUE(report.autoExposure);
  EXPECT_EQ(report.curve, ToneMap::Neutral);
  EXPECT_NEAR(report.exposureEv, std::log2(0.18 / 0.5) + 1.5, 1e-5);
  // 0.18 x 2^1.5 = 0.509, below the compression: minus the offset 0.04.
  EXPECT_NEAR(out.at(0).y, 0.18f * std::exp2(1.5f) - 0.04f, 1e-5f);
  EXPECT_EQ(out.at(4), Vec3(0.0f));  // NaN shows black, as encodeSrgb8 draws it
  EXPECT_NE(report.ToString().find("(auto)"), std::string::npos) << report.ToString();

  params.exposureEv = std::numeric_limits<float>::infinity();
  EXPECT_THROW(toneMapped(img, params), InputError);
}

TEST(ToneMapped, PngHoldsTheCurvedPixels) {
  RgbImage img(2, 1);
  img.set(0, Vec3(0.5f));
  img.set(1, {2.0f, 1.0f, 0.5f});
  ToneParams params;
  params.autoExposure = false;
  const std::vector<unsigned char> png = encodeTonedPng(img, params);
  const DecodedImage decoded = decodeImageBytes(png.data(), png.size());
  ASSERT_EQ(decoded.channels, 3);
  const float expected[6] = {0.46f, 0.46f, 0.46f, 0.96f, 0.5340905f, 0.3211357f};
  for (int k = 0; k < 6; ++k) {
    EXPECT_EQ(std::lround(decoded.values[size_t(k)] * 255.0f), encodeSrgb8(expected[k])) << k;
  }
}

TEST(ToneMapped, WriteTonedImageByExtension) {
  const std::string dir = test::outputDir("ToneMapped_Write");
  const RgbImage img = constantImage(4, 2, Vec3(3.0f));
  ToneReport report;
  writeTonedImage(dir + "/picture.png", img, {}, nullptr, &report);
  EXPECT_TRUE(std::filesystem::exists(dir + "/picture.png"));
  EXPECT_NEAR(report.exposureEv, std::log2(0.18 / 3.0), 1e-5);
  // An EXR keeps the radiance: no exposure, no curve.
  writeTonedImage(dir + "/radiance.exr", img);
  EXPECT_EQ(readImage(dir + "/radiance.exr").rgb, img.rgb);
  test::expectRefusal([&] { writeTonedImage(dir + "/picture.txt", img); }, {"picture.txt"});
}

}  // namespace
}  // namespace lo
