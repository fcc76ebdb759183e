// The bake's per-voxel loop: KNN gather (src/gather) then K-means into VDLs
// (paper §3.1.1 and §3.1.2), TBB-parallel over runs of consecutive voxels.

#include "cluster/vdl_cluster.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"

namespace lo {
namespace vdl_grid_internal {

// Per-thread state: the gatherer holds candidate scratch; the sample buffer
// and result are reused from voxel to voxel so the loop does not allocate.
struct Worker {
  Worker(const SurfaceGrid& grid, const std::vector<Photon>& photons,
         std::shared_ptr<const BinnedPhotons> binned, const GatherParams& params)
      : gatherer(grid, photons, std::move(binned), params) {}
  Gatherer gatherer;
  GatherResult gathered;
  std::vector<DirectionSample> samples;
  double gatherSeconds = 0;
  double clusterSeconds = 0;
};

using Clock = std::chrono::steady_clock;

inline double secondsBetween(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

// Voxels in canonical order are grouped by 8^3 block, so a run of 64 indices
// mostly stays within one or two blocks: neighbouring gathers touch the same
// photon bins.
constexpr size_t kGrainVoxels = 64;

struct BakeBody {
  const std::vector<Photon>& photons;
  const ClusterParams& cluster;
  tbb::enumerable_thread_specific<Worker>& workers;
  Progress& progress;
  VdlGrid& out;

  void operator()(const tbb::blocked_range<size_t>& range) const {
    Worker& w = workers.local();
    double gatherSeconds = 0, clusterSeconds = 0;
    const size_t maxVdls = size_t(out.maxVdls);
    for (size_t v = range.begin(); v != range.end(); ++v) {
      Clock::time_point t0 = Clock::now();
      w.gatherer.gather(v, w.gathered);
      const GatherResult& g = w.gathered;
      // Each photon's share of the irradiance estimate E = sum(power) / (pi r_k^2)
      // (W/m^2), so the VDLs of the voxel sum to its estimate.
      w.samples.clear();
      const float r = g.radius;
      if (r > 0) {
        const float invArea = 1.0f / (kPi * r * r);
        for (uint32_t p : g.photons) {
          const Photon& ph = photons[p];
          w.samples.push_back({ph.direction, ph.power * invArea});
        }
      }
      Clock::time_point t1 = Clock::now();
      ClusterResult c =
          clusterDirections(w.samples.data(), w.samples.size(), cluster.vdls, cluster, v);
      Clock::time_point t2 = Clock::now();
      gatherSeconds += secondsBetween(t0, t1);
      clusterSeconds += secondsBetween(t1, t2);

      out.normals[v] = g.normal;
      out.irradiance[v] = g.irradiance;
      out.photonCount[v] = float(g.photons.size());
      out.radius[v] = g.radius;
      out.angularError[v] = c.angularError;
      out.vdlCount[v] = uint8_t(c.count);
      Vdl* dst = out.vdls.data() + v * maxVdls;
      for (int i = 0; i < c.count; ++i) dst[i] = c.vdls[i];
    }
    w.gatherSeconds += gatherSeconds;
    w.clusterSeconds += clusterSeconds;
    progress.advance(range.size());
  }
};

}  // namespace vdl_grid_internal

VdlGrid buildVdlGrid(const SurfaceGrid& grid, const std::vector<Photon>& photons,
                     const GatherParams& gather, const ClusterParams& cluster,
                     ProgressSink* progress, BakeTimings* timings) {
  using namespace vdl_grid_internal;
  if (cluster.vdls < 1 || cluster.vdls > kMaxVdls) {
    throw InputError("VDL count " + std::to_string(cluster.vdls) + " is outside [1, " +
                     std::to_string(kMaxVdls) + "]");
  }
  const size_t n = grid.size();
  LO_CHECK_EQ(grid.areas.size(), n);

  VdlGrid out;
  out.frame = grid.frame;
  // In auto mode vdls is the cap, so it is also the slot count per voxel.
  out.maxVdls = cluster.vdls;
  out.coords = grid.coords;
  out.areas = grid.areas;
  out.normals.assign(n, Vec3{});
  out.irradiance.assign(n, Vec3{});
  out.photonCount.assign(n, 0.0f);
  out.radius.assign(n, 0.0f);
  out.angularError.assign(n, 0.0f);
  out.vdlCount.assign(n, 0);
  out.vdls.assign(n * size_t(out.maxVdls), Vdl{});  // unused slots stay zero

  // One copy of the binned photons, read by every thread's gatherer.
  std::shared_ptr<const BinnedPhotons> binned = binPhotonsForGather(grid, photons);
  tbb::enumerable_thread_specific<Worker> workers(
      [&] { return Worker(grid, photons, binned, gather); });
  {
    Progress bar(progress, "gather + cluster", n);
    // Every voxel writes only its own slots and seeds its K-means with its
    // index, so the result does not depend on the partition or thread count.
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, kGrainVoxels),
                      BakeBody{photons, cluster, workers, bar, out});
  }

  if (timings) {
    *timings = BakeTimings{};
    for (const Worker& w : workers) {
      timings->gatherSeconds += w.gatherSeconds;
      timings->clusterSeconds += w.clusterSeconds;
    }
  }
  return out;
}

}  // namespace lo
