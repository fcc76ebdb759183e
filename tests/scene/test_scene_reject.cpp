// One malformed file per input the loader refuses, with a message that
// names the file and what is wrong (docs/scene.md, "Limits"), before it
// allocates for what the file claims.

#include <gtest/gtest.h>

#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>

#include "core/error.h"
#include "core/file.h"
#include "scene/place_model.h"
#include "scene/scene.h"
#include "scene/scene_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

using namespace test;  // scene_fixture.h

TEST_F(SceneReject, MissingFile) {
  expectInputError(dir + "/nope.gltf", "missing");
  expectInputError(dir + "/nope.obj", "missing");
  ASSERT_EQ(mkfifo((dir + "/pipe.gltf").c_str(), 0600), 0);  // would block a reader
  expectInputError(dir + "/pipe.gltf", "is a pipe");
}

TEST_F(SceneReject, UnknownExtension) {
  expectInputError(write("scene.fbx", "whatever"), "extension");
}

TEST_F(SceneReject, MissingExternalBuffer) {
  MiniGltf g = oneTriangle();
  g.bufferUri = "mesh.bin";
  std::string path = write("scene.gltf", g);
  expectInputError(path, "missing buffer");
  expectInputError(path, "mesh.bin");
  // With the .bin present it loads.
  write("mesh.bin", g.blob());
  EXPECT_EQ(loadScene(path).triangleCount(), 1u);
  // A .bin far larger than its byteLength is refused from its size, unread
  // (a sparse 64 MiB file: nothing is written to the disk).
  fs::resize_file(dir + "/mesh.bin", uintmax_t(64) << 20);
  expectInputError(path, "holds 67108864 bytes where its byteLength says");
}

// A data: URI buffer whose bytes are not its byteLength: tinygltf's refusal
// quoted the URI (megabytes of base64 in a real file); now the buffer is
// named with both sizes, and the URI is not in the message.
TEST_F(SceneReject, ADataUriOfAnotherLengthIsNamedNotQuoted) {
  const MiniGltf g = oneTriangle();
  const std::string good = g.json();
  EXPECT_EQ(loadScene(write("good.gltf", good)).triangleCount(), 1u);
  const std::string length = "\"byteLength\": " + std::to_string(g.blob().size()) + ", \"uri\"";
  const size_t at = good.find(length);
  ASSERT_NE(at, std::string::npos) << good;
  for (const uint64_t claimed : {uint64_t(1) << 62, uint64_t(g.blob().size() + 3)}) {
    SCOPED_TRACE(claimed);
    std::string json = good;
    json.replace(at, length.size(), "\"byteLength\": " + std::to_string(claimed) + ", \"uri\"");
    const std::string path = write("lying.gltf", json);
    try {
      loadScene(path);
      ADD_FAILURE() << "loaded";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("buffer 0: its data URI holds " + std::to_string(g.blob().size()) +
                          " bytes where its byteLength says " + std::to_string(claimed)),
                std::string::npos)
          << what;
      EXPECT_EQ(what.find("base64,"), std::string::npos) << what;
      EXPECT_LT(what.size(), 400u) << what;
    }
  }
}

TEST_F(SceneReject, TrianglesBeyondMemoryAreCountedBeforeBuilt) {
  // Twenty nodes instancing a mesh of 1e8 triangles (an accessor without a
  // buffer view: zeros, as glTF allows): 2e9 triangles, refused from the
  // accessors' counts before any is built.
  std::string nodes, roots;
  for (int i = 0; i < 20; ++i) {
    nodes += std::string(i ? ", " : "") + R"({"mesh": 0})";
    roots += std::string(i ? ", " : "") + std::to_string(i);
  }
  write("many.gltf",
        R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [)" + roots +
            R"(]}], "nodes": [)" + nodes +
            R"(], "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
            "accessors": [{"componentType": 5126, "count": 300000000, "type": "VEC3",
            "min": [0, 0, 0], "max": [0, 0, 0]}]})");
  expectInputError(dir + "/many.gltf", "the node tree makes 2000000000 triangles");
}

// The objects of --add were loaded and joined one after the other, each
// checked alone: a model added many times grew until the system ended the
// process. Every copy's triangles are counted, with the scene's, before any
// is joined (256 bytes each within half the memory available, as the node
// tree's); each file is loaded once, and its copies share its textures.
TEST_F(SceneReject, AddedObjectsTrianglesAreCountedBeforeAnyIsJoined) {
  // A model of 1,000 triangles, textured.
  write("tex.ppm", "P6\n2 2\n255\n" + std::string(12, '\x80'));
  write("m.mtl", "newmtl a\nKd 1 1 1\nmap_Kd tex.ppm\n");
  std::string obj = "mtllib m.mtl\nusemtl a\n";
  for (int t = 0; t < 1000; ++t) {
    const std::string x = std::to_string(t % 100), y = std::to_string(t / 100);
    obj += "v " + x + " " + y + " 0\nv " + x + ".5 " + y + " 0\nv " + x + " " + y + ".5 0\n";
    obj += "f " + std::to_string(3 * t + 1) + " " + std::to_string(3 * t + 2) + " " +
           std::to_string(3 * t + 3) + "\n";
  }
  const std::string model = write("model.obj", obj);
  const Scene base = loadScene(write("base.gltf", oneTriangle()));
  auto copies = [&](int n) {
    std::vector<AddedModel> added;
    for (int i = 0; i < n; ++i) added.push_back({model, parsePlacement(std::to_string(i) + ",0,0")});
    return added;
  };
  // 16 MiB: half of it holds 32,768 triangles of 256 bytes.
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "16M", 1);
  Scene scene = base;
  try {
    placeModels(scene, copies(40));
    ADD_FAILURE() << "40,001 triangles were joined";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--add: the scene and its 40 added objects make 40001 "
                                         "triangles"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("half the 16.0 MiB of memory available"),
              std::string::npos)
        << e.what();
  }
  EXPECT_EQ(scene.triangleCount(), 1u);  // nothing joined
  EXPECT_EQ(scene.materials.size(), base.materials.size());
  // 30 copies fit, and share one texture.
  EXPECT_NO_THROW(placeModels(scene, copies(30)));
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  EXPECT_EQ(scene.triangleCount(), 30001u);
  ASSERT_EQ(scene.textures.size(), base.textures.size() + 1);
  ASSERT_EQ(scene.materials.size(), base.materials.size() + 30);
  for (size_t m = base.materials.size(); m < scene.materials.size(); ++m) {
    EXPECT_EQ(scene.materials[m].baseColorTexture, int(base.textures.size())) << m;
  }
  EXPECT_EQ(scene.movingMaterialsFrom, base.materials.size());
  // The 30th copy sits where its --at put it.
  EXPECT_EQ(scene.positions.back().x, 29.0f + 99.0f);
}

TEST_F(SceneReject, BufferUriEscapingTheFolder) {
  fs::create_directories(dir + "/inner");
  MiniGltf g = oneTriangle();
  write("outside.bin", g.blob());  // exists, and must still be refused
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

TEST_F(SceneReject, IndexOutOfRange) {
  MiniGltf g = oneTriangle();
  g.indices = {0, 1, 7};
  expectInputError(write("index.gltf", g), "out of range");
}

TEST_F(SceneReject, AccessorOutOfRangeOfBufferView) {
  MiniGltf g = oneTriangle();
  std::string j = g.json();
  // Claim 300 positions in a 36-byte view.
  std::string from = "\"count\": 3, \"type\": \"VEC3\"";
  j.replace(j.find(from), from.size(), "\"count\": 300, \"type\": \"VEC3\"");
  expectInputError(write("accessor.gltf", j), "out of range");
  // A bufferView beyond its buffer.
  j = g.json();
  from = "\"byteOffset\": 0, \"byteLength\": 36";
  j.replace(j.find(from), from.size(), "\"byteOffset\": 0, \"byteLength\": 3600");
  expectInputError(write("view.gltf", j), "out of range");
}

TEST_F(SceneReject, NonFiniteVertex) {
  MiniGltf g = oneTriangle();
  g.positions[4] = std::nanf("");
  expectInputError(write("nan.gltf", g), "non-finite");
  g = oneTriangle();
  g.positions[0] = INFINITY;
  expectInputError(write("inf.gltf", g), "non-finite");
}

TEST_F(SceneReject, PointsMode) {
  MiniGltf g = oneTriangle();
  g.mode = 0;
  expectInputError(write("points.gltf", g), "unsupported primitive mode");
  g.mode = 1;
  expectInputError(write("lines.gltf", g), "unsupported primitive mode");
}

TEST_F(SceneReject, UnreadableImage) {
  write("garbage.png", "this is not a png at all, just bytes");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}])";
  g.image = "garbage.png";
  std::string path = write("image.gltf", g);
  expectInputError(path, "unreadable image");
  expectInputError(path, "garbage.png");
}

TEST_F(SceneReject, TruncatedGlb) {
  std::string glb = oneTriangle().glb();
  for (size_t keep :
       {size_t(0), size_t(10), size_t(19), size_t(40), glb.size() / 2, glb.size() - 4}) {
    std::string name = "cut" + std::to_string(keep) + ".glb";
    write(name, glb.substr(0, keep));
    expectInputError(dir + "/" + name, "truncated");
  }
  // Garbage with the right magic and sizes that lie.
  std::string lying = glb;
  uint32_t huge = 0x7fffffff;
  std::memcpy(&lying[12], &huge, 4);
  expectInputError(write("lying.glb", lying), "truncated");
  // And the shared scene, truncated, if it is there.
  std::string shared = test::sharedScenesDir() + "/composed/cornell-box.glb";
  if (fs::exists(shared)) {
    std::string bytes = readFile(shared);
    write("cornell-half.glb", bytes.substr(0, bytes.size() / 2));
    expectInputError(dir + "/cornell-half.glb", "truncated");
  }
}

TEST_F(SceneReject, NoTriangles) {
  MiniGltf g = oneTriangle();
  g.indices = {0, 1, 1};  // degenerate: dropped
  expectInputError(write("degenerate.gltf", g), "no triangles");
  expectInputError(write("empty.obj", "# nothing\nv 0 0 0\n"), "no triangles");
}

TEST_F(SceneReject, InvalidJson) {
  expectInputError(write("broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"nodes\": ["),
                   "invalid glTF");
  // A number beyond a double (eighth hostile list F4-33) is refused with the
  // reason and where, not "does not parse" alone.
  MiniGltf g = oneTriangle();
  g.extraTop = R"("extras": {"big": 1e400}, )";
  const std::string path = write("overflow.gltf", g);
  expectInputError(path, "the JSON does not parse: number overflow parsing '1e400' at line 1");
  expectInputError(write("comma.gltf", "{\"asset\": {\"version\": \"2.0\"}\n \"nodes\": []}"),
                   "parse error at line 2");
}

TEST_F(SceneReject, NodeCycle) {
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "children": [1]}, {"children": [0]}])";
  expectInputError(write("cycle.gltf", g), "node 0 is reached twice");
  // A node shared by two parents is the one named (H17-7-1: a later node
  // was, by the count of visits).
  g.nodes = R"([{"children": [2]}, {"children": [2]}, {"mesh": 0, "name": "wall"}, {}, {}])";
  g.sceneNodes = "[0, 1, 3, 4]";
  expectInputError(write("shared.gltf", g), "node 2 ('wall') is reached twice");
}

// Hardening (docs/scene.md, "Limits"): inputs that used to crash or load as
// a silently wrong scene are refused with a message naming the file and the
// problem; a base colour above 1 is clamped with a warning.
TEST_F(SceneLimits, DeepJsonIsRefusedBeforeParsing) {
  MiniGltf g = oneTriangle();
  std::string deep(100000, '[');
  deep += std::string(100000, ']');
  g.extraTop = "\"extras\": " + deep + ", ";
  expectInputError(write("deep.gltf", g), "nested more than");
  // Brackets inside strings do not count.
  g.extraTop = "\"extras\": {\"note\": \"" + std::string(1000, '[') + "\"}, ";
  EXPECT_EQ(loadScene(write("brackets.gltf", g)).triangleCount(), 1u);
}

TEST_F(SceneLimits, IndexBeyondInt32IsRefused) {
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{}])";
  std::string json = g.json();
  const std::string from = "\"material\": 0", to = "\"material\": 4294967299";  // 2^32 + 3
  ASSERT_NE(json.find(from), std::string::npos);
  json.replace(json.find(from), from.size(), to);
  write("index.gltf", json);
  expectRefusal([&] { loadScene(dir + "/index.gltf"); },
                {"/meshes/0/primitives/0/material = 4294967299 is out of range"});
}

TEST_F(SceneLimits, CoordinatesBeyondTheTracersRangeAreRefused) {
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "translation": [1e20, 0, 0]}])";
  expectInputError(write("far.gltf", g), "beyond 1e+12 scene units");
  g.nodes = R"([{"mesh": 0, "translation": [1e9, 0, 0]}])";  // far, but representable
  EXPECT_EQ(loadScene(write("farish.gltf", g)).triangleCount(), 1u);
}

// A triangle whose area overflows single precision (the Cornell box scaled
// by 1e11 was refused as "emits non-finite power", H10-4-232), and a ground
// so much wider than the rest that the tracers' ray offset, 1e-5 of the
// scene's size, passes small parts by (H11-5-36: a room's indirect light lost
// without a word): refused, and warned.
TEST_F(SceneLimits, TrianglesBeyondSinglePrecisionAreRefusedAndAHugeGroundWarned) {
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"mesh": 0, "scale": [2e9, 2e9, 2e9]}])";
  expectInputError(write("wide.gltf", g), "triangle 0 spans 2.82843e+09 scene units, beyond 1e+09");
  // Twenty small triangles on a 1 x 1 patch, and one ground of side S: the
  // offset is 1.5e-5 of the diagonal, warned past a tenth of the median
  // triangle (0.1 of 1.41 here: S about 6,700).
  auto withGround = [&](float side) {
    MiniGltf m;
    for (int i = 0; i < 20; ++i) {
      const float x = 0.05f * float(i);
      m.positions.insert(m.positions.end(), {x, 0, 0, x + 1, 0, 0, x, 1, 0});
    }
    m.positions.insert(m.positions.end(), {-side, -1, -side, side, -1, -side, 0, -1, side});
    for (uint32_t i = 0; i < 63; ++i) m.indices.push_back(i);
    return loadScene(write("ground.gltf", m)).warnings;
  };
  auto warned = [](const std::vector<std::string>& warnings) {
    for (const std::string& w : warnings) {
      if (w.find("rays leave a surface about") != std::string::npos) return true;
    }
    return false;
  };
  EXPECT_FALSE(warned(withGround(1000)));
  const std::vector<std::string> far = withGround(1e5f);
  EXPECT_TRUE(warned(far));
  EXPECT_NE(far.front().find("while a quarter of its triangles are under 1.41421 across"),
            std::string::npos)
      << far.front();
  // Thirty more ground triangles, a majority: the small ones still count
  // (H12-5-34: twenty large quads hid them from a median).
  auto withGrounds = [&](int grounds) {
    MiniGltf m;
    for (int i = 0; i < 20; ++i) {
      const float x = 0.05f * float(i);
      m.positions.insert(m.positions.end(), {x, 0, 0, x + 1, 0, 0, x, 1, 0});
    }
    for (int i = 0; i < grounds; ++i) {
      const float y = -1.0f - 0.01f * float(i);
      m.positions.insert(m.positions.end(), {-1e5f, y, -1e5f, 1e5f, y, -1e5f, 0, y, 1e5f});
    }
    for (uint32_t i = 0; i < uint32_t(3 * (20 + grounds)); ++i) m.indices.push_back(i);
    return loadScene(write("grounds.gltf", m)).warnings;
  };
  EXPECT_TRUE(warned(withGrounds(30)));
  // Or 500 of them: the twenty small ones are 4% of all, each narrower than
  // the offset itself (about 4.2 here).
  EXPECT_TRUE(warned(withGrounds(500)));
}

TEST_F(SceneLimits, BaseColourAboveOneIsClampedWithAWarning) {
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"name": "hot", "pbrMetallicRoughness": {"baseColorFactor": [1000, 0.5, 1.5, 1]}}])";
  const Scene s = loadScene(write("bright.gltf", g));
  EXPECT_EQ(s.materials[0].baseColor, Vec3(1.0f, 0.5f, 1.0f));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("material 'hot'"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("clamped"), std::string::npos) << s.warnings[0];
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.5, 0.5, 1]}}])";
  EXPECT_TRUE(loadScene(write("fine.gltf", g)).warnings.empty());
}

}  // namespace
}  // namespace lo
