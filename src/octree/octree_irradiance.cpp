#include "octree/octree_irradiance.h"

#include <algorithm>
#include <cmath>

namespace lo {
namespace octree_irradiance_internal {

/// The leaf of voxel c (lookupLeaf in the shader), through the C++ descent.
bool leafAt(const GpuOctree& octree, int cx, int cy, int cz, float voxelSize,
            OctreeSample& sample) {
  const int res = 1 << octree.depth;
  if (cx < 0 || cy < 0 || cz < 0 || cx >= res || cy >= res || cz >= res) return false;
  const Vec3 centre =
      octree.origin + Vec3{float(cx) + 0.5f, float(cy) + 0.5f, float(cz) + 0.5f} * voxelSize;
  sample = lookupOctree(octree, centre);
  return sample.found;
}

/// shadeLeaf in the shader with brdfCos -> max(0, n . d).
Vec3 shadeLeaf(const OctreeSample& sample, const Vec3& n, int maxVdls) {
  Vec3 sum{0, 0, 0};
  const int count = std::min(sample.vdlCount, maxVdls);
  for (int i = 0; i < count; ++i) {
    sum += sample.vdls[i].irradiance * std::max(0.0f, dot(n, sample.vdls[i].direction));
  }
  return sum;
}

}  // namespace octree_irradiance_internal

Vec3 octreeIrradiance(const GpuOctree& octree, const Vec3& position, const Vec3& normal,
                      const OctreeShadeParams& params) {
  using namespace octree_irradiance_internal;
  if (octree.depth < 1 || octree.pool.empty()) return {0, 0, 0};
  const float voxelSize = octree.cubeSize / float(1 << octree.depth);
  const Vec3 q = (position - octree.origin) / voxelSize + normal * params.normalOffset;
  OctreeSample sample;
  if (params.interpolation) {
    const Vec3 u = q - Vec3{0.5f, 0.5f, 0.5f};
    const Vec3 base{std::floor(u.x), std::floor(u.y), std::floor(u.z)};
    const Vec3 f = u - base;
    Vec3 sum{0, 0, 0};
    float weightSum = 0;
    for (int k = 0; k < 8; ++k) {
      const int ox = k & 1, oy = (k >> 1) & 1, oz = (k >> 2) & 1;
      const float w = (ox ? f.x : 1 - f.x) * (oy ? f.y : 1 - f.y) * (oz ? f.z : 1 - f.z);
      if (w <= 0) continue;
      if (leafAt(octree, int(base.x) + ox, int(base.y) + oy, int(base.z) + oz, voxelSize, sample)) {
        sum += shadeLeaf(sample, normal, params.maxVdls) * w;
        weightSum += w;
      }
    }
    if (weightSum > 0) return sum / weightSum;
  }
  // nearestLeaf: the voxel in front of the surface, else the one behind it.
  const Vec3 front = q, back = q - normal * (2.0f * params.normalOffset);
  for (const Vec3& p : {front, back}) {
    if (leafAt(octree, int(std::floor(p.x)), int(std::floor(p.y)), int(std::floor(p.z)), voxelSize,
               sample)) {
      return shadeLeaf(sample, normal, params.maxVdls);
    }
  }
  return {0, 0, 0};
}

}  // namespace lo
