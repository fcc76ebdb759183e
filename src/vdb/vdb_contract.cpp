// The light-grid file contract's names (docs/vdb-contract.md) and the
// deterministic file identity. No OpenVDB.

#include "vdb/vdb_contract.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "vdb/vdb_io.h"

namespace lo {
namespace vdb_internal {

std::string layerPrefix(int layer) { return "layer" + std::to_string(layer) + "_"; }

bool isRequiredVoxelGrid(const std::string& name) {
  bool found = false;
  forEachField([&](const auto& row) {
    if (row.optional || row.arity == FieldArity::OneOrNone) return;
    for (const FieldGrid& grid : fieldGrids(row, 0, kMaxVdls, 9)) found = found || grid.name == name;
  });
  return found;
}

// ---------------------------------------------------------------------------
// Deterministic bytes. io::Archive writes a random UUID (36 ASCII characters
// after the 21-byte header prefix: magic, file version, library version, the
// grid-offsets flag). The bake must give byte-identical files for identical
// inputs, so the UUID is replaced by one derived from the rest of the file:
// identical content, identical identity, which is what OpenVDB uses it for.

namespace {

constexpr std::streamoff kUuidOffset = 8 + 4 + 4 + 4 + 1;
constexpr size_t kUuidLength = 36;

uint64_t fnv1a(uint64_t h, const char* data, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    h ^= uint8_t(data[i]);
    h *= 0x100000001b3ull;
  }
  return h;
}

}  // namespace

void makeUuidDeterministic(const std::string& file) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  if (!f) throw std::runtime_error("cannot reopen the temporary file");
  char uuid[kUuidLength];
  f.seekg(kUuidOffset);
  f.read(uuid, kUuidLength);
  if (!f || uuid[8] != '-' || uuid[13] != '-' || uuid[18] != '-' || uuid[23] != '-') {
    throw std::runtime_error("unexpected OpenVDB header layout (UUID not found)");
  }
  uint64_t h1 = 0xcbf29ce484222325ull, h2 = 0x84222325cbf29ce4ull;
  std::vector<char> buffer(1 << 16);
  while (f) {
    f.read(buffer.data(), std::streamsize(buffer.size()));
    size_t got = size_t(f.gcount());
    h1 = fnv1a(h1, buffer.data(), got);
    h2 = fnv1a(h2, buffer.data(), got);
  }
  f.clear();
  char hex[33];
  std::snprintf(hex, sizeof(hex), "%016llx%016llx", static_cast<unsigned long long>(h1),
                static_cast<unsigned long long>(h2));
  hex[12] = '8';  // RFC 9562 version 8: "custom" (here: content hash)
  std::string text = std::string(hex, 8) + "-" + std::string(hex + 8, 4) + "-" +
                     std::string(hex + 12, 4) + "-" + std::string(hex + 16, 4) + "-" +
                     std::string(hex + 20, 12);
  f.seekp(kUuidOffset);
  f.write(text.data(), std::streamsize(text.size()));
  if (!f) throw std::runtime_error("cannot rewrite the file header");
}

}  // namespace vdb_internal

const std::vector<std::string>& optionalVdlGridNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    forEachField([&](const auto& row) {
      if (row.optional) out.push_back(row.gridName);
    });
    return out;
  }();
  return names;
}

const std::vector<std::string>& droppableVdlGridNames() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out = optionalVdlGridNames();
    out.push_back(vdb_internal::kDensityGrid);
    return out;
  }();
  return names;
}

}  // namespace lo
