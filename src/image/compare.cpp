/// @file image/compare.cpp
/// @brief Image error metrics (image/compare.h).

#include "image/compare.h"

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>
#include <vector>

#include "core/error.h"
#include "core/resources.h"

namespace lo {
namespace {

void checkSizes(const RgbImage& test, const RgbImage& reference, const CompareParams& params) {
  if (test.pixelCount() == 0 || reference.pixelCount() == 0)
    throw InputError("compare: empty image");
  if (test.width != reference.width || test.height != reference.height)
    throw InputError("compare: image sizes differ: " + std::to_string(test.width) + " x " +
                     std::to_string(test.height) + " vs reference " +
                     std::to_string(reference.width) + " x " + std::to_string(reference.height));
  if (params.mask &&
      (params.mask->width != reference.width || params.mask->height != reference.height))
    throw InputError("compare: mask is " + std::to_string(params.mask->width) + " x " +
                     std::to_string(params.mask->height) + ", images are " +
                     std::to_string(reference.width) + " x " + std::to_string(reference.height));
}

enum class PixelUse { Compare, Ignore, NonFinite };

PixelUse pixelUse(const RgbImage& test, const RgbImage& reference, const CompareParams& params,
                  size_t i) {
  if (params.mask && maxComponent(params.mask->at(i)) == 0) return PixelUse::Ignore;
  Vec3 b = reference.at(i);
  if (params.ignoreBackground && b == Vec3{0, 0, 0}) return PixelUse::Ignore;
  if (!isFinite(b) || !isFinite(test.at(i))) return PixelUse::NonFinite;
  return PixelUse::Compare;
}

struct Accumulator {
  double sumSqDiff = 0, sumSqRef = 0, sumAbsDiff = 0, sumAbsRef = 0, maxAbs = 0;
  void add(double a, double b) {
    double d = a - b;
    sumSqDiff += d * d;
    sumSqRef += b * b;
    sumAbsDiff += std::fabs(d);
    sumAbsRef += std::fabs(b);
    maxAbs = std::max(maxAbs, std::fabs(d));
  }
  static double ratio(double num, double den) {
    if (den > 0) return num / den;
    return num > 0 ? std::numeric_limits<double>::infinity() : 0.0;
  }
  ChannelError result() const {
    ChannelError e;
    e.relRmse = std::sqrt(ratio(sumSqDiff, sumSqRef));
    e.relMae = ratio(sumAbsDiff, sumAbsRef);
    e.maxAbs = maxAbs;
    return e;
  }
};

}  // namespace

namespace {

template <typename Combine>
RgbImage binWith(const RgbImage& image, int bin, float init, Combine combine, bool mean) {
  if (bin < 1) throw InputError("bin size " + std::to_string(bin) + " must be at least 1");
  if (bin == 1) return image;
  const int w = (image.width + bin - 1) / bin, h = (image.height + bin - 1) / bin;
  RgbImage out(w, h);
  for (int by = 0; by < h; ++by) {
    for (int bx = 0; bx < w; ++bx) {
      double acc[3] = {init, init, init};
      int n = 0;
      for (int y = by * bin; y < std::min(image.height, (by + 1) * bin); ++y) {
        for (int x = bx * bin; x < std::min(image.width, (bx + 1) * bin); ++x) {
          const float* p = image.pixel(x, y);
          for (int c = 0; c < 3; ++c) acc[c] = combine(acc[c], double(p[c]));
          ++n;
        }
      }
      for (int c = 0; c < 3; ++c) {
        out.rgb[(size_t(by) * size_t(w) + size_t(bx)) * 3 + size_t(c)] =
            float(mean ? acc[c] / n : acc[c]);
      }
    }
  }
  return out;
}

}  // namespace

RgbImage binImage(const RgbImage& image, int bin) {
  return binWith(image, bin, 0.0f, [](double a, double v) { return a + v; }, true);
}

RgbImage binMask(const RgbImage& mask, int bin) {
  // A pixel is selected when any channel is non-zero: its selection is max(|c|).
  RgbImage selection = mask;
  for (size_t i = 0; i < selection.pixelCount(); ++i) {
    const Vec3 v = selection.at(i);
    const float s = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > 0 ? 1.0f : 0.0f;
    selection.set(i, Vec3(s));
  }
  return binWith(selection, bin, 1.0f, [](double a, double v) { return std::min(a, v); }, false);
}

RgbImage binStdError(const RgbImage& stdError, int bin) {
  RgbImage squared = stdError;
  for (float& v : squared.rgb) v *= v;
  // Sums of squares per block, then sqrt(sum) / n.
  RgbImage out = binWith(squared, bin, 0.0f, [](double a, double v) { return a + v; }, false);
  for (int by = 0; by < out.height; ++by) {
    for (int bx = 0; bx < out.width; ++bx) {
      const int nx = std::min(stdError.width, (bx + 1) * bin) - bx * bin;
      const int ny = std::min(stdError.height, (by + 1) * bin) - by * bin;
      const float n = float(nx * ny);
      float* p = out.rgb.data() + (size_t(by) * size_t(out.width) + size_t(bx)) * 3;
      for (int c = 0; c < 3; ++c) p[c] = std::sqrt(p[c]) / n;
    }
  }
  return out;
}

double referenceNoise(const RgbImage& reference, const RgbImage& stdError,
                      const CompareParams& params) {
  checkSizes(stdError, reference, params);
  double se2 = 0, y2 = 0;
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    if (pixelUse(stdError, reference, params, i) != PixelUse::Compare) continue;
    const Vec3 s = stdError.at(i);
    const double se = 0.2126 * s.x + 0.7152 * s.y + 0.0722 * s.z;
    const double y = luminance(reference.at(i));
    se2 += se * se;
    y2 += y * y;
  }
  return y2 > 0 ? std::sqrt(se2 / y2) : 0.0;
}

ImageNoise imageNoise(const RgbImage& image, const RgbImage& stdError) {
  if (image.pixelCount() == 0 || stdError.width != image.width || stdError.height != image.height) {
    throw InputError("imageNoise: an image of " + std::to_string(image.width) + " x " +
                     std::to_string(image.height) + " with standard errors of " +
                     std::to_string(stdError.width) + " x " + std::to_string(stdError.height));
  }
  double sum = 0, se2 = 0;
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    sum += image.rgb[i];
    se2 += double(stdError.rgb[i]) * stdError.rgb[i];
  }
  const double n = double(image.rgb.size());
  ImageNoise noise;
  noise.mean = sum / n;
  noise.rmsStdError = std::sqrt(se2 / n);
  return noise;
}

Vec3 channelPercentiles(const RgbImage& image, double p, const CompareParams& params) {
  checkSizes(image, image, params);
  if (!(p > 0 && p <= 100)) {
    throw InputError("the clip percentile (--clip-percentile, clip_percentile) " + formatNumber(p) +
                     " is not in (0, 100]");
  }
  std::vector<float> values[3];
  for (size_t i = 0; i < image.pixelCount(); ++i) {
    if (pixelUse(image, image, params, i) != PixelUse::Compare) continue;
    const Vec3 v = image.at(i);
    for (int c = 0; c < 3; ++c) values[c].push_back(v[c]);
  }
  Vec3 out(0.0f);
  if (values[0].empty()) return out;
  // Nearest rank: the smallest value with at least p% of the values at or below it.
  const size_t n = values[0].size();
  const size_t rank = std::min(n, size_t(std::max(1.0, std::ceil(p / 100.0 * double(n))))) - 1;
  for (int c = 0; c < 3; ++c) {
    std::nth_element(values[c].begin(), values[c].begin() + std::ptrdiff_t(rank), values[c].end());
    out[c] = values[c][rank];
  }
  return out;
}

void clipChannels(RgbImage& image, const Vec3& limit) {
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    image.rgb[i] = std::min(image.rgb[i], limit[int(i % 3)]);
  }
}

DarkHoles darkHoles(const RgbImage& test, const RgbImage& reference, const CompareParams& params,
                    double darkFraction, double litFraction) {
  checkSizes(test, reference, params);
  const double mean = compareImages(test, reference, params).meanReferenceLuminance;
  DarkHoles holes;
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    if (pixelUse(test, reference, params, i) != PixelUse::Compare) continue;
    ++holes.compared;
    if (luminance(test.at(i)) < darkFraction * mean &&
        luminance(reference.at(i)) > litFraction * mean) {
      ++holes.pixels;
    }
  }
  return holes;
}

CompareResult compareImages(const RgbImage& test, const RgbImage& reference,
                            const CompareParams& params) {
  checkSizes(test, reference, params);
  CompareResult r;
  Accumulator acc[4], pooled;
  double maxLum = -1, sumLum = 0, sumTestLum = 0;
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    PixelUse use = pixelUse(test, reference, params, i);
    if (use == PixelUse::Ignore) {
      ++r.ignoredPixels;
      continue;
    }
    if (use == PixelUse::NonFinite) {
      ++r.nonFinitePixels;
      continue;
    }
    ++r.comparedPixels;
    Vec3 a = test.at(i), b = reference.at(i);
    for (int c = 0; c < 3; ++c) {
      acc[c].add(a[c], b[c]);
      pooled.add(a[c], b[c]);
    }
    double ya = luminance(a), yb = luminance(b);
    acc[3].add(ya, yb);
    sumLum += yb;
    sumTestLum += ya;
    if (std::fabs(ya - yb) > maxLum) {
      maxLum = std::fabs(ya - yb);
      r.maxErrorX = int(i % size_t(reference.width));
      r.maxErrorY = int(i / size_t(reference.width));
    }
  }
  for (int c = 0; c < 3; ++c) r.channel[c] = acc[c].result();
  r.luminance = acc[3].result();
  r.rgb = pooled.result();
  r.meanReferenceLuminance = r.comparedPixels ? sumLum / double(r.comparedPixels) : 0.0;
  r.meanTestLuminance = r.comparedPixels ? sumTestLum / double(r.comparedPixels) : 0.0;
  return r;
}

std::string CompareResult::ToString() const {
  std::ostringstream os;
  char line[160];
  os << "channel    rel.RMSE    rel.MAE     max.abs\n";
  const char* names[5] = {"R", "G", "B", "Y", "RGB"};
  for (int c = 0; c < 5; ++c) {
    const ChannelError& e = c < 3 ? channel[c] : c == 3 ? luminance : rgb;
    std::snprintf(line, sizeof line, "%-8s %10.5f %10.5f %11.5g\n", names[c], e.relRmse, e.relMae,
                  e.maxAbs);
    os << line;
  }
  os << "pixels: " << comparedPixels << " compared, " << ignoredPixels << " ignored, "
     << nonFinitePixels << " non-finite; largest Y error at (" << maxErrorX << ", " << maxErrorY
     << "); mean Y: reference " << meanReferenceLuminance << ", test " << meanTestLuminance;
  if (meanReferenceLuminance > 0) {
    std::snprintf(line, sizeof line, " (%.4f of the reference)",
                  meanTestLuminance / meanReferenceLuminance);
    os << line;
  }
  return os.str();
}

RgbImage differenceImage(const RgbImage& test, const RgbImage& reference,
                         const CompareParams& params, float scale) {
  checkSizes(test, reference, params);
  if (!(scale > 0)) {
    double mean = compareImages(test, reference, params).meanReferenceLuminance;
    scale = float(0.25 * mean);
    if (!(scale > 0)) scale = 1.0f;
  }
  static const Vec3 kRamp[5] = {{0, 0, 0}, {0, 0, 1}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}};
  RgbImage out(reference.width, reference.height);
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    PixelUse use = pixelUse(test, reference, params, i);
    if (use == PixelUse::Ignore) {
      out.set(i, Vec3{0.2f, 0.2f, 0.2f});
      continue;
    }
    if (use == PixelUse::NonFinite) {
      out.set(i, Vec3{1, 0, 1});  // magenta: NaN or inf
      continue;
    }
    float t = std::fabs(luminance(test.at(i)) - luminance(reference.at(i))) / scale;
    float x = std::clamp(t, 0.0f, 1.0f) * 4.0f;
    int k = std::min(3, int(x));
    float f = x - float(k);
    out.set(i, kRamp[k] * (1.0f - f) + kRamp[k + 1] * f);
  }
  return out;
}

std::string CompareReport::nonFiniteWarning() const {
  if (nonFiniteImagePixels == 0) return "";
  const std::string count = std::to_string(nonFiniteImagePixels) +
                            (nonFiniteImagePixels == 1 ? " pixel is" : " pixels are") +
                            " not finite (NaN or infinite in the test image or the reference)";
  const std::string compared = std::to_string(result.comparedPixels);
  if (bin <= 1) {
    return count + " and left out: the figures are of the " + compared + " pixels compared";
  }
  const std::string bins = std::to_string(bin) + " x " + std::to_string(bin);
  return count + ": the " + std::to_string(result.nonFinitePixels) + " bins of " + bins +
         " that hold them are left out, the figures are of the " + compared + " bins compared";
}

std::string CompareReport::blackReferenceWarning() const {
  const char* names[5] = {"R", "G", "B", "Y", "RGB"};
  const ChannelError* channels[5] = {&result.channel[0], &result.channel[1], &result.channel[2],
                                     &result.luminance, &result.rgb};
  std::string black;
  for (int c = 0; c < 5; ++c) {
    if (std::isinf(channels[c]->relRmse) || std::isinf(channels[c]->relMae)) {
      black += (black.empty() ? "" : ", ") + std::string(names[c]);
    }
  }
  if (black.empty()) return "";
  return "the reference is black (0) in " + black +
         " over the pixels compared, where the test image is not: relative errors (rel_rmse, "
         "rel_mae) are undefined there and reported as inf; max_abs measures the difference";
}

std::vector<std::string> CompareReport::warnings() const {
  std::vector<std::string> out;
  for (const std::string& w : {nonFiniteWarning(), blackReferenceWarning()}) {
    if (!w.empty()) out.push_back(w);
  }
  return out;
}

void checkStdError(const RgbImage& stdError, const std::string& what) {
  for (size_t i = 0; i < stdError.pixelCount(); ++i) {
    const Vec3 e = stdError.at(i);
    for (int c = 0; c < 3; ++c) {
      // NaN and infinities too: they read as a reference without noise
      // ("reference noise: 0", H15-4-2).
      if (e[c] >= 0 && std::isfinite(e[c])) continue;
      char text[160];
      std::snprintf(text, sizeof text,
                    "pixel (%d, %d) holds a standard error of %g in channel %c: a standard error "
                    "is a finite number, 0 or more",
                    int(i % size_t(stdError.width)), int(i / size_t(stdError.width)), double(e[c]),
                    "RGB"[c]);
      throw InputError(what + ": " + text);
    }
  }
}

CompareReport compareReport(RgbImage test, RgbImage reference, const CompareSettings& settings,
                            const RgbImage* mask, const RgbImage* stdError,
                            ProgressSink* progress) {
  Progress steps(progress, "compare", 7);
  CompareReport r;
  r.ignoreBackground = settings.ignoreBackground;
  if (mask) r.mask = *mask;
  RgbImage error;
  if (stdError) {
    if (stdError->width != reference.width || stdError->height != reference.height)
      throw InputError("compare: standard error is " + std::to_string(stdError->width) + " x " +
                       std::to_string(stdError->height) + ", images are " +
                       std::to_string(reference.width) + " x " + std::to_string(reference.height));
    checkStdError(*stdError, "compare: the reference's standard error");
    error = *stdError;
  }
  steps.advance();
  // Black holes are judged per pixel against the reference as it is.
  r.holes = darkHoles(test, reference, r.params());
  steps.advance();
  if (settings.clipPercentile < 100) {
    r.clip = channelPercentiles(reference, settings.clipPercentile, r.params());
    clipChannels(test, r.clip);
    clipChannels(reference, r.clip);
  }
  steps.advance();
  // Per pixel, as clipped and before binning, over the mask as given.
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    if (pixelUse(test, reference, r.params(), i) == PixelUse::NonFinite) ++r.nonFiniteImagePixels;
  }
  steps.advance();
  r.bin = settings.bin;
  if (settings.bin > 1) {
    test = binImage(test, settings.bin);
    reference = binImage(reference, settings.bin);
    if (mask) r.mask = binMask(r.mask, settings.bin);
    if (stdError) error = binStdError(error, settings.bin);
  }
  steps.advance();
  r.result = compareImages(test, reference, r.params());
  steps.advance();
  // Nothing compared is no score (its figures would read 0: a perfect one).
  if (r.result.comparedPixels == 0) {
    throw InputError("compare: no pixel to compare: " + std::to_string(r.result.ignoredPixels) +
                     " left out (the mask, --ignore-background), " +
                     std::to_string(r.result.nonFinitePixels) +
                     " not finite (NaN or infinite in either image)" +
                     (settings.bin > 1 ? " of the " + std::to_string(settings.bin) + " x " +
                                             std::to_string(settings.bin) + " bins"
                                       : std::string()));
  }
  if (stdError) r.referenceNoise = referenceNoise(reference, error, r.params());
  steps.advance();
  r.test = std::move(test);
  r.reference = std::move(reference);
  return r;
}

}  // namespace lo
