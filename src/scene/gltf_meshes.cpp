/// @file scene/gltf_meshes.cpp
/// @brief glTF mesh primitives as Scene triangles (SceneBuilder,
/// gltf_internal.h): modes triangulated, positions in world space, and
/// the vertex attributes (normals, two UV sets, tangents, colours) that
/// only some primitives carry filled in for the others.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "core/resources.h"
#include "scene/gltf_internal.h"

namespace lo::scene_internal::gltf_internal {

void SceneBuilder::morph(const tinygltf::Primitive& prim, const std::vector<double>& weights,
                         const std::string& what, size_t nverts, std::vector<double>& pos,
                         std::vector<double>& nrm) {
  for (size_t t = 0; t < prim.targets.size() && t < weights.size(); ++t) {
    if (weights[t] == 0) continue;
    for (const auto& [name, accessor] : prim.targets[t]) {
      std::vector<double>* into = name == "POSITION" ? &pos : name == "NORMAL" ? &nrm : nullptr;
      if (!into || into->empty()) continue;  // TANGENT, or a normal the primitive lacks
      const std::string label = what + " morph target " + std::to_string(t) + " " + name;
      const std::vector<double> delta = reader_.read(accessor, TINYGLTF_TYPE_VEC3, label);
      if (reader_.count(accessor) != nverts) {
        fail(path_, label + " has " + std::to_string(reader_.count(accessor)) +
                        " elements, POSITION has " + std::to_string(nverts));
      }
      for (size_t k = 0; k < into->size(); ++k) (*into)[k] += weights[t] * delta[k];
    }
  }
}

void SceneBuilder::warnMissingUvSets(int material, const std::function<bool(int)>& has,
                                     const std::string& what) {
  const Material& m = scene_.materials[size_t(material)];
  const std::pair<int, int> uses[] = {{m.baseColorTexture, m.baseColorTexCoord},
                                      {m.normalTexture, m.normalTexCoord},
                                      {m.metallicRoughnessTexture, m.metallicRoughnessTexCoord},
                                      {m.occlusionTexture, m.occlusionTexCoord},
                                      {m.emissiveTexture, m.emissiveTexCoord}};
  for (const auto& [texture, set] : uses) {
    if (texture < 0 || has(set) || !missingUvSets_.insert({material, set}).second) continue;
    scene_.warnings.push_back(path_ + ": " + what + ": material " + std::to_string(material) +
                              " has a texture on TEXCOORD_" + std::to_string(set) +
                              ", which the primitive lacks: its texels are read at (0, 0)");
  }
}

void SceneBuilder::addMesh(int meshIndex, const Mat4& world,
                           const std::vector<double>* nodeWeights) {
  if (size_t(meshIndex) >= model_.meshes.size()) {
    fail(path_, "mesh index " + std::to_string(meshIndex) + " out of range");
  }
  const tinygltf::Mesh& mesh = model_.meshes[size_t(meshIndex)];
  // Morph targets at their default weights, the node's over the mesh's
  // (glTF 2.0, morph targets): they were left out, and a lifted part drawn
  // where its base shape lies (H14-4-1).
  const std::vector<double>& weights =
      nodeWeights && !nodeWeights->empty() ? *nodeWeights : mesh.weights;
  for (size_t i = 0; i < weights.size(); ++i) {
    if (!std::isfinite(weights[i])) {
      fail(path_, "mesh " + std::to_string(meshIndex) + ": morph target weight " +
                      std::to_string(i) + " is not finite");
    }
  }
  const bool morphed = std::any_of(weights.begin(), weights.end(), [](double w) { return w != 0; });
  // glTF asks one weight a target; other counts are read as far as both go.
  for (size_t p = 0; p < mesh.primitives.size() && morphed; ++p) {
    const size_t targets = mesh.primitives[p].targets.size();
    if (targets == weights.size() || !morphCountsWarned_.insert(meshIndex).second) continue;
    scene_.warnings.push_back(path_ + ": mesh " + std::to_string(meshIndex) + " primitive " +
                              std::to_string(p) + " has " + std::to_string(targets) +
                              " morph targets and " + std::to_string(weights.size()) +
                              " weights (glTF asks one a target): " +
                              (targets < weights.size() ? "the extra weights are left out"
                                                        : "the targets without one weigh 0"));
  }
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
    // Vertices this node's primitives already converted from the same
    // accessors are used again, not copied (vertexBlocks_).
    const VertexBlockKey key{world.m,
                             {sameValues(posAcc), sameValues(attr("NORMAL")),
                              sameValues(attr("TANGENT")), sameValues(attr("TEXCOORD_0")),
                              sameValues(attr("TEXCOORD_1")), sameValues(attr("COLOR_0"))}};
    // Morphed vertices are this node's own.
    const bool morphs = morphed && !prim.targets.empty();
    const auto converted = morphs ? vertexBlocks_.end() : vertexBlocks_.find(key);
    const bool shared = converted != vertexBlocks_.end();
    std::vector<double> pos, nrm, uv0, uv1, tan, color;
    size_t nverts = reader_.count(posAcc);
    if (!shared) {
      pos = reader_.read(posAcc, TINYGLTF_TYPE_VEC3, what + " POSITION");
      nverts = pos.size() / 3;
      auto readSameCount = [&](int acc, int type, const char* key) {
        std::vector<double> v = reader_.read(acc, type, what + " " + key);
        if (reader_.count(acc) != nverts) {
          fail(path_, what + ": " + key + " has " + std::to_string(reader_.count(acc)) +
                          " elements, POSITION has " + std::to_string(nverts));
        }
        return v;
      };
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
        const int type =
            acc < model_.accessors.size() && model_.accessors[acc].type == TINYGLTF_TYPE_VEC3
                ? TINYGLTF_TYPE_VEC3
                : TINYGLTF_TYPE_VEC4;
        color = readSameCount(attr("COLOR_0"), type, "COLOR_0");
      }
      if (morphs) morph(prim, weights, what, nverts, pos, nrm);
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
    // glTF asks triangles for a multiple of three: the loader reads the
    // whole triangles and says what it left out (35 indices lost 2 silently).
    if (mode == TINYGLTF_MODE_TRIANGLES && idx.size() % 3 != 0) {
      scene_.warnings.push_back(path_ + ": " + what + ": " + std::to_string(idx.size()) +
                                (prim.indices >= 0 ? " indices" : " vertices") +
                                " are not a whole number of triangles: the last " +
                                std::to_string(idx.size() % 3) + " are left out");
    }

    int material = prim.material;
    if (material < 0)
      material = defaultMaterial();
    else if (size_t(material) >= model_.materials.size())
      fail(path_, what + ": material index " + std::to_string(material) + " out of range");

    warnMissingUvSets(
        material, [&](int set) { return attr(set == 0 ? "TEXCOORD_0" : "TEXCOORD_1") >= 0; }, what);
    uint32_t base = shared ? converted->second : uint32_t(scene_.positions.size());
    if (!shared) {
      if (uint64_t(base) + nverts > std::numeric_limits<uint32_t>::max()) {
        fail(path_, "too many vertices for 32-bit indices");
      }
      checkVertexBudget(nverts);
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
      appendNormals(nrm, normalMatrix, nverts, base);
      appendUv(scene_.texcoords0, hasUv0_, uv0, nverts, base);
      appendUv(scene_.texcoords1, hasUv1_, uv1, nverts, base);
      appendTangents(tan, world, nverts, base, flip);
      appendColors(color, nverts, base, what);
      if (!morphs) vertexBlocks_.emplace(key, base);
    }

    for (auto& t : tris) {
      if (flip) std::swap(t[1], t[2]);
      for (uint32_t i : t) scene_.indices.push_back(base + i);
      scene_.triangleMaterial.push_back(material);
    }
  }
}

std::vector<std::array<uint32_t, 3>> SceneBuilder::triangulate(const std::vector<uint32_t>& idx,
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

void SceneBuilder::appendNormals(const std::vector<double>& nrm, const Mat4& normalMatrix,
                                 size_t nverts, uint32_t base) {
  if (nrm.empty() && !hasNormals_) {
    return;  // still no normals anywhere: Scene::normals stays empty
  }
  if (!hasNormals_) {
    // The first primitive with normals: earlier primitives get their
    // (area-weighted) vertex normals from their faces.
    hasNormals_ = true;
    scene_.normals.assign(base, Vec3{});
    normalFromFaces_.assign(base, 1);
  }
  if (!nrm.empty()) {
    for (size_t v = 0; v < nverts; ++v) {
      Vec3 n = normalize(
          normalMatrix.vector({float(nrm[3 * v]), float(nrm[3 * v + 1]), float(nrm[3 * v + 2])}));
      if (!isFinite(n)) fail(path_, "non-finite vertex normal");
      scene_.normals.push_back(n);
    }
    normalFromFaces_.resize(normalFromFaces_.size() + nverts, 0);
  } else {
    scene_.normals.resize(scene_.normals.size() + nverts, Vec3{});
    normalFromFaces_.resize(normalFromFaces_.size() + nverts, 1);
  }
}

void SceneBuilder::appendUv(std::vector<float>& dst, bool& has, const std::vector<double>& uv,
                            size_t nverts, uint32_t base) {
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

bool SceneBuilder::optionalAttribute(std::vector<float>& dst, bool& seen, bool present,
                                     uint32_t base, size_t nverts, size_t width, float fill) {
  if (!present && !seen) return false;
  if (!seen) {
    seen = true;
    dst.assign(width * size_t(base), fill);
  }
  if (!present) dst.resize(dst.size() + width * nverts, fill);
  return present;
}

void SceneBuilder::appendTangents(const std::vector<double>& tan, const Mat4& world, size_t nverts,
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

void SceneBuilder::appendColors(const std::vector<double>& color, size_t nverts, uint32_t base,
                                const std::string& what) {
  if (!optionalAttribute(scene_.colors, hasColors_, !color.empty(), base, nverts, 4, 1.0f)) {
    return;
  }
  const size_t channels = color.size() / nverts;  // 3 or 4
  size_t outside = 0;
  double lowest = 0, highest = 1;
  for (size_t v = 0; v < nverts; ++v) {
    for (size_t a = 0; a < 4; ++a) {
      const double c = a < channels ? color[channels * v + a] : 1.0;
      if (!std::isfinite(c)) fail(path_, what + ": non-finite vertex colour (COLOR_0)");
      if (c < 0 || c > 1) ++outside;
      lowest = std::min(lowest, c);
      highest = std::max(highest, c);
      scene_.colors.push_back(float(std::clamp(c, 0.0, 1.0)));
    }
  }
  // Clamped as a base colour factor out of range is, and said as it is
  // (H16-4-3: a COLOR_0 of 100 drew as 1 without a word).
  if (outside > 0) {
    scene_.warnings.push_back(path_ + ": " + what + ": " + std::to_string(outside) +
                              " vertex colour channel(s) (COLOR_0) outside [0, 1], from " +
                              formatNumber(lowest) + " to " + formatNumber(highest) +
                              ": clamped to [0, 1]");
  }
}

void SceneBuilder::finishVertexAttributes() {
  LO_CHECK(!hasNormals_ || scene_.normals.size() == scene_.positions.size());
  if (!hasNormals_) return;
  LO_CHECK_EQ(normalFromFaces_.size(), scene_.positions.size());
  // The triangles' windings are final here (mirrored nodes flipped): their
  // cross products point to the front.
  for (size_t t = 0; t < scene_.triangleCount(); ++t) {
    const uint32_t* corner = &scene_.indices[3 * t];
    if (!normalFromFaces_[corner[0]] && !normalFromFaces_[corner[1]] &&
        !normalFromFaces_[corner[2]]) {
      continue;
    }
    const Vec3& a = scene_.positions[corner[0]];
    const Vec3 n = cross(scene_.positions[corner[1]] - a, scene_.positions[corner[2]] - a);
    for (int k = 0; k < 3; ++k)
      if (normalFromFaces_[corner[k]]) scene_.normals[corner[k]] += n;
  }
  for (size_t v = 0; v < normalFromFaces_.size(); ++v)
    if (normalFromFaces_[v]) scene_.normals[v] = normalize(scene_.normals[v]);
}

void SceneBuilder::checkVertexBudget(size_t nverts) {
  // What a vertex holds at most (position, normal, two UV sets, tangent,
  // colour: 72 bytes; the double position kept for the rebase: 24), as the
  // triangle budget counts (gltf_nodes.cpp).
  constexpr double kVertexBytes = 72 + 24;
  if (!availableMemory_) availableMemory_ = availableMemoryBytes();
  const double vertices = double(scene_.positions.size()) + double(nverts);
  if (*availableMemory_ > 0 && vertices * kVertexBytes > 0.5 * double(*availableMemory_)) {
    fail(path_, "the primitives make " + std::to_string(uint64_t(vertices)) +
                    " vertices of their own (" + formatBytes(size_t(vertices * kVertexBytes)) +
                    " to hold), beyond half the " + formatBytes(*availableMemory_) +
                    " of memory available (primitives that share a vertex buffer through the "
                    "same accessors share its vertices)");
  }
}

int SceneBuilder::sameValues(int index) {
  if (index < 0 || size_t(index) >= model_.accessors.size()) return index;
  if (sameValues_.empty()) sameValues_.assign(model_.accessors.size(), -2);
  int& known = sameValues_[size_t(index)];
  if (known != -2) return known;
  const tinygltf::Accessor& a = model_.accessors[size_t(index)];
  if (a.sparse.isSparse || a.bufferView < 0) return known = index;
  const std::array<size_t, 6> values{size_t(a.bufferView), a.byteOffset,   size_t(a.componentType),
                                     size_t(a.normalized), size_t(a.type), a.count};
  return known = accessorValues_.emplace(values, index).first->second;
}

}  // namespace lo::scene_internal::gltf_internal
