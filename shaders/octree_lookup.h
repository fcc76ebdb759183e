/* octree_lookup.h: the light octree lookup, written once for GLSL and C++
 * (the practice of NanoVDB's PNanoVDB.h). The fragment shader includes it
 * (render_scene.frag); the C++ build is octree/octree_irradiance.cpp, which
 * gives lookupOctree() and octreeIrradiance() to the tests, the sweep and the
 * CPU renderers. Needs octree_layout.h first.
 *
 * What it holds (paper §4.2, Fig. 6):
 *   loLookupLeaf     the descent from the root tile to the leaf of a voxel
 *                    (at most `depth` texel fetches; a leaf may sit at any level)
 *   loHalfToFloat    IEEE binary16 bits -> float (half-precision VDL texels)
 *   loFetchVdl       one VDL texel, decoded: rgb irradiance (W/m^2), a packed direction
 *   loLeafVdls       a leaf's VDLs for a surface point (the layer of a layered
 *                    leaf that serves it)
 *   loServingLeaf    a voxel's leaf and its VDLs for a surface point, in one call
 *   loNearestServingLeaf  the voxel in front of the point, else behind, that serves it
 *   loShadeVdlsFacing  sum_i response(d_i) c_i over those VDLs (paper §4.2.2),
 *                    or the SH irradiance as one light from its dominant
 *                    direction, plus the light their surface reflects to a
 *                    point below its horizon (loSurfaceBelow); their
 *                    irradiance, and whether they face a surface
 *   loNearestLeaf    the voxel in front of a surface point, else the one behind it
 *   loOctreeIndirect the indirect light at a surface point: trilinear over the 8
 *                    voxels around it with empty ones left out and the weights
 *                    renormalized (§4.2.1), else the voxel in front, else behind
 *                    (loOctreeIndirectIrradiance: with the irradiance beside it)
 *   loOctreeIrradiance the same lookup's irradiance and the direction it comes
 *                    from, for lightmaps (§4.2.3)
 *   loVolumeIndirect the free-space octree's light at a point of an object
 *                    that was not baked (trilinear, lit boxes respected)
 *
 * The includer defines, before including:
 *   LO_FETCH_POOL(p)      RGBA8UI texel of the pool at ivec3 p, as uvec4
 *   LO_FETCH_VDL_FLOAT(p) RGBA32F VDL texel at ivec2 p, as vec4
 *   LO_FETCH_VDL_HALF(p)  RGBA16UI VDL texel at ivec2 p, as uvec4
 *   LO_VDLS_HALF          true when the VDL texels are the 16-bit ones
 *   LO_VDLS_COMPACT       true when those hold compact texels (RGB9E5)
 *   LO_VDL_SCALE          the compact texels' irradiance scale
 *   LO_SH_TERMS           0 when the leaves hold VDLs, else the SH terms per leaf
 *   LO_SURFACE_TEXELS     true when each leaf's (layer's) light ends in a surface texel
 * and, anywhere in the same unit, the response of a surface to one VDL:
 *   vec3 loVdlResponse(LoSurface s, vec3 d)   (the BRDF times the cosine in the
 *   shader; the cosine alone, i.e. irradiance, in C++).
 * In C++ the functions take the octree as their first argument (LO_TEX_PARAM)
 * and live in namespace lo::lookup with GLM standing in for GLSL's types.
 */
#ifndef LO_OCTREE_LOOKUP_H
#define LO_OCTREE_LOOKUP_H

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace lo {
struct GpuOctree;
namespace lookup {
using namespace glm;
using namespace ::lo::layout;
using uint = ::lo::layout::uint;
/* GLSL's built-ins are GLM's here, ahead of lo's own min/max/dot (core/math.h). */
using glm::any;
using glm::dot;
using glm::exp2;
using glm::floor;
using glm::greaterThanEqual;
using glm::length;
using glm::lessThan;
using glm::max;
using glm::min;
using glm::uintBitsToFloat;
#define LO_LOOKUP_FN inline
#define LO_TEX_PARAM const ::lo::GpuOctree &tex,
#define LO_TEX tex,
#define LO_OUT(T) T &
#else
#define LO_LOOKUP_FN
#define LO_TEX_PARAM
#define LO_TEX
#define LO_OUT(T) out T
#endif

/* What a surface point needs to respond to a VDL. */
struct LoSurface {
  vec3 n;         /* unit shading normal, world space */
  vec3 v;         /* unit direction to the viewer */
  vec3 baseColor; /* linear RGB */
  float metallic;
  float roughness;
  vec3 ng;        /* unit normal that picks surface layers: the interpolated
                     vertex (or geometric) normal, turned to the viewer */
};

vec3 loVdlResponse(LoSurface s, vec3 d); /* defined by the includer */

/* Octree descent (paper Fig. 6): from the root tile to the leaf holding voxel
 * c, and the leaf's edge in voxels (1 at the octree's depth, 2^k for a leaf k
 * levels up). False in empty space or outside the cube. */
LO_LOOKUP_FN bool loLookupLeafSize(LO_TEX_PARAM ivec3 c, int depth, LO_OUT(uvec4) leaf,
                                   LO_OUT(int) size) {
  leaf = uvec4(0u);
  size = 1;
  int resolution = 1 << depth;
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(resolution)))) return false;
  ivec3 tile = ivec3(0);
  for (int level = depth - 1; level >= 0; --level) {
    ivec3 child = (c >> level) & 1;
    uvec4 t = LO_FETCH_POOL(tile * 2 + child);
    if (t.a == LO_FLAG_EMPTY) return false;
    if (t.a != LO_FLAG_INNER) {
      leaf = t;
      size = 1 << level;
      return loIsLeaf(t.a);
    }
    tile = ivec3(t);
  }
  return false;
}

/* loLookupLeafSize without the size. */
LO_LOOKUP_FN bool loLookupLeaf(LO_TEX_PARAM ivec3 c, int depth, LO_OUT(uvec4) leaf) {
  int size;
  return loLookupLeafSize(LO_TEX c, depth, leaf, size);
}

/* IEEE binary16 bits -> float, exact (unpackHalf2x16 needs GLSL 4.20). */
LO_LOOKUP_FN float loHalfToFloat(uint h) {
  uint e = (h >> 10u) & 31u;
  if (e == 31u) return uintBitsToFloat(((h & 32768u) << 16u) | 2139095040u | ((h & 1023u) << 13u));
  float m = float(h & 1023u);
  float v = e == 0u ? m * exp2(-24.0f) : (1.0f + m / 1024.0f) * exp2(float(e) - 15.0f);
  return (h & 32768u) != 0u ? -v : v;
}

/* One texel of the VDL texture as stored: rgb (irradiance in W/m^2 for a
 * VDL; for compact texels before the octree's scale), a = packed direction
 * or count. Layer block headers are read with this (octree_layout.h). */
LO_LOOKUP_FN vec4 loFetchTexel(LO_TEX_PARAM uint index) {
  ivec2 p = ivec2(int(loVdlTexelX(index)), int(loVdlTexelY(index)));
  if (LO_VDLS_HALF) {
    uvec4 t = LO_FETCH_VDL_HALF(p);
    if (LO_VDLS_COMPACT && LO_SH_TERMS == 0) {
      uint bits = t.r | (t.g << 16u);
      return vec4(loRgb9e5Channel(bits, 0u), loRgb9e5Channel(bits, 9u),
                  loRgb9e5Channel(bits, 18u), float(t.a));
    }
    return vec4(loHalfToFloat(t.r), loHalfToFloat(t.g), loHalfToFloat(t.b), float(t.a));
  }
  return LO_FETCH_VDL_FLOAT(p);
}

/* One VDL texel: rgb irradiance (W/m^2), a packed direction (octree_layout.h). */
LO_LOOKUP_FN vec4 loFetchVdl(LO_TEX_PARAM uint index) {
  vec4 t = loFetchTexel(LO_TEX index);
  if (LO_VDLS_COMPACT) return vec4(vec3(t) * LO_VDL_SCALE, t.a);
  return t;
}

LO_LOOKUP_FN vec3 loVdlDirection(float code) {
  return vec3(loUnpackDirectionX(code), loUnpackDirectionY(code), loUnpackDirectionZ(code));
}

/* The VDLs of leaf texel `leaf` (voxel c) that light a surface point at q
 * (octree voxel units) whose surface faces ng: all of a plain leaf's; of a
 * layered leaf (octree_layout.h), the layer whose normal lies closest to ng,
 * within LO_LAYER_MIN_COSINE, and whose surface lies on q's side of every
 * other layer's plane (LO_LAYER_SIDE_TOLERANCE for a parallel plane,
 * LO_LAYER_JOINT_TOLERANCE for one across it): a floor layer lit from one
 * side of a thin wall does not light the floor on its other side, not even
 * at the wall's foot. Relaxed, the layer closest in normal serves, wherever
 * the other layers' planes lie: the lookup asks so only where no voxel of the
 * cell around the point serves it strictly (loNearestServingLeaf), which
 * would leave it black. A voxel across a grille holds faces of several bars
 * in each layer, and the layers' points, means over those faces, separate
 * nothing. False when no layer serves the point: the voxel then lends it no
 * light. */
LO_LOOKUP_FN bool loLeafVdls(LO_TEX_PARAM uvec4 leaf, ivec3 c, vec3 q, vec3 ng, bool relaxed,
                             LO_OUT(uint) first, LO_OUT(int) count) {
  first = loUnpackAddress(leaf.r, leaf.g, leaf.b);
  count = int(leaf.a);
  if (leaf.a != LO_FLAG_LAYERED) return true;
  vec4 h = loFetchTexel(LO_TEX first);
  int layers = min(int(h.a), int(LO_MAX_LAYERS));
  int counts[3];
  counts[0] = int(h.r);
  counts[1] = int(h.g);
  counts[2] = int(h.b);
  vec3 points[3];
  vec3 normals[3];
  uint address[3];
  uint a = first + 1u;
  for (int l = 0; l < layers; ++l) {
    vec4 t = loFetchTexel(LO_TEX a);
    points[l] = vec3(c) + vec3(t);
    normals[l] = loVdlDirection(t.a);
    address[l] = a + 1u;
    a += 1u + uint(counts[l]) + (LO_SURFACE_TEXELS ? 1u : 0u);
  }
  int best = -1;
  float bestCosine = LO_LAYER_MIN_COSINE;
  for (int l = 0; l < layers; ++l) {
    float cosine = dot(ng, normals[l]);
    if (!(cosine > bestCosine)) continue;
    bool sameSide = true;
    for (int m = 0; m < layers; ++m) {
      if (m == l) continue;
      float sq = dot(normals[m], q - points[m]);
      float sl = dot(normals[m], points[l] - points[m]);
      float tolerance = abs(dot(normals[l], normals[m])) > LO_LAYER_MIN_COSINE
                            ? LO_LAYER_SIDE_TOLERANCE
                            : LO_LAYER_JOINT_TOLERANCE;
      if (!relaxed && ((sq < -tolerance && sl > tolerance) || (sq > tolerance && sl < -tolerance))) {
        sameSide = false;
      }
    }
    if (sameSide) {
      best = l;
      bestCosine = cosine;
    }
  }
  if (best < 0) return false;
  first = address[best];
  count = counts[best];
  return true;
}

/* SH irradiance E(n) = sum_i E_i Y_i(n) of the LO_SH_TERMS texels at
 * `first` (octree_layout.h), clamped at zero, and the direction its light
 * mostly comes from: the gradient of the band-1 terms' luminance (unit, or
 * zero when they vanish). */
LO_LOOKUP_FN vec3 loShIrradiance(LO_TEX_PARAM uint first, vec3 n, LO_OUT(vec3) dominant) {
  vec3 e = vec3(0.0f);
  vec3 g = vec3(0.0f);
  for (int i = 0; i < LO_SH_TERMS; ++i) {
    vec3 t = vec3(loFetchVdl(LO_TEX first + uint(i)));
    e += t * loShBasis(uint(i), n.x, n.y, n.z);
    float y = dot(t, vec3(0.2126f, 0.7152f, 0.0722f));
    if (i == 1) g.y = y;
    if (i == 2) g.z = y;
    if (i == 3) g.x = y;
  }
  float len = length(g);
  dominant = len > 0.0f ? g / len : vec3(0.0f);
  return max(e, vec3(0.0f));
}

/* The SH light of a leaf as one directional light of irradiance E(n) from
 * the dominant direction d (the surface's normal where d lies below or
 * along its horizon): response(d) E(n) / (n . d), which is E(n) times the
 * BRDF for a diffuse surface and keeps a specular highlight along d. */
LO_LOOKUP_FN vec3 loShadeShIrradiance(LO_TEX_PARAM uint first, LoSurface s,
                                      LO_OUT(vec3) irradiance) {
  vec3 d;
  irradiance = loShIrradiance(LO_TEX first, s.n, d);
  if (!(dot(s.n, d) > 0.05f)) d = s.n;
  return loVdlResponse(s, d) * irradiance / max(dot(s.n, d), 0.05f);
}

/* loShadeShIrradiance without the irradiance. */
LO_LOOKUP_FN vec3 loShadeSh(LO_TEX_PARAM uint first, LoSurface s) {
  vec3 e;
  return loShadeShIrradiance(LO_TEX first, s, e);
}

/* The voxel under a surface point: q is the point in voxel units, already
 * moved by normalOffset voxels along n towards the viewer, so a surface lying
 * on a voxel face is looked up in the voxel in front of it; if that one is
 * empty, in the voxel behind it. */
LO_LOOKUP_FN bool loNearestLeaf(LO_TEX_PARAM vec3 q, vec3 n, int depth, float normalOffset,
                                LO_OUT(uvec4) leaf, LO_OUT(ivec3) voxel) {
  voxel = ivec3(floor(q));
  if (loLookupLeaf(LO_TEX voxel, depth, leaf)) return true;
  voxel = ivec3(floor(q - (normalOffset + normalOffset) * n));
  return loLookupLeaf(LO_TEX voxel, depth, leaf);
}

/* The surface texel after the light of a leaf or layer (`count` VDLs at
 * `first`, or LO_SH_TERMS terms; octree_layout.h): the normal m of the
 * surface that light was gathered on and its reflectance. Returns the share
 * of the cosine-weighted hemisphere of a point facing n that lies below
 * that surface's plane, (1 - n . m) / 2, for n . m >= 0: what such a point
 * (a step's riser, a rail, a door frame, thinner than a voxel and lit by
 * the floor's or the wall's VDLs, which hold only light from above that
 * surface) sees of the surface itself. For n . m < 0 it falls back to 0 at
 * n = -m, as (1 - |n . m|) / 2: a face turned against the surface is as
 * likely the far side of a thin wall, which sees another room, as a slab's
 * underside. 0 without surface texels. */
LO_LOOKUP_FN float loSurfaceBelow(LO_TEX_PARAM uint first, int count, vec3 n, LO_OUT(vec3) m,
                                  LO_OUT(vec3) reflectance) {
  m = vec3(0.0f);
  reflectance = vec3(0.0f);
  if (!LO_SURFACE_TEXELS) return 0.0f;
  vec4 t = loFetchTexel(LO_TEX first + uint(LO_SH_TERMS > 0 ? LO_SH_TERMS : count));
  m = loVdlDirection(t.a);
  reflectance = vec3(t);
  return max(0.0f, 0.5f * (1.0f - abs(dot(n, m))));
}

/* The light a surface point s reflects of irradiance e from below the plane
 * of the surface whose normal is m: e from the mean direction of that part
 * of its hemisphere (between s.ng and -m), through the surface's response. */
LO_LOOKUP_FN vec3 loShadeBelow(LoSurface s, vec3 m, vec3 e) {
  vec3 d = s.ng - m;
  float len = length(d);
  d = len > 1e-3f ? d / len : s.n;
  return loVdlResponse(s, d) * e / max(dot(s.n, d), 0.05f);
}

/* Whether the light of a leaf's VDLs (the first maxVdls of `count` at
 * `first`) reaches a surface facing ng at all: some of it arrives from above
 * the surface's horizon, or the leaf holds none (a dark voxel is dark for
 * every surface). A voxel all of whose light arrives from behind the surface
 * lights another surface (the far side of a wall thinner than a voxel, the
 * other face of an edge that no layer split off): in an interpolation it
 * would count as darkness. */
LO_LOOKUP_FN bool loLeafFaces(LO_TEX_PARAM uint first, int count, int maxVdls, vec3 ng) {
  if (LO_SH_TERMS > 0 || count <= 0) return true;
  int n = min(count, maxVdls);
  for (int i = 0; i < n; ++i) {
    if (dot(ng, loVdlDirection(loFetchVdl(LO_TEX first + uint(i)).a)) > 0.0f) return true;
  }
  return false;
}

/* Paper §4.2.2: c = sum_i brdf(d_i, v, n) c_i over the first maxVdls of the
 * `count` VDLs at `first` (the strongest come first), each a directional light
 * of irradiance c_i (in an SH octree, loShadeShIrradiance); beside it, from
 * the same fetch of each VDL, their irradiance sum_i max(0, n . d_i) c_i and
 * whether any of them faces ng (loLeafFaces). The shader's walk thus gives
 * the light a surface reflects and the irradiance its probe is normalised by
 * at once (render_scene.frag). */
LO_LOOKUP_FN vec3 loShadeVdlsFacing(LO_TEX_PARAM uint first, int count, int maxVdls, LoSurface s,
                                    LO_OUT(vec3) irradiance, LO_OUT(bool) faces) {
  vec3 m;
  vec3 reflectance;
  /* The surface's own normal, not a normal map's: its bumps do not see
   * below the surface they lie on. */
  float below = loSurfaceBelow(LO_TEX first, count, s.ng, m, reflectance);
  if (LO_SH_TERMS > 0) {
    faces = true;
    vec3 light = loShadeShIrradiance(LO_TEX first, s, irradiance);
    if (below > 0.0f) {
      vec3 d;
      vec3 e = below * reflectance * loShIrradiance(LO_TEX first, m, d);
      light += loShadeBelow(s, m, e);
      irradiance += e;
    }
    return light;
  }
  faces = count <= 0;
  irradiance = vec3(0.0f);
  int n = min(count, maxVdls);
  vec3 sum = vec3(0.0f);
  vec3 surface = vec3(0.0f); /* the VDLs' irradiance on their own surface */
  for (int i = 0; i < n; ++i) {
    vec4 t = loFetchVdl(LO_TEX first + uint(i));
    vec3 d = loVdlDirection(t.a);
    if (dot(s.ng, d) > 0.0f) faces = true;
    sum += loVdlResponse(s, d) * vec3(t);
    irradiance += vec3(max(dot(s.n, d), 0.0f)) * vec3(t);
    surface += vec3(max(dot(m, d), 0.0f)) * vec3(t);
  }
  if (below > 0.0f) {
    vec3 e = below * reflectance * surface;
    sum += loShadeBelow(s, m, e);
    irradiance += e;
  }
  return sum;
}

/* The VDLs of voxel c that serve a surface point at q facing ng: its leaf
 * (loLookupLeaf), then the leaf's layer for the point (loLeafVdls, strictly
 * or relaxed). */
LO_LOOKUP_FN bool loServingLeaf(LO_TEX_PARAM ivec3 c, vec3 q, vec3 ng, int depth, bool relaxed,
                                LO_OUT(uint) first, LO_OUT(int) count) {
  uvec4 leaf;
  return loLookupLeaf(LO_TEX c, depth, leaf) &&
         loLeafVdls(LO_TEX leaf, c, q, ng, relaxed, first, count);
}

/* Position in voxel units of the octree, moved normalOffset voxels along n. */
LO_LOOKUP_FN vec3 loOctreePosition(vec3 p, vec3 n, vec3 origin, float voxelSize,
                                   float normalOffset) {
  return (p - origin) / voxelSize + normalOffset * n;
}

/* The cell of 8 voxel centres around q (voxel units) that a trilinear
 * interpolation reads: its lowest voxel, and q's fraction f across it. */
LO_LOOKUP_FN ivec3 loTrilinearCell(vec3 q, LO_OUT(vec3) f) {
  vec3 u = q - vec3(0.5f);
  f = u - floor(u);
  return ivec3(floor(u));
}

/* Corner k (0..7) of that cell: 0 or 1 per axis. */
LO_LOOKUP_FN ivec3 loCellCorner(int k) { return ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1); }

/* Whether a voxel of the cell of 8 around q serves the point strictly with
 * light that faces it (loLeafFaces): what the interpolation takes. */
LO_LOOKUP_FN bool loCellServes(LO_TEX_PARAM vec3 q, vec3 ng, int depth, int maxVdls) {
  vec3 f;
  ivec3 base = loTrilinearCell(q, f);
  uint first;
  int count;
  for (int k = 0; k < 8; ++k) {
    if (loServingLeaf(LO_TEX base + loCellCorner(k), q, ng, depth, false, first, count) &&
        loLeafFaces(LO_TEX first, count, maxVdls, ng)) {
      return true;
    }
  }
  return false;
}

/* loNearestLeaf's choice, the voxel in front of the surface else the one
 * behind it, among the voxels that serve the point (loServingLeaf):
 * strictly, or relaxed where no voxel of the cell around it serves it
 * strictly (loCellServes), which would leave it black. */
LO_LOOKUP_FN bool loNearestServingLeaf(LO_TEX_PARAM vec3 q, vec3 n, vec3 ng, int depth,
                                       float normalOffset, int maxVdls, LO_OUT(uint) first,
                                       LO_OUT(int) count) {
  ivec3 front = ivec3(floor(q));
  ivec3 back = ivec3(floor(q - (normalOffset + normalOffset) * n));
  if (loServingLeaf(LO_TEX front, q, ng, depth, false, first, count)) return true;
  if (loServingLeaf(LO_TEX back, q, ng, depth, false, first, count)) return true;
  if (loCellServes(LO_TEX q, ng, depth, maxVdls)) return false;
  if (loServingLeaf(LO_TEX front, q, ng, depth, true, first, count)) return true;
  return loServingLeaf(LO_TEX back, q, ng, depth, true, first, count);
}

/* Weight of corner o (0 or 1 per axis) of the cell in a trilinear
 * interpolation at fraction f. */
LO_LOOKUP_FN float loTrilinearWeight(vec3 f, ivec3 o) {
  return (o.x == 1 ? f.x : 1.0f - f.x) * (o.y == 1 ? f.y : 1.0f - f.y) *
         (o.z == 1 ? f.z : 1.0f - f.z);
}

/* Indirect light at world position p of surface s (paper §3.2, §4.2), and
 * the irradiance E(p, s.n) of the same VDLs with the same weights. */
LO_LOOKUP_FN vec3 loOctreeIndirectIrradiance(LO_TEX_PARAM vec3 p, vec3 origin, float voxelSize,
                                             int depth, float normalOffset, bool interpolation,
                                             int maxVdls, LoSurface s,
                                             LO_OUT(vec3) irradiance) {
  vec3 q = loOctreePosition(p, s.n, origin, voxelSize, normalOffset);
  uint first;
  int count;
  vec3 e;
  bool faces;
  irradiance = vec3(0.0f);
  if (interpolation) {
    /* Trilinear over the 8 voxels around q (paper §4.2.1); empty neighbours,
     * layered ones without a layer for this surface (loLeafVdls) and those
     * whose light all comes from behind it (loLeafFaces) are left out and
     * the remaining weights renormalized, so light never leaks in from empty
     * space or through a thin wall, and neither fades at the edge of the
     * geometry nor darkens beside the far side of a thin wall. */
    vec3 f;
    ivec3 base = loTrilinearCell(q, f);
    vec3 sum = vec3(0.0f);
    vec3 irradianceSum = vec3(0.0f);
    float weightSum = 0.0f;
    for (int k = 0; k < 8; ++k) {
      ivec3 o = loCellCorner(k);
      float w = loTrilinearWeight(f, o);
      if (w <= 0.0f) continue;
      if (!loServingLeaf(LO_TEX base + o, q, s.ng, depth, false, first, count)) continue;
      vec3 light = loShadeVdlsFacing(LO_TEX first, count, maxVdls, s, e, faces);
      if (!faces) continue;
      sum += w * light;
      irradianceSum += w * e;
      weightSum += w;
    }
    if (weightSum > 0.0f) {
      irradiance = irradianceSum / weightSum;
      return sum / weightSum;
    }
  }
  if (loNearestServingLeaf(LO_TEX q, s.n, s.ng, depth, normalOffset, maxVdls, first, count)) {
    return loShadeVdlsFacing(LO_TEX first, count, maxVdls, s, irradiance, faces);
  }
  return vec3(0.0f);
}

/* loOctreeIndirectIrradiance without the irradiance. */
LO_LOOKUP_FN vec3 loOctreeIndirect(LO_TEX_PARAM vec3 p, vec3 origin, float voxelSize, int depth,
                                   float normalOffset, bool interpolation, int maxVdls,
                                   LoSurface s) {
  vec3 e;
  return loOctreeIndirectIrradiance(LO_TEX p, origin, voxelSize, depth, normalOffset,
                                    interpolation, maxVdls, s, e);
}

/* Irradiance and where it comes from, for lightmaps (paper §4.2.3: one VDL
 * per texel rebuilt for the specular term): loShadeVdlsFacing with the cosine as
 * the response, E = sum_i max(0, n . d_i) c_i, and beside it the
 * luminance-weighted direction sum sum_i Y(c_i) max(0, n . d_i) d_i (Rec. 709
 * luminance, world space, towards the light). */
LO_LOOKUP_FN vec3 loShadeVdlsIrradiance(LO_TEX_PARAM uint first, int count, int maxVdls, vec3 n,
                                        LO_OUT(vec3) direction) {
  vec3 m;
  vec3 reflectance;
  float below = loSurfaceBelow(LO_TEX first, count, n, m, reflectance);
  vec3 bd = n - m; /* where the light from below the surface comes from */
  bd = length(bd) > 1e-3f ? normalize(bd) : n;
  if (LO_SH_TERMS > 0) {
    vec3 d;
    vec3 e = loShIrradiance(LO_TEX first, n, d);
    direction = dot(e, vec3(0.2126f, 0.7152f, 0.0722f)) * d;
    if (below > 0.0f) {
      vec3 eb = below * reflectance * loShIrradiance(LO_TEX first, m, d);
      e += eb;
      direction += dot(eb, vec3(0.2126f, 0.7152f, 0.0722f)) * bd;
    }
    return e;
  }
  int used = min(count, maxVdls);
  vec3 irradiance = vec3(0.0f);
  vec3 surface = vec3(0.0f);
  direction = vec3(0.0f);
  for (int i = 0; i < used; ++i) {
    vec4 t = loFetchVdl(LO_TEX first + uint(i));
    vec3 d = loVdlDirection(t.a);
    float cosine = max(0.0f, dot(n, d));
    irradiance += vec3(cosine) * vec3(t);
    direction += (cosine * dot(vec3(t), vec3(0.2126f, 0.7152f, 0.0722f))) * d;
    surface += vec3(max(dot(m, d), 0.0f)) * vec3(t);
  }
  if (below > 0.0f) {
    vec3 eb = below * reflectance * surface;
    irradiance += eb;
    direction += dot(eb, vec3(0.2126f, 0.7152f, 0.0722f)) * bd;
  }
  return irradiance;
}

/* loOctreeIndirect of a Lambertian surface of unit albedo times pi, i.e. the
 * irradiance E(p, n) (n also picks the layers), with the direction sum of
 * loShadeVdlsIrradiance taken with the same weights. The lightmap bakes
 * (lightmap/lightmap_atlas.cpp on the CPU, shaders/atlas_bake.frag on the
 * GPU) call this one function. */
LO_LOOKUP_FN vec3 loOctreeIrradiance(LO_TEX_PARAM vec3 p, vec3 n, vec3 origin, float voxelSize,
                                     int depth, float normalOffset, bool interpolation,
                                     int maxVdls, LO_OUT(vec3) direction) {
  vec3 q = loOctreePosition(p, n, origin, voxelSize, normalOffset);
  uint first;
  int count;
  vec3 e;
  vec3 d;
  direction = vec3(0.0f);
  if (interpolation) {
    vec3 f;
    ivec3 base = loTrilinearCell(q, f);
    vec3 sum = vec3(0.0f);
    vec3 directionSum = vec3(0.0f);
    float weightSum = 0.0f;
    for (int k = 0; k < 8; ++k) {
      ivec3 o = loCellCorner(k);
      float w = loTrilinearWeight(f, o);
      if (w <= 0.0f) continue;
      if (loServingLeaf(LO_TEX base + o, q, n, depth, false, first, count) &&
          loLeafFaces(LO_TEX first, count, maxVdls, n)) {
        e = loShadeVdlsIrradiance(LO_TEX first, count, maxVdls, n, d);
        sum += w * e;
        directionSum += w * d;
        weightSum += w;
      }
    }
    if (weightSum > 0.0f) {
      direction = directionSum / weightSum;
      return sum / weightSum;
    }
  }
  if (loNearestServingLeaf(LO_TEX q, n, n, depth, normalOffset, maxVdls, first, count)) {
    return loShadeVdlsIrradiance(LO_TEX first, count, maxVdls, n, direction);
  }
  return vec3(0.0f);
}

/* Whether the free-space leaf of voxel c, `size` voxels wide (a merged
 * leaf's; loLookupLeafSize), lends its light to q (voxel units of its
 * octree): q lies within the leaf's lit box (in the leaf's own units), grown
 * by LO_VOLUME_BOX_MARGIN voxels on the sides where the box stops inside the
 * leaf (a wall cuts it); a side where the light reached the leaf's face
 * bounds nothing. */
LO_LOOKUP_FN bool loVolumeLends(LO_TEX_PARAM uint first, ivec3 c, int size, vec3 q) {
  vec4 h = loFetchTexel(LO_TEX first - 1u);
  vec3 corner = vec3((c / size) * size);
  vec3 local = (q - corner) / float(size);
  float margin = LO_VOLUME_BOX_MARGIN / float(size);
  vec3 box = vec3(h);
  for (int a = 0; a < 3; ++a) {
    float lower = loVolumeBoxLower(box[a]);
    float upper = loVolumeBoxUpper(box[a]);
    if (lower > 0.0f && local[a] < lower - margin) return false;
    if (upper < 1.0f && local[a] > upper + margin) return false;
  }
  return true;
}

/* The free-space light at world position p of a surface s that was not in
 * the bake (an object added later): none when p's own voxel has no light
 * or p lies beyond its lit box; else trilinear over the 8 voxels of the
 * free-space octree around p, voxels without light or whose lit box p lies
 * beyond (loVolumeLends) left out and the weights renormalized; and the
 * irradiance E(p, s.n) of the same light with the same weights. */
LO_LOOKUP_FN vec3 loVolumeIndirectIrradiance(LO_TEX_PARAM vec3 p, vec3 origin, float voxelSize,
                                             int depth, LoSurface s, LO_OUT(vec3) irradiance) {
  vec3 q = (p - origin) / voxelSize;
  irradiance = vec3(0.0f);
  /* The point's own voxel first: without light there (a room the light
   * never reached, where a wall lies on the voxels' face), or with its
   * light beyond a wall, the neighbours lend none either. */
  uvec4 own;
  int size;
  if (!loLookupLeafSize(LO_TEX ivec3(floor(q)), depth, own, size) ||
      !loVolumeLends(LO_TEX loUnpackAddress(own.r, own.g, own.b), ivec3(floor(q)), size, q)) {
    return vec3(0.0f);
  }
  vec3 f;
  ivec3 base = loTrilinearCell(q, f);
  vec3 sum = vec3(0.0f);
  vec3 irradianceSum = vec3(0.0f);
  float weightSum = 0.0f;
  for (int k = 0; k < 8; ++k) {
    ivec3 o = loCellCorner(k);
    float w = loTrilinearWeight(f, o);
    if (w <= 0.0f) continue;
    uvec4 leaf;
    vec3 e;
    if (!loLookupLeafSize(LO_TEX base + o, depth, leaf, size)) continue;
    uint first = loUnpackAddress(leaf.r, leaf.g, leaf.b);
    if (!loVolumeLends(LO_TEX first, base + o, size, q)) continue;
    sum += w * loShadeShIrradiance(LO_TEX first, s, e);
    irradianceSum += w * e;
    weightSum += w;
  }
  if (!(weightSum > 0.0f)) return vec3(0.0f);
  irradiance = irradianceSum / weightSum;
  return sum / weightSum;
}

/* loVolumeIndirectIrradiance without the irradiance. */
LO_LOOKUP_FN vec3 loVolumeIndirect(LO_TEX_PARAM vec3 p, vec3 origin, float voxelSize, int depth,
                                   LoSurface s) {
  vec3 e;
  return loVolumeIndirectIrradiance(LO_TEX p, origin, voxelSize, depth, s, e);
}

#ifdef __cplusplus
}  // namespace lookup
}  // namespace lo
#endif
#undef LO_LOOKUP_FN

#endif /* LO_OCTREE_LOOKUP_H */
