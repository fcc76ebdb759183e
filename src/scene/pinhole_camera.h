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
  /// Frames the bounds' bounding sphere from the side `side` (unit; +Z by
  /// default), looking at its centre.
  static PinholeCamera framing(const Bounds3& bounds, float yfovRadians,
                               const Vec3& side = Vec3(0, 0, 1));
  /// The camera for a scene without one of its own: its bounds framed from
  /// viewSide(scene).
  static PinholeCamera framing(const Scene& scene, float yfovRadians);
  /// The scene's first camera, else framing(scene, yfovRadians).
  static PinholeCamera ofScene(const Scene& scene, float yfovRadians = 45.0f * kPi / 180.0f);
};

/// The side a scene shows its front faces to: the direction of the sum of
/// its triangles' area-weighted normals, where that sum is at least a fifth
/// of their area (an open room's walls and floor facing in, a ground facing
/// up), at most 60 degrees from the horizon (from +Z where it leans no way
/// across); else +Z, for closed objects and rooms, whose normals cancel. A
/// room corner framed from +Z would show the backs of its walls: black in
/// every renderer, their light on the other side.
Vec3 viewSide(const Scene& scene);

}  // namespace lo
