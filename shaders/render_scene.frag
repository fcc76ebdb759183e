#version 330 core
// Scene pass: hybrid shading (paper §3): emission + direct light from punctual
// lights and emitter VPLs (shadow maps) + indirect light from the light octree
// (paper §3.2, §4.2, Fig. 6), whose lookup is shaders/octree_lookup.h, shared
// with C++. Radiance out, linear, W/(m^2 sr). See docs/render.md.
// `#include "x"` lines are replaced by the file (render/gl_util.cpp).
#include "octree_layout.h"
#include "render_constants.h"
#include "render_scene_inputs.glsl"
#include "render_lights.h"
#include "material_brdf.h"
#include "render_scene_probe.glsl"

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
  return loBrdfCosWeighted(s.n, s.v, d, s.baseColor, s.metallic, s.roughness, uTransmission,
                           uDielectric, uSpecular, gVdlSpecular);
}

vec3 hashColor(ivec3 c) {
  uint h = uint(c.x) * 73856093u ^ uint(c.y) * 19349663u ^ uint(c.z) * 83492791u;
  h = (h ^ (h >> 13u)) * 1274126177u;
  return vec3(float(h & 255u), float((h >> 8u) & 255u), float((h >> 16u) & 255u)) / 255.0 * 0.8 + 0.2;
}

// Direct light (lights, shadow maps, area lights) is compiled only into the
// program of the modes that draw it (LO_DIRECT_LIGHT, render/scene_pass.cpp):
// on a software rasterizer its code alone doubles the cost of the others.
#ifdef LO_DIRECT_LIGHT
#include "render_scene_shadows.glsl"
#include "render_scene_lights.glsl"
#endif  // LO_DIRECT_LIGHT

#include "render_scene_surface.glsl"

// Indirect light at the fragment (paper §3.2): the octree's VDLs (or the
// lightmap atlas's one rebuilt VDL) through the BRDF, and the probe's share
// of the specular lobe. ng: the geometric normal, turned to the viewer.
vec3 indirectLight(vec3 n, vec3 v, vec3 ng, vec3 baseColor, float metallic, float roughness,
                   vec3 nLayer) {
  LoSurface s = LoSurface(n, v, baseColor, metallic, roughness, nLayer);
  float probe = probeWeight(roughness);
  gVdlSpecular = 1.0 - probe;
  vec3 indirect;
  // The atlas programs (LO_ATLAS_LIGHTING) leave the octree walk out: on
  // a software rasterizer the code's mere presence costs (scene_pass.cpp).
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
  return indirect;
}

// Light through a transmissive surface (KHR_materials_transmission).
vec3 transmittedLight(vec3 n, vec3 v, vec3 baseColor) {
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
  return uTransmission * (1.0 - fresnel) * baseColor * behind;
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
      // glTF: occlusion darkens the indirect light only.
      float occlusion = uHasOcclusionTexture
                            ? 1.0 + uOcclusionStrength * (texture(uOcclusionTexture, vOcclusionUv).r - 1.0)
                            : 1.0;
      radiance += occlusion * indirectLight(n, v, ng, baseColor, metallic, roughness, nLayer);
    }
  }
  if (uTransmission > 0.0) radiance += transmittedLight(n, v, baseColor);
  if (cutOut) discard;
  radiance *= uExposureScale;
  fragColor = vec4(uEncodeSrgb ? srgbEncode(radiance) : radiance, coverage);
}
