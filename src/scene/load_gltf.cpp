/// @file scene/load_gltf.cpp
/// @brief glTF 2.0 (.gltf/.glb) loader on top of tinygltf.
///
/// tinygltf parses; this file distrusts everything it returns. Before tinygltf
/// sees the file, external uris are confined to the scene's folder and buffer
/// views are checked against their buffers (tinygltf 2.7 indexes a buffer with
/// an unchecked bufferView when it decodes embedded images). After parsing,
/// every accessor is checked to fit its bufferView and buffer, and every index
/// to be below the vertex count, before a byte is read.

#define TINYGLTF_IMPLEMENTATION
// Images are decoded by src/image (decodeImageBytes), the project's one copy
// of stb_image; tinygltf only hands over the encoded bytes (storeEncodedImage).
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#include <tiny_gltf.h>

#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <set>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/file.h"
#include "core/resources.h"
#include "image/image.h"
#include "scene/gltf_prevalidate.h"
#include "scene/gltf_transform.h"
#include "scene/scene_internal.h"

namespace lo::scene_internal {

namespace {

namespace fs = std::filesystem;

Mat4 nodeLocalTransform(const tinygltf::Node& node) {
  return localTransform(node.matrix, node.translation, node.rotation, node.scale);
}

// ---------------------------------------------------------------------------
// tinygltf callbacks.

/// Keeps the encoded bytes; images are decoded later, and only those a
/// material uses, so that the error names the problem precisely.
bool storeEncodedImage(tinygltf::Image* image, const int, std::string*, std::string*, int, int,
                       const unsigned char* bytes, int size, void*) {
  image->image.assign(bytes, bytes + size);
  image->width = image->height = image->component = image->bits = -1;
  image->as_is = true;
  return true;
}

struct FsContext {
  fs::path canonicalBase;
};

bool insideBase(const std::string& file, const FsContext& ctx) {
  std::error_code ec;
  fs::path canon = fs::weakly_canonical(file, ec);
  if (ec) return false;
  auto b = ctx.canonicalBase.begin(), f = canon.begin();
  for (; b != ctx.canonicalBase.end() && f != canon.end(); ++b, ++f) {
    if (b->empty()) continue;
    if (*b != *f) return false;
  }
  return b == ctx.canonicalBase.end();
}

// Defence in depth: the uris were checked before parsing; these refuse any
// other file too (tinygltf also looks for external files in the current
// directory, which must not happen).
bool fsFileExists(const std::string& file, void* user) {
  std::error_code ec;
  return insideBase(file, *static_cast<FsContext*>(user)) && fs::is_regular_file(file, ec);
}
std::string fsExpandFilePath(const std::string& file, void*) { return file; }
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& file,
                     void* user) {
  if (!fsFileExists(file, user)) {
    if (err) *err += "refused or missing file '" + file + "'";
    return false;
  }
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    if (err) *err += "cannot open '" + file + "'";
    return false;
  }
  out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}
bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&,
                      void*) {
  if (err) *err += "the scene loader never writes files";
  return false;
}

// ---------------------------------------------------------------------------
// Accessors.

class GltfReader {
 public:
  GltfReader(const std::string& path, const tinygltf::Model& model) : path_(path), model_(model) {}

  /// Reads accessor `index` as doubles, count * components values, with the
  /// normalization of integer types applied. `type` is the required
  /// TINYGLTF_TYPE_*; `what` names the use in error messages.
  std::vector<double> read(int index, int type, const std::string& what) const {
    if (index < 0 || size_t(index) >= model_.accessors.size()) {
      fail(path_, what + ": accessor index " + std::to_string(index) + " out of range (" +
                      std::to_string(model_.accessors.size()) + " accessors)");
    }
    const tinygltf::Accessor& acc = model_.accessors[size_t(index)];
    std::string name = what + " (accessor " + std::to_string(index) + ")";
    if (acc.type != type) fail(path_, name + " has the wrong type " + std::to_string(acc.type));
    int comps = tinygltf::GetNumComponentsInType(uint32_t(type));
    int csize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
    if (comps <= 0 || csize <= 0) {
      fail(path_, name + " has an invalid component type " + std::to_string(acc.componentType));
    }
    if (acc.count > (size_t(1) << 28)) {
      fail(path_, name + " count " + std::to_string(acc.count) + " is out of range");
    }
    // Sizes are checked against the bytes that back them before anything is
    // allocated: a small file must not cost gigabytes (docs/robustness.md).
    size_t elemSize = size_t(comps) * size_t(csize);
    const unsigned char* data = nullptr;
    size_t stride = elemSize;
    if (acc.bufferView >= 0) {
      data = viewData(acc.bufferView, name);
      const tinygltf::BufferView& bv = model_.bufferViews[size_t(acc.bufferView)];
      stride = bv.byteStride ? bv.byteStride : elemSize;
      if (stride < elemSize) {
        fail(path_, name + ": byteStride " + std::to_string(stride) +
                        " is smaller than the element size " + std::to_string(elemSize));
      }
      if (acc.count > 0) {
        uint64_t end = uint64_t(acc.byteOffset) + uint64_t(stride) * (acc.count - 1) + elemSize;
        if (end > bv.byteLength) {
          fail(path_, name + " is out of range of its bufferView " +
                          std::to_string(acc.bufferView) + " (needs " + std::to_string(end) +
                          " bytes, view has " + std::to_string(bv.byteLength) + ")");
        }
      }
    } else if (acc.sparse.isSparse) {
      // No bufferView: zeros but for the sparse values. Such an accessor may
      // hold at most kMaxImplicitElementsPerSparse elements per sparse value.
      const size_t limit =
          std::max<size_t>(kMinImplicitElements,
                           kMaxImplicitElementsPerSparse * size_t(std::max(0, acc.sparse.count)));
      if (acc.count > limit) {
        fail(path_, name + " has no bufferView: " + std::to_string(acc.count) +
                        " implicit zero elements for " + std::to_string(acc.sparse.count) +
                        " sparse values, more than the " + std::to_string(limit) + " allowed");
      }
    } else {
      // Refused before allocating: found by fuzz_gltf (2^28 elements, 6.4 GB).
      fail(path_, name + " has neither a bufferView nor sparse values");
    }
    std::vector<double> out(acc.count * size_t(comps), 0.0);
    if (data) {
      for (size_t e = 0; e < acc.count; ++e)
        for (int c = 0; c < comps; ++c)
          out[e * size_t(comps) + size_t(c)] =
              component(data + acc.byteOffset + e * stride + size_t(c) * size_t(csize),
                        acc.componentType, acc.normalized);
    }
    if (acc.sparse.isSparse) readSparse(acc, comps, csize, name, out);
    return out;
  }

  /// Reads an index accessor (SCALAR of unsigned byte/short/int).
  std::vector<uint32_t> readIndices(int index, const std::string& what) const {
    if (index >= 0 && size_t(index) < model_.accessors.size()) {
      int ct = model_.accessors[size_t(index)].componentType;
      if (ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
          ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
          ct != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT) {
        fail(path_, what + " (accessor " + std::to_string(index) +
                        ") must hold unsigned integers, has component type " + std::to_string(ct));
      }
    }
    std::vector<double> v = read(index, TINYGLTF_TYPE_SCALAR, what);
    std::vector<uint32_t> out(v.size());
    for (size_t i = 0; i < v.size(); ++i) out[i] = uint32_t(v[i]);
    return out;
  }

  size_t count(int index) const {
    return index >= 0 && size_t(index) < model_.accessors.size()
               ? model_.accessors[size_t(index)].count
               : 0;
  }

 private:
  const unsigned char* viewData(int view, const std::string& name) const {
    if (view < 0 || size_t(view) >= model_.bufferViews.size()) {
      fail(path_, name + ": bufferView index " + std::to_string(view) + " out of range");
    }
    const tinygltf::BufferView& bv = model_.bufferViews[size_t(view)];
    if (bv.buffer < 0 || size_t(bv.buffer) >= model_.buffers.size()) {
      fail(path_, name + ": buffer index " + std::to_string(bv.buffer) + " out of range");
    }
    const tinygltf::Buffer& buf = model_.buffers[size_t(bv.buffer)];
    if (bv.byteOffset > buf.data.size() || bv.byteLength > buf.data.size() - bv.byteOffset) {
      fail(path_, name + ": bufferView " + std::to_string(view) + " is out of range of buffer " +
                      std::to_string(bv.buffer) + " (missing buffer data?)");
    }
    return buf.data.data() + bv.byteOffset;
  }

  void readSparse(const tinygltf::Accessor& acc, int comps, int csize, const std::string& name,
                  std::vector<double>& out) const {
    if (acc.sparse.count < 0 || size_t(acc.sparse.count) > acc.count) {
      fail(path_, name + ": sparse count out of range");
    }
    size_t n = size_t(acc.sparse.count);
    int ict = acc.sparse.indices.componentType;
    int isize = tinygltf::GetComponentSizeInBytes(uint32_t(ict));
    if (isize <= 0 || ict == TINYGLTF_COMPONENT_TYPE_FLOAT) {
      fail(path_, name + ": invalid sparse index component type");
    }
    auto fits = [&](int view, int offset, size_t bytes) {
      if (offset < 0) fail(path_, name + ": negative sparse byteOffset");
      const unsigned char* d = viewData(view, name + " sparse");
      if (uint64_t(offset) + bytes > model_.bufferViews[size_t(view)].byteLength) {
        fail(path_, name + ": sparse data out of range of bufferView " + std::to_string(view));
      }
      return d + offset;
    };
    const unsigned char* idx =
        fits(acc.sparse.indices.bufferView, acc.sparse.indices.byteOffset, n * size_t(isize));
    size_t elemSize = size_t(comps) * size_t(csize);
    const unsigned char* val =
        fits(acc.sparse.values.bufferView, acc.sparse.values.byteOffset, n * elemSize);
    for (size_t s = 0; s < n; ++s) {
      double target = component(idx + s * size_t(isize), ict, false);
      if (target < 0 || target >= double(acc.count)) {
        fail(path_, name + ": sparse index " + std::to_string(uint64_t(target)) +
                        " out of range (count " + std::to_string(acc.count) + ")");
      }
      for (int c = 0; c < comps; ++c)
        out[size_t(target) * size_t(comps) + size_t(c)] = component(
            val + s * elemSize + size_t(c) * size_t(csize), acc.componentType, acc.normalized);
    }
  }

  template <typename T>
  static T load(const unsigned char* p) {
    T v;
    std::memcpy(&v, p, sizeof(T));
    return v;
  }

  /// glTF 2.0 spec, "Animations / normalized integers": c / (2^(n-1) - 1)
  /// clamped at -1 for signed, c / (2^n - 1) for unsigned.
  static double component(const unsigned char* p, int type, bool normalized) {
    switch (type) {
      case TINYGLTF_COMPONENT_TYPE_BYTE: {
        double v = load<int8_t>(p);
        return normalized ? std::max(v / 127.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
        double v = load<uint8_t>(p);
        return normalized ? v / 255.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_SHORT: {
        double v = load<int16_t>(p);
        return normalized ? std::max(v / 32767.0, -1.0) : v;
      }
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
        double v = load<uint16_t>(p);
        return normalized ? v / 65535.0 : v;
      }
      case TINYGLTF_COMPONENT_TYPE_INT:
        return double(load<int32_t>(p));
      case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
        return double(load<uint32_t>(p));
      case TINYGLTF_COMPONENT_TYPE_FLOAT:
        return double(load<float>(p));
      case TINYGLTF_COMPONENT_TYPE_DOUBLE:
        return load<double>(p);
      default:
        return 0.0;
    }
  }

  const std::string& path_;
  const tinygltf::Model& model_;
};

// ---------------------------------------------------------------------------
// Scene assembly.

double numberExt(const tinygltf::ExtensionMap& ext, const char* name, const char* key,
                 double fallback) {
  auto it = ext.find(name);
  if (it == ext.end() || !it->second.IsObject() || !it->second.Has(key)) return fallback;
  const tinygltf::Value& v = it->second.Get(key);
  return v.IsNumber() ? v.GetNumberAsDouble() : fallback;
}

Vec3 vec3From(const std::vector<double>& v, const Vec3& fallback) {
  if (v.size() < 3) return fallback;
  return {float(v[0]), float(v[1]), float(v[2])};
}

class SceneBuilder {
 public:
  SceneBuilder(const std::string& path, const tinygltf::Model& model, const std::string& skyMesh)
      : path_(path), model_(model), reader_(path, model), skyMeshFlag_(skyMesh) {}

  Scene build() {
    for (const std::string& name : model_.extensionsUsed) {
      if (!readsGltfExtension(name)) {
        scene_.warnings.push_back(path_ + ": uses the glTF extension " + name +
                                  ", which is not read: the scene is loaded without it");
      }
    }
    convertMaterials();
    traverse();
    readSky();
    if (!skyMeshFlag_.empty()) {  // the command line's sky mesh replaces the file's sky
      skyMesh_ = skyMeshFlag_;
      turbidity_ = 0;
      scene_.sky = Sky();
      skyScale_ = false;
    }
    finishVertexAttributes();
    rebase();
    if (!skyMesh_.empty() || turbidity_ > 0) {
      // extras.lightoctree_sky, when given, scales the sky's image.
      const Vec3 scale = skyScale_ ? scene_.sky.radiance : Vec3{1, 1, 1};
      scene_.sourcePath = path_;  // for their messages
      if (!skyMesh_.empty()) {
        skyFromMaterial(scene_, skyMesh_);
      } else {
        physicalSky(scene_, turbidity_);
      }
      scene_.sky.radiance = scale;
    }
    return std::move(scene_);
  }

 private:
  struct Pending {
    std::vector<Vec3> positions, normals;
    std::vector<float> uv0, uv1;
    bool hasNormals = false, hasUv0 = false, hasUv1 = false;
  };

  void convertMaterials() {
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

  /// KHR_materials_pbrSpecularGlossiness (archived, written by older
  /// exporters) read approximately, as a dielectric: the diffuse factor and
  /// texture as the base colour, 1 - glossiness as the roughness (0.5 where
  /// a specular-glossiness texture holds the glossiness, which is not read),
  /// metallic 0; the specular colour is not read. Warned once per file.
  bool readSpecularGlossiness(const tinygltf::ExtensionMap& extensions, size_t i, Material& m) {
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

  /// A texture reference `what` of material i: its index checked, its
  /// KHR_texture_transform into `transform`, and its texture (sRGB colour
  /// or linear data) into `texture` and `texCoordOut` where it names UV set
  /// 0 or 1 (other sets are not loaded: the factor alone is used). Nothing
  /// for a negative index.
  void textureReference(size_t i, const std::string& what, int index, int texCoord,
                        const tinygltf::ExtensionMap& extensions, bool srgb, int& texture,
                        int& texCoordOut, TextureTransform& transform) {
    if (index < 0) return;
    if (size_t(index) >= model_.textures.size()) {
      fail(path_, "material " + std::to_string(i) + ": " + what + " index " +
                      std::to_string(index) + " out of range");
    }
    readTextureTransform(extensions, i, transform, texCoord);
    if (texCoord == 0 || texCoord == 1) {
      texture = textureFromImage(model_.textures[size_t(index)].source, index, srgb);
      texCoordOut = texCoord;
    }
  }

  /// KHR_texture_transform of a texture reference into `out`; its texCoord
  /// overrides `texCoord`. @throws InputError naming the material.
  void readTextureTransform(const tinygltf::ExtensionMap& extensions, size_t i,
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

  /// The sampler of glTF texture `tex` (glTF's defaults where it has none).
  TextureSampler samplerOf(int tex) const {
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

  int textureFromImage(int source, int tex, bool srgb = true) {
    std::string what =
        "(texture " + std::to_string(tex) + ", image " + std::to_string(source) + ")";
    if (source < 0 || size_t(source) >= model_.images.size()) {
      fail(path_, "unreadable image: image index out of range " + what);
    }
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
      std::error_code ec;
      const fs::path file = fs::path(path_).parent_path() / percentDecode(im.uri);
      if (!fs::is_regular_file(file, ec)) {
        if (missingImages_.insert(source).second) {
          scene_.warnings.push_back(path_ + ": texture image '" + im.uri + "' " + what +
                                    " is missing; the materials using it show their factors "
                                    "alone");
        }
        return -1;
      }
    }
    if (im.image.empty()) fail(path_, "unreadable image: no data " + what);
    // The file's bytes, shared by every texture decoding this image.
    std::shared_ptr<const std::vector<uint8_t>>& bytes = imageBytes_[source];
    if (!bytes) bytes = std::make_shared<const std::vector<uint8_t>>(im.image);
    Texture t = decodeImage(path_, bytes, what, srgb);
    t.sampler = key.sampler;
    t.name =
        im.name.empty() ? (im.uri.empty() ? "image" + std::to_string(source) : im.uri) : im.name;
    int index = int(scene_.textures.size());
    scene_.textures.push_back(std::move(t));
    imageToTexture_[key] = index;
    return index;
  }

  int defaultMaterial() {
    if (defaultMaterial_ < 0) {
      defaultMaterial_ = int(scene_.materials.size());
      Material m;
      m.name = "default";
      scene_.materials.push_back(m);
    }
    return defaultMaterial_;
  }

  /// The sky: the glTF scene's `"extras": {"lightoctree_sky": [r, g, b]}`,
  /// radiance in W/(m^2 sr), and `"lightoctree_sky_image": "sky.hdr"`, an
  /// equirectangular map beside the file that the colour then scales (no
  /// glTF extension describes a sky's radiance; docs/scene.md, "Sky").
  void readSky() {
    const auto& scenes = model_.scenes;
    const int s = model_.defaultScene >= 0 ? model_.defaultScene : scenes.empty() ? -1 : 0;
    if (s < 0 || size_t(s) >= scenes.size()) return;
    const tinygltf::Value& extras = scenes[size_t(s)].extras;
    if (!extras.IsObject()) return;
    if (extras.Has("lightoctree_sky_mesh")) {
      // The material of a sky box to take as the sky (skyFromMaterial).
      const tinygltf::Value& name = extras.Get("lightoctree_sky_mesh");
      const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_sky_mesh";
      if (!name.IsString() || name.Get<std::string>().empty()) {
        fail(path_, what + " must be the name of the sky box's material");
      }
      if (extras.Has("lightoctree_sky_image")) {
        fail(path_, what + " and extras.lightoctree_sky_image: give one sky");
      }
      skyMesh_ = name.Get<std::string>();
    }
    if (extras.Has("lightoctree_physical_sky")) {
      // The daylight sky of the scene's sun, at this turbidity (physicalSky).
      const tinygltf::Value& t = extras.Get("lightoctree_physical_sky");
      const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_physical_sky";
      if (!t.IsNumber() || !(t.GetNumberAsDouble() > 0)) {
        fail(path_, what + " must be the atmosphere's turbidity (a number, 2 to 10)");
      }
      if (extras.Has("lightoctree_sky_image") || extras.Has("lightoctree_sky_mesh")) {
        fail(path_, what + " and another sky (lightoctree_sky_image or _mesh): give one sky");
      }
      turbidity_ = float(t.GetNumberAsDouble());
    }
    skyScale_ = extras.Has("lightoctree_sky");
    if (extras.Has("lightoctree_sky_image")) {
      // An equirectangular radiance map beside the file (.exr or .hdr).
      const tinygltf::Value& uri = extras.Get("lightoctree_sky_image");
      const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_sky_image";
      if (!uri.IsString()) fail(path_, what + " must be a file name (.exr or .hdr)");
      std::string base = std::filesystem::path(path_).parent_path().string();
      if (base.empty()) base = ".";
      const std::string file = resolveInsideFolder(path_, base, uri.Get<std::string>(), what);
      try {
        scene_.sky.image = loadSkyImage(file);
      } catch (const InputError& e) {
        fail(path_, what + ": " + e.what());
      }
      scene_.sky.radiance = Vec3{1, 1, 1};  // unless lightoctree_sky scales it
    }
    if (!extras.Has("lightoctree_sky")) return;
    const tinygltf::Value& v = extras.Get("lightoctree_sky");
    const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_sky";
    if (!v.IsArray() || v.ArrayLen() != 3) {
      fail(path_, what + " must be an array of 3 numbers (radiance, W/(m^2 sr))");
    }
    for (int c = 0; c < 3; ++c) {
      const tinygltf::Value& x = v.Get(c);
      if (!x.IsNumber()) fail(path_, what + " must be an array of 3 numbers (radiance, W/(m^2 sr))");
      const double value = x.GetNumberAsDouble();
      if (!std::isfinite(value) || value < 0 || value > 1e9) {
        fail(path_, what + "[" + std::to_string(c) + "] = " + std::to_string(value) +
                        " is not a radiance (finite, 0 to 1e9)");
      }
      scene_.sky.radiance[c] = float(value);
    }
  }

  std::vector<int> sceneRoots() const {
    const auto& scenes = model_.scenes;
    int s = model_.defaultScene;
    if (s >= int(scenes.size())) fail(path_, "default scene index out of range");
    if (s < 0 && !scenes.empty()) s = 0;
    if (s >= 0) return scenes[size_t(s)].nodes;
    // No scenes: every node that is nobody's child is a root.
    std::vector<char> isChild(model_.nodes.size(), 0);
    for (const auto& n : model_.nodes)
      for (int c : n.children)
        if (c >= 0 && size_t(c) < isChild.size()) isChild[size_t(c)] = 1;
    std::vector<int> roots;
    for (size_t i = 0; i < model_.nodes.size(); ++i)
      if (!isChild[i]) roots.push_back(int(i));
    return roots;
  }

  /// The triangles the node tree will make, from the accessors' counts, and
  /// the memory they will take, before any is built: ten thousand nodes
  /// instancing a 200k-triangle mesh are 2e9 triangles, built only to be
  /// refused (32-bit indices) after minutes and gigabytes.
  void checkTriangleBudget() {
    std::vector<uint64_t> perMesh(model_.meshes.size(), 0);
    for (size_t m = 0; m < model_.meshes.size(); ++m) {
      for (const tinygltf::Primitive& prim : model_.meshes[m].primitives) {
        int accessor = prim.indices;
        if (accessor < 0) {
          auto pos = prim.attributes.find("POSITION");
          accessor = pos == prim.attributes.end() ? -1 : pos->second;
        }
        if (accessor < 0 || size_t(accessor) >= model_.accessors.size()) continue;
        const uint64_t count = uint64_t(model_.accessors[size_t(accessor)].count);
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        perMesh[m] += mode == TINYGLTF_MODE_TRIANGLES ? count / 3 : (count >= 2 ? count - 2 : 0);
      }
    }
    uint64_t triangles = 0;
    std::vector<int> stack = sceneRoots();
    size_t visits = 0;
    while (!stack.empty()) {
      const int n = stack.back();
      stack.pop_back();
      // Out-of-range nodes and cycles are traverse()'s to name.
      if (n < 0 || size_t(n) >= model_.nodes.size() || ++visits > model_.nodes.size()) return;
      const tinygltf::Node& node = model_.nodes[size_t(n)];
      if (node.mesh >= 0 && size_t(node.mesh) < perMesh.size()) triangles += perMesh[size_t(node.mesh)];
      for (int c : node.children) stack.push_back(c);
    }
    // Per triangle, at most three vertices of their own (position, normal,
    // two UV sets, tangent: 56 bytes; the double position kept for the
    // rebase: 24), its indices and material (16).
    const double bytes = double(triangles) * (3.0 * (56 + 24) + 16);
    const size_t available = availableMemoryBytes();
    if (triangles > (uint64_t(1) << 32) / 3 || (available > 0 && bytes > 0.5 * double(available))) {
      fail(path_, "the node tree makes " + std::to_string(triangles) + " triangles (" +
                      formatBytes(size_t(std::min(bytes, 1e18))) + " to hold), beyond " +
                      (available > 0 ? "half the " + formatBytes(available) + " of memory available"
                                     : std::string("32-bit indices")));
    }
  }

  void traverse() {
    checkTriangleBudget();
    struct Item {
      int node;
      Mat4 parent;
      size_t depth;
    };
    std::vector<Item> stack;
    std::vector<int> roots = sceneRoots();
    for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.push_back({*r, Mat4{}, 0});
    size_t visits = 0;
    while (!stack.empty()) {
      Item item = stack.back();
      stack.pop_back();
      if (item.node < 0 || size_t(item.node) >= model_.nodes.size()) {
        fail(path_, "node index " + std::to_string(item.node) + " out of range");
      }
      // A valid glTF node tree visits each node once; a cycle or a shared
      // child would never end or multiply the geometry.
      if (item.depth > model_.nodes.size() || ++visits > model_.nodes.size()) {
        fail(path_, "the node hierarchy is not a tree (cycle or shared node " +
                        std::to_string(item.node) + ")");
      }
      const tinygltf::Node& node = model_.nodes[size_t(item.node)];
      Mat4 world = item.parent * nodeLocalTransform(node);
      for (double v : world.m)
        if (!std::isfinite(v))
          fail(path_, "node " + std::to_string(item.node) + " has a non-finite transform");
      if (isRegionMarker(node, item.node)) {
        addRegion(node, item.node, world);
      } else if (node.mesh >= 0) {
        addMesh(node.mesh, world);
      }
      if (node.camera >= 0) addCamera(node, item.node, world);
      auto ext = node.extensions.find("KHR_lights_punctual");
      if (ext != node.extensions.end() && ext->second.IsObject() && ext->second.Has("light")) {
        const tinygltf::Value& l = ext->second.Get("light");
        if (!l.IsInt())
          fail(path_, "node " + std::to_string(item.node) + ": light is not an index");
        addLight(node, item.node, l.Get<int>(), world);
      }
      for (auto c = node.children.rbegin(); c != node.children.rend(); ++c)
        stack.push_back({*c, world, item.depth + 1});
    }
  }

  /// A region-of-interest marker: `"extras": {"lightoctree_region": true}`.
  bool isRegionMarker(const tinygltf::Node& node, int nodeIndex) const {
    if (!node.extras.IsObject() || !node.extras.Has("lightoctree_region")) return false;
    const tinygltf::Value& v = node.extras.Get("lightoctree_region");
    if (!v.IsBool()) {
      fail(path_, "node " + std::to_string(nodeIndex) +
                      ": extras.lightoctree_region must be true or false");
    }
    return v.Get<bool>();
  }

  /// The marker's mesh, loaded like any other for its world-space bounds, then
  /// taken out of the scene again: it marks the region, it is not geometry.
  void addRegion(const tinygltf::Node& node, int nodeIndex, const Mat4& world) {
    if (node.mesh < 0) {
      fail(path_, "node " + std::to_string(nodeIndex) +
                      " marks the region of interest (extras.lightoctree_region) but has no "
                      "mesh: give it a box mesh spanning the region");
    }
    Scene& sc = scene_;
    const size_t positions = sc.positions.size(), normals = sc.normals.size(),
                 uv0 = sc.texcoords0.size(), uv1 = sc.texcoords1.size(),
                 tangents = sc.tangents.size(), colors = sc.colors.size(),
                 indices = sc.indices.size(),
                 materials = sc.triangleMaterial.size();
    const bool hadNormals = hasNormals_, hadUv0 = hasUv0_, hadUv1 = hasUv1_,
               hadTangents = hasTangents_, hadColors = hasColors_;
    addMesh(node.mesh, world);
    for (size_t i = positions; i < sc.positions.size(); ++i) sc.region.extend(sc.positions[i]);
    world_.region.insert(world_.region.end(), world_.vertices.begin() + ptrdiff_t(positions),
                         world_.vertices.end());
    world_.vertices.resize(positions);
    sc.positions.resize(positions);
    sc.normals.resize(normals);
    sc.texcoords0.resize(uv0);
    sc.texcoords1.resize(uv1);
    sc.tangents.resize(tangents);
    sc.colors.resize(colors);
    hasNormals_ = hadNormals;
    hasUv0_ = hadUv0;
    hasUv1_ = hadUv1;
    hasTangents_ = hadTangents;
    hasColors_ = hadColors;
    sc.indices.resize(indices);
    sc.triangleMaterial.resize(materials);
  }

  void addCamera(const tinygltf::Node& node, int nodeIndex, const Mat4& world) {
    if (size_t(node.camera) >= model_.cameras.size()) {
      fail(path_, "node " + std::to_string(nodeIndex) + ": camera index out of range");
    }
    const tinygltf::Camera& g = model_.cameras[size_t(node.camera)];
    if (g.type != "perspective") return;  // orthographic cameras are skipped (docs/scene.md)
    Camera c;
    c.name = !node.name.empty() ? node.name
                                : (!g.name.empty() ? g.name : "camera" + std::to_string(nodeIndex));
    c.position = world.point({0, 0, 0});
    world_.cameras.push_back(world.pointInDouble({0, 0, 0}));
    c.forward = normalize(world.vector({0, 0, -1}));
    Vec3 up = world.vector({0, 1, 0});
    const Vec3 across = up - c.forward * dot(up, c.forward);
    if (!(lengthSquared(across) > 1e-12f * lengthSquared(up))) {
      fail(path_, "camera on node " + std::to_string(nodeIndex) +
                      " has a degenerate transform: its up is parallel to its view");
    }
    c.up = normalize(across);
    c.yfov = float(g.perspective.yfov);
    c.aspectRatio = float(g.perspective.aspectRatio);
    c.znear = float(g.perspective.znear);
    c.zfar = float(g.perspective.zfar);
    if (!(c.znear >= 0) || !std::isfinite(c.zfar) || (c.zfar > 0 && !(c.zfar > c.znear))) {
      fail(path_, "camera on node " + std::to_string(nodeIndex) + ": znear " +
                      std::to_string(c.znear) + " and zfar " + std::to_string(c.zfar) +
                      " (glTF: zfar > znear > 0, or no zfar)");
    }
    if (!(c.yfov > 0 && c.yfov < kPi) || lengthSquared(c.forward) == 0) {
      fail(path_,
           "camera on node " + std::to_string(nodeIndex) + " has an invalid yfov or transform");
    }
    scene_.cameras.push_back(c);
  }

  void addLight(const tinygltf::Node& node, int nodeIndex, int lightIndex, const Mat4& world) {
    if (lightIndex < 0 || size_t(lightIndex) >= model_.lights.size()) {
      fail(path_, "node " + std::to_string(nodeIndex) + ": light index " +
                      std::to_string(lightIndex) + " out of range");
    }
    const tinygltf::Light& g = model_.lights[size_t(lightIndex)];
    Light l;
    if (g.type == "point")
      l.type = Light::Type::Point;
    else if (g.type == "spot")
      l.type = Light::Type::Spot;
    else if (g.type == "directional")
      l.type = Light::Type::Directional;
    else
      fail(path_, "light " + std::to_string(lightIndex) + " has unknown type '" + g.type + "'");
    l.name = !node.name.empty() ? node.name
                                : (!g.name.empty() ? g.name : "light" + std::to_string(lightIndex));
    l.position = world.point({0, 0, 0});
    l.direction = normalize(world.vector({0, 0, -1}));
    l.color = vec3From(g.color, Vec3{1, 1, 1});
    l.intensity = float(g.intensity);
    l.range = float(g.range);
    l.innerConeAngle = float(g.spot.innerConeAngle);
    l.outerConeAngle = float(g.spot.outerConeAngle);
    if (!isFinite(l.color) || !std::isfinite(l.intensity) || !std::isfinite(l.range) ||
        !isFinite(l.position) || lengthSquared(l.direction) == 0) {
      fail(path_, "light " + std::to_string(lightIndex) + " has a non-finite value or transform");
    }
    scene_.lights.push_back(l);
    world_.lights.push_back(world.pointInDouble({0, 0, 0}));
  }

  void addMesh(int meshIndex, const Mat4& world) {
    if (size_t(meshIndex) >= model_.meshes.size()) {
      fail(path_, "mesh index " + std::to_string(meshIndex) + " out of range");
    }
    const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
    Mat4 normalMatrix = world.normalMatrix();
    bool flip = world.det3() < 0;
    for (size_t p = 0; p < mesh.primitives.size(); ++p) {
      const tinygltf::Primitive& prim = mesh.primitives[p];
      std::string what = "mesh " + std::to_string(meshIndex) + " primitive " + std::to_string(p);
      int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
      if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
          mode != TINYGLTF_MODE_TRIANGLE_FAN) {
        static const char* names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
        std::string name = mode >= 0 && mode < 4 ? names[mode] : std::to_string(mode);
        fail(path_, what + ": unsupported primitive mode " + name + " (only triangles are loaded)");
      }
      auto attr = [&](const char* key) {
        auto it = prim.attributes.find(key);
        return it == prim.attributes.end() ? -1 : it->second;
      };
      int posAcc = attr("POSITION");
      if (posAcc < 0) fail(path_, what + " has no POSITION attribute");
      std::vector<double> pos = reader_.read(posAcc, TINYGLTF_TYPE_VEC3, what + " POSITION");
      size_t nverts = pos.size() / 3;
      auto readSameCount = [&](int acc, int type, const char* key) {
        std::vector<double> v = reader_.read(acc, type, what + " " + key);
        if (reader_.count(acc) != nverts) {
          fail(path_, what + ": " + key + " has " + std::to_string(reader_.count(acc)) +
                          " elements, POSITION has " + std::to_string(nverts));
        }
        return v;
      };
      std::vector<double> nrm, uv0, uv1, tan, color;
      if (attr("NORMAL") >= 0) nrm = readSameCount(attr("NORMAL"), TINYGLTF_TYPE_VEC3, "NORMAL");
      if (attr("TANGENT") >= 0) tan = readSameCount(attr("TANGENT"), TINYGLTF_TYPE_VEC4, "TANGENT");
      if (attr("TEXCOORD_0") >= 0)
        uv0 = readSameCount(attr("TEXCOORD_0"), TINYGLTF_TYPE_VEC2, "TEXCOORD_0");
      if (attr("TEXCOORD_1") >= 0)
        uv1 = readSameCount(attr("TEXCOORD_1"), TINYGLTF_TYPE_VEC2, "TEXCOORD_1");
      if (attr("COLOR_0") >= 0) {
        // VEC3 or VEC4; floats, or normalized unsigned bytes or shorts (the
        // reader scales those to [0, 1]).
        const size_t acc = size_t(attr("COLOR_0"));
        if (acc < model_.accessors.size() &&
            model_.accessors[acc].componentType != TINYGLTF_COMPONENT_TYPE_FLOAT &&
            !model_.accessors[acc].normalized) {
          fail(path_, what + ": COLOR_0 of integers must be normalized (glTF 2.0, meshes)");
        }
        const int type = acc < model_.accessors.size() &&
                                 model_.accessors[acc].type == TINYGLTF_TYPE_VEC3
                             ? TINYGLTF_TYPE_VEC3
                             : TINYGLTF_TYPE_VEC4;
        color = readSameCount(attr("COLOR_0"), type, "COLOR_0");
      }

      std::vector<uint32_t> idx;
      if (prim.indices >= 0) {
        idx = reader_.readIndices(prim.indices, what + " indices");
        for (uint32_t i : idx)
          if (i >= nverts) {
            fail(path_, what + ": vertex index " + std::to_string(i) + " out of range (" +
                            std::to_string(nverts) + " vertices)");
          }
      } else {
        idx.resize(nverts);
        for (size_t i = 0; i < nverts; ++i) idx[i] = uint32_t(i);
      }
      std::vector<std::array<uint32_t, 3>> tris = triangulate(idx, mode);

      int material = prim.material;
      if (material < 0)
        material = defaultMaterial();
      else if (size_t(material) >= model_.materials.size())
        fail(path_, what + ": material index " + std::to_string(material) + " out of range");

      uint32_t base = uint32_t(scene_.positions.size());
      if (uint64_t(base) + nverts > std::numeric_limits<uint32_t>::max()) {
        fail(path_, "too many vertices for 32-bit indices");
      }
      for (size_t v = 0; v < nverts; ++v) {
        const Vec3d pd =
            world.pointInDouble({float(pos[3 * v]), float(pos[3 * v + 1]), float(pos[3 * v + 2])});
        const Vec3 pw = pd.toVec3();
        if (!isFinite(pw)) {
          fail(path_, what + ": non-finite vertex position (vertex " + std::to_string(v) + ")");
        }
        scene_.positions.push_back(pw);
        world_.vertices.push_back(pd);
      }
      // Normals / UV sets present on some primitives only: fill the others.
      appendNormals(nrm, normalMatrix, nverts, base, tris, flip);
      appendUv(scene_.texcoords0, hasUv0_, uv0, nverts, base);
      appendUv(scene_.texcoords1, hasUv1_, uv1, nverts, base);
      appendTangents(tan, world, nverts, base, flip);
      appendColors(color, nverts, base, what);

      for (auto& t : tris) {
        if (flip) std::swap(t[1], t[2]);
        for (uint32_t i : t) scene_.indices.push_back(base + i);
        scene_.triangleMaterial.push_back(material);
      }
    }
  }

  /// Triangle list from TRIANGLES / TRIANGLE_STRIP / TRIANGLE_FAN (glTF 2.0
  /// spec 3.7.2.1); triangles with a repeated index (strip restarts) dropped.
  static std::vector<std::array<uint32_t, 3>> triangulate(const std::vector<uint32_t>& idx,
                                                          int mode) {
    std::vector<std::array<uint32_t, 3>> tris;
    if (mode == TINYGLTF_MODE_TRIANGLES) {
      for (size_t i = 0; i + 2 < idx.size(); i += 3)
        tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
    } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
      for (size_t i = 0; i + 2 < idx.size(); ++i) {
        if (i % 2 == 0)
          tris.push_back({idx[i], idx[i + 1], idx[i + 2]});
        else
          tris.push_back({idx[i + 1], idx[i], idx[i + 2]});
      }
    } else {
      for (size_t i = 1; i + 1 < idx.size(); ++i) tris.push_back({idx[i], idx[i + 1], idx[0]});
    }
    std::vector<std::array<uint32_t, 3>> kept;
    kept.reserve(tris.size());
    for (const auto& t : tris)
      if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) kept.push_back(t);
    return kept;
  }

  void appendNormals(const std::vector<double>& nrm, const Mat4& normalMatrix, size_t nverts,
                     uint32_t base, const std::vector<std::array<uint32_t, 3>>& tris, bool flip) {
    if (nrm.empty() && !hasNormals_) {
      return;  // still no normals anywhere: Scene::normals stays empty
    }
    if (!hasNormals_) {
      // The first primitive with normals: earlier primitives get their
      // (area-weighted) vertex normals from their faces.
      hasNormals_ = true;
      scene_.normals.assign(base, Vec3{});
      for (size_t t = 0; t < scene_.triangleCount(); ++t) {
        Vec3 n = cross(
            scene_.positions[scene_.indices[3 * t + 1]] - scene_.positions[scene_.indices[3 * t]],
            scene_.positions[scene_.indices[3 * t + 2]] - scene_.positions[scene_.indices[3 * t]]);
        for (int k = 0; k < 3; ++k) scene_.normals[scene_.indices[3 * t + size_t(k)]] += n;
      }
      for (Vec3& n : scene_.normals) n = normalize(n);
    }
    if (!nrm.empty()) {
      for (size_t v = 0; v < nverts; ++v) {
        Vec3 n = normalize(
            normalMatrix.vector({float(nrm[3 * v]), float(nrm[3 * v + 1]), float(nrm[3 * v + 2])}));
        if (!isFinite(n)) fail(path_, "non-finite vertex normal");
        scene_.normals.push_back(n);
      }
    } else {
      std::vector<Vec3> acc(nverts, Vec3{});
      for (const auto& t : tris) {
        const Vec3& a = scene_.positions[base + t[0]];
        Vec3 n = cross(scene_.positions[base + t[1]] - a, scene_.positions[base + t[2]] - a);
        if (flip) n = -n;
        for (uint32_t i : t) acc[i] += n;
      }
      for (const Vec3& n : acc) scene_.normals.push_back(normalize(n));
    }
  }

  void appendUv(std::vector<float>& dst, bool& has, const std::vector<double>& uv, size_t nverts,
                uint32_t base) {
    if (uv.empty() && !has) return;
    if (!has) {
      has = true;
      dst.assign(2 * size_t(base), 0.0f);
    }
    if (uv.empty()) {
      dst.resize(dst.size() + 2 * nverts, 0.0f);
    } else {
      for (double x : uv) {
        if (!std::isfinite(x)) fail(path_, "non-finite texture coordinate");
        dst.push_back(float(x));
      }
    }
  }

  /// An attribute only some primitives carry, `width` floats a vertex, in
  /// `dst`: from the first primitive that has one (`present`), the vertices
  /// before it get `fill`, as do those of a later primitive without one.
  /// Returns whether this primitive's values are to be appended.
  bool optionalAttribute(std::vector<float>& dst, bool& seen, bool present, uint32_t base,
                         size_t nverts, size_t width, float fill) {
    if (!present && !seen) return false;
    if (!seen) {
      seen = true;
      dst.assign(width * size_t(base), fill);
    }
    if (!present) dst.resize(dst.size() + width * nverts, fill);
    return present;
  }

  /// TANGENT of a primitive into Scene::tangents (xyz by the node's linear
  /// part, normalised; w flipped with the winding under a mirroring
  /// transform); vertices of primitives without one get w = 0.
  void appendTangents(const std::vector<double>& tan, const Mat4& world, size_t nverts,
                      uint32_t base, bool flip) {
    if (!optionalAttribute(scene_.tangents, hasTangents_, !tan.empty(), base, nverts, 4, 0.0f)) {
      return;
    }
    for (size_t v = 0; v < nverts; ++v) {
      Vec3 t = world.vector({float(tan[4 * v]), float(tan[4 * v + 1]), float(tan[4 * v + 2])});
      const float w = float(tan[4 * v + 3]);
      if (!isFinite(t) || !std::isfinite(w)) fail(path_, "non-finite vertex tangent");
      const bool usable = lengthSquared(t) > 0 && w != 0;
      t = usable ? normalize(t) : Vec3{0, 0, 0};
      scene_.tangents.insert(scene_.tangents.end(),
                             {t.x, t.y, t.z, usable ? ((w < 0) != flip ? -1.0f : 1.0f) : 0.0f});
    }
  }

  /// COLOR_0 of a primitive (RGB, alpha 1, or RGBA) into Scene::colors,
  /// clamped to [0, 1] (glTF's range); vertices of primitives without one
  /// are white.
  void appendColors(const std::vector<double>& color, size_t nverts, uint32_t base,
                    const std::string& what) {
    if (!optionalAttribute(scene_.colors, hasColors_, !color.empty(), base, nverts, 4, 1.0f)) {
      return;
    }
    const size_t channels = color.size() / nverts;  // 3 or 4
    for (size_t v = 0; v < nverts; ++v) {
      for (size_t a = 0; a < 4; ++a) {
        const double c = a < channels ? color[channels * v + a] : 1.0;
        if (!std::isfinite(c)) fail(path_, what + ": non-finite vertex colour (COLOR_0)");
        scene_.colors.push_back(float(std::clamp(c, 0.0, 1.0)));
      }
    }
  }

  /// Positions were gathered in double (world_): a scene far from the
  /// origin is stored relative to its centre (Scene::origin), the rest as
  /// the file places it.
  void rebase() {
    // The sky mesh's vertices do not count: it is about to leave the scene,
    // and a sky box much larger than the site would hide how far out it lies.
    int sky = -1;
    for (size_t m = 0; m < scene_.materials.size() && !skyMesh_.empty(); ++m) {
      if (scene_.materials[m].name == skyMesh_) {
        sky = int(m);
        break;
      }
    }
    scene_internal::RebaseBounds bounds;
    for (size_t t = 0; t < scene_.triangleCount(); ++t) {
      if (scene_.triangleMaterial[t] == sky) continue;
      for (int k = 0; k < 3; ++k) bounds.extend(world_.vertices[scene_.indices[3 * t + size_t(k)]]);
    }
    const Vec3d origin = bounds.origin();
    if (origin.x == 0 && origin.y == 0 && origin.z == 0) return;
    scene_.origin = origin;
    for (size_t i = 0; i < scene_.positions.size(); ++i) {
      scene_.positions[i] = scene_.toLocal(world_.vertices[i]);
    }
    for (size_t i = 0; i < scene_.lights.size(); ++i) {
      scene_.lights[i].position = scene_.toLocal(world_.lights[i]);
    }
    for (size_t i = 0; i < scene_.cameras.size(); ++i) {
      scene_.cameras[i].position = scene_.toLocal(world_.cameras[i]);
    }
    scene_.region = Bounds3();
    for (const Vec3d& p : world_.region) scene_.region.extend(scene_.toLocal(p));
  }

  void finishVertexAttributes() {
    LO_CHECK(!hasNormals_ || scene_.normals.size() == scene_.positions.size());
  }

  const std::string& path_;
  const tinygltf::Model& model_;
  GltfReader reader_;
  Scene scene_;
  /// World positions in double, parallel to scene_'s vertices, lights and
  /// cameras, and the region marker's vertices: what rebase() starts from.
  struct {
    std::vector<Vec3d> vertices, lights, cameras, region;
  } world_;
  /// A decoded texture: its image, whether as sRGB colour, its sampler.
  struct TextureKey {
    int image;
    bool srgb;
    TextureSampler sampler;
    bool operator<(const TextureKey& o) const {
      if (image != o.image) return image < o.image;
      if (srgb != o.srgb) return srgb < o.srgb;
      return sampler < o.sampler;
    }
  };
  std::map<TextureKey, int> imageToTexture_;
  std::string skyMeshFlag_;  ///< the command line's sky mesh (loadScene's skyMesh)
  std::string skyMesh_;    ///< extras.lightoctree_sky_mesh, or the flag's: a material to take as the sky
  bool skyScale_ = false;  ///< extras.lightoctree_sky was given
  float turbidity_ = 0;    ///< extras.lightoctree_physical_sky; 0 = none
  std::set<int> missingImages_;  ///< images whose file is missing, warned once
  /// Each image's file bytes, kept by the textures that decode it (Texture::encoded).
  std::map<int, std::shared_ptr<const std::vector<uint8_t>>> imageBytes_;
  int defaultMaterial_ = -1;
  bool hasNormals_ = false, hasUv0_ = false, hasUv1_ = false, hasTangents_ = false,
       hasColors_ = false, warnedSpecularGlossiness_ = false;
};

}  // namespace

Scene loadGltf(const std::string& path, const std::string& skyMesh) {
  fs::path p(path);
  std::string baseDir = p.parent_path().string();
  if (baseDir.empty()) baseDir = ".";
  bool binary = hasExtension(path, ".glb");
  std::vector<unsigned char> bytes = readFileBytes(path, path, "file");
  if (bytes.size() > size_t(std::numeric_limits<uint32_t>::max())) {
    fail(path, "file larger than 4 GiB");
  }
  std::string jsonText = binary ? glbJson(path, bytes) : std::string(bytes.begin(), bytes.end());
  // Both JSON parsers (nlohmann here, tinygltf's copy below) recurse once per
  // level: a document nested deeper than any glTF needs would overflow the
  // stack. Counted first, outside strings.
  checkJsonNesting(path, jsonText);
  nlohmann::json j = nlohmann::json::parse(jsonText, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) fail(path, "invalid glTF: the JSON does not parse");
  prevalidateJson(path, baseDir, j);
  j = nlohmann::json();

  FsContext ctx;
  std::error_code ec;
  ctx.canonicalBase = fs::weakly_canonical(baseDir, ec);
  if (ec) fail(path, "cannot resolve the scene folder '" + baseDir + "'");
  tinygltf::FsCallbacks callbacks{&fsFileExists, &fsExpandFilePath, &fsReadWholeFile,
                                  &fsWriteWholeFile, &ctx};
  tinygltf::TinyGLTF loader;
  loader.SetFsCallbacks(callbacks);
  loader.SetImageLoader(&storeEncodedImage, nullptr);
  tinygltf::Model model;
  std::string err, warn;  // warnings are not errors: ignored
  bool ok = binary ? loader.LoadBinaryFromMemory(&model, &err, &warn, bytes.data(),
                                                 unsigned(bytes.size()), baseDir)
                   : loader.LoadASCIIFromString(&model, &err, &warn, jsonText.data(),
                                                unsigned(jsonText.size()), baseDir);
  if (!ok) {
    std::string e = firstLine(err);
    if (e.find("File not found") != std::string::npos ||
        e.find("refused or missing") != std::string::npos) {
      fail(path, "missing buffer: " + e);
    }
    fail(path, "invalid glTF: " + (e.empty() ? std::string("tinygltf failed") : e));
  }
  bytes.clear();
  jsonText.clear();
  return SceneBuilder(path, model, skyMesh).build();
}

}  // namespace lo::scene_internal
