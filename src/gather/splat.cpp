// splatPhotons: the photon bins of the surface grid that the gather reads
// (paper §3.1.1). Each photon goes to the active voxel containing it.

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"
#include "gather/gather.h"

namespace lo {

size_t splatPhotons(SurfaceGrid& grid, const std::vector<Photon>& photons) {
  if (photons.size() >= size_t(std::numeric_limits<uint32_t>::max())) {
    throw InputError("too many photons (" + std::to_string(photons.size()) + ")");
  }
  const size_t n = grid.size();
  constexpr uint32_t kDropped = std::numeric_limits<uint32_t>::max();
  const double vs = grid.frame.voxelSize;
  const double ox = grid.frame.origin.x, oy = grid.frame.origin.y, oz = grid.frame.origin.z;
  std::vector<uint32_t> target(photons.size());
  tbb::enumerable_thread_specific<double> margins(0.0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, photons.size(), 4096),
                    [&](const tbb::blocked_range<size_t>& r) {
                      double& margin = margins.local();
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        const Vec3& p = photons[i].position;
                        target[i] = kDropped;
                        if (!isFinite(p)) continue;
                        const Coord c = grid.frame.coordOf(p);
                        const int64_t v = grid.find(c);
                        if (v >= 0) {
                          target[i] = uint32_t(v);
                          continue;
                        }
                        // Numeric edge case (a hit point a rounding error off its surface):
                        // the nearest active neighbour by distance from p to the voxel box,
                        // ties to the lower voxel index.
                        double best = INFINITY;
                        for (int dx = -1; dx <= 1; ++dx) {
                          for (int dy = -1; dy <= 1; ++dy) {
                            for (int dz = -1; dz <= 1; ++dz) {
                              const Coord nc{c.x + dx, c.y + dy, c.z + dz};
                              const int64_t w = grid.find(nc);
                              if (w < 0) continue;
                              // Same double arithmetic as the voxelizer's frame.
                              const double rx = double(p.x) - (ox + (nc.x + 0.5) * vs);
                              const double ry = double(p.y) - (oy + (nc.y + 0.5) * vs);
                              const double rz = double(p.z) - (oz + (nc.z + 0.5) * vs);
                              const double hv = 0.5 * vs;
                              const double ex = std::max(0.0, std::abs(rx) - hv);
                              const double ey = std::max(0.0, std::abs(ry) - hv);
                              const double ez = std::max(0.0, std::abs(rz) - hv);
                              const double d = std::sqrt(ex * ex + ey * ey + ez * ez);
                              if (d < best || (d == best && uint32_t(w) < target[i])) {
                                best = d;
                                target[i] = uint32_t(w);
                              }
                            }
                          }
                        }
                        if (target[i] != kDropped) margin = std::max(margin, best);
                      }
                    });
  double margin = 0;
  for (double m : margins) margin = std::max(margin, m);
  // Round up so the float margin is never below the double one.
  grid.binMargin = margin > 0 ? std::nextafter(float(margin), INFINITY) : 0.0f;

  // Counting sort: bins keep photon order.
  grid.binStart.assign(n + 1, 0);
  size_t dropped = 0;
  for (uint32_t t : target) {
    if (t == kDropped) {
      ++dropped;
    } else {
      ++grid.binStart[t + 1];
    }
  }
  for (size_t v = 0; v < n; ++v) grid.binStart[v + 1] += grid.binStart[v];
  grid.binPhotons.assign(photons.size() - dropped, 0);
  std::vector<uint32_t> cursor(grid.binStart.begin(), grid.binStart.end() - 1);
  for (size_t i = 0; i < target.size(); ++i) {
    if (target[i] != kDropped) grid.binPhotons[cursor[target[i]]++] = uint32_t(i);
  }
  return dropped;
}

void sortPhotonsByBin(SurfaceGrid& grid, std::vector<Photon>& photons) {
  const size_t n = photons.size(), binned = grid.binPhotons.size();
  LO_CHECK_LE(binned, n);
  bool identity = true;
  for (size_t j = 0; j < binned && identity; ++j) identity = grid.binPhotons[j] == uint32_t(j);
  if (identity) return;
  // Where each photon goes: a binned one to its slot, a dropped one after
  // the last slot in photon order. grid.binPhotons becomes the identity.
  std::vector<uint32_t> destination(n, std::numeric_limits<uint32_t>::max());
  for (size_t j = 0; j < binned; ++j) destination[grid.binPhotons[j]] = uint32_t(j);
  uint32_t next = uint32_t(binned);
  for (size_t i = 0; i < n; ++i) {
    if (destination[i] == std::numeric_limits<uint32_t>::max()) destination[i] = next++;
  }
  // The permutation's cycles, each followed once: the photon carried along
  // a cycle goes to its destination and picks up the one that stood there.
  std::vector<bool> placed(n, false);
  for (size_t start = 0; start < n; ++start) {
    if (placed[start]) continue;
    placed[start] = true;
    Photon carried = photons[start];
    size_t to = destination[start];
    while (to != start) {
      std::swap(carried, photons[to]);
      placed[to] = true;
      to = destination[to];
    }
    photons[start] = carried;
  }
  for (size_t j = 0; j < binned; ++j) grid.binPhotons[j] = uint32_t(j);
}

}  // namespace lo
