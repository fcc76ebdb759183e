#pragma once
/// @file scene/texture_mips.h
/// @brief The mip levels of a texture below its base level, built on the CPU
/// in parallel: the renderer uploads them (render/scene_geometry.cpp) where a
/// software rasteriser's glGenerateMipmap drew each level on one thread (0.32
/// s of the shared lamp's first frame for its five 2048² textures).

#include <cstdint>
#include <vector>

namespace lo {

/// One level: width x height texels of `channels` interleaved values each.
template <class T>
struct MipLevel {
  int width = 0, height = 0;
  std::vector<T> texels;
};

/// Levels 1, 2, ... down to 1 x 1 of the 8-bit image `base` (width x height
/// x channels), each side max(1, floor(side / 2)) of the one above, as GL
/// sizes them. A texel is the mean of the 2 x 2 above it (a side of odd
/// length leaves its last row or column out; a side of 1 repeats it),
/// rounded to the nearest code; with `srgb` the first three channels (or
/// all of a 3-channel image) are averaged as linear light and encoded
/// back, as GL filters an sRGB texture, and a fourth (alpha) as it is.
/// Deterministic whatever the thread count.
std::vector<MipLevel<uint8_t>> mipLevels(const uint8_t* base, int width, int height, int channels,
                                         bool srgb);

/// The same of a float image (linear values, plain means).
std::vector<MipLevel<float>> mipLevels(const float* base, int width, int height, int channels);

}  // namespace lo
