#pragma once
/// @file image/image.h
/// @brief Linear RGB float images and their files: OpenEXR (read/write, FLOAT
/// or HALF channels R, G, B read, FLOAT written) and PNG (8-bit sRGB write;
/// read for masks). OpenEXR and stb_image(_write) stay in src/image, which
/// both the GL renderer and the reference renderer write through, so that
/// neither links the other's libraries (the reference renderer and `compare`
/// run where no OpenGL exists).

#include <array>
#include <string>
#include <vector>

#include "core/math.h"

namespace lo {

class AtomicFileSet;  // core/file_set.h

/// Linear RGB, row-major, row 0 at the top: the one image type of the
/// project (GL frames, path-traced references, masks, differences).
struct RgbImage {
  int width = 0, height = 0;
  std::vector<float> rgb;  ///< width * height * 3

  RgbImage() = default;
  RgbImage(int w, int h) : width(w), height(h), rgb(size_t(w) * size_t(h) * 3, 0.0f) {}
  size_t pixelCount() const { return size_t(width) * size_t(height); }
  Vec3 at(size_t i) const { return {rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2]}; }
  /// The 3 floats of pixel (x, y), x to the right, y down.
  const float* pixel(int x, int y) const { return rgb.data() + (size_t(y) * width + x) * 3; }
  void set(size_t i, const Vec3& v) {
    rgb[3 * i] = v.x;
    rgb[3 * i + 1] = v.y;
    rgb[3 * i + 2] = v.z;
  }
};

/// Mean Rec. 709 luminance (core/math.h's luminance) of a linear image's
/// pixels, summed in double; 0 for an empty image.
double meanLuminance(const RgbImage& image);

/// An image file held in memory (PNG, JPEG, BMP, TGA, GIF, HDR, PNM, PSD:
/// stb_image), channel values scaled to [0, 1] (8-bit / 255, 16-bit / 65535;
/// Radiance HDR as stored), no colour conversion.
struct DecodedImage {
  int width = 0, height = 0;
  int channels = 0;           ///< 1..4
  std::vector<float> values;  ///< width * height * channels, row 0 at the top
};
/// @throws InputError with the decoder's reason (the caller names the file),
/// or, before any decoding, when the header's size breaks checkImageSize.
DecodedImage decodeImageBytes(const unsigned char* bytes, size_t size);

/// An image file's pixels as the file stores them: 8 or 16 bits per channel
/// (what a texture keeps: a fourth of floats' memory or less).
struct StoredImage {
  int width = 0, height = 0;
  int channels = 0;                ///< 1..4
  std::vector<uint8_t> unorm8;     ///< 8-bit files: width * height * channels
  std::vector<uint16_t> unorm16;   ///< 16-bit files (PNG): the same, 16 bits each
  std::string mimeType;            ///< "image/png", "image/jpeg", or "" for other formats
};
/// @brief decodeImageBytes without the conversion to floats.
/// @throws as decodeImageBytes.
StoredImage decodeStoredImage(const unsigned char* bytes, size_t size);
/// The bytes decodeStoredImage keeps of the image `bytes` hold (width x
/// height x channels x 1 or 2 bytes), read from its header without decoding;
/// 0 when the header names no image (decoding then says why).
size_t storedImageBytes(const unsigned char* bytes, size_t size);

/// Largest width or height of an image any stage reads (the largest 2D
/// texture GL contexts give, 16384).
constexpr int kMaxImageSide = 16384;
/// Refuses an image whose header says `width` x `height` before it is
/// decoded: a side above kMaxImageSide, or `bytesPerPixel` (what the reader
/// and its caller keep per pixel) x the pixels above half the memory
/// available. A few hundred bytes of JPEG can claim gigabytes.
/// @throws InputError "image of W x H ... " (the caller names the file).
void checkImageSize(int64_t width, int64_t height, double bytesPerPixel);

/// sRGB transfer function (IEC 61966-2-1) to linear, for one channel in [0, 1].
float srgbToLinear(float s);
/// srgbToLinear of the 256 values of an 8-bit channel (v / 255), computed once.
const std::array<float, 256>& srgb8ToLinear();
/// Its inverse: linear (clamped to [0, 1]; not finite: 0) to sRGB, in [0, 1].
float linearToSrgb(float linear);

/// Writes 32-bit float channels R, G, B (ZIP, lossless) to
/// `path` through `path.tmp` and a rename. @throws IoError naming the file.
void writeExr(const std::string& path, const RgbImage& image, AtomicFileSet* into = nullptr);
/// Writes radiance * 2^exposureEv, clamped, sRGB-encoded, 8-bit RGB.
void writePng(const std::string& path, const RgbImage& image, float exposureEv = 0.0f,
              AtomicFileSet* into = nullptr);
/// Reads an EXR's R, G, B channels (missing G/B copy R: single-channel masks
/// written as Y or R work too), a Radiance .hdr (linear) or a PNG/JPEG
/// (8-bit, sRGB decoded to linear unless `linear8Bit`, in which case v/255).
/// Dispatch by extension.
/// @throws InputError naming the file for an unknown extension or a failed read.
RgbImage readImage(const std::string& path, bool linear8Bit = false);
/// Dispatch by extension: .exr (linear, `exposureEv` ignored) or .png. The
/// writers take `into`: the file joins that set of outputs (core/file_set.h,
/// renamed with the others by its commit) instead of being renamed at once.
/// @throws InputError naming the file for another extension.
void writeImage(const std::string& path, const RgbImage& image, float exposureEv = 0.0f,
                AtomicFileSet* into = nullptr);

/// The 8-bit sRGB encoding PNG output uses, for one linear value (clamped;
/// NaN and Inf encode as 0).
unsigned char encodeSrgb8(float linear);

/// @brief A PNG file in memory (stb_image_write, zlib, no colour chunk):
/// `pixels` holds width * height * channels bytes (1..4 channels), row 0 at
/// the top. @throws InputError for a bad size or channel count.
std::vector<unsigned char> encodePng8(int width, int height, int channels,
                                      const unsigned char* pixels);
/// @brief The bytes writePng writes: radiance * 2^exposureEv, clamped,
/// sRGB-encoded (encodeSrgb8), 8-bit RGB.
std::vector<unsigned char> encodePng(const RgbImage& image, float exposureEv = 0.0f);

/// @brief RGBM: linear RGB in [0, range] in an 8-bit RGBA PNG, for HDR data
/// that must travel as PNG (lightmaps for viewers without EXR). Per pixel,
/// with c = RGB clamped to [0, range] (NaN as 0):
///   A = max(1, ceil(255 * max(c) / range)),  M = A / 255,
///   RGB = round(255 * c / (M * range)),
/// decoded as c' = (RGB / 255) * (A / 255) * range (decodeRgbm). No sRGB curve
/// on any channel: the PNG holds data, not a picture. A is rounded up, so the
/// channel never exceeds 255, and |c' - c| <= 0.5 / 255 * M * range
/// <= (0.5 / 255) * (max(c) + range / 255) per channel. The PNG says what it
/// holds: a gAMA chunk of 1.0 (linear data) and tEXt chunks
/// "lightoctree:encoding" and "lightoctree:rgbmRange" (the range, as text).
/// @throws InputError for an empty image or a range that is not finite and > 0.
std::vector<unsigned char> encodeRgbmPng(const RgbImage& image, float range);
/// @brief The inverse of encodeRgbmPng for a decoded RGBA image
/// (decodeImageBytes: channels scaled to [0, 1]). @throws InputError unless
/// the image has 4 channels and range is finite and > 0.
RgbImage decodeRgbm(const DecodedImage& image, float range);

/// @brief Unit vectors (a directional lightmap's directions) in an 8-bit RGB
/// PNG, each component c in [-1, 1] as round(127 * c) + 128 (NaN as 0), so
/// that 128 is exactly 0 (a texel without a direction: (128, 128, 128)) and
/// decodeUnitVectors gives c' = (byte - 128) / 127, |c' - c| <= 0.5 / 127.
/// Like encodeRgbmPng's, the PNG is marked as data: gAMA 1.0 and a tEXt
/// chunk "lightoctree:encoding". @throws InputError for an empty image.
std::vector<unsigned char> encodeUnitVectorPng(const RgbImage& vectors);
/// @brief The inverse of encodeUnitVectorPng for a decoded RGB or RGBA image
/// (decodeImageBytes: channels scaled to [0, 1]). @throws InputError for
/// fewer than 3 channels.
RgbImage decodeUnitVectors(const DecodedImage& image);

}  // namespace lo
