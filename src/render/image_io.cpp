#include "render/image_io.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfOutputFile.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include "core/error.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBIW_STATIC  // private copy: tinygltf in src/scene may define its own
#include <stb_image_write.h>

namespace lo {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

void writeExr(const std::string& path, const Image& image) {
  Imf::Header header(image.width, image.height);
  const char* names[3] = {"R", "G", "B"};
  for (const char* name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
  Imf::OutputFile file(path.c_str(), header);
  Imf::FrameBuffer fb;
  char* base = reinterpret_cast<char*>(const_cast<float*>(image.rgba.data()));
  for (int c = 0; c < 3; ++c) {
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), 4 * sizeof(float),
                                   size_t(image.width) * 4 * sizeof(float)));
  }
  file.setFrameBuffer(fb);
  file.writePixels(image.height);
}

}  // namespace

unsigned char encodeSrgb8(float linear) {
  float c = std::isfinite(linear) ? std::clamp(linear, 0.0f, 1.0f) : 0.0f;
  float s = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
  return static_cast<unsigned char>(std::lround(s * 255.0f));
}

void writeImage(const std::string& path, const Image& image, float exposureEv) {
  std::string ext = lowerExtension(path);
  if (ext != ".exr" && ext != ".png") {
    throw InputError(path + ": unsupported image extension '" + ext + "' (expected .exr or .png)");
  }
  if (image.width < 1 || image.height < 1 ||
      image.rgba.size() != size_t(image.width) * image.height * 4) {
    throw InputError(path + ": empty or inconsistent image");
  }
  std::string tmp = path + ".tmp";
  try {
    if (ext == ".exr") {
      writeExr(tmp, image);
    } else {
      float scale = std::exp2(exposureEv);
      std::vector<unsigned char> rgb(size_t(image.width) * image.height * 3);
      for (size_t i = 0; i < size_t(image.width) * image.height; ++i) {
        for (int c = 0; c < 3; ++c) rgb[i * 3 + c] = encodeSrgb8(image.rgba[i * 4 + c] * scale);
      }
      if (!stbi_write_png(tmp.c_str(), image.width, image.height, 3, rgb.data(), image.width * 3)) {
        throw IoError(path + ": cannot write PNG");
      }
    }
    std::filesystem::rename(tmp, path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    throw IoError(path + ": " + e.what());
  }
}

}  // namespace lo
