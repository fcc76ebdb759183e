// The glTF loader's geometry: node transforms (TRS, matrices, mirrors, far
// from the origin), the region marker, strips and fans, sparse accessors,
// .glb, tangents, and the extensions it reads, warns of or refuses.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "scene/scene.h"
#include "scene/scene_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

using namespace test;  // scene_fixture.h

TEST_F(SceneGltf, NodeTransformsTrsAndMatrix) {
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
  Scene s = loadScene(write("transform.gltf", g));
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
TEST_F(SceneGltf, RegionMarkerNodeGivesTheRegionAndIsNoGeometry) {
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0},
                {"mesh": 0, "translation": [5, 6, 7], "scale": [2, 3, 4],
                 "extras": {"lightoctree_region": true}},
                {"mesh": 0, "translation": [-1, 0, 0], "extras": {"lightoctree_region": false}}])";
  g.sceneNodes = "[0, 1, 2]";
  Scene s = loadScene(write("region.gltf", g));
  EXPECT_EQ(s.triangleCount(), 2u);  // nodes 0 and 2; the marker is not geometry
  EXPECT_EQ(s.positions.size(), 6u);
  EXPECT_EQ(s.normals.size(), 6u);
  ASSERT_FALSE(s.region.empty());
  expectNear(s.region.lower, {5, 6, 7}, 1e-6f, "region lower");
  expectNear(s.region.upper, {7, 9, 7}, 1e-6f, "region upper");
  // Without one, no region.
  MiniGltf plain = oneTriangle();
  EXPECT_TRUE(loadScene(write("plain.gltf", plain)).region.empty());
  // A marker needs a mesh, and true or false.
  MiniGltf noMesh = oneTriangle();
  noMesh.nodes = R"([{"mesh": 0}, {"extras": {"lightoctree_region": true}}])";
  noMesh.sceneNodes = "[0, 1]";
  expectInputError(write("nomesh.gltf", noMesh), "has no mesh");
  MiniGltf notBool = oneTriangle();
  notBool.nodes = R"([{"mesh": 0, "extras": {"lightoctree_region": 1}}])";
  expectInputError(write("notbool.gltf", notBool), "must be true or false");
}

TEST_F(SceneGltf, NonUniformScaleNormalsUseInverseTranspose) {
  MiniGltf g;
  // A tilted triangle; its vertex normals are its face normal.
  g.positions = {0, 0, 0, 1, 0, 1, 0, 1, 0};
  Vec3 n = normalize(cross(Vec3{1, 0, 1}, Vec3{0, 1, 0}));
  g.normals = {n.x, n.y, n.z, n.x, n.y, n.z, n.x, n.y, n.z};
  g.indices = {0, 1, 2};
  g.nodes = R"([{"mesh": 0, "scale": [3, 1, 0.5], "rotation": [0.2, 0.3, 0.1, 0.927]}])";
  Scene s = loadScene(write("scaled.gltf", g));
  for (int k = 0; k < 3; ++k) expectNear(s.normals[s.indices[size_t(k)]], s.faceNormal(0), 1e-5f);
}

TEST_F(SceneGltf, NegativeScaleFlipsWinding) {
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "scale": [-1, 1, 1]}])";
  Scene s = loadScene(write("mirror.gltf", g));
  ASSERT_EQ(s.triangleCount(), 1u);
  // Mirrored in x, the triangle still faces +z: the winding was flipped.
  expectNear(s.faceNormal(0), {0, 0, 1}, 1e-6f, "face normal");
  for (int k = 0; k < 3; ++k) expectNear(s.normals[s.indices[size_t(k)]], {0, 0, 1}, 1e-6f);
  // Without the mirror, the same triangle faces +z too (reference).
  g.nodes = R"([{"mesh": 0}])";
  Scene r = loadScene(write("plain.gltf", g));
  expectNear(r.faceNormal(0), {0, 0, 1}, 1e-6f, "reference");
}

TEST_F(SceneGltf, NonIndexedStripAndFan) {
  MiniGltf g;
  // A unit quad in z = 0 as a strip 0-1-2-3: (0,0) (1,0) (0,1) (1,1).
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  g.indexed = false;
  g.mode = 5;
  Scene strip = loadScene(write("strip.gltf", g));
  ASSERT_EQ(strip.triangleCount(), 2u);
  for (size_t t = 0; t < 2; ++t) expectNear(strip.faceNormal(t), {0, 0, 1}, 1e-6f, "strip");
  EXPECT_TRUE(strip.normals.empty());
  // The same quad as a fan 0-1-3-2.
  g.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  g.mode = 6;
  Scene fan = loadScene(write("fan.gltf", g));
  ASSERT_EQ(fan.triangleCount(), 2u);
  for (size_t t = 0; t < 2; ++t) expectNear(fan.faceNormal(t), {0, 0, 1}, 1e-6f, "fan");
  EXPECT_NEAR(fan.triangleArea(0) + fan.triangleArea(1), 1.0f, 1e-6f);
}

TEST_F(SceneGltf, SparseAccessor) {
  MiniGltf g = oneTriangle();
  std::string j = g.json();
  // POSITION gets one sparse substitute: index 0 (the first uint32 of the
  // index view) takes the value (0, 0, 1) (the first normal).
  std::string from = "\"count\": 3, \"type\": \"VEC3\"}";
  j.replace(j.find(from), from.size(),
            "\"count\": 3, \"type\": \"VEC3\", \"sparse\": {\"count\": 1, \"indices\": "
            "{\"bufferView\": 2, \"componentType\": 5125}, \"values\": {\"bufferView\": 1}}}");
  Scene s = loadScene(write("sparse.gltf", j));
  expectNear(s.positions[0], {0, 0, 1}, 1e-6f, "substituted");
  expectNear(s.positions[1], {1, 0, 0}, 1e-6f, "kept");
}

// Morph targets at their default weights, the node's over the mesh's: they
// were left out, a lifted part drawn in its base shape (H14-4-1). The
// target here is the normals' accessor, (0, 0, 1) at each vertex.
TEST_F(SceneGltf, MorphTargetsAreAppliedAtTheirDefaultWeights) {
  MiniGltf g = oneTriangle();
  auto morphed = [&](const std::string& meshWeights, const std::string& nodes) {
    g.nodes = nodes;
    std::string j = g.json();
    const std::string mode = ", \"mode\": 4}]";
    j.replace(j.find(mode), mode.size(),
              ", \"mode\": 4, \"targets\": [{\"POSITION\": 1}]}]" + meshWeights);
    return loadScene(write("morph.gltf", j));
  };
  const Scene base = morphed("", R"([{"mesh": 0}])");
  expectNear(base.positions[0], {0, 0, 0}, 1e-6f, "no weights: the base shape");
  const Scene lifted = morphed(", \"weights\": [0.5]", R"([{"mesh": 0}])");
  for (size_t v = 0; v < 3; ++v) {
    expectNear(lifted.positions[v], base.positions[v] + Vec3{0, 0, 0.5f}, 1e-6f, "mesh weight");
  }
  const Scene byNode = morphed(", \"weights\": [0.5]", R"([{"mesh": 0, "weights": [2]}])");
  expectNear(byNode.positions[1], base.positions[1] + Vec3{0, 0, 2}, 1e-6f, "the node's weight");
  EXPECT_THROW(morphed(", \"weights\": [1e300]", R"([{"mesh": 0}])"), InputError);
  // Weights of another type are refused by their pointer; another count is
  // read as far as both go, and warned (H15-4-1: taken as none, silently).
  for (const char* weights : {", \"weights\": [\"1\"]", ", \"weights\": {\"a\": 1}"}) {
    try {
      morphed(weights, R"([{"mesh": 0}])");
      ADD_FAILURE() << weights << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("/meshes/0/weights"), std::string::npos) << e.what();
    }
  }
  const Scene extra = morphed(", \"weights\": [0.5, 1, 1]", R"([{"mesh": 0}])");
  expectNear(extra.positions[0], base.positions[0] + Vec3{0, 0, 0.5f}, 1e-6f, "first weight");
  ASSERT_FALSE(extra.warnings.empty());
  EXPECT_NE(extra.warnings.back().find("has 1 morph targets and 3 weights"), std::string::npos)
      << extra.warnings.back();
}

// A texture on a UV set the primitive lacks, or on a set the loader does
// not read, is said (it was drawn at one texel, or left out, silently).
TEST_F(SceneGltf, TexturesOnMissingUvSetsAreWarned) {
  MiniGltf g = oneTriangle();
  g.image =  // one white texel
      "data:image/"
      "png;base64,"
      "iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJg"
      "gg==";
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
  const Scene s = loadScene(write("no-uv.gltf", g));
  bool said = false;
  for (const std::string& w : s.warnings) {
    said |= w.find("material 0 has a texture on TEXCOORD_0, which the primitive lacks") !=
            std::string::npos;
  }
  EXPECT_TRUE(said) << ::testing::PrintToString(s.warnings);
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 9}}}])";
  const Scene nine = loadScene(write("uv9.gltf", g));
  said = false;
  for (const std::string& w : nine.warnings) {
    said |= w.find("texture uses TEXCOORD_9, and only TEXCOORD_0 and TEXCOORD_1 are read") !=
            std::string::npos;
  }
  EXPECT_TRUE(said) << ::testing::PrintToString(nine.warnings);
}

// A sparse accessor without a bufferView stands for zeros: 2^28 of them in
// a few hundred bytes used to cost 6.4 GB before any check. Refused before
// allocating, naming the accessor.
TEST_F(SceneGltf, SparseAccessorOfImplicitZerosIsBounded) {
  MiniGltf g = oneTriangle();
  std::string j = g.json();
  const std::string from = "{\"bufferView\": 0, \"componentType\": 5126, \"count\": 3, \"type\": \"VEC3\"}";
  ASSERT_NE(j.find(from), std::string::npos) << j;
  j.replace(j.find(from), from.size(),
            "{\"componentType\": 5126, \"count\": 268435456, \"type\": \"VEC3\", \"sparse\": "
            "{\"count\": 1, \"indices\": {\"bufferView\": 2, \"componentType\": 5125}, "
            "\"values\": {\"bufferView\": 1}}}");
  expectInputError(write("huge.gltf", j), "implicit zero elements");
}

/// A strip of `columns` x 2 vertices along x in y = 0 (POSITION accessor 0,
/// NORMAL 1), and `primitives` primitives of one mesh, each two triangles of
/// it by its own index accessor; a copy of the POSITION accessor (2: the same
/// view and offset) serves every other primitive. NORMAL on every primitive
/// (`normals` "all") or on the first only ("first"). `nodes` and the
/// scene's roots as given.
std::string sharedBufferGltf(int columns, int primitives, const std::string& normals,
                             const std::string& nodes, const std::string& roots) {
  std::vector<float> pos, nrm;
  for (int c = 0; c < columns; ++c)
    for (int r = 0; r < 2; ++r) {
      pos.insert(pos.end(), {float(c), 0.0f, float(r)});
      nrm.insert(nrm.end(), {0.0f, 1.0f, 0.0f});
    }
  std::vector<uint32_t> idx;
  for (int p = 0; p < primitives; ++p) {
    const uint32_t a = uint32_t(2 * (p % (columns - 1)));
    idx.insert(idx.end(), {a, a + 1, a + 2, a + 2, a + 1, a + 3});  // facing +y
  }
  std::string blob;
  test::append(blob, pos);
  const size_t nrmOffset = blob.size();
  test::append(blob, nrm);
  const size_t idxOffset = blob.size();
  test::append(blob, idx);
  std::ostringstream os;
  os << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": )" << roots
     << R"(}], "nodes": )" << nodes << R"(, "meshes": [{"primitives": [)";
  for (int p = 0; p < primitives; ++p) {
    os << (p ? ", " : "") << R"({"attributes": {"POSITION": )" << (p % 2 ? 2 : 0)
       << (normals == "all" || p == 0 ? R"(, "NORMAL": 1)" : "") << R"(}, "indices": )" << 3 + p
       << "}";
  }
  os << R"(]}], "accessors": [)";
  const int vertices = 2 * columns;
  os << R"({"bufferView": 0, "componentType": 5126, "count": )" << vertices
     << R"(, "type": "VEC3"}, )";
  os << R"({"bufferView": 1, "componentType": 5126, "count": )" << vertices
     << R"(, "type": "VEC3"}, )";
  os << R"({"bufferView": 0, "componentType": 5126, "count": )" << vertices
     << R"(, "type": "VEC3"})";
  for (int p = 0; p < primitives; ++p) {
    os << R"(, {"bufferView": 2, "byteOffset": )" << 24 * p
       << R"(, "componentType": 5125, "count": 6, "type": "SCALAR"})";
  }
  os << R"(], "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": )" << nrmOffset
     << R"(}, {"buffer": 0, "byteOffset": )" << nrmOffset << R"(, "byteLength": )"
     << idxOffset - nrmOffset << R"(}, {"buffer": 0, "byteOffset": )" << idxOffset
     << R"(, "byteLength": )" << blob.size() - idxOffset << R"(}], "buffers": [{"byteLength": )"
     << blob.size() << R"(, "uri": "data:application/octet-stream;base64,)" << test::base64(blob)
     << R"("}]})";
  return os.str();
}

// Primitives that share a vertex buffer through the same accessors (or
// accessors that read the same bytes the same way) share its vertices in
// the scene: the scene's vertices follow the file, not primitives x buffer
// (10,000 primitives of one 4 MB buffer took gigabytes, issue 43). Each
// node instance still has its own; a region marker's are its own.
TEST_F(SceneGltf, PrimitivesThatShareAVertexBufferShareItsVertices) {
  // A column per primitive: none repeats another's triangles (those the
  // loader leaves out, SceneObj.TrianglesThatRepeatAnEarlierOneAreLeftOut).
  const int primitives = 2000, columns = primitives + 1;
  Scene s = loadScene(write(
      "shared.gltf", sharedBufferGltf(columns, primitives, "all", R"([{"mesh": 0}])", "[0]")));
  ASSERT_EQ(s.triangleCount(), size_t(2 * primitives));
  EXPECT_EQ(s.positions.size(), size_t(2 * columns));  // was 2 * columns * primitives
  EXPECT_EQ(s.normals.size(), s.positions.size());
  for (int p = 0; p < primitives; ++p) {
    const float x = float(p % (columns - 1));
    expectNear(s.positions[s.indices[6 * size_t(p)]], {x, 0, 0}, 0, "first corner");
    expectNear(s.positions[s.indices[6 * size_t(p) + 5]], {x + 1, 0, 1}, 0, "last corner");
  }

  // Two nodes: two instances, each with its vertices; a region marker over
  // the same mesh keeps its own and leaves the geometry's alone.
  Scene two = loadScene(
      write("two.gltf", sharedBufferGltf(columns, 8, "all",
                                         R"([{"mesh": 0}, {"mesh": 0, "translation": [0, 5, 0]},
          {"mesh": 0, "extras": {"lightoctree_region": true}}])",
                                         "[0, 1, 2]")));
  EXPECT_EQ(two.triangleCount(), 32u);
  EXPECT_EQ(two.positions.size(), size_t(4 * columns));
  ASSERT_FALSE(two.region.empty());
  expectNear(two.region.lower, {0, 0, 0}, 0, "region lower");
  expectNear(two.region.upper, {float(columns - 1), 0, 1}, 0, "region upper");

  // Without NORMAL (all but the first primitive, which has its own copy),
  // the shared vertices' normals come from the faces of every primitive that
  // uses them: all face +y, also the vertices the second primitive, which
  // made the copy, does not use.
  Scene faceted = loadScene(
      write("faceted.gltf", sharedBufferGltf(columns, 50, "first", R"([{"mesh": 0}])", "[0]")));
  EXPECT_EQ(faceted.positions.size(), size_t(4 * columns));
  ASSERT_EQ(faceted.normals.size(), faceted.positions.size());
  for (size_t t = 0; t < faceted.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k)
      expectNear(faceted.normals[faceted.indices[3 * t + size_t(k)]], {0, 1, 0}, 1e-6f, "normal");
}

// Vertices that are no primitive's to share (another node's instance, or
// accessors over other bytes) are counted before they are built: beyond
// half the memory available, refused by name rather than built to a bare
// out-of-memory.
TEST_F(SceneGltf, VerticesBeyondMemoryAreRefusedBeforeBuilt) {
  const std::string path =
      write("instances.gltf",
            sharedBufferGltf(1500, 4, "all",
                             R"([{"mesh": 0}, {"mesh": 0, "translation": [0, 5, 0]}])", "[0, 1]"));
  // 1 MiB: half of it holds 5,461 vertices of 96 bytes; each instance has 3,000.
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "1M", 1);
  expectInputError(path, "vertices of their own");
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  EXPECT_EQ(loadScene(path).positions.size(), 6000u);
}

TEST_F(SceneGltf, GlbAndDefaultMaterial) {
  MiniGltf g = oneTriangle();
  Scene s = loadScene(write("tri.glb", g.glb()));
  ASSERT_EQ(s.triangleCount(), 1u);
  ASSERT_EQ(s.materials.size(), 1u);  // the shared default
  EXPECT_EQ(s.materials[0].name, "default");
  EXPECT_EQ(s.triangleMaterial[0], 0);
}

// glTF TANGENT is read per vertex, turned by the node's transform, and its
// w flips under a mirroring node (the winding flips with it).
TEST_F(SceneGltf, TangentsAreReadAndTransformed) {
  MiniGltf g = oneTriangle();
  g.tangents = {1, 0, 0, 1, 1, 0, 0, 1, 1, 0, 0, 1};
  g.nodes = R"([{"mesh": 0, "rotation": [0, 0, 0.7071068, 0.7071068]}])";  // 90 deg about z
  Scene s = loadScene(write("tangent.gltf", g));
  ASSERT_EQ(s.tangents.size(), 12u);
  EXPECT_NEAR(s.tangents[0], 0.0f, 1e-5f);
  EXPECT_NEAR(s.tangents[1], 1.0f, 1e-5f);  // +x turned to +y
  EXPECT_EQ(s.tangents[3], 1.0f);
  g.nodes = R"([{"mesh": 0, "scale": [-1, 1, 1]}])";
  Scene m = loadScene(write("mirror.gltf", g));
  ASSERT_EQ(m.tangents.size(), 12u);
  EXPECT_EQ(m.tangents[3], -1.0f) << "a mirroring node flips the bitangent sign";
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


TEST_F(SceneGltf, ASceneFarFromTheOriginKeepsItsPrecision) {
  // Projected coordinates (1e6-1e7 m): floats there are 0.06-0.5 m apart, so
  // the loader keeps the scene relative to its centre, computed in double
  // (Scene::origin), and every position keeps float's precision near 0.
  const Vec3d t(1234567.25, 89.5, -7654321.0625);
  const Scene far = loadScene(write("far.gltf", quadUnderNode("1234567.25, 89.5, -7654321.0625")));
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
  const Scene near = loadScene(write("near.gltf", quadUnderNode("1, 2, 3")));
  EXPECT_FALSE(near.rebased());
  EXPECT_EQ(near.positions[2], Vec3(1.3f, 2.2f, 3.0f));
  EXPECT_EQ(near.lights[0].position, Vec3(1.5f, 2.25f, 4.0f));
}

// Triangles take a multiple of three indices: the whole triangles are read
// and the rest named in a warning (35 indices lost 2 without a word).
TEST_F(SceneGltf, IndicesThatAreNotWholeTrianglesAreNamed) {
  MiniGltf g = oneTriangle();
  g.positions = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  g.normals = {0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1};
  g.indices = {0, 1, 2, 1, 3};
  const Scene s = loadScene(write("five.gltf", g));
  EXPECT_EQ(s.triangleCount(), 1u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("5 indices are not a whole number of triangles: the last 2 are "
                               "left out"),
            std::string::npos)
      << s.warnings[0];
  const Scene whole = loadScene(write("three.gltf", oneTriangle()));
  EXPECT_TRUE(whole.warnings.empty());
}

// Extensions: one the file requires and the loader does not read is
// refused by name, with what to do (a Draco file failed on its accessors'
// missing buffer views, naming neither); one it only uses is a warning;
// one the loader reads may be required.
TEST_F(SceneGltf, ExtensionsTheLoaderDoesNotReadAreNamed) {
  MiniGltf draco = oneTriangle();
  draco.extraTop = R"("extensionsUsed": ["KHR_draco_mesh_compression"],
                      "extensionsRequired": ["KHR_draco_mesh_compression"], )";
  expectInputError(write("draco.gltf", draco),
                   "requires the glTF extension KHR_draco_mesh_compression");
  expectInputError(write("draco.gltf", draco), "uncompressed");
  MiniGltf webp = oneTriangle();
  webp.extraTop = R"("extensionsRequired": ["EXT_texture_webp"], )";
  expectInputError(write("webp.gltf", webp), "PNG or JPEG");

  MiniGltf used = oneTriangle();
  used.extraTop = R"("extensionsUsed": ["KHR_materials_clearcoat", "KHR_texture_transform"], )";
  const Scene s = loadScene(write("clearcoat.gltf", used));
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
  const Scene g = loadScene(write("specgloss.gltf", sg));
  ASSERT_EQ(g.materials.size(), 1u);
  expectNear(g.materials[0].baseColor, {0.2f, 0.4f, 0.6f}, 1e-6f, "diffuse");
  EXPECT_FLOAT_EQ(g.materials[0].baseAlpha, 0.5f);
  EXPECT_FLOAT_EQ(g.materials[0].roughness, 0.7f);
  EXPECT_EQ(g.materials[0].metallic, 0.0f);
  ASSERT_EQ(g.warnings.size(), 1u);
  EXPECT_NE(g.warnings[0].find("read approximately"), std::string::npos) << g.warnings[0];
  sg.materials = R"([{"extensions": {"KHR_materials_pbrSpecularGlossiness": {"glossinessFactor": 2}}}])";
  expectInputError(write("badgloss.gltf", sg), "glossinessFactor must lie in [0, 1]");

  MiniGltf read = oneTriangle();
  read.extraTop = R"("extensionsUsed": ["KHR_texture_transform", "KHR_mesh_quantization"],
                     "extensionsRequired": ["KHR_texture_transform", "KHR_mesh_quantization"], )";
  const Scene r = loadScene(write("read.gltf", read));
  EXPECT_EQ(r.triangleCount(), 1u);
  EXPECT_TRUE(r.warnings.empty());
}

}  // namespace
}  // namespace lo
