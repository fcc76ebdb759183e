/// @file cluster/volume_light.cpp
/// @brief buildVolumeLight: rays bucketed by slab of voxels, walked voxel by
/// voxel (Amanatides and Woo) within each slab, their track lengths projected
/// on the SH of shaders/octree_layout.h.

#include "cluster/volume_light.h"

#include <octree_layout.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "core/error.h"

namespace lo {

namespace volume_light_internal {

struct Vec3dd {
  double x, y, z;
  double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
};

/// The part [t0, t1] of the ray p0 + t (p1 - p0), t in [0, 1], inside the
/// box [lower, upper]; false when it misses.
bool clipToBox(const Vec3dd& p0, const Vec3dd& d, const double lower[3], const double upper[3],
               double& t0, double& t1) {
  t0 = 0;
  t1 = 1;
  for (int a = 0; a < 3; ++a) {
    if (d[a] == 0) {
      if (p0[a] < lower[a] || p0[a] > upper[a]) return false;
      continue;
    }
    double ta = (lower[a] - p0[a]) / d[a], tb = (upper[a] - p0[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 >= t1) return false;
  }
  return true;
}

/// Shortest track, in voxels, that counts as light in a voxel.
constexpr double kMinTrack = 1e-4;

/// A lit box within this of a voxel's face reaches it.
constexpr double kFaceTolerance = 1e-6;

/// What one voxel of a slab gathers, but its SH sums (kept apart, so that
/// a slab's cells stay small in the cache).
struct Cell {
  double fluence[3] = {0, 0, 0};
  double lower[3] = {1, 1, 1}, upper[3] = {0, 0, 0};
  uint32_t rays = 0;
  bool full = false;  ///< the box reaches every face: no ray can grow it
};

}  // namespace volume_light_internal

VolumeLight buildVolumeLight(const std::vector<PhotonSegment>& segments, const GridFrame& surface,
                             const VolumeLightParams& params, ProgressSink* progress) {
  using namespace volume_light_internal;
  if (params.levels < 0 || (params.shTerms != 4 && params.shTerms != 9)) {
    throw InputError("free-space light: levels " + std::to_string(params.levels) + " and " +
                     std::to_string(params.shTerms) + " SH terms; need levels >= 0 and 4 or 9 terms");
  }
  VolumeLight out;
  out.shTerms = params.shTerms;
  const int depth = std::max(1, surface.depth - params.levels);
  out.frame = surface;
  out.frame.depth = depth;
  out.frame.voxelSize = surface.voxelSize * float(1 << std::max(0, surface.depth - depth));
  const int res = out.frame.resolution();
  const double size = double(out.frame.voxelSize);
  const double volume = size * size * size;
  const Vec3 origin = out.frame.origin;
  auto local = [&](const Vec3& p) {
    return Vec3dd{(double(p.x) - origin.x) / size, (double(p.y) - origin.y) / size,
                  (double(p.z) - origin.z) / size};
  };
  Progress bar(progress, "Free-space light", size_t(res));

  // Slabs of `thick` z layers: each ray listed in the slabs it crosses, in
  // order, with the part of it inside the cube. A voxel's sums follow the
  // rays' order whatever the slabs, so their thickness changes no bit.
  // A slab per thread: a ray's set-up (its SH basis, clipping) is paid once
  // per slab it crosses, which costs more than the slabs' uneven loads.
  const int slabsWanted =
      params.slabs > 0 ? params.slabs : std::max(1, tbb::this_task_arena::max_concurrency());
  const int thick = std::max(1, (res + slabsWanted - 1) / slabsWanted);
  const int slabCount = (res + thick - 1) / thick;
  std::vector<std::vector<uint32_t>> slabs(static_cast<size_t>(slabCount));
  std::vector<float> clipStart(segments.size(), 0.0f), clipEnd(segments.size(), 0.0f);
  std::vector<int32_t> firstSlab(segments.size(), -1), lastSlab(segments.size(), -1);
  const double cubeLower[3] = {0, 0, 0}, cubeUpper[3] = {double(res), double(res), double(res)};
  LO_CHECK(segments.size() < size_t(std::numeric_limits<uint32_t>::max()));
  tbb::parallel_for(tbb::blocked_range<size_t>(0, segments.size(), 16384),
                    [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const PhotonSegment& s = segments[i];
      if (!(maxComponent(s.power) > 0) || !isFinite(s.from) || !isFinite(s.to)) continue;
      const Vec3dd p0 = local(s.from), p1 = local(s.to);
      const Vec3dd d{p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
      double t0, t1;
      if (!clipToBox(p0, d, cubeLower, cubeUpper, t0, t1)) continue;
      clipStart[i] = float(t0);
      clipEnd[i] = float(t1);
      const double za = p0.z + d.z * t0, zb = p0.z + d.z * t1;
      firstSlab[i] = std::clamp(int(std::floor(std::min(za, zb))), 0, res - 1) / thick;
      lastSlab[i] = std::clamp(int(std::floor(std::max(za, zb))), 0, res - 1) / thick;
    }
  });
  for (size_t i = 0; i < segments.size(); ++i) {
    for (int z = firstSlab[i]; z >= 0 && z <= lastSlab[i]; ++z) slabs[size_t(z)].push_back(uint32_t(i));
  }

  std::vector<std::vector<Coord>> slabCoords(static_cast<size_t>(slabCount));
  std::vector<std::vector<Cell>> slabCells(static_cast<size_t>(slabCount));
  std::vector<std::vector<double>> slabSums(static_cast<size_t>(slabCount));  // terms x 3 per cell
  const int terms = params.shTerms;
  auto walkSlab = [&](int slab) {
    const int zLow = slab * thick, zHigh = std::min(res, zLow + thick);
    const int layers = zHigh - zLow;
    std::vector<Cell> cells(size_t(res) * size_t(res) * size_t(layers));
    const size_t per = size_t(terms) * 3;
    std::vector<double> sums(cells.size() * per, 0.0);
    for (uint32_t i : slabs[size_t(slab)]) {
      const PhotonSegment& s = segments[i];
      const Vec3dd p0 = local(s.from), p1 = local(s.to);
      const Vec3dd d{p1.x - p0.x, p1.y - p0.y, p1.z - p0.z};
      // The cube's part of the ray, cut to the slab.
      double ta = clipStart[i], tb = clipEnd[i];
      if (d.z != 0) {
        double za = (double(zLow) - p0.z) / d.z, zb = (double(zHigh) - p0.z) / d.z;
        if (za > zb) std::swap(za, zb);
        ta = std::max(ta, za);
        tb = std::min(tb, zb);
      }
      if (!(ta < tb)) continue;
      const double length = std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z);  // voxel units
      if (!(length > 0)) continue;
      // Towards where the light came from.
      const float fx = float(-d.x / length), fy = float(-d.y / length), fz = float(-d.z / length);
      const double scale = length * size / volume;  // track length (world) per volume, per unit t
      // Power times each basis function, per unit of t.
      double weighted[layout::LO_SH_MAX_TERMS][3];
      for (int k = 0; k < terms; ++k) {
        const double y = double(layout::loShBasis(uint32_t(k), fx, fy, fz));
        for (int a = 0; a < 3; ++a) weighted[k][a] = y * double(s.power[a]) * scale;
      }
      const double flux[3] = {double(s.power.x) * scale, double(s.power.y) * scale,
                              double(s.power.z) * scale};
      const double tEps = (tb - ta) * 1e-9;
      const int lowCell[3] = {0, 0, zLow}, highCell[3] = {res - 1, res - 1, zHigh - 1};
      int cell[3], step[3];
      double tMax[3], inverse[3];
      for (int a = 0; a < 3; ++a) {
        const double pa = p0[a] + d[a] * (ta + tEps);
        cell[a] = std::clamp(int(std::floor(pa)), lowCell[a], highCell[a]);
        step[a] = d[a] > 0 ? 1 : -1;
        inverse[a] = d[a] != 0 ? 1.0 / d[a] : 0.0;
        tMax[a] = d[a] != 0 ? (double(cell[a] + (d[a] > 0 ? 1 : 0)) - p0[a]) * inverse[a]
                            : std::numeric_limits<double>::infinity();
      }
      double t = ta;
      for (int guard = 0; guard < 2 * res + layers + 4; ++guard) {
        const double tNext = std::min({tMax[0], tMax[1], tMax[2], tb});
        // A track shorter than kMinTrack (a ray ending on a wall that lies on
        // a voxel face, rounded into the next voxel) lights nothing there.
        if ((tNext - t) * length > kMinTrack) {
          const size_t index =
              (size_t(cell[2] - zLow) * size_t(res) + size_t(cell[1])) * size_t(res) + size_t(cell[0]);
          Cell& c = cells[index];
          double* sum = &sums[index * per];
          const double dt = tNext - t;
          for (int a = 0; a < 3; ++a) c.fluence[a] += flux[a] * dt;
          if (!c.full) {
            bool full = true;
            for (int a = 0; a < 3; ++a) {
              const double u = std::clamp(p0[a] + d[a] * t - double(cell[a]), 0.0, 1.0);
              const double v = std::clamp(p0[a] + d[a] * tNext - double(cell[a]), 0.0, 1.0);
              c.lower[a] = std::min({c.lower[a], u, v});
              c.upper[a] = std::max({c.upper[a], u, v});
              full = full && c.lower[a] <= kFaceTolerance && c.upper[a] >= 1.0 - kFaceTolerance;
            }
            if (full) {
              for (int a = 0; a < 3; ++a) {
                c.lower[a] = 0;
                c.upper[a] = 1;
              }
              c.full = true;
            }
          }
          for (int k = 0; k < terms; ++k) {
            for (int a = 0; a < 3; ++a) sum[k * 3 + a] += weighted[k][a] * dt;
          }
          ++c.rays;
        }
        if (tNext >= tb) break;
        const int a = tMax[0] < tMax[1] ? (tMax[0] < tMax[2] ? 0 : 2) : (tMax[1] < tMax[2] ? 1 : 2);
        cell[a] += step[a];
        if (cell[a] < lowCell[a] || cell[a] > highCell[a]) break;
        t = tNext;
        // From the face's own coordinate, not summed steps: a crossing's t
        // is the same whichever slab the walk started in.
        tMax[a] = (double(cell[a] + (d[a] > 0 ? 1 : 0)) - p0[a]) * inverse[a];
      }
    }
    for (int z = zLow; z < zHigh; ++z) {
      for (int y = 0; y < res; ++y) {
        for (int x = 0; x < res; ++x) {
          const size_t index = (size_t(z - zLow) * size_t(res) + size_t(y)) * size_t(res) + size_t(x);
          const Cell& c = cells[index];
          if (c.rays == 0 || !(c.fluence[0] + c.fluence[1] + c.fluence[2] > 0)) continue;
          slabCoords[size_t(slab)].push_back(Coord{x, y, z});
          slabCells[size_t(slab)].push_back(c);
          slabSums[size_t(slab)].insert(slabSums[size_t(slab)].end(), sums.begin() + std::ptrdiff_t(index * per),
                                        sums.begin() + std::ptrdiff_t((index + 1) * per));
        }
      }
    }
  };
  tbb::parallel_for(tbb::blocked_range<int>(0, slabCount, 1), [&](const tbb::blocked_range<int>& r) {
    for (int slab = r.begin(); slab != r.end(); ++slab) {
      walkSlab(slab);
      slabs[size_t(slab)] = std::vector<uint32_t>();
    }
  });
  bar.advance(size_t(res));

  struct Entry {
    uint64_t key;
    int z;
    size_t index;
  };
  std::vector<Entry> order;
  for (int z = 0; z < slabCount; ++z) {
    for (size_t k = 0; k < slabCoords[size_t(z)].size(); ++k) {
      order.push_back({canonicalVoxelKey(slabCoords[size_t(z)][k]), z, k});
    }
  }
  std::sort(order.begin(), order.end(), [](const Entry& a, const Entry& b) { return a.key < b.key; });
  const size_t n = order.size();
  out.coords.resize(n);
  out.irradiance.resize(n);
  out.sh.resize(n * size_t(terms));
  out.segments.resize(n);
  out.litLower.resize(n);
  out.litUpper.resize(n);
  for (size_t v = 0; v < n; ++v) {
    const Cell& c = slabCells[size_t(order[v].z)][order[v].index];
    const double* sum = &slabSums[size_t(order[v].z)][order[v].index * size_t(terms) * 3];
    out.coords[v] = slabCoords[size_t(order[v].z)][order[v].index];
    out.irradiance[v] = Vec3{float(c.fluence[0] / 4), float(c.fluence[1] / 4), float(c.fluence[2] / 4)};
    for (int k = 0; k < terms; ++k) {
      const double band = double(layout::loShCosineBand(uint32_t(k)));
      out.sh[v * size_t(terms) + size_t(k)] =
          Vec3{float(sum[k * 3] * band), float(sum[k * 3 + 1] * band), float(sum[k * 3 + 2] * band)};
    }
    out.segments[v] = float(c.rays);
    out.litLower[v] = Vec3{float(c.lower[0]), float(c.lower[1]), float(c.lower[2])};
    out.litUpper[v] = Vec3{float(c.upper[0]), float(c.upper[1]), float(c.upper[2])};
  }
  return out;
}

}  // namespace lo
