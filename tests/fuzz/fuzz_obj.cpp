// libFuzzer target: the OBJ/MTL loader, lo::loadScene on a .obj file.

#include "core/error.h"
#include "fuzz_input.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string path = lo::fuzz::inputPath(".obj");
  lo::fuzz::writeInput(path, data, size);
  try {
    lo::loadScene(path);
  } catch (const lo::InputError&) {
  }
  return 0;
}
