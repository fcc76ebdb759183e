#pragma once
/// @file image/compare.h
/// @brief Error metrics between a test image and a reference image, and a
/// false-colour difference image. Used by `lightoctree compare` and tests.
///
/// Over the set P of compared pixels, with a the test value and b the
/// reference value of one channel (R, G, B, or Rec. 709 luminance Y):
///   relative RMSE = sqrt( sum_P (a - b)^2 / sum_P b^2 )
///                 = sqrt( mean_P (a - b)^2 / mean_P b^2 )
///   relative MAE  = sum_P |a - b| / sum_P |b|
///   max error     = max_P |a - b|      (absolute, in the images' units)
/// A relative metric whose denominator is 0 is 0 if the images agree on P,
/// else +infinity.

#include <cstddef>
#include <string>

#include "core/number_range.h"
#include "core/progress.h"
#include "image/image.h"

namespace lo {

struct CompareParams {
  /// Optional mask of the same size: pixels whose mask is 0 in every channel
  /// are left out. Null = compare every pixel.
  const RgbImage* mask = nullptr;
  /// Also leave out pixels where the reference is exactly (0, 0, 0): the
  /// background of a scene that does not fill the frame.
  bool ignoreBackground = false;
};

struct ChannelError {
  double relRmse = 0;
  double relMae = 0;
  double maxAbs = 0;
};

struct CompareResult {
  ChannelError channel[3];  ///< R, G, B
  ChannelError luminance;   ///< Rec. 709 Y of each pixel
  /// R, G and B pooled: sqrt(sum over pixels and channels (a - b)^2 / sum b^2)
  /// (and likewise the MAE): one figure for colour errors that luminance
  /// averages away (a brown table drawn mauve-grey).
  ChannelError rgb;
  size_t comparedPixels = 0;
  size_t ignoredPixels = 0;            ///< by the mask or as background
  size_t nonFinitePixels = 0;          ///< NaN/inf in either image: left out and counted
  int maxErrorX = -1, maxErrorY = -1;  ///< pixel of the largest luminance error
  double meanReferenceLuminance = 0;   ///< over the compared pixels
  double meanTestLuminance = 0;        ///< over the same pixels
  std::string ToString() const;        ///< a small table
};

/// The image averaged over blocks of `bin` x `bin` pixels (blocks at the right
/// and bottom edges average the pixels they have): comparing binned images
/// measures the error of what the eye sees at that scale, without the
/// per-pixel noise of a Monte Carlo reference. `bin` = 1 returns the image.
/// @throws InputError if bin < 1.
RgbImage binImage(const RgbImage& image, int bin);
/// A mask binned like binImage: a block is selected when every pixel of it is.
RgbImage binMask(const RgbImage& mask, int bin);

/// Per-pixel standard errors binned as binImage bins values: the standard
/// error of each block's mean, sqrt(sum se^2) / n (pixels independent).
RgbImage binStdError(const RgbImage& stdError, int bin);

/// The reference's own noise as compareImages' luminance relative RMSE
/// counts an error: sqrt(sum_P se_Y^2 / sum_P Y^2) over the pixels P that
/// `params` compares, se_Y = 0.2126 se_R + 0.7152 se_G + 0.0722 se_B (the
/// channels of one path correlate, so this bounds the luminance's error).
/// `stdError` is the reference's per-pixel standard error (`reference
/// --std-error`), binned alike when the images are. A measured error at or
/// below it says nothing the reference can tell apart from its own noise.
/// @throws InputError if the sizes differ.
double referenceNoise(const RgbImage& reference, const RgbImage& stdError,
                      const CompareParams& params = {});

/// A Monte Carlo image's distance from converged, over all its channel
/// values v with per-value standard errors se (`reference --std-error`):
/// mean = mean(v), rmsStdError = sqrt(mean(se^2)), both in the image's units.
struct ImageNoise {
  double mean = 0;
  double rmsStdError = 0;
  /// rmsStdError as a percentage of the mean, 0 when the mean is not above
  /// 0 (`reference` prints it, to weigh errors measured against the image).
  double percent() const { return mean > 0 ? 100.0 * rmsStdError / mean : 0.0; }
};
/// @throws InputError naming both sizes if they differ, or if the image is empty.
ImageNoise imageNoise(const RgbImage& image, const RgbImage& stdError);

/// The p-th percentile (0 < p <= 100, nearest rank) of each channel of
/// `image` over the pixels `params` compares (against `image` itself).
/// 0 when no pixel is compared.
Vec3 channelPercentiles(const RgbImage& image, double p, const CompareParams& params = {});

/// Every value of channel c clamped to at most limit[c]: the test and the
/// reference clipped at the reference's 99th percentile compare the picture
/// without letting a few visible lamps (thousands of times brighter than the
/// walls) rule the RMSE.
void clipChannels(RgbImage& image, const Vec3& limit);

/// Black holes: compared pixels where the test's luminance is below
/// `darkFraction` of the reference's mean while the reference's own is above
/// `litFraction` of that mean: surfaces the reference lights that the test
/// draws (nearly) black. Counted per pixel, before any binning.
struct DarkHoles {
  size_t pixels = 0;    ///< black holes
  size_t compared = 0;  ///< pixels judged
  double share() const { return compared ? double(pixels) / double(compared) : 0.0; }
};
/// @throws InputError if the sizes (or the mask's) differ or an image is empty.
DarkHoles darkHoles(const RgbImage& test, const RgbImage& reference,
                    const CompareParams& params = {}, double darkFraction = 0.02,
                    double litFraction = 0.2);

/// @throws InputError if the sizes (or the mask's) differ or an image is empty.
CompareResult compareImages(const RgbImage& test, const RgbImage& reference,
                            const CompareParams& params = {});

/// `compare --bin` and the Python module's bin: blocks of 1 to 1024 pixels.
constexpr NumberRange kCompareBinRange{1, 1024, false, true};
/// `compare --clip-percentile` and clip_percentile: (0, 100], 100 = off.
constexpr NumberRange kClipPercentileRange{0, 100, true};

/// What `lightoctree compare` and the Python module's compare choose.
struct CompareSettings {
  int bin = 1;                 ///< average over bin x bin blocks first (kCompareBinRange)
  float clipPercentile = 100;  ///< clip at the reference's percentile first; 100 = off
  bool ignoreBackground = false;  ///< CompareParams::ignoreBackground
};

/// Everything `compare` measures, in the images the figures are of.
struct CompareReport {
  CompareResult result;  ///< of the clipped and binned images
  DarkHoles holes;       ///< per pixel, before clipping and binning
  Vec3 clip{0, 0, 0};    ///< clipPercentile < 100: the limit of each channel, else 0
  /// The reference's relative RMS standard error of Y over the compared
  /// pixels (and bins), referenceNoise(); < 0 when no standard error was given.
  double referenceNoise = -1;
  /// The images as compared (clipped, binned), for differenceImage; `mask`
  /// empty when none was given.
  RgbImage test, reference, mask;
  /// The parameters the figures were measured with, over this report's mask.
  CompareParams params() const {
    CompareParams p;
    p.mask = mask.rgb.empty() ? nullptr : &mask;
    p.ignoreBackground = ignoreBackground;
    return p;
  }
  bool ignoreBackground = false;
  int bin = 1;  ///< CompareSettings::bin: result counts bins of bin x bin pixels
  /// Pixels the mask and ignoreBackground select that are NaN or infinite in
  /// either image (after clipping, which takes an infinite value to its
  /// limit), counted per pixel before binning: left out of the figures, and
  /// with bin > 1 so is every bin holding one (result.nonFinitePixels).
  size_t nonFiniteImagePixels = 0;
  /// "" when no pixel was left out for not being finite; else a sentence
  /// for a warning saying how many were, and what the figures are of: a
  /// test image half NaN scored its other half without a word.
  std::string nonFiniteWarning() const;
  /// "" unless a channel's relative errors are infinite: the reference is
  /// black (0) there over the pixels compared and the test image is not, so
  /// rel_rmse and rel_mae are undefined (inf in the figures and the JSON).
  std::string blackReferenceWarning() const;
  /// Every warning of the comparison (nonFiniteWarning, blackReferenceWarning), in order.
  std::vector<std::string> warnings() const;
};

/// A standard error image (`reference --std-error`, `compare
/// --reference-error`): every value is 0 or more, or NaN where the reference
/// had no sample. A negative value was taken and made the reference's noise
/// figure a meaningless number. @throws InputError starting with `what`,
/// naming the pixel and channel.
void checkStdError(const RgbImage& stdError, const std::string& what);

/// @brief `compare`'s measurement in its order: black holes judged per pixel
/// against the reference as it is; then both images clipped at the
/// reference's clipPercentile (over the compared pixels); then the images, the
/// mask (binMask) and the standard error (binStdError) binned; then
/// compareImages and referenceNoise. `mask` and `stdError` may be null.
/// `progress` is told of each of these steps ("compare", 7 steps); a sink
/// that throws from a report stops it there (Python's Ctrl-C heard between
/// steps: 8000^2 pixels took 10 s, deaf, H15-1-1).
/// @throws InputError if the sizes differ, an image is empty or bin < 1.
CompareReport compareReport(RgbImage test, RgbImage reference, const CompareSettings& settings,
                            const RgbImage* mask = nullptr, const RgbImage* stdError = nullptr,
                            ProgressSink* progress = nullptr);

/// False colour of |Y(test) - Y(reference)| / scale: black 0, blue 0.25,
/// green 0.5, yellow 0.75, red >= 1; ignored pixels mid grey. scale <= 0
/// means 0.25 x the mean reference luminance over the compared pixels (so red
/// marks an error of a quarter of the mean brightness or more).
RgbImage differenceImage(const RgbImage& test, const RgbImage& reference,
                         const CompareParams& params = {}, float scale = 0);

}  // namespace lo
