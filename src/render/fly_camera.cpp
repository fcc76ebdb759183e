// FlyCamera: yaw/pitch walkthrough camera math.

#include "render/fly_camera.h"

#include <cmath>
#include <sstream>

namespace lo {

FlyCamera FlyCamera::lookingAt(const Vec3& eye, const Vec3& target, float yfovRadians) {
  FlyCamera c;
  c.position = eye;
  c.yfov = yfovRadians;
  Vec3 d = normalize(target - eye);
  if (lengthSquared(d) > 0) {
    // forward = (cos p sin y, sin p, -cos p cos y), see forward().
    c.pitch = std::clamp(std::asin(std::clamp(d.y, -1.0f, 1.0f)), -kMaxPitch, kMaxPitch);
    if (d.x != 0 || d.z != 0) c.yaw = std::atan2(d.x, -d.z);
  }
  return c;
}

Vec3 FlyCamera::forward() const {
  float cp = std::cos(pitch);
  return {cp * std::sin(yaw), std::sin(pitch), -cp * std::cos(yaw)};
}

Vec3 FlyCamera::right() const { return {std::cos(yaw), 0.0f, std::sin(yaw)}; }

Vec3 FlyCamera::up() const { return normalize(cross(right(), forward())); }

void FlyCamera::move(const Vec3& direction, float seconds) {
  float n = length(direction);
  if (!(n > 0)) return;
  Vec3 d = direction / n;
  Vec3 world = right() * d.x + Vec3(0, 1, 0) * d.y + forward() * d.z;
  position += world * (speed * seconds);
}

void FlyCamera::turn(float yawRadians, float pitchRadians) {
  yaw = std::remainder(yaw + yawRadians, 2.0f * kPi);
  pitch = std::clamp(pitch + pitchRadians, -kMaxPitch, kMaxPitch);
}

PinholeCamera FlyCamera::camera() const {
  PinholeCamera c;
  c.eye = position;
  c.forward = forward();
  c.up = up();
  c.yfov = yfov;
  return c;
}

CameraKey FlyCamera::key(float time) const {
  CameraKey k;
  k.time = time;
  k.eye = position;
  k.target = position + forward();
  k.fovDegrees = yfov * 180.0f / kPi;
  return k;
}

std::string FlyCamera::ToString() const {
  std::ostringstream os;
  os << "FlyCamera{position " << position.ToString() << ", yaw " << yaw << ", pitch " << pitch
     << ", yfov " << yfov << ", speed " << speed << "}";
  return os.str();
}

}  // namespace lo
