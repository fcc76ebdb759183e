// Image files and comparison metrics: known errors on constructed images,
// masks, EXR round trips.

#include <gtest/gtest.h>

#include <limits>
#include <sys/stat.h>

#include <algorithm>
#include <cstring>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "image/compare.h"
#include "image/image.h"
#include "core/file.h"
#include "core/isolate.h"
#include "test_util.h"

namespace lo {
namespace {

RgbImage ramp(int w, int h) {
  RgbImage img(w, h);
  for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = 0.1f + 0.01f * float(i % 97);
  return img;
}

TEST(Compare, ScaledImageHasKnownErrors) {
  RgbImage ref = ramp(7, 5), test = ref;
  for (float& v : test.rgb) v *= 1.1f;
  CompareResult r = compareImages(test, ref);
  for (int c = 0; c < 3; ++c) {
    EXPECT_NEAR(r.channel[c].relRmse, 0.1, 1e-5);
    EXPECT_NEAR(r.channel[c].relMae, 0.1, 1e-5);
  }
  EXPECT_NEAR(r.luminance.relRmse, 0.1, 1e-5);
  for (int c = 0; c < 3; ++c) {
    float maxRef = 0;
    for (size_t i = 0; i < ref.pixelCount(); ++i) maxRef = std::max(maxRef, ref.rgb[3 * i + c]);
    EXPECT_NEAR(r.channel[c].maxAbs, 0.1 * maxRef, 1e-5);
  }
  EXPECT_EQ(r.comparedPixels, size_t(35));
  EXPECT_NEAR(r.meanTestLuminance / r.meanReferenceLuminance, 1.1, 1e-5);
  EXPECT_EQ(compareImages(ref, ref).luminance.relRmse, 0.0);
}

TEST(Compare, OffsetErrorRmseVsMae) {
  // Reference 1 everywhere; test 1 + e on half the pixels, 1 elsewhere:
  // rel. RMSE = sqrt(e^2 / 2), rel. MAE = e / 2.
  RgbImage ref(4, 4), test(4, 4);
  std::fill(ref.rgb.begin(), ref.rgb.end(), 1.0f);
  test = ref;
  for (size_t i = 0; i < 8; ++i) test.set(i, Vec3(1.5f));
  CompareResult r = compareImages(test, ref);
  EXPECT_NEAR(r.channel[1].relRmse, std::sqrt(0.25 / 2), 1e-6);
  EXPECT_NEAR(r.channel[1].relMae, 0.25, 1e-6);
  EXPECT_NEAR(r.channel[1].maxAbs, 0.5, 1e-6);
}

TEST(Compare, MaskAndBackgroundAreIgnored) {
  RgbImage ref(4, 1), test(4, 1), mask(4, 1);
  ref.set(0, Vec3(1));
  ref.set(1, Vec3(1));
  ref.set(2, Vec3(0));  // background
  ref.set(3, Vec3(1));
  test = ref;
  test.set(2, Vec3(5));  // error only in the background pixel ...
  test.set(3, Vec3(9));  // ... and in the masked pixel
  mask.set(0, Vec3(1));
  mask.set(1, Vec3(1));
  mask.set(2, Vec3(1));
  mask.set(3, Vec3(0));
  CompareParams params;
  params.mask = &mask;
  EXPECT_GT(compareImages(test, ref, params).luminance.relRmse, 1.0);
  params.ignoreBackground = true;
  CompareResult r = compareImages(test, ref, params);
  EXPECT_EQ(r.luminance.relRmse, 0.0);
  EXPECT_EQ(r.comparedPixels, size_t(2));
  EXPECT_EQ(r.ignoredPixels, size_t(2));
  RgbImage diff = differenceImage(test, ref, params);
  EXPECT_EQ(diff.at(3), Vec3(0.2f));  // ignored: grey
  EXPECT_EQ(diff.at(0), Vec3(0.0f));  // no error: black
}

TEST(Compare, PooledRgbErrorWeighsEveryChannel) {
  // Reference grey 1; test (1.3, 1, 0.7): luminance nearly unchanged, the
  // colour wrong: pooled RGB rel. RMSE = sqrt((0.09 + 0 + 0.09) / 3).
  RgbImage ref(3, 2), test(3, 2);
  std::fill(ref.rgb.begin(), ref.rgb.end(), 1.0f);
  for (size_t i = 0; i < test.pixelCount(); ++i) test.set(i, Vec3(1.3f, 1.0f, 0.7f));
  CompareResult r = compareImages(test, ref);
  EXPECT_NEAR(r.rgb.relRmse, std::sqrt(0.18 / 3), 1e-6);
  EXPECT_NEAR(r.rgb.relMae, 0.6 / 3, 1e-6);
  EXPECT_LT(r.luminance.relRmse, 0.05);
}

TEST(Compare, PercentilesAreNearestRankOverTheComparedPixels) {
  // Channel R holds 1..100 over 100 pixels, G 100..1, B 5: the 99th
  // percentile is 99, the 50th 50 (nearest rank), the 100th the largest.
  RgbImage img(10, 10);
  for (size_t i = 0; i < 100; ++i) img.set(i, Vec3(float(i + 1), float(100 - i), 5.0f));
  EXPECT_EQ(channelPercentiles(img, 99), Vec3(99, 99, 5));
  EXPECT_EQ(channelPercentiles(img, 50), Vec3(50, 50, 5));
  EXPECT_EQ(channelPercentiles(img, 100), Vec3(100, 100, 5));
  EXPECT_EQ(channelPercentiles(img, 0.5), Vec3(1, 1, 5));
  // A mask leaves the brightest pixels out of the count.
  RgbImage mask(10, 10);
  for (size_t i = 0; i < 50; ++i) mask.set(i, Vec3(1.0f));
  CompareParams masked;
  masked.mask = &mask;
  EXPECT_EQ(channelPercentiles(img, 100, masked).x, 50.0f);
  EXPECT_THROW(channelPercentiles(img, 0), InputError);
  EXPECT_THROW(channelPercentiles(img, std::nan("")), InputError);
  clipChannels(img, Vec3(10, 20, 1));
  EXPECT_EQ(img.at(99), Vec3(10, 1, 1));
  EXPECT_EQ(img.at(0), Vec3(1, 20, 1));
}

TEST(Compare, BlackHolesAreLitReferencePixelsTheTestDrawsBlack) {
  // Reference: 90 pixels at 1, 10 at 0 (a corner no light reaches); mean 0.9.
  // Test: 3 of the lit pixels black (holes), 2 at 0.01 (< 0.018: holes),
  // 1 at 0.02 (not), the unlit 10 black (agreeing: not holes).
  RgbImage ref(10, 10);
  for (size_t i = 0; i < 90; ++i) ref.set(i, Vec3(1.0f));
  RgbImage test = ref;
  for (size_t i = 0; i < 3; ++i) test.set(i, Vec3(0.0f));
  for (size_t i = 3; i < 5; ++i) test.set(i, Vec3(0.01f));
  test.set(5, Vec3(0.02f));
  DarkHoles holes = darkHoles(test, ref);
  EXPECT_EQ(holes.pixels, size_t(5));
  EXPECT_EQ(holes.compared, size_t(100));
  EXPECT_NEAR(holes.share(), 0.05, 1e-12);
  // Pixels the reference barely lights (below 20% of its mean) are not holes.
  ref.set(0, Vec3(0.1f));
  EXPECT_EQ(darkHoles(test, ref).pixels, size_t(4));
}

TEST(Compare, TheReportJudgesHolesFirstThenClipsThenBins) {
  // A 4 x 4 reference of 1 with one lamp pixel of 1000; the test equal but
  // one lit pixel black. Black holes are judged first, per pixel, against
  // the unclipped reference; then the images are clipped, then binned.
  RgbImage ref(4, 4), test(4, 4);
  std::fill(ref.rgb.begin(), ref.rgb.end(), 1.0f);
  ref.set(0, Vec3(1000.0f));
  test = ref;
  test.set(5, Vec3(0.0f));
  CompareSettings settings;
  settings.clipPercentile = 90;  // nearest rank: 1 (the lamp is the 16th of 16)
  settings.bin = 2;
  const CompareReport r = compareReport(test, ref, settings);
  EXPECT_EQ(r.holes.compared, size_t(16));
  // The unclipped mean is (15 + 1000) / 16 = 63.4: 2% of it is 1.27, so
  // every pixel of 1 counts as dark and none is above 20% of the mean but
  // the lamp: no hole is found there, as the reference's own lamp rules the
  // mean (the reason the bench clips the figures, not the holes).
  EXPECT_EQ(r.holes.pixels, size_t(0));
  EXPECT_EQ(r.clip, Vec3(1.0f));
  // Clipped, then binned 2 x 2: the block holding the black pixel averages
  // 0.75 against 1; the others agree. Rel. RMSE over 4 blocks of 3 channels:
  // sqrt(3 * 0.25^2 / (12 * 1)).
  EXPECT_EQ(r.test.width, 2);
  EXPECT_NEAR(r.result.rgb.relRmse, std::sqrt(3 * 0.0625 / 12.0), 1e-6);
  EXPECT_LT(r.referenceNoise, 0.0);  // no standard error given
  // Without the lamp the hole is found: 2% of a mean of 15/16 is 0.019.
  RgbImage plain(4, 4), holed(4, 4);
  std::fill(plain.rgb.begin(), plain.rgb.end(), 1.0f);
  holed = plain;
  holed.set(5, Vec3(0.0f));
  EXPECT_EQ(compareReport(holed, plain, CompareSettings{}).holes.pixels, size_t(1));
}

// Nothing compared is no score: an all-black mask, a reference black where
// --ignore-background leaves it out, or a test image of NaN used to report
// a relative RMSE of 0, a perfect one.
TEST(Compare, NothingComparedIsRefusedNotAPerfectScore) {
  RgbImage ref(4, 4), test(4, 4);
  std::fill(ref.rgb.begin(), ref.rgb.end(), 1.0f);
  test = ref;
  EXPECT_NEAR(compareReport(test, ref, CompareSettings{}).result.rgb.relRmse, 0.0, 1e-12);
  const RgbImage black(4, 4);  // zero everywhere
  test::expectRefusal([&] { compareReport(test, ref, CompareSettings{}, &black); },
                      {"no pixel to compare", "16 left out"});
  CompareSettings background;
  background.ignoreBackground = true;
  test::expectRefusal([&] { compareReport(test, black, background); }, {"no pixel to compare"});
  RgbImage nan = ref;
  std::fill(nan.rgb.begin(), nan.rgb.end(), std::numeric_limits<float>::quiet_NaN());
  test::expectRefusal([&] { compareReport(nan, ref, CompareSettings{}); },
                      {"no pixel to compare", "16 not finite"});
  CompareSettings binned;
  binned.bin = 2;
  test::expectRefusal([&] { compareReport(nan, ref, binned); }, {"4 not finite", "2 x 2 bins"});
}

// A negative standard error was taken and gave a reference noise figure of
// nothing measured (ninth hostile list H9-1-8); against a black reference the
// relative errors were inf without a word. Refused naming the pixel; warned.
TEST(Compare, ANegativeStandardErrorIsRefusedAndABlackReferenceWarned) {
  RgbImage ref(4, 4), test(4, 4), error(4, 4);
  std::fill(ref.rgb.begin(), ref.rgb.end(), 1.0f);
  std::fill(test.rgb.begin(), test.rgb.end(), 1.1f);
  std::fill(error.rgb.begin(), error.rgb.end(), 0.01f);
  EXPECT_GT(compareReport(test, ref, CompareSettings{}, nullptr, &error).referenceNoise, 0.0);
  error.rgb[3 * (4 * 2 + 1) + 1] = -0.5f;  // pixel (1, 2), channel G
  test::expectRefusal([&] { compareReport(test, ref, CompareSettings{}, nullptr, &error); },
                      {"standard error", "pixel (1, 2) holds a standard error of -0.5 in channel G",
                       "0 or more"});
  test::expectRefusal([&] { checkStdError(error, "--reference-error: e.exr"); },
                      {"--reference-error: e.exr: pixel (1, 2)"});
  // NaN and infinities read as a reference without noise (H15-4-2).
  for (const float odd : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
    error.rgb[3 * (4 * 2 + 1) + 1] = odd;
    test::expectRefusal([&] { checkStdError(error, "e.exr"); },
                        {"pixel (1, 2) holds a standard error of", "a finite number, 0 or more"});
  }
  error.rgb[3 * (4 * 2 + 1) + 1] = 0.01f;
  EXPECT_EQ(compareReport(test, ref, CompareSettings{}).blackReferenceWarning(), "");
  const RgbImage black(4, 4);
  const CompareReport dark = compareReport(test, black, CompareSettings{});
  EXPECT_TRUE(std::isinf(dark.result.luminance.relRmse));
  EXPECT_NE(dark.blackReferenceWarning().find("the reference is black (0) in R, G, B, Y, RGB"),
            std::string::npos)
      << dark.blackReferenceWarning();
  ASSERT_EQ(dark.warnings().size(), 1u);
  // Black against black is no difference: nothing undefined to warn of.
  EXPECT_EQ(compareReport(black, black, CompareSettings{}).warnings().size(), 0u);
}

// A test image half NaN was scored over its other half without a word:
// the report counts the pixels left out, per pixel before binning, and says
// so in a warning the command and the Python module give.
TEST(Compare, NonFinitePixelsLeftOutAreCountedAndWarned) {
  RgbImage ref(4, 4), test(4, 4);
  std::fill(ref.rgb.begin(), ref.rgb.end(), 1.0f);
  test = ref;
  const CompareReport clean = compareReport(test, ref, CompareSettings{});
  EXPECT_EQ(clean.nonFiniteImagePixels, 0u);
  EXPECT_EQ(clean.nonFiniteWarning(), "");
  // The top row NaN and one pixel of the second infinite: 5 of 16.
  for (int x = 0; x < 4; ++x) test.set(size_t(x), Vec3(std::numeric_limits<float>::quiet_NaN()));
  ref.set(5, Vec3(std::numeric_limits<float>::infinity()));
  const CompareReport half = compareReport(test, ref, CompareSettings{});
  EXPECT_EQ(half.nonFiniteImagePixels, 5u);
  EXPECT_EQ(half.result.nonFinitePixels, 5u);
  EXPECT_EQ(half.result.comparedPixels, 11u);
  EXPECT_EQ(half.nonFiniteWarning(),
            "5 pixels are not finite (NaN or infinite in the test image or the reference) and "
            "left out: the figures are of the 11 pixels compared");
  // Binned 2 x 2: the two top bins hold them; 2 of 4 bins compared.
  CompareSettings binned;
  binned.bin = 2;
  const CompareReport bins = compareReport(test, ref, binned);
  EXPECT_EQ(bins.nonFiniteImagePixels, 5u);
  EXPECT_EQ(bins.result.nonFinitePixels, 2u);
  EXPECT_EQ(bins.result.comparedPixels, 2u);
  EXPECT_NE(bins.nonFiniteWarning().find("5 pixels are not finite"), std::string::npos);
  EXPECT_NE(bins.nonFiniteWarning().find("the 2 bins of 2 x 2 that hold them are left out, the "
                                         "figures are of the 2 bins compared"),
            std::string::npos)
      << bins.nonFiniteWarning();
  // Pixels the mask leaves out are not counted, finite or not.
  RgbImage mask(4, 4);
  for (size_t i = 4; i < 16; ++i) mask.set(i, Vec3(1.0f));
  const CompareReport masked = compareReport(test, ref, CompareSettings{}, &mask);
  EXPECT_EQ(masked.nonFiniteImagePixels, 1u);
  EXPECT_EQ(masked.result.comparedPixels, 11u);
}

TEST(Compare, RejectsSizeMismatch) {
  EXPECT_THROW(compareImages(RgbImage(2, 2), RgbImage(2, 3)), InputError);
  RgbImage mask(1, 1);
  CompareParams params;
  params.mask = &mask;
  EXPECT_THROW(compareImages(RgbImage(2, 2), RgbImage(2, 2), params), InputError);
}

TEST(Compare, ExrRoundTripIsExact) {
  std::string dir = test::outputDir("ExrRoundTrip");
  RgbImage img = ramp(5, 3);
  img.rgb[4] = 1e-30f;
  img.rgb[7] = 12345.678f;
  writeExr(dir + "/a.exr", img);
  EXPECT_TRUE(leftoverTemporaries(dir + "/a.exr").empty());
  RgbImage back = readImage(dir + "/a.exr");
  EXPECT_EQ(back.width, 5);
  EXPECT_EQ(back.height, 3);
  EXPECT_EQ(back.rgb, img.rgb);
  EXPECT_THROW(readImage(dir + "/missing.exr"), InputError);
  EXPECT_THROW(readImage(dir + "/a.tif"), InputError);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// binImage averages blocks (partial ones at the edges over what they hold);
// binMask keeps a block only when all its pixels are selected.
// The standard error of a block's mean: sqrt(sum se^2) / n; the noise of a
// reference as the relative RMSE counts it, over the compared pixels only.
TEST(Compare, ReferenceNoiseBinsAsAMeanOfIndependentPixels) {
  RgbImage se(3, 2);
  for (size_t i = 0; i < se.pixelCount(); ++i) se.set(i, Vec3(0.2f));
  const RgbImage binned = binStdError(se, 2);
  ASSERT_EQ(binned.width, 2);
  EXPECT_FLOAT_EQ(binned.at(0).x, 0.2f / 2.0f);                  // 4 pixels: 1/sqrt(4)
  EXPECT_FLOAT_EQ(binned.at(1).x, 0.2f / std::sqrt(2.0f));       // the right column, 2 pixels
  RgbImage ref(3, 2);
  for (size_t i = 0; i < ref.pixelCount(); ++i) ref.set(i, Vec3(2.0f));
  EXPECT_NEAR(referenceNoise(ref, se), 0.1, 1e-6);  // 0.2 / 2 for a grey image
  // A pixel left out by the mask, another as background, do not count.
  se.set(0, Vec3(100.0f));
  se.set(1, Vec3(100.0f));
  ref.set(1, Vec3(0.0f));
  RgbImage mask(3, 2);
  for (size_t i = 0; i < mask.pixelCount(); ++i) mask.set(i, Vec3(1));
  mask.set(0, Vec3(0));
  CompareParams params;
  params.mask = &mask;
  params.ignoreBackground = true;
  EXPECT_NEAR(referenceNoise(ref, se, params), 0.1, 1e-6);
  EXPECT_THROW(referenceNoise(ref, RgbImage(2, 2)), InputError);
}

TEST(Compare, BinningAveragesBlocksAndMasksKeepWholeBlocks) {
  RgbImage image(3, 2);
  for (size_t i = 0; i < image.pixelCount(); ++i) image.set(i, Vec3(float(i)));
  const RgbImage binned = binImage(image, 2);
  ASSERT_EQ(binned.width, 2);
  ASSERT_EQ(binned.height, 1);
  EXPECT_FLOAT_EQ(binned.at(0).x, (0 + 1 + 3 + 4) / 4.0f);
  EXPECT_FLOAT_EQ(binned.at(1).y, (2 + 5) / 2.0f);  // the right column alone
  EXPECT_EQ(binImage(image, 1).rgb, image.rgb);
  EXPECT_THROW(binImage(image, 0), InputError);
  RgbImage mask(3, 2);
  for (size_t i = 0; i < mask.pixelCount(); ++i) mask.set(i, Vec3(1));
  mask.set(4, Vec3(0));  // one pixel of the first block left out
  const RgbImage m = binMask(mask, 2);
  EXPECT_EQ(m.at(0).x, 0.0f);
  EXPECT_EQ(m.at(1).x, 1.0f);
  // Binned errors: a test image off by +1 and -1 on alternating pixels has
  // no error at all once two such pixels share a block.
  RgbImage ref(2, 1), test(2, 1);
  ref.set(0, Vec3(2));
  ref.set(1, Vec3(2));
  test.set(0, Vec3(3));
  test.set(1, Vec3(1));
  EXPECT_GT(compareImages(test, ref).luminance.relRmse, 0.4);
  EXPECT_NEAR(compareImages(binImage(test, 2), binImage(ref, 2)).luminance.relRmse, 0.0, 1e-7);
}


TEST(ReadImage, APipeIsRefusedNotWaitedOn) {
  // One rule for every input (core/file.h requireRegularFile): a FIFO named
  // as an image would block the reader forever.
  const std::string fifo = test::outputDir("ReadImage_Pipe") + "/image.png";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  test::expectRefusal([&] { readImage(fifo); }, {"is a pipe"});
  EXPECT_THROW(readImage(test::outputDir("ReadImage_Pipe") + "/absent.exr"), InputError);
}


TEST(ReadImage, AHeaderClaimingAHugeImageIsRefusedBeforeDecoding) {
  // A PNG of a few dozen bytes whose header says 16385 x 4096: refused from
  // the header (kMaxImageSide), in memory and on disk, before decoding.
  auto be32 = [](uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  std::string png = "\x89PNG\r\n\x1a\n";
  png += be32(13) + "IHDR" + be32(16385) + be32(4096) + std::string("\x08\x02\x00\x00\x00", 5);
  png += be32(0);  // CRC: the size is read before anything checks it
  png += be32(0) + "IDAT" + be32(0) + be32(0) + "IEND" + be32(0);
  // The bomb is not decoded.
  test::expectRefusal(
      [&] { decodeImageBytes(reinterpret_cast<const unsigned char*>(png.data()), png.size()); },
      {"16385 x 4096"});
  const std::string path = test::outputDir("ReadImage_Bomb") + "/bomb.png";
  std::ofstream(path, std::ios::binary) << png;
  try {
    readImage(path);
    ADD_FAILURE() << "the bomb was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("16385 x 4096"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW(checkImageSize(kMaxImageSide, 1, 16));
  EXPECT_THROW(checkImageSize(kMaxImageSide + 1, 1, 16), InputError);
}

// The fuzz seeds of the image decoders (tests/fuzz/seeds/image/).
std::string seedImage(const char* name) {
  return readFile(test::dataDir() + "/../tests/fuzz/seeds/image/" + name);
}

TEST(ReadImage, BytesThatCannotHoldTheHeadersPixelsAreRefused) {
  // A PNG and a JPEG of 16 x 16 whose headers are changed to 4000 x 4000:
  // within every size limit, but 149 and 677 bytes cannot hold that many
  // pixels (a 156-byte JPEG claiming 12000^2 decoded for 52 s and 3.3 GB).
  const std::string png = seedImage("tiny.png"), jpg = seedImage("tiny.jpg");
  auto decodes = [](const std::string& bytes) {
    return decodeImageBytes(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
  };
  EXPECT_EQ(decodes(png).width, 16);
  EXPECT_EQ(decodes(jpg).height, 16);
  std::string forgedPng = png;
  for (int k : {16, 20}) {  // IHDR width and height, big-endian
    forgedPng[size_t(k) + 2] = char(4000 >> 8);
    forgedPng[size_t(k) + 3] = char(4000 & 0xff);
  }
  std::string forgedJpg = jpg;
  const size_t sof = forgedJpg.find("\xff\xc0");
  ASSERT_NE(sof, std::string::npos);
  for (size_t k : {sof + 5, sof + 7}) {  // SOF0 height and width, big-endian
    forgedJpg[k] = char(4000 >> 8);
    forgedJpg[k + 1] = char(4000 & 0xff);
  }
  for (const auto& [bytes, what] : {std::pair{forgedPng, "PNG"}, std::pair{forgedJpg, "JPEG"}}) {
    try {
      decodes(bytes);
      ADD_FAILURE() << what << " decoded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string("a 4000 x 4000 ") + what), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("truncated, or a header that lies"), std::string::npos)
          << e.what();
    }
  }
  // A JPEG whose Huffman table counts more than 256 codes: stb (Debian 12's)
  // wrote past its tables (the image fuzz target's finding); refused first.
  const std::string overflow = seedImage("huffman-table-overflow.jpg");
  try {
    decodes(overflow);
    ADD_FAILURE() << "the Huffman table overflow was decoded";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not a valid JPEG: a Huffman table of"), std::string::npos)
        << e.what();
  }
  // The same on disk, through readImage (compare, --mask).
  const std::string path = test::outputDir("ReadImage_Forged") + "/forged.jpg";
  std::ofstream(path, std::ios::binary) << forgedJpg;
  EXPECT_THROW(readImage(path), InputError);
}

// The image fuzz target's seeds and findings (tests/fuzz/seeds/image/) as an
// ordinary test, under the sanitizers in CI: each decodes or is refused.
TEST(ReadImage, FuzzSeedsDecodeOrAreRefusedCleanly) {
  int decoded = 0, refused = 0;
  for (const auto& e : std::filesystem::directory_iterator(test::dataDir() + "/../tests/fuzz/seeds/image")) {
    const std::string bytes = readFile(e.path().string());
    try {
      decodeImageBytes(reinterpret_cast<const unsigned char*>(bytes.data()), bytes.size());
      ++decoded;
    } catch (const InputError&) {
      ++refused;
    }
  }
  EXPECT_GE(decoded, 2);  // tiny.png, tiny.jpg
  EXPECT_GE(refused, 1);  // huffman-table-overflow.jpg
}

TEST(ReadImage, AnExrThatHoldsLessThanItsHeaderIsRefusedUnread) {
  // An EXR of 16 x 8000 (ZIP) whose header says 8000 x 8000: OpenEXR would
  // fill what the chunks lack without a word, into a 768 MB frame. Its 313
  // KB cannot hold 768 MB at deflate's 1032:1: refused before any pixel is
  // read, under a 4 GiB address-space limit (the memory check, which sees
  // the limit, lets the 1.43 GiB read through: the compression check
  // refuses it).
  const std::string dir = test::outputDir("ReadImage_ExrBands");
  writeExr(dir + "/small.exr", ramp(16, 8000));
  std::string bytes = readFile(dir + "/small.exr");
  const size_t at = bytes.find(std::string("dataWindow\0box2i\0", 17));
  ASSERT_NE(at, std::string::npos);
  const size_t xmax = at + 17 + 4 + 8;  // after the size, xmin and ymin
  const int32_t wide = 7999;
  std::memcpy(&bytes[xmax], &wide, 4);
  const std::string forged = dir + "/forged.exr";
  std::ofstream(forged, std::ios::binary) << bytes;
  IsolationLimits limits;
  limits.memoryBytes = size_t(4) << 30;
  limits.seconds = 60;
  const IsolatedRun run = runIsolated(
      [&](std::string& message) {
        try {
          readImage(forged);
        } catch (const InputError& e) {
          message = e.what();
          return 1;
        }
        return 0;
      },
      limits);
  if (run.outcome == IsolatedRun::Outcome::NotIsolated) GTEST_SKIP() << "no fork";
  ASSERT_EQ(int(run.outcome), int(IsolatedRun::Outcome::Finished)) << run.ToString(limits);
  EXPECT_EQ(run.exitCode, 1) << run.message;
  EXPECT_NE(run.message.find("forged.exr"), std::string::npos) << run.message;
  EXPECT_NE(run.message.find("a 8000 x 8000 EXR of 12 bytes per pixel compressed at most 1032:1"),
            std::string::npos) << run.message;
  // A whole file still reads.
  EXPECT_EQ(readImage(dir + "/small.exr").rgb, ramp(16, 8000).rgb);
}

/// A Radiance HDR of `width` x `height` whose row r is (1, 0.5, 0.25) times
/// 2^(r % 2): flat RGBE below 8 pixels wide, else one run per stream and
/// row (12 bytes a row). Also the header's length.
std::string radianceHdr(int width, int height, size_t* headerBytes) {
  std::string hdr = "#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y " + std::to_string(height) +
                    " +X " + std::to_string(width) + "\n";
  *headerBytes = hdr.size();
  for (int r = 0; r < height; ++r) {
    const char rgbe[4] = {char(128), char(64), char(32), char(129 + r % 2)};
    if (width < 8) {
      for (int x = 0; x < width; ++x) hdr.append(rgbe, 4);
      continue;
    }
    hdr += {2, 2, char(width >> 8), char(width & 0xff)};
    for (char value : rgbe) hdr += {char(128 + width), value};
  }
  return hdr;
}

TEST(ReadImage, ARadianceHdrCutBeforeItsLastRowIsRefusedNotRepeatedToTheEnd) {
  // stb_image reads on past the end of a Radiance file, repeating its last
  // pixel: a sky cut after a fifth of its rows came back whole (eighth
  // hostile list F7-43, F7-16, F7-48). Flat and run-length files alike.
  const std::string dir = test::outputDir("ReadImage_CutHdr");
  for (int width : {4, 16}) {
    size_t header = 0;
    const std::string whole = radianceHdr(width, 6, &header);
    const size_t rowBytes = (whole.size() - header) / 6;
    const std::string path = dir + "/sky" + std::to_string(width) + ".hdr";
    std::ofstream(path, std::ios::binary) << whole;
    const RgbImage image = readImage(path);
    ASSERT_EQ(image.width, width);
    ASSERT_EQ(image.height, 6);
    for (int r = 0; r < 6; ++r) {
      const float scale = r % 2 ? 2.0f : 1.0f;
      EXPECT_EQ(image.rgb[3 * size_t(r * width)], scale) << "row " << r;
      EXPECT_EQ(image.rgb[3 * size_t(r * width + width - 1) + 2], 0.25f * scale) << "row " << r;
    }
    // Cut inside row 3, and by its last byte alone.
    for (const auto& [bytes, rows] : {std::pair{header + 3 * rowBytes + 5, 3},
                                      std::pair{whole.size() - 1, 5}}) {
      const std::string cut = dir + "/cut" + std::to_string(width) + ".hdr";
      std::ofstream(cut, std::ios::binary) << whole.substr(0, bytes);
      test::expectRefusal([&] { readImage(cut); },
                          {cut, "ends after " + std::to_string(rows) + " of the 6 rows",
                           "truncated or damaged"});
    }
  }
}

TEST(ReadImage, AFileWhoseBytesAreNotItsExtensionsFormatIsRefused) {
  // stb decodes whatever it recognises: a PNG named .hdr was taken as a
  // linear radiance sky (eighth hostile list F7-19).
  const std::string dir = test::outputDir("ReadImage_Renamed");
  const std::string png = seedImage("tiny.png");
  std::ofstream(dir + "/p.png", std::ios::binary) << png;
  EXPECT_EQ(readImage(dir + "/p.png").width, 16);
  for (const char* name : {"/p.hdr", "/p.exr"}) {
    std::ofstream(dir + name, std::ios::binary) << png;
    test::expectRefusal([&] { readImage(dir + name); },
                        {dir + name, "holds a PNG image, not", "renamed"});
  }
  std::ofstream(dir + "/text.hdr", std::ios::binary) << "not an image at all";
  test::expectRefusal([&] { readImage(dir + "/text.hdr"); },
                      {"its first bytes are not those of Radiance HDR"});
}

// A GIF whose header holds no frame (14 bytes, from a glTF's data URI): stb
// refuses it with no reason, and the message was "unreadable image ...: "
// and nothing; it now says which formats are read.
TEST(ReadImage, AnImageRefusedWithoutAReasonIsNamedNotLeftBlank) {
  const std::string gif("GIF89a\x01\x00\x01\x00\x00\x00\x00;", 14);
  test::expectRefusal(
      [&] { decodeStoredImage(reinterpret_cast<const unsigned char*>(gif.data()), gif.size()); },
      {"not a PNG, JPEG or HDR image"});
}

}  // namespace
}  // namespace lo
