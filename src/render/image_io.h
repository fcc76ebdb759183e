#pragma once
/// @file render/image_io.h
/// @brief Writing rendered images: OpenEXR (linear float RGB, what the
/// renderer computed) or PNG (exposure, clamp, sRGB-encoded 8-bit).

#include <string>

#include "render/renderer.h"

namespace lo {

/// Writes `image` by the extension of `path`: .exr (32-bit float R, G, B,
/// linear radiance; `exposureEv` ignored) or .png (radiance * 2^exposureEv,
/// clamped to [0,1], sRGB transfer function, 8 bits). Written to a temporary
/// name beside `path` and renamed. @throws InputError for another extension,
/// IoError when writing fails.
void writeImage(const std::string& path, const Image& image, float exposureEv = 0.0f);

/// The 8-bit sRGB encoding PNG output uses, for one linear value.
unsigned char encodeSrgb8(float linear);

}  // namespace lo
