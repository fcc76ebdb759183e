// The OBJ loader: .mtl materials and grouping, undefined materials and
// missing textures warned once by name, vertex colours, coordinates far from
// the origin read again in double, and the files it refuses.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_files.h"
#include "scene/scene_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

using namespace test;  // scene_fixture.h

bool hasWarning(const Scene& s, const std::string& text) {
  for (const std::string& w : s.warnings) {
    if (w.find(text) != std::string::npos) return true;
  }
  return false;
}

TEST_F(SceneObj, MaterialMappingAndGrouping) {
  write("m.mtl",
        "newmtl shiny\nKd 0.5 0.25 0.125\nKs 0.5 0.625 0.25\nNs 98\nd 0.25\nNi 1.4\n"
        "newmtl lamp\nKd 0 0 0\nKe 2 3 4\n");
  write("scene.obj",
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
  // OBJ has no single-sided faces: both sides are drawn, whatever the
  // winding; emission stays on the winding's side (not doubleSided).
  for (const Material& m : s.materials) {
    EXPECT_FALSE(m.backFaceCulling) << m.name;
    EXPECT_FALSE(m.doubleSided) << m.name;
  }
}

// A triangle that repeats an earlier one (the same vertices in the same
// winding, from any corner, and the same material) is left out once the
// scene is loaded: 5,000 primitives over one index accessor made 4 million
// triangles on one spot, and a bake of 2 minutes and 7.2 GB (issue 43, G05).
// Its mirror image (the other face of a sheet), the same vertices in another
// material, and the same corners through other vertices (another colour)
// are not copies; the order of the rest is kept, and the user hears how
// many went.
TEST_F(SceneObj, TrianglesThatRepeatAnEarlierOneAreLeftOut) {
  write("m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nnewmtl b\nKd 0.25 0.25 0.25\n");
  write("scene.obj",
        "mtllib m.mtl\nv 0 0 0 1 1 1\nv 1 0 0 1 1 1\nv 1 1 0 1 1 1\nv 0 0 0 1 0 0\n"
        "usemtl a\n"
        "f 1 2 3\n"   // 0: kept
        "f 2 3 1\n"   // the same, from its second corner: out
        "f 1 3 2\n"   // 2: its mirror image: kept
        "f 4 2 3\n"   // 3: a red corner where the first is white: kept
        "f 3 1 2\n"   // the first again, from its third corner: out
        "f 3 1 2\n"   // and again: out
        "usemtl b\n"
        "f 1 2 3\n");  // the same in another material: out (F5-18: 20,001 such copies
                       // made every ray test each; which one GL draws is undefined)
  Scene s = loadScene(dir + "/scene.obj");
  SCOPED_TRACE(s.ToString());
  ASSERT_EQ(s.triangleCount(), 3u);
  const Vec3 a{0, 0, 0}, b{1, 0, 0}, c{1, 1, 0};
  const std::vector<std::vector<Vec3>> kept = {{a, b, c}, {a, c, b}, {a, b, c}};
  for (size_t t = 0; t < kept.size(); ++t)
    for (size_t k = 0; k < 3; ++k)
      expectNear(s.positions[s.indices[3 * t + k]], kept[t][k], 0, "corner");
  expectNear(s.albedo(2, 0, 0), {0.5f, 0, 0}, 1e-6f, "the red copy");
  EXPECT_EQ(s.triangleMaterial, (std::vector<int32_t>{0, 0, 0}));
  EXPECT_TRUE(hasWarning(s, "4 of 7 triangles repeat an earlier one (the same vertices and "
                            "winding, 1 of them in another material"))
      << s.warnings.size();
  // A scene without copies loads as it was, with no word.
  write("plain.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\nf 1 3 2\n");
  Scene plain = loadScene(dir + "/plain.obj");
  EXPECT_EQ(plain.triangleCount(), 2u);
  EXPECT_FALSE(hasWarning(plain, "repeat an earlier one"));
}

TEST_F(SceneObj, UndefinedMaterialIsWarnedOnceByName) {
  // usemtl of a name the .mtl does not define (a real asset's "Texture1"):
  // the faces get the default material, and the user hears of it once.
  write("m.mtl", "newmtl wall\nKd 0.5 0.5 0.5\n");
  write("scene.obj",
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

// MTL numbers that are not finite numbers were read as 0 without a word
// (H16-4-5: `Ke inf` drew black): each statement is warned, by line.
TEST_F(SceneObj, MtlValuesThatAreNotNumbersAreWarned) {
  write("m.mtl", "newmtl lamp\nKd 0.5 0.5 0.5\nKe inf 1 1\nKs seven\nNs 10\nKa spectral f.spd\n");
  write("scene.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl lamp\nf 1 2 3\n");
  Scene s = loadScene(dir + "/scene.obj");
  ASSERT_EQ(s.warnings.size(), 2u) << ::testing::PrintToString(s.warnings);
  EXPECT_NE(s.warnings[0].find("m.mtl line 3: Ke 'inf' is not a finite number: read as 0"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_NE(s.warnings[1].find("m.mtl line 4: Ks 'seven' is not a finite number"),
            std::string::npos)
      << s.warnings[1];
}

// An OBJ and an MTL that begin with a UTF-8 byte-order mark (Windows editors
// write one) are read whole: the first statement (mtllib, newmtl) was lost,
// and every material with it, without a word (H17-7-2).
TEST_F(SceneObj, AByteOrderMarkIsSkipped) {
  write("m.mtl", "\xEF\xBB\xBFnewmtl red\nKd 0.8 0.1 0.1\n");
  write("scene.obj", "\xEF\xBB\xBFmtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl red\nf 1 2 3\n");
  const Scene s = loadScene(dir + "/scene.obj");
  EXPECT_TRUE(s.warnings.empty()) << ::testing::PrintToString(s.warnings);
  expectNear(s.albedo(0, 0, 0), {0.8f, 0.1f, 0.1f}, 1e-6f, "red");
  const std::vector<std::string> files = sceneFiles(dir + "/scene.obj");
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(fs::path(files[1]).filename(), "m.mtl");
}

// An MTL colour of one number is grey, as the format says (tinyobjloader
// read `Kd 0.5` as red: green and blue 0); one of two numbers is warned
// (its blue is read as 0).
TEST_F(SceneObj, MtlColourOfOneNumberIsGreyAndOfTwoIsWarned) {
  write("m.mtl", "newmtl grey\nKd 0.5\nnewmtl two\nKd 0.25 0.5 0.75\nKe 1 1\n");
  write("scene.obj",
        "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl grey\nf 1 2 3\n"
        "usemtl two\nf 1 3 4\n");
  const Scene s = loadScene(dir + "/scene.obj");
  expectNear(s.albedo(0, 0, 0), {0.5f, 0.5f, 0.5f}, 1e-6f, "Kd 0.5");
  expectNear(s.albedo(1, 0, 0), {0.25f, 0.5f, 0.75f}, 1e-6f, "Kd of three");
  ASSERT_EQ(s.warnings.size(), 1u) << ::testing::PrintToString(s.warnings);
  EXPECT_NE(s.warnings[0].find("m.mtl line 5: Ke has two numbers: its blue is read as 0"),
            std::string::npos)
      << s.warnings[0];
}

// OBJ vertex colours (`v x y z r g b`) multiply the base colour like glTF's
// COLOR_0, when every vertex has one, read as the display (sRGB) values the
// tools that write them mean; a file where only some have one keeps none
// (white).
TEST_F(SceneObj, VertexColoursMultiplyTheBaseColour) {
  write("m.mtl", "newmtl a\nKd 0.5 0.5 0.5\n");
  write("c.obj",
        "mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0 0 0.5 0\nv 0 1 0 0 0 1\nusemtl a\nf 1 2 3\n");
  const Scene s = loadScene(dir + "/c.obj");
  ASSERT_EQ(s.colors.size(), 4 * s.positions.size());
  expectNear(s.albedo(0, 0, 0), {0.5f, 0, 0}, 1e-6f, "red corner");
  // Display values: 0.5 is sRGB, 0.214 linear.
  expectNear(s.albedo(0, 1, 0), {0, 0.5f * 0.21404f, 0}, 1e-5f, "sRGB 0.5 corner");
  write("some.obj",
        "mtllib m.mtl\nv 0 0 0 1 0 0\nv 1 0 0\nv 0 1 0\nusemtl a\nf 1 2 3\n");
  const Scene some = loadScene(dir + "/some.obj");
  EXPECT_TRUE(some.colors.empty());
  expectNear(some.albedo(0, 0, 0), {0.5f, 0.5f, 0.5f}, 1e-6f, "no colours");
}

// A map_Kd or a material library that names a folder: said to be a folder,
// not missing.
TEST_F(SceneObj, ATextureOrLibraryThatIsAFolderIsNamedAsAFolder) {
  fs::create_directories(dir + "/wood.png");
  write("m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd wood.png\n");
  write("scene.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nusemtl a\nf 1 2 3\n");
  const Scene s = loadScene(dir + "/scene.obj");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("map_Kd 'wood.png' is a folder, not an image file"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_EQ(s.materials[0].baseColorTexture, -1);
  fs::create_directories(dir + "/lib.mtl");
  write("lib.obj", "mtllib lib.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 3\n");
  expectInputError(dir + "/lib.obj", "material library 'lib.mtl' is a folder, not a file");
}

TEST_F(SceneObj, MissingTextureFileIsWarnedOnceByName) {
  write("m.mtl", "newmtl a\nKd 0.5 0.5 0.5\nmap_Kd gone.png\n"
                 "newmtl b\nKd 0.2 0.2 0.2\nmap_Kd gone.png\n");
  write("scene.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                     "usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\n");
  Scene s = loadScene(dir + "/scene.obj");
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("map_Kd 'gone.png' is missing"), std::string::npos) << s.warnings[0];
  ASSERT_EQ(s.materials.size(), 2u);
  EXPECT_EQ(s.materials[0].baseColorTexture, -1);
  EXPECT_EQ(s.materials[1].baseColorTexture, -1);
}

TEST_F(SceneObj, Rejects) {
  fs::create_directories(dir + "/inner");
  write("evil.mtl", "newmtl x\nKd 1 1 1\n");
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expectInputError(write("inner/escape.obj", "mtllib ../evil.mtl\n" + tri + "usemtl x\nf 1 2 3\n"),
                   "outside the scene folder");
  expectInputError(write("inner/absolute.obj", "mtllib /etc/passwd\n" + tri + "f 1 2 3\n"),
                   "outside the scene folder");
  expectInputError(write("inner/nomtl.obj", "mtllib absent.mtl\n" + tri + "f 1 2 3\n"),
                   "missing material library");
  expectInputError(write("inner/index.obj", tri + "f 1 2 9\n"), "out of range");
  expectInputError(write("inner/quad.obj", tri + "f 1 2 3 12\n"), "out of range");
  expectInputError(write("inner/nan.obj", "v 0 0 0\nv 1e400 0 0\nv 0 1 0\nf 1 2 3\n"),
                   "non-finite");
  write("inner/tex.mtl", "newmtl t\nmap_Kd garbage.png\n");
  write("inner/garbage.png", "not an image");
  expectInputError(write("inner/tex.obj", "mtllib tex.mtl\n" + tri + "usemtl t\nf 1 2 3\n"),
                   "unreadable image");
}

// tinyobjloader read "v nan 0 0" and the coordinates missing from "v 1 2"
// as 0: the bake ran on a vertex at the origin without a word (D17 of the
// seventh hostile list). Both are refused, naming the line and the vertex.
TEST_F(SceneObj, AVertexThatIsNotThreeFiniteNumbersIsRefusedNamingItsLine) {
  const std::string rest = "v 0 1 0\nf 1 2 3\n";
  expectInputError(write("nan.obj", "v 0 0 0\nv nan 0 0\n" + rest),
                   "line 2: vertex 2 'v nan 0 0' has a non-finite coordinate");
  expectInputError(write("inf.obj", "v 0 0 0\r\nv 1 -inf 0\r\n" + rest),
                   "line 2: vertex 2 'v 1 -inf 0' has a non-finite coordinate");
  expectInputError(write("short.obj", "# two numbers\nv 0 0 0\nv 1 2\n" + rest),
                   "line 3: vertex 2 'v 1 2' has 2 coordinates, not 3 numbers (x y z)");
  expectInputError(write("one.obj", "v 1\nv 1 0 0\n" + rest),
                   "line 1: vertex 1 'v 1' has 1 coordinate, not 3");
  expectInputError(write("word.obj", "v 0 0 0\nv 1 zero 0\n" + rest), "has 1 coordinate");
  EXPECT_EQ(loadScene(write("fine.obj", "v 0 0 0 # a comment\nv\t1 0 0 0.5 0.5 0.5\n" + rest))
                .triangleCount(),
            1u);
}

// A polygon of n vertices on a circle, then a triangle of another material:
// the OBJ reader keeps a face's vertex count in 8 bits, so a face of 256
// vertices would read as one of 0 and shift the triangle's indices and
// material. Up to 255 vertices load (fan-triangulated), 256 are refused.
TEST_F(SceneObj, AFaceOfMoreThan255VerticesIsRefusedNotShifted) {
  write("two.mtl", "newmtl grey\nKd 0.5 0.5 0.5\nnewmtl lamp\nKd 0 0 0\nKe 1 1 1\n");
  for (int n : {255, 256, 300}) {
    SCOPED_TRACE(n);
    std::string obj = "mtllib two.mtl\n";
    for (int i = 0; i < n; ++i) {
      const double a = 6.283185307179586 * i / n;
      obj += "v " + std::to_string(std::cos(a)) + " 0 " + std::to_string(std::sin(a)) + "\n";
    }
    obj += "v 0 1 0\nv 1 1 0\nv 0 1 1\no disc\nusemtl grey\nf";
    for (int i = 1; i <= n; ++i) obj += " " + std::to_string(i);
    obj += "\no lamp\nusemtl lamp\nf " + std::to_string(n + 1) + " " + std::to_string(n + 2) +
           " " + std::to_string(n + 3) + "\n";
    const std::string path = write("disc" + std::to_string(n) + ".obj", obj);
    if (n <= 255) {
      const Scene s = loadScene(path);
      ASSERT_EQ(s.triangleCount(), size_t(n - 2 + 1));
      int lamp = 0;
      for (size_t t = 0; t < s.triangleCount(); ++t) {
        if (s.materials[size_t(s.triangleMaterial[t])].name == "lamp") {
          ++lamp;
          EXPECT_NEAR(s.positions[s.indices[3 * t]].y, 1.0f, 1e-6f);
        }
      }
      EXPECT_EQ(lamp, 1);
    } else {
      expectInputError(path, "object 'disc' has a face of more than 255 vertices");
    }
  }
}

TEST_F(SceneObj, ASceneFarFromTheOriginKeepsItsPrecision) {
  // The OBJ's own numbers, read again in double (its parser reads float).
  write("far.obj",
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

}  // namespace
}  // namespace lo
