/// @file image/image.cpp
/// @brief OpenEXR and PNG files for image/image.h.

#include "image/image.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>

#include "core/error.h"
#include "core/file.h"
#include "core/resources.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb_image_write.h>
// The project's one copy of stb_image: scene textures decode through
// decodeImageBytes too.
#define STB_IMAGE_IMPLEMENTATION
#include <stb_image.h>

namespace lo {
namespace {

void checkImage(const std::string& path, const RgbImage& image) {
  if (image.width < 1 || image.height < 1 || image.rgb.size() != image.pixelCount() * 3)
    throw InputError(path + ": empty or inconsistent image (" + std::to_string(image.width) +
                     " x " + std::to_string(image.height) + ")");
}


RgbImage readExr(const std::string& path) {
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i& dw = file.header().dataWindow();
    // The header's size before any pixel: the image and a float frame buffer.
    try {
      checkImageSize(int64_t(dw.max.x) - dw.min.x + 1, int64_t(dw.max.y) - dw.min.y + 1, 2 * 12);
    } catch (const InputError& e) {
      throw InputError(path + ": " + e.what());
    }
    RgbImage image(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1);
    const Imf::ChannelList& channels = file.header().channels();
    const char* names[3] = {"R", "G", "B"};
    const char* first =
        channels.findChannel("R") ? "R" : (channels.findChannel("Y") ? "Y" : nullptr);
    if (!first) throw InputError(path + ": no R or Y channel");
    Imf::FrameBuffer fb;
    // Slices are addressed from the data window's origin, which may not be (0, 0).
    char* base =
        reinterpret_cast<char*>(image.rgb.data()) -
        (ptrdiff_t(dw.min.x) + ptrdiff_t(dw.min.y) * image.width) * 3 * ptrdiff_t(sizeof(float));
    size_t yStride = size_t(image.width) * 3 * sizeof(float);
    fb.insert(first, Imf::Slice(Imf::FLOAT, base, 3 * sizeof(float), yStride));
    for (int c = 1; c < 3; ++c) {
      if (channels.findChannel(names[c]))
        fb.insert(names[c],
                  Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float), yStride));
    }
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    // Single-channel files (masks): G and B copy the first channel.
    for (int c = 1; c < 3; ++c) {
      if (channels.findChannel(names[c])) continue;
      for (size_t i = 0; i < image.pixelCount(); ++i) image.rgb[3 * i + c] = image.rgb[3 * i];
    }
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read EXR (" + e.what() + ")");
  }
}

}  // namespace

float linearToSrgb(float linear) {
  float c = std::isfinite(linear) ? std::clamp(linear, 0.0f, 1.0f) : 0.0f;
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

unsigned char encodeSrgb8(float linear) {
  return static_cast<unsigned char>(std::lround(linearToSrgb(linear) * 255.0f));
}

void writeExr(const std::string& path, const RgbImage& image) {
  checkImage(path, image);
  writeAtomically(path, [&](const std::string& tmp) {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    const char* names[3] = {"R", "G", "B"};
    for (const char* name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(tmp.c_str(), header);
    Imf::FrameBuffer fb;
    char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgb.data()));
    for (int c = 0; c < 3; ++c) {
      fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float),
                                     size_t(image.width) * 3 * sizeof(float)));
    }
    file.setFrameBuffer(fb);
    file.writePixels(image.height);
  });
}

void writePng(const std::string& path, const RgbImage& image, float exposureEv) {
  checkImage(path, image);
  const std::vector<unsigned char> png = encodePng(image, exposureEv);
  writeTextAtomically(path, std::string(png.begin(), png.end()));
}

std::vector<unsigned char> encodePng8(int width, int height, int channels,
                                      const unsigned char* pixels) {
  if (width < 1 || height < 1 || channels < 1 || channels > 4 || !pixels) {
    throw InputError("encodePng8: " + std::to_string(width) + " x " + std::to_string(height) +
                     " pixels of " + std::to_string(channels) + " channel(s)");
  }
  std::vector<unsigned char> out;
  auto append = [](void* context, void* data, int size) {
    auto* bytes = static_cast<std::vector<unsigned char>*>(context);
    const auto* p = static_cast<const unsigned char*>(data);
    bytes->insert(bytes->end(), p, p + size);
  };
  if (!stbi_write_png_to_func(append, &out, width, height, channels, pixels, width * channels)) {
    throw IoError("encodePng8: stbi_write_png_to_func failed");
  }
  return out;
}

std::vector<unsigned char> encodePng(const RgbImage& image, float exposureEv) {
  checkImage("encodePng", image);
  const float scale = std::exp2(exposureEv);
  std::vector<unsigned char> rgb(image.pixelCount() * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = encodeSrgb8(image.rgb[i] * scale);
  return encodePng8(image.width, image.height, 3, rgb.data());
}

std::vector<unsigned char> encodeRgbmPng(const RgbImage& image, float range) {
  checkImage("encodeRgbmPng", image);
  if (!(std::isfinite(range) && range > 0)) {
    throw InputError("encodeRgbmPng: range " + std::to_string(range) + " must be finite and > 0");
  }
  std::vector<unsigned char> rgba(image.pixelCount() * 4);
  for (size_t i = 0; i < image.pixelCount(); ++i) {
    float c[3];
    for (int k = 0; k < 3; ++k) {
      const float v = image.rgb[3 * i + size_t(k)];
      c[k] = std::isfinite(v) ? std::clamp(v, 0.0f, range) : 0.0f;
    }
    const float m = std::max({c[0], c[1], c[2]}) / range;
    // Rounded up (at least 1, so that the division below is defined): the
    // largest channel then needs at most 255.
    const int a = std::clamp(int(std::ceil(double(m) * 255.0)), 1, 255);
    const double scale = 255.0 / (double(a) / 255.0 * double(range));
    for (int k = 0; k < 3; ++k) {
      rgba[4 * i + size_t(k)] = (unsigned char)std::min(255L, std::lround(double(c[k]) * scale));
    }
    rgba[4 * i + 3] = (unsigned char)a;
  }
  return encodePng8(image.width, image.height, 4, rgba.data());
}

RgbImage decodeRgbm(const DecodedImage& image, float range) {
  if (image.channels != 4 || image.width < 1 || image.height < 1 ||
      image.values.size() != size_t(image.width) * size_t(image.height) * 4) {
    throw InputError("decodeRgbm: RGBM needs an RGBA image, got " +
                     std::to_string(image.channels) + " channel(s)");
  }
  if (!(std::isfinite(range) && range > 0)) {
    throw InputError("decodeRgbm: range " + std::to_string(range) + " must be finite and > 0");
  }
  RgbImage out(image.width, image.height);
  for (size_t i = 0; i < out.pixelCount(); ++i) {
    const float m = image.values[4 * i + 3] * range;
    for (int k = 0; k < 3; ++k) out.rgb[3 * i + size_t(k)] = image.values[4 * i + size_t(k)] * m;
  }
  return out;
}

void writeImage(const std::string& path, const RgbImage& image, float exposureEv) {
  const std::string ext = lowerExtension(path);
  if (ext == ".exr") return writeExr(path, image);
  if (ext == ".png") return writePng(path, image, exposureEv);
  throw InputError(path + ": unsupported image extension '" + ext + "' (expected .exr or .png)");
}

RgbImage readImage(const std::string& path, bool linear8Bit) {
  requireRegularFile(path, "the image");
  std::string ext = lowerExtension(path);
  if (ext != ".exr") {
    // The header's size before decoding (stb's buffer and the image's floats).
    int w = 0, h = 0, n = 0;
    if (stbi_info(path.c_str(), &w, &h, &n)) {
      try {
        checkImageSize(w, h, 4 * 4 + 12);
      } catch (const InputError& e) {
        throw InputError(path + ": " + e.what());
      }
    }
  }
  if (ext == ".exr") return readExr(path);
  if (ext == ".hdr") {
    // Radiance RGBE: linear floats (stb applies no transfer curve to them).
    int w = 0, h = 0, n = 0;
    float* data = stbi_loadf(path.c_str(), &w, &h, &n, 3);
    if (!data) throw InputError(path + ": cannot read image (" + stbi_failure_reason() + ")");
    RgbImage image(w, h);
    std::copy(data, data + image.rgb.size(), image.rgb.begin());
    stbi_image_free(data);
    return image;
  }
  if (ext != ".png" && ext != ".jpg" && ext != ".jpeg")
    throw InputError(path + ": unsupported image extension '" + ext +
                     "' (expected .exr, .hdr, .png or .jpg)");
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(path.c_str(), &w, &h, &n, 3);
  if (!data) throw InputError(path + ": cannot read image (" + stbi_failure_reason() + ")");
  RgbImage image(w, h);
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    float v = float(data[i]) / 255.0f;
    image.rgb[i] = linear8Bit ? v : srgbToLinear(v);
  }
  stbi_image_free(data);
  return image;
}

float srgbToLinear(float s) {
  return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
}

void checkImageSize(int64_t width, int64_t height, double bytesPerPixel) {
  const std::string size = std::to_string(width) + " x " + std::to_string(height);
  if (width < 1 || height < 1 || width > kMaxImageSide || height > kMaxImageSide) {
    throw InputError("image of " + size + " pixels: its sides must lie from 1 to " +
                     std::to_string(kMaxImageSide));
  }
  const double needed = double(width) * double(height) * bytesPerPixel;
  const size_t available = availableMemoryBytes();
  if (available > 0 && needed > 0.5 * double(available)) {
    throw InputError("image of " + size + " pixels would take " + formatBytes(size_t(needed)) +
                     " to read, more than half the " + formatBytes(available) +
                     " of memory available");
  }
}

DecodedImage decodeImageBytes(const unsigned char* bytes, size_t size) {
  if (size == 0 || size > size_t(std::numeric_limits<int>::max())) {
    throw InputError("empty or too large");
  }
  const int n = int(size);
  int w = 0, h = 0, comp = 0;
  // The header's size first: stb, its floats and the caller's texture
  // (16 bytes per texel) per pixel, at most 4 channels of 16 bits.
  if (stbi_info_from_memory(bytes, n, &w, &h, &comp)) checkImageSize(w, h, 4 * (2 + 4) + 16);
  DecodedImage out;
  auto finish = [&](auto* data, float scale) {
    out.width = w;
    out.height = h;
    out.channels = comp;
    out.values.resize(size_t(w) * size_t(h) * size_t(comp));
    for (size_t i = 0; i < out.values.size(); ++i) out.values[i] = float(data[i]) * scale;
    stbi_image_free(data);
  };
  if (stbi_is_16_bit_from_memory(bytes, n)) {
    stbi_us* data = stbi_load_16_from_memory(bytes, n, &w, &h, &comp, 0);
    if (data && w > 0 && h > 0 && comp >= 1 && comp <= 4) {
      finish(data, 1.0f / 65535.0f);
      return out;
    }
    if (data) stbi_image_free(data);
  }
  stbi_uc* data = stbi_load_from_memory(bytes, n, &w, &h, &comp, 0);
  if (!data || w <= 0 || h <= 0 || comp < 1 || comp > 4) {
    if (data) stbi_image_free(data);
    const char* reason = stbi_failure_reason();
    throw InputError(reason ? reason : "cannot decode");
  }
  finish(data, 1.0f / 255.0f);
  return out;
}

}  // namespace lo
