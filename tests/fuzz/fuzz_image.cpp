// libFuzzer target: the image decoders the loaders use. The bytes go to
// decodeImageBytes (scene textures: stb's PNG, JPEG, HDR and the rest, by
// content) and, as files, to readImage by extension (.exr: OpenEXR's header
// and pixels; .png: compare and --mask).

#include "core/error.h"
#include "fuzz_input.h"
#include "image/image.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    lo::decodeImageBytes(data, size);
  } catch (const lo::InputError&) {
  }
  static const std::string exr = lo::fuzz::inputPath(".exr");
  static const std::string png = lo::fuzz::inputPath(".png");
  for (const std::string* path : {&exr, &png}) {
    lo::fuzz::writeInput(*path, data, size);
    try {
      lo::readImage(*path);
    } catch (const lo::InputError&) {
    }
  }
  return 0;
}
