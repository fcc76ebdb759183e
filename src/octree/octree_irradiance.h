#pragma once
/// @file octree/octree_irradiance.h
/// @brief The light octree's indirect irradiance at a surface point, in C++:
///   E(p, n) = sum_i c_i max(0, n . d_i)          (W/m^2)
/// over the VDLs (c_i, d_i) of the voxel under p, i.e. the fragment shader's
/// indirect() (shaders/render_scene.frag) with the BRDF times cosine replaced
/// by the cosine alone: the same normal offset, the same trilinear
/// interpolation over the 8 surrounding voxels with empty ones left out and
/// the weights renormalized, the same fallback to the voxel behind. For a
/// Lambertian surface of albedo a, the shader's radiance is a / pi * E.
/// This is the quantity the reference's ReferencePart::Irradiance estimates.

#include "core/math.h"
#include "octree/gpu_octree.h"

namespace lo {

struct OctreeShadeParams {
  bool interpolation = true;   ///< trilinear over the 8 neighbouring voxels (paper §4.2.1)
  int maxVdls = kMaxVdls;      ///< VDLs used per voxel, the strongest first
  float normalOffset = 0.01f;  ///< voxel sizes along n (RenderParams::normalOffset)
};

/// E(p, n) as above. `position` in world space, `normal` unit. Zero where no
/// voxel is found (empty space, outside the cube).
Vec3 octreeIrradiance(const GpuOctree& octree, const Vec3& position, const Vec3& normal,
                      const OctreeShadeParams& params = {});

/// E(p, n) of a surface that was not baked, from the free-space octree
/// (buildVolumeOctree): shaders/octree_lookup.h's loVolumeIndirect with the
/// cosine as the response. Zero where no lit voxel lends its light.
Vec3 volumeIrradiance(const GpuOctree& volume, const Vec3& position, const Vec3& normal);

/// E(p, n) and the direction it comes from, for a directional lightmap
/// (paper §4.2.3: one VDL per texel rebuilt for the specular term).
struct OctreeIrradianceSample {
  Vec3 irradiance{0, 0, 0};  ///< E(p, n), W/m^2: octreeIrradiance's value
  /// sum_i Y(c_i) max(0, n . d_i) d_i (Y = Rec. 709 luminance) over the same
  /// VDLs with the same interpolation weights as E: the luminance-weighted
  /// VDL direction sum, world space, towards the light. Its length is at
  /// most Y(E), equal when every contributing VDL has one direction; zero
  /// where nothing lights the point.
  Vec3 directionSum{0, 0, 0};
};

/// E(p, n) as octreeIrradiance, and the luminance-weighted direction sum:
/// shaders/octree_lookup.h's loOctreeIrradiance, the function the GPU's
/// lightmap bake (shaders/atlas_bake.frag) runs too; a test holds its E to
/// octreeIrradiance's.
OctreeIrradianceSample octreeIrradianceSample(const GpuOctree& octree, const Vec3& position,
                                              const Vec3& normal,
                                              const OctreeShadeParams& params = {});

}  // namespace lo
