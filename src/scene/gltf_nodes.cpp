/// @file scene/gltf_nodes.cpp
/// @brief The glTF node tree (SceneBuilder, gltf_internal.h): the scene's
/// roots, the triangle budget checked before anything is built, the
/// traversal into world space, and region-of-interest markers.

#include "scene/gltf_internal.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "core/printable.h"
#include "core/resources.h"

namespace lo::scene_internal::gltf_internal {

namespace {

Mat4 nodeLocalTransform(const tinygltf::Node& node) {
  return localTransform(node.matrix, node.translation, node.rotation, node.scale);
}

}  // namespace

std::vector<int> SceneBuilder::sceneRoots() const {
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

void SceneBuilder::checkTriangleBudget() {
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
  const std::string problem = triangleBudgetProblem(triangles);
  if (!problem.empty()) fail(path_, "the node tree makes " + problem);
}

void SceneBuilder::traverse() {
  checkTriangleBudget();
  struct Item {
    int node;
    Mat4 parent;
    size_t depth;
  };
  std::vector<Item> stack;
  std::vector<int> roots = sceneRoots();
  for (auto r = roots.rbegin(); r != roots.rend(); ++r) stack.push_back({*r, Mat4{}, 0});
  std::vector<char> seen(model_.nodes.size(), 0);
  while (!stack.empty()) {
    Item item = stack.back();
    stack.pop_back();
    if (item.node < 0 || size_t(item.node) >= model_.nodes.size()) {
      fail(path_, "node index " + std::to_string(item.node) + " out of range");
    }
    // A valid glTF node tree visits each node once; a cycle or a shared
    // child would never end or multiply the geometry. The node reached a
    // second time is the one named (the count of visits named a later one).
    if (seen[size_t(item.node)]++) {
      const std::string& name = model_.nodes[size_t(item.node)].name;
      fail(path_, "the node hierarchy is not a tree: node " + std::to_string(item.node) +
                      (name.empty() ? "" : " ('" + printableShort(name) + "')") +
                      " is reached twice (a child of two nodes, of a node and the scene, or "
                      "in a cycle)");
    }
    const tinygltf::Node& node = model_.nodes[size_t(item.node)];
    checkAffine(node, item.node);
    Mat4 world = item.parent * nodeLocalTransform(node);
    for (double v : world.m)
      if (!std::isfinite(v))
        fail(path_, "node " + std::to_string(item.node) + " has a non-finite transform");
    if (isRegionMarker(node, item.node)) {
      addRegion(node, item.node, world);
    } else if (node.mesh >= 0) {
      addMesh(node.mesh, world, &node.weights);
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

void SceneBuilder::checkAffine(const tinygltf::Node& node, int nodeIndex) const {
  // Column-major: the bottom row is elements 3, 7, 11 and 15. glTF asks a
  // matrix decomposable to translation, rotation and scale; a projective one
  // (bottom row not 0, 0, 0, 1) had its bottom row dropped without a word.
  const std::vector<double>& m = node.matrix;
  if (m.size() != 16) return;
  const double tolerance = 1e-6;
  if (std::fabs(m[3]) <= tolerance && std::fabs(m[7]) <= tolerance &&
      std::fabs(m[11]) <= tolerance && std::fabs(m[15] - 1.0) <= tolerance) {
    return;
  }
  fail(path_, "node " + std::to_string(nodeIndex) +
                  (node.name.empty() ? std::string() : " '" + printable(node.name) + "'") +
                  ": matrix has the bottom row (" + formatNumber(m[3]) + ", " + formatNumber(m[7]) +
                  ", " + formatNumber(m[11]) + ", " + formatNumber(m[15]) +
                  "), expected (0, 0, 0, 1): a projective matrix, which glTF forbids (a node's "
                  "matrix is translation, rotation and scale)");
}

bool SceneBuilder::isRegionMarker(const tinygltf::Node& node, int nodeIndex) const {
  if (!node.extras.IsObject() || !node.extras.Has("lightoctree_region")) return false;
  const tinygltf::Value& v = node.extras.Get("lightoctree_region");
  if (!v.IsBool()) {
    fail(path_, "node " + std::to_string(nodeIndex) +
                    ": extras.lightoctree_region must be true or false");
  }
  return v.Get<bool>();
}

void SceneBuilder::addRegion(const tinygltf::Node& node, int nodeIndex, const Mat4& world) {
  if (node.mesh < 0) {
    fail(path_, "node " + std::to_string(nodeIndex) +
                    " marks the region of interest (extras.lightoctree_region) but has no "
                    "mesh: give it a box mesh spanning the region");
  }
  Scene& sc = scene_;
  const size_t positions = sc.positions.size(), normals = sc.normals.size(),
               uv0 = sc.texcoords0.size(), uv1 = sc.texcoords1.size(),
               tangents = sc.tangents.size(), colors = sc.colors.size(),
               indices = sc.indices.size(), materials = sc.triangleMaterial.size(),
               fromFaces = normalFromFaces_.size();
  const bool hadNormals = hasNormals_, hadUv0 = hasUv0_, hadUv1 = hasUv1_,
             hadTangents = hasTangents_, hadColors = hasColors_;
  // The marker's vertices are its own: none shared with the geometry's,
  // none left for the geometry to share.
  std::map<VertexBlockKey, uint32_t> blocks;
  blocks.swap(vertexBlocks_);
  addMesh(node.mesh, world);
  blocks.swap(vertexBlocks_);
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
  normalFromFaces_.resize(fromFaces);
  hasNormals_ = hadNormals;
  hasUv0_ = hadUv0;
  hasUv1_ = hadUv1;
  hasTangents_ = hadTangents;
  hasColors_ = hadColors;
  sc.indices.resize(indices);
  sc.triangleMaterial.resize(materials);
}

}  // namespace lo::scene_internal::gltf_internal
