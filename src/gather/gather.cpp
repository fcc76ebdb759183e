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
inline double voteRange(const BinnedPhotons::Entry* begin, const BinnedPhotons::Entry* end,
                        const Query& q) {
  double sum[4] = {0, 0, 0, 0};
  size_t j = 0;
  for (const BinnedPhotons::Entry* e = begin; e != end; ++e, ++j) {
    const float d2 = ellipsoidDistance2(e->position, q.point, q.normal, q.squash2m1);
    const float c = dot(e->normal, q.normal);
    float vote = c > 0 ? e->weight : (c < 0 ? -e->weight : 0.0f);
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
  bool accepts(float c) const { return sphere || (positive ? c > 0 : c < 0); }
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
template <typename Vote, typename Select>
void gatherWith(const SurfaceGrid& grid, const std::vector<Photon>& photons, size_t voxel,
                const GatherParams& params, float radius, std::vector<uint64_t>& keys,
                GatherResult& out, Vote&& vote, Select&& select) {
  Query query;
  query.point = grid.centroids[voxel];
  query.normal = grid.normals[voxel];
  query.squash2m1 = params.normalSquash * params.normalSquash - 1.0f;
  query.radius2 = radius * radius;

  Scan scan;
  vote(query, scan);
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
  Side side{query.normal == Vec3{}, true};
  if (scan.orientation < 0) {
    n = -n;
    side.positive = false;
  }

  const size_t k = size_t(params.k);
  KnnSelection selection(keys, k);
  select(query, side, selection);
  const float kth2 = selection.finish();
  float rk = radius;
  if (kth2 >= 0) rk = std::sqrt(kth2);
  // k photons at one point: no area to divide by, so fall back to the radius.
  if (!(rk > 0)) rk = radius;

  out.photons.resize(keys.size());
  double power[3] = {0, 0, 0};
  for (size_t i = 0; i < keys.size(); ++i) {
    const uint32_t p = uint32_t(keys[i]);
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

std::shared_ptr<const BinnedPhotons> binPhotonsForGather(const SurfaceGrid& grid,
                                                         const std::vector<Photon>& photons) {
  if (grid.binStart.size() != grid.size() + 1) {
    throw InputError("gather: the surface grid has no photon bins (call splatPhotons first)");
  }
  auto binned = std::make_shared<BinnedPhotons>();
  binned->entries.resize(grid.binPhotons.size());
  for (size_t j = 0; j < grid.binPhotons.size(); ++j) {
    const uint32_t i = grid.binPhotons[j];
    LO_CHECK_LT(size_t(i), photons.size());
    const Photon& p = photons[i];
    binned->entries[j] = {p.position, p.normal, average(p.power), i};
  }
  binned->bins.resize(grid.size());
  for (size_t v = 0; v < grid.size(); ++v) {
    BinnedPhotons::Bin& bin = binned->bins[v];
    const uint32_t b = grid.binStart[v], e = grid.binStart[v + 1];
    if (b == e) continue;
    bin.lower = bin.upper = binned->entries[b].position;
    bool finite = true;
    for (uint32_t j = b; j != e; ++j) {
      const BinnedPhotons::Entry& entry = binned->entries[j];
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
      bin.weight[g] += entry.weight;
    }
    if (bin.groups < 0 || !finite) bin.groups = 0;
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

Gatherer::Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                   const GatherParams& params)
    : Gatherer(grid, photons, nullptr, params) {}

Gatherer::Gatherer(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                   std::shared_ptr<const BinnedPhotons> binned, const GatherParams& params)
    : grid_(grid), photons_(photons), binned_(std::move(binned)), params_(params) {
  gather_internal::checkParams(params);
  LO_CHECK_EQ(grid.binStart.size(), grid.size() + 1);
  if (!binned_) binned_ = binPhotonsForGather(grid, photons);
  LO_CHECK_EQ(binned_->entries.size(), grid.binPhotons.size());
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
  // d^2 = |D|^2 + (s^2 - 1)(D.n)^2 >= min(1, s^2) |D|^2: a bin's box distance
  // bounds the ellipsoid distance of its photons from below (with slack for
  // the float rounding of d^2).
  const double squash = std::min(1.0, double(params_.normalSquash));
  const Vec3& q = grid_.centroids[voxel];
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
  const BinnedPhotons::Entry* entries = binned_->entries.data();
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
          votePhoton(entries[j].position, entries[j].normal, entries[j].weight, query, scan);
        }
      } else {
        scan.orientation += voteRange(entries + nb.begin, entries + nb.end, query);
      }
    }
  };
  // Pass 2, the selection: nearest bins first; once k candidates are held, a
  // bin whose bound exceeds the k-th distance cannot improve the set, nor can
  // any later bin.
  auto select = [&](const Query& query, Side side, KnnSelection& selection) {
    std::sort(near_.begin(), near_.end());
    for (const Near& nr : near_) {
      if (selection.full() && nr.bound2 > double(selection.bound())) break;
      const Neighbour& nb = blockNeighbours_[nr.neighbour];
      for (uint32_t j = nb.begin; j != nb.end; ++j) {
        selectPhoton(entries[j].position, entries[j].normal, entries[j].index, query, side,
                     selection);
      }
    }
  };
  gatherWith(grid_, photons_, voxel, params_, radius_, keys_, out, vote, select);
}

GatherResult gatherBruteForce(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                              size_t voxel, const GatherParams& params) {
  using namespace gather_internal;
  checkParams(params);
  LO_CHECK_LT(voxel, grid.size());
  const float radius = resolveRadius(params, grid.frame);
  std::vector<uint64_t> keys;
  GatherResult out;
  auto vote = [&](const Query& query, Scan& scan) {
    for (const Photon& p : photons) votePhoton(p.position, p.normal, average(p.power), query, scan);
  };
  auto select = [&](const Query& query, Side side, KnnSelection& selection) {
    for (size_t i = 0; i < photons.size(); ++i) {
      selectPhoton(photons[i].position, photons[i].normal, uint32_t(i), query, side, selection);
    }
  };
  gatherWith(grid, photons, voxel, params, radius, keys, out, vote, select);
  return out;
}

}  // namespace lo
