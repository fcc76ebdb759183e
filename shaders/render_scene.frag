#version 330 core
// Scene pass: hybrid shading (paper §3): emission + direct light from punctual
// lights and emitter VPLs (shadow maps) + indirect light from the light octree
// (paper §3.2, §4.2, Fig. 6). octree_layout.h is prepended after #version.
// Radiance out, linear, W/(m^2 sr). See docs/render.md.

#define MODE_FULL 0
#define MODE_DIRECT 1
#define MODE_INDIRECT 2
#define MODE_VOXELS 3

#define LIGHT_POINT 0
#define LIGHT_SPOT 1
#define LIGHT_DIRECTIONAL 2
#define LIGHT_EMITTER 3

const int kMaxLights = 32;
const int kMaxShadowLayers = 96;

in vec3 vPosition;  // world
in vec3 vNormal;    // world, interpolated
in vec3 vBaseColor;
in vec2 vMetallicRoughness;
in vec3 vEmission;
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

// std140 twin: GpuLight / LightBlock in src/render/renderer.cpp.
struct Light {
  vec4 positionType;    // xyz world position, w type
  vec4 directionRange;  // xyz unit direction light travels (spot, directional, emitter normal), w range (0 = none)
  vec4 colorFar;        // rgb: W/sr (point, spot, emitter at normal incidence) or W/m^2 (directional); w shadow far
  vec4 params;          // x cos outer, y cos inner, z first shadow layer (-1 = none), w near-field area
};
layout(std140) uniform LightBlock {
  Light uLights[kMaxLights];
  mat4 uShadowMatrices[kMaxShadowLayers];
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

// Octree descent (paper Fig. 6): uDepth texel fetches from the root tile to
// the leaf holding voxel c. False in empty space or outside the cube.
bool lookupLeaf(ivec3 c, out uvec4 leaf) {
  leaf = uvec4(0u);
  int resolution = 1 << uDepth;
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, ivec3(resolution)))) return false;
  ivec3 tile = ivec3(0);
  for (int level = uDepth - 1; level >= 0; --level) {
    ivec3 child = (c >> level) & 1;
    uvec4 t = texelFetch(uOctree, tile * 2 + child, 0);
    if (t.a == LO_FLAG_EMPTY) return false;
    if (t.a != LO_FLAG_INNER) {
      leaf = t;
      return loIsLeaf(t.a);
    }
    tile = ivec3(t.rgb);
  }
  return false;
}

// IEEE binary16 bits -> float (unpackHalf2x16 needs GLSL 4.20; this is 3.30).
float halfToFloat(uint h) {
  uint e = (h >> 10u) & 31u;
  float m = float(h & 1023u);
  float v = e == 0u ? m * exp2(-24.0) : (1.0 + m / 1024.0) * exp2(float(e) - 15.0);
  return (h & 32768u) != 0u ? -v : v;
}

// One VDL texel: rgb irradiance (W/m^2), a packed direction (octree_layout.h).
vec4 fetchVdl(uint index) {
  ivec2 p = ivec2(int(loVdlTexelX(index)), int(loVdlTexelY(index)));
  if (uHalfVdls) {
    uvec4 t = texelFetch(uVdlsHalf, p, 0);
    return vec4(halfToFloat(t.r), halfToFloat(t.g), halfToFloat(t.b), float(t.a));
  }
  return texelFetch(uVdls, p, 0);
}

// Paper §4.2.2: c = sum_i brdf(d_i, v, n) c_i, each VDL a directional light of
// irradiance c_i (on a surface facing d_i), so the cosine n.d_i is applied here.
vec3 shadeLeaf(uvec4 leaf, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
  uint first = loUnpackAddress(leaf.r, leaf.g, leaf.b);
  int count = min(int(leaf.a), uMaxVdls);
  vec3 sum = vec3(0.0);
  for (int i = 0; i < count; ++i) {
    vec4 t = fetchVdl(first + uint(i));
    vec3 d = vec3(loUnpackDirectionX(t.a), loUnpackDirectionY(t.a), loUnpackDirectionZ(t.a));
    sum += brdfCos(n, v, d, baseColor, metallic, roughness) * t.rgb;
  }
  return sum;
}

vec3 hashColor(ivec3 c) {
  uint h = uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u;
  h = (h ^ (h >> 13u)) * 1274126177u;
  return vec3(float(h & 255u), float((h >> 8u) & 255u), float((h >> 16u) & 255u)) / 255.0 * 0.8 + 0.2;
}

// The voxel under a surface point: q is the point in voxel units, already
// moved by uNormalOffset voxels along the normal towards the viewer; a surface
// lying on a voxel face is then looked up in the voxel in front of it, and if
// that one is empty, in the voxel behind it.
bool nearestLeaf(vec3 q, vec3 n, out uvec4 leaf, out ivec3 voxel) {
  voxel = ivec3(floor(q));
  if (lookupLeaf(voxel, leaf)) return true;
  voxel = ivec3(floor(q - 2.0 * uNormalOffset * n));
  return lookupLeaf(voxel, leaf);
}

vec3 indirect(vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
  vec3 q = (p - uOctreeOrigin) / uVoxelSize + uNormalOffset * n;
  if (uInterpolation) {
    // Trilinear over the 8 voxels around q (paper §4.2.1); empty neighbours
    // are left out and the remaining weights renormalized, so light never
    // leaks in from empty space or fades at the edge of the geometry.
    vec3 u = q - 0.5;
    ivec3 base = ivec3(floor(u));
    vec3 f = u - floor(u);
    vec3 sum = vec3(0.0);
    float weightSum = 0.0;
    for (int k = 0; k < 8; ++k) {
      ivec3 o = ivec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
      vec3 w3 = mix(1.0 - f, f, vec3(o));
      float w = w3.x * w3.y * w3.z;
      if (w <= 0.0) continue;
      uvec4 leaf;
      if (lookupLeaf(base + o, leaf)) {
        sum += w * shadeLeaf(leaf, n, v, baseColor, metallic, roughness);
        weightSum += w;
      }
    }
    if (weightSum > 0.0) return sum / weightSum;
  }
  uvec4 leaf;
  ivec3 voxel;
  if (nearestLeaf(q, n, leaf, voxel)) return shadeLeaf(leaf, n, v, baseColor, metallic, roughness);
  return vec3(0.0);
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
  if (type == LIGHT_POINT || type == LIGHT_EMITTER) {
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
    if (type == LIGHT_DIRECTIONAL) {
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
      if (type == LIGHT_SPOT) {
        E *= L.params.y > L.params.x ? smoothstep(L.params.x, L.params.y, cd) : step(L.params.x, cd);
      } else if (type == LIGHT_EMITTER) {
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
  vec3 baseColor = vBaseColor;
  float metallic = vMetallicRoughness.x;
  float roughness = vMetallicRoughness.y;

  vec3 radiance = vec3(0.0);
  if (uMode == MODE_VOXELS) {
    uvec4 leaf;
    ivec3 voxel;
    vec3 q = (vPosition - uOctreeOrigin) / uVoxelSize + uNormalOffset * n;
    radiance = nearestLeaf(q, n, leaf, voxel) ? hashColor(voxel) : vec3(0.0);
  } else {
    if (uMode == MODE_FULL || uMode == MODE_DIRECT) {
      radiance += vEmission + direct(vPosition, n, v, baseColor, metallic, roughness);
    }
    if (uMode == MODE_FULL || uMode == MODE_INDIRECT) {
      radiance += indirect(vPosition, n, v, baseColor, metallic, roughness);
    }
  }
  radiance *= uExposureScale;
  fragColor = vec4(uEncodeSrgb ? srgbEncode(radiance) : radiance, 1.0);
}
