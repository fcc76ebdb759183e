/// @file reference/light_tree.cpp
/// @brief The light tree of light_tree.h: built by median splits along the
/// longest axis of the lights' positions, walked from the root by the
/// children's importance bounds.

#include "reference/light_tree.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "material/bsdf.h"

namespace lo {

namespace light_tree_internal {

/// A light's weight: its intensity (W/sr, or W/m^2 for a directional light)
/// by its brightest channel; 0 for a light the path tracer skips.
float lightPower(const Light& light) {
  return light.intensity > 0 && maxComponent(light.color) > 0
             ? light.intensity * maxComponent(light.color)
             : 0.0f;
}

/// The largest u below 1 in double.
constexpr double kOneBelow = 1.0 - 0x1.0p-53;

}  // namespace light_tree_internal

using light_tree_internal::kOneBelow;
using light_tree_internal::lightPower;

LightTree::LightTree(const std::vector<Light>& lights) : lights_(&lights) {
  std::vector<uint32_t> positional;
  leafOf_.assign(lights.size(), -1);
  for (size_t i = 0; i < lights.size(); ++i) {
    const float power = lightPower(lights[i]);
    if (!(power > 0)) continue;
    if (lights[i].type == Light::Type::Directional) {
      directional_.push_back(uint32_t(i));
      directionalPick_.add(double(power));
    } else {
      positional.push_back(uint32_t(i));
    }
  }
  directionalTotal_ = directionalPick_.total();
  count_ = positional.size() + directional_.size();
  if (!positional.empty()) {
    nodes_.reserve(2 * positional.size() - 1);
    parent_.reserve(2 * positional.size() - 1);
    build(positional, 0, positional.size(), -1);
  }
}

int32_t LightTree::build(std::vector<uint32_t>& order, size_t begin, size_t end, int32_t parent) {
  const std::vector<Light>& lights = *lights_;
  const int32_t index = int32_t(nodes_.size());
  nodes_.emplace_back();
  parent_.push_back(parent);
  if (end - begin == 1) {
    Node& leaf = nodes_[size_t(index)];
    const Light& light = lights[order[begin]];
    leaf.lower = leaf.upper = light.position;
    leaf.power = lightPower(light);
    leaf.light = order[begin];
    leafOf_[order[begin]] = index;
    return index;
  }
  // The median along the longest axis of the positions, ties by index: the
  // halves are the same sets whatever order nth_element leaves them in, so
  // the tree is the same on every machine.
  Bounds3 box;
  for (size_t i = begin; i < end; ++i) box.extend(lights[order[i]].position);
  const Vec3 extent = box.upper - box.lower;
  const int axis =
      extent.x >= extent.y && extent.x >= extent.z ? 0 : (extent.y >= extent.z ? 1 : 2);
  const size_t mid = begin + (end - begin) / 2;
  std::nth_element(order.begin() + ptrdiff_t(begin), order.begin() + ptrdiff_t(mid),
                   order.begin() + ptrdiff_t(end), [&](uint32_t a, uint32_t b) {
                     const float ka = lights[a].position[axis], kb = lights[b].position[axis];
                     return ka != kb ? ka < kb : a < b;
                   });
  const int32_t first = build(order, begin, mid, index);
  const int32_t second = build(order, mid, end, index);
  Node& node = nodes_[size_t(index)];
  node.second = second;
  node.lower = min(nodes_[size_t(first)].lower, nodes_[size_t(second)].lower);
  node.upper = max(nodes_[size_t(first)].upper, nodes_[size_t(second)].upper);
  node.power = nodes_[size_t(first)].power + nodes_[size_t(second)].power;
  return index;
}

Vec3 punctualIrradiance(const Light& light, const Vec3& p, Vec3& wi, float& dist) {
  dist = std::numeric_limits<float>::infinity();
  if (light.type == Light::Type::Directional) {
    wi = -normalize(light.direction);
    return light.color * light.intensity;
  }
  const Vec3 d = light.position - p;
  dist = length(d);
  if (!(dist > 0)) return Vec3{0, 0, 0};
  wi = d / dist;
  float scale = rangeWindow(dist, light.range) / (dist * dist);
  if (light.type == Light::Type::Spot) {
    const float cosOuter = std::cos(light.outerConeAngle);
    const float cosInner = std::max(cosOuter, std::cos(light.innerConeAngle));
    scale *= spotFalloff(dot(-wi, normalize(light.direction)), cosInner, cosOuter);
  }
  return light.color * (light.intensity * scale);
}

float LightTree::importance(const Light& light, const Vec3& p, const Vec3& n) {
  if (!(lightPower(light) > 0)) return 0.0f;
  Vec3 wi;
  float dist = 0;
  const Vec3 irradiance = punctualIrradiance(light, p, wi, dist);
  return std::max(0.0f, maxComponent(irradiance)) * std::max(0.0f, dot(wi, n));
}

float LightTree::nodeImportance(int32_t index, const Vec3& p, const Vec3& n) const {
  const Node& node = nodes_[size_t(index)];
  if (node.second < 0) return importance((*lights_)[node.light], p, n);
  // The box's bounding sphere, a little larger than rounding could make it,
  // seen from p: every light of the node lies in it.
  const Vec3 centre = (node.lower + node.upper) * 0.5f;
  const Vec3 d = centre - p;
  const float dist2 = lengthSquared(d);
  const float dist = std::sqrt(dist2);
  const float radius = 0.5f * length(node.upper - node.lower) * 1.001f + 1e-6f * dist;
  float cosBound = 1.0f;
  if (dist > radius) {
    // The largest cosine with n over directions within the sphere's cone:
    // cos(max(0, angle(n, centre) - half angle of the cone)).
    const float sinCone = radius / dist;
    const float cosCone = std::sqrt(std::max(0.0f, 1.0f - sinCone * sinCone));
    const float cosine = dot(d, n) / dist;
    if (cosine < cosCone) {
      const float sine = std::sqrt(std::max(0.0f, 1.0f - cosine * cosine));
      cosBound = cosine * cosCone + sine * sinCone;
      if (!(cosBound > 0)) return 0.0f;
    }
  }
  return node.power * cosBound / std::max(dist2, radius * radius);
}

double LightTree::treeShare(const Vec3& p, const Vec3& n) const {
  if (nodes_.empty()) return 0.0;
  if (directional_.empty()) return 1.0;
  const double tree = double(nodeImportance(0, p, n));
  const double total = tree + directionalTotal_;
  return total > 0 ? tree / total : 0.0;
}

bool LightTree::sample(const Vec3& p, const Vec3& n, double u, uint32_t& light, float& pmf) const {
  if (empty()) return false;
  u = std::clamp(u, 0.0, kOneBelow);
  const double share = treeShare(p, n);
  double probability = 0;
  if (u >= share) {
    // The directional group (share < 1 only when it has lights).
    probability = 1.0 - share;
    u = std::min((u - share) / probability, kOneBelow);
    const size_t k = directionalPick_.sample(u);
    light = directional_[k];
    pmf = float(probability * directionalPick_.pmf(k));
    return pmf > 0;
  }
  probability = share;
  u = std::min(u / share, kOneBelow);
  int32_t node = 0;
  if (nodes_.size() == 1 && !(nodeImportance(0, p, n) > 0)) return false;
  while (nodes_[size_t(node)].second >= 0) {
    const int32_t first = node + 1, second = nodes_[size_t(node)].second;
    const double a = double(nodeImportance(first, p, n));
    const double b = double(nodeImportance(second, p, n));
    const double total = a + b;
    if (!(total > 0)) return false;
    const double pa = a / total;
    if (u < pa) {
      node = first;
      u = std::min(u / pa, kOneBelow);
      probability *= pa;
    } else {
      node = second;
      u = std::min((u - pa) / (1.0 - pa), kOneBelow);
      probability *= b / total;
    }
  }
  light = nodes_[size_t(node)].light;
  pmf = float(probability);
  return pmf > 0;
}

float LightTree::pmf(const Vec3& p, const Vec3& n, uint32_t light) const {
  if (light >= leafOf_.size()) return 0.0f;
  const double share = treeShare(p, n);
  if (leafOf_[light] < 0) {
    const auto it = std::find(directional_.begin(), directional_.end(), light);
    if (it == directional_.end()) return 0.0f;
    return float((1.0 - share) * directionalPick_.pmf(size_t(it - directional_.begin())));
  }
  int32_t node = leafOf_[light];
  if (nodes_.size() == 1) return nodeImportance(0, p, n) > 0 ? float(share) : 0.0f;
  double probability = share;
  while (parent_[size_t(node)] >= 0) {
    const int32_t parent = parent_[size_t(node)];
    const int32_t first = parent + 1, second = nodes_[size_t(parent)].second;
    const double a = double(nodeImportance(first, p, n));
    const double b = double(nodeImportance(second, p, n));
    const double total = a + b;
    if (!(total > 0)) return 0.0f;
    probability *= (node == first ? a : b) / total;
    node = parent;
  }
  return float(probability);
}

}  // namespace lo
