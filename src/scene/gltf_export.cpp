/// @file scene/gltf_export.cpp
/// @brief glTF 2.0 writer for scene/gltf_export.h.
///
/// The JSON is built with nlohmann-json and the .glb container by hand (its
/// layout is 20 lines of the spec), not with tinygltf 2.7's writer, which
/// writes "zfar": 0 for a camera without a far plane (the validator rejects
/// it: zfar must be > 0 when present), and writes a .gltf's buffer either as
/// a base64 data uri or to a file of its own choosing, not atomically. Every
/// value written is one the Khronos validator accepts: factors clamped to
/// their ranges, unit normals and quaternions, POSITION min/max taken from
/// the floats written, TEXCOORD_n numbered from 0, indices below the
/// primitive-restart value.

#include "scene/gltf_export.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <unordered_map>

#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "image/image.h"

namespace lo {

namespace gltf_export_internal {

using json = nlohmann::json;

constexpr int kFloat = 5126, kUnsignedShort = 5123, kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962, kElementArrayBuffer = 34963;

[[noreturn]] void fail(const std::string& what) { throw InputError("glTF export: " + what); }

/// glTF uris are URI references: every byte outside RFC 3986's unreserved
/// set (and '/') percent-encoded, so that names with spaces stay valid.
std::string uriEncode(const std::string& name) {
  static const char* hex = "0123456789ABCDEF";
  std::string out;
  for (unsigned char c : name) {
    if (std::isalnum(c) || c == '-' || c == '.' || c == '_' || c == '~' || c == '/') {
      out += char(c);
    } else {
      out += '%';
      out += hex[c >> 4];
      out += hex[c & 15];
    }
  }
  return out;
}

/// The one buffer: every bufferView starts at a multiple of 4 bytes (the
/// largest component is 4 bytes; glTF requires the alignment of the
/// component type, and 4 keeps every view valid for any accessor).
class BufferBuilder {
 public:
  int addView(const void* bytes, size_t size, int target) {
    data_.resize((data_.size() + 3) & ~size_t(3), '\0');
    json view = {{"buffer", 0}, {"byteOffset", data_.size()}, {"byteLength", size}};
    if (target) view["target"] = target;
    data_.append(static_cast<const char*>(bytes), size);
    views_.push_back(std::move(view));
    return int(views_.size()) - 1;
  }
  /// The data, padded to a multiple of 4 (the GLB chunk rule).
  std::string finish() {
    data_.resize((data_.size() + 3) & ~size_t(3), '\0');
    return std::move(data_);
  }
  json& views() { return views_; }

 private:
  std::string data_;
  json views_ = json::array();
};

/// Unit quaternion [x, y, z, w] of the rotation whose matrix has the columns
/// x, y, z (an orthonormal right-handed basis): Shepperd's method.
std::array<double, 4> quaternionFromBasis(const std::array<double, 3>& x,
                                          const std::array<double, 3>& y,
                                          const std::array<double, 3>& z) {
  const double m00 = x[0], m10 = x[1], m20 = x[2];
  const double m01 = y[0], m11 = y[1], m21 = y[2];
  const double m02 = z[0], m12 = z[1], m22 = z[2];
  std::array<double, 4> q;
  const double trace = m00 + m11 + m22;
  if (trace > 0) {
    const double s = 2 * std::sqrt(trace + 1);
    q = {(m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s, 0.25 * s};
  } else if (m00 > m11 && m00 > m22) {
    const double s = 2 * std::sqrt(1 + m00 - m11 - m22);
    q = {0.25 * s, (m01 + m10) / s, (m02 + m20) / s, (m21 - m12) / s};
  } else if (m11 > m22) {
    const double s = 2 * std::sqrt(1 + m11 - m00 - m22);
    q = {(m01 + m10) / s, 0.25 * s, (m12 + m21) / s, (m02 - m20) / s};
  } else {
    const double s = 2 * std::sqrt(1 + m22 - m00 - m11);
    q = {(m02 + m20) / s, (m12 + m21) / s, 0.25 * s, (m10 - m01) / s};
  }
  const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (double& c : q) c /= n;
  return q;
}

std::array<double, 3> unit(const Vec3& v) {
  const double x = v.x, y = v.y, z = v.z, l = std::sqrt(x * x + y * y + z * z);
  return {x / l, y / l, z / l};
}
std::array<double, 3> crossD(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
std::array<double, 3> normalizeD(const std::array<double, 3>& a) {
  const double l = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  return {a[0] / l, a[1] / l, a[2] / l};
}

/// A node's rotation that takes its local -Z to `forward` and its local +Y
/// as close to `up` as forward allows (glTF cameras and lights look down -Z).
std::array<double, 4> lookRotation(const Vec3& forward, const Vec3& up) {
  const std::array<double, 3> f = unit(forward);
  std::array<double, 3> u = unit(up);
  std::array<double, 3> x = crossD(f, u);
  if (!(x[0] * x[0] + x[1] * x[1] + x[2] * x[2] > 1e-12)) {
    // Up parallel to forward (or missing): any perpendicular will do.
    u = std::fabs(f[1]) < 0.9 ? std::array<double, 3>{0, 1, 0} : std::array<double, 3>{1, 0, 0};
    x = crossD(f, u);
  }
  x = normalizeD(x);
  const std::array<double, 3> y = crossD(x, f);
  return quaternionFromBasis(x, y, {-f[0], -f[1], -f[2]});
}

json vec3Json(const Vec3& v) { return json::array({double(v.x), double(v.y), double(v.z)}); }
float clamp01(float v) { return std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f; }

bool hasUvSet(const Scene& scene, int set) {
  const std::vector<float>& uv = set == 1 ? scene.texcoords1 : scene.texcoords0;
  return !uv.empty() && uv.size() == 2 * scene.positions.size();
}

void checkExport(const Scene& scene, const LightmapExport& lm) {
  const size_t nt = scene.triangleCount();
  if (nt == 0) fail("the scene has no triangles");
  checkSceneIndices(scene);
  const size_t pages = lm.pageUris.size();
  auto sizeError = [&](const char* field, size_t size, size_t expected) {
    fail("LightmapExport." + std::string(field) + " has " + std::to_string(size) + " values for " +
         std::to_string(nt) + " triangles (" + std::to_string(expected) + " expected)");
  };
  if (lm.uv.size() != 6 * nt) sizeError("uv", lm.uv.size(), 6 * nt);
  if (lm.trianglePage.size() != nt) sizeError("trianglePage", lm.trianglePage.size(), nt);
  if (pages == 0) fail("LightmapExport.pageUris is empty (one file name per page)");
  if (!lm.directionUris.empty() && lm.directionUris.size() != pages) {
    fail("LightmapExport.directionUris has " + std::to_string(lm.directionUris.size()) +
         " names for " + std::to_string(pages) + " pages");
  }
  for (const auto* uris : {&lm.pageUris, &lm.directionUris}) {
    for (size_t p = 0; p < uris->size(); ++p) {
      const std::string& uri = (*uris)[p];
      if (uri.empty() || uri.front() == '/' || uri.find("..") != std::string::npos ||
          uri.find(':') != std::string::npos) {
        fail(std::string("LightmapExport.") + (uris == &lm.pageUris ? "pageUris[" : "directionUris[") +
             std::to_string(p) + "] '" + uri + "' is not a file name relative to the glTF's folder");
      }
    }
  }
  if (lm.width < 1 || lm.height < 1) {
    fail("LightmapExport: page size " + std::to_string(lm.width) + " x " +
         std::to_string(lm.height));
  }
  for (size_t t = 0; t < nt; ++t) {
    if (lm.trianglePage[t] < 0 || size_t(lm.trianglePage[t]) >= pages) {
      fail("LightmapExport.trianglePage: triangle " + std::to_string(t) + " is on page " +
           std::to_string(lm.trianglePage[t]) + " of " + std::to_string(pages));
    }
  }
  for (size_t i = 0; i < lm.uv.size(); ++i) {
    if (!(lm.uv[i] >= 0 && lm.uv[i] <= 1)) {
      fail("LightmapExport.uv: triangle " + std::to_string(i / 6) + " has " +
           std::to_string(lm.uv[i]) + ", outside [0, 1]");
    }
  }
  if (lm.encoding != "linear-exr" && lm.encoding != "rgbm-png") {
    fail("LightmapExport.encoding '" + lm.encoding + "' (expected linear-exr or rgbm-png)");
  }
  if (lm.encoding == "rgbm-png" && !(std::isfinite(lm.rgbmRange) && lm.rgbmRange > 0)) {
    fail("LightmapExport.rgbmRange " + std::to_string(lm.rgbmRange) +
         " must be finite and > 0 for rgbm-png");
  }
  if (lm.content != "indirect" && lm.content != "full") {
    fail("LightmapExport.content '" + lm.content + "' (expected indirect or full)");
  }
  if (lm.unlit) {
    if (lm.previewPng.size() != pages) {
      fail("LightmapExport.previewPng has " + std::to_string(lm.previewPng.size()) +
           " images for " + std::to_string(pages) + " pages (unlit needs one per page)");
    }
    for (size_t p = 0; p < pages; ++p)
      if (lm.previewPng[p].empty())
        fail("LightmapExport.previewPng[" + std::to_string(p) + "] is empty");
    if (!std::isfinite(lm.previewExposureEv))
      fail("LightmapExport.previewExposureEv is not finite");
  }
  if (!scene.normals.empty() && scene.normals.size() != scene.positions.size()) {
    fail("scene normals: " + std::to_string(scene.normals.size()) + " for " +
         std::to_string(scene.positions.size()) + " vertices");
  }
}

/// Builds the glTF document and its buffer.
class Exporter {
 public:
  Exporter(const Scene& scene, const LightmapExport& lm) : scene_(scene), lm_(lm) {
    hasUv0_ = hasUvSet(scene, 0);
    hasUv1_ = hasUvSet(scene, 1);
    // The scene's own second set goes to TEXCOORD_2 unless it is the
    // lightmap (--uv texcoord1: the same numbers).
    if (hasUv1_) {
      uv1IsLightmap_ = true;
      for (size_t c = 0; c < 3 * scene.triangleCount() && uv1IsLightmap_; ++c) {
        const uint32_t v = scene.indices[c];
        uv1IsLightmap_ = scene.texcoords1[2 * v] == lm.uv[2 * c] &&
                         scene.texcoords1[2 * v + 1] == lm.uv[2 * c + 1];
      }
    }
  }

  /// The document; `buffer` receives the binary data.
  json build(std::string& buffer, const std::string& binUri) {
    json doc;
    doc["asset"] = {{"version", "2.0"}, {"generator", "Light Octree: lightoctree lightmap"}};
    buildMesh();
    json nodes = json::array();
    std::string meshName = std::filesystem::path(scene_.sourcePath).stem().string();
    nodes.push_back({{"name", meshName.empty() ? "scene" : meshName}, {"mesh", 0}});
    if (!lm_.unlit) addLights(nodes);
    addCameras(nodes, doc);
    json sceneNodes = json::array();
    for (size_t i = 0; i < nodes.size(); ++i) sceneNodes.push_back(i);
    if (scene_.rebased()) {
      // A scene the loader rebased (Scene::origin): everything under one node
      // that puts it back where the file had it, in double.
      nodes.push_back({{"name", "scene origin"},
                       {"translation", {scene_.origin.x, scene_.origin.y, scene_.origin.z}},
                       {"children", sceneNodes}});
      sceneNodes = json::array({nodes.size() - 1});
    }
    doc["scene"] = 0;
    doc["scenes"] = json::array({{{"nodes", sceneNodes}}});
    doc["nodes"] = std::move(nodes);
    doc["meshes"] = json::array({{{"name", "lightmapped"}, {"primitives", primitives_}}});
    doc["materials"] = std::move(materials_);
    doc["accessors"] = std::move(accessors_);
    if (!images_.empty()) {
      doc["images"] = std::move(images_);
      doc["textures"] = std::move(textures_);
      if (!samplers_.empty()) doc["samplers"] = std::move(samplers_);
    }
    if (!lights_.empty()) {
      doc["extensions"]["KHR_lights_punctual"] = {{"lights", std::move(lights_)}};
      extensionsUsed_.insert("KHR_lights_punctual");
    }
    if (!extensionsUsed_.empty()) {
      doc["extensionsUsed"] =
          json(std::vector<std::string>(extensionsUsed_.begin(), extensionsUsed_.end()));
    }
    doc["bufferViews"] = std::move(buffer_.views());
    buffer = buffer_.finish();
    json b = {{"byteLength", buffer.size()}};
    if (!binUri.empty()) b["uri"] = uriEncode(binUri);
    doc["buffers"] = json::array({b});
    return doc;
  }

 private:
  struct VertexKey {
    uint32_t vertex, u, v;
    bool operator==(const VertexKey& o) const { return vertex == o.vertex && u == o.u && v == o.v; }
  };
  struct VertexKeyHash {
    size_t operator()(const VertexKey& k) const {
      uint64_t h = k.vertex * 0x9E3779B97F4A7C15ull;
      h ^= (uint64_t(k.u) << 32 | k.v) + 0x632BE59BD9B4E019ull + (h << 6) + (h >> 2);
      return size_t(h ^ (h >> 29));
    }
  };

  int addAccessor(const void* data, size_t bytes, int target, int componentType, size_t count,
                  const char* type) {
    const int view = buffer_.addView(data, bytes, target);
    accessors_.push_back(
        {{"bufferView", view}, {"componentType", componentType}, {"count", count}, {"type", type}});
    return int(accessors_.size()) - 1;
  }

  /// A unit normal for vertex v of triangle t: the vertex normal
  /// renormalised in double, else the face normal, else +Z.
  std::array<float, 3> safeNormal(uint32_t v, size_t t) const {
    for (const Vec3& n : {scene_.normals[v], scene_.faceNormal(t)}) {
      const double x = n.x, y = n.y, z = n.z, l = std::sqrt(x * x + y * y + z * z);
      if (std::isfinite(l) && l > 1e-20) return {float(x / l), float(y / l), float(z / l)};
    }
    return {0, 0, 1};
  }

  void buildMesh() {
    const size_t nt = scene_.triangleCount();
    // Triangles by (material, page), in scene order within each.
    std::map<std::pair<int32_t, int32_t>, std::vector<uint32_t>> groups;
    for (size_t t = 0; t < nt; ++t) {
      groups[{scene_.triangleMaterial[t], lm_.trianglePage[t]}].push_back(uint32_t(t));
    }
    std::map<int32_t, int> pagesOfMaterial;
    for (const auto& g : groups) ++pagesOfMaterial[g.first.first];
    for (const auto& [key, triangles] : groups) {
      const int material = addMaterial(key.first, key.second, pagesOfMaterial[key.first] > 1);
      const Material& m = scene_.materials[size_t(key.first)];
      const bool tangents =
          !lm_.unlit && !scene_.normals.empty() && mapExported(m.normalTexture, m.normalTexCoord);
      addPrimitive(triangles, material, tangents);
    }
  }

  /// Per welded vertex, the TANGENT glTF's normal maps read (xyz, w = 1:
  /// bitangent = cross(normal, tangent)): the frame Scene::shadingNormal
  /// builds per triangle (tangent = dp/du of the normal map's UVs after its
  /// transform), averaged over the vertex's triangles by area and made
  /// orthogonal to the vertex normal.
  std::vector<float> tangents(const std::vector<uint32_t>& triangles,
                              const std::vector<uint32_t>& indices, const std::vector<float>& nrm) {
    std::vector<Vec3> sum(nrm.size() / 3, Vec3{0, 0, 0});
    for (size_t k = 0; k < triangles.size(); ++k) {
      const size_t t = triangles[k];
      const Material& m = scene_.materials[size_t(scene_.triangleMaterial[t])];
      float u[3], v[3];
      const float bary[3][2] = {{0, 0}, {1, 0}, {0, 1}};
      for (int c = 0; c < 3; ++c)
        scene_.texcoord(t, bary[c][0], bary[c][1], m.normalTexCoord, m.normalTransform, u[c], v[c]);
      const Vec3 p0 = scene_.positions[scene_.indices[3 * t]];
      const Vec3 e1 = scene_.positions[scene_.indices[3 * t + 1]] - p0;
      const Vec3 e2 = scene_.positions[scene_.indices[3 * t + 2]] - p0;
      const float du1 = u[1] - u[0], dv1 = v[1] - v[0], du2 = u[2] - u[0], dv2 = v[2] - v[0];
      const float det = du1 * dv2 - du2 * dv1;
      if (!(std::fabs(det) > 1e-20f)) continue;
      const Vec3 t3 = (e1 * dv2 - e2 * dv1) / det;
      if (!(lengthSquared(t3) > 1e-30f) || !isFinite(t3)) continue;
      const Vec3 weighted = normalize(t3) * (0.5f * length(cross(e1, e2)));
      for (int c = 0; c < 3; ++c) sum[indices[3 * k + size_t(c)]] += weighted;
    }
    std::vector<float> out;
    out.reserve(sum.size() * 4);
    for (size_t i = 0; i < sum.size(); ++i) {
      const std::array<double, 3> n{nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]};
      std::array<double, 3> t{sum[i].x, sum[i].y, sum[i].z};
      double d = t[0] * n[0] + t[1] * n[1] + t[2] * n[2];
      for (int a = 0; a < 3; ++a) t[a] -= d * n[a];
      if (!(t[0] * t[0] + t[1] * t[1] + t[2] * t[2] > 1e-24)) {
        // No UV gradient here: any unit vector perpendicular to the normal.
        const std::array<double, 3> axis =
            std::fabs(n[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
        d = axis[0] * n[0] + axis[1] * n[1] + axis[2] * n[2];
        for (int a = 0; a < 3; ++a) t[a] = axis[size_t(a)] - d * n[a];
      }
      t = normalizeD(t);
      out.insert(out.end(), {float(t[0]), float(t[1]), float(t[2]), 1.0f});
    }
    return out;
  }

  void addPrimitive(const std::vector<uint32_t>& triangles, int material, bool withTangents) {
    std::unordered_map<VertexKey, uint32_t, VertexKeyHash> slot;
    slot.reserve(triangles.size() * 2);
    std::vector<float> pos, nrm, uv0, uv1, uv2, rgba;
    std::vector<uint32_t> indices;
    indices.reserve(3 * triangles.size());
    const bool normals = !scene_.normals.empty();
    const bool colors = scene_.colors.size() == 4 * scene_.positions.size();
    const bool writeUv2 = hasUv1_ && !uv1IsLightmap_;
    for (uint32_t t : triangles) {
      for (int k = 0; k < 3; ++k) {
        const size_t c = 3 * size_t(t) + size_t(k);
        const uint32_t v = scene_.indices[c];
        const float lu = lm_.uv[2 * c], lv = lm_.uv[2 * c + 1];
        VertexKey key{v, 0, 0};
        std::memcpy(&key.u, &lu, 4);
        std::memcpy(&key.v, &lv, 4);
        auto [it, added] = slot.try_emplace(key, uint32_t(pos.size() / 3));
        indices.push_back(it->second);
        if (!added) continue;
        const Vec3& p = scene_.positions[v];
        pos.insert(pos.end(), {p.x, p.y, p.z});
        if (normals) {
          const std::array<float, 3> n = safeNormal(v, t);
          nrm.insert(nrm.end(), n.begin(), n.end());
        }
        uv1.insert(uv1.end(), {lu, lv});
        if (hasUv0_) {
          uv0.insert(uv0.end(), {scene_.texcoords0[2 * v], scene_.texcoords0[2 * v + 1]});
        } else {
          uv0.insert(uv0.end(), {lu, lv});
        }
        if (writeUv2)
          uv2.insert(uv2.end(), {scene_.texcoords1[2 * v], scene_.texcoords1[2 * v + 1]});
        if (colors) rgba.insert(rgba.end(), &scene_.colors[4 * v], &scene_.colors[4 * v] + 4);
      }
    }
    const size_t count = pos.size() / 3;
    json attributes;
    attributes["POSITION"] =
        addAccessor(pos.data(), pos.size() * 4, kArrayBuffer, kFloat, count, "VEC3");
    json lo = json::array(), hi = json::array();
    for (int a = 0; a < 3; ++a) {
      float mn = pos[size_t(a)], mx = pos[size_t(a)];
      for (size_t i = 0; i < count; ++i) {
        mn = std::min(mn, pos[3 * i + size_t(a)]);
        mx = std::max(mx, pos[3 * i + size_t(a)]);
      }
      lo.push_back(double(mn));
      hi.push_back(double(mx));
    }
    accessors_.back()["min"] = lo;
    accessors_.back()["max"] = hi;
    if (normals) {
      attributes["NORMAL"] =
          addAccessor(nrm.data(), nrm.size() * 4, kArrayBuffer, kFloat, count, "VEC3");
    }
    if (withTangents) {
      const std::vector<float> tan = tangents(triangles, indices, nrm);
      attributes["TANGENT"] =
          addAccessor(tan.data(), tan.size() * 4, kArrayBuffer, kFloat, count, "VEC4");
    }
    attributes["TEXCOORD_0"] =
        addAccessor(uv0.data(), uv0.size() * 4, kArrayBuffer, kFloat, count, "VEC2");
    attributes["TEXCOORD_1"] =
        addAccessor(uv1.data(), uv1.size() * 4, kArrayBuffer, kFloat, count, "VEC2");
    if (writeUv2) {
      attributes["TEXCOORD_2"] =
          addAccessor(uv2.data(), uv2.size() * 4, kArrayBuffer, kFloat, count, "VEC2");
    }
    if (colors) {
      attributes["COLOR_0"] =
          addAccessor(rgba.data(), rgba.size() * 4, kArrayBuffer, kFloat, count, "VEC4");
    }
    int indexAccessor;
    // 16-bit indices while every index stays below 65535, glTF's
    // primitive-restart value for them.
    if (count < 65535) {
      std::vector<uint16_t> small(indices.begin(), indices.end());
      indexAccessor = addAccessor(small.data(), small.size() * 2, kElementArrayBuffer,
                                  kUnsignedShort, small.size(), "SCALAR");
    } else {
      indexAccessor = addAccessor(indices.data(), indices.size() * 4, kElementArrayBuffer,
                                  kUnsignedInt, indices.size(), "SCALAR");
    }
    primitives_.push_back(
        {{"attributes", attributes}, {"indices", indexAccessor}, {"material", material}});
  }

  /// The glTF texture of Scene texture `index`: the image file's own bytes
  /// when the texture was read from a PNG or JPEG and is read here with the
  /// encoding it was decoded with (each file embedded once); else its texels
  /// encoded as an 8-bit PNG (once per texture and encoding).
  int texture(int index, bool srgb) {
    auto it = textureOf_.find({index, srgb});
    if (it != textureOf_.end()) return it->second;
    const Texture& tex = scene_.textures[size_t(index)];
    int result = -1;
    if (tex.encoded && !tex.encoded->empty() && tex.srgb == srgb) {
      auto image = imageOfFile_.find(tex.encoded.get());
      const int source = image != imageOfFile_.end()
                             ? image->second
                             : addImage(*tex.encoded, tex.mimeType, tex.name);
      imageOfFile_[tex.encoded.get()] = source;
      textures_.push_back({{"source", source}});
      result = int(textures_.size()) - 1;
      addSampler(textures_.back(), tex.sampler);
    } else {
      const size_t n = tex.texelCount();
      const int channels = tex.hasAlpha() ? 4 : 3;
      std::vector<unsigned char> pixels(n * size_t(channels));
      auto data8 = [](float v) {
        return (unsigned char)std::lround(255.0f *
                                          (std::isfinite(v) ? std::clamp(v, 0.0f, 1.0f) : 0.0f));
      };
      for (size_t i = 0; i < n; ++i) {
        const int x = int(i % size_t(tex.width)), y = int(i / size_t(tex.width));
        const Vec3 c = tex.texel(x, y);
        for (int k = 0; k < 3; ++k)
          pixels[i * size_t(channels) + size_t(k)] = srgb ? encodeSrgb8(c[k]) : data8(c[k]);
        if (channels == 4) pixels[i * 4 + 3] = data8(tex.texelAlpha(x, y));
      }
      const std::vector<unsigned char> png =
          encodePng8(tex.width, tex.height, channels, pixels.data());
      textures_.push_back({{"source", addImage(png, "image/png", tex.name)}});
      result = int(textures_.size()) - 1;
      addSampler(textures_.back(), tex.sampler);
    }
    textureOf_[{index, srgb}] = result;
    return result;
  }

  /// `texture`'s sampler when it is not glTF's default (one per distinct sampler).
  void addSampler(json& texture, const TextureSampler& sampler) {
    const TextureSampler defaults;
    if (!(sampler < defaults) && !(defaults < sampler)) return;
    auto it = samplerOf_.find(sampler);
    if (it == samplerOf_.end()) {
      json s = {{"magFilter", sampler.magFilter}, {"wrapS", sampler.wrapS}, {"wrapT", sampler.wrapT}};
      if (sampler.minFilter != 0) s["minFilter"] = sampler.minFilter;
      samplers_.push_back(std::move(s));
      it = samplerOf_.emplace(sampler, int(samplers_.size()) - 1).first;
    }
    texture["sampler"] = it->second;
  }

  /// An image in the buffer; returns its index.
  int addImage(const std::vector<unsigned char>& bytes, const std::string& mimeType,
               const std::string& name) {
    const int view = buffer_.addView(bytes.data(), bytes.size(), 0);
    json image = {{"bufferView", view}, {"mimeType", mimeType}};
    if (!name.empty()) image["name"] = name;
    images_.push_back(std::move(image));
    return int(images_.size()) - 1;
  }

  /// Whether a map is written: a decoded texture on a UV set the scene has
  /// (Scene ignores a map whose set is missing, so the export drops it).
  bool mapExported(int index, int texCoord) const {
    if (index < 0 || size_t(index) >= scene_.textures.size()) return false;
    const Texture& tex = scene_.textures[size_t(index)];
    return !tex.empty() && tex.byteSize() > 0 && hasUvSet(scene_, texCoord);
  }

  /// A texture reference, or null when the map is dropped (mapExported).
  json textureInfo(int index, int texCoord, const TextureTransform& transform, bool srgb) {
    if (!mapExported(index, texCoord)) return nullptr;
    json info = {{"index", texture(index, srgb)}};
    const int set = texCoord == 1 && !uv1IsLightmap_ ? 2 : texCoord;
    if (set != 0) info["texCoord"] = set;
    json tt = json::object();
    if (transform.offset[0] != 0 || transform.offset[1] != 0)
      tt["offset"] = {double(transform.offset[0]), double(transform.offset[1])};
    if (transform.rotation != 0) tt["rotation"] = double(transform.rotation);
    if (transform.scale[0] != 1 || transform.scale[1] != 1)
      tt["scale"] = {double(transform.scale[0]), double(transform.scale[1])};
    if (!tt.empty()) {
      info["extensions"]["KHR_texture_transform"] = tt;
      extensionsUsed_.insert("KHR_texture_transform");
    }
    return info;
  }

  json lightmapExtras(int page) const {
    json l = {{"uri", uriEncode(lm_.pageUris[size_t(page)])},
              {"page", page},
              {"texCoord", 1},
              {"encoding", lm_.encoding},
              {"quantity", "irradiance"},
              {"units", "W/m^2"},
              {"content", lm_.content},
              {"shading", "radiance = baseColor / pi * E"},
              {"width", lm_.width},
              {"height", lm_.height}};
    if (lm_.encoding == "rgbm-png") l["rgbmRange"] = double(lm_.rgbmRange);
    if (!lm_.directionUris.empty()) {
      l["direction"] = {{"uri", uriEncode(lm_.directionUris[size_t(page)])},
                        {"encoding", "unit-vector-png"},
                        {"decode", "d = (byte - 128) / 127 per channel"},
                        {"space", "world"},
                        {"quantity", "mean direction towards the light"},
                        {"shading", "one light of colour E / max(dot(n_vertex, d), 0.05) from d"}};
    }
    return l;
  }

  int addMaterial(int32_t index, int32_t page, bool nameByPage) {
    const Material& m = scene_.materials[size_t(index)];
    json g;
    g["name"] = nameByPage ? m.name + " (lightmap page " + std::to_string(page) + ")" : m.name;
    const float alpha = clamp01(m.baseAlpha);
    if (m.alphaMode == AlphaMode::Mask) {
      g["alphaMode"] = "MASK";
      g["alphaCutoff"] = std::isfinite(m.alphaCutoff) ? std::max(0.0, double(m.alphaCutoff)) : 0.5;
    } else if (m.alphaMode == AlphaMode::Blend) {
      g["alphaMode"] = "BLEND";
    }
    // A surface drawn from both sides (an OBJ face) stays so in glTF, unless
    // it emits: glTF's doubleSided would make it emit from both sides too.
    if (m.doubleSided || (!m.backFaceCulling && !m.isEmissive())) g["doubleSided"] = true;
    g["extras"]["lightmap"] = lightmapExtras(page);
    json pbr;
    if (lm_.unlit) {
      // The baked radiance is the colour; nothing else of the material shows.
      pbr["baseColorFactor"] = {1.0, 1.0, 1.0, double(alpha)};
      pbr["metallicFactor"] = 0.0;
      pbr["roughnessFactor"] = 1.0;
      pbr["baseColorTexture"] = {{"index", previewTexture(page)}, {"texCoord", 1}};
      g["pbrMetallicRoughness"] = pbr;
      g["extensions"]["KHR_materials_unlit"] = json::object();
      extensionsUsed_.insert("KHR_materials_unlit");
      g["extras"]["lightmapPreview"] = {
          {"quantity", "radiance"},
          {"units", "W/(m^2 sr)"},
          {"encoding", "srgb-png"},
          {"exposureEv", double(lm_.previewExposureEv)},
          {"shows", "(baseColor / pi * E + emissive) * 2^exposureEv, clamped to 1"}};
      materials_.push_back(std::move(g));
      return int(materials_.size()) - 1;
    }
    pbr["baseColorFactor"] = {clamp01(m.baseColor.x), clamp01(m.baseColor.y),
                              clamp01(m.baseColor.z), alpha};
    pbr["metallicFactor"] = clamp01(m.metallic);
    pbr["roughnessFactor"] = clamp01(m.roughness);
    json base = textureInfo(m.baseColorTexture, m.baseColorTexCoord, m.baseColorTransform, true);
    if (!base.is_null()) pbr["baseColorTexture"] = base;
    json mr = textureInfo(m.metallicRoughnessTexture, m.metallicRoughnessTexCoord,
                          m.metallicRoughnessTransform, false);
    if (!mr.is_null()) pbr["metallicRoughnessTexture"] = mr;
    g["pbrMetallicRoughness"] = pbr;
    json normal = textureInfo(m.normalTexture, m.normalTexCoord, m.normalTransform, false);
    if (!normal.is_null()) {
      if (std::isfinite(m.normalScale) && m.normalScale != 1)
        normal["scale"] = double(m.normalScale);
      g["normalTexture"] = normal;
    }
    json occlusion =
        textureInfo(m.occlusionTexture, m.occlusionTexCoord, m.occlusionTransform, false);
    if (!occlusion.is_null()) {
      if (m.occlusionStrength != 1) occlusion["strength"] = double(clamp01(m.occlusionStrength));
      g["occlusionTexture"] = occlusion;
    }
    const float strength = maxComponent(m.emission);
    if (std::isfinite(strength) && strength > 0) {
      // emissiveFactor lies in [0, 1]; brighter emitters carry the rest as
      // KHR_materials_emissive_strength.
      const float scale = std::max(1.0f, strength);
      g["emissiveFactor"] = vec3Json(max(m.emission, Vec3{0, 0, 0}) / scale);
      if (scale > 1) {
        g["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", double(scale)}};
        extensionsUsed_.insert("KHR_materials_emissive_strength");
      }
      json emissive = textureInfo(m.emissiveTexture, m.emissiveTexCoord, m.emissiveTransform, true);
      if (!emissive.is_null()) g["emissiveTexture"] = emissive;
    }
    if (m.transmission > 0) {
      g["extensions"]["KHR_materials_transmission"] = {
          {"transmissionFactor", double(clamp01(m.transmission))}};
      extensionsUsed_.insert("KHR_materials_transmission");
    }
    if (std::isfinite(m.ior) && m.ior != 1.5f && (m.ior >= 1 || m.ior == 0)) {
      g["extensions"]["KHR_materials_ior"] = {{"ior", double(m.ior)}};
      extensionsUsed_.insert("KHR_materials_ior");
    }
    if (std::isfinite(m.thickness) && m.thickness > 0) {
      g["extensions"]["KHR_materials_volume"] = {{"thicknessFactor", double(m.thickness)}};
      extensionsUsed_.insert("KHR_materials_volume");
    }
    materials_.push_back(std::move(g));
    return int(materials_.size()) - 1;
  }

  int previewTexture(int page) {
    auto it = previewOf_.find(page);
    if (it != previewOf_.end()) return it->second;
    textures_.push_back({{"source", addImage(lm_.previewPng[size_t(page)], "image/png",
                                             "lightmap preview " + std::to_string(page))}});
    const int t = int(textures_.size()) - 1;
    previewOf_[page] = t;
    return t;
  }

  void addLights(json& nodes) {
    for (const Light& light : scene_.lights) {
      Vec3 color = light.color;
      float intensity = light.intensity;
      const float c = maxComponent(color);
      if (!isFinite(color) || !std::isfinite(intensity) || c < 0) continue;
      // glTF's colour lies in [0, 1]: a brighter colour moves into intensity.
      if (c > 1) {
        color = color / c;
        intensity *= c;
      }
      json l = {{"color", vec3Json(max(color, Vec3{0, 0, 0}))}, {"intensity", double(intensity)}};
      if (!light.name.empty()) l["name"] = light.name;
      if (light.range > 0 && std::isfinite(light.range)) l["range"] = double(light.range);
      json node;
      node["name"] = light.name.empty() ? "light" : light.name;
      switch (light.type) {
        case Light::Type::Point:
          l["type"] = "point";
          break;
        case Light::Type::Spot: {
          l["type"] = "spot";
          const double outer = std::clamp(double(light.outerConeAngle), 1e-6, kPi / 2.0);
          const double inner = std::clamp(double(light.innerConeAngle), 0.0, outer * 0.999);
          l["spot"] = {{"innerConeAngle", inner}, {"outerConeAngle", outer}};
          break;
        }
        case Light::Type::Directional:
          l["type"] = "directional";
          break;
      }
      if (light.type != Light::Type::Directional) node["translation"] = vec3Json(light.position);
      if (light.type != Light::Type::Point) {
        const std::array<double, 4> q = lookRotation(light.direction, {0, 1, 0});
        node["rotation"] = {q[0], q[1], q[2], q[3]};
      }
      node["extensions"]["KHR_lights_punctual"] = {{"light", lights_.size()}};
      lights_.push_back(std::move(l));
      nodes.push_back(std::move(node));
    }
  }

  void addCameras(json& nodes, json& doc) {
    json cameras = json::array();
    for (const Camera& cam : scene_.cameras) {
      if (!(cam.yfov > 0 && cam.yfov < kPi) || !isFinite(cam.position) ||
          !(lengthSquared(cam.forward) > 0)) {
        continue;
      }
      json p = {{"yfov", double(cam.yfov)},
                {"znear", cam.znear > 0 && std::isfinite(cam.znear) ? double(cam.znear) : 0.01}};
      if (cam.zfar > p["znear"].get<double>() && std::isfinite(cam.zfar))
        p["zfar"] = double(cam.zfar);
      if (cam.aspectRatio > 0 && std::isfinite(cam.aspectRatio))
        p["aspectRatio"] = double(cam.aspectRatio);
      json c = {{"type", "perspective"}, {"perspective", p}};
      if (!cam.name.empty()) c["name"] = cam.name;
      const std::array<double, 4> q = lookRotation(cam.forward, cam.up);
      json node = {{"name", cam.name.empty() ? "camera" : cam.name},
                   {"camera", cameras.size()},
                   {"translation", vec3Json(cam.position)},
                   {"rotation", {q[0], q[1], q[2], q[3]}}};
      cameras.push_back(std::move(c));
      nodes.push_back(std::move(node));
    }
    if (!cameras.empty()) doc["cameras"] = std::move(cameras);
  }

  const Scene& scene_;
  const LightmapExport& lm_;
  bool hasUv0_ = false, hasUv1_ = false, uv1IsLightmap_ = false;
  BufferBuilder buffer_;
  json accessors_ = json::array(), primitives_ = json::array(), materials_ = json::array();
  json images_ = json::array(), textures_ = json::array(), lights_ = json::array();
  json samplers_ = json::array();
  std::map<std::pair<int, bool>, int> textureOf_;
  std::map<const std::vector<uint8_t>*, int> imageOfFile_;  ///< embedded image files
  std::map<TextureSampler, int> samplerOf_;
  std::map<int, int> previewOf_;
  std::set<std::string> extensionsUsed_;
};

void appendU32(std::string& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out += char((v >> (8 * i)) & 0xFF);
}

/// The GLB container (glTF 2.0 spec, "Binary glTF Layout"): a 12-byte
/// header, the JSON chunk padded with spaces, the BIN chunk padded with zeros.
std::string glb(std::string jsonText, const std::string& bin) {
  jsonText.resize((jsonText.size() + 3) & ~size_t(3), ' ');
  const uint64_t length = 12 + 8 + jsonText.size() + (bin.empty() ? 0 : 8 + bin.size());
  if (length > 0xFFFFFFFFull) fail("the .glb would exceed 4 GiB");
  std::string out;
  out.reserve(size_t(length));
  out += "glTF";
  appendU32(out, 2);
  appendU32(out, uint32_t(length));
  appendU32(out, uint32_t(jsonText.size()));
  appendU32(out, 0x4E4F534Au);  // "JSON"
  out += jsonText;
  if (!bin.empty()) {
    appendU32(out, uint32_t(bin.size()));
    appendU32(out, 0x004E4942u);  // "BIN\0"
    out += bin;
  }
  return out;
}

}  // namespace gltf_export_internal

GltfFiles encodeLightmapGltf(const Scene& scene, const LightmapExport& lightmap,
                             const std::string& path) {
  using namespace gltf_export_internal;
  const bool binary = hasExtension(path, ".glb");
  if (!binary) checkOutputExtension(path, "a glTF export", {".glb", ".gltf"});
  checkExport(scene, lightmap);
  GltfFiles files;
  if (!binary) files.binUri = std::filesystem::path(path).stem().string() + ".bin";
  std::string buffer;
  Exporter exporter(scene, lightmap);
  const json doc = exporter.build(buffer, files.binUri);
  // Names from OBJ files may hold bytes that are not UTF-8: replaced, not fatal.
  if (binary) {
    files.gltf = glb(doc.dump(-1, ' ', false, json::error_handler_t::replace), buffer);
  } else {
    files.gltf = doc.dump(1, ' ', false, json::error_handler_t::replace) + "\n";
    files.bin = std::move(buffer);
  }
  return files;
}

void writeGltfFiles(const GltfFiles& files, const std::string& path, AtomicFileSet* set) {
  AtomicFileSet own;
  AtomicFileSet& into = set ? *set : own;
  if (!files.binUri.empty()) {
    into.addText((std::filesystem::path(path).parent_path() / files.binUri).string(), files.bin);
  }
  into.addText(path, files.gltf);
  if (!set) own.commit();
}

void writeLightmapGltf(const Scene& scene, const LightmapExport& lightmap,
                       const std::string& path) {
  writeGltfFiles(encodeLightmapGltf(scene, lightmap, path), path);
}

}  // namespace lo
