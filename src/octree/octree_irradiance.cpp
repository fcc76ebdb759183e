// The C++ build of shaders/octree_lookup.h: the fragment shader's lookup,
// compiled against the texel arrays of a GpuOctree instead of GL textures.
// lookupOctree (gpu_octree.h) and octreeIrradiance (octree_irradiance.h) are
// thin wrappers of it, so the CPU figures (tests, the sweep) are the shader's.

#include "octree/octree_irradiance.h"

#include <glm/glm.hpp>
#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "octree/gpu_octree.h"

namespace lo {
namespace octree_lookup_internal {

/// Pool texel at p, or an empty texel outside the pool (GL returns zero for
/// out-of-range texelFetch on the implementations we target).
glm::uvec4 fetchPool(const GpuOctree& o, const glm::ivec3& p) {
  if (p.x < 0 || p.y < 0 || p.z < 0 || p.x >= o.poolWidth() || p.y >= o.poolHeight() ||
      p.z >= o.poolDepth()) {
    return glm::uvec4(0u);
  }
  const size_t i =
      ((size_t(p.z) * size_t(o.poolHeight()) + size_t(p.y)) * size_t(o.poolWidth()) + size_t(p.x)) *
      4;
  return {o.pool[i], o.pool[i + 1], o.pool[i + 2], o.pool[i + 3]};
}

size_t vdlOffset(const GpuOctree& o, const glm::ivec2& p) {
  return (size_t(p.y) * size_t(o.vdlWidth) + size_t(p.x)) * 4;
}

glm::vec4 fetchVdlFloat(const GpuOctree& o, const glm::ivec2& p) {
  const size_t i = vdlOffset(o, p);
  if (i + 4 > o.vdlTexels.size()) return glm::vec4(0.0f);
  return {o.vdlTexels[i], o.vdlTexels[i + 1], o.vdlTexels[i + 2], o.vdlTexels[i + 3]};
}

glm::uvec4 fetchVdlHalf(const GpuOctree& o, const glm::ivec2& p) {
  const size_t i = vdlOffset(o, p);
  if (i + 4 > o.vdlTexelsHalf.size()) return glm::uvec4(0u);
  return {o.vdlTexelsHalf[i], o.vdlTexelsHalf[i + 1], o.vdlTexelsHalf[i + 2],
          o.vdlTexelsHalf[i + 3]};
}

}  // namespace octree_lookup_internal
}  // namespace lo

#define LO_FETCH_POOL(p) ::lo::octree_lookup_internal::fetchPool(tex, p)
#define LO_FETCH_VDL_FLOAT(p) ::lo::octree_lookup_internal::fetchVdlFloat(tex, p)
#define LO_FETCH_VDL_HALF(p) ::lo::octree_lookup_internal::fetchVdlHalf(tex, p)
#define LO_VDLS_HALF tex.halfFloat
#define LO_VDLS_COMPACT tex.compact
#define LO_VDL_SCALE tex.irradianceScale
#define LO_SH_TERMS tex.shTerms
#define LO_SURFACE_TEXELS tex.surfaceTexels
#include <octree_lookup.h>

namespace lo {
namespace lookup {
/// E = sum_i c_i max(0, n . d_i): the shader's brdfCos with the BRDF left
/// out, i.e. irradiance (see octree_irradiance.h).
vec3 loVdlResponse(LoSurface s, vec3 d) { return vec3(max(0.0f, dot(s.n, d))); }
}  // namespace lookup

namespace {

glm::vec3 toGlm(const Vec3& v) { return {v.x, v.y, v.z}; }
Vec3 fromGlm(const glm::vec3& v) { return {v.x, v.y, v.z}; }

/// A white Lambertian surface facing `normal`: with the cosine as the
/// response, the lookup's value is the irradiance.
lookup::LoSurface irradianceSurface(const Vec3& normal) {
  lookup::LoSurface s;
  s.n = toGlm(normal);
  s.v = s.n;
  s.baseColor = glm::vec3(1.0f);
  s.metallic = 0.0f;
  s.roughness = 1.0f;
  s.ng = s.n;
  return s;
}

}  // namespace

OctreeSample lookupOctree(const GpuOctree& octree, const Vec3& worldPosition) {
  OctreeSample sample;
  if (octree.depth < 1 || octree.pool.empty()) return sample;
  // Normalized octree position; the comparisons are written so that NaN fails.
  const Vec3 u = (worldPosition - octree.origin) / octree.cubeSize;
  if (!(u.x >= 0.0f && u.x < 1.0f && u.y >= 0.0f && u.y < 1.0f && u.z >= 0.0f && u.z < 1.0f)) {
    return sample;
  }
  const int res = 1 << octree.depth;
  auto voxelOf = [res](float t) { return std::min(int(std::floor(t * float(res))), res - 1); };
  const Coord voxel{voxelOf(u.x), voxelOf(u.y), voxelOf(u.z)};
  glm::uvec4 leaf;
  if (!lookup::loLookupLeaf(octree, glm::ivec3(voxel.x, voxel.y, voxel.z), octree.depth, leaf)) {
    return sample;
  }
  sample.found = true;
  sample.voxel = voxel;
  uint32_t first = layout::loUnpackAddress(leaf.r, leaf.g, leaf.b);
  uint32_t count = leaf.a;
  if (leaf.a == layout::LO_FLAG_LAYERED) {
    // Layer 0: its VDLs follow the block header and its own header.
    const glm::vec4 h = lookup::loFetchTexel(octree, first);
    sample.layerCount = int(h.a);
    count = uint32_t(h.r);
    first += 2;
  }
  sample.vdlCount = int(count);
  for (uint32_t i = 0; i < count; ++i) {
    const glm::vec4 t = lookup::loFetchVdl(octree, first + i);
    sample.vdls[i].irradiance = {t.r, t.g, t.b};
    sample.vdls[i].direction = fromGlm(lookup::loVdlDirection(t.a));
  }
  return sample;
}

Vec3 octreeIrradiance(const GpuOctree& octree, const Vec3& position, const Vec3& normal,
                      const OctreeShadeParams& params) {
  if (octree.depth < 1 || octree.pool.empty()) return {0, 0, 0};
  const float voxelSize = octree.cubeSize / float(1 << octree.depth);
  const lookup::LoSurface s = irradianceSurface(normal);
  return fromGlm(lookup::loOctreeIndirect(octree, toGlm(position), toGlm(octree.origin), voxelSize,
                                          octree.depth, params.normalOffset, params.interpolation,
                                          params.maxVdls, s));
}

Vec3 volumeIrradiance(const GpuOctree& volume, const Vec3& position, const Vec3& normal) {
  if (volume.depth < 1 || volume.pool.empty()) return {0, 0, 0};
  const float voxelSize = volume.cubeSize / float(1 << volume.depth);
  return fromGlm(lookup::loVolumeIndirect(volume, toGlm(position), toGlm(volume.origin), voxelSize,
                                          volume.depth, irradianceSurface(normal)));
}

OctreeIrradianceSample octreeIrradianceSample(const GpuOctree& octree, const Vec3& position,
                                              const Vec3& normal, const OctreeShadeParams& params) {
  OctreeIrradianceSample out;
  if (octree.depth < 1 || octree.pool.empty()) return out;
  const float voxelSize = octree.cubeSize / float(1 << octree.depth);
  glm::vec3 direction;
  out.irradiance = fromGlm(lookup::loOctreeIrradiance(
      octree, toGlm(position), toGlm(normal), toGlm(octree.origin), voxelSize, octree.depth,
      params.normalOffset, params.interpolation, params.maxVdls, direction));
  out.directionSum = fromGlm(direction);
  return out;
}

}  // namespace lo
