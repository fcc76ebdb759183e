// The C++ build of shaders/material_brdf.h: plain values in, GLM inside.

#include "material/gltf_brdf.h"

#include <material_brdf.h>

namespace lo {
namespace {

glm::vec3 toGlm(const Vec3& v) { return {v.x, v.y, v.z}; }
glm::vec2 layerOf(const GltfBrdfMaterial& m) { return {m.dielectricF0, m.specular}; }
Vec3 fromGlm(const glm::vec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

GltfBrdfLobes gltfBrdfLobes(const GltfBrdfMaterial& m, const Vec3& n, const Vec3& v,
                            const Vec3& l) {
  glm::vec3 diffuse, specular;
  brdf::loBrdfLobes(toGlm(n), toGlm(v), toGlm(l), toGlm(m.baseColor), m.metallic,
                    brdf::loBrdfAlpha(m.roughness), m.transmission, layerOf(m), diffuse, specular);
  return {fromGlm(diffuse), fromGlm(specular)};
}

Vec3 gltfBrdf(const GltfBrdfMaterial& m, const Vec3& n, const Vec3& v, const Vec3& l) {
  return fromGlm(brdf::loBrdf(toGlm(n), toGlm(v), toGlm(l), toGlm(m.baseColor), m.metallic,
                              m.roughness, m.transmission, layerOf(m)));
}

Vec3 gltfBrdfCos(const GltfBrdfMaterial& m, const Vec3& n, const Vec3& v, const Vec3& l,
                 bool specular, float specularWeight) {
  return fromGlm(brdf::loBrdfCosWeighted(toGlm(n), toGlm(v), toGlm(l), toGlm(m.baseColor),
                                         m.metallic, m.roughness, m.transmission, layerOf(m),
                                         specular, specularWeight));
}

Vec3 gltfEnvironmentBrdf(const GltfBrdfMaterial& m, float nv) {
  return fromGlm(
      brdf::loEnvironmentBrdf(toGlm(m.baseColor), m.metallic, m.roughness, nv, layerOf(m)));
}

}  // namespace lo
