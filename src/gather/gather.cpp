// KNN prefiltering per voxel (paper §3.1.1): the k nearest photons within a
// radius r, distances measured in an ellipsoid aligned with the voxel normal.
//
// Candidates come from the photon bins of nearby active voxels (the surface
// grid is the search structure: §4.1 fetched photons "directly using the
// octree"). The active neighbours of an 8^3 block are looked up once and
// reused by every voxel of the block; each voxel then prunes them by the
// distance from its query point to their box. See docs/grid-and-gather.md for
// the measurements behind this choice.

#include "gather/gather.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>
#include <utility>

#include "core/error.h"

namespace lo {

namespace gather_internal {

/// Squared ellipsoid distance d^2 = |D - (D.n)n|^2 + (s (D.n))^2, D = p - q,
/// written as |D|^2 + (s^2 - 1)(D.n)^2 (n unit, or zero for a sphere).
/// `squash2m1` = s^2 - 1. Both gather paths call this one function on the same
/// float inputs, so the grid gather and the brute force see identical distances.
inline float ellipsoidDistance2(const Vec3& p, const Vec3& q, const Vec3& n, float squash2m1) {
  const Vec3 d = p - q;
  const float dn = dot(d, n);
  return std::max(0.0f, lengthSquared(d) + squash2m1 * dn * dn);
}

struct Query {
  Vec3 point;
  Vec3 normal;  ///< unit, or zero: sphere metric
  float squash2m1;
  float radius2;
};

/// Accumulated over the photons within r (either side of the surface).
struct Scan {
  double orientation = 0;      ///< sum of average(power) * sign(dot(photon normal, n))
  double mean[3] = {0, 0, 0};  ///< sum of average(power) * photon normal (sphere metric only)
};

struct Lists {
  std::vector<uint64_t>& front;  ///< dot(photon normal, n) > 0, or everything when n = 0
  std::vector<uint64_t>& back;   ///< dot(photon normal, n) < 0
};

/// (d^2, index) as one integer: for d^2 >= 0 the float's bit pattern orders
/// like its value.
inline uint64_t candidateKey(float d2, uint32_t index) {
  uint32_t bits;
  std::memcpy(&bits, &d2, sizeof bits);
  return uint64_t(bits) << 32 | index;
}
inline float candidateDistance2(uint64_t key) {
  const uint32_t bits = uint32_t(key >> 32);
  float d2;
  std::memcpy(&d2, &bits, sizeof d2);
  return d2;
}

/// P is Photon or Gatherer's LocalPhoton (position, normal, power).
template <typename P>
inline void scanPhoton(const P& ph, uint32_t index, const Query& q, Lists& lists, Scan& scan) {
  const float d2 = ellipsoidDistance2(ph.position, q.point, q.normal, q.squash2m1);
  if (!(d2 <= q.radius2)) return;  // also drops NaN positions
  const uint64_t key = candidateKey(d2, index);
  const float w = average(ph.power);
  const float c = dot(ph.normal, q.normal);
  if (c > 0) {
    lists.front.push_back(key);
    scan.orientation += w;
  } else if (c < 0) {
    lists.back.push_back(key);
    scan.orientation -= w;
  } else if (q.normal == Vec3{}) {
    lists.front.push_back(key);
    scan.mean[0] += double(w) * ph.normal.x;
    scan.mean[1] += double(w) * ph.normal.y;
    scan.mean[2] += double(w) * ph.normal.z;
  }
  // else: exactly perpendicular to a non-zero n, rejected on either side.
}

/// Runs the orientation rule around `collect(query, lists, scan)`, which must
/// pass every photon within the radius to scanPhoton (any order):
///  1. n = the voxel normal, flipped towards the side the light arrives from
///     (sign of the power-weighted vote of the candidates' photon normals);
///  2. if the voxel normal is zero (cancelling faces), n = the power-weighted
///     mean of the candidates' photon normals (sphere metric), and the
///     candidates are collected again with the ellipsoid along that n;
///  3. if that is zero too, the sphere metric without back rejection.
/// Photons with dot(photon normal, n) <= 0 arrived from behind (the photon
/// normal faces its arrival side, so this also removes photons on the back of a
/// thin wall) and are rejected; the k nearest by (d^2, index) are kept.
template <typename Collect>
void gatherWith(const SurfaceGrid& grid, const std::vector<Photon>& photons, size_t voxel,
                const GatherParams& params, float radius, std::vector<uint64_t>& front,
                std::vector<uint64_t>& back, GatherResult& out, Collect&& collect) {
  Query query;
  query.point = grid.centroids[voxel];
  query.normal = grid.normals[voxel];
  query.squash2m1 = params.normalSquash * params.normalSquash - 1.0f;
  query.radius2 = radius * radius;

  Lists lists{front, back};
  Scan scan;
  front.clear();
  back.clear();
  collect(query, lists, scan);
  if (query.normal == Vec3{}) {
    const Vec3 mean =
        normalize(Vec3{float(scan.mean[0]), float(scan.mean[1]), float(scan.mean[2])});
    if (mean != Vec3{}) {
      query.normal = mean;
      scan = Scan{};
      front.clear();
      collect(query, lists, scan);
    }
  }
  Vec3 n = query.normal;
  if (scan.orientation < 0) {
    n = -n;
    std::swap(front, back);
  }

  const size_t k = size_t(params.k);
  float rk = radius;
  if (front.size() > k) {
    std::nth_element(front.begin(), front.begin() + std::ptrdiff_t(k - 1), front.end());
    rk = std::sqrt(candidateDistance2(front[k - 1]));
    front.resize(k);
  } else if (front.size() == k) {
    rk = std::sqrt(candidateDistance2(*std::max_element(front.begin(), front.end())));
  }
  // k photons at one point: no area to divide by, so fall back to the radius.
  if (!(rk > 0)) rk = radius;

  out.photons.resize(front.size());
  double power[3] = {0, 0, 0};
  for (size_t i = 0; i < front.size(); ++i) {
    const uint32_t p = uint32_t(front[i]);
    out.photons[i] = p;
    power[0] += photons[p].power.x;
    power[1] += photons[p].power.y;
    power[2] += photons[p].power.z;
  }
  const double invArea = 1.0 / (double(kPi) * double(rk) * double(rk));
  out.radius = rk;
  out.normal = n;
  out.irradiance = {float(power[0] * invArea), float(power[1] * invArea),
                    float(power[2] * invArea)};
}

void checkParams(const GatherParams& params) {
  if (params.k < 1) throw InputError("gather k " + std::to_string(params.k) + " must be >= 1");
  if (!(params.normalSquash > 0) || !std::isfinite(params.normalSquash)) {
    throw InputError("gather normalSquash " + std::to_string(params.normalSquash) +
                     " must be finite and > 0");
  }
}

/// Euclidean reach of the search region: d <= r implies |D| <= r / min(1, s).
inline double euclideanReach(const GatherParams& params, float radius) {
  return double(radius) / std::min(1.0, double(params.normalSquash));
}

}  // namespace gather_internal

float resolveRadius(const GatherParams& params, const GridFrame& frame) {
  if (!(params.radius >= 0) || !std::isfinite(params.radius)) {
    throw InputError("gather radius " + std::to_string(params.radius) +
                     " must be finite and >= 0 (0 = default)");
  }
  return params.radius > 0 ? params.radius : kDefaultRadiusVoxels * frame.voxelSize;
}

Gatherer::Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                   const GatherParams& params)
    : grid_(grid), photons_(photons), params_(params) {
  gather_internal::checkParams(params);
  LO_CHECK_EQ(grid.binStart.size(), grid.size() + 1);
  radius_ = resolveRadius(params, grid.frame);
  // Photons in a voxel's bin lie inside its box grown by binMargin, and the
  // query point (the centroid) lies in its own voxel's closed box: +1 covers a
  // centroid on the upper face.
  const double reach =
      (gather_internal::euclideanReach(params, radius_) + grid.binMargin) / grid.frame.voxelSize;
  reachVoxels_ = int(std::min(double(grid.frame.resolution()), std::ceil(reach))) + 1;
}

void Gatherer::updateBlock(const Coord& c) {
  const Coord block{c.x >> 3, c.y >> 3, c.z >> 3};
  if (blockValid_ && block == blockCoord_) return;
  blockCoord_ = block;
  blockValid_ = true;
  blockNeighbours_.clear();
  blockPhotons_.clear();
  const int res = grid_.frame.resolution();
  int lo[3], hi[3];
  const int b[3] = {block.x, block.y, block.z};
  for (int a = 0; a < 3; ++a) {
    lo[a] = std::max(0, b[a] * 8 - reachVoxels_);
    hi[a] = std::min(res - 1, b[a] * 8 + 7 + reachVoxels_);
  }
  for (int x = lo[0]; x <= hi[0]; ++x) {
    for (int y = lo[1]; y <= hi[1]; ++y) {
      for (int z = lo[2]; z <= hi[2]; ++z) {
        const int64_t v = grid_.find({x, y, z});
        if (v < 0) continue;
        const uint32_t s = grid_.binStart[size_t(v)], e = grid_.binStart[size_t(v) + 1];
        if (s == e) continue;
        Neighbour nb{Coord{x, y, z}, uint32_t(blockPhotons_.size()), 0};
        for (uint32_t j = s; j != e; ++j) {
          const uint32_t i = grid_.binPhotons[j];
          const Photon& p = photons_[i];
          blockPhotons_.push_back({p.position, p.normal, p.power, i});
        }
        nb.end = uint32_t(blockPhotons_.size());
        blockNeighbours_.push_back(nb);
      }
    }
  }
}

void Gatherer::gather(size_t voxel, GatherResult& out) {
  using namespace gather_internal;
  LO_CHECK_LT(voxel, grid_.size());
  updateBlock(grid_.coords[voxel]);
  const GridFrame& f = grid_.frame;
  const double vs = f.voxelSize;
  // Prune neighbour bins in index space by the distance from the query point to
  // their box grown by binMargin; the relative slack keeps float rounding of
  // the photon distances from making the pruning stricter than the brute force.
  const double reach = (euclideanReach(params_, radius_) + grid_.binMargin) / vs;
  const double slackReach = reach * (1.0 + 1e-4) + 1e-6;
  const double reach2 = slackReach * slackReach;
  const Vec3& q = grid_.centroids[voxel];
  const double qi[3] = {(double(q.x) - f.origin.x) / vs, (double(q.y) - f.origin.y) / vs,
                        (double(q.z) - f.origin.z) / vs};
  const LocalPhoton* local = blockPhotons_.data();
  auto collect = [&](const Query& query, Lists& lists, Scan& scan) {
    for (const Neighbour& nb : blockNeighbours_) {
      const double dx = std::max({0.0, nb.coord.x - qi[0], qi[0] - (nb.coord.x + 1.0)});
      const double dy = std::max({0.0, nb.coord.y - qi[1], qi[1] - (nb.coord.y + 1.0)});
      const double dz = std::max({0.0, nb.coord.z - qi[2], qi[2] - (nb.coord.z + 1.0)});
      if (dx * dx + dy * dy + dz * dz > reach2) continue;
      for (uint32_t j = nb.begin; j != nb.end; ++j) {
        scanPhoton(local[j], local[j].index, query, lists, scan);
      }
    }
  };
  gatherWith(grid_, photons_, voxel, params_, radius_, candidates_, backCandidates_, out, collect);
}

GatherResult gatherBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                              size_t voxel, const GatherParams& params) {
  using namespace gather_internal;
  checkParams(params);
  LO_CHECK_LT(voxel, grid.size());
  const float radius = resolveRadius(params, grid.frame);
  std::vector<uint64_t> front, back;
  GatherResult out;
  auto collect = [&](const Query& query, Lists& lists, Scan& scan) {
    for (size_t i = 0; i < photons.size(); ++i) {
      scanPhoton(photons[i], uint32_t(i), query, lists, scan);
    }
  };
  gatherWith(grid, photons, voxel, params, radius, front, back, out, collect);
  return out;
}

}  // namespace lo
