/// @file image/tonemap.cpp
/// @brief Automatic exposure and tone curves for image/tonemap.h.

#include "image/tonemap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "core/error.h"
#include "core/file.h"

namespace lo {
namespace tonemap_internal {

/// The Rec. 709 Y of a pixel that takes part in the automatic exposure, 0
/// for one that does not (Y not finite, or not above 0 once in float). Summed
/// in double: three channels near FLT_MAX do not overflow.
float exposureLuminance(const float* rgb) {
  const double y = 0.2126 * double(rgb[0]) + 0.7152 * double(rgb[1]) + 0.0722 * double(rgb[2]);
  if (!(std::isfinite(y) && y > 0)) return 0.0f;
  return float(std::min(y, double(std::numeric_limits<float>::max())));
}

/// The 8-bit code 255 starts here: linearToSrgb(v) * 255 rounds to 255 from
/// sRGB 254.5 / 255 on. Found once by bisection on encodeSrgb8 itself, so
/// that "clipped" means exactly what the PNG holds.
float clipThreshold() {
  static const float threshold = [] {
    float below = 0.5f, above = 1.0f;  // encodeSrgb8(below) < 255 <= encodeSrgb8(above)
    for (;;) {
      const float mid = below + 0.5f * (above - below);
      if (mid <= below || mid >= above) return above;
      (encodeSrgb8(mid) == 255 ? above : below) = mid;
    }
  }();
  return threshold;
}

/// @throws InputError naming the field of `params` that is out of range.
void checkParams(const AutoExposureParams& params) {
  auto bad = [](const char* field, float value, const char* range) {
    throw InputError(std::string("AutoExposureParams.") + field + " " + std::to_string(value) +
                     " must be " + range);
  };
  if (!(std::isfinite(params.key) && params.key > 0)) bad("key", params.key, "finite and > 0");
  if (!(params.highlightQuantile >= 0 && params.highlightQuantile <= 1)) {
    bad("highlightQuantile", params.highlightQuantile, "in [0, 1]");
  }
  if (!(std::isfinite(params.highlightLimit) && params.highlightLimit > 0)) {
    bad("highlightLimit", params.highlightLimit, "finite and > 0");
  }
  if (!(std::isfinite(params.maxHighlightStops) && params.maxHighlightStops >= 0)) {
    bad("maxHighlightStops", params.maxHighlightStops, "finite and >= 0");
  }
  if (!(std::isfinite(params.floorStops) && params.floorStops >= 0)) {
    bad("floorStops", params.floorStops, "finite and >= 0");
  }
}

/// v x scale in double, back in float: an exposure of 2^140 (an image of
/// denormals) neither overflows the scale nor the product (held at FLT_MAX,
/// which the curve takes to white).
float expose(float v, double scale) {
  const double x = double(v) * scale;
  constexpr double kMax = std::numeric_limits<float>::max();
  return std::isnan(x) ? 0.0f : float(std::clamp(x, -kMax, kMax));
}

std::string formatEv(float ev) {
  char text[32];
  std::snprintf(text, sizeof text, "%+.2f EV", double(ev));
  return text;
}

std::string formatPercent(double share) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f%%", 100.0 * share);
  return text;
}

}  // namespace tonemap_internal

ToneMap parseToneMap(const std::string& name) {
  if (name == "clamp") return ToneMap::Clamp;
  if (name == "neutral") return ToneMap::Neutral;
  throw InputError("unknown tone map '" + name + "' (expected clamp or neutral)");
}

std::string toString(ToneMap curve) { return curve == ToneMap::Clamp ? "clamp" : "neutral"; }

Vec3 pbrNeutral(const Vec3& linear) {
  // The reference GLSL line by line (KhronosGroup/ToneMapping,
  // PBR_Neutral/pbrNeutral.glsl), in float as a shader computes it.
  constexpr float startCompression = 0.8f - 0.04f;
  constexpr float desaturation = 0.15f;
  Vec3 color = linear;
  const float x = std::min(color.x, std::min(color.y, color.z));
  const float offset = x < 0.08f ? x - 6.25f * x * x : 0.04f;
  color -= Vec3(offset);

  const float peak = std::max(color.x, std::max(color.y, color.z));
  if (peak < startCompression) return color;

  constexpr float d = 1.0f - startCompression;
  const float newPeak = 1.0f - d * d / (peak + d - startCompression);
  color *= newPeak / peak;

  const float g = 1.0f - 1.0f / (desaturation * (peak - newPeak) + 1.0f);
  // GLSL mix(a, b, t) = a * (1 - t) + b * t.
  return color * (1.0f - g) + Vec3(newPeak) * g;
}

Vec3 toneMapPixel(const Vec3& exposed, ToneMap curve) {
  Vec3 c;
  for (int k = 0; k < 3; ++k) {
    const float v = exposed[k];
    c[k] = std::isfinite(v) && v > 0.0f ? v : 0.0f;
  }
  if (curve == ToneMap::Neutral) c = pbrNeutral(c);
  // The curve's output is in [0, 1) by construction; the clamp also holds the
  // last rounding of float and is the whole of ToneMap::Clamp.
  return {std::clamp(c.x, 0.0f, 1.0f), std::clamp(c.y, 0.0f, 1.0f), std::clamp(c.z, 0.0f, 1.0f)};
}

float autoExposureEv(const RgbImage& image, const AutoExposureParams& params) {
  using tonemap_internal::exposureLuminance;
  tonemap_internal::checkParams(params);
  const size_t n = std::min(image.pixelCount(), image.rgb.size() / 3);
  // The highlight quantile by rank (nearest rank below) on a float copy of
  // the taking-part luminances (4 bytes a pixel; the image holds 12).
  std::vector<float> sorted;
  sorted.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    const float y = exposureLuminance(image.rgb.data() + 3 * i);
    if (y > 0) sorted.push_back(y);
  }
  if (sorted.empty()) return 0.0f;
  const size_t rank =
      size_t(std::floor(double(params.highlightQuantile) * double(sorted.size() - 1)));
  std::nth_element(sorted.begin(), sorted.begin() + ptrdiff_t(rank), sorted.end());
  const double logHighlight = std::log2(double(sorted[rank]));
  const double logFloor = logHighlight - double(params.floorStops);

  // The log-average in pixel order, so that it sums the same way every time.
  double sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const float y = exposureLuminance(image.rgb.data() + 3 * i);
    if (y > 0) sum += std::max(std::log2(double(y)), logFloor);
  }
  const double logKey = sum / double(sorted.size());

  const double evKey = std::log2(double(params.key)) - logKey;
  const double evHighlight = std::log2(double(params.highlightLimit)) - logHighlight;
  double ev = evKey;
  if (evHighlight < ev) ev = std::max(evHighlight, evKey - double(params.maxHighlightStops));
  // Finite parameters and luminances from denormals (2^-149) to FLT_MAX
  // (2^128) keep |ev| below about 300; the guard holds the promise anyway.
  return std::isfinite(ev) ? float(ev) : 0.0f;
}

std::string ToneParams::ToString() const {
  return std::string("ToneParams{") + (autoExposure ? "auto exposure " : "exposure ") +
         tonemap_internal::formatEv(exposureEv) + ", " + toString(curve) + "}";
}

std::string ToneReport::ToString() const {
  using namespace tonemap_internal;
  return "exposure " + formatEv(exposureEv) + (autoExposure ? " (auto)" : "") + ", " +
         toString(curve) + ", " + formatPercent(clippedShare) + " of pixels clip, " +
         formatPercent(whiteShare) + " white";
}

RgbImage toneMapped(const RgbImage& image, const ToneParams& params, ToneReport* report) {
  if (!std::isfinite(params.exposureEv)) {
    throw InputError("exposure " + std::to_string(params.exposureEv) +
                     " EV is not a finite number");
  }
  if (image.width < 0 || image.height < 0 || image.rgb.size() != image.pixelCount() * 3) {
    throw InputError("toneMapped: " + std::to_string(image.rgb.size()) + " floats for a " +
                     std::to_string(image.width) + " x " + std::to_string(image.height) +
                     " RGB image");
  }
  const float ev =
      params.exposureEv + (params.autoExposure ? autoExposureEv(image, params.autoParams) : 0.0f);
  const double scale = std::exp2(double(ev));
  const float clip = tonemap_internal::clipThreshold();
  RgbImage out(image.width, image.height);
  size_t clipped = 0, white = 0;
  for (size_t i = 0; i < image.pixelCount(); ++i) {
    const float* p = image.rgb.data() + 3 * i;
    using tonemap_internal::expose;
    const Vec3 c =
        toneMapPixel({expose(p[0], scale), expose(p[1], scale), expose(p[2], scale)}, params.curve);
    out.set(i, c);
    const int atWhite = int(c.x >= clip) + int(c.y >= clip) + int(c.z >= clip);
    clipped += atWhite > 0;
    white += atWhite == 3;
  }
  if (report) {
    const double pixels = double(std::max<size_t>(1, image.pixelCount()));
    report->exposureEv = ev;
    report->autoExposure = params.autoExposure;
    report->curve = params.curve;
    report->clippedShare = double(clipped) / pixels;
    report->whiteShare = double(white) / pixels;
  }
  return out;
}

std::vector<unsigned char> encodeTonedPng(const RgbImage& image, const ToneParams& params,
                                          ToneReport* report) {
  return encodePng(toneMapped(image, params, report), 0.0f);
}

void writeTonedImage(const std::string& path, const RgbImage& image, const ToneParams& params,
                     AtomicFileSet* into, ToneReport* report) {
  if (lowerExtension(path) != ".png") return writeImage(path, image, 0.0f, into);
  // Display-linear in [0, 1]: writePng's exposure 0 and clamp leave it as it is.
  writePng(path, toneMapped(image, params, report), 0.0f, into);
}

}  // namespace lo
