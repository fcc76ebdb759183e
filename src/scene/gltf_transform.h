#pragma once
/// @file scene/gltf_transform.h
/// @brief The glTF loader's node transforms (internal to src/scene).

#include <array>
#include <cmath>
#include <vector>

#include "core/math.h"

namespace lo::scene_internal {

// 4x4 transforms, column-major like glTF (m[col * 4 + row]), in double so that
// deep hierarchies do not accumulate float error.
struct Mat4 {
  std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

  double& at(int row, int col) { return m[size_t(col * 4 + row)]; }
  double at(int row, int col) const { return m[size_t(col * 4 + row)]; }

  Mat4 operator*(const Mat4& b) const {
    Mat4 r;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) {
        double s = 0;
        for (int k = 0; k < 4; ++k) s += at(i, k) * b.at(k, j);
        r.at(i, j) = s;
      }
    return r;
  }
  Vec3 point(const Vec3& p) const { return pointInDouble(p).toVec3(); }
  /// The transformed point before rounding to float (the loader rebases it).
  Vec3d pointInDouble(const Vec3& p) const {
    return {at(0, 0) * p.x + at(0, 1) * p.y + at(0, 2) * p.z + at(0, 3),
            at(1, 0) * p.x + at(1, 1) * p.y + at(1, 2) * p.z + at(1, 3),
            at(2, 0) * p.x + at(2, 1) * p.y + at(2, 2) * p.z + at(2, 3)};
  }
  Vec3 vector(const Vec3& v) const {
    double x = at(0, 0) * v.x + at(0, 1) * v.y + at(0, 2) * v.z;
    double y = at(1, 0) * v.x + at(1, 1) * v.y + at(1, 2) * v.z;
    double z = at(2, 0) * v.x + at(2, 1) * v.y + at(2, 2) * v.z;
    return {float(x), float(y), float(z)};
  }
  double det3() const {
    return at(0, 0) * (at(1, 1) * at(2, 2) - at(1, 2) * at(2, 1)) -
           at(0, 1) * (at(1, 0) * at(2, 2) - at(1, 2) * at(2, 0)) +
           at(0, 2) * (at(1, 0) * at(2, 1) - at(1, 1) * at(2, 0));
  }
  /// Inverse transpose of the upper 3x3 (normals), up to the positive factor
  /// |det|: the cofactor matrix times sign(det). Normals are renormalized after.
  Mat4 normalMatrix() const {
    Mat4 r;
    double s = det3() < 0 ? -1.0 : 1.0;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
        r.at(i, j) = s * (at(i1, j1) * at(i2, j2) - at(i1, j2) * at(i2, j1));
      }
    return r;
  }
};

/// A glTF node's local transform: its matrix when it has 16 values, else
/// translation * rotation (a quaternion, normalized) * scale.
inline Mat4 localTransform(const std::vector<double>& matrix, const std::vector<double>& translation,
                           const std::vector<double>& rotation, const std::vector<double>& scale) {
  Mat4 r;
  if (matrix.size() == 16) {
    for (size_t i = 0; i < 16; ++i) r.m[i] = matrix[i];
    return r;
  }
  Mat4 t, rot, s;
  if (translation.size() == 3) {
    t.at(0, 3) = translation[0];
    t.at(1, 3) = translation[1];
    t.at(2, 3) = translation[2];
  }
  if (rotation.size() == 4) {
    double x = rotation[0], y = rotation[1], z = rotation[2], w = rotation[3];
    double n = std::sqrt(x * x + y * y + z * z + w * w);
    if (n > 0) x /= n, y /= n, z /= n, w /= n;
    rot.at(0, 0) = 1 - 2 * (y * y + z * z);
    rot.at(0, 1) = 2 * (x * y - z * w);
    rot.at(0, 2) = 2 * (x * z + y * w);
    rot.at(1, 0) = 2 * (x * y + z * w);
    rot.at(1, 1) = 1 - 2 * (x * x + z * z);
    rot.at(1, 2) = 2 * (y * z - x * w);
    rot.at(2, 0) = 2 * (x * z - y * w);
    rot.at(2, 1) = 2 * (y * z + x * w);
    rot.at(2, 2) = 1 - 2 * (x * x + y * y);
  }
  if (scale.size() == 3) {
    s.at(0, 0) = scale[0];
    s.at(1, 1) = scale[1];
    s.at(2, 2) = scale[2];
  }
  return t * rot * s;
}

}  // namespace lo::scene_internal
