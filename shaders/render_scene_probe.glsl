// The reflection probe's part of the scene pass (render/reflection_probe.cpp
// captures it). Part of render_scene.frag, after material_brdf.h.

// The probe's share of a surface's specular indirect light: all of it up to
// roughness LO_PROBE_FULL, none above LO_PROBE_NONE (the VDLs' directions
// light broad lobes well; a handful of VDLs cannot show a sharp reflection).
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
