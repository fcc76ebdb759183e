#include "lightgrid/grid_frame.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/error.h"

namespace lo {
namespace {

int32_t clampedFloor(double t) {
  // Keeps far-away or non-finite points representable as int32 coordinates.
  if (!(t > -1e9)) return -1000000000;
  if (t > 1e9) return 1000000000;
  return int32_t(std::floor(t));
}

}  // namespace

Vec3 GridFrame::voxelCenter(const Coord& c) const {
  const double vs = voxelSize;
  return {float(double(origin.x) + (c.x + 0.5) * vs), float(double(origin.y) + (c.y + 0.5) * vs),
          float(double(origin.z) + (c.z + 0.5) * vs)};
}

Bounds3 GridFrame::voxelBounds(const Coord& c) const {
  const double vs = voxelSize;
  Bounds3 b;
  b.lower = {float(double(origin.x) + c.x * vs), float(double(origin.y) + c.y * vs),
             float(double(origin.z) + c.z * vs)};
  b.upper = {float(double(origin.x) + (c.x + 1.0) * vs), float(double(origin.y) + (c.y + 1.0) * vs),
             float(double(origin.z) + (c.z + 1.0) * vs)};
  return b;
}

Coord GridFrame::coordOf(const Vec3& p) const {
  const double vs = voxelSize;
  return {clampedFloor((double(p.x) - origin.x) / vs), clampedFloor((double(p.y) - origin.y) / vs),
          clampedFloor((double(p.z) - origin.z) / vs)};
}

std::string GridFrame::ToString() const {
  std::ostringstream os;
  os.precision(9);
  os << "GridFrame{origin " << origin.ToString() << ", voxel " << voxelSize << ", depth " << depth;
  if (offset.x != 0 || offset.y != 0 || offset.z != 0) {
    os << ", offset (" << offset.x << ", " << offset.y << ", " << offset.z << ")";
  }
  os << "}";
  return os.str();
}

GridFrame makeGridFrame(const Bounds3& sceneBounds, int depth, float padding) {
  if (depth < 1 || depth > kMaxGridDepth) {
    throw InputError("grid depth " + std::to_string(depth) + " is outside [1, " + std::to_string(kMaxGridDepth) + "]");
  }
  if (!(padding >= 0.0f) || !std::isfinite(padding)) {
    throw InputError("grid padding " + std::to_string(padding) + " must be finite and >= 0");
  }
  if (sceneBounds.empty() || !isFinite(sceneBounds.lower) || !isFinite(sceneBounds.upper)) {
    throw InputError("scene bounds " + sceneBounds.ToString() + " are empty or not finite");
  }
  const double ex = double(sceneBounds.upper.x) - sceneBounds.lower.x;
  const double ey = double(sceneBounds.upper.y) - sceneBounds.lower.y;
  const double ez = double(sceneBounds.upper.z) - sceneBounds.lower.z;
  const double extent = std::max({ex, ey, ez});
  const int res = 1 << depth;
  const double edge = extent * (1.0 + 2.0 * double(padding));
  const double vs = edge / res;
  // A single point (or a box so small that the voxel size underflows float)
  // has no meaningful cube to divide.
  if (!(extent > 0) || !(float(vs) >= std::numeric_limits<float>::min())) {
    throw InputError("scene bounds " + sceneBounds.ToString() + " are degenerate (largest extent " +
                     std::to_string(extent) + ")");
  }
  GridFrame f;
  f.depth = depth;
  f.voxelSize = float(vs);
  const double center[3] = {0.5 * (double(sceneBounds.lower.x) + sceneBounds.upper.x),
                            0.5 * (double(sceneBounds.lower.y) + sceneBounds.upper.y),
                            0.5 * (double(sceneBounds.lower.z) + sceneBounds.upper.z)};
  for (int a = 0; a < 3; ++a) f.origin[a] = float(center[a] - 0.5 * edge);
  // Rounding the frame to float must not leave part of the scene outside the
  // grid (it matters only with zero padding): grow the voxel size / lower the
  // origin by ulps until the float frame covers the bounds.
  for (int iter = 0; iter < 64; ++iter) {
    bool covered = true;
    for (int a = 0; a < 3; ++a) {
      if (double(f.origin[a]) > double(sceneBounds.lower[a])) {
        f.origin[a] = std::nextafter(f.origin[a], -INFINITY);
        covered = false;
      }
      if (double(f.origin[a]) + res * double(f.voxelSize) < double(sceneBounds.upper[a])) {
        f.voxelSize = std::nextafter(f.voxelSize, INFINITY);
        covered = false;
      }
    }
    if (covered) break;
  }
  return f;
}

}  // namespace lo
