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
in vec2 vNormalUv;
in vec2 vMetallicRoughnessUv;
in vec2 vOcclusionUv;
in vec2 vEmissiveUv;
in vec3 vLightmap;  // lightmap u, v, page
in vec4 vTangent;   // glTF TANGENT, w = +-1; w = 0: derive the tangent from the UVs
out vec4 fragColor;

uniform usampler3D uOctree;  // RGBA8UI pool of 2x2x2 tiles
uniform sampler2D uVdls;       // RGBA32F: irradiance, packed direction
uniform usampler2D uVdlsHalf;  // RGBA16UI: half-float bits of irradiance, packed direction
uniform bool uHalfVdls;        // which of the two holds the VDLs
uniform bool uCompactVdls;     // the 16-bit texels hold compact (RGB9E5) irradiance
uniform float uVdlScale;       // ... times this scale
uniform int uShTerms;          // 0: the leaves hold VDLs; else SH terms per leaf
uniform sampler2DArrayShadow uShadowMaps;
uniform sampler2DArray uShadowDepths;  // the same maps read as depths (PCSS blocker search)
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
uniform sampler2D uNormalTexture;  // tangent-space normal map, linear [0, 1] texels
uniform bool uHasNormalTexture;
uniform float uNormalScale;
uniform sampler2D uMetallicRoughnessTexture;  // linear: G roughness, B metallic
uniform bool uHasMetallicRoughnessTexture;
uniform sampler2D uOcclusionTexture;  // linear: R ambient occlusion
uniform bool uHasOcclusionTexture;
uniform float uOcclusionStrength;
uniform sampler2D uEmissiveTexture;  // linear RGB emission map (sRGB decoded at load)
uniform bool uHasEmissiveTexture;
uniform float uEmissionScale;  // 1; 0 while the probe is captured if emitters are lights
uniform int uAlphaMode;      // LO_ALPHA_OPAQUE, LO_ALPHA_MASK or LO_ALPHA_BLEND (glTF alphaMode)
uniform float uBaseAlpha;    // baseColorFactor's alpha
uniform float uAlphaCutoff;  // glTF alphaCutoff (mask)
uniform float uTransmission;  // KHR_materials_transmission of this draw; 0 = opaque
uniform vec3 uViewForward;     // the camera's unit view direction (render space)
uniform vec4 uCascadeFar;      // view depth where each sun cascade ends
uniform vec4 uCascadeTexel;    // world size of a texel of each cascade
uniform vec4 uCascadeDepth;    // world depth range of each cascade's map
uniform bool uAtlas;           // indirect light from the lightmap atlas, not the octree
uniform sampler2DArray uAtlasIrradiance;  // E (W/m^2) per texel, a layer per page (RGB9E5)
uniform sampler2DArray uAtlasDirection;   // unit mean VDL direction per texel (RGBA8 snorm)
uniform bool uHasProbe;        // environment reflections from the probe (RenderParams::reflections)
uniform samplerCube uProbe;    // the lit scene seen from the render-space origin, mipmapped
uniform vec3 uProbeBoxMin;     // the scene's bounds (render space): the parallax box
uniform vec3 uProbeBoxMax;
uniform float uProbeMaxLod;
uniform sampler2D uBehind;    // the opaque image under transmissive surfaces (as output)
uniform float uThickness;     // KHR_materials_volume thickness; 0 = thin-walled
uniform float uIor;           // KHR_materials_ior
uniform mat4 uViewProj;       // render space -> clip (the vertex shader's)

// std140 twin: GpuLight / LightBlock in src/render/renderer.cpp.
struct Light {
  vec4 positionType;    // xyz world position, w type
  vec4 directionRange;  // xyz unit direction light travels (spot, directional, emitter normal), w range (0 = none)
  vec4 colorFar;        // rgb: W/sr (point, spot, emitter at normal incidence) or W/m^2 (directional); w shadow far
  vec4 params;          // x cos outer, y cos inner, z first shadow layer (-1 = none), w near-field area
  vec4 corner0;         // area light: triangle corners (render space); corner0.w sqrt(area)
  vec4 corner1;
  vec4 corner2;
};
layout(std140) uniform LightBlock {
  Light uLights[LO_MAX_LIGHTS];
  mat4 uShadowMatrices[LO_MAX_SHADOW_LAYERS];
  ivec4 uLightCount;     // x lights, y of them area lights (the last y)
  vec4 uShadowParams;    // x depth bias (fraction of far), y normal offset (world units)
};

// glTF metallic-roughness BRDF times the cosine: Lambert diffuse plus a GGX
// lobe (height-correlated Smith visibility, Schlick Fresnel). With uSpecular
// off it is exactly baseColor/pi * (n.l): the analytic tests rely on that.
// `specularWeight` scales the GGX lobe alone (the VDLs' share of a surface's
// specular light when the reflection probe takes the rest).
// The two lobes of the BRDF (no cosine) towards l (unit, nl = n.l > 0):
// (1 - F) diffuse and F D V, GGX of alpha a.
void brdfLobes(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float a,
               out vec3 diffuse, out vec3 specular) {
  float nl = max(dot(n, l), 1e-4);
  diffuse = baseColor * (1.0 - metallic) * (1.0 - uTransmission) / LO_PI;
  float nv = max(dot(n, v), 1e-4);
  vec3 h = normalize(l + v);
  float nh = max(dot(n, h), 0.0);
  float vh = clamp(dot(v, h), 0.0, 1.0);  // pow(1 - vh, 5) is NaN for vh a rounding above 1
  float a2 = a * a;
  float dd = nh * nh * (a2 - 1.0) + 1.0;
  float D = a2 / (LO_PI * dd * dd);
  float vis = 0.5 / (nl * sqrt(nv * nv * (1.0 - a2) + a2) + nv * sqrt(nl * nl * (1.0 - a2) + a2));
  vec3 f0 = mix(vec3(0.04), baseColor, metallic);
  vec3 F = f0 + (1.0 - f0) * pow(1.0 - vh, 5.0);
  diffuse *= 1.0 - F;
  specular = F * (D * vis);
}

vec3 brdfCosWeighted(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness,
                     float specularWeight) {
  float nl = dot(n, l);
  if (nl <= 0.0) return vec3(0.0);
  if (!uSpecular) return baseColor * (1.0 - metallic) * (1.0 - uTransmission) / LO_PI * nl;
  vec3 diffuse, specular;
  brdfLobes(n, v, l, baseColor, metallic, max(roughness * roughness, 2e-3), diffuse, specular);
  return (diffuse + specularWeight * specular) * nl;
}

vec3 brdfCos(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness) {
  return brdfCosWeighted(n, v, l, baseColor, metallic, roughness, 1.0);
}

// The probe's share of a surface's specular indirect light: all of it up to
// roughness LO_PROBE_FULL, none above LO_PROBE_NONE (the VDLs' directions
// light broad lobes well; a handful of VDLs cannot show a sharp reflection).
float probeWeight(float roughness) {
  return uHasProbe && uSpecular ? 1.0 - smoothstep(LO_PROBE_FULL, LO_PROBE_NONE, roughness) : 0.0;
}

// Specular light from the probe (paper §5.1, Fig. 12: cube maps with the
// VDLs): the reflected ray is intersected with the scene's bounds and the
// probe read towards that point (box projection, parallax-corrected: right
// where the scene is a box around the probe), at a mip level growing with
// roughness, times the split-sum environment BRDF in Karis's analytic fit
// (Physically Based Shading on Mobile, 2014).
vec3 probeSpecular(vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
  vec3 r = reflect(-v, n);
  r = mix(r, vec3(1e-6), equal(r, vec3(0.0)));  // no 0/0 below
  vec3 t1 = (uProbeBoxMax - p) / r, t2 = (uProbeBoxMin - p) / r;
  vec3 tf = max(t1, t2);
  float t = max(min(min(tf.x, tf.y), tf.z), 0.0);
  vec3 dir = p + r * t;  // from the probe at the render-space origin
  vec3 radiance = textureLod(uProbe, dir, roughness * uProbeMaxLod).rgb;
  float nv = clamp(dot(n, v), 0.0, 1.0);
  const vec4 c0 = vec4(-1.0, -0.0275, -0.572, 0.022);
  const vec4 c1 = vec4(1.0, 0.0425, 1.04, -0.04);
  vec4 q = roughness * c0 + c1;
  float a004 = min(q.x * q.x, exp2(-9.28 * nv)) * q.x + q.y;
  vec2 ab = vec2(-1.04, 1.04) * a004 + q.zw;
  vec3 f0 = mix(vec3(0.04), baseColor, metallic);
  return radiance * (f0 * ab.x + ab.y);
}

// The octree lookup, shared with C++ (octree/octree_irradiance.cpp).
#define LO_FETCH_POOL(p) texelFetch(uOctree, p, 0)
#define LO_FETCH_VDL_FLOAT(p) texelFetch(uVdls, p, 0)
#define LO_FETCH_VDL_HALF(p) texelFetch(uVdlsHalf, p, 0)
#define LO_VDLS_HALF uHalfVdls
#define LO_VDLS_COMPACT uCompactVdls
#define LO_VDL_SCALE uVdlScale
#define LO_SH_TERMS uShTerms
#include "octree_lookup.h"

// The VDLs light the diffuse lobe and the share of the specular one that the
// probe does not (gVdlSpecular, set by main).
float gVdlSpecular = 1.0;
vec3 loVdlResponse(LoSurface s, vec3 d) {
  return brdfCosWeighted(s.n, s.v, d, s.baseColor, s.metallic, s.roughness, gVdlSpecular);
}

vec3 hashColor(ivec3 c) {
  uint h = uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u;
  h = (h ^ (h >> 13u)) * 1274126177u;
  return vec3(float(h & 255u), float((h >> 8u) & 255u), float((h >> 16u) & 255u)) / 255.0 * 0.8 + 0.2;
}

// Direct light (lights, shadow maps, area lights) is compiled only into the
// program of the modes that draw it (LO_DIRECT_LIGHT, render/renderer.cpp):
// on a software rasterizer its code alone doubles the cost of the others.
#ifdef LO_DIRECT_LIGHT
// Cube face of direction d: the layer offset of a point light's six maps.
int cubeFace(vec3 d) {
  vec3 ad = abs(d);
  if (ad.x >= ad.y && ad.x >= ad.z) return d.x > 0.0 ? 0 : 1;
  if (ad.y >= ad.z) return d.y > 0.0 ? 2 : 3;
  return d.z > 0.0 ? 4 : 5;
}

// The point a shadow map is read at: p moved along n by the normal offset,
// scaled up at grazing angles (toLight the direction to the light), where
// shadow acne appears.
vec3 shadowPoint(vec3 p, vec3 n, vec3 toLight) {
  float nl = clamp(dot(n, toLight), 0.0, 1.0);
  return p + n * uShadowParams.y * (1.0 + 2.0 * (1.0 - nl));
}

// Irradiance on the surface (p, n) from a Lambertian triangle (a, b, c) of
// unit radiance: the projected solid angle of the triangle clipped to the
// surface's upper hemisphere, 1/2 sum_i theta_i n.unit(u_i x u_i+1) over its
// edges (Lambert's formula; Arvo 1995), exact. `lightCentre` is the clipped
// polygon's vertex mean, the direction the BRDF is evaluated in.
float polygonIrradiance(vec3 p, vec3 n, vec3 a, vec3 b, vec3 c, out vec3 lightCentre) {
  vec3 q[3] = vec3[3](a - p, b - p, c - p);
  vec3 poly[4];
  int count = 0;
  for (int i = 0; i < 3; ++i) {
    vec3 s = q[i], e = q[(i + 1) % 3];
    float ds = dot(n, s), de = dot(n, e);
    if (ds >= 0.0 && count < 4) {
      poly[count] = s;
      ++count;
    }
    if ((ds >= 0.0) != (de >= 0.0) && count < 4) {
      poly[count] = mix(s, e, ds / (ds - de));
      ++count;
    }
  }
  lightCentre = p;
  if (count < 3) return 0.0;
  float sum = 0.0;
  vec3 mean = vec3(0.0);
  for (int i = 0; i < count; ++i) {
    vec3 u0 = normalize(poly[i]), u1 = normalize(poly[(i + 1) % count]);
    vec3 cr = cross(u0, u1);
    float s = length(cr);
    if (s > 1e-9) sum += atan(s, dot(u0, u1)) * dot(cr, n) / s;
    mean += poly[i];
  }
  lightCentre = p + mean / float(count);
  return 0.5 * abs(sum);
}

// The point of triangle (a, b, c) nearest p (Ericson, Real-Time Collision
// Detection, 5.1.5).
vec3 closestOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  float denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

// Soft shadow of area light i (PCSS, Fernando 2005) from its shadow cube at
// the triangle's centre: the blockers found in the region of the map that
// can hide part of the light from p give their mean distance d_b; the
// penumbra's angular half-width is then h (d_r - d_b) / (d_r d_b), h half
// the light's size and d_r the receiver's distance, and the map is filtered
// over it with hardware-compared taps (a box filter of the shadow edge:
// smooth and monotonic, no bands). Each tap is compared with the distance of
// the receiver's tangent plane in the tap's own direction, not with p's, so
// that a wide kernel on a surface the light sees at a grazing angle does not
// shadow the surface itself; directions behind the emitter's plane carry no
// light, so what the map holds there (the ceiling around a ceiling light)
// blocks nothing.
// Distance / far of the receiver's tangent plane (through the light centre
// lc's offset `plane` = (ps - lc).n) along the shadow-map direction of uv t,
// or a negative value for directions behind the emitter (normal nE).
float receiverDepth(mat4 clipToRender, vec2 t, vec3 lc, vec3 n, vec3 nE, float plane, float far) {
  vec4 w = clipToRender * vec4(t * 2.0 - 1.0, 0.0, 1.0);
  vec3 dir = normalize(w.xyz / w.w - lc);
  if (dot(dir, nE) <= 0.0) return -1.0;
  float dn = dot(dir, n);
  float receiver = dn < -1e-4 || dn > 1e-4 ? plane / dn : far;
  return receiver > 0.0 ? min(receiver / far, 1.0) : 1.0;
}

float areaShadow(int i, vec3 p, vec3 n, vec3 toLight) {
  // The light read in place (a copy of the 7-vec4 struct is dear on llvmpipe).
#define L uLights[i]
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  vec3 ps = shadowPoint(p, n, toLight);
  vec3 lc = L.positionType.xyz;
  vec3 d = ps - lc;
  int layer = first + cubeFace(d);
  vec4 c = uShadowMatrices[layer] * vec4(ps, 1.0);
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  float far = L.colorFar.w;
  float dr = length(d);
  if (dr / far > 1.0) return 1.0;
  mat4 clipToRender = inverse(uShadowMatrices[layer]);
  float plane = dot(d, n);  // the receiver's tangent plane, as seen from the light centre
  float h = 0.5 * L.corner0.w;
  // Blockers from 0.3 d_r out can hide the light: search that cone (in a
  // cube face, an angle's tangent t spans t/2 in uv).
  float search = min(0.5 * h * 0.7 / (0.3 * dr), 0.2);
  // 4 x 4 taps on a grid turned by atan(1/4), so that the blocker estimate,
  // and with it the filter's width, changes in small steps along any edge.
  const int kTaps = 4;
  const vec2 kSearchTurn = vec2(0.970143, 0.242536);  // (cos, sin) of atan(1/4)
  float blockers = 0.0, blockerSum = 0.0;
  for (int y = 0; y < kTaps; ++y) {
    for (int x = 0; x < kTaps; ++x) {
      vec2 g = (vec2(x, y) + 0.5) / float(kTaps) * 2.0 - 1.0;
      vec2 t = uv + vec2(kSearchTurn.x * g.x - kSearchTurn.y * g.y,
                         kSearchTurn.y * g.x + kSearchTurn.x * g.y) * search;
      float receiver = receiverDepth(clipToRender, t, lc, n, L.directionRange.xyz, plane, far);
      // Behind the emitter's plane no light travels: nothing there blocks it.
      if (receiver < 0.0) continue;
      float stored = texture(uShadowDepths, vec3(t, float(layer))).r;
      if (stored < receiver - uShadowParams.x) {
        blockers += 1.0;
        blockerSum += stored * far;
      }
    }
  }
  if (blockers == 0.0) return 1.0;
  float db = max(blockerSum / blockers, 1e-4 * far);
  float texel = 1.0 / float(textureSize(uShadowDepths, 0).x);
  float radius = clamp(0.5 * h * max(dr - db, 0.0) / (dr * db), texel, 0.2);
  // 6 x 6 taps on a grid turned by atan(1/6) (a rook pattern: every edge
  // direction but a few sees 36 distinct tap positions, not 6 columns): 36
  // levels between umbra and light, each blurred by the hardware 2x2
  // comparison, below what the eye resolves as a band.
  const int kFilterTaps = 6;
  const vec2 kTurn = vec2(0.986394, 0.164399);  // (cos, sin) of atan(1/6)
  float lit = 0.0;
  for (int y = 0; y < kFilterTaps; ++y) {
    for (int x = 0; x < kFilterTaps; ++x) {
      vec2 g = (vec2(x, y) + 0.5) / float(kFilterTaps) * 2.0 - 1.0;
      vec2 t = uv + vec2(kTurn.x * g.x - kTurn.y * g.y, kTurn.y * g.x + kTurn.x * g.y) * radius;
      float receiver = receiverDepth(clipToRender, t, lc, n, L.directionRange.xyz, plane, far);
      lit += receiver < 0.0 ? 1.0
                            : texture(uShadowMaps, vec4(t, float(layer), receiver - uShadowParams.x));
    }
  }
  return lit / float(kFilterTaps * kFilterTaps);
}

// Shadow of directional light i from its cascades (render/renderer.cpp
// fitCascades): the cascade by the point's view depth, a slope-scaled depth
// bias, and a filter that cannot leak: the map is read as nearest texels, a tap is
// lit only when the 2 x 2 texels around it all are (an erosion of the lit
// area by one texel), and 3 x 3 such taps one texel apart are tent-weighted
// by the point's position between texels (smooth as it moves). A floor point
// next to the wall of a closed room under the sun thus never reads the lit
// ground outside the wall through a texel that straddles the wall's base;
// the price is a shadow one texel larger, on the lit side.
// The fragment's unit geometric normal, turned to the viewer (set by main):
// shadow lookups (receiver plane, offsets, biases) follow the surface's real
// plane, not the normal map's or the interpolated normal's (a tilted
// receiver plane shadows the surface by itself).
vec3 gGeometricNormal;

float sunShadow(int i, vec3 p, vec3 n, vec3 toLight) {
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  float depth = dot(p - uEye, uViewForward);
  int c = depth < uCascadeFar.x ? 0 : depth < uCascadeFar.y ? 1 : depth < uCascadeFar.z ? 2 : 3;
  // Slope-scaled depth bias, no normal offset: a point lifted off the floor
  // by a normal offset rises above the base of a wall next to it in the
  // sun's view and reads that wall's texels as lit. The taps reach two
  // texels out, over which a surface at angle theta to the light changes
  // depth by 2 tan(theta) texels.
  float nl = clamp(abs(dot(gGeometricNormal, toLight)), 0.05, 1.0);
  float slope = min(sqrt(1.0 - nl * nl) / nl, 4.0);
  int layer = first + c;
  vec4 clip = uShadowMatrices[layer] * vec4(p, 1.0);
  vec3 ndc = clip.xyz / clip.w;
  vec2 uv = ndc.xy * 0.5 + 0.5;
  float ref = ndc.z * 0.5 + 0.5 - (0.5 + 2.5 * slope) * uCascadeTexel[c] / uCascadeDepth[c];
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ref > 1.0) return 1.0;
  int size = textureSize(uShadowDepths, 0).x;
  vec2 t = uv * float(size) - 0.5;
  ivec2 base = ivec2(floor(t)) - 1;
  vec2 f = t - floor(t);
  // 4 x 4 nearest comparisons around the point.
  float lit[16];
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      ivec2 q = clamp(base + ivec2(x, y), ivec2(0), ivec2(size - 1));
      lit[4 * y + x] = texelFetch(uShadowDepths, ivec3(q, layer), 0).r >= ref ? 1.0 : 0.0;
    }
  }
  // Each of the 2 x 2 nearest texel centres is lit only if the 3 x 3 texels
  // around it all are; the point interpolates those four bilinearly.
  float e[4];
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 2; ++x) {
      float m = 1.0;
      for (int dy = 0; dy < 3; ++dy) {
        for (int dx = 0; dx < 3; ++dx) m = min(m, lit[4 * (y + dy) + x + dx]);
      }
      e[2 * y + x] = m;
    }
  }
  float sum = mix(mix(e[0], e[1], f.x), mix(e[2], e[3], f.x), f.y);
  return sum;
}

float shadow(int i, vec3 p, vec3 n, vec3 toLight) {
  // The light read in place (a copy of the 7-vec4 struct is dear on llvmpipe).
#define L uLights[i]
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  int type = int(L.positionType.w);
  vec3 ps = shadowPoint(p, n, toLight);
  int layer = first;
  if (type == LO_LIGHT_POINT || type == LO_LIGHT_EMITTER) layer += cubeFace(ps - L.positionType.xyz);
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
  // Area lights come last in the block (uLightCount.y of the uLightCount.x):
  // their own loop keeps the other lights' loop small, which llvmpipe runs
  // several times faster.
  for (int i = uLightCount.x - uLightCount.y; i < uLightCount.x; ++i) {
#define L uLights[i]
    // One-sided Lambertian emitter: nothing behind its plane is lit, and
    // a point in the plane (the ceiling around a ceiling light) sees it at
    // grazing incidence: nothing either (the clipped edge sum would be
    // all rounding there).
    if (dot(p - L.corner0.xyz, L.directionRange.xyz) <= 1e-3 * L.corner0.w) continue;
    vec3 lightCentre;
    float solid = polygonIrradiance(p, n, L.corner0.xyz, L.corner1.xyz, L.corner2.xyz, lightCentre);
    if (solid <= 0.0) continue;
    vec3 la = normalize(lightCentre - p);
    float visible = areaShadow(i, p, gGeometricNormal, la);
    if (visible <= 0.0) continue;
    // Diffuse: the lobe in the direction of the light's visible part times
    // the exact projected solid angle.
    vec3 diffuse, specular;
    float a = max(roughness * roughness, 2e-3);
    brdfLobes(n, v, la, baseColor, metallic, a, diffuse, specular);
    if (!uSpecular) diffuse = baseColor * (1.0 - metallic) * (1.0 - uTransmission) / LO_PI;
    vec3 f = diffuse * solid;
    if (uSpecular) {
      // Specular: a representative point (Karis 2013): the point of the
      // triangle nearest the reflected ray, the GGX lobe evaluated towards
      // it with its own alpha and scaled by (alpha / alpha')^2, alpha'
      // widened by the light's angular radius: a glossy surface shows the
      // light's shape, not a highlight of the lobe's size at its centre.
      vec3 r = reflect(-v, n);
      vec3 nE = L.directionRange.xyz;
      float towards = dot(r, nE);
      vec3 q = lightCentre;
      if (towards < -1e-4) q = p + r * max(dot(L.corner0.xyz - p, nE) / towards, 0.0);
      q = closestOnTriangle(q, L.corner0.xyz, L.corner1.xyz, L.corner2.xyz);
      vec3 ls = normalize(q - p);
      float nls = dot(n, ls);
      if (nls > 0.0) {
        float distance = length(lightCentre - p);
        float radius = L.corner0.w * 0.5641896;  // sqrt(area / pi)
        float wide = clamp(a + radius / (2.0 * distance), a, 1.0);
        vec3 dRep, sRep;
        brdfLobes(n, v, ls, baseColor, metallic, a, dRep, sRep);
        float omega = solid / max(dot(n, la), 1e-4);  // the light's solid angle
        f += sRep * (a * a / (wide * wide)) * nls * omega;
      }
    }
    sum += f * L.colorFar.rgb * visible;
#undef L
  }
  for (int i = 0; i < uLightCount.x - uLightCount.y; ++i) {
    // The light read in place (a copy of the 7-vec4 struct is dear on llvmpipe).
#define L uLights[i]
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
    float visible = type == LO_LIGHT_DIRECTIONAL ? sunShadow(i, p, gGeometricNormal, l)
                                                   : shadow(i, p, gGeometricNormal, l);
    sum += brdfCos(n, v, l, baseColor, metallic, roughness) * E * visible;
  }
  return sum;
}

#endif  // LO_DIRECT_LIGHT

// The normal map's normal in world space. With the file's TANGENT (vTangent.w
// = +-1) the frame is its tangent and w cross(n, t), turned with the normal
// to the side seen (side = -1 when n was flipped to face the viewer), as the
// glTF sample viewer does. Without it the tangent is the direction of +u on
// the surface, from screen-space derivatives of the position and the UVs,
// and the bitangent cross(n, t), glTF's convention for tangent.w = 1
// (mirrored UVs are not detected). Scene::shadingNormal is the C++ twin.
vec3 perturbNormal(vec3 n, vec3 p, vec2 uv, float side) {
  if (abs(vTangent.w) > 0.5) {
    vec3 n0 = n * side;
    vec3 t0 = vTangent.xyz - n0 * dot(n0, vTangent.xyz);
    if (dot(t0, t0) > 1e-20) {
      t0 = normalize(t0);
      vec3 b0 = cross(n0, t0) * sign(vTangent.w);
      vec3 m = texture(uNormalTexture, uv).rgb * 2.0 - 1.0;
      m.xy *= uNormalScale;
      return normalize((t0 * m.x + b0 * m.y) * side + n * m.z);
    }
  }
  vec3 dpdx = dFdx(p), dpdy = dFdy(p);
  vec2 duvdx = dFdx(uv), duvdy = dFdy(uv);
  float det = duvdx.x * duvdy.y - duvdy.x * duvdx.y;
  if (abs(det) < 1e-20) return n;
  vec3 t = (duvdy.y * dpdx - duvdx.y * dpdy) / det;
  t = t - n * dot(n, t);
  if (dot(t, t) < 1e-20) return n;
  t = normalize(t);
  vec3 b = cross(n, t);
  vec3 m = texture(uNormalTexture, uv).rgb * 2.0 - 1.0;
  m.xy *= uNormalScale;
  return normalize(mat3(t, b, n) * m);
}

vec3 srgbDecode(vec3 c) {
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(vec3(0.04045), c));
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
  float side = 1.0;
  if (dot(n, ng) < 0.0) {
    n = -n;
    side = -1.0;
  }
#ifdef LO_DIRECT_LIGHT
  gGeometricNormal = normalize(ng);
#endif
  // The interpolated normal, before the normal map: it picks the octree's
  // surface layers (octree_lookup.h), as the bake's photons were sorted by
  // the geometry's own normals.
  vec3 nLayer = n;
  if (uHasNormalTexture) n = perturbNormal(n, vPosition, vNormalUv, side);
  // glTF: base colour = factor x texture, sampled per pixel (trilinear,
  // anisotropic where the context has it).
  vec3 baseColor = vBaseColor;
  float alpha = uBaseAlpha;
  if (uHasBaseColorTexture) {
    vec4 texel = texture(uBaseColorTexture, vUv);
    baseColor *= texel.rgb;
    alpha *= texel.a;
  }
  // glTF alpha modes: a mask cuts the surface out below the cutoff (the
  // depth pre-pass and the shadow maps cut the same fragments,
  // render_alpha.h); a blended surface covers `alpha` of what lies behind it.
  // The cut is made at the end: implicit-derivative texture reads after a
  // discard are undefined in non-uniform control flow.
  bool cutOut = uAlphaMode == LO_ALPHA_MASK && alpha < uAlphaCutoff;
  float coverage = uAlphaMode == LO_ALPHA_BLEND ? clamp(alpha, 0.0, 1.0) : 1.0;
  vec3 emission = vEmission;
  if (uHasEmissiveTexture) emission *= texture(uEmissiveTexture, vEmissiveUv).rgb;
  float metallic = vMetallicRoughness.x;
  float roughness = vMetallicRoughness.y;
  if (uHasMetallicRoughnessTexture) {
    vec3 mr = texture(uMetallicRoughnessTexture, vMetallicRoughnessUv).rgb;
    roughness *= mr.g;
    metallic *= mr.b;
  }

  vec3 radiance = vec3(0.0);
#ifndef LO_ATLAS_LIGHTING
  if (uMode == LO_MODE_VOXELS) {
    uvec4 leaf;
    ivec3 voxel;
    vec3 q = loOctreePosition(vPosition, n, uOctreeOrigin, uVoxelSize, uNormalOffset);
    radiance = loNearestLeaf(q, n, uDepth, uNormalOffset, leaf, voxel) ? hashColor(voxel) : vec3(0.0);
  } else
#endif
  {
#ifdef LO_DIRECT_LIGHT
    if (uMode == LO_MODE_FULL || uMode == LO_MODE_DIRECT) {
      radiance += emission * uEmissionScale + direct(vPosition, n, v, baseColor, metallic, roughness);
    }
#endif
    if (uMode == LO_MODE_FULL || uMode == LO_MODE_INDIRECT) {
      LoSurface s = LoSurface(n, v, baseColor, metallic, roughness, nLayer);
      // glTF: occlusion darkens the indirect light only.
      float occlusion = uHasOcclusionTexture
                            ? 1.0 + uOcclusionStrength * (texture(uOcclusionTexture, vOcclusionUv).r - 1.0)
                            : 1.0;
      float probe = probeWeight(roughness);
      gVdlSpecular = 1.0 - probe;
      vec3 indirect;
      // The atlas programs (LO_ATLAS_LIGHTING) leave the octree walk out: on
      // a software rasterizer the code's mere presence costs (renderer.cpp).
#ifdef LO_ATLAS_LIGHTING
      if (true) {
#else
      if (uAtlas) {
#endif
        // Render to atlas (paper §4.2.3): one VDL rebuilt from the texel's
        // irradiance E (baked for the interpolated vertex normal) and mean
        // direction d: E / (n_bake . d) along d, through the same BRDF.
        vec3 E = texture(uAtlasIrradiance, vLightmap).rgb;
        vec3 d = texture(uAtlasDirection, vLightmap).rgb;
        float dl = length(d);
        indirect = vec3(0.0);
        if (dl > 1e-3) {
          d /= dl;
          vec3 nb = normalize(vNormal);
          if (dot(nb, ng) < 0.0) nb = -nb;
          indirect = loVdlResponse(s, d) * E / max(dot(nb, d), 0.05);
        }
      } else {
#ifndef LO_ATLAS_LIGHTING
        indirect = loOctreeIndirect(vPosition, uOctreeOrigin, uVoxelSize, uDepth, uNormalOffset,
                                    uInterpolation, uMaxVdls, s);
#endif
      }
      if (probe > 0.0) {
        indirect += probe * probeSpecular(vPosition, n, v, baseColor, metallic, roughness);
      }
      radiance += occlusion * indirect;
    }
  }
  if (uTransmission > 0.0) {
    // Thin-walled transmission (glTF without KHR_materials_volume): the
    // surface replaces that share of its diffuse lobe by the scene behind
    // it, seen straight through, tinted by the base colour and weighted by
    // the Fresnel transmittance at the viewing angle (Schlick, F0 = 0.04).
    // Thin-walled: seen straight through. With a volume: screen-space
    // refraction, the image read where the refracted ray leaves a slab of the
    // material's thickness (an approximation: the real exit depends on the
    // shape behind the surface).
    vec3 behind;
    if (uThickness > 0.0) {
      vec3 t = refract(-v, n, 1.0 / max(uIor, 1.0));
      if (dot(t, t) == 0.0) t = -v;
      vec4 clip = uViewProj * vec4(vPosition + t * uThickness, 1.0);
      vec2 uv = clamp(clip.xy / clip.w * 0.5 + 0.5, vec2(0.0), vec2(1.0));
      behind = textureLod(uBehind, uv, 0.0).rgb;
    } else {
      behind = texelFetch(uBehind, ivec2(gl_FragCoord.xy), 0).rgb;
    }
    if (uEncodeSrgb) behind = srgbDecode(behind);
    behind /= uExposureScale;
    float fresnel = 0.04 + 0.96 * pow(1.0 - clamp(dot(n, v), 0.0, 1.0), 5.0);
    radiance += uTransmission * (1.0 - fresnel) * baseColor * behind;
  }
  if (cutOut) discard;
  radiance *= uExposureScale;
  fragColor = vec4(uEncodeSrgb ? srgbEncode(radiance) : radiance, coverage);
}
