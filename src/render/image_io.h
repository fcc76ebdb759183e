#pragma once
/// @file render/image_io.h
/// @brief Rendered frames as files: OpenEXR (linear float RGB, what the
/// renderer computed) or PNG (exposure, clamp, sRGB-encoded 8-bit). The file
/// formats themselves live in src/image.

#include <string>

#include "image/image.h"
#include "render/renderer.h"

namespace lo {

/// The RGB channels of a rendered RGBA frame.
RgbImage toRgbImage(const Image& image);

/// Writes `image` by the extension of `path` (image/image.h writeImage):
/// .exr (32-bit float R, G, B, linear radiance; `exposureEv` ignored) or .png
/// (radiance * 2^exposureEv, clamped to [0,1], sRGB, 8 bits). Written to a
/// temporary name beside `path` and renamed. @throws InputError for another
/// extension or an empty image, IoError when writing fails.
void writeImage(const std::string& path, const Image& image, float exposureEv = 0.0f);

}  // namespace lo
