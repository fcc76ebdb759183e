/* octree_layout.h: the GPU light octree texture layout, one header valid in
 * both C++ (included by src/octree and tests) and GLSL (prepended to shaders).
 * A unit test asserts that the C++ build and the shaders agree on every value.
 *
 * Octree pool (paper §4.2.1, after Lefebvre, Hornus and Neyret, GPU Gems 2
 * ch. 37): a 3D texture, internal format RGBA8UI, made of 2x2x2 node tiles.
 * Tile t sits at texel (2*tx, 2*ty, 2*tz); its 8 texels are the 8 children of
 * one node, child (cx,cy,cz) in {0,1}^3 at texel (2*tx+cx, 2*ty+cy, 2*tz+cz).
 * The root node is tile (0,0,0). Each texel:
 *   A == LO_FLAG_EMPTY    : empty branch (no geometry below)
 *   A == LO_FLAG_INNER    : RGB = tile coordinates (tx, ty, tz) of the child tile
 *   A in [1, LO_MAX_VDLS] : leaf holding A VDLs; RGB = 24-bit index
 *                           (R | G<<8 | B<<16) of its first VDL texel
 *   A == LO_FLAG_LAYERED  : leaf of a voxel with surface layers (below); RGB =
 *                           24-bit index of its layer block
 * A leaf stores only the VDLs its voxel has (the count lives in the flag).
 *
 * Layer block (a voxel whose surfaces face clearly different ways keeps one
 * set of VDLs per orientation, at most LO_MAX_LAYERS): texels of the VDL
 * texture, read like VDL texels (loFetchVdl):
 *   block header : RGB = the VDL counts of layers 0, 1, 2 (0 past the last),
 *                  A = the number of layers
 *   per layer, in order: its header, RGB = a point of its surface in voxel
 *                  units relative to the voxel's lower corner, A = its unit
 *                  normal packed like a VDL direction; then its VDL texels
 *                  (and its surface texel, below). The counts leave the
 *                  surface texels out.
 *
 * Surface texel (octrees whose grid records the surfaces' reflectance,
 * GpuOctree::surfaceTexels; LO_SURFACE_TEXELS in the lookup): right after
 * the light of every leaf and of every layer, one texel read like a layer
 * header: RGB = the reflectance (0..1) of the surface that light was
 * gathered on, A = that surface's unit normal packed like a VDL direction
 * (RGB zero where the voxel has no normal; a merged leaf's: its voxels'
 * means weighted by their areas, octree/adaptive_leaves.h). The
 * lookup lights a point from below that surface's plane with it
 * (loSurfaceBelow in octree_lookup.h).
 *
 * VDL texture (paper §4.2.2, Fig. 8): a 2D texture, LO_VDL_TEXTURE_WIDTH
 * texels wide. One texel per VDL: RGB = irradiance (W/m^2), A = direction
 * packed into an integer thetaQ * 256 + phiQ (8+8 bits).
 *   full precision: RGBA32F; A holds the packed integer exactly as a float.
 *   half precision: RGBA16UI (not RGBA16F): RGB = IEEE half bits, decoded with
 *     unpackHalf2x16(bits).x; A = the packed integer itself, used as
 *     float(A). A half float holds integers exactly only up to 2048 and
 *     overflows at 65504, and no 16-bit float encoding has 65536 finite,
 *     non-denormal values, so the 16-bit packed direction cannot ride in a
 *     half alpha; as an integer channel it costs the same 8 bytes per VDL.
 *   compact: RGBA16UI too: R | G << 16 = RGB as shared-exponent RGB9E5 bits
 *     (9-bit mantissas, a 5-bit exponent shared by the three channels), times
 *     a power-of-two scale per octree chosen so that its brightest texel fits:
 *     no irradiance is clamped, whatever the light's power; B = 0; A = the
 *     packed direction as for half. Header texels of layer blocks are stored
 *     without the scale.
 * VDL index i lives at texel (i % LO_VDL_TEXTURE_WIDTH, i / LO_VDL_TEXTURE_WIDTH).
 *
 * SH octrees (the sh1 / sh2 representations, LO_SH_TERMS = 4 or 9 for the
 * whole octree): a plain leaf's flag is 1 and its first texel index points
 * at LO_SH_TERMS texels, RGB = the SH terms E_i below, A = 0; a layer
 * block's counts are LO_SH_TERMS per layer. Compact SH texels are RGBA16UI
 * with RGB = IEEE half bits times the octree's power-of-two scale (the terms
 * are signed, which RGB9E5 cannot hold); block headers are halves without
 * the scale.
 *
 * Direction frame: theta from +Z (0..pi), phi from +X towards +Y (0..2pi),
 * world space: d = (sin(theta) cos(phi), sin(theta) sin(phi), cos(theta)).
 */
#ifndef LO_OCTREE_LAYOUT_H
#define LO_OCTREE_LAYOUT_H

#ifdef __cplusplus
#include <cmath>
#include <cstdint>
namespace lo {
namespace layout {
using uint = uint32_t;
using std::acos;
using std::cos;
using std::exp2;
using std::floor;
using std::min;
using std::sin;
#define LO_LAYOUT_FN inline
#else
#define LO_LAYOUT_FN
#endif

const uint LO_FLAG_EMPTY = 0u;
const uint LO_FLAG_INNER = 255u;
const uint LO_FLAG_LAYERED = 254u;
const uint LO_MAX_VDLS = 8u;
const uint LO_MAX_LAYERS = 3u;
/* A layer serves a surface point whose normal lies within this cosine of
 * its own (60 degrees: layers are that far apart, lightgrid/vdl_grid.h)... */
const float LO_LAYER_MIN_COSINE = 0.5;
/* ...and that lies on the same side as the layer's surface of every other
 * layer's plane, within this many voxels: a plane parallel to the layer's
 * own (the other face of a thin wall, where a fragment lies on the plane
 * itself)... */
const float LO_LAYER_SIDE_TOLERANCE = 0.1;
/* ...or within this many, of a plane across the layer's (a wall standing on
 * a floor layer): a floor fragment at the wall's foot is on one side, the
 * side its light belongs to. */
const float LO_LAYER_JOINT_TOLERANCE = 0.001;
const uint LO_VDL_TEXTURE_WIDTH = 4096u;
const uint LO_ADDRESS_BITS = 24u;
const uint LO_MAX_ADDRESS = 16777215u; /* 2^24 - 1 */
const uint LO_MAX_TILES_PER_AXIS = 256u; /* tile coordinates are 8-bit */
const uint LO_THETA_STEPS = 255u; /* thetaQ in [0, 255] maps to [0, pi] */
const uint LO_PHI_STEPS = 256u;   /* phiQ in [0, 255] maps to [0, 2pi), wraps */
const float LO_PI = 3.14159265358979323846;

/* atan2 with C++'s IEEE behaviour at (0, 0) (GLSL's atan(y, x) is undefined
 * there, and GLSL has no atan2). */
#ifdef __cplusplus
inline float loAtan2(float y, float x) { return std::atan2(y, x); }
#else
float loAtan2(float y, float x) {
  if (x != 0.0 || y != 0.0) return atan(y, x);
  bool negX = (floatBitsToUint(x) >> 31u) != 0u;
  return negX ? ((floatBitsToUint(y) >> 31u) != 0u ? -LO_PI : LO_PI) : y;
}
#endif

LO_LAYOUT_FN bool loIsLeaf(uint flag) {
  return (flag >= 1u && flag <= LO_MAX_VDLS) || flag == LO_FLAG_LAYERED;
}

/* Shared-exponent RGB9E5 bits -> RGB (GL_RGB9_E5's decoding, OpenGL 4.5
 * spec 8.5.2): channel = mantissa * 2^(exponent - 15 - 9). */
LO_LAYOUT_FN float loRgb9e5Channel(uint bits, uint shift) {
  uint e = (bits >> 27u) & 31u;
  return float((bits >> shift) & 511u) * exp2(float(e) - 24.0);
}

/* 24-bit address <-> three 8-bit channels. */
LO_LAYOUT_FN uint loPackAddressR(uint address) { return address & 255u; }
LO_LAYOUT_FN uint loPackAddressG(uint address) { return (address >> 8u) & 255u; }
LO_LAYOUT_FN uint loPackAddressB(uint address) { return (address >> 16u) & 255u; }
LO_LAYOUT_FN uint loUnpackAddress(uint r, uint g, uint b) { return r | (g << 8u) | (b << 16u); }

/* Texel of VDL index i in the VDL texture. */
LO_LAYOUT_FN uint loVdlTexelX(uint index) { return index % LO_VDL_TEXTURE_WIDTH; }
LO_LAYOUT_FN uint loVdlTexelY(uint index) { return index / LO_VDL_TEXTURE_WIDTH; }

/* Direction packing: unit (x, y, z) -> thetaQ * 256 + phiQ, exact in a float. */
LO_LAYOUT_FN float loPackDirection(float x, float y, float z) {
  float c = z < -1.0 ? -1.0 : (z > 1.0 ? 1.0 : z);
  float theta = acos(c);
  float phi = loAtan2(y, x);
  if (phi < 0.0) phi += 2.0 * LO_PI;
  /* min(): a GPU acos may return a little more than pi; thetaQ must stay 8-bit. */
  uint thetaQ = min(uint(floor(theta / LO_PI * float(LO_THETA_STEPS) + 0.5)), LO_THETA_STEPS);
  uint phiQ = uint(floor(phi / (2.0 * LO_PI) * float(LO_PHI_STEPS) + 0.5)) % LO_PHI_STEPS;
  return float(thetaQ * 256u + phiQ);
}

LO_LAYOUT_FN float loPackedTheta(float code) {
  uint p = uint(code);
  return float(p / 256u) * (LO_PI / float(LO_THETA_STEPS));
}

LO_LAYOUT_FN float loPackedPhi(float code) {
  uint p = uint(code);
  return float(p % 256u) * (2.0 * LO_PI / float(LO_PHI_STEPS));
}

LO_LAYOUT_FN float loUnpackDirectionX(float code) {
  return sin(loPackedTheta(code)) * cos(loPackedPhi(code));
}
LO_LAYOUT_FN float loUnpackDirectionY(float code) {
  return sin(loPackedTheta(code)) * sin(loPackedPhi(code));
}
LO_LAYOUT_FN float loUnpackDirectionZ(float code) { return cos(loPackedTheta(code)); }

/* Spherical harmonics (the `sh1` / `sh2` representations, docs/accuracy.md):
 * real SH in the usual order i = l(l+1) + m, i < 4 for L1, < 9 for L2 (Sloan,
 * "Stupid Spherical Harmonics Tricks", 2008), at a unit direction (x, y, z).
 * A leaf then holds LO_SH_TERMS texels instead of VDLs, texel i with the
 * RGB coefficient E_i of the voxel's irradiance E(n) = sum_i E_i Y_i(n)
 * (W/m^2): the radiance coefficients already convolved with the clamped
 * cosine (Ramamoorthi and Hanrahan 2001). */
const uint LO_SH_MAX_TERMS = 9u;
LO_LAYOUT_FN float loShBasis(uint i, float x, float y, float z) {
  if (i == 0u) return 0.282094792;
  if (i == 1u) return 0.488602512 * y;
  if (i == 2u) return 0.488602512 * z;
  if (i == 3u) return 0.488602512 * x;
  if (i == 4u) return 1.092548431 * x * y;
  if (i == 5u) return 1.092548431 * y * z;
  if (i == 6u) return 0.315391565 * (3.0 * z * z - 1.0);
  if (i == 7u) return 1.092548431 * x * z;
  return 0.546274215 * (x * x - y * y);
}
/* The clamped cosine's SH coefficients per band: pi, 2 pi / 3, pi / 4 for
 * the terms of bands 0, 1 and 2 (irradiance = this times radiance). */
LO_LAYOUT_FN float loShCosineBand(uint i) {
  if (i == 0u) return LO_PI;
  if (i < 4u) return 2.0 * LO_PI / 3.0;
  return LO_PI / 4.0;
}

/* Free-space octree (the volume light, lightgrid/volume_light.h): a second
 * octree of the same layout over the same cube, coarser, whose every leaf
 * holds LO_SH_TERMS SH texels of the light from all directions, preceded by
 * one header texel at (first index - 1): RGB = per axis lower * 16 + upper,
 * the box [lower / 16, (upper + 1) / 16] (in the leaf's own units from its
 * lower corner: a voxel's, or a merged leaf's) its light filled; A = 0.
 * Stored like a layer block's header. */
const float LO_VOLUME_BOX_STEPS = 16.0f;
LO_LAYOUT_FN float loPackVolumeBox(float lower, float upper) {
  float lo = min(floor(lower * LO_VOLUME_BOX_STEPS), LO_VOLUME_BOX_STEPS - 1.0f);
  float hi = min(floor(upper * LO_VOLUME_BOX_STEPS - 0.001f), LO_VOLUME_BOX_STEPS - 1.0f);
  lo = lo < 0.0f ? 0.0f : lo;
  hi = hi < lo ? lo : hi;
  return lo * LO_VOLUME_BOX_STEPS + hi;
}
LO_LAYOUT_FN float loVolumeBoxLower(float code) {
  return floor(code / LO_VOLUME_BOX_STEPS + 0.001f) / LO_VOLUME_BOX_STEPS;
}
LO_LAYOUT_FN float loVolumeBoxUpper(float code) {
  float lo = floor(code / LO_VOLUME_BOX_STEPS + 0.001f);
  return (code - lo * LO_VOLUME_BOX_STEPS + 1.0f) / LO_VOLUME_BOX_STEPS;
}
/* A voxel lends its light to a point that lies within this many voxels
 * beyond its lit box, on a side where the box stops inside the voxel. */
const float LO_VOLUME_BOX_MARGIN = 0.1f;

#ifdef __cplusplus
#undef LO_LAYOUT_FN
}  // namespace layout
}  // namespace lo
#endif

#endif /* LO_OCTREE_LAYOUT_H */
