/// @file octree/collapse_volume.cpp
/// @brief The free-space octree's adaptive leaves (buildVolumeOctree,
/// GpuOctreeParams::volumeTolerance): collapseVolume, gpu_octree_internal.h.

#include "octree/gpu_octree_internal.h"

#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace lo::gpu_octree_internal {

using namespace layout;

/// A lit box this near a face reaches it (cluster/volume_light.cpp keeps the
/// same rule).
constexpr float kVolumeFaceTolerance = 1e-6f;

AdaptiveLeaves collapseVolume(const VolumeLight& v, float tolerance) {
  AdaptiveLeaves out;
  const size_t n = v.size();
  out.collapsed.assign(n, 0);
  if (!(tolerance > 0) || n == 0) return out;
  const int terms = v.shTerms;
  struct Node {
    std::vector<Vec3> sh;
    Vec3 lower{0, 0, 0}, upper{1, 1, 1};  ///< its lit box, node units
  };
  auto pack = [](const Coord& c) {
    return (uint64_t(uint32_t(c.x)) << 42) | (uint64_t(uint32_t(c.y)) << 21) | uint64_t(uint32_t(c.z));
  };
  auto unpack = [](uint64_t k) {
    return Coord{int((k >> 42) & 0x1fffff), int((k >> 21) & 0x1fffff), int(k & 0x1fffff)};
  };
  std::map<uint64_t, Node> level;
  std::map<std::pair<int, uint64_t>, CollapsedLeaf> merged;  ///< by (level, node)
  for (size_t k = 0; k < n; ++k) {
    Node node;
    node.sh.assign(v.shOf(k), v.shOf(k) + terms);
    node.lower = v.litLower[k];
    node.upper = v.litUpper[k];
    level[pack(v.coords[k])] = std::move(node);
  }
  Vec3 normals[14];
  int m = 0;
  for (int a = 0; a < 3; ++a) {
    Vec3 e{0, 0, 0};
    e[a] = 1;
    normals[m++] = e;
    normals[m++] = -e;
  }
  for (int s = 0; s < 8; ++s) {
    normals[m++] = normalize(Vec3{s & 1 ? 1.0f : -1.0f, s & 2 ? 1.0f : -1.0f, s & 4 ? 1.0f : -1.0f});
  }
  auto irradiance = [terms](const std::vector<Vec3>& sh, const Vec3& d) {
    float e = 0;
    for (int i = 0; i < terms; ++i) e += luminance(sh[size_t(i)]) * loShBasis(uint(i), d.x, d.y, d.z);
    return e;
  };
  for (int l = v.frame.depth - 1; l >= 1; --l) {
    std::map<uint64_t, std::vector<uint64_t>> parents;
    for (const auto& [key, node] : level) {
      const Coord c = unpack(key);
      parents[pack(Coord{c.x >> 1, c.y >> 1, c.z >> 1})].push_back(key);
    }
    std::map<uint64_t, Node> next;
    for (const auto& [parent, children] : parents) {
      bool merge = children.size() == 8;
      Node joined;
      joined.lower = Vec3{1, 1, 1};
      joined.upper = Vec3{0, 0, 0};
      // A child's light may stop short of its faces on the parent's outside
      // only (a wall along the parent's side), never inside the parent: the
      // parent's box is then the children's together.
      for (uint64_t k : children) {
        if (!merge) break;
        const Node& child = level[k];
        const int o[3] = {int((k >> 42) & 1), int((k >> 21) & 1), int(k & 1)};
        for (int a = 0; a < 3; ++a) {
          const bool inner = o[a] == 0 ? child.upper[a] >= 1.0f - kVolumeFaceTolerance
                                       : child.lower[a] <= kVolumeFaceTolerance;
          merge = merge && inner;
          joined.lower[a] = std::min(joined.lower[a], (float(o[a]) + child.lower[a]) * 0.5f);
          joined.upper[a] = std::max(joined.upper[a], (float(o[a]) + child.upper[a]) * 0.5f);
        }
      }
      if (merge) {
        joined.sh.assign(size_t(terms), Vec3{0, 0, 0});
        for (uint64_t k : children) {
          for (int i = 0; i < terms; ++i) joined.sh[size_t(i)] += level[k].sh[size_t(i)] * 0.125f;
        }
        float mean = 0;
        for (const Vec3& d : normals) mean += irradiance(joined.sh, d) / 14.0f;
        for (uint64_t k : children) {
          for (const Vec3& d : normals) {
            if (!(std::fabs(irradiance(level[k].sh, d) - irradiance(joined.sh, d)) <= tolerance * mean)) {
              merge = false;
            }
          }
        }
      }
      if (merge) next[parent] = std::move(joined);
    }
    if (next.empty()) break;
    // Merged nodes go up a level and may merge again; the others stay.
    for (auto& [parent, node] : next) {
      CollapsedLeaf leaf;
      leaf.coord = unpack(parent);
      leaf.level = l;
      leaf.sh = node.sh;
      leaf.litLower = node.lower;
      leaf.litUpper = node.upper;
      merged[std::make_pair(l, parent)] = std::move(leaf);
    }
    level = std::move(next);
  }
  // Only the topmost merge of each branch is a leaf.
  const int depth = v.frame.depth;
  auto ancestorMerged = [&](const Coord& c, int fromLevel, int belowLevel) {
    for (int l = 1; l < belowLevel; ++l) {
      const int shift = fromLevel - l;
      if (merged.count({l, pack(Coord{c.x >> shift, c.y >> shift, c.z >> shift})})) return true;
    }
    return false;
  };
  for (auto& [key, leaf] : merged) {
    if (!ancestorMerged(leaf.coord, leaf.level, leaf.level)) out.leaves.push_back(std::move(leaf));
  }
  for (size_t k = 0; k < n; ++k) {
    if (ancestorMerged(v.coords[k], depth, depth)) {
      out.collapsed[k] = 1;
      ++out.voxelsCollapsed;
    }
  }
  return out;
}

}  // namespace lo::gpu_octree_internal
