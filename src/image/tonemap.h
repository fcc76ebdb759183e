#pragma once
/// @file image/tonemap.h
/// @brief From radiance to a picture a person can look at: an automatic
/// exposure and a tone curve applied before the 8-bit sRGB encoding of PNG
/// output. A fixed exposure with a hard clamp (encodePng) turns most of a
/// bright scene pure white; here the exposure follows the image's key
/// (log-average luminance to middle grey) and the Khronos PBR Neutral curve
/// rolls highlights off below white instead of cutting them.
///
/// The chain for one pixel, all in linear Rec. 709 RGB:
///   radiance -> x 2^ev (exposure) -> curve -> display-linear [0, 1]
///            -> encodeSrgb8 (image/image.h).
/// EXR output stays radiance: exposure and curve are for pictures only.

#include <string>
#include <vector>

#include "core/math.h"
#include "image/image.h"

namespace lo {

class AtomicFileSet;  // core/file_set.h

/// The curve from exposed linear RGB to display-linear RGB in [0, 1].
enum class ToneMap {
  Clamp,    ///< each channel clamped to [0, 1] (what encodePng does alone)
  Neutral,  ///< Khronos PBR Neutral (pbrNeutral): base colours kept, highlights compressed
};
/// "clamp" | "neutral". @throws InputError naming the value.
ToneMap parseToneMap(const std::string& name);
std::string toString(ToneMap curve);

/// @brief The Khronos PBR Neutral tone mapper, exactly as its reference GLSL
/// (github.com/KhronosGroup/ToneMapping, PBR_Neutral/pbrNeutral.glsl), in
/// float: with x = min(R, G, B), the offset f = x - 6.25 x^2 for x < 0.08,
/// else 0.04 (F90) is taken from every channel; while the peak
/// p = max(c - f) stays below Ks = 0.8 - 0.04 that is all (so base colours
/// from 0.08 to 0.8 come out as c - 0.04); above, the peak is compressed to
/// p_n = 1 - (1 - Ks)^2 / (p + 1 - 2 Ks) and the colour moves towards grey
/// p_n by g = 1 - 1 / (0.15 (p - p_n) + 1). No hue shift; output in [0, 1).
/// `linear` must be non-negative and finite (toneMapPixel ensures it).
Vec3 pbrNeutral(const Vec3& linear);

/// @brief One exposed pixel through `curve`: a channel that is not finite or
/// is negative counts as 0 (as encodeSrgb8 treats NaN and Inf), then the
/// curve. The result lies in [0, 1].
Vec3 toneMapPixel(const Vec3& exposed, ToneMap curve);

/// How autoExposureEv picks the exposure. Luminance is Rec. 709 Y of the
/// image's linear RGB; only pixels with a finite Y > 0 take part (a NaN, an
/// Inf, the black background of a frame the scene does not fill).
struct AutoExposureParams {
  /// The display-linear value the image's key lands on: middle grey
  /// (18% reflectance; sRGB 0.46).
  float key = 0.18f;
  /// Which luminance stands for the highlights: this quantile of the taking
  /// part (0.99: the brightest 1% may clip freely, lamps and the sun).
  float highlightQuantile = 0.99f;
  /// The exposure is lowered until the highlight quantile lands at or below
  /// this many times display white (1): PBR Neutral maps 4 to 0.98, just
  /// short of the 8-bit white.
  float highlightLimit = 4.0f;
  /// ... but by at most this many stops below what the key asks for, so that
  /// a frame with a large bright window keeps its room in view (the window
  /// then clips, as in a photograph).
  float maxHighlightStops = 1.0f;
  /// Pixels darker than the highlight quantile x 2^-floorStops count as that
  /// (a pixel 13 stops below the highlights is black on any display): a few
  /// near-zero values cannot drag the log-average, nor the exposure, without
  /// bound.
  float floorStops = 13.0f;
};

/// @brief The exposure in EV (stops; the picture is radiance x 2^EV) that
/// maps the image's key to `params.key`:
///   key  = 2^( mean over the taking-part pixels of log2(max(Y, Yfloor)) ),
///          the log-average (geometric mean) luminance, with
///          Yfloor = Yh x 2^-floorStops and Yh the highlight quantile of Y;
///   evKey = log2(params.key / key);
///   ev   = evKey, lowered to log2(highlightLimit / Yh) when Yh x 2^evKey
///          exceeds highlightLimit, but not below evKey - maxHighlightStops.
/// A constant image of luminance L gives log2(key / L). Sums run in double,
/// in pixel order, on one thread: the same image gives the same exposure.
/// @return 0 for an empty image or one without a finite pixel of Y > 0;
/// always finite.
/// @throws InputError naming the field of `params` out of range (key,
/// highlightLimit: finite, > 0; highlightQuantile in [0, 1]; the stops
/// finite, >= 0).
float autoExposureEv(const RgbImage& image, const AutoExposureParams& params = {});

/// How a radiance image becomes a picture.
struct ToneParams {
  /// Stops: with autoExposure, a compensation added to the automatic
  /// exposure (+1 = twice as bright as auto); without, the exposure itself
  /// (radiance x 2^exposureEv, as encodePng's exposureEv).
  float exposureEv = 0.0f;
  bool autoExposure = true;  ///< autoExposureEv(image, autoParams) + exposureEv
  ToneMap curve = ToneMap::Neutral;
  AutoExposureParams autoParams;
  std::string ToString() const;
};

/// What toneMapped did: the exposure it used and how much of the picture is
/// white. A channel clips where its 8-bit sRGB code (encodeSrgb8) is 255,
/// i.e. display-linear >= 0.9954: what a person sees as clipped, whichever
/// the curve (PBR Neutral reaches 1 only in the limit).
struct ToneReport {
  float exposureEv = 0.0f;    ///< the exposure applied, compensation included
  bool autoExposure = false;  ///< whether it came from autoExposureEv
  ToneMap curve = ToneMap::Neutral;
  double clippedShare = 0;  ///< share of all pixels with at least one channel at 255
  double whiteShare = 0;    ///< share of all pixels with all three channels at 255
  /// "exposure +1.25 EV (auto), neutral, 0.3% of pixels clip, 0.1% white"
  std::string ToString() const;
};

/// @brief The picture of `image`: every pixel x 2^ev, then params.curve
/// (toneMapPixel), display-linear in [0, 1], ready for encodeSrgb8/encodePng
/// at exposure 0. An empty image gives an empty image (and a report of 0).
/// @param report when not null, filled with the exposure and clipped shares.
/// The exposure and its product are computed in double, so an image of tiny
/// values (auto exposure far above 2^127) is not lost to overflow.
/// @throws InputError when params.exposureEv is not finite, params.autoParams
/// is out of range (autoExposureEv), or the image's pixels do not match its size.
RgbImage toneMapped(const RgbImage& image, const ToneParams& params = {},
                    ToneReport* report = nullptr);

/// @brief encodePng of toneMapped(image, params, report): the PNG a person
/// looks at. @throws as toneMapped and encodePng.
std::vector<unsigned char> encodeTonedPng(const RgbImage& image, const ToneParams& params = {},
                                          ToneReport* report = nullptr);

/// @brief writeImage with a tone curve: a .png gets encodeTonedPng's bytes
/// (through `path.tmp` and a rename, or into `into`); an .exr keeps the
/// radiance as writeExr writes it, neither exposed nor curved, and leaves
/// `report` as it was. @throws InputError naming the file for another
/// extension or an empty image; IoError from the write.
void writeTonedImage(const std::string& path, const RgbImage& image, const ToneParams& params = {},
                     AtomicFileSet* into = nullptr, ToneReport* report = nullptr);

}  // namespace lo
