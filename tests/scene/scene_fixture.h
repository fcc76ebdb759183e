#pragma once
/// @file tests/scene/scene_fixture.h
/// @brief What the loader's tests write and check again and again: scene
/// files in a fresh folder, a one-mesh glTF written as text, and the
/// InputError a bad file must raise.

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "core/math.h"

namespace lo::test {

/// Writes `bytes` to `path` (binary).
void writeFile(const std::string& path, const std::string& bytes);

/// Standard base64 (RFC 4648, padded): what a glTF data: URI holds.
std::string base64(const std::string& in);

/// Appends the bytes of `v` to `blob`, then zeros up to a multiple of 4
/// (glTF's accessor alignment).
template <typename T>
void append(std::string& blob, const std::vector<T>& v) {
  blob.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
  while (blob.size() % 4) blob.push_back('\0');
}

/// A one-mesh glTF written as text: POSITION (+ NORMAL) (+ uint32 indices) in
/// one buffer, and whatever nodes, materials and extra members a test needs.
struct MiniGltf {
  std::vector<float> positions;
  std::vector<float> normals;
  std::vector<uint32_t> indices;
  bool indexed = true;
  int mode = 4;
  int material = -1;
  std::string nodes = R"([{"mesh": 0}])";
  std::string sceneNodes = "[0]";
  std::string materials;  // JSON array, or empty
  std::string extraTop;   // more top-level members, each followed by ","
  std::string image;      // the uri of texture 0's image, or empty: no texture
  std::string bufferUri;  // empty: embedded data: URI
  std::vector<float> tangents;  // TANGENT (VEC4), or empty

  /// The buffer: positions, normals, indices, tangents, each 4-byte aligned.
  std::string blob() const;
  /// The .gltf text.
  std::string json() const;
  /// The same content as a .glb (JSON chunk + BIN chunk, no uri).
  std::string glb() const;
};

/// One triangle in the z = 0 plane, counter-clockwise seen from +z.
MiniGltf oneTriangle();

/// Writes g's JSON to dir/name; returns the path.
std::string writeGltf(const std::string& dir, const std::string& name, const MiniGltf& g);

/// Expects a and b within `tol` in each coordinate; `what` names the check.
void expectNear(const Vec3& a, const Vec3& b, float tol, const std::string& what = "");

/// Expects loadScene(path) to throw InputError whose message names the file
/// (its file name) and contains `keyword`.
void expectInputError(const std::string& path, const std::string& keyword);

/// The fixture of the tests that write scene files: `dir`, a fresh folder
/// named after the test (Suite_Name, under the build's test output).
class SceneFileTest : public ::testing::Test {
 protected:
  void SetUp() override;
  /// Writes `bytes` to dir/name; returns the path.
  std::string write(const std::string& name, const std::string& bytes) const;
  /// Writes g's JSON to dir/name; returns the path.
  std::string write(const std::string& name, const MiniGltf& g) const;
  std::string dir;
};

/// The suites whose every test writes its scene files.
using SceneGltf = SceneFileTest;
using SceneObj = SceneFileTest;
using SceneReject = SceneFileTest;
using SceneLimits = SceneFileTest;

}  // namespace lo::test
