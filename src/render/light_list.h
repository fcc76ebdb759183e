#pragma once
// Internal to src/render, free of GL: the lights of a scene as the scene
// shader's light block holds them (shaders/render_lights.h).

#include <render_constants.h>
#include <render_lights.h>

#include <vector>

#include "render/render_space.h"
#include "scene/scene.h"

namespace lo::render_internal {

using shader::GpuLight;
using shader::LightBlock;

/// Emissive triangles -> area lights (LO_LIGHT_AREA, render space), when
/// there are at most LO_MAX_AREA_LIGHTS of them; else empty (they become
/// VPLs). The shader integrates each exactly (unshadowed, Lambertian) and
/// softens its shadow by the light's size (PCSS, see docs/render.md).
std::vector<GpuLight> areaLights(const Scene& scene, const RenderSpace& space);

/// Emissive triangles -> `count` virtual point lights (LO_LIGHT_EMITTER,
/// render space), chosen in proportion to emitted power by the tracers'
/// EmitterSampler (scene/emitter_sampler.h) with stratified, deterministic
/// samples. Each is a one-sided Lambertian patch of intensity
/// I(theta) = colorFar.rgb cos(theta) (W/sr), i.e. of power pi colorFar.rgb:
/// together they carry the sampler's total power. A double-sided emitter's
/// samples alternate sides.
std::vector<GpuLight> emitterVpls(const Scene& scene, const RenderSpace& space, int count);

}  // namespace lo::render_internal
