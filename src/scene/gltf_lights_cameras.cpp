/// @file scene/gltf_lights_cameras.cpp
/// @brief glTF perspective cameras and KHR_lights_punctual lights placed by
/// their nodes (SceneBuilder, gltf_internal.h).

#include "scene/gltf_internal.h"

#include <cmath>
#include <string>

#include "core/resources.h"

namespace lo::scene_internal::gltf_internal {

void SceneBuilder::addCamera(const tinygltf::Node& node, int nodeIndex, const Mat4& world) {
  if (size_t(node.camera) >= model_.cameras.size()) {
    fail(path_, "node " + std::to_string(nodeIndex) + ": camera index out of range");
  }
  const tinygltf::Camera& g = model_.cameras[size_t(node.camera)];
  const std::string name =
      !node.name.empty() ? node.name
                         : (!g.name.empty() ? g.name : "camera" + std::to_string(nodeIndex));
  if (g.type != "perspective") {
    // Orthographic cameras are left out (docs/scene.md), said so; one glTF
    // forbids (a magnification of 0) is refused, as a perspective one is
    // (H10-4-166: taken without a word).
    const double xmag = g.orthographic.xmag, ymag = g.orthographic.ymag;
    if (!(std::isfinite(xmag) && std::isfinite(ymag) && xmag != 0 && ymag != 0)) {
      fail(path_, "camera '" + name + "' on node " + std::to_string(nodeIndex) +
                      ": orthographic xmag " + formatNumber(xmag) + " and ymag " +
                      formatNumber(ymag) + " (glTF: finite and not zero)");
    }
    scene_.warnings.push_back(path_ + ": camera '" + name + "' on node " +
                              std::to_string(nodeIndex) +
                              " is orthographic, which lightoctree does not draw: left out");
    return;
  }
  Camera c;
  c.name = name;
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
  const double degrees = g.perspective.yfov * 180.0 / kPi;
  if (!kFovDegreesRange.contains(degrees)) {
    fail(path_, "camera '" + c.name + "' on node " + std::to_string(nodeIndex) + ": yfov " +
                    formatNumber(g.perspective.yfov) + " radians (" + formatNumber(degrees) +
                    " degrees): a field of view must be " + kFovDegreesRange.ToString() +
                    " degrees, as --fov");
  }
  if (lengthSquared(c.forward) == 0) {
    fail(path_, "camera '" + c.name + "' on node " + std::to_string(nodeIndex) +
                    " has a degenerate transform");
  }
  scene_.cameras.push_back(c);
}

void SceneBuilder::addLight(const tinygltf::Node& node, int nodeIndex, int lightIndex,
                            const Mat4& world) {
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

}  // namespace lo::scene_internal::gltf_internal
