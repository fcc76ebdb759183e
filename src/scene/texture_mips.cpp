// mipLevels: a texture's mip chain on the CPU (scene/texture_mips.h), rows in
// parallel.

#include "scene/texture_mips.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace lo {
namespace {

/// sRGB code -> linear value (IEC 61966-2-1), and the midpoints between
/// consecutive codes' values, which encoding searches.
struct SrgbTables {
  std::array<float, 256> linear;
  std::array<float, 255> midpoints;
  SrgbTables() {
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      linear[size_t(i)] =
          float(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    for (size_t i = 0; i < 255; ++i) midpoints[i] = 0.5f * (linear[i] + linear[i + 1]);
  }
  /// The code whose linear value lies nearest v.
  uint8_t encode(float v) const {
    return uint8_t(std::upper_bound(midpoints.begin(), midpoints.end(), v) - midpoints.begin());
  }
};

const SrgbTables& srgbTables() {
  static const SrgbTables tables;
  return tables;
}

/// The level below the `width` x `height` image `above`: each texel from the
/// 2 x 2 texels above it, `mean(four values, channel)` per channel.
template <class T, class Mean>
MipLevel<T> halve(const T* above, int width, int height, int channels, const Mean& mean) {
  MipLevel<T> level;
  level.width = std::max(1, width / 2);
  level.height = std::max(1, height / 2);
  level.texels.resize(size_t(level.width) * size_t(level.height) * size_t(channels));
  const size_t c = size_t(channels), w = size_t(width);
  tbb::parallel_for(tbb::blocked_range<int>(0, level.height, 16),
                    [&](const tbb::blocked_range<int>& rows) {
                      for (int y = rows.begin(); y != rows.end(); ++y) {
                        const size_t y0 = size_t(std::min(2 * y, height - 1));
                        const size_t y1 = size_t(std::min(2 * y + 1, height - 1));
                        for (int x = 0; x < level.width; ++x) {
                          const size_t x0 = size_t(std::min(2 * x, width - 1));
                          const size_t x1 = size_t(std::min(2 * x + 1, width - 1));
                          const T* t[4] = {above + (y0 * w + x0) * c, above + (y0 * w + x1) * c,
                                           above + (y1 * w + x0) * c, above + (y1 * w + x1) * c};
                          T* out = &level.texels[(size_t(y) * size_t(level.width) + size_t(x)) * c];
                          for (size_t k = 0; k < c; ++k) {
                            out[k] = mean(t[0][k], t[1][k], t[2][k], t[3][k], int(k));
                          }
                        }
                      }
                    });
  return level;
}

/// Levels 1, 2, ... of `base`, each halved from the one above (the base
/// itself read in place).
template <class T, class Mean>
std::vector<MipLevel<T>> chain(const T* base, int width, int height, int channels,
                               const Mean& mean) {
  std::vector<MipLevel<T>> levels;
  if (width < 1 || height < 1 || channels < 1) return levels;
  while (width > 1 || height > 1) {
    const T* above = levels.empty() ? base : levels.back().texels.data();
    levels.push_back(halve(above, width, height, channels, mean));
    width = levels.back().width;
    height = levels.back().height;
  }
  return levels;
}

}  // namespace

std::vector<MipLevel<uint8_t>> mipLevels(const uint8_t* base, int width, int height, int channels,
                                         bool srgb) {
  const SrgbTables& tables = srgbTables();
  const int srgbChannels = srgb ? std::min(channels, 3) : 0;
  return chain(base, width, height, channels,
               [&](uint8_t a, uint8_t b, uint8_t c, uint8_t d, int k) -> uint8_t {
                 if (k < srgbChannels) {
                   const std::array<float, 256>& l = tables.linear;
                   return tables.encode(0.25f * ((l[a] + l[b]) + (l[c] + l[d])));
                 }
                 return uint8_t((unsigned(a) + b + c + d + 2) / 4);
               });
}

std::vector<MipLevel<float>> mipLevels(const float* base, int width, int height, int channels) {
  return chain(base, width, height, channels, [](float a, float b, float c, float d, int) {
    return 0.25f * ((a + b) + (c + d));
  });
}

}  // namespace lo
