/* material_brdf.h: the glTF metallic-roughness BRDF, written once for GLSL and
 * C++ (the practice of octree_lookup.h). The scene shader includes it
 * (render_scene.frag); the C++ build is material/gltf_brdf.cpp, which gives
 * the same functions to the tests and to the tracers' BSDF (material/bsdf.cpp).
 *
 * The BRDF (docs/render.md), as glTF 2.0's Appendix B mixes it: a dielectric
 * (Lambert diffuse weighted by 1 - F plus a GGX specular layer weighted by
 * F, Schlick's Fresnel) and a metal (the GGX lobe, F0 = baseColor), mixed by
 * metallic. The dielectric's layer is `layer` = (F0, weight):
 * F = weight (F0 + (1 - F0)(1 - v.h)^5), F0 = ((ior - 1) / (ior + 1))^2
 * (KHR_materials_ior; 0.04 at glTF's default 1.5) and weight
 * KHR_materials_specular's specularFactor (1 by default; 0: a Lambert base). GGX after Walter et al. 2007, with
 * height-correlated Smith visibility (Heitz 2014, eq. 99).
 * KHR_materials_transmission takes its share of the diffuse lobe away (the
 * renderer draws the transmitted light separately). With the specular lobe
 * off the BRDF is exactly baseColor (1 - metallic)(1 - transmission) / pi:
 * the analytic render tests rely on that.
 *
 *   loBrdfAlpha        GGX alpha of a perceptual roughness (roughness^2, floored)
 *   loGgxD, loGgxLambda  GGX's distribution and Smith's Lambda (also the tracers')
 *   loBrdfDiffuseOnly  the diffuse lobe alone, no Fresnel weight (specular off)
 *   loBrdfLobes        the two lobes towards l, no cosine: (1 - F) diffuse, F D V
 *   loBrdf             their sum, no cosine (what a tracer's f(wo, wi) is)
 *   loBrdfCosWeighted  f (n.l), the GGX lobe scaled by a weight, 0 below the surface
 *   loBrdfCos          the same with the whole GGX lobe
 *   loEnvironmentBrdf  the split-sum environment BRDF in Karis's analytic fit
 *
 * Directions are unit, in one space, pointing away from the surface: n the
 * shading normal, v to the viewer, l to the light. Colours are linear RGB.
 * In C++ the functions live in namespace lo::brdf, with GLM standing in for
 * GLSL's types.
 */
#ifndef LO_MATERIAL_BRDF_H
#define LO_MATERIAL_BRDF_H

#ifdef __cplusplus
#include <glm/glm.hpp>
namespace lo {
namespace brdf {
using namespace glm;
/* GLSL's built-ins are GLM's here, ahead of lo's own min/max/dot (core/math.h). */
using glm::clamp;
using glm::dot;
using glm::exp2;
using glm::max;
using glm::min;
using glm::mix;
using glm::normalize;
using glm::pow;
using glm::sqrt;
#define LO_BRDF_FN inline
#define LO_BRDF_OUT(T) T &
#else
#define LO_BRDF_FN
#define LO_BRDF_OUT(T) out T
#endif

const float LO_BRDF_PI = 3.14159265358979323846f;

/* The GGX alpha of a perceptual roughness; the floor keeps a mirror's lobe
 * finite for a point light (a highlight of about one pixel, not a NaN). */
LO_BRDF_FN float loBrdfAlpha(float roughness) { return max(roughness * roughness, 2e-3f); }

/* GGX's normal distribution D(m) at nh = n.m > 0 (Walter et al. 2007, eq.
 * 33), alpha a: the renderer's specular lobe and the tracers' sampling
 * densities (material/bsdf.cpp) read this one text. */
LO_BRDF_FN float loGgxD(float nh, float a) {
  float a2 = a * a;
  float dd = nh * nh * (a2 - 1.0f) + 1.0f;
  return a2 / (LO_BRDF_PI * dd * dd);
}

/* Smith's Lambda for GGX (Heitz 2014, eq. 72) at a direction whose cosine to
 * the normal is c; 0 at and below the horizon. */
LO_BRDF_FN float loGgxLambda(float c, float a) {
  float c2 = c * c;
  if (c2 <= 0.0f) return 0.0f;
  float tan2 = max(0.0f, 1.0f - c2) / c2;
  return 0.5f * (-1.0f + sqrt(1.0f + a * a * tan2));
}

LO_BRDF_FN vec3 loBrdfDiffuseOnly(vec3 baseColor, float metallic, float transmission) {
  return baseColor * (1.0f - metallic) * (1.0f - transmission) / LO_BRDF_PI;
}

/* The two lobes of the BRDF (no cosine) towards l: (1 - F) diffuse and
 * F D V, GGX of alpha a. Meant for n.l > 0; the cosines are floored so that
 * grazing directions give finite values. */
LO_BRDF_FN void loBrdfLobes(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float a,
                            float transmission, vec2 layer, LO_BRDF_OUT(vec3) diffuse,
                            LO_BRDF_OUT(vec3) specular) {
  float nl = max(dot(n, l), 1e-4f);
  diffuse = loBrdfDiffuseOnly(baseColor, metallic, transmission);
  float nv = max(dot(n, v), 1e-4f);
  vec3 h = normalize(l + v);
  float nh = max(dot(n, h), 0.0f);
  float vh = clamp(dot(v, h), 0.0f, 1.0f); /* (1 - vh)^5 < 0 for vh a rounding above 1 */
  float a2 = a * a;
  float D = loGgxD(nh, a);
  float vis =
      0.5f / (nl * sqrt(nv * nv * (1.0f - a2) + a2) + nv * sqrt(nl * nl * (1.0f - a2) + a2));
  /* The specification's mix (glTF 2.0, Appendix B): the dielectric's
   * Fresnel (its layer's F0 and weight) weights its diffuse base and its
   * specular layer, the metal's (F0 = baseColor) its specular lobe alone. */
  /* (1 - v.h)^5 by multiplication: a software rasteriser's pow is a log and
   * an exp, and this runs for every light and VDL of every fragment. */
  float m = 1.0f - vh;
  float m2 = m * m;
  float schlick = m2 * m2 * m;
  float fDielectric = layer.y * (layer.x + (1.0f - layer.x) * schlick);
  vec3 fMetal = baseColor + (1.0f - baseColor) * schlick;
  diffuse *= 1.0f - fDielectric;
  specular = mix(vec3(fDielectric), fMetal, metallic) * (D * vis);
}

/* f(v, l): both lobes, no cosine; 0 when l is below the surface. */
LO_BRDF_FN vec3 loBrdf(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic, float roughness,
                       float transmission, vec2 layer) {
  if (dot(n, l) <= 0.0f) return vec3(0.0f);
  vec3 diffuse, specular;
  loBrdfLobes(n, v, l, baseColor, metallic, loBrdfAlpha(roughness), transmission, layer, diffuse,
              specular);
  return diffuse + specular;
}

/* f(v, l) (n.l) with the GGX lobe scaled by specularWeight (the VDLs' share
 * of a surface's specular light when the reflection probe takes the rest);
 * without `specular`, the diffuse lobe alone and no Fresnel weight. */
LO_BRDF_FN vec3 loBrdfCosWeighted(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic,
                                  float roughness, float transmission, vec2 layer, bool specular,
                                  float specularWeight) {
  float nl = dot(n, l);
  if (nl <= 0.0f) return vec3(0.0f);
  if (!specular) return loBrdfDiffuseOnly(baseColor, metallic, transmission) * nl;
  vec3 diffuseLobe, specularLobe;
  loBrdfLobes(n, v, l, baseColor, metallic, loBrdfAlpha(roughness), transmission, layer,
              diffuseLobe, specularLobe);
  return (diffuseLobe + specularWeight * specularLobe) * nl;
}

LO_BRDF_FN vec3 loBrdfCos(vec3 n, vec3 v, vec3 l, vec3 baseColor, float metallic,
                          float roughness, float transmission, vec2 layer, bool specular) {
  return loBrdfCosWeighted(n, v, l, baseColor, metallic, roughness, transmission, layer, specular,
                           1.0f);
}

/* The split-sum environment BRDF (Karis 2013): the GGX lobe's directional
 * albedo as F0 x + y, in Karis's analytic fit (Physically Based Shading on
 * Mobile, 2014); nv = n.v clamped to [0, 1]. Radiance prefiltered along the
 * reflected ray times this is the lobe's reflected light. */
LO_BRDF_FN vec3 loEnvironmentBrdf(vec3 baseColor, float metallic, float roughness, float nv,
                                  vec2 layer) {
  const vec4 c0 = vec4(-1.0f, -0.0275f, -0.572f, 0.022f);
  const vec4 c1 = vec4(1.0f, 0.0425f, 1.04f, -0.04f);
  vec4 q = roughness * c0 + c1;
  float a004 = min(q.x * q.x, exp2(-9.28f * nv)) * q.x + q.y;
  vec2 ab = vec2(-1.04f, 1.04f) * a004 + vec2(q.z, q.w);
  /* The dielectric's layer weighted as in loBrdfLobes; F0 x + y is linear in
   * F0 and in the weight. */
  vec3 dielectric = vec3(layer.y * (layer.x * ab.x + ab.y));
  return mix(dielectric, baseColor * ab.x + ab.y, metallic);
}

#ifdef __cplusplus
}  // namespace brdf
}  // namespace lo
#endif

#endif /* LO_MATERIAL_BRDF_H */
