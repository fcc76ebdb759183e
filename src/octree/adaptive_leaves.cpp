/// @file octree/adaptive_leaves.cpp
/// @brief Bottom-up collapse of siblings whose light agrees (adaptive_leaves.h).

#include "octree/adaptive_leaves.h"

#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "core/error.h"
#include "octree/gpu_octree.h"

namespace lo {

Vec3 vdlIntensity(const Vdl& vdl, const Vec3& normal, bool cosineCorrection) {
  if (!cosineCorrection || !(lengthSquared(normal) > 0.5f)) return vdl.irradiance;
  // The cosine with the direction the shader decodes, as buildGpuOctree divides by.
  const Vec3 d = normalize(vdl.direction);
  const float packed = layout::loPackDirection(d.x, d.y, d.z);
  const Vec3 dq{layout::loUnpackDirectionX(packed), layout::loUnpackDirectionY(packed),
                layout::loUnpackDirectionZ(packed)};
  return vdl.irradiance / std::max(std::fabs(dot(normalize(normal), dq)), kMinCorrectionCosine);
}

namespace adaptive_internal {

/// A node's light while collapsing: its texels (intensities or SH terms),
/// its weight, and the voxels below it that it must serve.
struct Node {
  std::vector<Vdl> vdls;  ///< intensities, as stored
  std::vector<Vec3> sh;
  /// Its surface texel's (GpuOctree::surfaceTexels): the weighted mean
  /// reflectance and the unit weighted mean normal of its voxels.
  Vec3 reflectance{0, 0, 0}, normal{0, 0, 0};
  double weight = 0;
  std::vector<uint32_t> voxels;
};

/// Irradiance of a leaf's light texels alone at normal n.
Vec3 lightAt(const Node& node, const Vec3& n) {
  Vec3 e{0, 0, 0};
  if (!node.sh.empty()) {
    for (size_t i = 0; i < node.sh.size(); ++i) {
      e += node.sh[i] * layout::loShBasis(uint32_t(i), n.x, n.y, n.z);
    }
    return Vec3{std::max(0.0f, e.x), std::max(0.0f, e.y), std::max(0.0f, e.z)};
  }
  for (const Vdl& v : node.vdls) e += v.irradiance * std::max(0.0f, dot(n, v.direction));
  return e;
}

/// Irradiance of a leaf at normal n, as the shader computes it: its light,
/// and what its surface reflects from below its plane (loSurfaceBelow).
Vec3 irradianceAt(const Node& node, const Vec3& n) {
  const float below = 0.5f * (1.0f - std::fabs(dot(n, node.normal)));
  if (!(maxComponent(node.reflectance) > 0) || !(below > 0)) return lightAt(node, n);
  return lightAt(node, n) + node.reflectance * lightAt(node, node.normal) * below;
}

float brightest(const Vec3& e) { return std::max({e.x, e.y, e.z}); }

/// Reduces directional lights to at most `count`: repeatedly the two whose
/// directions lie closest (ties: the lower indices) become one, intensity
/// summed, direction the luminance-weighted mean; strongest first at the end.
/// Deterministic; n <= 8 children x 8 VDLs, so the O(n^3) search is cheap.
std::vector<Vdl> mergeVdls(std::vector<Vdl> vdls, size_t count) {
  while (vdls.size() > count) {
    size_t a = 0, b = 1;
    float best = -2;
    for (size_t i = 0; i < vdls.size(); ++i) {
      for (size_t j = i + 1; j < vdls.size(); ++j) {
        const float c = dot(vdls[i].direction, vdls[j].direction);
        if (c > best) {
          best = c;
          a = i;
          b = j;
        }
      }
    }
    const float wa = luminance(vdls[a].irradiance), wb = luminance(vdls[b].irradiance);
    const Vec3 d = vdls[a].direction * wa + vdls[b].direction * wb;
    vdls[a].irradiance += vdls[b].irradiance;
    if (lengthSquared(d) > 0) vdls[a].direction = normalize(d);
    vdls.erase(vdls.begin() + std::ptrdiff_t(b));
  }
  std::stable_sort(vdls.begin(), vdls.end(), [](const Vdl& x, const Vdl& y) {
    return luminance(x.irradiance) > luminance(y.irradiance);
  });
  return vdls;
}

}  // namespace adaptive_internal

AdaptiveLeaves collapseLeaves(const VdlGrid& grid, float tolerance, bool cosineCorrection) {
  using namespace adaptive_internal;
  if (!(tolerance >= 0) || !std::isfinite(tolerance)) {
    throw InputError("adaptive leaves: tolerance " + std::to_string(tolerance) +
                     " must be finite and >= 0");
  }
  const size_t n = grid.size();
  AdaptiveLeaves out;
  out.collapsed.assign(n, 0);
  if (tolerance == 0 || n == 0) return out;
  const int depth = grid.frame.depth;
  const bool sh = grid.shTerms > 0;

  std::vector<char> layered(n, 0);
  for (uint32_t v : grid.layers.voxel) layered[v] = 1;
  // Each voxel's own leaf, and what it must keep: its irradiance at its normal.
  std::vector<Vec3> own(n, Vec3{0, 0, 0});
  std::vector<Vec3> unitNormal(n, Vec3{0, 0, 0});
  double meanBrightest = 0;
  size_t lit = 0;
  std::map<uint64_t, Node> level;  // nodes of the current level by packed coordinate
  auto pack = [](const Coord& c) {
    return (uint64_t(uint32_t(c.x)) << 42) | (uint64_t(uint32_t(c.y)) << 21) | uint64_t(uint32_t(c.z));
  };
  auto unpack = [](uint64_t k) {
    return Coord{int((k >> 42) & 0x1fffff), int((k >> 21) & 0x1fffff), int(k & 0x1fffff)};
  };
  std::map<uint64_t, char> blocked;  // parents that cannot collapse (a child that cannot)
  for (size_t v = 0; v < n; ++v) {
    // A voxel of the grid that is not plain light (dark, layered, without a
    // normal) keeps its parent from collapsing over it.
    const Coord parent{grid.coords[v].x >> 1, grid.coords[v].y >> 1, grid.coords[v].z >> 1};
    const bool normal = lengthSquared(grid.normals[v]) > 0.5f;
    if (!grid.lit(v) || layered[v] || !normal) {
      blocked[pack(parent)] = 1;
      continue;
    }
    Node node;
    unitNormal[v] = normalize(grid.normals[v]);
    if (sh) {
      node.sh.assign(grid.shOf(v), grid.shOf(v) + grid.shTerms);
    } else {
      for (int i = 0; i < grid.vdlCount[v]; ++i) {
        Vdl t = grid.vdlsOf(v)[i];
        t.irradiance = vdlIntensity(t, grid.normals[v], cosineCorrection);
        t.direction = normalize(t.direction);
        node.vdls.push_back(t);
      }
    }
    node.weight = grid.areas.size() == n && grid.areas[v] > 0 ? double(grid.areas[v]) : 1.0;
    node.normal = unitNormal[v];
    if (grid.reflectance.size() == n) node.reflectance = storedReflectance(grid.reflectance[v]);
    node.voxels.push_back(uint32_t(v));
    own[v] = irradianceAt(node, unitNormal[v]);
    meanBrightest += double(brightest(own[v]));
    ++lit;
    level.emplace(pack(grid.coords[v]), std::move(node));
  }
  if (lit == 0) return out;
  const float floor = kAdaptiveFloorShare * float(meanBrightest / double(lit));

  for (int l = depth - 1; l >= 1; --l) {
    // Children grouped by parent, in coordinate order (std::map: deterministic).
    std::map<uint64_t, std::vector<Node*>> families;
    for (auto& [key, node] : level) {
      const Coord c = unpack(key);
      families[pack(Coord{c.x >> 1, c.y >> 1, c.z >> 1})].push_back(&node);
    }
    std::map<uint64_t, Node> next;
    std::map<uint64_t, char> nextBlocked;
    for (auto& [parentKey, children] : families) {
      const Coord parent = unpack(parentKey);
      const uint64_t grandKey = pack(Coord{parent.x >> 1, parent.y >> 1, parent.z >> 1});
      bool ok = !blocked.count(parentKey);
      size_t slots = 0;
      for (const Node* c : children) slots = std::max(slots, c->vdls.size());
      Node merged;
      if (ok) {
        double weight = 0;
        for (const Node* c : children) weight += c->weight;
        if (sh) {
          merged.sh.assign(size_t(grid.shTerms), Vec3{0, 0, 0});
          for (const Node* c : children) {
            for (size_t i = 0; i < merged.sh.size(); ++i) {
              merged.sh[i] += c->sh[i] * float(c->weight / weight);
            }
          }
        } else {
          std::vector<Vdl> pool;
          for (const Node* c : children) {
            for (const Vdl& t : c->vdls) {
              pool.push_back({t.irradiance * float(c->weight / weight), t.direction});
            }
          }
          merged.vdls = mergeVdls(std::move(pool), slots);
        }
        merged.weight = weight;
        Vec3 normalSum{0, 0, 0};
        for (const Node* c : children) {
          merged.reflectance += c->reflectance * float(c->weight / weight);
          normalSum += c->normal * float(c->weight);
        }
        merged.normal = lengthSquared(normalSum) > 0 ? normalize(normalSum) : Vec3{0, 0, 0};
        for (const Node* c : children) {
          merged.voxels.insert(merged.voxels.end(), c->voxels.begin(), c->voxels.end());
        }
        for (uint32_t v : merged.voxels) {
          const Vec3 e = irradianceAt(merged, unitNormal[v]);
          const float scale = tolerance * std::max(brightest(own[v]), floor);
          const Vec3 d = e - own[v];
          if (!(std::max({std::fabs(d.x), std::fabs(d.y), std::fabs(d.z)}) <= scale)) {
            ok = false;
            break;
          }
        }
      }
      if (ok) {
        next.emplace(parentKey, std::move(merged));
      } else {
        nextBlocked[grandKey] = 1;
        // The children stay leaves: those that are collapsed nodes (above the
        // grid's depth) become collapsed leaves now.
        for (Node* c : children) {
          if (l + 1 == depth) continue;  // voxels of the grid: leaves of their own
          CollapsedLeaf leaf;
          const Coord first = grid.coords[c->voxels[0]];
          const int shift = depth - (l + 1);
          leaf.coord = Coord{first.x >> shift, first.y >> shift, first.z >> shift};
          leaf.level = l + 1;
          leaf.vdls = c->vdls;
          leaf.sh = c->sh;
          leaf.reflectance = c->reflectance;
          leaf.normal = c->normal;
          for (uint32_t v : c->voxels) out.collapsed[v] = 1;
          out.voxelsCollapsed += c->voxels.size();
          out.leaves.push_back(std::move(leaf));
        }
      }
    }
    for (const auto& [key, flag] : blocked) {
      if (!families.count(key)) nextBlocked[pack(Coord{unpack(key).x >> 1, unpack(key).y >> 1,
                                                       unpack(key).z >> 1})] = flag;
    }
    level = std::move(next);
    blocked = std::move(nextBlocked);
  }
  // Nodes that collapsed all the way to level 1 are leaves there.
  for (auto& [key, node] : level) {
    CollapsedLeaf leaf;
    leaf.coord = unpack(key);
    leaf.level = 1;
    leaf.vdls = node.vdls;
    leaf.sh = node.sh;
    leaf.reflectance = node.reflectance;
    leaf.normal = node.normal;
    for (uint32_t v : node.voxels) out.collapsed[v] = 1;
    out.voxelsCollapsed += node.voxels.size();
    out.leaves.push_back(std::move(leaf));
  }
  return out;
}

}  // namespace lo
