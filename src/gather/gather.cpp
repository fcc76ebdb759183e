// KNN prefiltering per voxel (paper §3.1.1): the k nearest photons within a
// radius r, distances measured in an ellipsoid aligned with the voxel normal.
//
// Candidates come from the photon bins of nearby active voxels (the surface
// grid is the search structure: §4.1 fetched photons "directly using the
// octree"). The active neighbours of an 8^3 block are looked up once and
// reused by every voxel of the block; each voxel then prunes them by the
// distance from its query point to their box. Two passes per voxel: the
// orientation vote over every photon within r, then the k nearest, visiting
// the bins nearest first and stopping once no farther bin can improve the set.
// See docs/grid-and-gather.md for the measurements behind this choice.

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

/// The orientation vote, over the photons within r (either side of the surface).
struct Scan {
  double orientation = 0;      ///< sum of average(power) * sign(dot(photon normal, n))
  double mean[3] = {0, 0, 0};  ///< sum of average(power) * photon normal (sphere metric only)
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

/// Pass 1 for photons known to lie within r that share one normal, with
/// their weights summed: the votes each of them gives.
inline void voteGroup(const Vec3& normal, double weight, const Query& q, Scan& scan) {
  const float c = dot(normal, q.normal);
  if (c > 0) {
    scan.orientation += weight;
  } else if (c < 0) {
    scan.orientation -= weight;
  } else if (q.normal == Vec3{}) {
    scan.mean[0] += weight * normal.x;
    scan.mean[1] += weight * normal.y;
    scan.mean[2] += weight * normal.z;
  }
}

/// Pass 1: one photon's vote (if within r).
inline void votePhoton(const Vec3& position, const Vec3& normal, float weight, const Query& q,
                       Scan& scan) {
  const float d2 = ellipsoidDistance2(position, q.point, q.normal, q.squash2m1);
  if (!(d2 <= q.radius2)) return;  // also drops NaN positions
  voteGroup(normal, double(weight), q, scan);
}

/// Pass 1 over a run of binned photons with a non-zero query normal: the sum
/// of their votes (votePhoton), without branches (whether a photon lies within
/// r is as unpredictable as a coin near the edge of the region) and in four
/// partial sums, so that the additions do not wait on each other.
inline double voteRange(const Photon* begin, const Photon* end, const Query& q) {
  double sum[4] = {0, 0, 0, 0};
  size_t j = 0;
  for (const Photon* e = begin; e != end; ++e, ++j) {
    const float d2 = ellipsoidDistance2(e->position, q.point, q.normal, q.squash2m1);
    const float c = dot(e->normal, q.normal);
    const float weight = BinnedPhotons::weight(*e);
    float vote = c > 0 ? weight : (c < 0 ? -weight : 0.0f);
    vote = d2 <= q.radius2 ? vote : 0.0f;  // also drops NaN positions
    sum[j & 3] += double(vote);
  }
  return (sum[0] + sum[1]) + (sum[2] + sum[3]);
}


/// Collects candidate keys and keeps an upper bound of the k-th smallest:
/// once the buffer holds 2k keys it is cut to the k smallest (nth_element), so
/// the bound tightens and farther photons are not even stored.
class KnnSelection {
 public:
  KnnSelection(std::vector<uint64_t>& keys, size_t k) : keys_(keys), k_(k) { keys_.clear(); }
  /// True once k keys are held: then no key farther than bound() can be among
  /// the k nearest (a key at exactly bound() still can, by its index).
  bool full() const { return full_; }
  float bound() const { return bound_; }
  void push(uint64_t key) {
    if (full_ && candidateDistance2(key) > bound_) return;
    keys_.push_back(key);
    if (keys_.size() == k_ && !full_) {
      full_ = true;
      bound_ = candidateDistance2(*std::max_element(keys_.begin(), keys_.end()));
    } else if (keys_.size() >= 2 * k_) {
      cut();
    }
  }
  /// Leaves the k smallest keys (all of them if fewer), in no particular but
  /// deterministic order; returns the k-th smallest distance^2 or -1 if fewer.
  float finish() {
    if (keys_.size() > k_) cut();
    if (keys_.size() < k_) return -1.0f;
    return candidateDistance2(*std::max_element(keys_.begin(), keys_.end()));
  }

 private:
  void cut() {
    std::nth_element(keys_.begin(), keys_.begin() + std::ptrdiff_t(k_ - 1), keys_.end());
    keys_.resize(k_);
    bound_ = candidateDistance2(keys_[k_ - 1]);
  }
  std::vector<uint64_t>& keys_;
  size_t k_;
  bool full_ = false;
  float bound_ = 0.0f;
};

/// Which side's photons are kept: those with sign(dot(photon normal,
/// query normal)) == side; with a zero query normal (sphere metric), all.
struct Side {
  bool sphere;
  bool positive;
  float cosine = 0;  ///< kept beyond this cosine (0: the whole hemisphere)
  bool accepts(float c) const { return sphere || (positive ? c > cosine : c < -cosine); }
};

/// Where and how one gather looks: the query point and normal, whether the
/// normal is already oriented (a surface layer: no vote), and how far from it
/// a photon's normal may turn.
struct QuerySpec {
  Vec3 point;
  Vec3 normal;
  bool fixedNormal = false;
  float sideCosine = 0;
};

/// Pass 2: one photon as a candidate (if within r and on the kept side).
inline void selectPhoton(const Vec3& position, const Vec3& normal, uint32_t index, const Query& q,
                         Side side, KnnSelection& selection) {
  const float d2 = ellipsoidDistance2(position, q.point, q.normal, q.squash2m1);
  if (!(d2 <= q.radius2)) return;
  if (!side.accepts(dot(normal, q.normal))) return;
  selection.push(candidateKey(d2, index));
}

/// Runs the gather around two callbacks that visit every photon within the
/// radius (any order): `vote(query, scan)` calls votePhoton, `select(query,
/// side, selection)` calls selectPhoton (it may skip photons that provably lie
/// farther than the bound of a full selection).
///  1. n = the voxel normal, flipped towards the side the light arrives from
///     (sign of the power-weighted vote of the candidates' photon normals);
///  2. if the voxel normal is zero (cancelling faces), n = the power-weighted
///     mean of the candidates' photon normals (sphere metric), and the vote
///     runs again with the ellipsoid along that n;
///  3. if that is zero too, the sphere metric without back rejection.
/// Photons with dot(photon normal, n) <= 0 arrived from behind (the photon
/// normal faces its arrival side, so this also removes photons on the back of a
/// thin wall) and are rejected; the k nearest by (d^2, index) are kept.
/// The share of the disc of radius r around q, perpendicular to n, that lies
/// on surfaces facing like n: 32 points spread evenly over the disc's area
/// (4 rings of 8), each counted when the voxel holding it, or one of the
/// voxels half a voxel above and below it along n (the surface may curve
/// away from the disc), has geometry within 60 degrees of n (either way:
/// the winding need not face the light). A density estimate divides the
/// photons' power by this share of pi r^2: near an edge, where the disc
/// reaches past the surface, the photons cover only part of it.
/// With GatherParams::surfaceAt, each point asks the scene instead: is
/// there such surface along the normal within the gather's ellipsoid there.
/// GatherParams::edgeCorrection; 1 for the sphere metric or r = 0.
double surfaceCoverage(const SurfaceGrid& grid, const Vec3& q, const Vec3& n, float r,
                       float squash, const SurfaceProbe& surfaceAt) {
  if (n == Vec3{} || !(r > 0) || grid.size() == 0) return 1.0;
  const Vec3 a = std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const Vec3 t1 = normalize(cross(n, a)), t2 = cross(n, t1);
  const float lift = 0.5f * grid.frame.voxelSize;
  const bool orientations = grid.orientationStart.size() == grid.size() + 1;
  // Whether point p of the disc lies on a surface facing like n in voxel v:
  // one of v's orientations faces like n, and p lies on q's side of the
  // planes of those that cross it (a wall standing on the floor: points of
  // the floor's disc past the wall are not on the floor), within a tenth of
  // a voxel. Either side: the test does not depend on the winding.
  const float tolerance = 0.1f * grid.frame.voxelSize;
  auto facesLikeN = [&](int64_t v, const Vec3& p) {
    if (v < 0) return false;
    if (!orientations || grid.orientationStart[size_t(v)] == grid.orientationStart[size_t(v) + 1]) {
      return std::fabs(dot(grid.normals[size_t(v)], n)) > 0.5f || grid.normals[size_t(v)] == Vec3{};
    }
    // The facing surface's area against a full cut through the voxel: a
    // surface that fills its voxel goes on behind whatever crosses it (a ball
    // resting on the floor: the floor continues under it, in shadow); one
    // that fills part of it ends at a crossing surface (a wall standing on
    // the floor: no floor behind the wall).
    const float h2 = grid.frame.voxelSize * grid.frame.voxelSize;
    bool facing = false, partial = true;
    for (uint32_t o = grid.orientationStart[size_t(v)]; o < grid.orientationStart[size_t(v) + 1];
         ++o) {
      const SurfaceGrid::Orientation& k = grid.orientations[o];
      if (std::fabs(dot(k.normal, n)) > 0.5f) {
        facing = true;
        const float full =
            h2 / std::max({std::fabs(k.normal.x), std::fabs(k.normal.y), std::fabs(k.normal.z)});
        partial = partial && k.area < 0.9f * full;
      }
    }
    if (!facing) return false;
    if (!partial) return true;
    for (uint32_t o = grid.orientationStart[size_t(v)]; o < grid.orientationStart[size_t(v) + 1];
         ++o) {
      const SurfaceGrid::Orientation& k = grid.orientations[o];
      if (std::fabs(dot(k.normal, n)) > 0.5f) continue;
      const float sp = dot(k.normal, p - k.centroid), sq = dot(k.normal, q - k.centroid);
      if ((sp > tolerance && sq < -tolerance) || (sp < -tolerance && sq > tolerance)) return false;
    }
    return true;
  };
  constexpr int kRings = 4, kAngles = 8;
  int covered = 0;
  for (int ring = 0; ring < kRings; ++ring) {
    const float rr = r * std::sqrt((float(ring) + 0.5f) / float(kRings));
    for (int k = 0; k < kAngles; ++k) {
      // Rings turned by half a step against each other.
      const float phi = (float(k) + 0.5f * float(ring & 1)) * (2.0f * kPi / float(kAngles));
      const Vec3 p = q + (t1 * std::cos(phi) + t2 * std::sin(phi)) * rr;
      if (surfaceAt) {
        // The ellipsoid's half thickness at this distance from q (at least
        // a tenth of a voxel: a surface that curves away).
        const float h = std::max(std::sqrt(std::max(r * r - rr * rr, 0.0f)) / std::max(squash, 1e-3f),
                                 0.1f * grid.frame.voxelSize);
        covered += surfaceAt(p, n, h);
        continue;
      }
      const Coord c = grid.frame.coordOf(p);
      bool hit = facesLikeN(grid.find(c), p);
      if (!hit) {
        const Coord up = grid.frame.coordOf(p + n * lift), down = grid.frame.coordOf(p - n * lift);
        hit = (up != c && facesLikeN(grid.find(up), p)) ||
              (down != c && facesLikeN(grid.find(down), p));
      }
      covered += hit;
    }
  }
  return double(covered) / double(kRings * kAngles);
}

template <typename Vote, typename Prepare, typename Select>
void gatherWith(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                const QuerySpec& spec, const GatherParams& params, float radius,
                std::vector<uint64_t>& keys, GatherResult& out, Vote&& vote, Prepare&& prepare,
                Select&& select) {
  Query query;
  query.point = spec.point;
  query.normal = spec.normal;
  query.squash2m1 = params.normalSquash * params.normalSquash - 1.0f;
  query.radius2 = radius * radius;

  Scan scan;
  if (spec.fixedNormal) {
    scan.orientation = 1;  // the layer's normal is oriented already
  } else {
    vote(query, scan);
  }
  if (query.normal == Vec3{}) {
    const Vec3 mean =
        normalize(Vec3{float(scan.mean[0]), float(scan.mean[1]), float(scan.mean[2])});
    if (mean != Vec3{}) {
      query.normal = mean;
      scan = Scan{};
      vote(query, scan);
    }
  }
  Vec3 n = query.normal;
  Side side{query.normal == Vec3{}, true, spec.sideCosine};
  if (scan.orientation < 0) {
    n = -n;
    side.positive = false;
  }
  prepare(query.point, n, side);

  const size_t k = size_t(params.k);
  KnnSelection selection(keys, k);
  select(query, side, selection);
  const float kth2 = selection.finish();
  float rk = radius;
  if (kth2 >= 0) rk = std::sqrt(kth2);
  // k photons at one point: no area to divide by, so fall back to the radius.
  if (!(rk > 0)) rk = radius;

  out.photons.resize(keys.size());
  double power[3] = {0, 0, 0}, reflected[3] = {0, 0, 0}, y = 0, y2 = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    const uint32_t p = uint32_t(keys[i]);
    out.photons[i] = p;
    const Vec3 r = reflectanceOf(photons[p]);
    for (int c = 0; c < 3; ++c) {
      power[c] += photons[p].power[c];
      reflected[c] += double(photons[p].power[c]) * double(r[c]);
    }
    const double yp = double(luminance(photons[p].power));
    y += yp;
    y2 += yp * yp;
  }
  out.noise = relativeNoise(y, y2);
  // Edge correction: the disc's share on the surface (at least a quarter,
  // so that a stray estimate cannot blow up).
  const double coverage =
      params.edgeCorrection
          ? std::max(0.25, surfaceCoverage(grid, query.point, n, rk, params.normalSquash,
                                           params.surfaceAt))
          : 1.0;
  const double invArea = 1.0 / (double(kPi) * double(rk) * double(rk) * coverage);
  out.radius = rk;
  out.coverage = float(coverage);
  out.normal = n;
  out.irradiance = {float(power[0] * invArea), float(power[1] * invArea),
                    float(power[2] * invArea)};
  for (int c = 0; c < 3; ++c) {
    out.reflectance[c] = power[c] > 0 ? float(reflected[c] / power[c]) : 0.0f;
  }
}

void checkParams(const GatherParams& params) {
  if (params.k < 1) throw InputError("gather k " + std::to_string(params.k) + " must be >= 1");
  if (!(params.normalSquash > 0) || !std::isfinite(params.normalSquash)) {
    throw InputError("gather normalSquash " + std::to_string(params.normalSquash) +
                     " must be finite and > 0");
  }
  if (!(params.layerCosine >= -1 && params.layerCosine < 1)) {
    throw InputError("gather layerCosine " + std::to_string(params.layerCosine) +
                     " must lie in [-1, 1)");
  }
  if (!(params.occlusionLift >= 0) || !std::isfinite(params.occlusionLift)) {
    throw InputError("gather occlusionLift " + std::to_string(params.occlusionLift) +
                     " must be finite and >= 0");
  }
}

/// Euclidean reach of the search region: d <= r implies |D| <= r / min(1, s).
inline double euclideanReach(const GatherParams& params, float radius) {
  return double(radius) / std::min(1.0, double(params.normalSquash));
}

}  // namespace gather_internal

std::shared_ptr<const BinnedPhotons> binPhotonsForGather(const SurfaceGrid& grid,
                                                         const std::vector<Photon>& photons) {
  if (grid.binStart.size() != grid.size() + 1) {
    throw InputError("gather: the surface grid has no photon bins (call splatPhotons first)");
  }
  auto binned = std::make_shared<BinnedPhotons>();
  const size_t slots = grid.binPhotons.size();
  bool inOrder = true;
  for (size_t j = 0; j < slots; ++j) {
    LO_CHECK_LT(size_t(grid.binPhotons[j]), photons.size());
    inOrder = inOrder && grid.binPhotons[j] == uint32_t(j);
  }
  if (inOrder) {
    binned->inBinOrder = photons.data();
  } else {
    binned->copy.resize(slots);
    for (size_t j = 0; j < slots; ++j) binned->copy[j] = photons[grid.binPhotons[j]];
    binned->inBinOrder = binned->copy.data();
  }
  binned->indices = grid.binPhotons.data();
  binned->group.assign(slots, BinnedPhotons::kNoGroup);
  for (size_t j = 0; j < slots; ++j) {
    binned->causticPhotons += binned->photon(uint32_t(j)).caustic != 0;
  }
  binned->bins.resize(grid.size());
  for (size_t v = 0; v < grid.size(); ++v) {
    BinnedPhotons::Bin& bin = binned->bins[v];
    const uint32_t b = grid.binStart[v], e = grid.binStart[v + 1];
    if (b == e) continue;
    bin.lower = bin.upper = binned->photon(b).position;
    bool finite = true;
    for (uint32_t j = b; j != e; ++j) {
      const Photon& entry = binned->photon(j);
      finite = finite && isFinite(entry.position) && isFinite(entry.normal);
      for (int a = 0; a < 3; ++a) {
        bin.lower[a] = std::min(bin.lower[a], entry.position[a]);
        bin.upper[a] = std::max(bin.upper[a], entry.position[a]);
      }
      if (bin.groups < 0) continue;
      int g = 0;
      while (g < bin.groups && !(bin.normal[g] == entry.normal)) ++g;
      if (g == bin.groups) {
        if (g == BinnedPhotons::kMaxGroups) {
          bin.groups = -1;  // too many normals: vote per photon
          continue;
        }
        bin.normal[g] = entry.normal;
        ++bin.groups;
      }
      bin.weight[g] += BinnedPhotons::weight(entry);
    }
    if (bin.groups < 0 || !finite) bin.groups = 0;
    // Where each group (or the whole bin) lies, for the occlusion test.
    double sum[BinnedPhotons::kMaxGroups][3] = {};
    uint32_t count[BinnedPhotons::kMaxGroups] = {};
    for (uint32_t j = b; j != e; ++j) {
      const Photon& entry = binned->photon(j);
      int g = 0;
      if (bin.groups > 0) {
        while (!(bin.normal[g] == entry.normal)) ++g;
        binned->group[j] = uint16_t(g);
      } else {
        bin.normalSum += entry.normal;
      }
      for (int a = 0; a < 3; ++a) sum[g][a] += double(entry.position[a]);
      ++count[g];
    }
    for (int g = 0; g < std::max(1, bin.groups); ++g) {
      if (count[g] == 0) continue;
      bin.point[g] = Vec3{float(sum[g][0] / count[g]), float(sum[g][1] / count[g]),
                          float(sum[g][2] / count[g])};
    }
  }
  return binned;
}

float resolveRadius(const GatherParams& params, const GridFrame& frame) {
  if (!(params.radius >= 0) || !std::isfinite(params.radius)) {
    throw InputError("gather radius " + std::to_string(params.radius) +
                     " must be finite and >= 0 (0 = default)");
  }
  return params.radius > 0 ? params.radius : kDefaultRadiusVoxels * frame.voxelSize;
}

double gatherReach(const GatherParams& params, const GridFrame& frame) {
  gather_internal::checkParams(params);
  return gather_internal::euclideanReach(params, resolveRadius(params, frame));
}

Gatherer::Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                   const GatherParams& params)
    : Gatherer(grid, photons, nullptr, params) {}

Gatherer::Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                   std::shared_ptr<const BinnedPhotons> binned, const GatherParams& params)
    : grid_(grid), photons_(photons), binned_(std::move(binned)), params_(params) {
  gather_internal::checkParams(params);
  LO_CHECK_EQ(grid.binStart.size(), grid.size() + 1);
  if (!binned_) binned_ = binPhotonsForGather(grid, photons);
  LO_CHECK_EQ(binned_->group.size(), grid.binPhotons.size());
  radius_ = resolveRadius(params, grid.frame);
  causticRadius_ = std::min(radius_, params.causticRadius > 0
                                         ? params.causticRadius
                                         : kDefaultCausticRadiusVoxels * grid.frame.voxelSize);
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
        if (s != e) blockNeighbours_.push_back({Coord{x, y, z}, uint32_t(v), s, e});
      }
    }
  }
}

void Gatherer::findNear(const Vec3& q) {
  using namespace gather_internal;
  const GridFrame& f = grid_.frame;
  const double vs = f.voxelSize;
  // Prune neighbour bins in index space by the distance from the query point to
  // their box grown by binMargin; the relative slack keeps float rounding of
  // the photon distances from making the pruning stricter than the brute force.
  const double reach = (euclideanReach(params_, radius_) + grid_.binMargin) / vs;
  const double slackReach = reach * (1.0 + 1e-4) + 1e-6;
  const double reach2 = slackReach * slackReach;
  // d^2 = |D|^2 + (s^2 - 1)(D.n)^2 >= min(1, s^2) |D|^2: a bin's box distance
  // bounds the ellipsoid distance of its photons from below (with slack for
  // the float rounding of d^2).
  const double squash = std::min(1.0, double(params_.normalSquash));
  const double qi[3] = {(double(q.x) - f.origin.x) / vs, (double(q.y) - f.origin.y) / vs,
                        (double(q.z) - f.origin.z) / vs};
  near_.clear();
  for (uint32_t i = 0; i < uint32_t(blockNeighbours_.size()); ++i) {
    const Neighbour& nb = blockNeighbours_[i];
    const double dx = std::max({0.0, nb.coord.x - qi[0], qi[0] - (nb.coord.x + 1.0)});
    const double dy = std::max({0.0, nb.coord.y - qi[1], qi[1] - (nb.coord.y + 1.0)});
    const double dz = std::max({0.0, nb.coord.z - qi[2], qi[2] - (nb.coord.z + 1.0)});
    const double box2 = dx * dx + dy * dy + dz * dz;
    if (box2 > reach2) continue;
    const double euclid = std::max(0.0, std::sqrt(box2) * vs - double(grid_.binMargin));
    near_.push_back({euclid * euclid * squash * squash * (1.0 - 1e-4), i});
  }
}

void Gatherer::markBlocked(size_t ownVoxel, const Vec3& point, const Vec3& normal,
                           float sideCosine) {
  if (!params_.blocked) return;
  const float lift = params_.occlusionLift * grid_.frame.voxelSize;
  const Vec3 from = point + normal * lift;
  const bool sphere = normal == Vec3{};
  for (Near& nr : near_) {
    const Neighbour& nb = blockNeighbours_[nr.neighbour];
    if (nb.voxel == ownVoxel) continue;
    const BinnedPhotons::Bin& bin = binned_->bins[nb.voxel];
    if (bin.groups > 0) {
      for (int g = 0; g < bin.groups; ++g) {
        // A group the kept side rejects contributes nothing: no ray.
        if (!sphere && !(dot(bin.normal[g], normal) > sideCosine)) continue;
        if (params_.blocked(from, bin.point[g] + bin.normal[g] * lift)) nr.blocked |= 1u << g;
      }
    } else {
      const Vec3 n = normalize(bin.normalSum);
      const Vec3 to = bin.point[0] + (isFinite(n) ? n : Vec3{0, 0, 0}) * lift;
      if (params_.blocked(from, to)) nr.blocked = 1u;
    }
  }
}

void Gatherer::gather(size_t voxel, GatherResult& out) {
  LO_CHECK_LT(voxel, grid_.size());
  gatherAt(voxel, grid_.centroids[voxel], grid_.normals[voxel], false, 0.0f,
           hasCaustics() ? 0 : -1, radius_, out);
}

void Gatherer::gatherLayer(size_t voxel, const Vec3& point, const Vec3& normal,
                           GatherResult& out) {
  LO_CHECK_LT(voxel, grid_.size());
  gatherAt(voxel, point, normal, true, params_.layerCosine, hasCaustics() ? 0 : -1, radius_, out);
}

void Gatherer::gatherCaustics(size_t voxel, const Vec3& point, const Vec3& normal,
                              GatherResult& out) {
  LO_CHECK_LT(voxel, grid_.size());
  if (!hasCaustics()) {
    out = GatherResult{};
    out.normal = normal;
    out.radius = causticRadius_;
    return;
  }
  gatherAt(voxel, point, normal, true, params_.layerCosine, 1, causticRadius_, out);
}

void Gatherer::gatherAt(size_t voxel, const Vec3& point, const Vec3& normal, bool fixedNormal,
                        float sideCosine, int caustic, float radius, GatherResult& out) {
  using namespace gather_internal;
  updateBlock(grid_.coords[voxel]);
  findNear(point);
  const BinnedPhotons& binned = *binned_;
  const Photon* inBinOrder = binned.inBinOrder;
  // Pass 1, the orientation vote: every photon within r, in bin order.
  // A bin whose photons all lie within r (d^2 is convex, so its largest value
  // over the bin's bounds is at a corner; slack for the float rounding of the
  // photons' d^2) and share a few normals votes per normal: the same signs,
  // with the weights summed in bin order beforehand.
  const double inside2 = double(radius_) * double(radius_) * (1.0 - 1e-5);
  auto vote = [&](const Query& query, Scan& scan) {
    const double qn[3] = {query.normal.x, query.normal.y, query.normal.z};
    const double qp[3] = {query.point.x, query.point.y, query.point.z};
    const double squash2m1 = query.squash2m1;
    const bool sphere = query.normal == Vec3{};
    for (const Near& nr : near_) {
      const Neighbour& nb = blockNeighbours_[nr.neighbour];
      const BinnedPhotons::Bin& bin = binned_->bins[nb.voxel];
      if (bin.groups > 0) {
        double worst = 0;
        for (int corner = 0; corner < 8; ++corner) {
          double d[3], dn = 0, dd = 0;
          for (int a = 0; a < 3; ++a) {
            d[a] = double((corner >> a) & 1 ? bin.upper[a] : bin.lower[a]) - qp[a];
            dn += d[a] * qn[a];
            dd += d[a] * d[a];
          }
          worst = std::max(worst, dd + squash2m1 * dn * dn);
        }
        if (worst <= inside2) {
          for (int g = 0; g < bin.groups; ++g) voteGroup(bin.normal[g], bin.weight[g], query, scan);
          continue;
        }
      }
      if (sphere) {
        for (uint32_t j = nb.begin; j != nb.end; ++j) {
          const Photon& p = inBinOrder[j];
          votePhoton(p.position, p.normal, BinnedPhotons::weight(p), query, scan);
        }
      } else {
        scan.orientation += voteRange(inBinOrder + nb.begin, inBinOrder + nb.end, query);
      }
    }
  };
  auto prepare = [&](const Vec3& p, const Vec3& n, const Side& side) {
    markBlocked(voxel, p, n, side.sphere ? -2.0f : side.cosine);
  };
  // Pass 2, the selection: nearest bins first; once k candidates are held, a
  // bin whose bound exceeds the k-th distance cannot improve the set, nor can
  // any later bin. Groups behind geometry (markBlocked) are skipped.
  auto select = [&](const Query& query, Side side, KnnSelection& selection) {
    std::sort(near_.begin(), near_.end());
    for (const Near& nr : near_) {
      if (selection.full() && nr.bound2 > double(selection.bound())) break;
      const Neighbour& nb = blockNeighbours_[nr.neighbour];
      if (nr.blocked == 0) {
        for (uint32_t j = nb.begin; j != nb.end; ++j) {
          if (caustic >= 0 && inBinOrder[j].caustic != caustic) continue;
          selectPhoton(inBinOrder[j].position, inBinOrder[j].normal, binned.index(j), query, side,
                       selection);
        }
      } else if (binned.bins[nb.voxel].groups > 0) {
        for (uint32_t j = nb.begin; j != nb.end; ++j) {
          if (nr.blocked & (1u << binned.group[j])) continue;
          if (caustic >= 0 && inBinOrder[j].caustic != caustic) continue;
          selectPhoton(inBinOrder[j].position, inBinOrder[j].normal, binned.index(j), query, side,
                       selection);
        }
      }
    }
  };
  QuerySpec spec;
  spec.point = point;
  spec.normal = normal;
  spec.fixedNormal = fixedNormal;
  spec.sideCosine = sideCosine;
  gatherWith(grid_, photons_, spec, params_, radius, keys_, out, vote, prepare, select);
}

int Gatherer::findSurfaceLayers(size_t voxel, const LayerParams& params,
                                SurfaceLayer* out) const {
  LO_CHECK_LT(voxel, grid_.size());
  // Candidate surfaces: the voxel's geometric orientations (SurfaceGrid::
  // orientations), else its one normal and centroid.
  struct Candidate {
    Vec3 normal, point;
    float area;
    bool twoSided;  ///< a thin wall: faces of the voxel's geometry look both ways
    /// A point of the faces looking the other way (their centroid), where the
    /// back layer gathers: a slab thicker than the gather's ellipsoid (a
    /// ledge's underside half a metre below its top) holds its photons
    /// there, not on the front face.
    Vec3 backPoint;
  };
  Candidate candidates[SurfaceGrid::kMaxOrientations];
  int count = 0;
  if (grid_.orientationStart.size() == grid_.size() + 1) {
    for (uint32_t o = grid_.orientationStart[voxel]; o < grid_.orientationStart[voxel + 1]; ++o) {
      const SurfaceGrid::Orientation& g = grid_.orientations[o];
      // The two faces of a thin wall are one surface here: its photons say
      // which side (or both) is lit.
      bool opposite = false;
      for (int c = 0; c < count; ++c) {
        if (-dot(candidates[c].normal, g.normal) > params.splitCosine) {
          opposite = true;
          if (!candidates[c].twoSided) candidates[c].backPoint = g.centroid;  // the largest
          candidates[c].twoSided = true;
        }
      }
      if (!opposite) candidates[count++] = {g.normal, g.centroid, g.area, false, g.centroid};
    }
  }
  if (count == 0) {
    if (!(lengthSquared(grid_.normals[voxel]) > 0.5f)) return 0;
    candidates[count++] = {grid_.normals[voxel], grid_.centroids[voxel], grid_.areas[voxel], false,
                           grid_.centroids[voxel]};
  }
  // Which side of each surface its photons arrived on: the photons of the
  // voxel's own bin within params.splitCosine of the front or the back.
  double front[SurfaceGrid::kMaxOrientations] = {}, back[SurfaceGrid::kMaxOrientations] = {};
  // Power-weighted sums of those photons' positions.
  double frontAt[SurfaceGrid::kMaxOrientations][3] = {},
         backAt[SurfaceGrid::kMaxOrientations][3] = {};
  uint32_t frontCount[SurfaceGrid::kMaxOrientations] = {},
           backCount[SurfaceGrid::kMaxOrientations] = {};
  double total = 0;
  for (uint32_t j = grid_.binStart[voxel]; j != grid_.binStart[voxel + 1]; ++j) {
    const Photon& e = binned_->photon(j);
    const float weight = BinnedPhotons::weight(e);
    if (!isFinite(e.normal) || !(weight >= 0)) continue;
    total += double(weight);
    for (int c = 0; c < count; ++c) {
      const float d = dot(e.normal, candidates[c].normal);
      const double w = double(weight);
      if (d > params.splitCosine) {
        front[c] += w;
        ++frontCount[c];
        for (int a = 0; a < 3; ++a) frontAt[c][a] += w * double(e.position[a]);
      } else if (-d > params.splitCosine) {
        back[c] += w;
        ++backCount[c];
        for (int a = 0; a < 3; ++a) backAt[c][a] += w * double(e.position[a]);
      }
    }
  }
  // A surface lit on one side is a layer facing that side (its winding's when
  // no photon landed on it: a dark layer still claims its fragments); lit on
  // both, two layers facing away from each other. A thin wall (faces both
  // ways) always has both: its dark face's layer claims the fragments of
  // that side, and the fragments of a floor meeting it there find no layer
  // of the wall facing their way, so the lit face's light stays on its side.
  auto significant = [&](double w, uint32_t n) {
    return n >= params.minPhotons && w >= double(params.minShare) * total && w > 0;
  };
  const float minArea = params.minArea * grid_.frame.voxelSize * grid_.frame.voxelSize;
  int layers = 0;
  for (int c = 0; c < count && layers < params.maxLayers; ++c) {
    const Candidate& k = candidates[c];
    const bool f = significant(front[c], frontCount[c]),
               b = significant(back[c], backCount[c]) || (k.twoSided && f);
    if (c > 0 && !f && !b && k.area < minArea) continue;  // a sliver: no layer (LayerParams::minArea)
    auto mean = [&](const double* at, double w, const Vec3& point) {
      return w > 0 ? Vec3{float(at[0] / w), float(at[1] / w), float(at[2] / w)} : point;
    };
    if (f || !b) {
      out[layers++] = {k.normal, k.point, front[c], frontCount[c], mean(frontAt[c], front[c], k.point)};
    }
    if (b && layers < params.maxLayers) {
      out[layers++] = {-k.normal, k.backPoint, back[c], backCount[c],
                       mean(backAt[c], back[c], k.backPoint)};
    }
  }
  return layers;
}

namespace gather_internal {

GatherResult bruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                        const QuerySpec& spec, const GatherParams& params) {
  checkParams(params);
  const float radius = resolveRadius(params, grid.frame);
  std::vector<uint64_t> keys;
  GatherResult out;
  auto vote = [&](const Query& query, Scan& scan) {
    for (const Photon& p : photons) votePhoton(p.position, p.normal, average(p.power), query, scan);
  };
  // Caustic photons apart, as Gatherer::gather leaves them.
  bool apart = false;
  for (const Photon& p : photons) apart = apart || (params.separateCaustics && p.caustic != 0);
  auto select = [&](const Query& query, Side side, KnnSelection& selection) {
    for (size_t i = 0; i < photons.size(); ++i) {
      if (apart && photons[i].caustic != 0) continue;
      selectPhoton(photons[i].position, photons[i].normal, uint32_t(i), query, side, selection);
    }
  };
  gatherWith(grid, photons, spec, params, radius, keys, out, vote,
             [](const Vec3&, const Vec3&, const Side&) {}, select);
  return out;
}

}  // namespace gather_internal

GatherResult gatherBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                              size_t voxel, const GatherParams& params) {
  LO_CHECK_LT(voxel, grid.size());
  gather_internal::QuerySpec spec;
  spec.point = grid.centroids[voxel];
  spec.normal = grid.normals[voxel];
  return gather_internal::bruteForce(grid, photons, spec, params);
}

GatherResult gatherLayerBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                                   const Vec3& point, const Vec3& normal,
                                   const GatherParams& params) {
  gather_internal::QuerySpec spec;
  spec.point = point;
  spec.normal = normal;
  spec.fixedNormal = true;
  spec.sideCosine = params.layerCosine;
  return gather_internal::bruteForce(grid, photons, spec, params);
}

}  // namespace lo
