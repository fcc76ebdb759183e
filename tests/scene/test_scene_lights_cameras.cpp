// Lights and cameras as the loader reads them: KHR_lights_punctual under
// node transforms, values kept in their ranges or refused by name, cameras
// that cannot show anything refused; and the framing of a scene without a
// camera.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"
#include "scene/scene_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

using namespace test;  // scene_fixture.h

TEST_F(SceneGltf, LightAndMaterialValuesStayInTheirRanges) {
  // glTF's [0, 1] factors are clamped with a warning naming them; a negative
  // emission is taken as 0, warned; intensities and positions beyond what
  // the bake can carry are refused, naming the light (docs/scene.md, "Limits").
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
  const Scene s = loadScene(write("odd.gltf", g));
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
  // A spot's inner cone beyond its outer one (glTF asks inner < outer): the
  // renderer drew none of its direct light, the tracers the outer cone
  // (eighth hostile list F4-35). Clamped to the outer cone, warned.
  const Scene spot = loadScene(write(
      "spot.gltf",
      withLight(R"({"type": "spot", "intensity": 1,
                    "spot": {"innerConeAngle": 1.0, "outerConeAngle": 0.2}})",
                "[0, 1, 0]")));
  ASSERT_EQ(spot.lights.size(), 1u);
  EXPECT_FLOAT_EQ(spot.lights[0].outerConeAngle, 0.2f);
  EXPECT_EQ(spot.lights[0].innerConeAngle, spot.lights[0].outerConeAngle);
  all.clear();
  for (const std::string& w : spot.warnings) all += w + "\n";
  EXPECT_NE(all.find("light 'L' has innerConeAngle 1 beyond its outerConeAngle 0.2 (radians): "
                     "clamped to 0.2"),
            std::string::npos)
      << all;
  expectInputError(
      write("bright.gltf",
                withLight(R"({"type": "point", "intensity": 1e37})", "[0, 1, 0]")),
      "light 'L' has intensity 1e+37");
  expectInputError(
      write("far.gltf", withLight(R"({"type": "point", "intensity": 1})", "[1e19, 0, 0]")),
      "light 'L' lies at");
}

// A field of another JSON type than glTF gives it was taken by tinygltf as
// absent, its default without a word (ninth hostile list H9-4-103: a point
// light's "intensity": "5" lit as 1; H9-4-111: "emissiveFactor": "bright"
// on the only emitter, then "scene has no light"; H9-4-120..122: the sky key
// in the file's own extras, ignored). Refused, naming the JSON pointer.
TEST_F(SceneGltf, FieldsOfAnotherTypeAreRefusedNamingTheirPointer) {
  auto withLight = [](const std::string& light) {
    MiniGltf g = oneTriangle();
    g.nodes = R"([{"mesh": 0}, {"name": "L", "translation": [0, 1, 0],
                  "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual":
                    {"lights": [)" + light + R"(]}}, )";
    return g;
  };
  // The same light with a number is read as it says.
  const Scene five = loadScene(write("five.gltf", withLight(R"({"type": "point", "intensity": 5})")));
  ASSERT_EQ(five.lights.size(), 1u);
  EXPECT_EQ(five.lights[0].intensity, 5.0f);
  expectInputError(write("text.gltf", withLight(R"({"type": "point", "intensity": "5"})")),
                   "/extensions/KHR_lights_punctual/lights/0/intensity is \"5\", expected a number");
  expectInputError(write("colour.gltf", withLight(R"({"type": "point", "color": [1, 1]})")),
                   "/extensions/KHR_lights_punctual/lights/0/color is [1,1], expected an array of 3 numbers");
  MiniGltf material = oneTriangle();
  material.material = 0;
  material.materials = R"([{"name": "lamp", "emissiveFactor": "bright"}])";
  expectInputError(write("emissive.gltf", material),
                   "/materials/0/emissiveFactor is \"bright\", expected an array of 3 numbers");
  material.materials = R"([{"pbrMetallicRoughness": {"roughnessFactor": null}}])";
  expectInputError(write("rough.gltf", material),
                   "/materials/0/pbrMetallicRoughness/roughnessFactor is null, expected a number");
  MiniGltf node = oneTriangle();
  node.nodes = R"([{"mesh": 0, "translation": [0, "1", 0]}])";
  expectInputError(write("node.gltf", node), "/nodes/0/translation is [0,\"1\",0]");
  // What ties the file together (tenth list H10-4-197..244): a node's mesh of
  // -1 dropped the node's object, children "7" its subtree; now refused.
  node.nodes = R"([{"mesh": -1}])";
  expectInputError(write("mesh.gltf", node), "/nodes/0/mesh is -1, expected a whole number from 0");
  node.nodes = R"([{"mesh": 0, "children": "7"}])";
  expectInputError(write("children.gltf", node),
                   "/nodes/0/children is \"7\", expected an array of whole numbers from 0");
  node.nodes = R"([{"mesh": 0.0}])";  // tinygltf drops an index written as 0.0 too
  expectInputError(write("whole.gltf", node), "/nodes/0/mesh is 0.0, expected a whole number");
  for (const char* sky : {"[-1, -1, -1]", "[1, 1]", "\"blue\"", "[1, 1, 1]"}) {
    MiniGltf top = oneTriangle();
    top.extraTop = std::string(R"("extras": {"lightoctree_sky": )") + sky + "}, ";
    expectInputError(write("top-sky.gltf", top),
                     "/extras/lightoctree_sky is read from the scene's extras "
                     "(/scenes/N/extras/lightoctree_sky), not the file's");
  }
}

// More fields tinygltf dropped without a word, from the eleventh hostile
// list (H11-4-222/223, -205, -158, -153/155, -258/266): a mesh's primitives
// empty or null, a texture index "0", a buffer's byteLength "2496", a file of
// another glTF version, and JSON in UTF-16.
TEST_F(SceneGltf, EmptyPrimitivesTextIndicesAndOtherVersionsAreRefused) {
  const MiniGltf g = oneTriangle();
  auto edited = [&](const char* name, const std::string& from, const std::string& to) {
    std::string text = g.json();
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    text.replace(at, from.size(), to);
    const std::string path = dir + "/" + name;
    std::ofstream(path, std::ios::binary) << text;
    return path;
  };
  const std::string meshes = R"("meshes": [{"primitives": [)";
  expectInputError(edited("none.gltf", meshes, R"("meshes": [{"primitives": []}, {"primitives": [)"),
                   "/meshes/0/primitives is [], expected an array of at least 1 element");
  expectInputError(edited("null.gltf", meshes, R"("meshes": [{"primitives": [null]}, {"primitives": [)"),
                   "/meshes/0/primitives/0 is null, expected an object");
  // Members glTF requires (twelfth list H12-4-23, -36, -167): a primitive
  // without attributes, lights given as an object, a texture without index.
  expectInputError(edited("bare.gltf", meshes, R"("meshes": [{"primitives": [{}]}, {"primitives": [)"),
                   "/meshes/0/primitives/0/attributes is missing, expected an object");
  expectInputError(edited("lights.gltf", "\"scene\": 0",
                          R"("extensions": {"KHR_lights_punctual": {"lights": {"type": "point"}}}, "scene": 0)"),
                   "/extensions/KHR_lights_punctual/lights is {\"type\":\"point\"}, expected an array");
  const std::string version = R"({"version": "2.0"})";
  expectInputError(edited("v3.gltf", version, R"({"version": "3.0"})"),
                   "glTF 3.0 (/asset/version): lightoctree reads glTF 2.0");
  expectInputError(edited("min9.gltf", version, R"({"version": "2.0", "minVersion": "9.0"})"),
                   "needs glTF 9.0 (/asset/minVersion)");
  expectInputError(edited("vtext.gltf", version, R"({"version": "two"})"),
                   "/asset/version is \"two\", expected MAJOR.MINOR");
  // A long one is quoted cut, as other values (H12-5-23: 10 MB quoted whole).
  try {
    loadScene(edited("vlong.gltf", version, "{\"version\": \"" + std::string(100000, '7') + "\"}"));
    ADD_FAILURE() << "a version of 100,000 digits was taken";
  } catch (const InputError& e) {
    EXPECT_LT(std::string(e.what()).size(), 400u) << std::string(e.what()).substr(0, 400);
  }
  EXPECT_NO_THROW(loadScene(edited("v21.gltf", version, R"({"version": "2.1", "minVersion": "2.0"})")));
  const std::string length = "\"byteLength\": " + std::to_string(g.blob().size()) + ", \"uri\"";
  expectInputError(edited("length.gltf", length,
                          "\"byteLength\": \"" + std::to_string(g.blob().size()) + "\", \"uri\""),
                   "/buffers/0/byteLength is \"" + std::to_string(g.blob().size()) +
                       "\", expected a whole number from 0");
  MiniGltf textured = oneTriangle();
  textured.material = 0;
  textured.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": "0"}}}])";
  expectInputError(write("index.gltf", textured),
                   "/materials/0/pbrMetallicRoughness/baseColorTexture/index is \"0\", expected a "
                   "whole number from 0");
  textured.materials = R"([{"emissiveTexture": {"texCoord": 0}}])";
  expectInputError(write("noindex.gltf", textured),
                   "/materials/0/emissiveTexture/index is missing, expected a whole number from 0");
  // UTF-16 (little-endian, with its byte-order mark): named as such.
  std::string utf16 = "\xff\xfe";
  for (char c : g.json()) utf16 += std::string{c, '\0'};
  std::ofstream(dir + "/utf16.gltf", std::ios::binary) << utf16;
  expectInputError(dir + "/utf16.gltf", "the JSON is UTF-16 or UTF-32");
}

// A node matrix whose bottom row is not (0, 0, 0, 1) is projective, which
// glTF forbids; its bottom row was dropped without a word (H9-4-94).
TEST_F(SceneGltf, AProjectiveNodeMatrixIsRefusedNamingTheNode) {
  MiniGltf g = oneTriangle();
  g.nodes = R"([{"name": "floor", "mesh": 0,
                 "matrix": [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 1, 0, 0, 0, 0]}])";
  expectInputError(write("projective.gltf", g),
                   "node 0 'floor': matrix has the bottom row (0, 0, 1, 0), expected (0, 0, 0, 1)");
  g.nodes = R"([{"name": "floor", "mesh": 0,
                 "matrix": [2, 0, 0, 0, 0, 2, 0, 0, 0, 0, 2, 0, 1, 2, 3, 1]}])";
  const Scene s = loadScene(write("affine.gltf", g));
  ASSERT_FALSE(s.positions.empty());
  double lowX = 1e30, highX = -1e30;  // the triangle spans x 0..1, scaled by 2 and moved by 1
  for (const Vec3& p : s.positions) {
    lowX = std::min(lowX, s.toWorld(p).x);
    highX = std::max(highX, s.toWorld(p).x);
    EXPECT_NEAR(s.toWorld(p).z, 3.0, 1e-5);
  }
  EXPECT_NEAR(lowX, 1.0, 1e-5);
  EXPECT_NEAR(highX, 3.0, 1e-5);
}

// A spot's cone out of glTF's range (0 < outer <= pi/2, 0 <= inner < outer):
// negative angles lit the room as a wide cone, an outer cone of 0 sent nothing,
// both without a word (H9-4-101). An outer cone of no width is refused, the
// other angles clamped with a warning naming the light.
TEST_F(SceneGltf, SpotConesOutsideGltfsRangeAreRefusedOrClampedNamingTheLight) {
  auto spot = [&](const std::string& name, const std::string& cone) {
    MiniGltf g = oneTriangle();
    g.nodes = R"([{"mesh": 0}, {"name": "S", "translation": [0, 1, 0],
                  "extensions": {"KHR_lights_punctual": {"light": 0}}}])";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("extensionsUsed": ["KHR_lights_punctual"], "extensions": {"KHR_lights_punctual":
                    {"lights": [{"type": "spot", "intensity": 10, "spot": )" + cone + "}]}}, ";
    return write(name, g);
  };
  expectInputError(spot("neg.gltf", R"({"innerConeAngle": -1, "outerConeAngle": -0.5})"),
                   "light 'S' has outerConeAngle -0.5 (radians)");
  expectInputError(spot("zero.gltf", R"({"innerConeAngle": 0, "outerConeAngle": 0})"),
                   "light 'S' has outerConeAngle 0 (radians)");
  const Scene inner = loadScene(spot("inner.gltf", R"({"innerConeAngle": -1, "outerConeAngle": 0.5})"));
  ASSERT_EQ(inner.lights.size(), 1u);
  EXPECT_EQ(inner.lights[0].innerConeAngle, 0.0f);
  EXPECT_FLOAT_EQ(inner.lights[0].outerConeAngle, 0.5f);
  const Scene wide = loadScene(spot("wide.gltf", R"({"outerConeAngle": 3})"));
  EXPECT_FLOAT_EQ(wide.lights[0].outerConeAngle, kPi / 2);
  std::string all;
  for (const std::string& w : inner.warnings) all += w + "\n";
  for (const std::string& w : wide.warnings) all += w + "\n";
  EXPECT_NE(all.find("light 'S' has innerConeAngle -1 (radians), below 0: clamped to 0"),
            std::string::npos)
      << all;
  EXPECT_NE(all.find("light 'S' has outerConeAngle 3 (radians), beyond pi/2: clamped to pi/2"),
            std::string::npos)
      << all;
}

TEST_F(SceneGltf, PunctualLights) {
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
  Scene s = loadScene(write("lights.gltf", g));
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

TEST_F(SceneGltf, CamerasThatCannotShowAnythingAreRefused) {
  // A camera whose up is parallel to its view (here: squashed to nothing
  // along its up), whose far plane is nearer than its near one, or that
  // lies beyond kMaxCoordinate: refused by name instead of a black image.
  auto withCamera = [&](const std::string& name, const std::string& node,
                        const std::string& perspective) {
    MiniGltf g = oneTriangle();
    g.nodes = R"([{"mesh": 0}, )" + node + "]";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("cameras": [{"type": "perspective", "perspective": )" + perspective + "}], ";
    return write(name, g);
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
  // A near plane beyond the whole scene (eighth hostile list F4-55): the
  // renderer leaves it out, as the tracers; the loader says so.
  const Scene beyond = loadScene(withCamera("znear.gltf", R"({"camera": 0, "name": "far-near",
                                              "translation": [0, 0, 3]})",
                                            R"({"yfov": 0.8, "znear": 1e30})"));
  std::string all;
  for (const std::string& w : beyond.warnings) all += w + "\n";
  EXPECT_NE(all.find("camera 'far-near' has znear 1e+30, beyond the whole scene"),
            std::string::npos)
      << all;
  const Scene near = loadScene(withCamera("near.gltf", R"({"camera": 0, "translation": [0, 0, 3]})",
                                          R"({"yfov": 0.8, "znear": 1e-30, "zfar": 1e30})"));
  EXPECT_TRUE(near.warnings.empty()) << near.warnings.front();
  // An orthographic camera is left out, said so; one of magnification 0
  // (glTF forbids it) is refused (H10-4-166: both taken without a word).
  auto ortho = [&](const std::string& name, const std::string& mags) {
    MiniGltf g = oneTriangle();
    g.nodes = R"([{"mesh": 0}, {"camera": 0, "name": "top", "translation": [0, 0, 3]}])";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("cameras": [{"type": "orthographic", "orthographic": {)" + mags +
                 R"(, "znear": 0.1, "zfar": 10}}], )";
    return write(name, g);
  };
  const Scene top = loadScene(ortho("ortho.gltf", R"("xmag": 1, "ymag": 1)"));
  EXPECT_TRUE(top.cameras.empty());
  ASSERT_EQ(top.warnings.size(), 1u);
  EXPECT_NE(top.warnings[0].find("camera 'top' on node 1 is orthographic, which lightoctree does "
                                 "not draw: left out"),
            std::string::npos)
      << top.warnings[0];
  expectInputError(ortho("ortho0.gltf", R"("xmag": 0, "ymag": 0)"),
                   "camera 'top' on node 1: orthographic xmag 0 and ymag 0 (glTF: finite and not zero)");
}

// A yfov of 1e-30 radians was taken (a projection of scale 1e30, an image of
// one texel of the scene) and one of 0 or pi refused without a name: a
// scene's camera takes the fields of view --fov takes (kFovDegreesRange),
// and a refusal names the camera and its yfov.
TEST_F(SceneGltf, ACameraFieldOfViewOutsideWhatFovTakesIsRefusedNamingTheCamera) {
  auto withYfov = [&](const std::string& name, const std::string& yfov) {
    MiniGltf g = oneTriangle();
    g.nodes = R"([{"mesh": 0}, {"camera": 0, "name": "tele", "translation": [0, 0, 3]}])";
    g.sceneNodes = "[0, 1]";
    g.extraTop = R"("cameras": [{"type": "perspective", "perspective": {"yfov": )" + yfov +
                 R"(, "znear": 0.1}}], )";
    return write(name, g);
  };
  for (const char* yfov : {"1e-30", "0.0001", "0", "-0.5", "3.14159265358979", "3.2"}) {
    const std::string path = withYfov(std::string("yfov-") + yfov + ".gltf", yfov);
    expectInputError(path, "camera 'tele' on node 1: yfov");
    expectInputError(path, "must be a finite number from 1 to 179 degrees");
  }
  // The edges of the range, as --fov takes them: 1 and 179 degrees.
  for (double degrees : {1.0001, 30.0, 178.999}) {
    char yfov[32];
    std::snprintf(yfov, sizeof yfov, "%.17g", degrees * kPi / 180.0);
    const Scene s = loadScene(withYfov("fine.gltf", yfov));
    ASSERT_EQ(s.cameras.size(), 1u);
    EXPECT_NEAR(double(s.cameras[0].yfov) * 180.0 / kPi, degrees, 1e-4);
  }
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
