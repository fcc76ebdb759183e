// glTF materials and textures as the loader reads them: the material
// extensions, KHR_texture_transform, data maps decoded linear, alpha modes
// and the emissive texture, vertex colours, a missing texture file; the
// sampler's filters and wraps; texels released after upload.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/image.h"
#include "scene/scene.h"
#include "scene/scene_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

using namespace test;  // scene_fixture.h

/// oneTriangle with material 0, whose texture 0 is tex.ppm, written to
/// `dir`: a 2x1 binary PPM (stb_image reads PNM), red and sRGB grey 188.
MiniGltf texturedTriangle(const std::string& dir) {
  writeFile(dir + "/tex.ppm", std::string("P6\n2 1\n255\n\xff\x00\x00\xbc\xbc\xbc", 17));
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.image = "tex.ppm";
  return g;
}

TEST_F(SceneGltf, MaterialExtensionsAndTexture) {
  MiniGltf g = texturedTriangle(dir);
  g.materials = R"([{"name": "glass", "doubleSided": true, "emissiveFactor": [0.5, 0.25, 1],
    "pbrMetallicRoughness": {"baseColorFactor": [0.5, 1, 1, 1], "metallicFactor": 0.25,
      "roughnessFactor": 0.75, "baseColorTexture": {"index": 0}},
    "extensions": {"KHR_materials_emissive_strength": {"emissiveStrength": 4},
      "KHR_materials_transmission": {"transmissionFactor": 0.9},
      "KHR_materials_ior": {"ior": 1.33}, "KHR_materials_volume": {"thicknessFactor": 0.2}}}])";
  Scene s = loadScene(write("material.gltf", g));
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
TEST_F(SceneGltf, TextureTransform) {
  MiniGltf g = texturedTriangle(dir);
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0, "texCoord": 0,
      "extensions": {"KHR_texture_transform": {"offset": [0.5, -0.25], "rotation": 1.5707963,
        "scale": [2, 3], "texCoord": 1}}}}}])";
  Scene s = loadScene(write("transform.gltf", g));
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
  expectInputError(write("bad-transform.gltf", g), "KHR_texture_transform offset");
}

// normalTexture, metallicRoughnessTexture and occlusionTexture: index, scale
// or strength and UV set are read, and the maps are decoded as data (no sRGB
// curve), a separate texture from the same image used as colour.
TEST_F(SceneGltf, NormalTextureIsLinearData) {
  MiniGltf g = texturedTriangle(dir);
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0},
        "metallicRoughnessTexture": {"index": 0}},
      "normalTexture": {"index": 0, "scale": 0.5},
      "occlusionTexture": {"index": 0, "strength": 0.75}}])";
  Scene s = loadScene(write("normal.gltf", g));
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
TEST_F(SceneGltf, AlphaModesAndEmissiveTexture) {
  // 2x1: left texel opaque white, right texel alpha 64/255; colours
  // (255, 0, 0) and (0, 255, 0) for the emissive use.
  write("alpha.tga", tgaRgba(2, 1, {255, 0, 0, 255, 0, 255, 0, 64}));
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"alphaMode": "MASK", "alphaCutoff": 0.4,
    "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 0.8], "baseColorTexture": {"index": 0}},
    "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 0}}])";
  g.image = "alpha.tga";
  Scene s = loadScene(write("alpha.gltf", g));
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

TEST_F(SceneGltf, UnknownAlphaModeIsRefused) {
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"alphaMode": "DITHER"}])";
  expectRefusal([&] { loadScene(write("bad.gltf", g)); }, {"alphaMode 'DITHER'"});
}

// COLOR_0 multiplies the base colour and its alpha (glTF 2.0, "Metallic-
// Roughness Material"): as normalized unsigned bytes (VEC4) or floats
// (VEC3, alpha 1); a primitive without one is white. Both tracers read it
// through Scene::albedo and Scene::coverage (the GL renderer through its
// vertices, test RenderImage.VertexColoursMultiplyTheBaseColour).
TEST_F(SceneGltf, VertexColoursMultiplyTheBaseColour) {
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
  const Scene s = loadScene(write("colors.gltf", os.str()));
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();
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

// Float vertex colours beyond [0, 1] are clamped, as a base colour factor
// beyond it is, and said (H16-4-3: a COLOR_0 of 100 drew as 1 without a word).
TEST_F(SceneGltf, VertexColoursOutsideTheUnitRangeAreClampedAndWarned) {
  std::string blob;
  append(blob, std::vector<float>{0, 0, 0, 1, 0, 0, 0, 1, 0});
  append(blob, std::vector<float>{100, 0.5f, 0.5f, -5, 0.5f, 0.5f, 0.5f, 0.5f, 0.5f});
  std::ostringstream os;
  os << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
    "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "COLOR_0": 1}}]}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"},
                  {"bufferView": 1, "componentType": 5126, "count": 3, "type": "VEC3"}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36},
                    {"buffer": 0, "byteOffset": 36, "byteLength": 36}],
    "buffers": [{"byteLength": )"
     << blob.size() << R"(, "uri": "data:application/octet-stream;base64,)" << base64(blob)
     << R"("}]})";
  const Scene s = loadScene(write("colors-out.gltf", os.str()));
  ASSERT_EQ(s.colors.size(), 12u);
  EXPECT_EQ(s.colors[0], 1.0f);
  EXPECT_EQ(s.colors[4], 0.0f);
  EXPECT_EQ(s.colors[8], 0.5f);
  size_t said = 0;
  for (const std::string& w : s.warnings) {
    if (w.find("2 vertex colour channel(s) (COLOR_0) outside [0, 1], from -5 to 100: clamped") !=
        std::string::npos) {
      ++said;
    }
  }
  EXPECT_EQ(said, 1u) << ::testing::PrintToString(s.warnings);
}

TEST_F(SceneGltf, MissingTextureFileIsWarnedOnceByName) {
  // An asset copied without one of its textures: the scene loads, the
  // materials using it keep their factors, and the warning names the file
  // once, however many materials use it.
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1],
                     "baseColorTexture": {"index": 0}}, "normalTexture": {"index": 0}}])";
  g.image = "absent.png";
  const Scene s = loadScene(write("absent.gltf", g));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("'absent.png'"), std::string::npos) << s.warnings[0];
  EXPECT_NE(s.warnings[0].find("missing"), std::string::npos) << s.warnings[0];
  EXPECT_EQ(s.materials[0].baseColorTexture, -1);
  EXPECT_EQ(s.materials[0].normalTexture, -1);
  expectNear(s.materials[0].baseColor, {0.5f, 0.25f, 1.0f}, 1e-6f);
}

// A texture URI that names a folder was warned as missing, which sent the
// user looking for a file that is there: the warning says it is a folder.
// The scene loads, the materials keep their factors.
TEST_F(SceneGltf, ATextureThatIsAFolderIsWarnedAsAFolder) {
  std::filesystem::create_directories(dir + "/albedo.png");
  MiniGltf g = oneTriangle();
  g.material = 0;
  g.materials = R"([{"pbrMetallicRoughness": {"baseColorFactor": [0.5, 0.25, 1, 1],
                     "baseColorTexture": {"index": 0}}}])";
  g.image = "albedo.png";
  const Scene s = loadScene(write("folder.gltf", g));
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("texture image 'albedo.png' (texture 0, image 0) is a folder, "
                               "not an image file"),
            std::string::npos)
      << s.warnings[0];
  EXPECT_EQ(s.warnings[0].find("missing"), std::string::npos) << s.warnings[0];
  EXPECT_EQ(s.materials[0].baseColorTexture, -1);
  expectNear(s.materials[0].baseColor, {0.5f, 0.25f, 1.0f}, 1e-6f);
}

// The textures' memory is checked as a total, before any is decoded: each
// image was checked alone as it was decoded, and 160 copies of a 4096^2 PNG
// reached 7.4 GB before one was refused.
TEST_F(SceneGltf, TexturesAreCheckedAgainstTheMemoryAsATotal) {
  // 256 x 256 RGB: 192 KiB kept per texture (1 MiB by the check of one image,
  // which counts the decoder's working copies).
  // Each its own file: images of one file are one texture (below).
  for (int i = 0; i < 16; ++i) {
    writeFile(dir + "/big" + std::to_string(i) + ".ppm",
              "P6\n256 256\n255\n" + std::string(256 * 256 * 3, '\x80'));
  }
  auto scene = [&](int n) {
    MiniGltf g = oneTriangle();
    g.material = 0;
    std::string textures, images, materials;
    for (int i = 0; i < n; ++i) {
      const std::string comma = i ? ", " : "", index = std::to_string(i);
      textures += comma + R"({"source": )" + index + "}";
      images += comma + R"({"uri": "big)" + index + R"(.ppm"})";
      materials += comma + R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": )" +
                   index + "}}}";
    }
    g.extraTop = R"("textures": [)" + textures + R"(], "images": [)" + images + "], ";
    g.materials = "[" + materials + "]";
    return write("textures" + std::to_string(n) + ".gltf", g);
  };
  // 4 MiB available: the textures may take 2 MiB, 10 of them (1.9 MiB), not 16 (3 MiB).
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "4M", 1);
  EXPECT_EQ(loadScene(scene(10)).textures.size(), 10u);
  expectInputError(scene(16), "its 16 textures would take 3.0 MiB decoded");
  expectInputError(scene(16), "more than 2.0 MiB, half the 4.0 MiB of memory available");
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  const Scene s = loadScene(scene(16));
  ASSERT_EQ(s.textures.size(), 16u);
  EXPECT_EQ(s.textures[15].width, 256);
  EXPECT_EQ(s.textures[15].name, "big15.ppm");
  expectNear(s.textures[15].texelAt(0), Vec3{srgbToLinear(128.0f / 255.0f)}, 1e-6f);
}

// Images that name one file are one image: 300 images of one 1024^2 PNG
// were decoded 300 times (1.85 GB for a 4.5 KB file, ninth hostile list
// H9-5-10, H9-5-11) and the total-texture check let them through. One
// texture per file, decoding (colour or data) and sampler; "./one.ppm" is
// "one.ppm".
TEST_F(SceneGltf, ImagesOfOneFileAreDecodedOnce) {
  writeFile(dir + "/one.ppm", "P6\n256 256\n255\n" + std::string(256 * 256 * 3, '\x80'));
  writeFile(dir + "/two.ppm", "P6\n2 2\n255\n" + std::string(2 * 2 * 3, '\x40'));
  MiniGltf g = oneTriangle();
  g.material = 0;
  std::string textures, images, materials;
  const int n = 40;
  for (int i = 0; i < n; ++i) {
    const std::string comma = i ? ", " : "", index = std::to_string(i);
    textures += comma + R"({"source": )" + index + "}";
    images += comma + (i == n - 1 ? std::string(R"({"uri": "two.ppm"})")
                       : i % 2  ? std::string(R"({"uri": "./one.ppm"})")
                                : std::string(R"({"uri": "one.ppm"})"));
    materials += comma + R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": )" + index +
                 "}}}";
  }
  // Material 0 also takes texture 1 as data (its normal map): another decoding.
  materials = R"({"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}},
                 "normalTexture": {"index": 1}})" + materials.substr(materials.find("}}}") + 3);
  g.extraTop = R"("textures": [)" + textures + R"(], "images": [)" + images + "], ";
  g.materials = "[" + materials + "]";
  // Under a limit that holds the two decodings of one.ppm (192 KiB each),
  // not its 39 images decoded each (7.3 MiB).
  setenv("LIGHTOCTREE_MEMORY_LIMIT", "4M", 1);
  const Scene s = loadScene(write("shared.gltf", g));
  unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  ASSERT_EQ(s.textures.size(), 3u);  // one.ppm as colour and as data, two.ppm
  EXPECT_EQ(s.textures[0].width, 256);
  ASSERT_EQ(s.materials.size(), size_t(n));
  for (int i = 0; i < n - 1; ++i) EXPECT_EQ(s.materials[size_t(i)].baseColorTexture, 0) << i;
  EXPECT_EQ(s.materials[0].normalTexture, 1);
  EXPECT_EQ(s.textures[2].width, 2);
  EXPECT_EQ(s.materials[size_t(n - 1)].baseColorTexture, 2);
}

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

}  // namespace
}  // namespace lo
