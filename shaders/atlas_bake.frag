#version 330 core
// Render to atlas on the GPU (paper §4.2.3; render/atlas_gpu.cpp): one
// fragment per texel of a triangle's UV bounding box. It keeps the texels
// the triangle's footprint overlaps, finds the point of the triangle nearest
// to the texel centre, and evaluates the light octree there with
// loOctreeIrradiance, the lookup the CPU bake (lightmap/lightmap_atlas.cpp)
// and the scene shader share (octree_lookup.h). The depth is the squared UV
// distance from the centre to the triangle: with GL_LESS and the triangles
// drawn in index order, a texel goes to the triangle containing its centre,
// else to the nearest, ties to the lower index: the CPU path's rule.
#include "octree_layout.h"

flat in vec2 fTexel0;
flat in vec2 fTexel1;
flat in vec2 fTexel2;
flat in vec3 fPosition0;
flat in vec3 fPosition1;
flat in vec3 fPosition2;
flat in vec3 fNormal0;
flat in vec3 fNormal1;
flat in vec3 fNormal2;
flat in int fTriangle;

uniform usampler3D uOctree;
uniform sampler2D uVdls;
uniform usampler2D uVdlsHalf;
uniform bool uHalfVdls;
uniform bool uCompactVdls;
uniform float uVdlScale;
uniform int uShTerms;
uniform bool uSurfaceTexels;
uniform float uVoxelSize;
uniform int uDepth;
uniform float uNormalOffset;
uniform bool uInterpolation;
uniform int uMaxVdls;

layout(location = 0) out vec4 oIrradiance;  // E, W/m^2; a = 1
layout(location = 1) out vec4 oDirection;   // unit direction sum, or zero
layout(location = 2) out int oTriangle;

#define LO_FETCH_POOL(p) texelFetch(uOctree, p, 0)
#define LO_FETCH_VDL_FLOAT(p) texelFetch(uVdls, p, 0)
#define LO_FETCH_VDL_HALF(p) texelFetch(uVdlsHalf, p, 0)
#define LO_VDLS_HALF uHalfVdls
#define LO_VDLS_COMPACT uCompactVdls
#define LO_VDL_SCALE uVdlScale
#define LO_SH_TERMS uShTerms
#define LO_SURFACE_TEXELS uSurfaceTexels
#include "octree_lookup.h"

// Irradiance: the response to a VDL is its cosine (octree_irradiance.cpp).
vec3 loVdlResponse(LoSurface s, vec3 d) { return vec3(max(dot(s.n, d), 0.0)); }

// Barycentrics of the point of triangle abc nearest to p (Ericson, Real-Time
// Collision Detection, §5.1.5), as lightmap_atlas.cpp's closestPointBarycentrics.
vec3 closestBarycentrics(vec2 p, vec2 a, vec2 b, vec2 c) {
  vec2 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return vec3(1.0, 0.0, 0.0);
  vec2 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return vec3(0.0, 1.0, 0.0);
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) {
    float v = d1 / (d1 - d3);
    return vec3(1.0 - v, v, 0.0);
  }
  vec2 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return vec3(0.0, 0.0, 1.0);
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) {
    float w = d2 / (d2 - d6);
    return vec3(1.0 - w, 0.0, w);
  }
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    float w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return vec3(0.0, 1.0 - w, w);
  }
  float denom = 1.0 / (va + vb + vc);
  float v = vb * denom, w = vc * denom;
  return vec3(1.0 - v - w, v, w);
}

void main() {
  vec2 t[3] = vec2[3](fTexel0, fTexel1, fTexel2);
  vec2 centre = gl_FragCoord.xy;  // (x + 0.5, y + 0.5)
  // Separating axes: a triangle edge's outward normal along which the
  // texel square's nearest corner lies on or beyond the edge's line.
  float area2 = (t[1].x - t[0].x) * (t[2].y - t[0].y) - (t[2].x - t[0].x) * (t[1].y - t[0].y);
  float s = area2 > 0.0 ? 1.0 : -1.0;
  bool inside = true;
  for (int k = 0; k < 3; ++k) {
    vec2 e = t[(k + 1) % 3] - t[k];
    vec2 n = s * vec2(e.y, -e.x);
    float f = dot(n, centre) - dot(n, t[k]);
    if (f - 0.5 * (abs(n.x) + abs(n.y)) >= 0.0) discard;
    inside = inside && f <= 0.0;
  }
  vec3 b = closestBarycentrics(centre, t[0], t[1], t[2]);
  float distance2 = 0.0;
  if (!inside) {
    vec2 d = b.x * t[0] + b.y * t[1] + b.z * t[2] - centre;
    distance2 = dot(d, d);
  }
  gl_FragDepth = min(distance2, 1.0);

  vec3 position = b.x * fPosition0 + b.y * fPosition1 + b.z * fPosition2;
  vec3 m = b.x * fNormal0 + b.y * fNormal1 + b.z * fNormal2;
  float l = length(m);
  vec3 normal = l > 0.0 ? m / l : vec3(0.0);
  // No vertex normals, or ones that cancel (a folded sheet): the winding's.
  if (!(dot(normal, normal) > 0.5)) {
    normal = normalize(cross(fPosition1 - fPosition0, fPosition2 - fPosition0));
  }
  vec3 direction;
  vec3 e = loOctreeIrradiance(position, normal, vec3(0.0), uVoxelSize, uDepth, uNormalOffset,
                              uInterpolation, uMaxVdls, direction);
  float dl = length(direction);
  oIrradiance = vec4(e, 1.0);
  oDirection = vec4(dl > 0.0 && !isinf(dl) ? direction / dl : vec3(0.0), 0.0);
  oTriangle = fTriangle;
}
