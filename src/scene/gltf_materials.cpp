/// @file scene/gltf_materials.cpp
/// @brief The glTF materials as Scene materials (SceneBuilder, gltf_internal.h):
/// factors, alpha, the KHR_materials_* extensions read, texture references
/// with KHR_texture_transform, samplers, and images decoded into textures.

#include "scene/gltf_internal.h"

#include <cmath>
#include <filesystem>
#include <initializer_list>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "core/file.h"

namespace lo::scene_internal::gltf_internal {

namespace {

namespace fs = std::filesystem;

double numberExt(const tinygltf::ExtensionMap& ext, const char* name, const char* key,
                 double fallback) {
  auto it = ext.find(name);
  if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key)) return fallback;
  const tinygltf::Value& v = it->second.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

}  // namespace

void SceneBuilder::convertMaterials() {
  for (size_t i = 0; i < model_.materials.size(); ++i) {
    const tinygltf::Material& g = model_.materials[i];
    Material m;
    m.name = g.name.empty() ? "material" + std::to_string(i) : g.name;
    const auto& pbr = g.pbrMetallicRoughness;
    m.baseColor = vec3From(pbr.baseColorFactor, Vec3{1, 1, 1});
    m.baseAlpha = pbr.baseColorFactor.size() >= 4 ? float(pbr.baseColorFactor[3]) : 1.0f;
    if (g.alphaMode == "MASK") {
      m.alphaMode = AlphaMode::Mask;
    } else if (g.alphaMode == "BLEND") {
      m.alphaMode = AlphaMode::Blend;
    } else if (!g.alphaMode.empty() && g.alphaMode != "OPAQUE") {
      fail(path_, "material " + std::to_string(i) + ": unknown alphaMode '" + g.alphaMode +
                      "' (expected OPAQUE, MASK or BLEND)");
    }
    m.alphaCutoff = float(g.alphaCutoff);
    if (!std::isfinite(m.baseAlpha) || !std::isfinite(m.alphaCutoff) || m.baseAlpha < 0 ||
        m.baseAlpha > 1 || m.alphaCutoff < 0) {
      fail(path_, "material " + std::to_string(i) +
                      ": base colour alpha must lie in [0, 1] and alphaCutoff be >= 0");
    }
    m.metallic = float(pbr.metallicFactor);
    m.roughness = float(pbr.roughnessFactor);
    float strength = float(
        numberExt(g.extensions, "KHR_materials_emissive_strength", "emissiveStrength", 1.0));
    m.emission = vec3From(g.emissiveFactor, Vec3{0, 0, 0}) * strength;
    m.transmission =
        float(numberExt(g.extensions, "KHR_materials_transmission", "transmissionFactor", 0.0));
    m.ior = float(numberExt(g.extensions, "KHR_materials_ior", "ior", 1.5));
    // KHR_materials_specular: the dielectric layer's weight; its colour
    // (specularColorFactor, a tint of F0) is not read (docs/scene.md).
    m.specular =
        float(numberExt(g.extensions, "KHR_materials_specular", "specularFactor", 1.0));
    if (!(m.specular >= 0 && m.specular <= 1)) {
      fail(path_, "material " + std::to_string(i) +
                      ": KHR_materials_specular specularFactor must lie in [0, 1]");
    }
    if (!(m.ior == 0 || m.ior >= 1) || !std::isfinite(m.ior)) {
      fail(path_, "material " + std::to_string(i) +
                      ": KHR_materials_ior ior must be 0 or at least 1");
    }
    m.thickness =
        float(numberExt(g.extensions, "KHR_materials_volume", "thicknessFactor", 0.0));
    if (!(m.thickness >= 0)) {
      fail(path_, "material " + std::to_string(i) +
                      ": KHR_materials_volume thicknessFactor must be finite and >= 0");
    }
    m.doubleSided = g.doubleSided;
    m.unlit = g.extensions.count("KHR_materials_unlit") > 0;
    if (!isFinite(m.baseColor) || !isFinite(m.emission) || !std::isfinite(m.metallic) ||
        !std::isfinite(m.roughness) || !std::isfinite(m.transmission) || !std::isfinite(m.ior)) {
      fail(path_, "material " + std::to_string(i) + " has a non-finite factor");
    }
    // Colour maps (sRGB): base colour, emissive.
    textureReference(i, "texture", pbr.baseColorTexture.index, pbr.baseColorTexture.texCoord,
                     pbr.baseColorTexture.extensions, true, m.baseColorTexture,
                     m.baseColorTexCoord, m.baseColorTransform);
    const bool specularGlossiness = readSpecularGlossiness(g.extensions, i, m);
    textureReference(i, "emissive texture", g.emissiveTexture.index, g.emissiveTexture.texCoord,
                     g.emissiveTexture.extensions, true, m.emissiveTexture, m.emissiveTexCoord,
                     m.emissiveTransform);
    // Data maps (no sRGB curve): normal, metallic-roughness, occlusion.
    textureReference(i, "normal texture", g.normalTexture.index, g.normalTexture.texCoord,
                     g.normalTexture.extensions, false, m.normalTexture, m.normalTexCoord,
                     m.normalTransform);
    m.normalScale = float(g.normalTexture.scale);
    if (!specularGlossiness) {  // else the metal-rough fallback's map, not read
      textureReference(i, "metallic-roughness texture", pbr.metallicRoughnessTexture.index,
                       pbr.metallicRoughnessTexture.texCoord,
                       pbr.metallicRoughnessTexture.extensions, false,
                       m.metallicRoughnessTexture, m.metallicRoughnessTexCoord,
                       m.metallicRoughnessTransform);
    }
    textureReference(i, "occlusion texture", g.occlusionTexture.index,
                     g.occlusionTexture.texCoord, g.occlusionTexture.extensions, false,
                     m.occlusionTexture, m.occlusionTexCoord, m.occlusionTransform);
    m.occlusionStrength = float(g.occlusionTexture.strength);
    if (!std::isfinite(m.normalScale) || !std::isfinite(m.occlusionStrength)) {
      fail(path_, "material " + std::to_string(i) + ": a texture scale or strength is not finite");
    }
    if (m.unlit) {
      // Unlit: the base colour is all there is (the extension's rule);
      // it casts and emits nothing (Material::unlit).
      m.emission = Vec3{0, 0, 0};
      m.emissiveTexture = -1;
      m.transmission = 0;
    }
    scene_.materials.push_back(std::move(m));
  }
}

bool SceneBuilder::readSpecularGlossiness(const tinygltf::ExtensionMap& extensions, size_t i,
                                          Material& m) {
  auto it = extensions.find("KHR_materials_pbrSpecularGlossiness");
  if (it == extensions.end() || !it->second.IsObject()) return false;
  const tinygltf::Value& e = it->second;
  const std::string what = "material " + std::to_string(i) + ": KHR_materials_pbrSpecularGlossiness ";
  float diffuse[4] = {1, 1, 1, 1};
  if (e.Has("diffuseFactor")) {
    const tinygltf::Value& f = e.Get("diffuseFactor");
    if (!f.IsArray() || f.ArrayLen() != 4) fail(path_, what + "diffuseFactor must hold 4 numbers");
    for (int k = 0; k < 4; ++k) {
      const tinygltf::Value& c = f.Get(k);
      diffuse[k] = c.IsNumber() ? float(c.GetNumberAsDouble()) : -1.0f;
      if (!(diffuse[k] >= 0 && diffuse[k] <= 1)) fail(path_, what + "diffuseFactor must lie in [0, 1]");
    }
  }
  const double glossiness = numberExt(extensions, "KHR_materials_pbrSpecularGlossiness",
                                      "glossinessFactor", 1.0);
  if (!(glossiness >= 0 && glossiness <= 1)) fail(path_, what + "glossinessFactor must lie in [0, 1]");
  m.baseColor = {diffuse[0], diffuse[1], diffuse[2]};
  m.baseAlpha = diffuse[3];
  m.metallic = 0;
  m.roughness = e.Has("specularGlossinessTexture") ? 0.5f : float(1.0 - glossiness);
  m.baseColorTexture = -1;
  if (e.Has("diffuseTexture") && e.Get("diffuseTexture").IsObject()) {
    const tinygltf::Value& t = e.Get("diffuseTexture");
    if (!t.Get("index").IsInt() || t.Get("index").GetNumberAsInt() < 0) {
      fail(path_, what + "diffuseTexture has no texture index");
    }
    const int texCoord =
        t.Has("texCoord") && t.Get("texCoord").IsInt() ? t.Get("texCoord").GetNumberAsInt() : 0;
    tinygltf::ExtensionMap textureExtensions;
    if (t.Has("extensions") && t.Get("extensions").IsObject()) {
      const tinygltf::Value& x = t.Get("extensions");
      for (const std::string& key : x.Keys()) textureExtensions[key] = x.Get(key);
    }
    textureReference(i, "KHR_materials_pbrSpecularGlossiness diffuseTexture",
                     t.Get("index").GetNumberAsInt(), texCoord, textureExtensions, true,
                     m.baseColorTexture, m.baseColorTexCoord, m.baseColorTransform);
  }
  if (!warnedSpecularGlossiness_) {
    warnedSpecularGlossiness_ = true;
    scene_.warnings.push_back(path_ + ": KHR_materials_pbrSpecularGlossiness read approximately, "
                                      "as dielectrics: diffuse as the base colour, 1 - glossiness "
                                      "as the roughness; specular colours not read");
  }
  return true;
}

void SceneBuilder::textureReference(size_t i, const std::string& what, int index, int texCoord,
                                    const tinygltf::ExtensionMap& extensions, bool srgb,
                                    int& texture, int& texCoordOut, TextureTransform& transform) {
  if (index < 0) return;
  if (size_t(index) >= model_.textures.size()) {
    fail(path_, "material " + std::to_string(i) + ": " + what + " index " +
                    std::to_string(index) + " out of range");
  }
  readTextureTransform(extensions, i, transform, texCoord);
  if (texCoord == 0 || texCoord == 1) {
    texture = textureFromImage(model_.textures[size_t(index)].source, index, srgb);
    texCoordOut = texCoord;
  } else {
    scene_.warnings.push_back(path_ + ": material " + std::to_string(i) + ": " + what +
                              " uses TEXCOORD_" + std::to_string(texCoord) +
                              ", and only TEXCOORD_0 and TEXCOORD_1 are read: left out");
  }
}

void SceneBuilder::readTextureTransform(const tinygltf::ExtensionMap& extensions, size_t i,
                                        TextureTransform& tt, int& texCoord) {
  auto transform = extensions.find("KHR_texture_transform");
  if (transform == extensions.end() || !transform->second.IsObject()) return;
  const tinygltf::Value& t = transform->second;
  auto pair = [&](const char* key, float* out) {
    if (!t.Has(key)) return;
    const tinygltf::Value& a = t.Get(key);
    if (!a.IsArray() || a.ArrayLen() != 2 || !a.Get(0).IsNumber() || !a.Get(1).IsNumber()) {
      fail(path_, "material " + std::to_string(i) + ": KHR_texture_transform " + key +
                      " is not two numbers");
    }
    out[0] = float(a.Get(0).GetNumberAsDouble());
    out[1] = float(a.Get(1).GetNumberAsDouble());
  };
  pair("offset", tt.offset);
  pair("scale", tt.scale);
  if (t.Has("rotation") && t.Get("rotation").IsNumber()) {
    tt.rotation = float(t.Get("rotation").GetNumberAsDouble());
  }
  if (t.Has("texCoord") && t.Get("texCoord").IsInt()) texCoord = t.Get("texCoord").GetNumberAsInt();
  if (!std::isfinite(tt.offset[0]) || !std::isfinite(tt.offset[1]) || !std::isfinite(tt.scale[0]) ||
      !std::isfinite(tt.scale[1]) || !std::isfinite(tt.rotation)) {
    fail(path_, "material " + std::to_string(i) + ": KHR_texture_transform is not finite");
  }
}

TextureSampler SceneBuilder::samplerOf(int tex) const {
  TextureSampler out;
  const int index = model_.textures[size_t(tex)].sampler;
  if (index < 0) return out;
  const std::string what = "texture " + std::to_string(tex) + ": sampler " + std::to_string(index);
  if (size_t(index) >= model_.samplers.size()) fail(path_, what + " out of range");
  const tinygltf::Sampler& s = model_.samplers[size_t(index)];
  auto oneOf = [&](int value, std::initializer_list<int> allowed, const char* field) {
    for (int a : allowed) {
      if (value == a) return;
    }
    fail(path_, what + ": " + field + " " + std::to_string(value) + " is not a glTF value");
  };
  if (s.magFilter >= 0) {
    oneOf(s.magFilter, {TextureSampler::kNearest, TextureSampler::kLinear}, "magFilter");
    out.magFilter = s.magFilter;
  }
  if (s.minFilter >= 0) {
    oneOf(s.minFilter, {9728, 9729, 9984, 9985, 9986, 9987}, "minFilter");
    out.minFilter = s.minFilter;
  }
  const std::initializer_list<int> wraps = {TextureSampler::kRepeat, TextureSampler::kClampToEdge,
                                            TextureSampler::kMirroredRepeat};
  oneOf(s.wrapS, wraps, "wrapS");
  oneOf(s.wrapT, wraps, "wrapT");
  out.wrapS = s.wrapS;
  out.wrapT = s.wrapT;
  return out;
}

int SceneBuilder::sharedImage(int image) {
  const tinygltf::Image& im = model_.images[size_t(image)];
  std::string source;
  if (!im.uri.empty() && im.uri.rfind("data:", 0) != 0) {
    source = "file:" + fs::path(percentDecode(im.uri)).lexically_normal().string();
  } else if (!im.uri.empty()) {
    source = im.uri;  // a data URI: its bytes
  } else if (im.bufferView >= 0) {
    source = "bufferView:" + std::to_string(im.bufferView);
  } else {
    return image;
  }
  return imageBySource_.emplace(source, image).first->second;
}

int SceneBuilder::textureFromImage(int source, int tex, bool srgb) {
  std::string what =
      "(texture " + std::to_string(tex) + ", image " + std::to_string(source) + ")";
  if (source < 0 || size_t(source) >= model_.images.size()) {
    fail(path_, "unreadable image: image index out of range " + what);
  }
  // 300 images naming one file were decoded 300 times (1.85 GB for a 4.5 KB
  // PNG): one texture per file (as --add shares a model's), per decoding
  // and sampler.
  source = sharedImage(source);
  if (!model_.images[size_t(source)].uri.empty()) {
    what = "'" + model_.images[size_t(source)].uri + "' " + what;
  }
  // Colour and data decodings of one image are two textures, and so are
  // two samplers of it.
  const TextureKey key{source, srgb, samplerOf(tex)};
  auto it = imageToTexture_.find(key);
  if (it != imageToTexture_.end()) return it->second;
  const tinygltf::Image& im = model_.images[size_t(source)];
  if (im.image.empty() && !im.uri.empty() && im.uri.rfind("data:", 0) != 0) {
    // A file the folder does not hold (an asset copied without all of its
    // textures): the materials show their factors; the user hears it once.
    // A folder (or a pipe) of that name is said to be one, not missing.
    const fs::path file = fs::path(path_).parent_path() / percentDecode(im.uri);
    const std::string problem = notRegularFile(file.string());
    if (!problem.empty()) {
      if (missingImages_.insert(source).second) {
        scene_.warnings.push_back(
            path_ + ": texture image " + what +
            (problem == "missing" ? " is missing" : " is " + problem + ", not an image file") +
            "; the materials using it show their factors alone");
      }
      return -1;
    }
  }
  if (im.image.empty()) fail(path_, "unreadable image: no data " + what);
  // The file's bytes, shared by every texture decoding this image.
  std::shared_ptr<const std::vector<uint8_t>>& bytes = imageBytes_[source];
  if (!bytes) bytes = std::make_shared<const std::vector<uint8_t>>(im.image);
  // Decoded once every texture is known (decodeTextures: their total memory first).
  Texture t;
  t.sampler = key.sampler;
  t.name =
      im.name.empty() ? (im.uri.empty() ? "image" + std::to_string(source) : im.uri) : im.name;
  int index = int(scene_.textures.size());
  scene_.textures.push_back(std::move(t));
  pendingTextures_.push_back({index, bytes, what, srgb});
  imageToTexture_[key] = index;
  return index;
}

int SceneBuilder::defaultMaterial() {
  if (defaultMaterial_ < 0) {
    defaultMaterial_ = int(scene_.materials.size());
    Material m;
    m.name = "default";
    scene_.materials.push_back(m);
  }
  return defaultMaterial_;
}

}  // namespace lo::scene_internal::gltf_internal
