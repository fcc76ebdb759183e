/// @file render/image_io.cpp
#include "render/image_io.h"

#include "core/error.h"

namespace lo {

RgbImage toRgbImage(const Image& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgba.size() != size_t(image.width) * size_t(image.height) * 4) {
    throw InputError("empty or inconsistent rendered image (" + std::to_string(image.width) +
                     " x " + std::to_string(image.height) + ")");
  }
  RgbImage rgb(image.width, image.height);
  for (size_t i = 0; i < rgb.pixelCount(); ++i) {
    for (int c = 0; c < 3; ++c) rgb.rgb[3 * i + c] = image.rgba[4 * i + c];
  }
  return rgb;
}

void writeImage(const std::string& path, const Image& image, float exposureEv) {
  writeImage(path, toRgbImage(image), exposureEv);
}

}  // namespace lo
