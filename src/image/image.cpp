/// @file image/image.cpp
/// @brief OpenEXR and PNG files for image/image.h.

#include "image/image.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/resources.h"

// stb's implementation is compiled once, in stb_image_impl.cpp.
#include <stb_image.h>
#include <stb_image_write.h>

namespace lo {
namespace {

void checkImage(const std::string& path, const RgbImage& image) {
  if (image.width < 1 || image.height < 1 || image.rgb.size() != image.pixelCount() * 3)
    throw InputError(path + ": empty or inconsistent image (" + std::to_string(image.width) +
                     " x " + std::to_string(image.height) + ")");
}


/// The largest ratio of raw pixel bytes to stored bytes an EXR compression
/// reaches, 0 where none is bounded (the DCT of DWAA/DWAB under zlib).
double largestExrRatio(Imf::Compression c) {
  switch (c) {
    case Imf::NO_COMPRESSION: return 1;
    case Imf::RLE_COMPRESSION: return 64;  // a run of up to 128 bytes in 2
    case Imf::ZIPS_COMPRESSION:
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION: return 1032;  // deflate
    case Imf::PIZ_COMPRESSION: return 1024;    // Huffman codes with runs of up to 255 values
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION: return 11;  // a flat 4 x 4 block of halves in 3 bytes
    default: return 0;
  }
}

/// Refuses an EXR whose file is too small for the pixels its header claims
/// under its compression's largest ratio (OpenEXR fills what a chunk lacks
/// without a word: an 8 KB file claiming 16000 x 16000 cost 3 GB).
void checkExrHoldsItsPixels(const std::string& path, const Imf::Header& header, int64_t width,
                            int64_t height) {
  const double ratio = largestExrRatio(header.compression());
  if (ratio <= 0) return;
  double bytesPerPixel = 0;
  for (auto c = header.channels().begin(); c != header.channels().end(); ++c) {
    const double size = c.channel().type == Imf::HALF ? 2.0 : 4.0;
    const double samples = double(std::max(1, c.channel().xSampling)) * std::max(1, c.channel().ySampling);
    bytesPerPixel += size / samples;
  }
  const double least = double(width) * double(height) * bytesPerPixel / ratio;
  std::error_code ec;
  const double held = double(std::filesystem::file_size(path, ec));
  if (!ec && held < least) {
    throw InputError(path + ": a " + std::to_string(width) + " x " + std::to_string(height) +
                     " EXR of " + std::to_string(int(bytesPerPixel)) +
                     " bytes per pixel compressed at most " + std::to_string(int(ratio)) +
                     ":1 needs at least " + formatBytes(size_t(least)) + "; the file holds " +
                     formatBytes(size_t(held)) + ": truncated, or a header that lies");
  }
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
    const int width = dw.max.x - dw.min.x + 1, height = dw.max.y - dw.min.y + 1;
    checkExrHoldsItsPixels(path, file.header(), width, height);
    const Imf::ChannelList& channels = file.header().channels();
    const char* names[3] = {"R", "G", "B"};
    const char* first =
        channels.findChannel("R") ? "R" : (channels.findChannel("Y") ? "Y" : nullptr);
    if (!first) throw InputError(path + ": no R or Y channel");
    // Read in bands of rows, the image growing by what each band decoded: a
    // file that ends before its last chunk fails at the first missing band,
    // having allocated only what it held.
    constexpr int kBandRows = 64;
    std::vector<float> band;
    RgbImage image;
    image.width = width;
    image.height = height;
    const size_t rowFloats = size_t(width) * 3;
    for (int y0 = dw.min.y; y0 <= dw.max.y; y0 += kBandRows) {
      const int y1 = std::min(dw.max.y, y0 + kBandRows - 1);
      band.assign(rowFloats * size_t(y1 - y0 + 1), 0.0f);
      // Slices are addressed from the data window's origin (x) and this
      // band's first row (y).
      char* base = reinterpret_cast<char*>(band.data()) -
                   (ptrdiff_t(dw.min.x) + ptrdiff_t(y0) * width) * 3 * ptrdiff_t(sizeof(float));
      const size_t yStride = rowFloats * sizeof(float);
      Imf::FrameBuffer fb;
      fb.insert(first, Imf::Slice(Imf::FLOAT, base, 3 * sizeof(float), yStride));
      for (int c = 1; c < 3; ++c) {
        if (channels.findChannel(names[c])) {
          fb.insert(names[c],
                    Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 3 * sizeof(float), yStride));
        }
      }
      file.setFrameBuffer(fb);
      file.readPixels(y0, y1);
      image.rgb.insert(image.rgb.end(), band.begin(), band.end());
    }
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

double meanLuminance(const RgbImage& image) {
  double sum = 0;
  for (size_t i = 0; i < image.pixelCount(); ++i) sum += double(luminance(image.at(i)));
  return image.pixelCount() ? sum / double(image.pixelCount()) : 0.0;
}

float linearToSrgb(float linear) {
  float c = std::isfinite(linear) ? std::clamp(linear, 0.0f, 1.0f) : 0.0f;
  return c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
}

unsigned char encodeSrgb8(float linear) {
  return static_cast<unsigned char>(std::lround(linearToSrgb(linear) * 255.0f));
}

void writeExr(const std::string& path, const RgbImage& image, AtomicFileSet* into) {
  checkImage(path, image);
  const auto write = [&](const std::string& tmp) {
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
  };
  writeOutput(into, path, write);
}

void writePng(const std::string& path, const RgbImage& image, float exposureEv,
              AtomicFileSet* into) {
  checkImage(path, image);
  const std::vector<unsigned char> png = encodePng(image, exposureEv);
  writeOutputText(into, path, std::string(png.begin(), png.end()));
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

namespace {

uint32_t crc32(const unsigned char* bytes, size_t size, uint32_t crc = 0) {
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) {
    crc ^= bytes[i];
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

/// A PNG chunk: length, type, data, CRC of type and data (big-endian).
std::string pngChunk(const char type[4], const std::string& data) {
  std::string chunk;
  auto be32 = [&chunk](uint32_t v) {
    for (int shift = 24; shift >= 0; shift -= 8) chunk.push_back(char((v >> shift) & 0xff));
  };
  be32(uint32_t(data.size()));
  const std::string body = std::string(type, 4) + data;
  chunk += body;
  be32(crc32(reinterpret_cast<const unsigned char*>(body.data()), body.size()));
  return chunk;
}

/// `png` (encodePng8's) marked as data after IHDR (8 + 25 bytes): gAMA 1.0
/// (linear values, no sRGB curve to undo) and text chunks naming the
/// encoding (and what `moreChunks` adds), so the file says how to read it
/// without the glTF beside it.
std::vector<unsigned char> dataPng(std::vector<unsigned char> png, const std::string& encoding,
                                   const std::string& moreChunks = "") {
  const std::string gamma{'\0', '\x01', '\x86', '\xa0'};  // 100000: gamma 1.0
  const std::string chunks =
      pngChunk("gAMA", gamma) + pngChunk("tEXt", std::string("Software") + '\0' + "lightoctree") +
      pngChunk("tEXt", std::string("lightoctree:encoding") + '\0' + encoding) + moreChunks;
  png.insert(png.begin() + 33, chunks.begin(), chunks.end());
  return png;
}

}  // namespace

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
  char rangeText[32];
  std::snprintf(rangeText, sizeof rangeText, "%.9g", double(range));
  return dataPng(encodePng8(image.width, image.height, 4, rgba.data()),
                 "rgbm: E = RGB/255 * A/255 * rgbmRange, W/m^2; not a colour image",
                 pngChunk("tEXt", std::string("lightoctree:rgbmRange") + '\0' + rangeText));
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

std::vector<unsigned char> encodeUnitVectorPng(const RgbImage& vectors) {
  checkImage("encodeUnitVectorPng", vectors);
  std::vector<unsigned char> rgb(vectors.rgb.size());
  for (size_t i = 0; i < rgb.size(); ++i) {
    const float c = vectors.rgb[i];
    rgb[i] = (unsigned char)(128 + (std::isfinite(c) ? std::lround(127.0f * std::clamp(c, -1.0f, 1.0f)) : 0));
  }
  return dataPng(encodePng8(vectors.width, vectors.height, 3, rgb.data()),
                 "unit vectors: c = (byte - 128) / 127 per channel, (128, 128, 128) = none; "
                 "not a colour image");
}

RgbImage decodeUnitVectors(const DecodedImage& image) {
  if (image.channels < 3 || image.width < 1 || image.height < 1 ||
      image.values.size() != size_t(image.width) * size_t(image.height) * size_t(image.channels)) {
    throw InputError("decodeUnitVectors: needs an RGB image, got " +
                     std::to_string(image.channels) + " channel(s)");
  }
  RgbImage out(image.width, image.height);
  const size_t n = size_t(image.channels);
  for (size_t i = 0; i < out.pixelCount(); ++i) {
    for (size_t k = 0; k < 3; ++k) {
      out.rgb[3 * i + k] = (std::round(image.values[n * i + k] * 255.0f) - 128.0f) / 127.0f;
    }
  }
  return out;
}

void writeImage(const std::string& path, const RgbImage& image, float exposureEv,
                AtomicFileSet* into) {
  const std::string ext = lowerExtension(path);
  if (ext == ".exr") return writeExr(path, image, into);
  if (ext == ".png") return writePng(path, image, exposureEv, into);
  throw InputError(path + ": unsupported image extension '" + ext + "' (expected .exr or .png)");
}

namespace {

/// Where a JPEG's segments start (after SOI, which stb, like the standard's
/// decoders, finds after any number of 0xff fill bytes); 0 when `bytes` is
/// not a JPEG.
size_t jpegBody(const unsigned char* bytes, size_t size) {
  size_t at = 0;
  while (at < size && bytes[at] == 0xff) ++at;
  return at >= 1 && at < size && bytes[at] == 0xd8 ? at + 1 : 0;
}

/// How many of the `height` rows of `width` pixels a Radiance HDR's bytes
/// hold, walked as stb_image decodes them: after the header (lines up to an
/// empty one) and the resolution line, flat RGBE below 8 or from 32768
/// pixels wide, else run-length scanlines (2, 2, width; then each of the
/// four streams as runs of one byte and dumps of literal bytes), which turn
/// flat for the whole image where a scanline does not start so. stb reads
/// on past the end, repeating the last pixel, so a cut file came back whole.
int64_t radianceRowsHeld(const unsigned char* bytes, size_t size, int64_t width, int64_t height) {
  size_t at = 0;
  for (bool blank = false, resolution = false; !resolution;) {
    const void* end = std::memchr(bytes + at, '\n', size - at);
    if (!end) return 0;
    const size_t next = size_t(static_cast<const unsigned char*>(end) - bytes) + 1;
    resolution = blank;
    blank = blank || next == at + 1;
    at = next;
  }
  const size_t rowBytes = size_t(width) * 4;
  auto flatRows = [&] { return std::min(height, int64_t((size - at) / rowBytes)); };
  if (width < 8 || width >= 32768) return flatRows();
  for (int64_t row = 0; row < height; ++row) {
    if (size - at < 4) return row;
    if (bytes[at] != 2 || bytes[at + 1] != 2 || (bytes[at + 2] & 0x80)) return flatRows();
    at += 4;
    for (int stream = 0; stream < 4; ++stream) {
      for (int64_t x = 0; x < width;) {
        if (at >= size) return row;
        const unsigned count = bytes[at++];
        x += count > 128 ? count - 128 : count;
        at += count > 128 ? 1 : count;
        if (at > size) return row;
      }
    }
  }
  return height;
}

/// Refuses an encoded image whose bytes cannot hold the pixels its header
/// claims, before it is decoded: a PNG below its raw size / 1032 (deflate's
/// largest ratio, at one bit per pixel), a JPEG below pixels / 4096 bytes, a
/// Radiance HDR that ends before its last row. Other formats pass.
void checkImageHoldsItsPixels(const unsigned char* bytes, size_t size, int64_t width,
                              int64_t height) {
  auto starts = [&](const char* magic, size_t n) {
    return size >= n && std::memcmp(bytes, magic, n) == 0;
  };
  const double pixels = double(width) * double(height);
  double least = 0;
  const char* why = "";
  if (starts("\x89PNG\r\n\x1a\n", 8)) {
    // One bit per pixel at the least (1-bit grey) and a filter byte per row,
    // through deflate, which compresses at most 1032:1.
    least = (double(height) * (1.0 + std::ceil(double(width) / 8.0))) / 1032.0;
    why = "PNG (deflate compresses at most 1032:1)";
  } else if (jpegBody(bytes, size) != 0) {
    // At least one bit per 8 x 8 block of the first component's DC scan
    // (pixels / 512 bytes); eight times below that to be safe.
    least = pixels / 4096.0;
    why = "JPEG (at least a bit per 8 x 8 block)";
  } else if (starts("#?", 2)) {
    const int64_t rows = radianceRowsHeld(bytes, size, width, height);
    if (rows < height) {
      throw InputError("a " + std::to_string(width) + " x " + std::to_string(height) +
                       " Radiance HDR ends after " + std::to_string(rows) + " of the " +
                       std::to_string(height) +
                       " rows its header promises: truncated or damaged");
    }
  }
  if (double(size) < least) {
    throw InputError("a " + std::to_string(width) + " x " + std::to_string(height) + " " + why +
                     " needs at least " + formatBytes(size_t(least)) + "; the file holds " +
                     formatBytes(size) + ": truncated, or a header that lies");
  }
}

/// The Huffman tables of a JPEG (every DHT segment, before and between the
/// scans) hold at most 256 codes each. stb_image as Debian 12 ships it
/// writes past its 257-entry tables when the 16 counts sum to more (a
/// finding of the image fuzz target; upstream stb issues 1289 and 1291), so
/// the segments are checked before stb sees the bytes. @throws InputError.
void checkJpegHuffmanTables(const unsigned char* bytes, size_t size, size_t at) {
  auto bad = [](const std::string& what) {
    throw InputError("not a valid JPEG: " + what);
  };
  while (at + 1 < size) {
    if (bytes[at] != 0xff) {
      // Entropy-coded data of a scan: the next marker is 0xff followed by
      // neither 0x00 (a stuffed byte) nor a restart marker.
      while (at + 1 < size &&
             !(bytes[at] == 0xff && bytes[at + 1] != 0x00 && bytes[at + 1] != 0xff &&
               (bytes[at + 1] < 0xd0 || bytes[at + 1] > 0xd7))) {
        ++at;
      }
      continue;
    }
    const unsigned marker = bytes[at + 1];
    if (marker == 0xff) {  // fill byte
      ++at;
      continue;
    }
    at += 2;
    if (marker == 0xd9) return;                                         // EOI
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd7)) continue;  // no length
    if (at + 2 > size) return;  // truncated: the decoder says so
    const size_t length = size_t(bytes[at]) << 8 | bytes[at + 1];
    if (length < 2) bad("a segment of length " + std::to_string(length));
    const size_t end = std::min(size, at + length);
    if (marker == 0xc4) {
      for (size_t p = at + 2; p < end;) {
        if (p + 17 > end) bad("a Huffman table cut short");
        size_t codes = 0;
        for (size_t i = 1; i <= 16; ++i) codes += bytes[p + i];
        if (codes > 256) bad("a Huffman table of " + std::to_string(codes) + " codes (at most 256)");
        p += 17 + codes;
      }
    }
    at += length;
  }
}

/// checkImageSize and checkImageHoldsItsPixels on what stb's header reader
/// finds (nothing when it finds no image: the decoder then says why).
void checkEncodedImage(const unsigned char* bytes, size_t size, double bytesPerPixel) {
  if (const size_t body = jpegBody(bytes, size)) checkJpegHuffmanTables(bytes, size, body);
  int w = 0, h = 0, comp = 0;
  if (size > size_t(std::numeric_limits<int>::max()) ||
      !stbi_info_from_memory(bytes, int(size), &w, &h, &comp)) {
    return;  // the decoder says why
  }
  checkImageSize(w, h, bytesPerPixel);
  checkImageHoldsItsPixels(bytes, size, w, h);
}

/// The format an image file's first bytes name: "EXR", "Radiance HDR",
/// "PNG", "JPEG", or "" for none of them.
std::string imageFormatOf(const std::string& head) {
  auto starts = [&](const char* magic) { return head.rfind(magic, 0) == 0; };
  if (starts("\x76\x2f\x31\x01")) return "EXR";
  if (starts("#?RADIANCE\n") || starts("#?RGBE\n")) return "Radiance HDR";
  if (starts("\x89PNG\r\n\x1a\n")) return "PNG";
  if (jpegBody(reinterpret_cast<const unsigned char*>(head.data()), head.size()) != 0) return "JPEG";
  return "";
}

/// Refuses a file whose first bytes are not the format its extension names
/// (an EXR or an HDR that is none; a PNG, JPEG, EXR or HDR under another's
/// name): stb decodes any format it knows, so a PNG named .hdr was read as
/// linear radiance.
void checkFormatOfExtension(const std::string& path, const std::string& ext,
                            const std::string& head) {
  const std::string named = ext == ".exr"   ? "EXR"
                            : ext == ".hdr" ? "Radiance HDR"
                            : ext == ".png" ? "PNG"
                                            : "JPEG";
  const std::string found = imageFormatOf(head);
  if (found == named || (found.empty() && ext != ".exr" && ext != ".hdr")) return;
  throw InputError(path + ": named " + ext + " but " +
                   (found.empty() ? "its first bytes are not those of " + named
                                  : "it holds a " + found + " image, not " + named) +
                   ": damaged, or renamed (give the file under its own format's extension)");
}

/// The first `n` bytes of the file at `path` (fewer when it is shorter).
std::string fileHead(const std::string& path, size_t n) {
  std::string head(n, '\0');
  std::ifstream in(path, std::ios::binary);
  in.read(head.data(), std::streamsize(n));
  head.resize(size_t(std::max<std::streamsize>(in.gcount(), 0)));
  return head;
}

}  // namespace

RgbImage readImage(const std::string& path, bool linear8Bit) {
  requireRegularFile(path, "the image");
  const std::string ext = lowerExtension(path);
  if (ext == ".exr") {
    checkFormatOfExtension(path, ext, fileHead(path, 16));
    return readExr(path);
  }
  if (ext != ".hdr" && ext != ".png" && ext != ".jpg" && ext != ".jpeg") {
    throw InputError(path + ": unsupported image extension '" + ext +
                     "' (expected .exr, .hdr, .png or .jpg)");
  }
  const std::string file = readFile(path);
  checkFormatOfExtension(path, ext, file);
  const auto* bytes = reinterpret_cast<const unsigned char*>(file.data());
  if (file.empty() || file.size() > size_t(std::numeric_limits<int>::max())) {
    throw InputError(path + ": cannot read image (empty or larger than 2 GiB)");
  }
  const int size = int(file.size());
  // The header's size, and whether the bytes can hold it, before decoding
  // (stb's buffer and the image's floats).
  try {
    checkEncodedImage(bytes, file.size(), 4 * 4 + 12);
  } catch (const InputError& e) {
    throw InputError(path + ": " + e.what());
  }
  int w = 0, h = 0, n = 0;
  if (ext == ".hdr") {
    // Radiance RGBE: linear floats (stb applies no transfer curve to them).
    float* data = stbi_loadf_from_memory(bytes, size, &w, &h, &n, 3);
    if (!data) throw InputError(path + ": cannot read image (" + stbi_failure_reason() + ")");
    RgbImage image(w, h);
    std::copy(data, data + image.rgb.size(), image.rgb.begin());
    stbi_image_free(data);
    return image;
  }
  unsigned char* data = stbi_load_from_memory(bytes, size, &w, &h, &n, 3);
  if (!data) throw InputError(path + ": cannot read image (" + stbi_failure_reason() + ")");
  RgbImage image(w, h);
  // A table, not a power per texel: 144 M texels took seconds of it.
  const std::array<float, 256>& toLinear = srgb8ToLinear();
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    image.rgb[i] = linear8Bit ? float(data[i]) / 255.0f : toLinear[data[i]];
  }
  stbi_image_free(data);
  return image;
}

float srgbToLinear(float s) {
  return s <= 0.04045f ? s / 12.92f : std::pow((s + 0.055f) / 1.055f, 2.4f);
}

const std::array<float, 256>& srgb8ToLinear() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[size_t(i)] = srgbToLinear(float(i) / 255.0f);
    return t;
  }();
  return table;
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


namespace {

/// decodeStoredImage once checkEncodedImage has passed the bytes.
StoredImage decodeChecked(const unsigned char* bytes, size_t size) {
  const int n = int(size);
  int w = 0, h = 0, comp = 0;
  StoredImage out;
  if (size >= 8 && std::memcmp(bytes, "\x89PNG\r\n\x1a\n", 8) == 0) out.mimeType = "image/png";
  if (jpegBody(bytes, size) != 0) out.mimeType = "image/jpeg";
  auto finish = [&](auto* data, auto& values) {
    out.width = w;
    out.height = h;
    out.channels = comp;
    values.assign(data, data + size_t(w) * size_t(h) * size_t(comp));
    stbi_image_free(data);
  };
  if (stbi_is_16_bit_from_memory(bytes, n)) {
    stbi_us* data = stbi_load_16_from_memory(bytes, n, &w, &h, &comp, 0);
    if (data && w > 0 && h > 0 && comp >= 1 && comp <= 4) {
      finish(data, out.unorm16);
      return out;
    }
    if (data) stbi_image_free(data);
  }
  stbi_uc* data = stbi_load_from_memory(bytes, n, &w, &h, &comp, 0);
  if (!data || w <= 0 || h <= 0 || comp < 1 || comp > 4) {
    if (data) stbi_image_free(data);
    // stb names no reason for a format it was built without (a GIF, a BMP):
    // say what is read instead of an empty reason.
    const char* reason = stbi_failure_reason();
    throw InputError(reason && *reason ? reason
                                       : "not a PNG, JPEG or HDR image this tool decodes (glTF "
                                         "textures are PNG or JPEG)");
  }
  finish(data, out.unorm8);
  return out;
}

void checkBytesSize(size_t size) {
  if (size == 0 || size > size_t(std::numeric_limits<int>::max())) {
    throw InputError("empty or too large");
  }
}

}  // namespace

size_t storedImageBytes(const unsigned char* bytes, size_t size) {
  int w = 0, h = 0, comp = 0;
  if (size == 0 || size > size_t(std::numeric_limits<int>::max()) ||
      !stbi_info_from_memory(bytes, int(size), &w, &h, &comp) || w <= 0 || h <= 0) {
    return 0;
  }
  const size_t channelBytes = stbi_is_16_bit_from_memory(bytes, int(size)) ? 2 : 1;
  return size_t(w) * size_t(h) * size_t(std::clamp(comp, 1, 4)) * channelBytes;
}

StoredImage decodeStoredImage(const unsigned char* bytes, size_t size) {
  checkBytesSize(size);
  // The header's size first: stb's pixels and the caller's copy, at most 4
  // channels of 16 bits each.
  checkEncodedImage(bytes, size, 2 * 4 * 2);
  return decodeChecked(bytes, size);
}

DecodedImage decodeImageBytes(const unsigned char* bytes, size_t size) {
  checkBytesSize(size);
  // The stored pixels and their floats (4 channels of 4 bytes) per pixel.
  checkEncodedImage(bytes, size, 2 * 4 * 2 + 4 * 4);
  const StoredImage stored = decodeChecked(bytes, size);
  DecodedImage out;
  out.width = stored.width;
  out.height = stored.height;
  out.channels = stored.channels;
  if (!stored.unorm16.empty()) {
    out.values.resize(stored.unorm16.size());
    for (size_t i = 0; i < out.values.size(); ++i) out.values[i] = float(stored.unorm16[i]) / 65535.0f;
  } else {
    out.values.resize(stored.unorm8.size());
    for (size_t i = 0; i < out.values.size(); ++i) out.values[i] = float(stored.unorm8[i]) / 255.0f;
  }
  return out;
}

}  // namespace lo
