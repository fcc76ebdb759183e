// The reflection probe's part of the scene pass (render/reflection_probe.cpp
// captures it). Part of render_scene.frag, after material_brdf.h.

// The probe's share of a surface's specular indirect light: all of it up to
// roughness LO_PROBE_FULL, none above LO_PROBE_NONE (the VDLs' directions
// light broad lobes well; a handful of VDLs cannot show a sharp reflection).
// Its light is normalised by the octree's (probeNormalization, below).
float probeWeight(float roughness) {
  return uHasProbe && uSpecular ? 1.0 - smoothstep(LO_PROBE_FULL, LO_PROBE_NONE, roughness) : 0.0;
}

// Specular light from the probe (paper §5.1, Fig. 12: cube maps with the
// VDLs): the reflected ray is intersected with the scene's bounds and the
// probe read towards that point (box projection, parallax-corrected: right
// where the scene is a box around the probe), at the mip level whose texels
// are as wide as the GGX lobe (its reflected directions' width at half
// maximum, about 2.57 alpha radians, over a face texel's pi/2 / 2^maxLod:
// the mips are box-filtered), times the split-sum environment BRDF
// (material_brdf.h).
vec3 probeSpecular(vec3 p, vec3 n, vec3 v, vec3 baseColor, float metallic, float roughness) {
  vec3 r = reflect(-v, n);
  r = mix(r, vec3(1e-6), equal(r, vec3(0.0)));  // no 0/0 below
  vec3 t1 = (uProbeBoxMax - p) / r, t2 = (uProbeBoxMin - p) / r;
  vec3 tf = max(t1, t2);
  float t = max(min(min(tf.x, tf.y), tf.z), 0.0);
  vec3 dir = p + r * t;  // from the probe at the render-space origin
  float lobeTexels = 1.64 * loBrdfAlpha(roughness) * exp2(uProbeMaxLod);
  float lod = clamp(log2(max(lobeTexels, 1.0)), 0.0, uProbeMaxLod);
  vec3 radiance = textureLod(uProbe, dir, lod).rgb;
  float nv = clamp(dot(n, v), 0.0, 1.0);
  return radiance * loEnvironmentBrdf(baseColor, metallic, roughness, nv, uDielectric);
}

// The probe's own irradiance towards n at its centre (W/m^2): its 9 SH
// terms, octree_layout.h's basis convolved with the clamped cosine,
// projected when it was captured (render/reflection_probe.cpp).
vec3 probeIrradiance(vec3 n) {
  vec3 e = vec3(0.0);
  for (int i = 0; i < 9; ++i) e += uProbeIrradiance[i] * loShBasis(uint(i), n.x, n.y, n.z);
  return max(e, vec3(0.0));
}

// How much the octree knows of the light at a surface: the photon tracer
// stores photons on surfaces with a diffuse lobe and on metals rougher than
// LO_PROBE_GLOSSY_ROUGHNESS (material/bsdf.cpp, storesPhotons), eased in
// over 0.1 of roughness. On a mirror or clear glass the octree holds only
// what neighbouring voxels lend: the probe keeps its own light there.
float probeKnowsLight(float metallic, float roughness) {
  if ((1.0 - metallic) * (1.0 - uTransmission) > 0.0) return 1.0;
  return metallic > 0.0
             ? smoothstep(LO_PROBE_GLOSSY_ROUGHNESS, LO_PROBE_GLOSSY_ROUGHNESS + 0.1, roughness)
             : 0.0;
}

// Irradiance normalisation (Lazarov 2013; Lagarde and de Rousiers 2014;
// Unreal's lightmap mixing): the probe shows the light around the scene's
// centre, not what reaches this point. Its light is scaled by the luminance
// of the irradiance the octree gives here (`irradiance`, E(n)) over the
// probe's own towards n, clamped to [0, LO_PROBE_NORMALIZATION_MAX]: where
// the octree knows of less light (a face turned from every emitter, the
// shade under a table) the reflection dims with it, to nothing where no
// light arrives (specular occlusion). The ratio of luminances keeps the
// reflection's colours.
float probeNormalization(vec3 n, vec3 irradiance) {
  const vec3 luminance = vec3(0.2126, 0.7152, 0.0722);
  float here = dot(irradiance, luminance);
  float there = dot(probeIrradiance(n), luminance);
  return clamp(here / max(there, 1e-6), 0.0, LO_PROBE_NORMALIZATION_MAX);
}
