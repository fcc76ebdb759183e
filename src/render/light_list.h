#pragma once
// Internal to src/render, free of GL: the lights of a scene as the scene
// shader's light block holds them (shaders/render_lights.h).

#include <render_constants.h>
#include <render_lights.h>

#include <vector>

#include "render/render_space.h"
#include "scene/emitter_sampler.h"
#include "scene/scene.h"

namespace lo::render_internal {

using shader::GpuLight;
using shader::LightBlock;

/// The emissive triangles as area lights: `lights` (LO_LIGHT_AREA, render
/// space), each a group of triangles that share corners (a quad, a cube, a
/// neon tube), groups merged by proximity down to LO_MAX_AREA_LIGHTS; and
/// `triangles`, the light block's uAreaTriangles: three vec4 per one-sided
/// triangle, its corners in xyz (wound to face where it emits: a
/// double-sided emitter is two triangles) and its mean radiance's R, G, B
/// in their w. A light's triangles are corner2.x to corner2.x + corner2.y.
/// The shader integrates each triangle exactly (unshadowed, Lambertian)
/// and shadows the group once from one cube map at its centre, softened
/// by its size (PCSS, see docs/render.md). Empty when the scene has none or
/// more than LO_MAX_AREA_TRIANGLES of them (they become VPLs).
struct AreaLightSet {
  std::vector<GpuLight> lights;
  std::vector<glm::vec4> triangles;
  size_t triangleCount() const { return triangles.size() / 3; }
};
/// `sampler` is buildEmitterSampler(scene): the emissive triangles with their
/// mean emission, read from their textures once for both kinds of lights.
AreaLightSet areaLights(const Scene& scene, const EmitterSampler& sampler,
                        const RenderSpace& space);

/// Emissive triangles -> `count` virtual point lights (LO_LIGHT_EMITTER,
/// render space), chosen in proportion to emitted power by the tracers'
/// EmitterSampler (scene/emitter_sampler.h) with stratified, deterministic
/// samples. Each is a one-sided Lambertian patch of intensity
/// I(theta) = colorFar.rgb cos(theta) (W/sr), i.e. of power pi colorFar.rgb:
/// together they carry the sampler's total power. A double-sided emitter's
/// samples alternate sides.
std::vector<GpuLight> emitterVpls(const Scene& scene, const EmitterSampler& emitters,
                                  const RenderSpace& space, int count);

}  // namespace lo::render_internal
