#pragma once
/// @file core/math.h
/// @brief Plain value types shared by every stage: Vec3, Coord, Bounds3.
/// Stages exchange these instead of a third-party math type, so that a stage's
/// public header never pulls in another stage's library.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

namespace lo {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 1.0f / kPi;

struct Vec3 {
  float x = 0, y = 0, z = 0;

  constexpr Vec3() = default;
  constexpr Vec3(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr explicit Vec3(float s) : x(s), y(s), z(s) {}

  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3 operator-() const { return {-x, -y, -z}; }
  constexpr Vec3 operator+(const Vec3& b) const { return {x + b.x, y + b.y, z + b.z}; }
  constexpr Vec3 operator-(const Vec3& b) const { return {x - b.x, y - b.y, z - b.z}; }
  constexpr Vec3 operator*(const Vec3& b) const { return {x * b.x, y * b.y, z * b.z}; }
  constexpr Vec3 operator/(const Vec3& b) const { return {x / b.x, y / b.y, z / b.z}; }
  constexpr Vec3 operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3 operator/(float s) const { return {x / s, y / s, z / s}; }
  Vec3& operator+=(const Vec3& b) { x += b.x; y += b.y; z += b.z; return *this; }
  Vec3& operator-=(const Vec3& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
  Vec3& operator*=(const Vec3& b) { x *= b.x; y *= b.y; z *= b.z; return *this; }
  Vec3& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
  Vec3& operator/=(float s) { x /= s; y /= s; z /= s; return *this; }
  constexpr bool operator==(const Vec3& b) const { return x == b.x && y == b.y && z == b.z; }
  constexpr bool operator!=(const Vec3& b) const { return !(*this == b); }

  std::string ToString() const;
};

constexpr Vec3 operator*(float s, const Vec3& v) { return v * s; }
constexpr float dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3& v) { return std::sqrt(dot(v, v)); }
constexpr float lengthSquared(const Vec3& v) { return dot(v, v); }
/// Unit vector along v; the zero vector stays zero (no NaN).
inline Vec3 normalize(const Vec3& v) {
  // Vectors whose squared length leaves float's normal range (sums of photon
  // powers of 1e-20 W; or 1e20) are scaled by their largest component
  // first: their squares would be denormal, or flushed to zero on threads
  // that run with denormals off (as a ray tracer's worker may leave them),
  // and the result would depend on the thread (a "unit" vector of length
  // 1.005). Inside the range: the plain quotient, bit for bit as ever.
  const float l2 = dot(v, v);
  if (!(l2 > 1e-30f && l2 < 1e30f)) {
    const float m = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
    if (!(m > 0) || !std::isfinite(m)) return l2 > 0 && std::isfinite(l2) ? v / std::sqrt(l2) : Vec3{};
    const Vec3 w = v / m;
    return w / std::sqrt(dot(w, w));
  }
  float l = length(v);
  return l > 0 ? v / l : Vec3{};
}
inline Vec3 min(const Vec3& a, const Vec3& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
inline Vec3 max(const Vec3& a, const Vec3& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
constexpr float maxComponent(const Vec3& v) {
  return v.x > v.y ? (v.x > v.z ? v.x : v.z) : (v.y > v.z ? v.y : v.z);
}
/// Mean of the three channels: the scalar "power" of an RGB triple.
constexpr float average(const Vec3& v) { return (v.x + v.y + v.z) * (1.0f / 3.0f); }
/// Rec. 709 luminance of a linear RGB triple.
constexpr float luminance(const Vec3& v) { return 0.2126f * v.x + 0.7152f * v.y + 0.0722f * v.z; }
inline bool isFinite(const Vec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Builds an orthonormal basis (t, b, n) around unit n (Duff et al. 2017,
/// branchless, no singularity at the poles).
inline void orthonormalBasis(const Vec3& n, Vec3& t, Vec3& b) {
  float sign = std::copysign(1.0f, n.z);
  float a = -1.0f / (sign + n.z);
  float c = n.x * n.y * a;
  t = {1.0f + sign * n.x * n.x * a, sign * c, -sign * n.x};
  b = {c, sign + n.y * n.y * a, -n.y};
}

/// A double-precision 3-vector, for geometry that must not depend on the
/// order of float operations (voxelization's overlap tests, chart flattening).
struct Vec3d {
  double x = 0, y = 0, z = 0;
  Vec3d() = default;
  Vec3d(double x_, double y_, double z_) : x(x_), y(y_), z(z_) {}
  explicit Vec3d(const Vec3& v) : x(v.x), y(v.y), z(v.z) {}
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  Vec3d operator+(const Vec3d& b) const { return {x + b.x, y + b.y, z + b.z}; }
  Vec3d operator-(const Vec3d& b) const { return {x - b.x, y - b.y, z - b.z}; }
  Vec3d operator*(double s) const { return {x * s, y * s, z * s}; }
  Vec3d& operator+=(const Vec3d& b) {
    x += b.x;
    y += b.y;
    z += b.z;
    return *this;
  }
  Vec3 toVec3() const { return {float(x), float(y), float(z)}; }
};
inline double dot(const Vec3d& a, const Vec3d& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const Vec3d& v) { return std::sqrt(dot(v, v)); }
inline Vec3d normalize(const Vec3d& v) {
  const double l = length(v);
  return l > 0 ? v * (1.0 / l) : Vec3d{};
}

/// Integer voxel coordinate (index space of a grid).
struct Coord {
  int32_t x = 0, y = 0, z = 0;
  constexpr bool operator==(const Coord& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Coord& o) const { return !(*this == o); }
  constexpr bool operator<(const Coord& o) const {
    return x != o.x ? x < o.x : (y != o.y ? y < o.y : z < o.z);
  }
  std::string ToString() const;
};

/// Axis-aligned box; an empty box has lower > upper.
struct Bounds3 {
  Vec3 lower{INFINITY, INFINITY, INFINITY};
  Vec3 upper{-INFINITY, -INFINITY, -INFINITY};

  bool empty() const { return lower.x > upper.x || lower.y > upper.y || lower.z > upper.z; }
  void extend(const Vec3& p) { lower = min(lower, p); upper = max(upper, p); }
  void extend(const Bounds3& b) { lower = min(lower, b.lower); upper = max(upper, b.upper); }
  Vec3 extent() const { return upper - lower; }
  Vec3 center() const { return (lower + upper) * 0.5f; }
  std::string ToString() const;
};

}  // namespace lo
