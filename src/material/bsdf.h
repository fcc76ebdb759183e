#pragma once
/// @file material/bsdf.h
/// @brief The material model the photon tracer scatters with, shared with the
/// reference path tracer (src/reference) so both estimate the same transport.
///
/// A glTF metallic-roughness material with KHR_materials_transmission is a
/// mixture of three lobes whose weights sum to 1 (transmission replaces the
/// diffuse base of the dielectric; the metal part is unaffected):
///   - dielectric (weight (1-metallic)(1-transmission)): glTF's fresnel_mix
///     of a Lambert base, baseColor / pi weighted by 1 - F, and a GGX
///     specular layer weighted by F (Schlick, F0 from the ior, times
///     KHR_materials_specular's weight), evaluated by the
///     GL renderer's own BRDF text (shaders/material_brdf.h through
///     material/gltf_brdf.h); sampled by a mixture of the cosine and the
///     GGX visible normals, chosen by the layer's expected share;
///   - metal (weight metallic): GGX (alpha = roughness^2), height-correlated
///     Smith G2, Schlick Fresnel with F0 = baseColor; alpha < kMirrorAlpha is a
///     perfect mirror (a delta lobe);
///   - glass (weight (1-metallic) transmission): smooth dielectric, Fresnel
///     reflection or transmission tinted by baseColor (a delta lobe); the
///     transmitted ray refracts where the material has a volume
///     (KHR_materials_volume thickness > 0) and goes straight through a
///     thin-walled one (glTF's default).
/// BsdfLobes built by hand (DirectIrradiance's probe) have no specular
/// layer: a pure Lambert base.
///
/// Directions are unit, world space, pointing away from the surface: wo
/// towards the viewer (or where a photon came from), wi towards the light.

#include "core/math.h"
#include "core/rng.h"
#include "scene/scene.h"

namespace lo {

/// Metal lobes at least this rough (perceptual roughness) count as glossy:
/// the photon tracer stores photons on them; sharper lobes only redirect.
constexpr float kGlossyRoughness = 0.2f;
/// GGX alpha below which a metal is sampled as a perfect mirror: the floor
/// of shaders/material_brdf.h's loBrdfAlpha, so that every GGX lobe the
/// tracers evaluate has the alpha the GL renderer gives it.
constexpr float kMirrorAlpha = 2e-3f;

/// Lobe weights (probabilities of choosing each lobe; they sum to 1).
struct BsdfLobes {
  float transmissionWeight = 0;
  float metalWeight = 0;
  float diffuseWeight = 1;   ///< the dielectric lobe's (base and specular layer)
  float roughness = 1;       ///< perceptual
  float alpha = 1;  ///< GGX alpha = roughness^2, floored at kMirrorAlpha
  /// The dielectric's GGX specular layer (glTF): its F0 (from the ior) and
  /// weight (KHR_materials_specular); weight 0: a Lambert base alone.
  float dielectricF0 = 0.04f;
  float layerWeight = 0;
  float ior = 1.5f;
  bool thinWalled = true;     ///< transmission passes straight (no KHR_materials_volume)
  bool storesPhotons = true;  ///< diffuse lobe, or metal rougher than kGlossyRoughness
  /// Whether any lobe is not a delta distribution (light sampling can help).
  bool hasSmoothLobe() const { return diffuseWeight > 0 || (metalWeight > 0 && !mirrorMetal()); }
  /// Whether the metal lobe is a perfect mirror (roughness^2 < kMirrorAlpha).
  bool mirrorMetal() const { return roughness * roughness < kMirrorAlpha; }
};
BsdfLobes bsdfLobes(const Material& material);
/// The same with metallic and roughness given (a metallic-roughness map's
/// values at a hit, Scene::metallicRoughness) in place of the factors.
BsdfLobes bsdfLobes(const Material& material, float metallic, float roughness);
/// The lobes at a hit of triangle t at (b1, b2): `perMaterial` unless the
/// material has a metallic-roughness map, else from the map's values there.
inline BsdfLobes bsdfLobesAt(const Scene& scene, const BsdfLobes& perMaterial, size_t t,
                             float b1, float b2) {
  const Material& m = scene.materials[size_t(scene.triangleMaterial[t])];
  if (m.metallicRoughnessTexture < 0) return perMaterial;
  float metallic, roughness;
  scene.metallicRoughness(t, b1, b2, metallic, roughness);
  return bsdfLobes(m, metallic, roughness);
}

/// One sampled scattering direction.
struct BsdfSample {
  Vec3 wi;             ///< new direction, not normalised (callers normalise)
  Vec3 weight;         ///< the chosen lobe's f * |cos| / pdf: what the throughput is multiplied by
  bool delta = false;  ///< mirror or glass: evalBsdf/pdfBsdf do not cover it
  /// Straight through a thin-walled transmissive surface: the light keeps
  /// its direction (the photon tracer does not count it as a bounce: the
  /// renderer draws such light as direct light, no shadow cast).
  bool passThrough = false;
};

/// Chooses a lobe by its weight and samples it: the dielectric by the
/// cosine or, for its specular layer, GGX visible normals (the weight is
/// f cos over the mixture's pdf),
/// metal by GGX visible normals (Heitz 2018), glass by the Fresnel
/// probability. `n` is the unit geometric normal turned to wo's side,
/// `frontFace` whether that is the winding side (so the ray enters the
/// material when it refracts). Returns false if the sample is lost (a GGX
/// reflection below the surface: the lobe's energy loss). Consumes the random
/// numbers in a fixed order (photon maps depend on it).
bool sampleBsdf(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& n,
                bool frontFace, Rng& rng, BsdfSample& out);

/// Sum over the smooth lobes (diffuse, rough metal) of weight * f(wo, wi) *
/// cos(n, wi); zero when wi is below the surface. Delta lobes give zero.
Vec3 evalBsdf(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& wi,
              const Vec3& n);
/// Solid-angle density with which sampleBsdf produces wi through a smooth
/// lobe (lobe weight times the lobe's pdf, summed; the dielectric's mixture
/// depends on the albedo). Used for MIS weights.
float pdfBsdf(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, const Vec3& wi,
              const Vec3& n);

/// The share of light falling on the surface (over the hemisphere, cosine
/// weighted) that it reflects back to the side it came from, RGB: the
/// Lambert base weighted by 1 - F and the specular layer by F, F the
/// Schlick Fresnel averaged over the hemisphere (F0 + (1 - F0) / 21), the
/// metal's F0 = albedo, the glass's own Fresnel reflection. What a surface
/// that sees this one from below its horizon receives of its light
/// (Photon::reflectance); lobes' own energy loss (GGX) is left out.
Vec3 hemisphericalReflectance(const BsdfLobes& lobes, const Vec3& albedo);
/// Unpolarised Fresnel reflectance of a smooth dielectric interface, n1 -> n2.
/// cosT receives the cosine of the refracted direction (0 at total reflection).
float fresnelDielectric(float cosI, float n1, float n2, float& cosT);

/// Cosine-weighted direction around +z (Malley: uniform disc, projected up).
inline Vec3 cosineHemisphere(float u1, float u2) {
  float r = std::sqrt(u1);
  float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1))};
}

inline Vec3 fromLocal(const Vec3& v, const Vec3& t, const Vec3& b, const Vec3& n) {
  return t * v.x + b * v.y + n * v.z;
}

/// glTF KHR_lights_punctual spot falloff: ((cos - cosOuter) / (cosInner - cosOuter))^2, clamped.
inline float spotFalloff(float cosTheta, float cosInner, float cosOuter) {
  float scale = 1.0f / std::max(1e-3f, cosInner - cosOuter);
  float a = std::clamp((cosTheta - cosOuter) * scale, 0.0f, 1.0f);
  return a * a;
}

/// glTF range window: clamp(1 - (d / range)^4, 0, 1); 1 for range <= 0.
inline float rangeWindow(float distance, float range) {
  if (range <= 0) return 1.0f;
  float q = distance / range;
  q *= q;
  return std::clamp(1.0f - q * q, 0.0f, 1.0f);
}

}  // namespace lo
