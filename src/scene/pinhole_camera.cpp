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

PinholeCamera PinholeCamera::framing(const Bounds3& bounds, float yfovRadians, const Vec3& side) {
  Vec3 center = bounds.center();
  float radius = 0.5f * length(bounds.extent());
  float distance = radius / std::sin(0.5f * yfovRadians);
  return lookAt(center + side * std::max(distance, 1e-3f), center, yfovRadians);
}

PinholeCamera PinholeCamera::framing(const Scene& scene, float yfovRadians) {
  return framing(scene.bounds(), yfovRadians, viewSide(scene));
}

PinholeCamera PinholeCamera::ofScene(const Scene& scene, float yfovRadians) {
  return scene.cameras.empty() ? framing(scene, yfovRadians) : fromScene(scene.cameras.front());
}

Vec3 viewSide(const Scene& scene) {
  double sum[3] = {0, 0, 0}, area = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const Vec3& a = scene.positions[scene.indices[3 * t]];
    const Vec3 n = cross(scene.positions[scene.indices[3 * t + 1]] - a,
                         scene.positions[scene.indices[3 * t + 2]] - a);  // 2 x area
    if (!isFinite(n)) continue;
    sum[0] += double(n.x);
    sum[1] += double(n.y);
    sum[2] += double(n.z);
    area += double(length(n));
  }
  const double norm = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  if (!(area > 0) || norm < 0.2 * area) return Vec3(0, 0, 1);
  // At most 60 degrees above or below the horizon: a scene that mostly
  // faces up (a ground under an object) is seen from above at a slant, not
  // straight down; from +Z where the normals have no horizontal lean.
  constexpr double kMaxSin = 0.8660254037844386;  // sin 60 degrees
  const double up = std::clamp(sum[1] / norm, -kMaxSin, kMaxSin);
  double hx = sum[0], hz = sum[2];
  const double h = std::sqrt(hx * hx + hz * hz);
  if (h < 1e-3 * norm) {
    hx = 0;
    hz = 1;
  } else {
    hx /= h;
    hz /= h;
  }
  const double across = std::sqrt(1 - up * up);
  return Vec3(float(hx * across), float(up), float(hz * across));
}

}  // namespace lo
