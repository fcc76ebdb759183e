// The glTF export (scene/gltf_export.h), read back by the project's own
// loader: the lightmap UVs arrive as TEXCOORD_1 bit for bit, triangles,
// positions, material factors, textures (within 8-bit quantisation),
// texture transforms, lights and cameras survive; the unlit form carries the
// preview pages as base colour on TEXCOORD_1; bad exports name the field and
// write nothing. The Khronos validator runs on the command's files (ctest
// gltf.validate_*).

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <fstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "image/image.h"
#include "scene/gltf_export.h"
#include "scene/scene.h"
#include "core/file.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

Texture smallTexture(int w, int h, bool alpha, float offset) {
  std::vector<Vec3> rgb;
  std::vector<float> a;
  for (int i = 0; i < w * h; ++i) {
    rgb.push_back({offset + 0.1f * float(i % 7), 0.05f * float(i), 0.9f - 0.1f * float(i % 5)});
    if (alpha) a.push_back(float(i) / float(w * h));
  }
  Texture t = Texture::fromLinear(w, h, rgb, a);
  t.name = "tex";
  return t;
}

/// Two quads of two materials (the second emissive, transmissive and
/// normal-mapped, its triangles on two lightmap pages), a textured first
/// material with a texture transform, two lights and a camera.
struct ExportCase {
  Scene scene;
  LightmapExport lm;
};

ExportCase exportCase() {
  ExportCase c;
  Scene& s = c.scene;
  s.sourcePath = "case.gltf";
  Material red;
  red.name = "red";
  red.baseColor = {0.6f, 0.1f, 0.05f};
  red.baseAlpha = 0.9f;
  red.metallic = 0.2f;
  red.roughness = 0.7f;
  red.doubleSided = true;
  red.alphaMode = AlphaMode::Mask;
  red.alphaCutoff = 0.3f;
  red.baseColorTexture = 0;
  red.baseColorTransform.offset[0] = 0.25f;
  red.baseColorTransform.offset[1] = 0.5f;
  red.baseColorTransform.rotation = 0.3f;
  red.baseColorTransform.scale[0] = 2;
  red.baseColorTransform.scale[1] = 3;
  Material lamp;
  lamp.name = "lamp";
  lamp.emission = {4, 2, 1};
  lamp.transmission = 0.5f;
  lamp.ior = 1.4f;
  lamp.thickness = 0.2f;
  lamp.normalTexture = 1;
  lamp.normalScale = 0.8f;
  s.materials = {red, lamp};
  s.textures = {smallTexture(3, 2, true, 0.0f), smallTexture(2, 2, false, 0.2f)};
  test::addQuad(s, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  test::addQuad(s, {0, 0, 1}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 1);
  for (size_t v = 0; v < s.positions.size(); ++v) {
    s.normals.push_back(v < 4 ? Vec3{0, 0, 1} : normalize(Vec3{1, 0.1f, 0}));
    s.texcoords0.insert(s.texcoords0.end(), {0.1f * float(v), 1.0f - 0.05f * float(v)});
  }
  Light point;
  point.name = "bulb";
  point.position = {0.5f, 2, 0.5f};
  point.color = {1, 0.5f, 0.25f};
  point.intensity = 3;
  point.range = 10;
  Light spot;
  spot.type = Light::Type::Spot;
  spot.name = "spot";
  spot.position = {1, 1, 1};
  spot.direction = normalize(Vec3{-1, -2, 0.5f});
  spot.intensity = 5;
  spot.innerConeAngle = 0.2f;
  spot.outerConeAngle = 0.6f;
  s.lights = {point, spot};
  Camera cam;
  cam.name = "view";
  cam.position = {0.3f, 0.4f, 3};
  cam.forward = normalize(Vec3{0.1f, -0.2f, -1});
  cam.up = normalize(Vec3{0, 1, 0} - cam.forward * dot(Vec3{0, 1, 0}, cam.forward));
  cam.yfov = 0.7f;
  s.cameras = {cam};

  const size_t nt = s.triangleCount();
  for (size_t i = 0; i < 6 * nt; ++i) c.lm.uv.push_back(float((i * 37) % 101) / 100.0f);
  c.lm.trianglePage = {0, 0, 0, 1};
  c.lm.width = c.lm.height = 64;
  c.lm.pageUris = {"case-lightmap0.exr", "case lightmap1.exr"};
  return c;
}

/// Loaded triangle t's corner k against the export's lightmap UV.
void expectTexcoord1(const Scene& loaded, const LightmapExport& lm) {
  ASSERT_EQ(loaded.texcoords1.size(), 2 * loaded.positions.size());
  for (size_t c = 0; c < loaded.indices.size(); ++c) {
    const uint32_t v = loaded.indices[c];
    ASSERT_EQ(loaded.texcoords1[2 * v], lm.uv[2 * c]) << "corner " << c;
    ASSERT_EQ(loaded.texcoords1[2 * v + 1], lm.uv[2 * c + 1]) << "corner " << c;
  }
}

TEST(GltfExport, LoaderReadsBackGeometryLightmapUvsMaterialsLightsAndCameras) {
  const ExportCase c = exportCase();
  const std::string dir = test::outputDir("GltfExportRoundTrip");
  for (const char* name : {"case.glb", "case.gltf"}) {
    SCOPED_TRACE(name);
    const std::string path = dir + "/" + name;
    writeLightmapGltf(c.scene, c.lm, path);
    EXPECT_TRUE(leftoverTemporaries(path).empty());
    if (std::string(name) == "case.gltf") {
      EXPECT_TRUE(fs::exists(dir + "/case.bin"));
      // The page uri is percent-encoded in the extras.
      EXPECT_NE(readFile(path).find("\"uri\": \"case%20lightmap1.exr\""), std::string::npos);
    }
    const Scene back = loadScene(path);
    ASSERT_EQ(back.triangleCount(), c.scene.triangleCount());
    // Primitives by (material, page), scene order within: here the order is kept.
    for (size_t i = 0; i < c.scene.indices.size(); ++i) {
      ASSERT_EQ(back.positions[back.indices[i]], c.scene.positions[c.scene.indices[i]]) << i;
      ASSERT_LT(length(back.normals[back.indices[i]] - c.scene.normals[c.scene.indices[i]]), 1e-6f);
      ASSERT_EQ(back.texcoords0[2 * back.indices[i]], c.scene.texcoords0[2 * c.scene.indices[i]]);
    }
    expectTexcoord1(back, c.lm);

    // red on page 0; lamp on pages 0 and 1: two glTF materials.
    ASSERT_EQ(back.materials.size(), 3u);
    EXPECT_EQ(back.triangleMaterial, (std::vector<int32_t>{0, 0, 1, 2}));
    const Material& red = back.materials[0];
    const Material& want = c.scene.materials[0];
    EXPECT_EQ(red.name, "red");
    EXPECT_EQ(red.baseColor, want.baseColor);
    EXPECT_EQ(red.baseAlpha, want.baseAlpha);
    EXPECT_EQ(red.metallic, want.metallic);
    EXPECT_EQ(red.roughness, want.roughness);
    EXPECT_EQ(red.alphaMode, AlphaMode::Mask);
    EXPECT_EQ(red.alphaCutoff, want.alphaCutoff);
    EXPECT_TRUE(red.doubleSided);
    EXPECT_EQ(red.baseColorTexCoord, 0);
    for (int k = 0; k < 2; ++k) {
      EXPECT_EQ(red.baseColorTransform.offset[k], want.baseColorTransform.offset[k]);
      EXPECT_EQ(red.baseColorTransform.scale[k], want.baseColorTransform.scale[k]);
    }
    EXPECT_EQ(red.baseColorTransform.rotation, want.baseColorTransform.rotation);
    // Colour texels through the sRGB curve and back: the same 8-bit codes;
    // alpha (linear) within half a step.
    ASSERT_GE(red.baseColorTexture, 0);
    const Texture& tex = back.textures[size_t(red.baseColorTexture)];
    const Texture& orig = c.scene.textures[0];
    ASSERT_EQ(tex.width, orig.width);
    ASSERT_EQ(tex.height, orig.height);
    ASSERT_EQ(tex.hasAlpha(), orig.hasAlpha());
    for (size_t i = 0; i < orig.texelCount(); ++i) {
      for (int k = 0; k < 3; ++k)
        EXPECT_EQ(encodeSrgb8(tex.texelAt(i)[k]), encodeSrgb8(orig.texelAt(i)[k])) << i;
      EXPECT_NEAR(tex.alphaAt(i), orig.alphaAt(i), 0.5f / 255 + 1e-6f) << i;
    }
    for (size_t m : {size_t(1), size_t(2)}) {
      const Material& lamp = back.materials[m];
      EXPECT_EQ(lamp.name, "lamp (lightmap page " + std::to_string(m - 1) + ")");
      EXPECT_EQ(lamp.emission, c.scene.materials[1].emission);  // factor 1 x strength 4
      EXPECT_EQ(lamp.transmission, 0.5f);
      EXPECT_EQ(lamp.ior, 1.4f);
      EXPECT_EQ(lamp.thickness, 0.2f);
      EXPECT_EQ(lamp.normalScale, 0.8f);
      ASSERT_GE(lamp.normalTexture, 0);
      const Texture& n = back.textures[size_t(lamp.normalTexture)];
      for (size_t i = 0; i < n.texelCount(); ++i)
        for (int k = 0; k < 3; ++k)
          EXPECT_NEAR(n.texelAt(i)[k], std::clamp(c.scene.textures[1].texelAt(i)[k], 0.0f, 1.0f),
                      0.5f / 255 + 1e-6f);
    }

    ASSERT_EQ(back.lights.size(), 2u);
    for (size_t i = 0; i < 2; ++i) {
      const Light& a = back.lights[i];
      const Light& b = c.scene.lights[i];
      EXPECT_EQ(a.type, b.type);
      EXPECT_EQ(a.name, b.name);
      EXPECT_LT(length(a.position - b.position), 1e-6f);
      EXPECT_EQ(a.color, b.color);
      EXPECT_EQ(a.intensity, b.intensity);
      if (a.type == Light::Type::Spot) {
        EXPECT_LT(length(a.direction - b.direction), 1e-6f) << a.direction.ToString();
        EXPECT_NEAR(a.innerConeAngle, b.innerConeAngle, 1e-7f);
        EXPECT_NEAR(a.outerConeAngle, b.outerConeAngle, 1e-7f);
      }
    }
    EXPECT_EQ(back.lights[0].range, 10.0f);
    ASSERT_EQ(back.cameras.size(), 1u);
    EXPECT_LT(length(back.cameras[0].position - c.scene.cameras[0].position), 1e-6f);
    EXPECT_LT(length(back.cameras[0].forward - c.scene.cameras[0].forward), 1e-6f);
    EXPECT_LT(length(back.cameras[0].up - c.scene.cameras[0].up), 1e-6f);
    EXPECT_EQ(back.cameras[0].yfov, 0.7f);
  }
}

// A texture read from a PNG or JPEG goes into the export as the file's own
// bytes (once, whichever materials use it), not as its texels encoded anew,
// with its sampler; a texture made in code is encoded as PNG.
TEST(GltfExport, ImagesReadFromFilesKeepTheirBytesAndSampler) {
  ExportCase c = exportCase();
  const std::vector<uint8_t> pixels = {10, 20, 30, 255, 40, 50, 60, 128, 70, 80, 90, 0,
                                       1,  2,  3,  4,   5,  6,  7,  8,   9,  10, 11, 12};
  const std::vector<unsigned char> png = encodePng8(3, 2, 4, pixels.data());
  Texture fromFile;
  fromFile.width = 3;
  fromFile.height = 2;
  fromFile.channels = 4;
  fromFile.format = TexelFormat::Unorm8;
  fromFile.srgb = true;
  fromFile.unorm8 = pixels;
  fromFile.encoded = std::make_shared<const std::vector<uint8_t>>(png.begin(), png.end());
  fromFile.mimeType = "image/png";
  fromFile.sampler.wrapS = TextureSampler::kClampToEdge;
  c.scene.textures[0] = fromFile;
  c.scene.materials[1].emissiveTexture = 0;  // the same image, used twice
  const GltfFiles files = encodeLightmapGltf(c.scene, c.lm, "files.gltf");
  const nlohmann::json doc = nlohmann::json::parse(files.gltf);
  ASSERT_EQ(doc["images"].size(), 2u) << "the file's image once, the code-made normal map once";
  const nlohmann::json& view = doc["bufferViews"][doc["images"][0]["bufferView"].get<int>()];
  const size_t offset = view.value("byteOffset", size_t(0)), length = view["byteLength"];
  ASSERT_LE(offset + length, files.bin.size());
  EXPECT_EQ(std::string(files.bin, offset, length), std::string(png.begin(), png.end()));
  EXPECT_EQ(doc["images"][0]["mimeType"], "image/png");
  EXPECT_EQ(doc["images"][1]["mimeType"], "image/png");
  const nlohmann::json& texture = doc["textures"][doc["materials"][0]["pbrMetallicRoughness"]
                                                    ["baseColorTexture"]["index"].get<int>()];
  ASSERT_TRUE(texture.contains("sampler"));
  EXPECT_EQ(doc["samplers"][texture["sampler"].get<int>()]["wrapS"], TextureSampler::kClampToEdge);
}

// A scene with a second UV set of its own (not the lightmap): it moves to
// TEXCOORD_2, and TEXCOORD_1 is the lightmap. With the scene's TEXCOORD_1
// as the lightmap (--uv texcoord1) there is no TEXCOORD_2.
TEST(GltfExport, OwnSecondUvSetMovesToTexcoord2) {
  ExportCase c = exportCase();
  const std::string dir = test::outputDir("GltfExportTexcoord2");
  for (size_t v = 0; v < c.scene.positions.size(); ++v)
    c.scene.texcoords1.insert(c.scene.texcoords1.end(), {0.5f, 0.25f});
  writeLightmapGltf(c.scene, c.lm, dir + "/own.glb");
  EXPECT_NE(readFile(dir + "/own.glb").find("TEXCOORD_2"), std::string::npos);
  expectTexcoord1(loadScene(dir + "/own.glb"), c.lm);

  // The lightmap from the scene's own TEXCOORD_1: one value per vertex.
  c.lm.uv.clear();
  for (uint32_t v : c.scene.indices)
    c.lm.uv.insert(c.lm.uv.end(), {c.scene.texcoords1[2 * v], c.scene.texcoords1[2 * v + 1]});
  writeLightmapGltf(c.scene, c.lm, dir + "/same.glb");
  EXPECT_EQ(readFile(dir + "/same.glb").find("TEXCOORD_2"), std::string::npos);
  expectTexcoord1(loadScene(dir + "/same.glb"), c.lm);
}

// Vertex colours (COLOR_0) go out as they came in: the export of a scene
// that has them reads back with the same colours at every corner.
TEST(GltfExport, VertexColoursGoOutAsTheyCameIn) {
  ExportCase c = exportCase();
  const std::string dir = test::outputDir("GltfExportColors");
  for (size_t v = 0; v < c.scene.positions.size(); ++v) {
    c.scene.colors.insert(c.scene.colors.end(), {float(v % 3) / 2.0f, 0.25f, 1.0f, 0.5f});
  }
  writeLightmapGltf(c.scene, c.lm, dir + "/colors.glb");
  const Scene back = loadScene(dir + "/colors.glb");
  ASSERT_EQ(back.colors.size(), 4 * back.positions.size());
  for (size_t i = 0; i < c.scene.indices.size(); ++i) {
    for (int a = 0; a < 4; ++a) {
      ASSERT_EQ(back.colors[4 * back.indices[i] + size_t(a)],
                c.scene.colors[4 * c.scene.indices[i] + size_t(a)])
          << "corner " << i << " channel " << a;
    }
  }
}

TEST(GltfExport, UnlitFormShowsThePreviewOnTexcoord1) {
  ExportCase c = exportCase();
  const std::string dir = test::outputDir("GltfExportUnlit");
  std::vector<RgbImage> pages;
  for (int p = 0; p < 2; ++p) {
    RgbImage img(4, 4);
    for (size_t i = 0; i < img.rgb.size(); ++i) img.rgb[i] = 0.05f * float(i % 13) + 0.3f * p;
    pages.push_back(img);
    c.lm.previewPng.push_back(encodePng(img));
  }
  c.lm.unlit = true;
  writeLightmapGltf(c.scene, c.lm, dir + "/preview.glb");
  const std::string bytes = readFile(dir + "/preview.glb");
  EXPECT_NE(bytes.find("\"extensionsUsed\":[\"KHR_materials_unlit\"]"), std::string::npos);
  EXPECT_EQ(bytes.find("KHR_lights_punctual"), std::string::npos);  // nothing is lit
  const Scene back = loadScene(dir + "/preview.glb");
  expectTexcoord1(back, c.lm);
  ASSERT_EQ(back.materials.size(), 3u);
  const int pageOf[3] = {0, 0, 1};
  for (size_t m = 0; m < 3; ++m) {
    const Material& mat = back.materials[m];
    EXPECT_EQ(mat.baseColor, Vec3(1, 1, 1));
    EXPECT_EQ(mat.emission, Vec3(0, 0, 0));
    EXPECT_EQ(mat.baseColorTexCoord, 1);
    ASSERT_GE(mat.baseColorTexture, 0);
    const Texture& t = back.textures[size_t(mat.baseColorTexture)];
    const RgbImage& want = pages[size_t(pageOf[m])];
    ASSERT_EQ(t.width, 4);
    for (size_t i = 0; i < want.pixelCount(); ++i)
      for (int k = 0; k < 3; ++k)
        ASSERT_EQ(encodeSrgb8(t.texelAt(i)[k]), encodeSrgb8(want.at(i)[k])) << m << " " << i;
  }
}

TEST(GltfExport, BadExportsNameTheFieldAndWriteNothing) {
  const std::string dir = test::outputDir("GltfExportErrors");
  const std::string path = dir + "/bad.glb";
  auto expectError = [&](const LightmapExport& lm, const std::string& field, const std::string& p) {
    try {
      writeLightmapGltf(exportCase().scene, lm, p);
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
    EXPECT_FALSE(fs::exists(p));
    EXPECT_TRUE(leftoverTemporaries(p).empty());
  };
  const LightmapExport good = exportCase().lm;
  LightmapExport lm = good;
  lm.uv.pop_back();
  expectError(lm, "LightmapExport.uv", path);
  lm = good;
  lm.uv[3] = 1.5f;
  expectError(lm, "outside [0, 1]", path);
  lm = good;
  lm.trianglePage[1] = 2;
  expectError(lm, "LightmapExport.trianglePage: triangle 1 is on page 2 of 2", path);
  lm = good;
  lm.encoding = "rgbm-png";
  expectError(lm, "LightmapExport.rgbmRange", path);
  lm = good;
  lm.unlit = true;
  expectError(lm, "LightmapExport.previewPng", path);
  lm = good;
  lm.pageUris[0] = "../up.exr";
  expectError(lm, "LightmapExport.pageUris[0]", path);
  expectError(good, "must end in .glb or .gltf", dir + "/bad.obj");
}

}  // namespace
}  // namespace lo
