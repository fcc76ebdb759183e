#version 330 core
// Scene pass: hybrid shading (paper §3): emission + direct light from punctual
// lights and emitter VPLs (shadow maps) + indirect light from the light octree
// (paper §3.2, §4.2, Fig. 6), whose lookup is shaders/octree_lookup.h, shared
// with C++. Radiance out, linear, W/(m^2 sr). See docs/render.md.
// `#include "x"` lines are replaced by the file (render/gl_util.cpp).
#include "octree_layout.h"
#include "render_constants.h"

in vec3 vPosition;  // world
in vec3 vNormal;    // world, interpolated
in vec3 vBaseColor;
in vec2 vMetallicRoughness;
in vec3 vEmission;
in vec2 vUv;
out vec4 fragColor;

uniform usampler3D uOctree;  // RGBA8UI pool of 2x2x2 tiles
uniform sampler2D uVdls;       // RGBA32F: irradiance, packed direction
uniform usampler2D uVdlsHalf;  // RGBA16UI: half-float bits of irradiance, packed direction
uniform bool uHalfVdls;        // which of the two holds the VDLs
uniform sampler2DArrayShadow uShadowMaps;
uniform vec3 uOctreeOrigin;  // world
uniform float uVoxelSize;    // world units
uniform int uDepth;
uniform vec3 uEye;
uniform int uMode;
uniform bool uInterpolation;
uniform bool uSpecular;
uniform int uMaxVdls;
uniform float uNormalOffset;  // voxel sizes
uniform float uExposureScale;
uniform bool uEncodeSrgb;
uniform sampler2D uBaseColorTexture;  // linear RGB (RGBA16F), mipmapped
uniform bool uHasBaseColorTexture;

// std140 twin: GpuLight / LightBlock in src/render/renderer.cpp.
struct Light {
  vec4 positionType;    // xyz world position, w type
  vec4 directionRange;  // xyz unit direction light travels (spot, directional, emitter normal), w range (0 = none)
  vec4 colorFar;        // rgb: W/sr (point, spot, emitter at normal incidence) or W/m^2 (directional); w shadow far
  vec4 params;          // x cos outer, y cos inner, z first shadow layer (-1 = none), w near-field area
};
layout(std140) uniform LightBlock {
  Light uLights[LO_MAX_LIGHTS];
  mat4 uShadowMatrices[LO_MAX_SHADOW_LAYERS];
  ivec4 uLightCount;     // x
  vec4 uShadowParams;    // x depth bias (fraction of far), y normal offset (world units)
};

// glTF metallic-roughness BRDF times the cosine: Lambert diffuse plus a GGX
// lobe (height-correlated Smith visibility, Schlick Fresnel). With uSpecular
// off it is exactly baseColor/pi * (n.l): the analytic tests rely on that.
vec3 brdfCos(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness) {
  float nl = dot(n, l);
  if (nl <= 0.0) return vec3(0.0);
  vec3 diffuse = baseColor * (1.0 - metallic) / LO_PI;
  if (!uSpecular) return diffuse * nl;
  float nv = max(dot(n, v), 1e-4);
  vec3 h = normalize(l + v);
  float nh = max(dot(n, h), 0.0);
  float vh = max(dot(v, h), 0.0);
  float a = max(roughness * roughness, 2e-3);
  float a2 = a * a;
  float dd = nh * nh * (a2 - 1.0) + 1.0;
  float D = a2 / (LO_PI * dd * dd);
  float vis = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));
  vec3 f0 = mix(vec3(0.04), baseColor, metallic);
  vec3 F = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
  return ((1.0 - F) * diffuse + F * (D * vis)) * nl;
}

// The octree lookup, shared with C++ (octree/octree_irradiance.cpp).
#define LO_FETCH_POOL(p) texelFetch(uOctree, p, 0)
#define LO_FETCH_VDL_FLOAT(p) texelFetch(uVdls, p, 0)
#define LO_FETCH_VDL_HALF(p) texelFetch(uVdlsHalf, p, 0)
#define LO_VDLS_HALF uHalfVdls
#include "octree_lookup.h"

vec3 loVdlResponse(LoSurface s, vec3 d) {
  return brdfCos(s.n, s.v, d, s.baseColor, s.metallic, s.roughness);
}

vec3 hashColor(ivec3 c) {
  uint h = uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u;
  h = (h ^ (h >> 13u)) * 1274126177u;
  return vec3(float(h & 255u), float((h >> 8u) & 255u), float((h >> 16u) & 255u)) / 255.0 * 0.8 + 0.2;
}

float shadow(int i, vec3 p, vec3 n, vec3 toLight) {
  Light L = uLights[i];
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  int type = int(L.positionType.w);
  // Normal offset scaled up at grazing angles, where shadow acne appears.
  float nl = clamp(dot(n, toLight), 0.0, 1.0);
  vec3 ps = p + n * uShadowParams.y * (1.0 + 2.0 * (1.0 - nl));
  int layer = first;
  if (type == LO_LIGHT_POINT || type == LO_LIGHT_EMITTER) {
    vec3 d = ps - L.positionType.xyz;
    vec3 ad = abs(d);
    if (ad.x >= ad.y && ad.x >= ad.z) {
      layer += d.x > 0.0 ? 0 : 1;
    } else if (ad.y >= ad.z) {
      layer += d.y > 0.0 ? 2 : 3;
    } else {
      layer += d.z > 0.0 ? 4 : 5;
    }
  }
  vec4 c = uShadowMatrices[layer] * vec4(ps, 1.0);
  vec3 ndc = c.xyz / c.w;
  vec2 uv = ndc.xy * 0.5 + 0.5;
  float ref = L.colorFar.w > 0.0 ? length(ps - L.positionType.xyz) / L.colorFar.w
                                 : ndc.z * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ref > 1.0) return 1.0;
  return texture(uShadowMaps, vec4(uv, float(layer), ref - uShadowParams.x));
}

vec3 direct(vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
  vec3 sum = vec3(0.0);
  for (int i = 0; i < uLightCount.x; ++i) {
    Light L = uLights[i];
    int type = int(L.positionType.w);
    vec3 l;
    vec3 E = L.colorFar.rgb;  // irradiance on a surface facing the light, W/m^2
    if (type == LO_LIGHT_DIRECTIONAL) {
      l = -L.directionRange.xyz;
    } else {
      vec3 tl = L.positionType.xyz - p;
      float dist2 = dot(tl, tl);
      float dist = sqrt(dist2);
      l = tl / dist;
      // Near-field clamp for emitter VPLs: never closer than the patch allows.
      E /= max(dist2, L.params.w);
      float range = L.directionRange.w;
      if (range > 0.0) {
        float r = dist / range;
        E *= pow(clamp(1.0 - r * r * r * r, 0.0, 1.0), 2.0);
      }
      float cd = dot(-l, L.directionRange.xyz);
      if (type == LO_LIGHT_SPOT) {
        E *= L.params.y > L.params.x ? smoothstep(L.params.x, L.params.y, cd) : step(L.params.x, cd);
      } else if (type == LO_LIGHT_EMITTER) {
        E *= max(cd, 0.0);  // Lambertian emitter patch: intensity falls with the cosine
      }
    }
    if (dot(n, l) <= 0.0 || max(E.r, max(E.g, E.b)) <= 0.0) continue;
    sum += brdfCos(n, v, l, baseColor, metallic, roughness) * E * shadow(i, p, n, l);
  }
  return sum;
}

vec3 srgbEncode(vec3 c) {
  c = clamp(c, 0.0, 1.0);
  return mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
}

void main() {
  vec3 v = normalize(uEye - vPosition);
  vec3 n = normalize(vNormal);
  // Surfaces keep their own (interpolated) normal, turned to the side the
  // viewer sees. The side is taken from the geometric normal (screen-space
  // derivatives), not from gl_FrontFacing: scene files do not agree on winding.
  vec3 ng = cross(dFdx(vPosition), dFdy(vPosition));
  if (dot(ng, v) < 0.0) ng = -ng;
  if (dot(n, ng) < 0.0) n = -n;
  // glTF: base colour = factor x texture, sampled per pixel (trilinear,
  // anisotropic where the context has it).
  vec3 baseColor = vBaseColor;
  if (uHasBaseColorTexture) baseColor *= texture(uBaseColorTexture, vUv).rgb;
  float metallic = vMetallicRoughness.x;
  float roughness = vMetallicRoughness.y;

  vec3 radiance = vec3(0.0);
  if (uMode == LO_MODE_VOXELS) {
    uvec4 leaf;
    ivec3 voxel;
    vec3 q = loOctreePosition(vPosition, n, uOctreeOrigin, uVoxelSize, uNormalOffset);
    radiance = loNearestLeaf(q, n, uDepth, uNormalOffset, leaf, voxel) ? hashColor(voxel) : vec3(0.0);
  } else {
    if (uMode == LO_MODE_FULL || uMode == LO_MODE_DIRECT) {
      radiance += vEmission + direct(vPosition, n, v, baseColor, metallic, roughness);
    }
    if (uMode == LO_MODE_FULL || uMode == LO_MODE_INDIRECT) {
      LoSurface s = LoSurface(n, v, baseColor, metallic, roughness);
      radiance += loOctreeIndirect(vPosition, uOctreeOrigin, uVoxelSize, uDepth, uNormalOffset,
                                   uInterpolation, uMaxVdls, s);
    }
  }
  radiance *= uExposureScale;
  fragColor = vec4(uEncodeSrgb ? srgbEncode(radiance) : radiance, 1.0);
}
