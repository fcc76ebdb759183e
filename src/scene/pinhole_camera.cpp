/// @file scene/pinhole_camera.cpp
#include "scene/pinhole_camera.h"

#include <algorithm>
#include <cmath>

#include "core/error.h"

namespace lo {

PinholeCamera PinholeCamera::fromScene(const Camera& camera) {
  PinholeCamera c;
  c.eye = camera.position;
  c.forward = normalize(camera.forward);
  c.up = normalize(camera.up);
  c.yfov = camera.yfov;
  c.znear = camera.znear > 0 ? camera.znear : 0.01f;
  c.zfar = camera.zfar;
  return c;
}

PinholeCamera PinholeCamera::lookAt(const Vec3& eye, const Vec3& target, float yfovRadians) {
  PinholeCamera c;
  c.eye = eye;
  c.forward = normalize(target - eye);
  if (lengthSquared(c.forward) == 0) throw InputError("camera: eye and target are the same point");
  Vec3 worldUp = std::fabs(c.forward.y) > 0.999f ? Vec3(0, 0, -1) : Vec3(0, 1, 0);
  Vec3 right = normalize(cross(c.forward, worldUp));
  c.up = cross(right, c.forward);
  c.yfov = yfovRadians;
  c.znear = std::max(1e-4f, 1e-3f * length(target - eye));
  return c;
}

PinholeCamera PinholeCamera::framing(const Bounds3& bounds, float yfovRadians) {
  Vec3 center = bounds.center();
  float radius = 0.5f * length(bounds.extent());
  float distance = radius / std::sin(0.5f * yfovRadians);
  return lookAt(center + Vec3(0, 0, std::max(distance, 1e-3f)), center, yfovRadians);
}

}  // namespace lo
