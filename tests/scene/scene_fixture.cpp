#include "scene/scene_fixture.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "scene/scene.h"
#include "test_util.h"

namespace lo::test {

namespace fs = std::filesystem;

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out.write(bytes.data(), std::streamsize(bytes.size()));
  ASSERT_TRUE(out.good()) << path;
}

std::string base64(const std::string& in) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    uint32_t n = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8 |
                 uint32_t(uint8_t(in[i + 2]));
    for (int k = 3; k >= 0; --k) out += table[(n >> (6 * k)) & 63];
  }
  if (i + 1 == in.size()) {
    uint32_t n = uint32_t(uint8_t(in[i])) << 16;
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    uint32_t n = uint32_t(uint8_t(in[i])) << 16 | uint32_t(uint8_t(in[i + 1])) << 8;
    out += table[(n >> 18) & 63];
    out += table[(n >> 12) & 63];
    out += table[(n >> 6) & 63];
    out += '=';
  }
  return out;
}

std::string MiniGltf::blob() const {
  std::string b;
  append(b, positions);
  append(b, normals);
  if (indexed) append(b, indices);
  append(b, tangents);
  return b;
}

std::string MiniGltf::json() const {
  std::string bin = blob();
  size_t posBytes = positions.size() * 4, nrmBytes = normals.size() * 4;
  std::ostringstream os;
  os << "{\"asset\": {\"version\": \"2.0\"}, ";
  if (!image.empty()) {
    os << "\"textures\": [{\"source\": 0}], \"images\": [{\"uri\": \"" << image << "\"}], ";
  }
  os << extraTop
     << "\"scene\": 0, \"scenes\": [{\"nodes\": " << sceneNodes << "}], \"nodes\": " << nodes
     << ", ";
  if (!materials.empty()) os << "\"materials\": " << materials << ", ";
  os << "\"meshes\": [{\"primitives\": [{\"attributes\": {\"POSITION\": 0";
  if (!normals.empty()) os << ", \"NORMAL\": 1";
  if (!tangents.empty()) os << ", \"TANGENT\": 3";
  os << "}";
  if (indexed) os << ", \"indices\": 2";
  if (material >= 0) os << ", \"material\": " << material;
  os << ", \"mode\": " << mode << "}]}], ";
  os << "\"accessors\": [{\"bufferView\": 0, \"componentType\": 5126, \"count\": "
     << positions.size() / 3 << ", \"type\": \"VEC3\"}, ";
  if (!normals.empty()) {
    os << "{\"bufferView\": 1, \"componentType\": 5126, \"count\": " << normals.size() / 3
       << ", \"type\": \"VEC3\"}, ";
  } else {
    os << "{\"bufferView\": 0, \"componentType\": 5126, \"count\": 1, \"type\": \"VEC3\"}, ";
  }
  os << "{\"bufferView\": 2, \"componentType\": 5125, \"count\": " << indices.size()
     << ", \"type\": \"SCALAR\"}";
  if (!tangents.empty()) {
    os << ", {\"bufferView\": 3, \"componentType\": 5126, \"count\": " << tangents.size() / 4
       << ", \"type\": \"VEC4\"}";
  }
  os << "], ";
  size_t nrmOffset = posBytes, idxOffset = posBytes + nrmBytes;
  os << "\"bufferViews\": [{\"buffer\": 0, \"byteOffset\": 0, \"byteLength\": " << posBytes
     << "}, {\"buffer\": 0, \"byteOffset\": " << nrmOffset << ", \"byteLength\": " << nrmBytes
     << "}, {\"buffer\": 0, \"byteOffset\": " << idxOffset
     << ", \"byteLength\": " << (indexed ? indices.size() * 4 : 0) << "}";
  if (!tangents.empty()) {
    os << ", {\"buffer\": 0, \"byteOffset\": " << idxOffset + (indexed ? indices.size() * 4 : 0)
       << ", \"byteLength\": " << tangents.size() * 4 << "}";
  }
  os << "], ";
  std::string uri =
      bufferUri.empty() ? "data:application/octet-stream;base64," + base64(bin) : bufferUri;
  os << "\"buffers\": [{\"byteLength\": " << bin.size() << ", \"uri\": \"" << uri << "\"}]}";
  return os.str();
}

std::string MiniGltf::glb() const {
  MiniGltf copy = *this;
  copy.bufferUri = "\x01";  // placeholder, removed below
  std::string j = copy.json();
  std::string marker = ", \"uri\": \"\x01\"";
  j.replace(j.find(marker), marker.size(), "");
  while (j.size() % 4) j.push_back(' ');
  std::string bin = blob();
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  std::string out = "glTF" + u32(2) + u32(uint32_t(12 + 8 + j.size() + 8 + bin.size()));
  out += u32(uint32_t(j.size())) + "JSON" + j;
  out += u32(uint32_t(bin.size())) + std::string("BIN\0", 4) + bin;
  return out;
}

MiniGltf oneTriangle() {
  MiniGltf g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  g.indices = {0, 1, 2};
  return g;
}

void expectNear(const Vec3& a, const Vec3& b, float tol, const std::string& what) {
  EXPECT_NEAR(a.x, b.x, tol) << what << ": " << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.y, b.y, tol) << what << ": " << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.z, b.z, tol) << what << ": " << a.ToString() << " vs " << b.ToString();
}

void expectInputError(const std::string& path, const std::string& keyword) {
  try {
    Scene s = loadScene(path);
    ADD_FAILURE() << "no InputError for " << path << " (loaded " << s.ToString() << ")";
  } catch (const InputError& e) {
    std::string msg = e.what();
    std::string name = fs::path(path).filename().string();
    EXPECT_NE(msg.find(name), std::string::npos) << "message does not name the file: " << msg;
    EXPECT_NE(msg.find(keyword), std::string::npos) << "message lacks '" << keyword << "': " << msg;
  } catch (const std::exception& e) {
    ADD_FAILURE() << "wrong exception type for " << path << ": " << e.what();
  }
}

std::string writeGltf(const std::string& dir, const std::string& name, const MiniGltf& g) {
  std::string path = dir + "/" + name;
  writeFile(path, g.json());
  return path;
}

void SceneFileTest::SetUp() {
  const ::testing::TestInfo* info = ::testing::UnitTest::GetInstance()->current_test_info();
  dir = outputDir(std::string(info->test_suite_name()) + "_" + info->name());
}

std::string SceneFileTest::write(const std::string& name, const std::string& bytes) const {
  writeFile(dir + "/" + name, bytes);
  return dir + "/" + name;
}

std::string SceneFileTest::write(const std::string& name, const MiniGltf& g) const {
  return writeGltf(dir, name, g);
}

}  // namespace lo::test
