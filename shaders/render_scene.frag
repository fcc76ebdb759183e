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
#define LO_SURFACE_TEXELS uSurfaceTexels
#include "octree_lookup.h"

// The VDLs light the diffuse lobe and the share of the specular one that the
// probe does not (gVdlSpecular, set by main). The same walk gives, beside
// it, the irradiance E(n) of the same light, with the cosine alone as the
// response as in C++ (octree/octree_irradiance.cpp) and the atlas bake: the
// probe's light is normalised by it (indirectLight).
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
// of the specular lobe, normalised by the irradiance that the same light
// gives here (probeNormalization). ng: the geometric normal, turned to the
// viewer.
vec3 indirectLight(vec3 n, vec3 v, vec3 ng, vec3 baseColor, float metallic, float roughness,
                   vec3 nLayer) {
  LoSurface s = LoSurface(n, v, baseColor, metallic, roughness, nLayer);
  float probe = probeWeight(roughness);
  float known = probe > 0.0 ? probeKnowsLight(metallic, roughness) : 0.0;
  gVdlSpecular = 1.0 - probe;
  vec3 indirect = vec3(0.0);
  vec3 irradiance = vec3(0.0);  // E(n) of the same light (W/m^2), for the probe
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
    irradiance = E;
    if (dl > 1e-3) {
      d /= dl;
      vec3 nb = normalize(vNormal);
      if (dot(nb, ng) < 0.0) nb = -nb;
      indirect = loVdlResponse(s, d) * E / max(dot(nb, d), 0.05);
    }
  } else {
#if defined(LO_FREE_SPACE)
    // An object added after the bake: the free-space octree's light, bound
    // in place of the surfaces' (scene_pass.cpp).
    indirect = loVolumeIndirectIrradiance(vPosition, uOctreeOrigin, uVoxelSize, uDepth, s,
                                          irradiance);
#elif !defined(LO_ATLAS_LIGHTING)
    indirect = loOctreeIndirectIrradiance(vPosition, uOctreeOrigin, uVoxelSize, uDepth,
                                          uNormalOffset, uInterpolation, uMaxVdls, s, irradiance);
#endif
  }
  if (probe > 0.0) {
    float scale = known > 0.0 ? mix(1.0, probeNormalization(n, irradiance), known) : 1.0;
    indirect += probe * scale * probeSpecular(vPosition, n, v, baseColor, metallic, roughness);
  }
  return indirect;
}

// A copy's texel at frame position uv (uBehind, and with glass the opaque
// depth and the back faces), within the texels this frame wrote: the copies
// may be larger, they only grow.
vec4 copyTexel(sampler2D copy, vec2 uv) {
  vec2 written = uBehindScale - 0.5 / vec2(textureSize(copy, 0));
  return textureLod(copy, min(uv * uBehindScale, written), 0.0);
}

// The opaque image's radiance at frame position uv.
vec3 behindAt(vec2 uv) {
  vec3 behind = copyTexel(uBehind, uv).rgb;
  if (uEncodeSrgb) behind = srgbDecode(behind);
  return behind / uExposureScale;
}

// The opaque scene's radiance behind a transmissive surface along the ray
// from q in direction d: the ray is taken to the scene's bounds (the walls
// of a room, the probe's parallax box) and that point read from the opaque
// image drawn before the transmissive surfaces; from the reflection probe
// when it falls off the screen or behind the camera.
vec3 behindAlong(vec3 q, vec3 d) {
  vec3 dd = mix(d, vec3(1e-6), equal(d, vec3(0.0)));  // no 0/0 below
  vec3 tf = max((uProbeBoxMax - q) / dd, (uProbeBoxMin - q) / dd);
  float tBox = max(min(min(tf.x, tf.y), tf.z), 0.0);
#ifdef LO_DIRECT_LIGHT
  // An emitter drawn as an area light (the probe leaves those out): its
  // radiance where the ray meets the nearest one's front face.
  if (uMode == LO_MODE_FULL || uMode == LO_MODE_DIRECT) {
    float nearest = tBox;
    vec3 emitted = vec3(-1.0);
    // The area lights' triangles: the last light's range ends them.
    int last = uLightCount.x - 1;
    int triangles = uLightCount.y > 0 ? int(uLights[last].corner2.x + uLights[last].corner2.y) : 0;
    for (int k = 0; k < triangles; ++k) {
      vec3 a = uAreaTriangles[3 * k].xyz, e1 = uAreaTriangles[3 * k + 1].xyz - a,
           e2 = uAreaTriangles[3 * k + 2].xyz - a;
      if (dot(d, cross(e1, e2)) >= 0.0) continue;  // its back
      vec3 pv = cross(d, e2);
      float det = dot(e1, pv);
      if (abs(det) < 1e-12) continue;
      vec3 s = q - a;
      float b1 = dot(s, pv) / det;
      vec3 qv = cross(s, e1);
      float b2 = dot(d, qv) / det;
      float t = dot(e2, qv) / det;
      if (b1 >= 0.0 && b2 >= 0.0 && b1 + b2 <= 1.0 && t > 0.0 && t <= nearest) {
        nearest = t;
        emitted = vec3(uAreaTriangles[3 * k].w, uAreaTriangles[3 * k + 1].w,
                       uAreaTriangles[3 * k + 2].w);
      }
    }
    if (emitted.x >= 0.0) return emitted;
  }
#endif
  vec3 hit = q + d * tBox;
  vec4 clip = uViewProj * vec4(hit, 1.0);
  vec2 uv = clip.xy / max(clip.w, 1e-9) * 0.5 + 0.5;
  bool onScreen = clip.w > 0.0 && all(greaterThanEqual(uv, vec2(0.0))) &&
                  all(lessThanEqual(uv, vec2(1.0)));
  if (!onScreen && uHasProbe) return textureLod(uProbe, hit, 0.0).rgb;
  return behindAt(clamp(uv, vec2(0.0), vec2(1.0)));
}

// Thick glass followed through the solid: compiled into the programs of a
// scene that has a volume (LO_VOLUMES, Renderer::Impl::buildSceneProgram).
#ifdef LO_VOLUMES
// Where render-space point x falls in the frame: uv in [0, 1], window depth;
// false when it is behind the camera or off the frame.
bool windowPoint(vec3 x, out vec3 w) {
  vec4 clip = uViewProj * vec4(x, 1.0);
  w = vec3(0.0);
  if (clip.w <= 0.0) return false;
  w = clip.xyz / clip.w * 0.5 + 0.5;
  return all(greaterThanEqual(w.xy, vec2(0.0))) && all(lessThanEqual(w.xy, vec2(1.0)));
}

// The opaque scene along the ray from q in direction d, met by marching the
// ray across the frame against the opaque image's depth (24 steps, closer
// near q, then bisection): what lies a few centimetres behind a glass block
// is found where it is, not where the scene's bounds would put it. Off the
// frame, or meeting nothing, behindAlong.
vec3 behindMarched(vec3 q, vec3 d) {
  if (!uHasOpaqueDepth) return behindAlong(q, d);
  vec3 dd = mix(d, vec3(1e-6), equal(d, vec3(0.0)));
  vec3 tf = max((uProbeBoxMax - q) / dd, (uProbeBoxMin - q) / dd);
  float tBox = max(min(min(tf.x, tf.y), tf.z), 0.0);
  const int kSteps = 24;
  float before = 0.0;
  for (int i = 1; i <= kSteps; ++i) {
    float s = tBox * pow(float(i) / float(kSteps), 2.0);
    vec3 w;
    if (!windowPoint(q + d * s, w)) break;
    if (w.z >= copyTexel(uOpaqueDepth, w.xy).r) {
      float lo = before, hi = s;
      for (int k = 0; k < 5; ++k) {
        float mid = 0.5 * (lo + hi);
        vec3 wm;
        if (windowPoint(q + d * mid, wm) && wm.z >= copyTexel(uOpaqueDepth, wm.xy).r) {
          hi = mid;
        } else {
          lo = mid;
        }
      }
      windowPoint(q + d * hi, w);
      return behindAt(w.xy);
    }
    before = s;
  }
  return behindAlong(q, d);
}

// The outward normal a back face's w holds (render_volume_back.frag).
vec3 backFaceNormal(float code) {
  float c = code - 1.0;
  vec2 o = vec2(floor(c / 1024.0), mod(c, 1024.0)) / 1023.0 * 2.0 - 1.0;
  vec3 n = vec3(o, 1.0 - abs(o.x) - abs(o.y));
  if (n.z < 0.0) n.xy = (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  return normalize(n);
}

// Where the ray from p inside a volume along t leaves it. The volume's back
// faces at the pixels of points along the ray (a quarter, a half and all of
// the material's thickness, then where the nearest exit so far lies) each
// give a plane the ray leaves through; a convex body's exit is the nearest
// of its faces' (a block's is found exactly once its face is among them).
// m: the outward normal there. False when no back face is found ahead.
bool volumeExit(vec3 p, vec3 t, out vec3 exitPoint, out vec3 m) {
  float best = 1e30;
  m = -t;
  for (int k = 0; k < 5; ++k) {
    float s = k < 3 ? uThickness * (k == 0 ? 0.25 : k == 1 ? 0.5 : 1.0) : 0.999 * best;
    if (s >= 1e29) break;
    vec3 w;
    if (!windowPoint(p + t * s, w)) continue;
    vec4 b = copyTexel(uBackFaces, w.xy);
    if (b.w == 0.0) continue;
    vec3 nb = backFaceNormal(b.w);
    float along = dot(t, nb);
    if (along <= 1e-3) continue;
    float exitAt = dot(b.xyz - p, nb) / along;
    if (exitAt > 0.0 && exitAt < best) {
      best = exitAt;
      m = nb;
    }
  }
  exitPoint = p + t * min(best, 1e29);
  return best < 1e29;
}
#endif  // LO_VOLUMES

// Light through a transmissive surface (KHR_materials_transmission), tinted
// by the base colour and weighted by the Fresnel transmittance of each
// interface it crosses (Schlick, F0 from the ior).
vec3 transmittedLight(vec3 n, vec3 v, vec3 baseColor) {
  float ior = max(uIor, 1.0);
  float f0 = (ior - 1.0) / (ior + 1.0);
  f0 *= f0;
  float fresnel = f0 + (1.0 - f0) * pow(1.0 - clamp(dot(n, v), 0.0, 1.0), 5.0);
  // How curved the surface is here: the normal's turn per unit of surface
  // across the pixel (a sphere: 1 / its radius; a pane: 0).
  float curvature = max(length(dFdx(n)) / max(length(dFdx(vPosition)), 1e-9),
                        length(dFdy(n)) / max(length(dFdy(vPosition)), 1e-9));
  vec3 t = refract(-v, n, 1.0 / ior);
  if (dot(t, t) == 0.0) t = -v;
#ifdef LO_VOLUMES
  vec3 exitPoint, m;
  if (uThickness > 0.0 && uHasVolumeBacks && curvature * uThickness < 0.25 &&
      volumeExit(vPosition, t, exitPoint, m)) {
    // A volume flat here (a block, a slab) whose back faces this frame drew:
    // the ray refracts in, leaves through the back face it meets (the share
    // the interface lets through) or is reflected inside it (the rest: past
    // the critical angle, a block's sides and bottom mirror what is behind),
    // up to four times, and goes on to the opaque scene it meets.
    vec3 p = vPosition;
    vec3 light = vec3(0.0);
    float carried = 1.0 - fresnel;
    for (int bounce = 0; bounce < 4 && carried > 0.0; ++bounce) {
      if (bounce > 0 && !volumeExit(p, t, exitPoint, m)) break;
      vec3 out_ = refract(t, -m, ior);
      float through = 0.0;
      if (dot(out_, out_) > 0.0) {
        through = 1.0 - (f0 + (1.0 - f0) * pow(1.0 - clamp(dot(out_, m), 0.0, 1.0), 5.0));
        light += carried * through * behindMarched(exitPoint, out_);
      }
      carried *= 1.0 - through;
      t = reflect(t, -m);
      p = exitPoint;
    }
    // What four inner reflections still hold (a block's corners reflect a
    // ray totally from face to face), or a ray whose exit the back faces do
    // not show: sent on from where it was last.
    if (carried > 0.0) light += carried * behindMarched(p, t);
    return uTransmission * baseColor * light;
  }
#endif  // LO_VOLUMES
  if (uThickness <= 0.0 || curvature * uThickness < 0.25) {
    // Thin-walled (glTF without KHR_materials_volume), or a volume whose
    // surface is flat on the scale of its thickness (a pane, a table top):
    // the scene behind, seen straight through (a slab shifts the view
    // sideways by at most its thickness, and bends nothing), through one
    // interface or two.
    vec3 behind = texelFetch(uBehind, ivec2(gl_FragCoord.xy), 0).rgb;
    if (uEncodeSrgb) behind = srgbDecode(behind);
    float through = uThickness > 0.0 ? (1.0 - fresnel) * (1.0 - fresnel) : 1.0 - fresnel;
    return uTransmission * through * baseColor * behind / uExposureScale;
  }
  // A curved volume (KHR_materials_volume): the surface taken as a ball whose
  // diameter is the material's thickness, touching the surface here (exact
  // for a sphere given its diameter, as exporters give it); the ray refracts
  // in, crosses the ball along its chord and leaves it there (the share the
  // far side lets through) or after one reflection inside it (the rest: a
  // light above a glass ball shows in its lower half), on to the scene
  // behind.
  float radius = 0.5 * uThickness;
  vec3 centre = vPosition - n * radius;
  vec3 light = vec3(0.0);
  float carried = 1.0 - fresnel;  // what entered
  vec3 p = vPosition;
  for (int bounce = 0; bounce < 2; ++bounce) {
    vec3 exitPoint = p + t * max(2.0 * radius * dot(t, normalize(centre - p)), 0.0);
    vec3 m = normalize(exitPoint - centre);  // outward at the exit
    vec3 out_ = refract(t, -m, ior);
    float through = 0.0;
    if (dot(out_, out_) > 0.0) {
      through = 1.0 - (f0 + (1.0 - f0) * pow(1.0 - clamp(dot(out_, m), 0.0, 1.0), 5.0));
      light += carried * through * behindAlong(exitPoint, out_);
    }
    carried *= 1.0 - through;
    t = reflect(t, -m);
    p = exitPoint;
  }
  return uTransmission * baseColor * light;
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
  float alpha = vBaseAlpha;
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
  // A one-sided emitter shows its light on its front (the winding's side,
  // where every tracer emits it) and none from behind.
  if (!gl_FrontFacing && !uEmitsBothSides) emission = vec3(0.0);
  float metallic = vMetallicRoughness.x;
  float roughness = vMetallicRoughness.y;
  if (uHasMetallicRoughnessTexture) {
    vec3 mr = texture(uMetallicRoughnessTexture, vMetallicRoughnessUv).rgb;
    roughness *= mr.g;
    metallic *= mr.b;
  }

  vec3 radiance = vec3(0.0);
  if (uUnlit) {
    // Seen by the camera alone, as its base colour (Material::unlit).
    if (uMode == LO_MODE_FULL || uMode == LO_MODE_DIRECT) radiance = baseColor;
  } else
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
#ifdef LO_ALPHA_CUT
  // Built without it for the other materials: a shader that may discard is
  // shaded before the depth and stencil tests on the software rasteriser
  // (Renderer::Impl::uncutTwins).
  if (cutOut) discard;
#endif
  radiance *= uExposureScale;
  fragColor = vec4(uEncodeSrgb ? srgbEncode(radiance) : radiance, coverage);
}
