// Tests of src/scene: the project's Cornell box, the shared scenes, node
// transforms, punctual lights, and one malformed file per rejected input.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "test_util.h"
#include "core/file.h"
#include "core/rng.h"
#include "scene/sky_sampler.h"
#include "core/error.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

// --- helpers ----------------------------------------------------------------

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
  std::string bufferUri;  // empty: embedded data: URI
  std::vector<float> tangents;  // TANGENT (VEC4), or empty

  std::string blob() const {
    std::string b;
    append(b, positions);
    append(b, normals);
    if (indexed) append(b, indices);
    append(b, tangents);
    return b;
  }

  std::string json() const {
    std::string bin = blob();
    size_t posBytes = positions.size() * 4, nrmBytes = normals.size() * 4;
    std::ostringstream os;
    os << "{\"asset\": {\"version\": \"2.0\"}, " << extraTop
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

  /// The same content as a .glb (JSON chunk + BIN chunk, no uri).
  std::string glb() const {
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
};

/// One triangle in the z = 0 plane, counter-clockwise seen from +z.
MiniGltf oneTriangle() {
  MiniGltf g;
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  g.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1};
  g.indices = {0, 1, 2};
  return g;
}

void expectNear(const Vec3& a, const Vec3& b, float tol, const std::string& what = "") {
  EXPECT_NEAR(a.x, b.x, tol) << what << ": " << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.y, b.y, tol) << what << ": " << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.z, b.z, tol) << what << ": " << a.ToString() << " vs " << b.ToString();
}

/// Expects loadScene(path) to throw InputError whose message names the file
/// (its file name) and contains `keyword`.
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

// --- the project's Cornell box ------------------------------------------------

TEST(SceneCornellBox, LoadsMeasuredRoom) {
  Scene s = loadScene(test::dataDir() + "/cornell-box.gltf");
  SCOPED_TRACE(s.ToString());
  EXPECT_EQ(s.triangleCount(), 32u);

  int emissive = 0;
  for (const Material& m : s.materials) {
    if (!m.isEmissive()) continue;
    ++emissive;
    expectNear(m.emission, {17, 12, 4}, 1e-4f, "light radiance");
    expectNear(m.baseColor, {0.78f, 0.78f, 0.78f}, 1e-6f, "light albedo");
  }
  EXPECT_EQ(emissive, 1);

  ASSERT_EQ(s.cameras.size(), 1u);
  const Camera& cam = s.cameras[0];
  EXPECT_EQ(cam.name, "cornell_camera");
  EXPECT_NEAR(cam.yfov, 2.0f * std::atan(12.5f / 35.0f), 1e-6f);
  EXPECT_NEAR(cam.aspectRatio, 1.0f, 1e-6f);
  expectNear(cam.position, {0, 0.273f, 0.8f}, 1e-6f, "camera position");
  expectNear(cam.forward, {0, 0, -1}, 1e-6f, "camera forward");
  expectNear(cam.up, {0, 1, 0}, 1e-6f, "camera up");

  Bounds3 b = s.bounds();
  expectNear(b.extent(), {0.556f, 0.5488f, 0.5592f}, 1e-5f, "room size");
  EXPECT_NEAR(b.center().x, 0.0f, 1e-5f);
  EXPECT_NEAR(b.lower.y, 0.0f, 1e-6f);
  EXPECT_NEAR(b.upper.z, 0.0f, 1e-6f);  // the open side at z = 0, facing the camera

  ASSERT_EQ(s.normals.size(), s.positions.size());
  const Vec3 room = b.center();
  int floor = 0, ceiling = 0, red = 0, green = 0, back = 0, light = 0, blocks = 0;
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    Vec3 n = s.faceNormal(t);
    const Vec3& p0 = s.positions[s.indices[3 * t]];
    const Vec3& p1 = s.positions[s.indices[3 * t + 1]];
    const Vec3& p2 = s.positions[s.indices[3 * t + 2]];
    Vec3 c = (p0 + p1 + p2) / 3.0f;
    for (int k = 0; k < 3; ++k) {
      EXPECT_GT(dot(s.normals[s.indices[3 * t + size_t(k)]], n), 0.9999f) << "triangle " << t;
    }
    const Material& m = s.materials[size_t(s.triangleMaterial[t])];
    float ymax = std::max({p0.y, p1.y, p2.y}), ymin = std::min({p0.y, p1.y, p2.y});
    if (m.isEmissive()) {
      ++light;
      EXPECT_LT(dot(n, {0, 1, 0}), -0.99f) << "light must face down";
      EXPECT_NEAR(c.y, 0.5483f, 1e-6f);
    } else if (m.name == "red") {
      ++red;
      EXPECT_GT(dot(n, {1, 0, 0}), 0.99f) << "red wall faces +x (inside)";
      EXPECT_LT(c.x, -0.27f) << "red wall is on the left of the camera";
    } else if (m.name == "green") {
      ++green;
      EXPECT_GT(dot(n, {-1, 0, 0}), 0.99f);
      EXPECT_GT(c.x, 0.27f);
    } else if (ymax < 1e-6f) {
      ++floor;
      EXPECT_GT(dot(n, {0, 1, 0}), 0.99f) << "floor faces up";
    } else if (ymin > 0.5487f) {
      ++ceiling;
      EXPECT_GT(dot(n, {0, -1, 0}), 0.99f) << "ceiling faces down";
    } else if (c.z < -0.559f) {
      ++back;
      EXPECT_GT(dot(n, {0, 0, 1}), 0.99f) << "back wall faces the camera";
    } else {
      ++blocks;
      // Block faces point away from the block's vertical axis (or up for the top).
      bool tall = ymax > 0.2f;
      Vec3 axis = tall ? Vec3{-0.0905f, 0, -0.3512f} : Vec3{0.0925f, 0, -0.169f};
      Vec3 away = c - Vec3{axis.x, c.y, axis.z};
      if (ymin == ymax) {
        EXPECT_GT(n.y, 0.99f) << "block top faces up";
      } else {
        EXPECT_GT(dot(n, normalize(away)), 0.5f) << "block side faces out, triangle " << t;
      }
      EXPECT_GT(dot(n, room - c), -1.0f);  // (finite)
    }
  }
  EXPECT_EQ(floor, 2);
  EXPECT_EQ(ceiling, 2);
  EXPECT_EQ(back, 2);
  EXPECT_EQ(red, 2);
  EXPECT_EQ(green, 2);
  EXPECT_EQ(light, 2);
  EXPECT_EQ(blocks, 20);
}

// --- shared scenes -------------------------------------------------------------

TEST(SceneShared, ComposedCornellBoxGlb) {
  std::string path = test::sharedScenesDir() + "/composed/cornell-box.glb";
  if (!fs::exists(path)) GTEST_SKIP() << "missing " << path;
  Scene s = loadScene(path);
  EXPECT_EQ(s.triangleCount(), 32u);
  int emissive = 0;
  for (const Material& m : s.materials) {
    if (!m.isEmissive()) continue;
    ++emissive;
    // emissiveFactor (1, 12/17, 4/17) x KHR_materials_emissive_strength 17.
    expectNear(m.emission, {17.0f, 12.0f, 4.0f}, 1e-4f, "emissive strength 17");
  }
  EXPECT_EQ(emissive, 1);
  ASSERT_FALSE(s.cameras.empty());
  expectNear(s.cameras[0].position, {0, 1, 3.9f}, 1e-5f, "camera");
  Bounds3 b = s.bounds();
  EXPECT_NEAR(b.lower.x, -1.0f, 0.05f);
  EXPECT_NEAR(b.upper.y, 1.99f, 0.01f);
}

TEST(SceneShared, CornellBoxObj) {
  std::string path = test::sharedScenesDir() + "/cornell-box/CornellBox-Original.obj";
  if (!fs::exists(path)) GTEST_SKIP() << "missing " << path;
  Scene s = loadScene(path);
  SCOPED_TRACE(s.ToString());
  EXPECT_GE(s.triangleCount(), 30u);
  int emissive = 0;
  for (const Material& m : s.materials) {
    if (m.isEmissive()) {
      ++emissive;
      EXPECT_EQ(m.name, "light");
      expectNear(m.emission, {17, 12, 4}, 1e-5f, "Ke");
      expectNear(m.baseColor, {0.78f, 0.78f, 0.78f}, 1e-6f, "Kd");
    }
    if (m.name == "leftWall") {
      expectNear(m.baseColor, {0.63f, 0.065f, 0.05f}, 1e-6f, "Kd");
      EXPECT_FLOAT_EQ(m.roughness, 1.0f);  // Ks 0 0 0: diffuse
      EXPECT_FLOAT_EQ(m.specular, 0.0f);   // and no specular layer
      EXPECT_FLOAT_EQ(m.ior, 1.5f);        // Ni 1.5
      EXPECT_FLOAT_EQ(m.transmission, 0.0f);
    }
  }
  EXPECT_EQ(emissive, 1);
  // Faces are grouped by material.
  for (size_t t = 1; t < s.triangleCount(); ++t)
    EXPECT_GE(s.triangleMaterial[t], s.triangleMaterial[t - 1]);
  // The floor (y = 0) faces up: the OBJ's winding is kept.
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    const Vec3& a = s.positions[s.indices[3 * t]];
    const Vec3& b = s.positions[s.indices[3 * t + 1]];
    const Vec3& c = s.positions[s.indices[3 * t + 2]];
    if (std::max({a.y, b.y, c.y}) < 1e-6f) {
      EXPECT_GT(s.faceNormal(t).y, 0.99f);
    }
  }
}

TEST(SceneShared, CornellBoxGltfMatchesObj) {
  std::string dir = test::sharedScenesDir() + "/cornell-box/";
  if (!fs::exists(dir + "CornellBox-Original.gltf")) GTEST_SKIP();
  Scene g = loadScene(dir + "CornellBox-Original.gltf");
  Scene o = loadScene(dir + "CornellBox-Original.obj");
  expectNear(g.bounds().lower, o.bounds().lower, 1e-5f, "lower");
  expectNear(g.bounds().upper, o.bounds().upper, 1e-5f, "upper");
  // (Areas differ: the OBJ holds two duplicated quads, see MANIFEST.md.)
  int emissiveG = 0;
  for (const Material& m : g.materials) emissiveG += m.isEmissive();
  EXPECT_EQ(emissiveG, 1);
}

// --- transforms -----------------------------------------------------------------

TEST(SceneGltf, NodeTransformsTrsAndMatrix) {
  std::string dir = test::outputDir("SceneGltf_NodeTransforms");
  MiniGltf g = oneTriangle();
  const float h = std::sqrt(0.5f);
  std::ostringstream nodes;
  // node 0: T(1,2,3), child node 1: R_y(90 deg) * S(2).  node 2: a matrix with
  // a non-uniform scale (x2 in y) and a translation (10, 0, 0).
  nodes << "[{\"translation\": [1, 2, 3], \"children\": [1]},"
        << " {\"mesh\": 0, \"rotation\": [0, " << h << ", 0, " << h << "], \"scale\": [2, 2, 2]},"
        << " {\"mesh\": 0, \"matrix\": [1,0,0,0, 1,2,0,0, 0,0,1,0, 10,0,0,1]}]";
  g.nodes = nodes.str();
  g.sceneNodes = "[0, 2]";
  Scene s = loadScene(writeGltf(dir, "transform.gltf", g));
  ASSERT_EQ(s.triangleCount(), 2u);
  // R_y(90): (x, y, z) -> (z, y, -x).
  expectNear(s.positions[s.indices[0]], {1, 2, 3}, 1e-5f, "p0");
  expectNear(s.positions[s.indices[1]], {1, 2, 1}, 1e-5f, "p1");
  expectNear(s.positions[s.indices[2]], {1, 4, 3}, 1e-5f, "p2");
  expectNear(s.normals[s.indices[0]], {1, 0, 0}, 1e-5f, "rotated normal");
  // Matrix node (column-major): x' = x + y + 10, y' = 2y (a shear, not just a scale).
  expectNear(s.positions[s.indices[4]], {11, 0, 0}, 1e-5f, "matrix p1");
  expectNear(s.positions[s.indices[5]], {11, 2, 0}, 1e-5f, "matrix p2");
  // Vertex normals by the inverse transpose agree with the transformed face.
  for (size_t t = 0; t < 2; ++t)
    for (int k = 0; k < 3; ++k)
      expectNear(s.normals[s.indices[3 * t + size_t(k)]], s.faceNormal(t), 1e-5f, "normal");
}

// A region of interest marked in the file: the marker node's mesh is not
// geometry; its world-space bounds are Scene::region.
TEST(SceneGltf, RegionMarkerNodeGivesTheRegionAndIsNoGeometry) {
  std::string dir = test::outputDir("SceneGltf_RegionMarker");
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0},
                {"mesh": 0, "translation": [5, 6, 7], "scale": [2, 3, 4],
                 "extras": {"lightoctree_region": true}},
                {"mesh": 0, "translation": [-1, 0, 0], "extras": {"lightoctree_region": false}}])";
  g.sceneNodes = "[0, 1, 2]";
  Scene s = loadScene(writeGltf(dir, "region.gltf", g));
  EXPECT_EQ(s.triangleCount(), 2u);  // nodes 0 and 2; the marker is not geometry
  EXPECT_EQ(s.positions.size(), 6u);
  EXPECT_EQ(s.normals.size(), 6u);
  ASSERT_FALSE(s.region.empty());
  expectNear(s.region.lower, {5, 6, 7}, 1e-6f, "region lower");
  expectNear(s.region.upper, {7, 9, 7}, 1e-6f, "region upper");
  // Without one, no region.
  MiniGltf plain = oneTriangle();
  EXPECT_TRUE(loadScene(writeGltf(dir, "plain.gltf", plain)).region.empty());
  // A marker needs a mesh, and true or false.
  MiniGltf noMesh = oneTriangle();
  noMesh.nodes = R"([{"mesh": 0}, {"extras": {"lightoctree_region": true}}])";
  noMesh.sceneNodes = "[0, 1]";
  expectInputError(writeGltf(dir, "nomesh.gltf", noMesh), "has no mesh");
  MiniGltf notBool = oneTriangle();
  notBool.nodes = R"([{"mesh": 0, "extras": {"lightoctree_region": 1}}])";
  expectInputError(writeGltf(dir, "notbool.gltf", notBool), "must be true or false");
}

TEST(SceneGltf, NonUniformScaleNormalsUseInverseTranspose) {
  std::string dir = test::outputDir("SceneGltf_NonUniform");
  MiniGltf g;
  // A tilted triangle; its vertex normals are its face normal.
  g.positions = {0, 0, 0, 1, 0, 1, 0, 1, 0};
  Vec3 n = normalize(cross(Vec3{1, 0, 1}, Vec3{0, 1, 0}));
  g.normals = {n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z};
  g.indices = {0, 1, 2};
  g.nodes = R"([{"mesh": 0, "scale": [3, 1, 0.5], "rotation": [0.2, 0.3, 0.1, 0.927]}])";
  Scene s = loadScene(writeGltf(dir, "scaled.gltf", g));
  for (int k = 0; k < 3; ++k) expectNear(s.normals[s.indices[size_t(k)]], s.faceNormal(0), 1e-5f);
}

TEST(SceneGltf, NegativeScaleFlipsWinding) {
  std::string dir = test::outputDir("SceneGltf_NegativeScale");
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "scale": [-1, 1, 1]}])";
  Scene s = loadScene(writeGltf(dir, "mirror.gltf", g));
  ASSERT_EQ(s.triangleCount(), 1u);
  // Mirrored in x, the triangle still faces +z: the winding was flipped.
  expectNear(s.faceNormal(0), {0, 0, 1}, 1e-6f, "face normal");
  for (int k = 0; k < 3; ++k) expectNear(s.normals[s.indices[size_t(k)]], {0, 0, 1}, 1e-6f);
  // Without the mirror, the same triangle faces +z too (reference).
  g.nodes = R"([{"mesh": 0}])";
  Scene r = loadScene(writeGltf(dir, "plain.gltf", g));
  expectNear(r.faceNormal(0), {0, 0, 1}, 1e-6f, "reference");
}

TEST(SceneGltf, NonIndexedStripAndFan) {
  std::string dir = test::outputDir("SceneGltf_StripFan");
  MiniGltf g;
  // A unit quad in z = 0 as a strip 0-1-2-3: (0,0) (1,0) (0,1) (1,1).
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  g.indexed = false;
  g.mode = 5;
  Scene strip = loadScene(writeGltf(dir, "strip.gltf", g));
  ASSERT_EQ(strip.triangleCount(), 2u);
  for (size_t t = 0; t < 2; ++t) expectNear(strip.faceNormal(t), {0, 0, 1}, 1e-6f, "strip");
  EXPECT_TRUE(strip.normals.empty());
  // The same quad as a fan 0-1-3-2.
  g.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  g.mode = 6;
  Scene fan = loadScene(writeGltf(dir, "fan.gltf", g));
  ASSERT_EQ(fan.triangleCount(), 2u);
  for (size_t t = 0; t < 2; ++t) expectNear(fan.faceNormal(t), {0, 0, 1}, 1e-6f, "fan");
  EXPECT_NEAR(fan.triangleArea(0) + fan.triangleArea(1), 1.0f, 1e-6f);
}

TEST(SceneGltf, SparseAccessor) {
  std::string dir = test::outputDir("SceneGltf_Sparse");
  MiniGltf g = oneTriangle();
  std::string j = g.json();
  // POSITION gets one sparse substitute: index 0 (the first uint32 of the
  // index view) takes the value (0, 0, 1) (the first normal).
  std::string from = "\"count\": 3, \"type\": \"VEC3\"}";
  j.replace(j.find(from), from.size(),
            "\"count\": 3, \"type\": \"VEC3\", \"sparse\": {\"count\": 1, \"indices\": "
            "{\"bufferView\": 2, \"componentType\": 5125}, \"values\": {\"bufferView\": 1}}}");
  writeFile(dir + "/sparse.gltf", j);
  Scene s = loadScene(dir + "/sparse.gltf");
  expectNear(s.positions[0], {0, 0, 1}, 1e-6f, "substituted");
  expectNear(s.positions[1], {1, 0, 0}, 1e-6f, "kept");
}

// A sparse accessor without a bufferView stands for zeros: 2^28 of them in
// a few hundred bytes used to cost 6.4 GB before any check. Refused before
// allocating, naming the accessor.
TEST(SceneGltf, SparseAccessorOfImplicitZerosIsBounded) {
  std::string dir = test::outputDir("SceneGltf_SparseHuge");
  MiniGltf g = oneTriangle();
  std::string j = g.json();
  const std::string from = "{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}";
  ASSERT_NE(j.find(from), std::string::npos) << j;
  j.replace(j.find(from), from.size(),
            "{\"componentType\": 5126, \"count\": 268435456, \"type\": \"VEC3\", \"sparse\": "
            "{\"count\": 1, \"indices\": {\"bufferView\": 2, \"componentType\": 5125}, "
            "\"values\": {\"bufferView\": 1}}}");
  writeFile(dir + "/huge.gltf", j);
  expectInputError(dir + "/huge.gltf", "implicit zero elements");
}

TEST(SceneGltf, GlbAndDefaultMaterial) {
  std::string dir = test::outputDir("SceneGltf_Glb");
  MiniGltf g = oneTriangle();
  writeFile(dir + "/tri.glb", g.glb());
  Scene s = loadScene(dir + "/tri.glb");
  ASSERT_EQ(s.triangleCount(), 1u);
  ASSERT_EQ(s.materials.size(), 1u);  // the shared default
  EXPECT_EQ(s.materials[0].name, "default");
  EXPECT_EQ(s.triangleMaterial[0], 0);
}

TEST(SceneGltf, MaterialExtensionsAndTexture) {
  std::string dir = test::outputDir("SceneGltf_Material");
  // A 2x1 binary PPM (stb_image reads PNM): red, and sRGB grey 188.
  writeFile(dir + "/tex.ppm", std::string("P6\n2 1\n255\n\xff\x00\x00\xbc\xbc\xbc", 17));
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"name": "glass", "doubleSided": true, "emissiveFactor": [0.5, 0.25, 1],
    "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 1], "metallicFactor": 0.25,
      "roughnessFactor": 0.75, "baseColorTexture": {"index": 0}},
    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
      "KHR_materials_transmission": {"transmissionFactor": 0.9},
      "KHR_materials_ior": {"ior": 1.33}, "KHR_materials_volume": {"thicknessFactor": 0.2}}}])";
  g.extraTop = R"("textures": [{"source": 0}], "images": [{"uri": "tex.ppm"}], )";
  Scene s = loadScene(writeGltf(dir, "material.gltf", g));
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  expectNear(m.emission, {2, 1, 4}, 1e-6f, "emission");
  EXPECT_FLOAT_EQ(m.metallic, 0.25f);
  EXPECT_FLOAT_EQ(m.roughness, 0.75f);
  EXPECT_FLOAT_EQ(m.transmission, 0.9f);
  EXPECT_FLOAT_EQ(m.ior, 1.33f);
  EXPECT_FLOAT_EQ(m.thickness, 0.2f);
  EXPECT_TRUE(m.doubleSided);
  ASSERT_EQ(m.baseColorTexture, 0);
  ASSERT_EQ(s.textures.size(), 1u);
  const Texture& t = s.textures[0];
  ASSERT_EQ(t.width, 2);
  ASSERT_EQ(t.height, 1);
  expectNear(t.texelAt(0), {1, 0, 0}, 1e-6f, "red texel");
  // sRGB 188/255 = 0.737 -> linear ((0.737 + 0.055) / 1.055)^2.4 = 0.5029.
  expectNear(t.texelAt(1), Vec3{0.50289f}, 1e-4f, "grey texel");
}

// KHR_texture_transform on the base colour texture: offset, rotation, scale
// and its texCoord override are read; the transform is the extension's
// offset + R(rotation) S(scale) uv.
TEST(SceneGltf, TextureTransform) {
  std::string dir = test::outputDir("SceneGltf_TextureTransform");
  writeFile(dir + "/tex.ppm", std::string("P6\n2 1\n255\n\xff\x00\x00\xbc\xbc\xbc", 17));
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 0,
      "extensions": {"KHR_texture_transform": {"offset": [0.5, -0.25], "rotation": 1.5707963,
        "scale": [2, 3], "texCoord": 1}}}}}])";
  g.extraTop = R"("textures": [{"source": 0}], "images": [{"uri": "tex.ppm"}], )";
  Scene s = loadScene(writeGltf(dir, "transform.gltf", g));
  const Material& m = s.materials.at(0);
  EXPECT_EQ(m.baseColorTexCoord, 1);
  EXPECT_FLOAT_EQ(m.baseColorTransform.offset[0], 0.5f);
  EXPECT_FLOAT_EQ(m.baseColorTransform.offset[1], -0.25f);
  EXPECT_FLOAT_EQ(m.baseColorTransform.scale[0], 2.0f);
  EXPECT_FLOAT_EQ(m.baseColorTransform.scale[1], 3.0f);
  // (1, 0) -> scale (2, 0) -> rotate a quarter turn: (cos 2, -sin 2) = (0, -2) -> + offset.
  float u = 1, v = 0;
  m.baseColorTransform.apply(u, v);
  EXPECT_NEAR(u, 0.5f, 1e-6f);
  EXPECT_NEAR(v, -2.25f, 1e-6f);
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0,
      "extensions": {"KHR_texture_transform": {"offset": [0.5]}}}}}])";
  expectInputError(writeGltf(dir, "bad-transform.gltf", g), "KHR_texture_transform offset");
}

// normalTexture, metallicRoughnessTexture and occlusionTexture: index, scale
// or strength and UV set are read, and the maps are decoded as data (no sRGB
// curve), a separate texture from the same image used as colour.
TEST(SceneGltf, NormalTextureIsLinearData) {
  std::string dir = test::outputDir("SceneGltf_NormalTexture");
  writeFile(dir + "/tex.ppm", std::string("P6\n2 1\n255\n\xff\x00\x00\xbc\xbc\xbc", 17));
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
        "metallicRoughnessTexture": {"index": 0}},
      "normalTexture": {"index": 0, "scale": 0.5},
      "occlusionTexture": {"index": 0, "strength": 0.75}}])";
  g.extraTop = R"("textures": [{"source": 0}], "images": [{"uri": "tex.ppm"}], )";
  Scene s = loadScene(writeGltf(dir, "normal.gltf", g));
  const Material& m = s.materials.at(0);
  ASSERT_GE(m.normalTexture, 0);
  ASSERT_GE(m.baseColorTexture, 0);
  EXPECT_NE(m.normalTexture, m.baseColorTexture);
  EXPECT_FLOAT_EQ(m.normalScale, 0.5f);
  EXPECT_EQ(m.normalTexCoord, 0);
  expectNear(s.textures[size_t(m.normalTexture)].texelAt(1), Vec3{188.0f / 255.0f}, 1e-6f,
             "data texel");
  expectNear(s.textures[size_t(m.baseColorTexture)].texelAt(1), Vec3{0.50289f}, 1e-4f,
             "colour texel");
  // The other data maps share the data decoding of the image.
  EXPECT_EQ(m.metallicRoughnessTexture, m.normalTexture);
  EXPECT_EQ(m.occlusionTexture, m.normalTexture);
  EXPECT_FLOAT_EQ(m.occlusionStrength, 0.75f);
}

// --- lights ---------------------------------------------------------------------

TEST(SceneGltf, PunctualLights) {
  std::string dir = test::outputDir("SceneGltf_Lights");
  MiniGltf g = oneTriangle();
  const float h = std::sqrt(0.5f);
  g.extraTop =
      R"("extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual": {"lights": [
      {"name": "bulb", "type": "point", "color": [1, 0.5, 0.25], "intensity": 10, "range": 5},
      {"type": "spot", "intensity": 3, "spot": {"innerConeAngle": 0.2, "outerConeAngle": 0.5}},
      {"type": "directional", "intensity": 2}]}}, )";
  std::ostringstream nodes;
  nodes << "[{\"mesh\": 0}, {\"translation\": [1, 2, 3], "
        << "\"extensions\": {\"KHR_lights_punctual\": {\"light\": 0}}},"
        << " {\"translation\": [0, 1, 0], \"children\": [3]},"
        << " {\"name\": \"spot_node\", \"translation\": [0, 5, 0], \"rotation\": [" << -h
        << ", 0, 0, " << h << "], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 1}}},"
        << " {\"rotation\": [0, " << h << ", 0, " << h
        << "], \"extensions\": {\"KHR_lights_punctual\": {\"light\": 2}}}]";
  g.nodes = nodes.str();
  g.sceneNodes = "[0, 1, 2, 4]";
  Scene s = loadScene(writeGltf(dir, "lights.gltf", g));
  ASSERT_EQ(s.lights.size(), 3u);
  const Light* point = nullptr;
  const Light* spot = nullptr;
  const Light* sun = nullptr;
  for (const Light& l : s.lights) {
    if (l.type == Light::Type::Point) point = &l;
    if (l.type == Light::Type::Spot) spot = &l;
    if (l.type == Light::Type::Directional) sun = &l;
  }
  ASSERT_TRUE(point && spot && sun);
  EXPECT_EQ(point->name, "bulb");
  expectNear(point->position, {1, 2, 3}, 1e-6f, "point position");
  expectNear(point->color, {1, 0.5f, 0.25f}, 1e-6f, "point colour");
  EXPECT_FLOAT_EQ(point->intensity, 10.0f);
  EXPECT_FLOAT_EQ(point->range, 5.0f);
  EXPECT_EQ(spot->name, "spot_node");
  expectNear(spot->position, {0, 6, 0}, 1e-6f, "spot position (parent + child)");
  expectNear(spot->direction, {0, -1, 0}, 1e-6f, "spot points down");
  EXPECT_FLOAT_EQ(spot->innerConeAngle, 0.2f);
  EXPECT_FLOAT_EQ(spot->outerConeAngle, 0.5f);
  EXPECT_FLOAT_EQ(spot->intensity, 3.0f);
  expectNear(sun->direction, {-1, 0, 0}, 1e-6f, "R_y(90) turns -z into -x");
  EXPECT_FLOAT_EQ(sun->intensity, 2.0f);
}

// --- rejected inputs -------------------------------------------------------------

TEST(SceneReject, MissingFile) {
  std::string dir = test::outputDir("SceneReject_Missing");
  expectInputError(dir + "/nope.gltf", "missing");
  expectInputError(dir + "/nope.obj", "missing");
  ASSERT_EQ(mkfifo((dir + "/pipe.gltf").c_str(), 0600), 0);  // would block a reader
  expectInputError(dir + "/pipe.gltf", "is a pipe");
}

TEST(SceneReject, UnknownExtension) {
  std::string dir = test::outputDir("SceneReject_Extension");
  writeFile(dir + "/scene.fbx", "whatever");
  expectInputError(dir + "/scene.fbx", "extension");
}

TEST(SceneReject, MissingExternalBuffer) {
  std::string dir = test::outputDir("SceneReject_MissingBuffer");
  MiniGltf g = oneTriangle();
  g.bufferUri = "mesh.bin";
  std::string path = writeGltf(dir, "scene.gltf", g);
  expectInputError(path, "missing buffer");
  expectInputError(path, "mesh.bin");
  // With the .bin present it loads.
  writeFile(dir + "/mesh.bin", g.blob());
  EXPECT_EQ(loadScene(path).triangleCount(), 1u);
  // A .bin far larger than its byteLength is refused from its size, unread
  // (a sparse 64 MiB file: nothing is written to the disk).
  fs::resize_file(dir + "/mesh.bin", uintmax_t(64) << 20);
  expectInputError(path, "holds 67108864 bytes where its byteLength says");
}

TEST(SceneReject, TrianglesBeyondMemoryAreCountedBeforeBuilt) {
  // Twenty nodes instancing a mesh of 1e8 triangles (an accessor without a
  // buffer view: zeros, as glTF allows): 2e9 triangles, refused from the
  // accessors' counts before any is built.
  std::string nodes, roots;
  for (int i = 0; i < 20; ++i) {
    nodes += std::string(i ? ", " : "") + R"({"mesh": 0})";
    roots += std::string(i ? ", " : "") + std::to_string(i);
  }
  const std::string dir = test::outputDir("SceneReject_Instances");
  writeFile(dir + "/many.gltf",
            R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [)" + roots +
                R"(]}], "nodes": [)" + nodes +
                R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
                "accessors": [{"componentType": 5126, "count": 300000000, "type": "VEC3",
                "min": [0, 0, 0], "max": [0, 0, 0]}]})");
  expectInputError(dir + "/many.gltf", "the node tree makes 2000000000 triangles");
}

TEST(SceneReject, BufferUriEscapingTheFolder) {
  std::string dir = test::outputDir("SceneReject_Escape");
  fs::create_directories(dir + "/inner");
  MiniGltf g = oneTriangle();
  writeFile(dir + "/outside.bin", g.blob());  // exists, and must still be refused
  g.bufferUri = "../outside.bin";
  std::string path = writeGltf(dir + "/inner", "escape.gltf", g);
  expectInputError(path, "outside the scene folder");
  expectInputError(path, "../outside.bin");
  g.bufferUri = "sub/%2e%2e/../outside.bin";  // percent-encoded ".."
  path = writeGltf(dir + "/inner", "encoded.gltf", g);
  expectInputError(path, "outside the scene folder");
  g.bufferUri = "/etc/passwd";
  path = writeGltf(dir + "/inner", "absolute.gltf", g);
  expectInputError(path, "outside the scene folder");
  expectInputError(path, "/etc/passwd");
}

TEST(SceneReject, IndexOutOfRange) {
  std::string dir = test::outputDir("SceneReject_Index");
  MiniGltf g = oneTriangle();
  g.indices = {0, 1, 7};
  expectInputError(writeGltf(dir, "index.gltf", g), "out of range");
}

TEST(SceneReject, AccessorOutOfRangeOfBufferView) {
  std::string dir = test::outputDir("SceneReject_Accessor");
  MiniGltf g = oneTriangle();
  std::string j = g.json();
  // Claim 300 positions in a 36-byte view.
  std::string from = "\"count\": 3, \"type\": \"VEC3\"";
  j.replace(j.find(from), from.size(), "\"count\": 300, \"type\": \"VEC3\"");
  writeFile(dir + "/accessor.gltf", j);
  expectInputError(dir + "/accessor.gltf", "out of range");
  // A bufferView beyond its buffer.
  j = g.json();
  from = "\"byteOffset\": 0, \"byteLength\": 36";
  j.replace(j.find(from), from.size(), "\"byteOffset\": 0, \"byteLength\": 3600");
  writeFile(dir + "/view.gltf", j);
  expectInputError(dir + "/view.gltf", "out of range");
}

TEST(SceneReject, NonFiniteVertex) {
  std::string dir = test::outputDir("SceneReject_NaN");
  MiniGltf g = oneTriangle();
  g.positions[4] = std::nanf("");
  expectInputError(writeGltf(dir, "nan.gltf", g), "non-finite");
  g = oneTriangle();
  g.positions[0] = INFINITY;
  expectInputError(writeGltf(dir, "inf.gltf", g), "non-finite");
}

TEST(SceneReject, PointsMode) {
  std::string dir = test::outputDir("SceneReject_Points");
  MiniGltf g = oneTriangle();
  g.mode = 0;
  expectInputError(writeGltf(dir, "points.gltf", g), "unsupported primitive mode");
  g.mode = 1;
  expectInputError(writeGltf(dir, "lines.gltf", g), "unsupported primitive mode");
}

TEST(SceneReject, UnreadableImage) {
  std::string dir = test::outputDir("SceneReject_Image");
  writeFile(dir + "/garbage.png", "this is not a png at all, just bytes");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
  g.extraTop = R"("textures": [{"source": 0}], "images": [{"uri": "garbage.png"}], )";
  std::string path = writeGltf(dir, "image.gltf", g);
  expectInputError(path, "unreadable image");
  expectInputError(path, "garbage.png");
}

/// A 0.3 x 0.2 quad in z = 0, a camera and a point light, under a node at
/// `t` (glTF JSON numbers, so the translation is exact in double).
MiniGltf quadUnderNode(const std::string& t) {
  MiniGltf g;
  g.positions = {0, 0, 0, 0.3f, 0, 0, 0.3f, 0.2f, 0, 0, 0.2f, 0};
  g.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  g.indices = {0, 1, 2, 0, 2, 3};
  g.nodes = R"([{"translation": [)" + t + R"(], "children": [1, 2, 3]}, {"mesh": 0},
      {"camera": 0, "translation": [0.1, 0.1, 2]},
      {"translation": [0.5, 0.25, 1], "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
  g.extraTop =
      R"("cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.01}}],
      "extensionsUsed": ["KHR_lights_punctual"],
      "extensions": {"KHR_lights_punctual": {"lights": [{"type": "point", "intensity": 1}]}},)";
  return g;
}

TEST(SceneGltf, ASceneFarFromTheOriginKeepsItsPrecision) {
  // Projected coordinates (1e6-1e7 m): floats there are 0.06-0.5 m apart, so
  // the loader keeps the scene relative to its centre, computed in double
  // (Scene::origin), and every position keeps float's precision near 0.
  const std::string dir = test::outputDir("SceneGltf_Far");
  const Vec3d t(1234567.25, 89.5, -7654321.0625);
  const Scene far = loadScene(writeGltf(dir, "far.gltf", quadUnderNode("1234567.25, 89.5, -7654321.0625")));
  ASSERT_TRUE(far.rebased());
  const Vec3d corners[4] = {{0, 0, 0}, {0.3f, 0, 0}, {0.3f, 0.2f, 0}, {0, 0.2f, 0}};
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(far.origin[a], t[a] + 0.5 * corners[2][a]);  // the quad's centre
  }
  ASSERT_EQ(far.positions.size(), 4u);
  for (size_t i = 0; i < 4; ++i) {
    const Vec3d world = far.toWorld(far.positions[i]);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(world[a], t[a] + corners[i][a], 1e-7) << i << a;
  }
  EXPECT_NEAR(far.triangleArea(0) + far.triangleArea(1), 0.06, 1e-7);
  ASSERT_EQ(far.lights.size(), 1u);
  ASSERT_EQ(far.cameras.size(), 1u);
  const Vec3d light = far.toWorld(far.lights[0].position);
  const Vec3d camera = far.toWorld(far.cameras[0].position);
  const Vec3d lightAt(0.5, 0.25, 1), cameraAt(0.1, 0.1, 2);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(light[a], t[a] + lightAt[a], 1e-6) << a;
    EXPECT_NEAR(camera[a], t[a] + cameraAt[a], 1e-6) << a;
  }
  // Near the origin nothing moves: the file's coordinates exactly.
  const Scene near = loadScene(writeGltf(dir, "near.gltf", quadUnderNode("1, 2, 3")));
  EXPECT_FALSE(near.rebased());
  EXPECT_EQ(near.positions[2], Vec3(1.3f, 2.2f, 3.0f));
  EXPECT_EQ(near.lights[0].position, Vec3(1.5f, 2.25f, 4.0f));
}

TEST(SceneObj, ASceneFarFromTheOriginKeepsItsPrecision) {
  // The OBJ's own numbers, read again in double (its parser reads float).
  const std::string dir = test::outputDir("SceneObj_Far");
  writeFile(dir + "/far.obj",
            "v 1234567.25 89.5 -7654321.0625\nv 1234567.55 89.5 -7654321.0625\n"
            "v 1234567.55 89.7 -7654321.0625\nv 1234567.25 89.7 -7654321.0625\nf 1 2 3 4\n");
  const Scene far = loadScene(dir + "/far.obj");
  ASSERT_TRUE(far.rebased());
  EXPECT_DOUBLE_EQ(far.origin.x, (1234567.25 + 1234567.55) / 2);
  const Vec3d p2 = far.toWorld(far.positions[2]);
  EXPECT_NEAR(p2.x, 1234567.55, 1e-7);
  EXPECT_NEAR(p2.y, 89.7, 1e-7);
  EXPECT_NEAR(p2.z, -7654321.0625, 1e-7);
  EXPECT_NEAR(far.triangleArea(0) + far.triangleArea(1), 0.06, 1e-7);
}

// --- a sky box taken as the sky ---------------------------------------------

TEST(SkyMesh, ASkyBoxBecomesTheSkyItShows) {
  // A floor under a 100 m sky box whose top is blue and whose sides are
  // orange (one material, a two-texel texture): the box leaves the geometry
  // and its colours go where the floor's centre sees them.
  Scene scene;
  scene.sourcePath = "sky-box scene";
  scene.materials.resize(2);
  scene.materials[0].name = "floor";
  scene.materials[1].name = "sky";
  scene.materials[1].baseColor = {1, 1, 1};
  scene.materials[1].baseColorTexture = 0;
  const Vec3 blue{0.2f, 0.4f, 0.8f}, orange{0.9f, 0.5f, 0.2f};
  Texture colours = Texture::fromLinear(2, 1, {blue, orange});
  scene.textures.push_back(colours);
  auto quad = [&](const Vec3& corner, const Vec3& eu, const Vec3& ev, int material, float u) {
    const uint32_t base = uint32_t(scene.positions.size());
    for (const Vec3& p : {corner, corner + eu, corner + eu + ev, corner + ev}) {
      scene.positions.push_back(p);
      scene.texcoords0.insert(scene.texcoords0.end(), {u, 0.5f});
    }
    for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) scene.indices.push_back(base + i);
    scene.triangleMaterial.insert(scene.triangleMaterial.end(), {material, material});
  };
  quad({-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, 0, 0.25f);
  const float r = 50;
  quad({-r, r, -r}, {2 * r, 0, 0}, {0, 0, 2 * r}, 1, 0.25f);  // top: blue
  for (int side = 0; side < 4; ++side) {                        // sides: orange
    const Vec3 corner = side == 0 ? Vec3{-r, -r, -r} : side == 1 ? Vec3{r, -r, -r}
                      : side == 2 ? Vec3{r, -r, r} : Vec3{-r, -r, r};
    const Vec3 along = side == 0 ? Vec3{2 * r, 0, 0} : side == 1 ? Vec3{0, 0, 2 * r}
                     : side == 2 ? Vec3{-2 * r, 0, 0} : Vec3{0, 0, -2 * r};
    quad(corner, along, {0, 2 * r, 0}, 1, 0.75f);
  }
  skyFromMaterial(scene, "sky", 64);
  ASSERT_EQ(scene.triangleCount(), 2u);
  EXPECT_EQ(scene.positions.size(), 4u);
  EXPECT_EQ(scene.texcoords0.size(), 8u);
  EXPECT_EQ(scene.bounds().upper, Vec3(1, 0, 1));
  ASSERT_TRUE(scene.sky.image);
  const Texture& sky = *scene.sky.image;
  ASSERT_EQ(sky.width, 64);
  ASSERT_EQ(sky.height, 32);
  EXPECT_EQ(scene.sky.radiance, Vec3(1, 1, 1));
  // Rows 0-7 look within 45 degrees of the zenith: the top everywhere; rows
  // 10-15 lower than 54.7 degrees (the top's corners): the sides; the lower
  // half is not used (black).
  for (int x = 0; x < 64; ++x) {
    for (int y = 0; y < 32; ++y) {
      const Vec3 texel = sky.texel(x, y);
      const Vec3 expected = y < 8 ? blue : (y >= 10 && y < 16) ? orange : y >= 16 ? Vec3{} : texel;
      const Vec3 d = texel - expected;
      ASSERT_LT(std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}), 1e-6f)
          << x << ", " << y << ": " << texel.ToString() << " vs " << expected.ToString();
    }
  }
  expectNear(scene.sky.radianceFrom({0, 1, 0}), blue, 1e-6f, "zenith");
  expectNear(scene.sky.radianceFrom(normalize(Vec3{1, 0.05f, 0})), orange, 1e-6f, "horizon");
}

TEST(SkyMesh, NamesWhatIsWrong) {
  Scene scene = test::boxWithTwoBlocks(Bounds3{{0.1f, 0, 0.1f}, {0.3f, 0.2f, 0.3f}},
                                       Bounds3{{0.6f, 0, 0.6f}, {0.8f, 0.5f, 0.8f}});
  scene.sourcePath = "box";
  try {
    skyFromMaterial(scene, "heaven");
    ADD_FAILURE() << "no error for an unknown material";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("no material named 'heaven'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(scene.materials[0].name), std::string::npos) << e.what();
  }
  EXPECT_THROW(skyFromMaterial(scene, scene.materials[0].name), InputError);  // all of it
  // The scene file's extras name it: a glTF whose only mesh is the sky.
  const std::string dir = test::outputDir("SkyMesh_Gltf");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"name": "dome"}])";
  g.extraTop = R"("scenes": [{"nodes": [0], "extras": {"lightoctree_sky_mesh": "dome"}}], )";
  std::string json = g.json();
  json.replace(json.find("\"scenes\": [{\"nodes\": [0]}], "), 28, "");
  writeFile(dir + "/dome.gltf", json);
  expectInputError(dir + "/dome.gltf", "nothing would be left beside the sky mesh");
}

// --- the daylight sky of the scene's sun ---------------------------------------

/// A floor under a sun `elevation` degrees high, `lux` W/m^2 (lx).
Scene sunlitFloor(float elevation, float lux) {
  Scene scene;
  scene.materials.resize(1);
  test::addQuad(scene, {-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, {0, 1, 0}, 0);
  Light sun;
  sun.type = Light::Type::Directional;
  sun.name = "sun";
  const float e = elevation * kPi / 180.0f;
  sun.direction = Vec3{0, -std::sin(e), -std::cos(e)};  // from the south-ish, towards -z
  sun.intensity = lux;
  scene.lights.push_back(sun);
  return scene;
}

double luminanceOf(const Vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

TEST(PhysicalSky, ZenithSunRatioAndShapeAreThoseOfTheModel) {
  const float elevation = 40, turbidity = 3;
  Scene scene = sunlitFloor(elevation, 1000.0f);
  physicalSky(scene, turbidity, 256);
  ASSERT_TRUE(scene.sky.image);
  const Texture& sky = *scene.sky.image;
  const double sunZenith = (90.0 - elevation) * kPi / 180.0;
  const double scale = 1000.0 / directSunIlluminance(sunZenith, turbidity);
  // The zenith: the model's luminance (times the scale) and chromaticity.
  const DaylightZenith z = daylightZenith(sunZenith, turbidity);
  const Vec3 top = scene.sky.radianceFrom({0, 1, 0});
  EXPECT_NEAR(luminanceOf(top), z.luminance * scale, 0.02 * z.luminance * scale);
  const double X = 0.4124564 * top.x + 0.3575761 * top.y + 0.1804375 * top.z;
  const double Y = 0.2126729 * top.x + 0.7151522 * top.y + 0.0721750 * top.z;
  const double Z = 0.0193339 * top.x + 0.1191920 * top.y + 0.9503041 * top.z;
  EXPECT_NEAR(X / (X + Y + Z), z.x, 0.005);
  EXPECT_NEAR(Y / (X + Y + Z), z.y, 0.005);
  EXPECT_GT(z.luminance, 2000.0);  // a clear day's zenith: thousands of cd/m^2
  EXPECT_LT(z.luminance, 12000.0);
  // Brighter around the sun than away from it; black below the horizon.
  const Vec3 towardsSun = scene.lights[0].direction * -1.0f;
  const Vec3 near = normalize(towardsSun + Vec3{0.15f, 0, 0});
  const Vec3 away = normalize(Vec3{0, towardsSun.y, -towardsSun.z});
  EXPECT_GT(luminanceOf(scene.sky.radianceFrom(near)), 3.0 * luminanceOf(scene.sky.radianceFrom(away)));
  EXPECT_EQ(scene.sky.radianceFrom({0, -1, 0}), Vec3(0, 0, 0));
  // The sky on a horizontal plane against the sun's direct light on it: the
  // model gives 0.52 at turbidity 3 and 40 degrees (measured clear skies:
  // 0.2-0.35; docs/scene.md): within a factor of two of what skies do.
  double skyOnFloor = 0;
  for (int y = 0; y < sky.height / 2; ++y) {
    for (int x = 0; x < sky.width; ++x) {
      const Vec3 d = skyPixelDirection(float(x) + 0.5f, float(y) + 0.5f, sky.width, sky.height);
      skyOnFloor += luminanceOf(sky.texel(x, y)) * d.y *
                    skyPixelSolidAngle(y, sky.width, sky.height);
    }
  }
  const double sunOnFloor = 1000.0 * std::sin(elevation * kPi / 180.0);
  EXPECT_GT(skyOnFloor / sunOnFloor, 0.15);
  EXPECT_LT(skyOnFloor / sunOnFloor, 0.7);
  // Linear in the sun: twice the sun, twice the sky.
  Scene brighter = sunlitFloor(elevation, 2000.0f);
  physicalSky(brighter, turbidity, 256);
  EXPECT_NEAR(luminanceOf(brighter.sky.radianceFrom({0, 1, 0})), 2.0 * luminanceOf(top),
              1e-4 * luminanceOf(top));
  // The atmosphere takes more of a low sun: less direct light at 10 degrees.
  EXPECT_LT(directSunIlluminance((90.0 - 10.0) * kPi / 180.0, 3.0),
            0.6 * directSunIlluminance(sunZenith, 3.0));
}

TEST(PhysicalSky, NeedsASunAboveTheHorizon) {
  Scene none = sunlitFloor(40, 1000);
  none.lights.clear();
  none.sourcePath = "no sun";
  EXPECT_THROW(physicalSky(none, 3), InputError);
  Scene night = sunlitFloor(-5, 1000);
  EXPECT_THROW(physicalSky(night, 3), InputError);
  Scene haze = sunlitFloor(40, 1000);
  EXPECT_THROW(physicalSky(haze, 40), InputError);
}

TEST(SceneGltf, CamerasThatCannotShowAnythingAreRefused) {
  // A camera whose up is parallel to its view (here: squashed to nothing
  // along its up), whose far plane is nearer than its near one, or that
  // lies beyond kMaxCoordinate: refused by name instead of a black image.
  const std::string dir = test::outputDir("SceneGltf_Cameras");
  auto withCamera = [&](const std::string& name, const std::string& node,
                        const std::string& perspective) {
    MiniGltf g = oneTriangle();
    g.nodes = R"([{"mesh": 0}, )" + node + "]";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("cameras": [{"type": "perspective", "perspective": )" + perspective + "}], ";
    return writeGltf(dir, name, g);
  };
  const std::string fine = R"({"yfov": 0.8, "znear": 0.1})";
  EXPECT_NO_THROW(loadScene(withCamera("ok.gltf", R"({"camera": 0, "translation": [0, 0, 3]})", fine)));
  expectInputError(withCamera("flat.gltf", R"({"camera": 0, "scale": [1, 0, 1]})", fine),
                   "its up is parallel to its view");
  expectInputError(withCamera("far.gltf", R"({"camera": 0})",
                              R"({"yfov": 0.8, "znear": 1.0, "zfar": 0.5})"),
                   "zfar > znear");
  expectInputError(withCamera("away.gltf", R"({"camera": 0, "translation": [0, 0, 1e19]})", fine),
                   "beyond");
}

TEST(SceneGltf, LightAndMaterialValuesStayInTheirRanges) {
  // glTF's [0, 1] factors are clamped with a warning naming them; a negative
  // emission is taken as 0, warned; intensities and positions beyond what
  // the bake can carry are refused, naming the light (docs/scene.md, "Limits").
  std::string dir = test::outputDir("SceneGltf_ValueRanges");
  auto withLight = [](const std::string& light, const std::string& translation) {
    MiniGltf g = oneTriangle();
    g.material = 0;
    g.materials = R"([{"name": "odd", "emissiveFactor": [1, -0.5, 1],
                       "pbrMetallicRoughness": {"metallicFactor": 1e30, "roughnessFactor": -3}}])";
    g.nodes = R"([{"mesh": 0}, {"name": "L", "translation": )" + translation +
              R"(, "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual":
                    {"lights": [)" + light + R"(]}}, )";
    return g;
  };
  MiniGltf g = withLight(R"({"name": "lamp", "type": "point", "color": [1, -0.5, 1], "intensity": 2})",
                         "[0, 1, 0]");
  const Scene s = loadScene(writeGltf(dir, "odd.gltf", g));
  EXPECT_EQ(s.materials[0].metallic, 1.0f);
  EXPECT_EQ(s.materials[0].roughness, 0.0f);
  EXPECT_EQ(s.materials[0].emission.y, 0.0f);
  EXPECT_EQ(s.lights[0].color.y, 0.0f);
  std::string all;
  for (const std::string& w : s.warnings) all += w + "\n";
  EXPECT_NE(all.find("material 'odd' metallic is 1e+30, outside [0, 1]"), std::string::npos) << all;
  EXPECT_NE(all.find("material 'odd' roughness is -3"), std::string::npos) << all;
  EXPECT_NE(all.find("material 'odd' has a negative emission"), std::string::npos) << all;
  EXPECT_NE(all.find("light 'L' colour channel 1 is -0.5"), std::string::npos) << all;
  expectInputError(
      writeGltf(dir, "bright.gltf",
                withLight(R"({"type": "point", "intensity": 1e37})", "[0, 1, 0]")),
      "light 'L' has intensity 1e+37");
  expectInputError(
      writeGltf(dir, "far.gltf", withLight(R"({"type": "point", "intensity": 1})", "[1e19, 0, 0]")),
      "light 'L' lies at");
}

TEST(SceneGltf, MissingTextureFileIsWarnedOnceByName) {
  // An asset copied without one of its textures: the scene loads, the
  // materials using it keep their factors, and the warning names the file
  // once, however many materials use it.
  std::string dir = test::outputDir("SceneGltf_MissingTexture");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1],
                     "baseColorTexture": {"index": 0}}, "normalTexture": {"index": 0}}])";
  g.extraTop = R"("textures": [{"source": 0}], "images": [{"uri": "absent.png"}], )";
  const Scene s = loadScene(writeGltf(dir, "absent.gltf", g));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("'absent.png'"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("missing"), std::string::npos) << s.warnings[0];
  EXPECT_EQ(s.materials[0].baseColorTexture, -1);
  EXPECT_EQ(s.materials[0].normalTexture, -1);
  expectNear(s.materials[0].baseColor, {0.5f, 0.25f, 1.0f}, 1e-6f);
}

// COLOR_0 multiplies the base colour and its alpha (glTF 2.0, "Metallic-
// Roughness Material"): as normalized unsigned bytes (VEC4) or floats
// (VEC3, alpha 1); a primitive without one is white. Both tracers read it
// through Scene::albedo and Scene::coverage (the GL renderer through its
// vertices, test RenderImage.VertexColoursMultiplyTheBaseColour).
TEST(SceneGltf, VertexColoursMultiplyTheBaseColour) {
  std::string dir = test::outputDir("SceneGltf_VertexColors");
  std::string blob;
  append(blob, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});                          // 0, 36 B
  append(blob, std::vector<uint8_t>{255, 0, 0, 255, 0, 255, 0, 128, 0, 0, 255, 0});  // 36, 12 B
  append(blob, std::vector<float>{0.5f, 0.25f, 1, 1, 1, 1, 0, 0, 0});                   // 48, 36 B
  std::ostringstream os;
  os << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 0.8]}, "alphaMode": "BLEND"}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}, "material": 0},
                               {"attributes": {"POSITION": 0, "COLOR_0": 2}, "material": 0},
                               {"attributes": {"POSITION": 0}, "material": 0}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5121, "normalized": true, "count": 3, "type": "VEC4"},
                  {"bufferView": 2, "componentType": 5126, "count": 3, "type": "VEC3"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 12},
                    {"buffer": 0, "byteOffset": 48, "byteLength": 36}],
    "buffers": [{"byteLength": )"
     << blob.size() << R"(, "uri": "data:application/octet-stream;base64,)" << base64(blob)
     << R"("}]})";
  writeFile(dir + "/colors.gltf", os.str());
  const Scene s = loadScene(dir + "/colors.gltf");
  ASSERT_EQ(s.triangleCount(), 3u);
  ASSERT_EQ(s.colors.size(), 4 * s.positions.size());
  // Triangle 0 at its corner 0 (red), at corner 1 (green, alpha 128/255).
  expectNear(s.albedo(0, 0, 0), {0.5f, 0, 0}, 1e-6f, "red corner");
  expectNear(s.albedo(0, 1, 0), {0, 1, 0}, 1e-6f, "green corner");
  EXPECT_NEAR(s.coverage(0, 1, 0), 0.8f * 128.0f / 255.0f, 1e-6f);
  EXPECT_NEAR(s.coverage(0, 0, 1), 0.0f, 1e-6f) << "blue corner: alpha 0";
  // Triangle 1: float RGB, alpha 1; halfway along its first edge.
  expectNear(s.albedo(1, 0, 0), {0.25f, 0.25f, 1}, 1e-6f, "float colour");
  expectNear(s.albedo(1, 0.5f, 0), {0.375f, 0.625f, 1}, 1e-6f, "interpolated");
  EXPECT_NEAR(s.coverage(1, 0.3f, 0.3f), 0.8f, 1e-6f);
  // Triangle 2: no COLOR_0, white.
  expectNear(s.albedo(2, 0.2f, 0.3f), {0.5f, 1, 1}, 1e-6f, "no colour");
  EXPECT_NEAR(s.coverage(2, 0.2f, 0.3f), 0.8f, 1e-6f);
}

// Extensions: one the file requires and the loader does not read is
// refused by name, with what to do (a Draco file failed on its accessors'
// missing buffer views, naming neither); one it only uses is a warning;
// one the loader reads may be required.
TEST(SceneGltf, ExtensionsTheLoaderDoesNotReadAreNamed) {
  std::string dir = test::outputDir("SceneGltf_Extensions");
  MiniGltf draco = oneTriangle();
  draco.extraTop = R"("extensionsUsed": ["KHR_draco_mesh_compression"],
                      "extensionsRequired": ["KHR_draco_mesh_compression"], )";
  expectInputError(writeGltf(dir, "draco.gltf", draco),
                   "requires the glTF extension KHR_draco_mesh_compression");
  expectInputError(writeGltf(dir, "draco.gltf", draco), "uncompressed");
  MiniGltf webp = oneTriangle();
  webp.extraTop = R"("extensionsRequired": ["EXT_texture_webp"], )";
  expectInputError(writeGltf(dir, "webp.gltf", webp), "PNG or JPEG");

  MiniGltf used = oneTriangle();
  used.extraTop = R"("extensionsUsed": ["KHR_materials_clearcoat", "KHR_texture_transform"], )";
  const Scene s = loadScene(writeGltf(dir, "clearcoat.gltf", used));
  EXPECT_EQ(s.triangleCount(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("KHR_materials_clearcoat, which is not read"), std::string::npos)
      << s.warnings[0];

  // The archived specular-glossiness extension is read approximately, as a
  // dielectric, with a warning, even where the file requires it.
  MiniGltf sg = oneTriangle();
  sg.material = 0;
  sg.extraTop = R"("extensionsUsed": ["KHR_materials_pbrSpecularGlossiness"],
                   "extensionsRequired": ["KHR_materials_pbrSpecularGlossiness"], )";
  sg.materials = R"([{"pbrMetallicRoughness": {"metallicFactor": 1},
                      "extensions": {"KHR_materials_pbrSpecularGlossiness": {
                        "diffuseFactor": [0.2, 0.4, 0.6, 0.5], "glossinessFactor": 0.3,
                        "specularFactor": [1, 0.8, 0.2]}}}])";
  const Scene g = loadScene(writeGltf(dir, "specgloss.gltf", sg));
  ASSERT_EQ(g.materials.size(), 1u);
  expectNear(g.materials[0].baseColor, {0.2f, 0.4f, 0.6f}, 1e-6f, "diffuse");
  EXPECT_FLOAT_EQ(g.materials[0].baseAlpha, 0.5f);
  EXPECT_FLOAT_EQ(g.materials[0].roughness, 0.7f);
  EXPECT_EQ(g.materials[0].metallic, 0.0f);
  ASSERT_EQ(g.warnings.size(), 1u);
  EXPECT_NE(g.warnings[0].find("read approximately"), std::string::npos) << g.warnings[0];
  sg.materials = R"([{"extensions": {"KHR_materials_pbrSpecularGlossiness": {"glossinessFactor": 2}}}])";
  expectInputError(writeGltf(dir, "badgloss.gltf", sg), "glossinessFactor must lie in [0, 1]");

  MiniGltf read = oneTriangle();
  read.extraTop = R"("extensionsUsed": ["KHR_texture_transform", "KHR_mesh_quantization"],
                     "extensionsRequired": ["KHR_texture_transform", "KHR_mesh_quantization"], )";
  const Scene r = loadScene(writeGltf(dir, "read.gltf", read));
  EXPECT_EQ(r.triangleCount(), 1u);
  EXPECT_TRUE(r.warnings.empty());
}

TEST(SceneReject, TruncatedGlb) {
  std::string dir = test::outputDir("SceneReject_Glb");
  std::string glb = oneTriangle().glb();
  for (size_t keep :
       {size_t(0), size_t(10), size_t(19), size_t(40), glb.size() / 2, glb.size() - 4}) {
    std::string name = "cut" + std::to_string(keep) + ".glb";
    writeFile(dir + "/" + name, glb.substr(0, keep));
    expectInputError(dir + "/" + name, "truncated");
  }
  // Garbage with the right magic and sizes that lie.
  std::string lying = glb;
  uint32_t huge = 0x7fffffff;
  std::memcpy(&lying[12], &huge, 4);
  writeFile(dir + "/lying.glb", lying);
  expectInputError(dir + "/lying.glb", "truncated");
  // And the shared scene, truncated, if it is there.
  std::string shared = test::sharedScenesDir() + "/composed/cornell-box.glb";
  if (fs::exists(shared)) {
    std::string bytes = readFile(shared);
    writeFile(dir + "/cornell-half.glb", bytes.substr(0, bytes.size() / 2));
    expectInputError(dir + "/cornell-half.glb", "truncated");
  }
}

TEST(SceneReject, NoTriangles) {
  std::string dir = test::outputDir("SceneReject_Empty");
  MiniGltf g = oneTriangle();
  g.indices = {0, 1, 1};  // degenerate: dropped
  expectInputError(writeGltf(dir, "degenerate.gltf", g), "no triangles");
  writeFile(dir + "/empty.obj", "# nothing\nv 0 0 0\n");
  expectInputError(dir + "/empty.obj", "no triangles");
}

TEST(SceneReject, InvalidJson) {
  std::string dir = test::outputDir("SceneReject_Json");
  writeFile(dir + "/broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": [");
  expectInputError(dir + "/broken.gltf", "invalid glTF");
}

TEST(SceneReject, NodeCycle) {
  std::string dir = test::outputDir("SceneReject_Cycle");
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "children": [1]}, {"children": [0]}])";
  expectInputError(writeGltf(dir, "cycle.gltf", g), "not a tree");
}

// --- OBJ ------------------------------------------------------------------------

TEST(SceneObj, MaterialMappingAndGrouping) {
  std::string dir = test::outputDir("SceneObj_Materials");
  writeFile(dir + "/m.mtl",
            "newmtl shiny\nKd 0.5 0.25 0.125\nKs 0.5 0.625 0.25\nNs 98\nd 0.25\nNi 1.4\n"
            "newmtl lamp\nKd 0 0 0\nKe 2 3 4\n");
  writeFile(
      dir + "/scene.obj",
      "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nvt 0 0\nvt 1 0\n"
      "usemtl lamp\nf 1 2 3\nusemtl shiny\nf 1/1/1 2/2/1 3/2/1 4/1/1\nusemtl lamp\nf 1 3 4\n");
  Scene s = loadScene(dir + "/scene.obj");
  SCOPED_TRACE(s.ToString());
  ASSERT_EQ(s.materials.size(), 2u);
  const Material& shiny = s.materials[0];
  EXPECT_EQ(shiny.name, "shiny");
  expectNear(shiny.baseColor, {0.5f, 0.25f, 0.125f}, 1e-6f);
  EXPECT_NEAR(shiny.roughness, std::sqrt(2.0f / 100.0f), 1e-6f);
  EXPECT_FLOAT_EQ(shiny.specular, 0.625f);  // the largest channel of Ks
  EXPECT_FLOAT_EQ(s.materials[1].specular, 0.0f);  // no Ks: Lambertian
  EXPECT_NEAR(shiny.transmission, 0.75f, 1e-6f);
  EXPECT_NEAR(shiny.ior, 1.4f, 1e-6f);
  expectNear(s.materials[1].emission, {2, 3, 4}, 1e-6f);
  ASSERT_EQ(s.triangleCount(), 4u);  // the quad is split in two
  EXPECT_EQ(s.triangleMaterial, (std::vector<int32_t>{0, 0, 1, 1}));
  for (size_t t = 0; t < 4; ++t) expectNear(s.faceNormal(t), {0, 0, 1}, 1e-6f);
  ASSERT_EQ(s.normals.size(), s.positions.size());
  for (const Vec3& n : s.normals) expectNear(n, {0, 0, 1}, 1e-6f, "normal");
  ASSERT_EQ(s.texcoords0.size(), 2 * s.positions.size());
}

TEST(SceneObj, UndefinedMaterialIsWarnedOnceByName) {
  // usemtl of a name the .mtl does not define (a real asset's "Texture1"):
  // the faces get the default material, and the user hears of it once.
  std::string dir = test::outputDir("SceneObj_UndefinedMaterial");
  writeFile(dir + "/m.mtl", "newmtl wall\nKd 0.5 0.5 0.5\n");
  writeFile(dir + "/scene.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "usemtl Texture1\nf 1 2 3\nusemtl wall\nf 1 3 4\nusemtl Texture1\nf 2 3 4\n");
  Scene s = loadScene(dir + "/scene.obj");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("usemtl 'Texture1' names no material"), std::string::npos)
      << s.warnings[0];
  ASSERT_EQ(s.triangleCount(), 3u);
  int defaults = 0;
  for (int32_t m : s.triangleMaterial) defaults += s.materials[size_t(m)].name == "default";
  EXPECT_EQ(defaults, 2);
}

// OBJ vertex colours (`v x y z r g b`) multiply the base colour like glTF's
// COLOR_0, when every vertex has one, read as the display (sRGB) values the
// tools that write them mean; a file where only some have one keeps none
// (white).
TEST(SceneObj, VertexColoursMultiplyTheBaseColour) {
  std::string dir = test::outputDir("SceneObj_VertexColors");
  writeFile(dir + "/m.mtl", "newmtl a\nKd 0.5 0.5 0.5\n");
  writeFile(dir + "/c.obj",
            "mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 0.5 0\nv 0 1 0 0 0 1\nusemtl a\nf 1 2 3\n");
  const Scene s = loadScene(dir + "/c.obj");
  ASSERT_EQ(s.colors.size(), 4 * s.positions.size());
  expectNear(s.albedo(0, 0, 0), {0.5f, 0, 0}, 1e-6f, "red corner");
  // Display values: 0.5 is sRGB, 0.214 linear.
  expectNear(s.albedo(0, 1, 0), {0, 0.5f * 0.21404f, 0}, 1e-5f, "sRGB 0.5 corner");
  writeFile(dir + "/some.obj",
            "mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  const Scene some = loadScene(dir + "/some.obj");
  EXPECT_TRUE(some.colors.empty());
  expectNear(some.albedo(0, 0, 0), {0.5f, 0.5f, 0.5f}, 1e-6f, "no colours");
}

TEST(SceneObj, MissingTextureFileIsWarnedOnceByName) {
  std::string dir = test::outputDir("SceneObj_MissingTexture");
  writeFile(dir + "/m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd gone.png\n"
                            "newmtl b\nKd 0.2 0.2 0.2\nmap_Kd gone.png\n");
  writeFile(dir + "/scene.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\n");
  Scene s = loadScene(dir + "/scene.obj");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("map_Kd 'gone.png' is missing"), std::string::npos) << s.warnings[0];
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].baseColorTexture, -1);
  EXPECT_EQ(s.materials[1].baseColorTexture, -1);
}

TEST(SceneObj, Rejects) {
  std::string dir = test::outputDir("SceneObj_Rejects");
  fs::create_directories(dir + "/inner");
  writeFile(dir + "/evil.mtl", "newmtl x\nKd 1 1 1\n");
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  writeFile(dir + "/inner/escape.obj", "mtllib ../evil.mtl\n" + tri + "usemtl x\nf 1 2 3\n");
  expectInputError(dir + "/inner/escape.obj", "outside the scene folder");
  writeFile(dir + "/inner/absolute.obj", "mtllib /etc/passwd\n" + tri + "f 1 2 3\n");
  expectInputError(dir + "/inner/absolute.obj", "outside the scene folder");
  writeFile(dir + "/inner/nomtl.obj", "mtllib absent.mtl\n" + tri + "f 1 2 3\n");
  expectInputError(dir + "/inner/nomtl.obj", "missing material library");
  writeFile(dir + "/inner/index.obj", tri + "f 1 2 9\n");
  expectInputError(dir + "/inner/index.obj", "out of range");
  writeFile(dir + "/inner/quad.obj", tri + "f 1 2 3 12\n");
  expectInputError(dir + "/inner/quad.obj", "out of range");
  writeFile(dir + "/inner/nan.obj", "v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n");
  expectInputError(dir + "/inner/nan.obj", "non-finite");
  writeFile(dir + "/inner/tex.mtl", "newmtl t\nmap_Kd garbage.png\n");
  writeFile(dir + "/inner/garbage.png", "not an image");
  writeFile(dir + "/inner/tex.obj", "mtllib tex.mtl\n" + tri + "usemtl t\nf 1 2 3\n");
  expectInputError(dir + "/inner/tex.obj", "unreadable image");
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

/// An uncompressed 32-bit TGA (stb_image reads it with its alpha channel),
/// pixels RGBA top row first.
std::string tgaRgba(int width, int height, const std::vector<uint8_t>& rgba) {
  std::string header(18, '\0');
  header[2] = 2;  // uncompressed true colour
  header[12] = char(width & 255);
  header[13] = char(width >> 8);
  header[14] = char(height & 255);
  header[15] = char(height >> 8);
  header[16] = 32;
  header[17] = 0x28;  // 8 alpha bits, origin top-left
  std::string body;
  for (size_t i = 0; i + 3 < rgba.size(); i += 4) {
    body += char(rgba[i + 2]);  // TGA stores BGRA
    body += char(rgba[i + 1]);
    body += char(rgba[i]);
    body += char(rgba[i + 3]);
  }
  return header + body;
}

// glTF alphaMode, alphaCutoff, the base colour's alpha, the texture's alpha
// channel and the emissive texture are read; Scene::coverage and
// Scene::emission apply them.
TEST(SceneGltf, AlphaModesAndEmissiveTexture) {
  std::string dir = test::outputDir("SceneGltf_Alpha");
  // 2x1: left texel opaque white, right texel alpha 64/255; colours
  // (255, 0, 0) and (0, 255, 0) for the emissive use.
  writeFile(dir + "/alpha.tga", tgaRgba(2, 1, {255, 0, 0, 255, 0, 255, 0, 64}));
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"alphaMode": "MASK", "alphaCutoff": 0.4,
    "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8], "baseColorTexture": {"index": 0}},
    "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0}}])";
  g.extraTop = R"("textures": [{"source": 0}], "images": [{"uri": "alpha.tga"}], )";
  Scene s = loadScene(writeGltf(dir, "alpha.gltf", g));
  ASSERT_EQ(s.materials.size(), 1u);
  const Material& m = s.materials[0];
  EXPECT_EQ(m.alphaMode, AlphaMode::Mask);
  EXPECT_FLOAT_EQ(m.alphaCutoff, 0.4f);
  EXPECT_FLOAT_EQ(m.baseAlpha, 0.8f);
  ASSERT_EQ(m.emissiveTexture, m.baseColorTexture) << "one sRGB decoding of the image, shared";
  const Texture& t = s.textures[size_t(m.baseColorTexture)];
  ASSERT_TRUE(t.hasAlpha());
  ASSERT_EQ(t.texelCount(), 2u);
  EXPECT_NEAR(t.alphaAt(0), 1.0f, 1e-6f);
  EXPECT_NEAR(t.alphaAt(1), 64.0f / 255.0f, 1e-6f) << "alpha is linear, not sRGB-decoded";
  // Vertex UVs of oneTriangle: find a barycentric point on each texel.
  s.texcoords0 = {0.25f, 0.5f, 0.75f, 0.5f, 0.25f, 0.5f};
  // b1 = 0: u = 0.25 (opaque texel) -> 0.8 >= 0.4: covered.
  EXPECT_EQ(s.coverage(0, 0, 0), 1.0f);
  // b1 = 1: u = 0.75: 0.8 * 0.251 = 0.2 < 0.4: cut out.
  EXPECT_EQ(s.coverage(0, 1, 0), 0.0f);
  s.materials[0].alphaMode = AlphaMode::Blend;
  EXPECT_NEAR(s.coverage(0, 1, 0), 0.8f * 64.0f / 255.0f, 1e-6f);
  s.materials[0].alphaMode = AlphaMode::Opaque;
  EXPECT_EQ(s.coverage(0, 1, 0), 1.0f);
  expectNear(s.emission(0, 0, 0), {1, 0, 0}, 1e-6f, "emission on the red texel");
  expectNear(s.emission(0, 1, 0), {0, 1, 0}, 1e-6f, "emission on the green texel");
  // Mean over the triangle: u = 0.25 + b1 / 2 runs from the red texel's
  // centre to the green one's, filtered bilinearly (glTF's default sampler),
  // so red = 1 - b1, whose mean over the triangle is 2/3; 64 stratified
  // samples.
  const Vec3 mean = s.triangleEmission(0);
  EXPECT_NEAR(mean.x + mean.y, 1.0f, 1e-5f);
  EXPECT_NEAR(mean.x, 2.0f / 3.0f, 0.03f);
}

TEST(SceneGltf, UnknownAlphaModeIsRefused) {
  std::string dir = test::outputDir("SceneGltf_BadAlpha");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"alphaMode": "DITHER"}])";
  try {
    loadScene(writeGltf(dir, "bad.gltf", g));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("alphaMode 'DITHER'"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// glTF TANGENT is read per vertex, turned by the node's transform, and its
// w flips under a mirroring node (the winding flips with it).
TEST(SceneGltf, TangentsAreReadAndTransformed) {
  std::string dir = test::outputDir("SceneGltf_Tangent");
  MiniGltf g = oneTriangle();
  g.tangents = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
  g.nodes = R"([{"mesh": 0, "rotation": [0, 0, 0.7071068, 0.7071068]}])";  // 90 deg about z
  Scene s = loadScene(writeGltf(dir, "tangent.gltf", g));
  ASSERT_EQ(s.tangents.size(), 12u);
  EXPECT_NEAR(s.tangents[0], 0.0f, 1e-5f);
  EXPECT_NEAR(s.tangents[1], 1.0f, 1e-5f);  // +x turned to +y
  EXPECT_EQ(s.tangents[3], 1.0f);
  g.nodes = R"([{"mesh": 0, "scale": [-1, 1, 1]}])";
  Scene m = loadScene(writeGltf(dir, "mirror.gltf", g));
  ASSERT_EQ(m.tangents.size(), 12u);
  EXPECT_EQ(m.tangents[3], -1.0f) << "a mirroring node flips the bitangent sign";
}

}  // namespace
}  // namespace lo


namespace lo {
namespace {

// Hardening (docs/scene.md, "Limits"): inputs that used to crash or load as
// a silently wrong scene are refused with a message naming the file and the
// problem; a base colour above 1 is clamped with a warning.
TEST(SceneLimits, DeepJsonIsRefusedBeforeParsing) {
  std::string dir = test::outputDir("SceneLimits.Deep");
  MiniGltf g = oneTriangle();
  std::string deep(100000, '[');
  deep += std::string(100000, ']');
  g.extraTop = "\"extras\": " + deep + ", ";
  try {
    loadScene(writeGltf(dir, "deep.gltf", g));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("deep.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("nested more than"), std::string::npos) << msg;
  }
  // Brackets inside strings do not count.
  g.extraTop = "\"extras\": {\"note\": \"" + std::string(1000, '[') + "\"}, ";
  EXPECT_EQ(loadScene(writeGltf(dir, "brackets.gltf", g)).triangleCount(), 1u);
}

TEST(SceneLimits, IndexBeyondInt32IsRefused) {
  std::string dir = test::outputDir("SceneLimits.Index");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{}])";
  std::string json = g.json();
  const std::string from = "\"material\": 0", to = "\"material\": 4294967299";  // 2^32 + 3
  ASSERT_NE(json.find(from), std::string::npos);
  json.replace(json.find(from), from.size(), to);
  writeFile(dir + "/index.gltf", json);
  try {
    loadScene(dir + "/index.gltf");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("/meshes/0/primitives/0/material = 4294967299 is out of range"),
              std::string::npos)
        << msg;
  }
}

TEST(SceneLimits, CoordinatesBeyondTheTracersRangeAreRefused) {
  std::string dir = test::outputDir("SceneLimits.Far");
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "translation": [1e20, 0, 0]}])";
  try {
    loadScene(writeGltf(dir, "far.gltf", g));
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("far.gltf"), std::string::npos) << msg;
    EXPECT_NE(msg.find("beyond 1e+12 scene units"), std::string::npos) << msg;
  }
  g.nodes = R"([{"mesh": 0, "translation": [1e9, 0, 0]}])";  // far, but representable
  EXPECT_EQ(loadScene(writeGltf(dir, "farish.gltf", g)).triangleCount(), 1u);
}

TEST(SceneLimits, BaseColourAboveOneIsClampedWithAWarning) {
  std::string dir = test::outputDir("SceneLimits.Bright");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"name": "hot", "pbrMetallicRoughness": {"baseColorFactor": [1000, 0.5, 1.5, 1]}}])";
  const Scene s = loadScene(writeGltf(dir, "bright.gltf", g));
  EXPECT_EQ(s.materials[0].baseColor, Vec3(1.0f, 0.5f, 1.0f));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("material 'hot'"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("clamped"), std::string::npos) << s.warnings[0];
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}])";
  EXPECT_TRUE(loadScene(writeGltf(dir, "fine.gltf", g)).warnings.empty());
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

/// A 2 x 2 texture of texel values 0, 1 (top row), 2, 3 (bottom row).
Texture fourTexels(const TextureSampler& sampler) {
  Texture t = Texture::fromLinear(2, 2, {Vec3(0.0f), Vec3(1.0f), Vec3(2.0f), Vec3(3.0f)});
  t.sampler = sampler;
  return t;
}

TEST(SceneTexture, SamplerFiltersAndWrapsAsGltfSays) {
  TextureSampler nearest;
  nearest.magFilter = TextureSampler::kNearest;
  const Texture n = fourTexels(nearest);
  EXPECT_EQ(n.lookup(0.25f, 0.25f).x, 0.0f);
  EXPECT_EQ(n.lookup(0.74f, 0.26f).x, 1.0f);
  EXPECT_EQ(n.lookup(0.51f, 0.99f).x, 3.0f);
  EXPECT_EQ(n.lookup(1.25f, -0.75f).x, 0.0f);  // repeat
  // Bilinear (glTF's default): texel centres exact, the middle the mean.
  const Texture b = fourTexels(TextureSampler{});
  EXPECT_FLOAT_EQ(b.lookup(0.25f, 0.25f).x, 0.0f);
  EXPECT_FLOAT_EQ(b.lookup(0.75f, 0.75f).x, 3.0f);
  EXPECT_FLOAT_EQ(b.lookup(0.5f, 0.25f).x, 0.5f);
  EXPECT_FLOAT_EQ(b.lookup(0.5f, 0.5f).x, 1.5f);
  // Repeat: across the left edge the right column's texels blend in.
  EXPECT_FLOAT_EQ(b.lookup(0.0f, 0.25f).x, 0.5f);
  // Clamp to edge: the edge texel alone, however far out.
  TextureSampler clamp;
  clamp.wrapS = clamp.wrapT = TextureSampler::kClampToEdge;
  const Texture c = fourTexels(clamp);
  EXPECT_FLOAT_EQ(c.lookup(0.0f, 0.25f).x, 0.0f);
  EXPECT_FLOAT_EQ(c.lookup(-7.0f, 0.25f).x, 0.0f);
  EXPECT_FLOAT_EQ(c.lookup(9.0f, 0.75f).x, 3.0f);
  // Mirrored repeat: [1, 2) is [0, 1) backwards.
  TextureSampler mirror = nearest;
  mirror.wrapS = TextureSampler::kMirroredRepeat;
  const Texture m = fourTexels(mirror);
  EXPECT_EQ(m.lookup(1.25f, 0.25f).x, 1.0f);
  EXPECT_EQ(m.lookup(1.75f, 0.25f).x, 0.0f);
  EXPECT_EQ(m.lookup(-0.25f, 0.25f).x, 0.0f);
  // Non-finite or huge coordinates stay inside the texture.
  EXPECT_TRUE(isFinite(b.lookup(NAN, 1e30f)));
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

TEST(SkySampler, DensityIntegratesToOneAndMatchesItsDraws) {
  // A 16 x 8 sky image with one bright texel (a sun) and a dim rest: the
  // density over the upper hemisphere integrates to 1, the draws report the
  // density pdf() gives their direction, and the sun's texel gets its share.
  std::vector<Vec3> radiance(16 * 8, Vec3(0.2f));
  radiance[2 * 16 + 5] = Vec3(500.0f);
  auto image = std::make_shared<Texture>(Texture::fromLinear(16, 8, radiance));
  Sky sky;
  sky.image = image;
  sky.radiance = {1, 1, 1};
  const SkySampler sampler(sky);
  ASSERT_FALSE(sampler.empty());
  double integral = 0;
  const int steps = 512;
  for (int i = 0; i < steps; ++i) {
    const float y = (float(i) + 0.5f) / float(steps);  // cos theta, uniform in solid angle
    for (int j = 0; j < 2 * steps; ++j) {
      const float phi = 2.0f * kPi * (float(j) + 0.5f) / float(2 * steps);
      const float r = std::sqrt(1.0f - y * y);
      integral += sampler.pdf(Vec3(r * std::cos(phi), y, r * std::sin(phi)));
    }
  }
  integral *= 2.0 * kPi / (double(steps) * double(2 * steps));
  EXPECT_NEAR(integral, 1.0, 0.01);
  Rng rng(3, 9);
  int sun = 0;
  const int draws = 20000;
  for (int i = 0; i < draws; ++i) {
    const double u0 = uniform53(rng);
    const float u1 = rng.uniform(), u2 = rng.uniform();
    Vec3 towards;
    float pdf = 0;
    ASSERT_TRUE(sampler.sample(u0, u1, u2, towards, pdf));
    ASSERT_GT(towards.y, 0.0f);
    EXPECT_NEAR(sampler.pdf(towards), pdf, 1e-3f * pdf);
    int x = 0, y = 0;
    skyPixelOf(towards, 16, 8, x, y);
    sun += x == 5 && y == 2;
  }
  // The sun texel's share of radiance x solid angle.
  double total = 0, sunShare = 0;
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 16; ++x) {
      const double w = average(image->texel(x, y)) * skyPixelSolidAngle(y, 16, 8);
      total += w;
      if (x == 5 && y == 2) sunShare = w;
    }
  }
  EXPECT_NEAR(double(sun) / draws, sunShare / total, 0.01);
  // A uniform sky: the upper hemisphere, 1 / 2 pi.
  Sky uniform;
  uniform.radiance = {1, 1, 1};
  EXPECT_FLOAT_EQ(SkySampler(uniform).pdf(Vec3(0, 1, 0)), 1.0f / (2.0f * kPi));
  EXPECT_EQ(SkySampler(uniform).pdf(Vec3(0, -1, 0)), 0.0f);
  EXPECT_TRUE(SkySampler(Sky{}).empty());
}

TEST(Scene, ReleasedTexelsLeaveEmptyTexturesWithTheirSamplers) {
  Scene scene;
  Material m;
  m.baseColor = Vec3(1.0f);
  m.baseColorTexture = 0;
  scene.materials.push_back(m);
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  scene.texcoords0 = {0, 0, 1, 0, 1, 1, 0, 1};
  scene.textures.push_back(Texture::fromLinear(2, 1, {Vec3(0.2f), Vec3(0.4f)}));
  scene.textures[0].name = "map";
  scene.textures[0].sampler.wrapS = 33071;  // GL_CLAMP_TO_EDGE
  EXPECT_NEAR(scene.albedo(0, 0.5f, 0.0f).x, 0.3f, 0.05f);
  scene.releaseTexels();
  ASSERT_EQ(scene.textures.size(), 1u);
  EXPECT_TRUE(scene.textures[0].empty());
  EXPECT_EQ(scene.textures[0].byteSize(), 0u);
  EXPECT_EQ(scene.textures[0].name, "map");
  EXPECT_EQ(scene.textures[0].sampler.wrapS, 33071);
  EXPECT_EQ(scene.albedo(0, 0.5f, 0.0f), Vec3(1.0f)) << "an empty texture reads white";
}

// A scene without a camera is framed from the side its surfaces face: a room
// corner (a floor and two walls facing in) from its open octant, so that the
// camera sees their fronts (framed from +Z it saw the backs of a wall, black
// in every renderer); a closed room, whose normals cancel, from +Z as before;
// a scene's own camera first.
TEST(SceneCamera, FramingLooksAtTheFrontFaces) {
  Scene corner;
  corner.materials.push_back(Material{});
  const Vec3 normals[3] = {{0, 1, 0}, {1, 0, 0}, {0, 0, 1}};
  test::addQuad(corner, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, normals[0], 0);  // floor
  test::addQuad(corner, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, normals[1], 0);  // wall x = 0
  test::addQuad(corner, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, normals[2], 0);  // wall z = 0
  const Vec3 side = viewSide(corner);
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(side[a], 1.0f / std::sqrt(3.0f), 1e-5f) << a;
  const PinholeCamera camera = PinholeCamera::framing(corner, 0.8f);
  for (const Vec3& n : normals) EXPECT_LT(dot(camera.forward, n), -0.5f) << "sees the fronts";
  EXPECT_GT(length(camera.eye - corner.bounds().center()), 0.5f * length(corner.bounds().extent()));

  // A ground alone faces straight up: seen from 60 degrees above the
  // horizon, from the +Z side, not from straight above.
  Scene ground;
  ground.materials.push_back(Material{});
  test::addQuad(ground, {-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, {0, 1, 0}, 0);
  const Vec3 above = viewSide(ground);
  EXPECT_NEAR(above.y, std::sqrt(3.0f) / 2, 1e-5f);
  EXPECT_NEAR(above.z, 0.5f, 1e-5f);
  EXPECT_NEAR(above.x, 0.0f, 1e-6f);

  Scene room;
  room.materials.push_back(Material{});
  test::addClosedBox(room, {0, 0, 0}, {1, 1, 1}, 0);
  EXPECT_EQ(viewSide(room), Vec3(0, 0, 1));
  EXPECT_EQ(PinholeCamera::ofScene(room, 0.8f).forward, Vec3(0, 0, -1));

  Camera own;
  own.position = {0.5f, 0.5f, 0.5f};
  own.forward = {1, 0, 0};
  own.up = {0, 1, 0};
  own.yfov = 0.5f;
  room.cameras.push_back(own);
  EXPECT_EQ(PinholeCamera::ofScene(room, 0.8f).forward, Vec3(1, 0, 0));
  EXPECT_EQ(PinholeCamera::ofScene(room, 0.8f).yfov, 0.5f);
}

}  // namespace
}  // namespace lo
