#pragma once
// Internal to src/render: the space everything on the GPU lives in.

#include "core/math.h"

namespace lo::render_internal {

/// Render space: world minus `origin`, the centre of the scene's bounds.
/// Everything the GPU sees (vertices, lights, shadow matrices, the camera,
/// the octree) is in render space, computed in double, so that a scene far
/// from the world origin keeps the precision of one near it in every shader
/// computation (view transform, depth, shadow lookups, the octree lookup,
/// screen-space derivatives).
struct RenderSpace {
  Vec3 origin{0, 0, 0};  ///< world position of render space's origin
  Bounds3 bounds;        ///< the scene's bounds, render space
  float sceneSize = 1;   ///< bounds diagonal, world units

  /// World -> render space, in double: exact for points near the scene.
  Vec3 toRender(const Vec3& world) const {
    return {float(double(world.x) - double(origin.x)), float(double(world.y) - double(origin.y)),
            float(double(world.z) - double(origin.z))};
  }
};

}  // namespace lo::render_internal
