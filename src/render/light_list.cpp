// Emissive triangles as the scene shader's lights: area lights, or VPLs
// drawn from the tracers' emitter sampler.

#include "render/light_list.h"

#include <algorithm>
#include <cmath>

#include "scene/emitter_sampler.h"

namespace lo::render_internal {
namespace {

glm::vec4 toVec4(const Vec3& v, float w) { return {v.x, v.y, v.z, w}; }

/// Base-2 radical inverse of i in [0, 1).
float radicalInverse(uint32_t i) {
  uint32_t bits = i;
  bits = (bits << 16u) | (bits >> 16u);
  bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
  bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
  bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
  bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
  return float(bits) * 2.3283064365386963e-10f;
}

}  // namespace

std::vector<GpuLight> areaLights(const Scene& scene, const RenderSpace& space) {
  std::vector<GpuLight> out;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
    if (m < 0 || size_t(m) >= scene.materials.size()) continue;
    const Vec3 emission = scene.triangleEmission(t);
    const float area = scene.triangleArea(t);
    if (!(maxComponent(emission) > 0) || !(area > 0)) continue;
    if (out.size() == size_t(shader::LO_MAX_AREA_LIGHTS)) return {};
    const Vec3 p0 = space.toRender(scene.positions[scene.indices[t * 3]]);
    const Vec3 p1 = space.toRender(scene.positions[scene.indices[t * 3 + 1]]);
    const Vec3 p2 = space.toRender(scene.positions[scene.indices[t * 3 + 2]]);
    const Vec3 n = scene.faceNormal(t);
    GpuLight l{};
    // The shadow cube sits at the triangle's centroid, just in front of it.
    l.positionType =
        toVec4((p0 + p1 + p2) / 3.0f + n * (1e-3f * space.sceneSize), float(shader::LO_LIGHT_AREA));
    l.directionRange = toVec4(n, 0);
    l.colorFar = toVec4(emission, 0);  // the mean radiance of a textured emitter
    l.params = toVec4(Vec3(-1, 1, -1), area);
    l.corner0 = toVec4(p0, std::sqrt(area));
    l.corner1 = toVec4(p1, 0);
    l.corner2 = toVec4(p2, 0);
    out.push_back(l);
  }
  return out;
}

std::vector<GpuLight> emitterVpls(const Scene& scene, const RenderSpace& space, int count) {
  const EmitterSampler emitters = buildEmitterSampler(scene);
  std::vector<GpuLight> out;
  if (emitters.empty() || count <= 0) return out;
  const double total = emitters.total();
  for (int i = 0; i < count; ++i) {
    double u = (i + 0.5) / count;
    double remapped = 0;
    size_t k = emitters.distribution.sample(u, &remapped);
    size_t t = emitters.triangles[k];
    float s = float(remapped);
    // Second coordinate from the base-2 radical inverse of i.
    float r = radicalInverse(uint32_t(i));
    float su = std::sqrt(std::clamp(s, 0.0f, 1.0f));
    float b1 = su * (1 - r), b2 = su * r;
    const Vec3 p0 = space.toRender(scene.positions[scene.indices[t * 3]]);
    const Vec3 p1 = space.toRender(scene.positions[scene.indices[t * 3 + 1]]);
    const Vec3 p2 = space.toRender(scene.positions[scene.indices[t * 3 + 2]]);
    const bool back = scene.materials[size_t(scene.triangleMaterial[t])].doubleSided && (i & 1);
    Vec3 n = back ? -scene.faceNormal(t) : scene.faceNormal(t);
    Vec3 p = p0 * (1 - b1 - b2) + p1 * b1 + p2 * b2 + n * (1e-3f * space.sceneSize);
    const Vec3 emission = scene.triangleEmission(t);
    // Area this sample stands for: the emitted power shared by count, as
    // one side of a Lambertian patch (power pi L A).
    float area = float(total / (kPi * double(average(emission))) / count);
    GpuLight l{};
    l.positionType = toVec4(p, float(shader::LO_LIGHT_EMITTER));
    l.directionRange = toVec4(n, 0);
    l.colorFar = toVec4(emission * area, 0);
    l.params = toVec4(Vec3(-1, 1, -1), area);
    out.push_back(l);
  }
  return out;
}

}  // namespace lo::render_internal
