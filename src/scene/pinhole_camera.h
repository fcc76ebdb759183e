#pragma once
/// @file scene/pinhole_camera.h
/// @brief The camera every image of a scene is taken with: the GL renderer
/// (render/renderer.h), the reference path tracer (reference/path_tracer.h)
/// and the viewer share it, so that their images line up pixel for pixel.
/// Conventions of glm::perspective + lookAt: the image spans `yfov`
/// vertically, width / height sets the horizontal extent, row 0 is the top.

#include "core/math.h"
#include "scene/scene.h"

namespace lo {

/// A pinhole camera in world space.
struct PinholeCamera {
  Vec3 eye{0, 0, 1};
  Vec3 forward{0, 0, -1};  ///< unit
  Vec3 up{0, 1, 0};        ///< unit, orthogonal to forward
  float yfov = 0.8f;       ///< vertical field of view, radians
  float znear = 0.01f;     ///< scene units (rasterization only)
  float zfar = 0;          ///< scene units, 0 = from the scene bounds (rasterization only)

  /// The scene file's camera (its near/far planes where it has them).
  static PinholeCamera fromScene(const Camera& camera);
  /// Looks at `target` from `eye`; world up is +Y unless the view is along it
  /// (then -Z). @throws InputError when eye and target are the same point.
  static PinholeCamera lookAt(const Vec3& eye, const Vec3& target, float yfovRadians);
  /// Frames the bounds' bounding sphere from the +Z side.
  static PinholeCamera framing(const Bounds3& bounds, float yfovRadians);
};

}  // namespace lo
