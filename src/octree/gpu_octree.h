#pragma once
/// @file octree/gpu_octree.h
/// @brief The GPU light octree (paper §4.2.1): the VDL grid converted into a
/// texture stack, an RGBA8UI indirection pool of 2x2x2 node tiles plus a 2D
/// float VDL texture. The texel layout is defined once, for C++ and GLSL, in
/// shaders/octree_layout.h. No GL here: plain arrays the renderer uploads.

#include <cstdint>
#include <string>
#include <vector>

#include "lightgrid/vdl_grid.h"
#include "core/math.h"

namespace lo {

struct GpuOctreeParams {
  bool halfFloat = false;        ///< VDL texels as RGBA16UI (half RGB bits) instead of RGBA32F
  /// Compact VDL texels (8 bytes, in the RGBA16UI texture): irradiance as
  /// shared-exponent RGB9E5 times a power-of-two scale per octree chosen from
  /// its brightest VDL, so nothing is clamped whatever the light's power
  /// (half floats clamp at 65504); shaders/octree_layout.h. Overrides halfFloat.
  bool compact = false;
  int max3DTextureSize = 2048;   ///< GL_MAX_3D_TEXTURE_SIZE of the target context
  int max2DTextureSize = 16384;  ///< GL_MAX_TEXTURE_SIZE of the target context
  /// The bake stores each VDL's share c_i of the irradiance *on the voxel's
  /// surface* (already cosine-weighted: the VDLs sum to the estimate), while
  /// the shader applies max(0, n.d_i) to c_i as the paper does (§4.2.2),
  /// counting the cosine twice: ~30% too dark in the Cornell box
  /// (docs/accuracy.md). On: each texel holds c_i / max(|n_v.d_i|,
  /// kMinCorrectionCosine), n_v the voxel's normal, so that the shader returns
  /// the baked estimate on the baked surface. Voxels without a normal keep c_i.
  /// On by default, as in every command; off gives the paper's form (the
  /// sweep's "paper-cosine" point).
  bool cosineCorrection = true;
  /// Adaptive leaves (octree/adaptive_leaves.h): siblings whose light agrees
  /// within this share of a voxel's irradiance, at every voxel's own surface,
  /// collapse into one coarser leaf. 0 = every leaf at the grid's depth.
  float tolerance = 0.0f;
  /// The same for the free-space octree (buildVolumeOctree): eight siblings
  /// whose irradiance agrees within this share, for 14 normals, merge. Its
  /// light varies more slowly than the surfaces' and is read on objects
  /// only, so it may merge more. 0 = no merging.
  float volumeTolerance = 0.0f;
};

/// Smallest cosine cosineCorrection divides by: bounds the gain of grazing
/// VDLs to 4x (they carry little light on the baked surface).
constexpr float kMinCorrectionCosine = 0.25f;

struct GpuOctree {
  int depth = 0;          ///< leaves at this depth (= the VDL grid's depth)
  Vec3 origin{0, 0, 0};   ///< world position of the octree cube's lower corner
  float cubeSize = 1.0f;  ///< world edge length of the octree cube (voxelSize * 2^depth)

  /// Indirection pool: tilesX * tilesY * tilesZ tiles of 2x2x2 texels, stored
  /// as a (2*tilesX) x (2*tilesY) x (2*tilesZ) RGBA8 3D texture, x fastest.
  int tilesX = 0, tilesY = 0, tilesZ = 0;
  std::vector<uint8_t> pool;

  /// VDL texture: vdlWidth x vdlHeight RGBA texels, row-major. Exactly one of
  /// vdlTexels (RGBA32F) / vdlTexelsHalf (RGBA16UI: RGB = IEEE half bits,
  /// A = packed direction as an integer; see shaders/octree_layout.h) is filled.
  int vdlWidth = 0, vdlHeight = 0;
  bool halfFloat = false;      ///< the texels are vdlTexelsHalf's 16-bit ones
  bool compact = false;        ///< those hold compact texels (RGB9E5 x irradianceScale)
  float irradianceScale = 1;   ///< compact: a power of two
  /// 0: the leaves hold VDLs; 4 or 9: each leaf (and layer) holds that many
  /// SH terms (VdlGrid::shTerms), compact ones as halves times the scale.
  int shTerms = 0;
  /// Each leaf's (and layer's) light is followed by one surface texel: the
  /// reflectance of the surface it was gathered on and that surface's normal
  /// (octree_layout.h; set when the grid records reflectance,
  /// VdlGrid::reflectance).
  bool surfaceTexels = false;
  std::vector<float> vdlTexels;
  std::vector<uint16_t> vdlTexelsHalf;

  size_t leafCount = 0;  ///< leaves (non-empty voxels, or collapsed nodes standing for several)
  size_t collapsedLeaves = 0;  ///< leaves above the grid's depth (adaptive leaves)
  size_t collapsedVoxels = 0;  ///< voxels those stand for
  size_t nodeCount = 0;  ///< tiles in the pool (inner nodes incl. root)
  size_t vdlCount = 0;   ///< VDL texels used

  int poolWidth() const { return 2 * tilesX; }
  int poolHeight() const { return 2 * tilesY; }
  int poolDepth() const { return 2 * tilesZ; }
  size_t poolBytes() const { return pool.size(); }
  size_t vdlBytes() const { return halfFloat ? vdlTexelsHalf.size() * 2 : vdlTexels.size() * 4; }
  std::string ToString() const;  ///< sizes and memory per leaf
};

/// Builds the texture stack; only non-empty branches are stored, and each leaf
/// stores only the VDLs its voxel has (count in the texel's alpha).
/// @throws InputError naming the limit (3D/2D texture size, 24-bit address
/// space) and by how much the scene exceeds it.
GpuOctree buildGpuOctree(const VdlGrid& grid, const GpuOctreeParams& params = {});

/// The free-space light (VdlGrid::volume) as an octree of its own, in the
/// same texel layout and precision as `params` asks (its tolerance and
/// cosine correction do not apply): each leaf its SH texels after a header
/// with the voxel's lit box (shaders/octree_layout.h). Drawn on the objects
/// that were not baked (loVolumeIndirect). @throws InputError as
/// buildGpuOctree, and for arrays of the wrong lengths.
GpuOctree buildVolumeOctree(const VolumeLight& volume, const GpuOctreeParams& params = {});

/// Memory of this octree per leaf next to the paper's figure (§4.2.1: 512 KiB
/// octree + 4 MiB VDLs for 100k leaves of a depth-6 octree with k = 4 VDLs),
/// as a few lines of text. Sizes only, no timing.
std::string octreeMemoryReport(const GpuOctree& octree);

/// IEEE 754 binary16 conversion, round to nearest even, denormals kept.
/// Finite values beyond the largest half (65504) clamp to +-65504 instead of
/// becoming infinity (an infinite irradiance would poison the shader's sum);
/// NaN stays NaN.
uint16_t floatToHalf(float value);
/// GL_RGB9_E5's shared-exponent encoding (OpenGL 4.5 spec 8.5.2): negative
/// and NaN channels become 0, values above 65408 clamp to it.
uint32_t encodeRgb9e5(const Vec3& rgb);
float halfToFloat(uint16_t bits);

/// Result of the C++ reference of the shader's lookup.
struct OctreeSample {
  bool found = false;  ///< false in empty space or outside the cube
  Coord voxel;         ///< the leaf's voxel coordinate at the octree depth
  int layerCount = 1;  ///< surface layers of the voxel; the VDLs below are layer 0's
  int vdlCount = 0;
  Vdl vdls[kMaxVdls];  ///< decoded (directions through the 8+8-bit packing)
};

/// The same descent the fragment shader does (depth texel fetches, then the VDL
/// fetches), in C++: the reference the shader is tested against.
OctreeSample lookupOctree(const GpuOctree& octree, const Vec3& worldPosition);

}  // namespace lo
