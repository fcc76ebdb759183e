#pragma once
/// @file render/fly_camera.h
/// @brief The walkthrough camera of `lightoctree view`: a position and a
/// yaw/pitch heading about the world up axis +Y (glTF's up). The input
/// handling (keys, mouse) lives in the tool; the math is here for tests.

#include <string>

#include "core/math.h"
#include "render/camera_path.h"
#include "render/renderer.h"

namespace lo {

struct FlyCamera {
  /// Pitch stays within +-89 degrees so that the view never lines up with +Y
  /// (where yaw is undefined and a look-at frame degenerates).
  static constexpr float kMaxPitch = 89.0f * kPi / 180.0f;

  Vec3 position{0, 0, 1};  ///< world space
  float yaw = 0;           ///< radians about +Y; 0 looks along -Z, positive turns towards +X
  float pitch = 0;         ///< radians above the horizon, |pitch| <= kMaxPitch
  float yfov = 0.785398f;  ///< vertical field of view, radians
  float speed = 1;         ///< scene units per second

  /// At `eye`, looking at `target` (pitch clamped as above).
  static FlyCamera lookingAt(const Vec3& eye, const Vec3& target, float yfovRadians);

  Vec3 forward() const;  ///< unit view direction
  Vec3 right() const;    ///< unit, horizontal, = forward x +Y normalized
  Vec3 up() const;       ///< unit, right x forward

  /// Moves `seconds * speed` along `direction` given in the camera's frame:
  /// x = right, y = world up (+Y), z = forward. `direction` need not be unit
  /// (diagonal key presses are normalized so they are not faster).
  void move(const Vec3& direction, float seconds);
  /// Adds to yaw (wrapped to [-pi, pi]) and pitch (clamped), radians.
  void turn(float yawRadians, float pitchRadians);

  PinholeCamera camera() const;
  /// A camera path keyframe: the target one unit along the view direction.
  CameraKey key(float time) const;
  std::string ToString() const;
};

}  // namespace lo
