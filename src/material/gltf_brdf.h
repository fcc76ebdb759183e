#pragma once
/// @file material/gltf_brdf.h
/// @brief The GL renderer's glTF metallic-roughness BRDF, compiled from the
/// same text as the shader's (shaders/material_brdf.h): the C++ twin the
/// tests check the GLSL build against, and the BRDF the tracers can share.
///
/// glTF's Appendix B: a dielectric (Lambert diffuse weighted by 1 - F plus a
/// GGX specular layer weighted by F = specular (F0 + (1 - F0)(1 - v.h)^5))
/// and a metal (GGX, Schlick with F0 = baseColor) mixed by metallic
/// (height-correlated Smith visibility); transmission takes its share of
/// the diffuse lobe. Directions are unit, in
/// one space, pointing away from the surface: n the shading normal, v to the
/// viewer, l to the light. BRDF values are in 1/sr.

#include "core/math.h"

namespace lo {

/// A glTF material at a surface point (factors times textures).
struct GltfBrdfMaterial {
  Vec3 baseColor{1, 1, 1};  ///< linear RGB
  float metallic = 0;
  float roughness = 1;     ///< perceptual; GGX alpha = roughness^2 (floored at 2e-3)
  float transmission = 0;  ///< KHR_materials_transmission
  float dielectricF0 = 0.04f;  ///< the dielectric layer's F0, ((ior - 1) / (ior + 1))^2
  float specular = 1;          ///< the dielectric layer's weight (KHR_materials_specular)
};

/// The two lobes of f(v, l) without the cosine: (1 - F) diffuse and F D V.
/// Meant for n.l > 0 (cosines are floored at 1e-4, not tested).
struct GltfBrdfLobes {
  Vec3 diffuse;
  Vec3 specular;
};
GltfBrdfLobes gltfBrdfLobes(const GltfBrdfMaterial& m, const Vec3& n, const Vec3& v, const Vec3& l);

/// f(v, l), both lobes, no cosine; zero when l is below the surface.
Vec3 gltfBrdf(const GltfBrdfMaterial& m, const Vec3& n, const Vec3& v, const Vec3& l);

/// f(v, l) (n.l), the GGX lobe scaled by `specularWeight`; with `specular`
/// false the diffuse lobe alone without its Fresnel weight,
/// baseColor (1 - metallic)(1 - transmission) / pi (n.l). Zero below the surface.
Vec3 gltfBrdfCos(const GltfBrdfMaterial& m, const Vec3& n, const Vec3& v, const Vec3& l,
                 bool specular = true, float specularWeight = 1);

/// The GGX lobe's directional albedo as the split-sum environment BRDF, in
/// Karis's analytic fit, for n.v = `nv` in [0, 1].
Vec3 gltfEnvironmentBrdf(const GltfBrdfMaterial& m, float nv);

}  // namespace lo
