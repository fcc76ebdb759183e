// Weighted spherical K-means of photon directions into virtual directional
// lights (paper §3.1.2). See docs/clustering.md for the method and its
// degenerate cases.

#include <algorithm>
#include <array>
#include <string>
#include <vector>

#include "cluster/kmeans_internal.h"
#include "cluster/vdl_cluster.h"
#include "core/error.h"
#include "core/rng.h"

namespace lo {
namespace kmeans_internal {
namespace {

// Called ~100k times per bake on ~300 samples: the per-sample arrays live in
// thread-local storage that only ever grows, so a call allocates nothing once
// a thread has seen its largest voxel.
struct Scratch {
  std::vector<float> weight;  // K-means weight = average(value); <= 0 means "never a seed, no pull"
  std::vector<float> dist2;   // k-means++: squared chord to the nearest chosen centre
  std::vector<uint8_t> label;

  void reserve(size_t n) {
    if (weight.size() < n) {
      weight.resize(n);
      dist2.resize(n);
      label.resize(n);
    }
  }
};

Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

// Fills scratch weights; returns the total positive weight.
double prepareWeights(const DirectionSample* samples, size_t n, Scratch& s) {
  s.reserve(n);
  double total = 0;
  for (size_t i = 0; i < n; ++i) {
    float w = average(samples[i].value);
    // NaN fails the test too, so a broken sample never pulls a centre.
    s.weight[i] = w > 0 ? w : 0.0f;
    total += s.weight[i];
  }
  return total;
}

// Nearest centre by chord length |d - c|. For unit vectors that is the largest
// dot product, which is cheaper; ties go to the lowest index.
inline int nearest(const Vec3& d, const Vec3* centre, int k) {
  int best = 0;
  float bestDot = dot(d, centre[0]);
  for (int j = 1; j < k; ++j) {
    float t = dot(d, centre[j]);
    if (t > bestDot) {
      bestDot = t;
      best = j;
    }
  }
  return best;
}

// Index i drawn with probability p[i] / total (p >= 0, total = sum p > 0).
size_t pickProportional(const float* w, const float* d2, size_t n, double total, Rng& rng) {
  double u = double(rng.uniform()) * total;
  double cum = 0;
  size_t last = 0;
  for (size_t i = 0; i < n; ++i) {
    double p = d2 ? double(w[i]) * double(d2[i]) : double(w[i]);
    if (p <= 0) continue;
    cum += p;
    last = i;
    if (cum > u) return i;
  }
  return last;  // rounding left u at the very end of the distribution
}

// k-means++ (Arthur & Vassilvitskii 2007) with the chord length and the sample
// weights: the first centre is drawn by weight, each next one by w * D^2. Stops
// early when every weighted sample coincides with a centre (fewer distinct
// directions than k), so identical directions give one VDL.
int seedCentres(const DirectionSample* samples, size_t n, double totalWeight, int k, Rng& rng,
                Scratch& s, Vec3* centre) {
  size_t first = pickProportional(s.weight.data(), nullptr, n, totalWeight, rng);
  centre[0] = samples[first].direction;
  int m = 1;
  for (size_t i = 0; i < n; ++i) {
    // Computed as a difference, not 2 - 2 dot: identical directions must give
    // exactly zero so that they can never be chosen twice.
    s.dist2[i] = lengthSquared(samples[i].direction - centre[0]);
  }
  while (m < k) {
    double total = 0;
    for (size_t i = 0; i < n; ++i) total += double(s.weight[i]) * double(s.dist2[i]);
    if (!(total > 0)) break;
    size_t pick = pickProportional(s.weight.data(), s.dist2.data(), n, total, rng);
    const Vec3 c = samples[pick].direction;
    centre[m++] = c;
    for (size_t i = 0; i < n; ++i) {
      s.dist2[i] = std::min(s.dist2[i], lengthSquared(samples[i].direction - c));
    }
  }
  return m;
}

struct ClusterSums {
  std::array<Vec3, kMaxVdls> weightedDir{};
  std::array<float, kMaxVdls> weight{};
};

void accumulate(const DirectionSample* samples, size_t n, const Scratch& s, int k,
                ClusterSums& sums) {
  for (int j = 0; j < k; ++j) {
    sums.weightedDir[j] = Vec3{};
    sums.weight[j] = 0;
  }
  for (size_t i = 0; i < n; ++i) {
    float w = s.weight[i];
    if (w <= 0) continue;
    int j = s.label[i];
    sums.weightedDir[j] += samples[i].direction * w;
    sums.weight[j] += w;
  }
}

// Empty clusters (no member with positive weight) are dropped, not re-seeded:
// re-seeding would need more random draws and iterations for a case that only
// arises when k is already larger than the voxel's distinct light directions.
// Members of a dropped cluster (all of weight 0) move to the nearest live one,
// which leaves the sums unchanged. Returns the live count.
int dropEmpty(const DirectionSample* samples, size_t n, Scratch& s, int k, Vec3* centre,
              ClusterSums& sums) {
  std::array<int, kMaxVdls> remap{};
  int live = 0;
  for (int j = 0; j < k; ++j) {
    if (sums.weight[j] > 0) {
      remap[j] = live;
      centre[live] = centre[j];
      sums.weightedDir[live] = sums.weightedDir[j];
      sums.weight[live] = sums.weight[j];
      ++live;
    } else {
      remap[j] = -1;
    }
  }
  if (live == k) return k;
  for (size_t i = 0; i < n; ++i) {
    int r = remap[s.label[i]];
    s.label[i] = uint8_t(r >= 0 ? r : nearest(samples[i].direction, centre, live));
  }
  return live;
}

bool assignAll(const DirectionSample* samples, size_t n, Scratch& s, const Vec3* centre, int k) {
  bool changed = false;
  for (size_t i = 0; i < n; ++i) {
    uint8_t j = uint8_t(nearest(samples[i].direction, centre, k));
    changed |= j != s.label[i];
    s.label[i] = j;
  }
  return changed;
}

bool vdlBefore(const Vdl& a, const Vdl& b) {
  float pa = average(a.irradiance), pb = average(b.irradiance);
  if (pa != pb) return pa > pb;
  for (int c = 0; c < 3; ++c) {
    if (a.direction[c] != b.direction[c]) return a.direction[c] < b.direction[c];
  }
  for (int c = 0; c < 3; ++c) {
    if (a.irradiance[c] != b.irradiance[c]) return a.irradiance[c] > b.irradiance[c];
  }
  return false;
}

// Lloyd iterations from centre[0..k), then the VDLs. Weights already prepared
// and their total is positive.
ClusterResult lloyd(const DirectionSample* samples, size_t n, Scratch& s, Vec3* centre, int k,
                    int maxIterations) {
  for (size_t i = 0; i < n; ++i) s.label[i] = uint8_t(nearest(samples[i].direction, centre, k));
  ClusterSums sums;
  for (int it = 0;; ++it) {
    accumulate(samples, n, s, k, sums);
    k = dropEmpty(samples, n, s, k, centre, sums);
    for (int j = 0; j < k; ++j) {
      // A zero sum means members in exactly opposite directions cancel: no
      // mean direction exists, so the centre stays where it was.
      Vec3 c = normalize(sums.weightedDir[j]);
      if (c != Vec3{}) centre[j] = c;
    }
    // After the update the centres are the normalized weighted means of the
    // current members, which is what a VDL's direction is defined as.
    if (it >= maxIterations || !assignAll(samples, n, s, centre, k)) break;
  }

  // VDL irradiance sums every member's value, weight 0 included, in sample
  // order and in double: the VDLs add up to the total up to one float rounding.
  std::array<std::array<double, 3>, kMaxVdls> irr{};
  double errorSum = 0, weightSum = 0;
  for (size_t i = 0; i < n; ++i) {
    int j = s.label[i];
    const Vec3& v = samples[i].value;
    irr[j][0] += v.x;
    irr[j][1] += v.y;
    irr[j][2] += v.z;
    if (s.weight[i] > 0) {
      errorSum += double(s.weight[i]) * lengthSquared(samples[i].direction - centre[j]);
      weightSum += s.weight[i];
    }
  }
  ClusterResult result;
  result.count = k;
  for (int j = 0; j < k; ++j) {
    result.vdls[j].irradiance = Vec3(float(irr[j][0]), float(irr[j][1]), float(irr[j][2]));
    result.vdls[j].direction = centre[j];
  }
  // Insertion sort: k <= 8, and GCC 12 warns falsely (-Warray-bounds) on
  // std::sort over part of a std::array.
  for (int a = 1; a < k; ++a) {
    for (int b = a; b > 0 && vdlBefore(result.vdls[b], result.vdls[b - 1]); --b) {
      std::swap(result.vdls[b], result.vdls[b - 1]);
    }
  }
  result.angularError = weightSum > 0 ? float(std::sqrt(errorSum / weightSum)) : 0.0f;
  return result;
}

void checkK(int k) {
  if (k < 1 || k > kMaxVdls) {
    throw InputError("VDL count " + std::to_string(k) + " is outside [1, " +
                     std::to_string(kMaxVdls) + "]");
  }
}

}  // namespace

ClusterResult clusterFromCentres(const DirectionSample* samples, size_t n, const Vec3* centres,
                                 int k, int maxIterations) {
  checkK(k);
  Scratch& s = scratch();
  if (n == 0 || !(prepareWeights(samples, n, s) > 0)) return {};
  std::array<Vec3, kMaxVdls> centre{};
  std::copy(centres, centres + k, centre.begin());
  return lloyd(samples, n, s, centre.data(), k, std::max(maxIterations, 0));
}

}  // namespace kmeans_internal

ClusterResult clusterDirections(const DirectionSample* samples, size_t n, int k,
                                const ClusterParams& params, uint64_t stream) {
  using namespace kmeans_internal;
  checkK(k);
  Scratch& s = scratch();
  if (n == 0) return {};
  double total = prepareWeights(samples, n, s);
  if (!(total > 0)) return {};  // no power: no light to represent

  const int maxIterations = std::max(params.maxIterations, 0);
  auto run = [&](int kk) {
    Rng rng(params.seed, stream);
    std::array<Vec3, kMaxVdls> centre{};
    int m = seedCentres(samples, n, total, kk, rng, s, centre.data());
    return lloyd(samples, n, s, centre.data(), m, maxIterations);
  };

  if (!params.autoCount) return run(k);
  // Auto mode (paper §5.3.2): the fewest VDLs whose chord-length deviation is
  // acceptable; k is the cap.
  ClusterResult r;
  for (int kk = 1; kk <= k; ++kk) {
    r = run(kk);
    if (r.angularError <= params.autoThreshold) break;
  }
  return r;
}

}  // namespace lo
