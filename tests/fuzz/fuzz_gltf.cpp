// libFuzzer target: the glTF 2.0 loader (.gltf text, or .glb when the input
// starts with the binary magic), lo::loadScene as every command calls it.

#include <cstring>

#include "core/error.h"
#include "fuzz_input.h"
#include "scene/scene.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const bool binary = size >= 4 && std::memcmp(data, "glTF", 4) == 0;
  static const std::string gltf = lo::fuzz::inputPath(".gltf"), glb = lo::fuzz::inputPath(".glb");
  const std::string& path = binary ? glb : gltf;
  lo::fuzz::writeInput(path, data, size);
  try {
    lo::loadScene(path);
  } catch (const lo::InputError&) {
  }
  return 0;
}
