// distributedBake: the steps of tiled_bake.h. Why the result equals bake()'s
// value for value (docs/scale.md, "Why the bytes are the same"):
//  - the photons are the same, in the same order on every rank: the first
//    `photons` of paths 0, 1, 2, ... (each path's random numbers depend on
//    its index alone), received batch by batch and, within a batch, in rank
//    order, which is path order;
//  - a rank holds every active voxel within photonHalo + 1 voxels of its
//    tiles and every photon within photonHalo, so each photon it holds is
//    splatted into the bin the whole grid gives it, and the bins its voxels
//    read are whole; the bin margin, a maximum over photons, is reduced over
//    the ranks;
//  - a voxel's gather and K-means read only those bins, its neighbours'
//    geometry and its own coordinate (the K-means stream), and the smoothing
//    reads the 26 neighbours, which the rank computes too.

#include "distributed/tiled_bake.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdlib>
#include <cstring>
#include <numeric>
#include <sstream>

#include "core/error.h"
#include "core/resources.h"
#include "distributed/vdl_grid_parts.h"
#include "photon/photon_map.h"

namespace lo {

namespace distributed_internal {

/// Estimated work of an active voxel against a stored photon (gather,
/// K-means and layers against splat and binning), from the cost model of
/// docs/scale.md.
/// Memory per voxel against memory per photon: the work is balanced by the
/// memory the bake needs (what a distributed bake is for), which also
/// follows the time closely on surfaces of uniform photon density.
constexpr double kVoxelWorkPhotons = double(kBakeBytesPerVoxel) / double(kBakeBytesPerPhoton);

inline int log2Exact(int v) {
  int s = 0;
  while ((1 << s) < v) ++s;
  return s;
}

/// Z-order (Morton) code of a tile, 3 x 10 bits.
inline uint32_t mortonCode(uint32_t x, uint32_t y, uint32_t z) {
  uint32_t code = 0;
  for (int b = 0; b < 10; ++b) {
    code |= ((x >> b) & 1u) << (3 * b + 2);
    code |= ((y >> b) & 1u) << (3 * b + 1);
    code |= ((z >> b) & 1u) << (3 * b);
  }
  return code;
}

void checkTilesPerAxis(int tiles, int depth) {
  const int most = maxTilesPerAxis(depth);
  if (tiles < 1 || tiles > most || (tiles & (tiles - 1)) != 0) {
    throw InputError("--tiles " + std::to_string(tiles) + " must be a power of two from 1 to " +
                     std::to_string(most) + " at --depth " + std::to_string(depth) +
                     " (tiles of at least 8^3 voxels, at most " + std::to_string(kMaxTilesPerAxis) +
                     " per axis)");
  }
}

/// Estimated work per tile: the geometry's area in it (a voxelization at the
/// tile resolution) in voxels, and `pilot` photons per tile scaled to the map.
std::vector<double> estimateWork(const Scene& scene, const GridParams& grid, int tilesPerAxis,
                                 const std::vector<uint64_t>& pilot, double photonScale) {
  const size_t tiles = size_t(tilesPerAxis) * size_t(tilesPerAxis) * size_t(tilesPerAxis);
  std::vector<double> work(tiles, 0.0);
  for (size_t t = 0; t < tiles; ++t) work[t] = double(pilot[t]) * photonScale;
  if (tilesPerAxis > 1 && scene.triangleCount() > 0) {
    GridParams coarse = grid;
    coarse.depth = log2Exact(tilesPerAxis);
    coarse.keepBlock = nullptr;
    const SurfaceGrid areas = buildSurfaceGrid(scene, coarse);
    const GridFrame fine =
        makeGridFrame(grid.region.empty() ? scene.bounds() : grid.region, grid.depth, grid.padding);
    const double voxelArea = double(fine.voxelSize) * double(fine.voxelSize);
    for (size_t i = 0; i < areas.size(); ++i) {
      const Coord& c = areas.coords[i];
      const size_t t =
          (size_t(c.x) * size_t(tilesPerAxis) + size_t(c.y)) * size_t(tilesPerAxis) + size_t(c.z);
      // A plane of normal n crosses (|nx| + |ny| + |nz|) A / h^2 voxels (its
      // projections on the three axis planes): per orientation of the tile's
      // geometry, else its mean normal (1 where opposite faces cancel).
      double voxels = 0;
      const uint32_t first = areas.orientationStart[i], last = areas.orientationStart[i + 1];
      auto crossing = [](const Vec3& n) {
        const double f = double(std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z));
        return f > 0 ? f : 1.0;
      };
      if (first == last) {
        voxels = double(areas.areas[i]) * crossing(areas.normals[i]);
      } else {
        double covered = 0;
        for (uint32_t o = first; o < last; ++o) {
          voxels += double(areas.orientations[o].area) * crossing(areas.orientations[o].normal);
          covered += double(areas.orientations[o].area);
        }
        voxels += std::max(0.0, double(areas.areas[i]) - covered);  // the small clusters dropped
      }
      work[t] += voxels / voxelArea * kVoxelWorkPhotons;
    }
  }
  return work;
}

/// What a rank's grid covers: the blocks within `halo` voxels of its tiles.
struct LocalRegion {
  const TilePlan* plan = nullptr;
  int rank = 0;
  int halo = 0;
  bool owns(int tx, int ty, int tz) const {
    const int T = plan->tilesPerAxis;
    return plan->owner[(size_t(tx) * size_t(T) + size_t(ty)) * size_t(T) + size_t(tz)] == rank;
  }
  /// Whether any tile of this rank lies within `halo` voxels of the block.
  bool keepBlock(const Coord& b) const {
    const int res = 1 << plan->depth;
    int lo[3], hi[3];
    const int v[3] = {b.x, b.y, b.z};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::max(0, v[a] * 8 - halo) >> plan->tileShift;
      hi[a] = std::min(res - 1, v[a] * 8 + 7 + halo) >> plan->tileShift;
    }
    for (int x = lo[0]; x <= hi[0]; ++x)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int z = lo[2]; z <= hi[2]; ++z)
          if (owns(x, y, z)) return true;
    return false;
  }
};

/// Photons of one batch sent to the ranks whose tiles or halo hold them;
/// appends what this rank receives to `held`.
struct ExchangeResult {
  uint64_t sent = 0, received = 0, unsent = 0;
};

ExchangeResult exchangePhotons(Communicator& comm, const TilePlan& plan, const GridFrame& frame,
                               const std::vector<Photon>& batch, std::vector<Photon>& held) {
  const int n = comm.size();
  ExchangeResult out;
  std::vector<uint64_t> begin(size_t(n) + 1, 0);
  for (const Photon& p : batch) {
    size_t to = 0;
    plan.forOwnersNear(frame.coordOf(p.position), plan.photonHalo, [&](int r) {
      ++begin[size_t(r) + 1];
      ++to;
    });
    out.unsent += to == 0;
  }
  for (int r = 0; r < n; ++r) begin[size_t(r) + 1] += begin[size_t(r)];
  std::vector<Photon> send(static_cast<size_t>(begin[size_t(n)]));
  std::vector<uint64_t> cursor(begin.begin(), begin.end() - 1);
  for (const Photon& p : batch) {
    plan.forOwnersNear(frame.coordOf(p.position), plan.photonHalo,
                       [&](int r) { send[size_t(cursor[size_t(r)]++)] = p; });
  }
  const size_t before = held.size();
  out.sent = exchangeItems(comm, send, begin, held);
  const uint64_t fromSelf = begin[size_t(comm.rank()) + 1] - begin[size_t(comm.rank())];
  out.received = (uint64_t(held.size() - before) - fromSelf) * sizeof(Photon);
  return out;
}

std::vector<char> rankStatsBytes(const RankStats& s) {
  std::vector<char> bytes(sizeof(RankStats), 0);
  std::memcpy(bytes.data(), &s, sizeof s);
  return bytes;
}

}  // namespace distributed_internal

int maxTilesPerAxis(int depth) {
  return std::max(1, std::min(kMaxTilesPerAxis, (1 << std::clamp(depth, 0, 30)) / 8));
}

int autoTilesPerAxis(int depth) { return std::min(32, maxTilesPerAxis(depth)); }

size_t TilePlan::tileOf(const Coord& c) const {
  const int res = 1 << depth;
  const size_t x = size_t(std::clamp(c.x, 0, res - 1) >> tileShift);
  const size_t y = size_t(std::clamp(c.y, 0, res - 1) >> tileShift);
  const size_t z = size_t(std::clamp(c.z, 0, res - 1) >> tileShift);
  const size_t T = size_t(tilesPerAxis);
  return (x * T + y) * T + z;
}

std::string TilePlan::ToString() const {
  std::ostringstream os;
  os << "TilePlan{depth " << depth << ", " << tilesPerAxis << "^3 tiles of " << (1 << tileShift)
     << "^3 voxels, " << ranks << " ranks, photon halo " << photonHalo << " voxels}";
  return os.str();
}

int photonHaloVoxels(const GatherParams& gather, const GridFrame& frame, double marginVoxels) {
  const double reach = gatherReach(gather, frame) / double(frame.voxelSize) + marginVoxels;
  // Gatherer's reach in voxels with its relative slack, plus one for a query
  // point on its voxel's upper face.
  const double slack = reach * (1.0 + 1e-4) + 1e-6;
  if (!(slack < double(1 << 20))) {
    throw InputError("the gathering radius reaches " + formatNumber(reach) +
                     " voxels: too far for a tiled bake");
  }
  const int reachVoxels = int(std::ceil(slack)) + 1;
  // + 1: the neighbours the smoothing reads are computed too;
  // + 1: a photon splats into a neighbour of its own voxel.
  return reachVoxels + 2;
}

TilePlan planTiles(int depth, int tilesPerAxis, const std::vector<double>& work, int ranks,
                   int photonHalo) {
  using namespace distributed_internal;
  checkTilesPerAxis(tilesPerAxis, depth);
  if (ranks < 1) throw InputError("ranks " + std::to_string(ranks) + " must be at least 1");
  TilePlan plan;
  plan.depth = depth;
  plan.tilesPerAxis = tilesPerAxis;
  plan.tileShift = depth - log2Exact(tilesPerAxis);
  plan.ranks = ranks;
  plan.photonHalo = photonHalo;
  const size_t T = size_t(tilesPerAxis), tiles = T * T * T;
  LO_CHECK_EQ(work.size(), tiles);
  plan.work = work;
  std::vector<std::pair<uint32_t, size_t>> curve(tiles);
  for (size_t x = 0; x < T; ++x)
    for (size_t y = 0; y < T; ++y)
      for (size_t z = 0; z < T; ++z) {
        const size_t t = (x * T + y) * T + z;
        curve[t] = {mortonCode(uint32_t(x), uint32_t(y), uint32_t(z)), t};
      }
  std::sort(curve.begin(), curve.end());
  double total = 0;
  for (double w : work) total += std::max(0.0, w);
  plan.owner.assign(tiles, 0);
  double before = 0;
  for (const auto& [code, t] : curve) {
    const double w = std::max(0.0, work[t]);
    const double mid = before + 0.5 * w;
    plan.owner[t] =
        total > 0 ? std::min(ranks - 1, int(std::floor(mid / total * double(ranks)))) : 0;
    before += w;
  }
  return plan;
}

BakeResult distributedBake(const Scene& scene, const BakeParams& requested,
                           const TileParams& tileParams, Communicator& comm, ProgressSink* progress,
                           DistributedStats* stats) {
  using namespace distributed_internal;
  const int ranks = comm.size(), me = comm.rank();
  Stopwatch total;
  const BakeParams params = checkedBakeParams(scene, requested, ranks);
  if (params.keepPhotons) {
    throw InputError(
        "--photon-map: a bake on several processes keeps no photon map (each holds a part of "
        "it); write it from a bake on one process");
  }
  const LevelParams level = params.levelParams();
  const GridFrame frame = makeGridFrame(params.region.empty() ? scene.bounds() : params.region,
                                        params.depth, level.grid.padding);
  const int tilesPerAxis =
      tileParams.tilesPerAxis != 0 ? tileParams.tilesPerAxis : autoTilesPerAxis(params.depth);
  checkTilesPerAxis(tilesPerAxis, params.depth);

  BakeResult result;
  BakeStats& st = result.stats;
  RankStats mine;
  std::vector<Photon> held;  // this rank's tiles and halo, in map order
  TilePlan plan;
  SurfaceGrid grid;
  uint64_t stored = 0, emitted = 0, empty = 0, unsent = 0;
  int halo = 0, attempts = 0;
  for (const double assumedMargin :
       {std::min(tileParams.assumedMarginVoxels, kMaxBinMarginVoxels), kMaxBinMarginVoxels}) {
    ++attempts;
    halo = photonHaloVoxels(level.gather, frame, assumedMargin);
    st = BakeStats{};
    st.triangles = scene.triangleCount();
    st.denseVoxels = size_t(1) << (3 * params.depth);
    mine = RankStats{};
    mine.rank = me;
    std::vector<Photon>().swap(held);
    stored = emitted = empty = unsent = 0;

    // 1. Photons by rank, sent batch by batch to the tiles that hold them.
    StageTimer traceTimer(st.stages, "trace + exchange");
    const PhotonParams photonParams = params.photonParams();
    PhotonTracer tracer(scene, photonParams);
    const size_t target = photonParams.storedPhotons;
    const size_t maxEmitted = maxEmittedPaths(photonParams);
    std::vector<Photon> batch;
    std::vector<uint32_t> pathPhotons;
    bool planned = false;
    auto makePlan = [&](const std::vector<Photon>& pilot, uint64_t pilotStored) {
      const size_t T = size_t(tilesPerAxis);
      std::vector<uint64_t> counts(T * T * T, 0);
      TilePlan probe;  // tile lookup only
      probe.depth = params.depth;
      probe.tilesPerAxis = tilesPerAxis;
      probe.tileShift = params.depth - log2Exact(tilesPerAxis);
      for (const Photon& p : pilot) ++counts[probe.tileOf(frame.coordOf(p.position))];
      comm.allreduceSum(counts.data(), counts.size());
      const double scale = pilotStored > 0 ? double(target) / double(pilotStored) : 0.0;
      plan = planTiles(params.depth, tilesPerAxis,
                       estimateWork(scene, level.grid, tilesPerAxis, counts, scale), ranks, halo);
      if (!tileParams.owner.empty()) {
        if (tileParams.owner.size() != plan.owner.size()) {
          throw InputError("a tile owner table of " + std::to_string(tileParams.owner.size()) +
                           " entries for " + std::to_string(plan.owner.size()) + " tiles");
        }
        for (int32_t r : tileParams.owner) {
          if (r < 0 || r >= ranks) {
            throw InputError("tile owner " + std::to_string(r) + " is not one of the " +
                             std::to_string(ranks) + " ranks");
          }
        }
        plan.owner = tileParams.owner;
      }
      planned = true;
    };
    {
      Progress bar(progress, "Tracing photons", target);
      while (target > 0 && tracer.canStore() && stored < target) {
        const size_t paths = photonBatchPaths(target, size_t(stored), size_t(emitted), maxEmitted);
        if (paths == 0) break;
        // This rank's contiguous share of the batch's paths.
        const uint64_t first = emitted + uint64_t(paths) * uint64_t(me) / uint64_t(ranks);
        const uint64_t last = emitted + uint64_t(paths) * uint64_t(me + 1) / uint64_t(ranks);
        batch.clear();
        pathPhotons.clear();
        Stopwatch traceClock;
        tracer.trace(first, size_t(last - first), batch, pathPhotons);
        mine.traceSeconds += traceClock.seconds();

        // Where the map's last photon lies: the ranks before hold `before`.
        Stopwatch exchangeClock;
        const std::vector<uint64_t> counts = comm.allgather(batch.size());
        uint64_t before = stored;
        for (int r = 0; r < me; ++r) before += counts[size_t(r)];
        uint64_t keptPaths = 0, keptEmpty = 0;
        size_t keptPhotons = 0;
        for (size_t i = 0; i < pathPhotons.size() && before + keptPhotons < target; ++i) {
          keptPhotons += std::min<uint64_t>(pathPhotons[i], target - before - keptPhotons);
          ++keptPaths;
          keptEmpty += pathPhotons[i] == 0;
        }
        batch.resize(keptPhotons);
        uint64_t sums[3] = {keptPaths, keptEmpty, uint64_t(keptPhotons)};
        comm.allreduceSum(sums, 3);
        emitted += sums[0];
        empty += sums[1];
        stored += sums[2];
        mine.photonsTraced += keptPhotons;
        const bool firstBatch = !planned;
        if (firstBatch) makePlan(batch, sums[2]);
        const ExchangeResult ex = exchangePhotons(comm, plan, frame, batch, held);
        if (firstBatch && sums[2] > 0 && stored < target) {
          // This rank's share of the map, from the first batch's: reserved
          // once, not grown by doubling (which would hold up to twice it).
          const double share = double(held.size()) / double(sums[2]);
          held.reserve(size_t(share * double(target) * 1.02) + 4096);
        }
        mine.bytesSent += ex.sent;
        mine.bytesReceived += ex.received;
        unsent += ex.unsent;
        mine.exchangeSeconds += exchangeClock.seconds();
        bar.advance(size_t(sums[2]));
      }
    }
    if (!planned) makePlan({}, 0);
    // The tests' stand-in for a machine lost mid-bake (docs/scale.md): this
    // rank dies as a killed process does, between the photon exchange and the
    // gather.
    if (const char* kill = std::getenv("LIGHTOCTREE_KILL_RANK")) {
      if (std::string(kill) == std::to_string(me)) std::raise(SIGKILL);
    }
    std::vector<Photon>().swap(batch);
    scalePhotonPower(held, size_t(emitted));
    st.storedPhotons = size_t(stored);
    st.emittedPaths = size_t(emitted);
    st.emptyPaths = size_t(empty);
    mine.photonsHeld = held.size();
    st.traceSeconds = traceTimer.finish(formatCount(size_t(stored)) + " photons from " +
                                        formatCount(size_t(emitted)) + " paths on " +
                                        std::to_string(ranks) + " ranks");
    for (size_t t = 0; t < plan.owner.size(); ++t) {
      if (plan.owner[t] == me && plan.work[t] > 0) ++mine.tilesOwned;
    }
    {
      double all = 0, own = 0;
      for (size_t t = 0; t < plan.work.size(); ++t) {
        all += plan.work[t];
        if (plan.owner[t] == me) own += plan.work[t];
      }
      mine.workShare = all > 0 ? own / all : 0.0;
    }

    // 2. This rank's tiles and halo, voxelized; its photons splatted.
    StageTimer voxelizeTimer(st.stages, "voxelize");
    LocalRegion region{&plan, me, halo + 1};
    GridParams gridParams = level.grid;
    {
      const int res = 1 << params.depth, edge = 1 << plan.tileShift;
      Coord lo{res, res, res}, hi{-1, -1, -1};
      const size_t T = size_t(tilesPerAxis);
      for (size_t t = 0; t < plan.owner.size(); ++t) {
        if (plan.owner[t] != me) continue;
        const int x = int(t / (T * T)), y = int(t / T % T), z = int(t % T);
        lo = {std::min(lo.x, x * edge), std::min(lo.y, y * edge), std::min(lo.z, z * edge)};
        hi = {std::max(hi.x, x * edge + edge - 1), std::max(hi.y, y * edge + edge - 1),
              std::max(hi.z, z * edge + edge - 1)};
      }
      gridParams.clipLower = {lo.x - region.halo, lo.y - region.halo, lo.z - region.halo};
      gridParams.clipUpper = {hi.x + region.halo, hi.y + region.halo, hi.z + region.halo};
      gridParams.keepBlock = [&region](const Coord& b) { return region.keepBlock(b); };
    }
    grid = buildSurfaceGrid(scene, gridParams, progress);
    mine.voxelsHeld = grid.size();
    mine.voxelizeSeconds = voxelizeTimer.finish(formatCount(grid.size()) + " voxels held on rank " +
                                                std::to_string(me));

    StageTimer splatTimer(st.stages, "splat photons");
    splatPhotons(grid, held);
    {
      double margin = double(grid.binMargin);
      comm.allreduceMax(&margin, 1);
      grid.binMargin = float(margin);  // a float already: the maximum of the ranks' floats
    }
    // Every rank sees the same margin, so all start again together.
    if (double(grid.binMargin) > assumedMargin * double(frame.voxelSize)) continue;
    // Photons outside every active voxel's neighbourhood, each counted by the
    // owner of its tile (or by its tracer, when no rank holds it).
    uint64_t dropped = unsent;
    {
      std::vector<char> binned(held.size(), 0);
      for (uint32_t i : grid.binPhotons) binned[i] = 1;
      for (size_t i = 0; i < held.size(); ++i) {
        if (!binned[i] && plan.ownerOf(frame.coordOf(held[i].position)) == me) ++dropped;
      }
    }
    comm.allreduceSum(&dropped, 1);
    st.level.droppedPhotons = size_t(dropped);
    mine.splatSeconds = splatTimer.finish();
    break;
  }
  const float binMargin = grid.binMargin;
  // The bound always holds: the second attempt never continues.
  LO_CHECK_LE(double(grid.binMargin), kMaxBinMarginVoxels * double(frame.voxelSize));

  // 3. Gather + cluster: this rank's voxels and the ring the smoothing reads.
  StageTimer clusterTimer(st.stages, "gather + cluster");
  std::vector<uint32_t> owned, computed;
  {
    std::vector<char> compute(grid.size(), 0);
    for (size_t v = 0; v < grid.size(); ++v) {
      if (plan.ownerOf(grid.coords[v]) != me) continue;
      owned.push_back(uint32_t(v));
      compute[v] = 1;
      if (!level.smoothing) continue;
      const Coord c = grid.coords[v];
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const int64_t w = grid.find({c.x + dx, c.y + dy, c.z + dz});
            if (w >= 0) compute[size_t(w)] = 1;
          }
    }
    for (size_t v = 0; v < grid.size(); ++v) {
      if (compute[v]) computed.push_back(uint32_t(v));
    }
  }
  mine.voxelsOwned = owned.size();
  mine.voxelsComputed = computed.size();
  GatherParams gather = level.gather;
  std::unique_ptr<GatherOcclusion> occlusion;
  if (level.occlusion && scene.triangleCount() > 0) {
    occlusion = std::make_unique<GatherOcclusion>(scene);
    gather.blocked = occlusion->test();
  }
  const LayerParams layerParams;
  VdlGrid local = buildVdlGrid(grid, held, gather, level.cluster, progress, &st.level.threadSeconds,
                               level.layers ? &layerParams : nullptr, &computed);
  if (level.smoothing) smoothVdlGrid(grid, local);
  std::vector<Photon>().swap(held);
  grid = SurfaceGrid{};
  mine.gatherClusterSeconds =
      clusterTimer.finish(formatCount(owned.size()) + " voxels owned, " +
                          formatCount(computed.size()) + " computed on rank " + std::to_string(me));

  // 4. The owned voxels, merged on rank 0.
  StageTimer mergeTimer(st.stages, "merge on rank 0");
  std::vector<std::vector<char>> parts =
      comm.gatherBytes(serializeVdlGrid(selectVoxels(local, owned)), 0);
  local = VdlGrid{};
  if (me == 0) {
    std::vector<VdlGrid> grids;
    for (std::vector<char>& bytes : parts) {
      grids.push_back(deserializeVdlGrid(bytes));
      std::vector<char>().swap(bytes);
    }
    result.grid = mergeVdlGrids(std::move(grids));
  }
  mine.mergeSeconds = mergeTimer.finish();

  uint64_t active = mine.voxelsOwned;
  comm.allreduceSum(&active, 1);
  st.level.activeVoxels = size_t(active);
  st.level.radius = resolveRadius(level.gather, frame);
  st.level.voxelizeSeconds = mine.voxelizeSeconds;
  st.level.splatSeconds = mine.splatSeconds;
  st.level.gatherClusterSeconds = mine.gatherClusterSeconds;
  if (me == 0) {
    size_t layered = 0;
    const VdlLayers& L = result.grid.layers;
    for (size_t e = 0; e < L.size(); ++e) {
      if (e == 0 || L.voxel[e] != L.voxel[e - 1]) ++layered;
    }
    st.level.layeredVoxels = layered;
    st.level.extraLayers = L.size();
  }
  result.metadata = bakeMetadata(scene, params, int64_t(stored), int64_t(emitted), st.level.radius);

  mine.totalSeconds = total.seconds();
  mine.peakRssBytes = peakRssBytes();
  // Every rank takes part, whether or not it asked for the figures.
  const std::vector<std::vector<char>> all = comm.gatherBytes(rankStatsBytes(mine), 0);
  if (stats) {
    stats->tilesPerAxis = tilesPerAxis;
    stats->photonHalo = halo;
    stats->attempts = attempts;
    stats->binMarginVoxels = double(binMargin) / double(frame.voxelSize);
    stats->tileOwner = plan.owner;
    stats->tileWork = plan.work;
    stats->ranks.clear();
    if (me == 0) {
      for (const std::vector<char>& bytes : all) {
        LO_CHECK_EQ(bytes.size(), sizeof(RankStats));
        RankStats s;
        std::memcpy(&s, bytes.data(), sizeof s);
        stats->ranks.push_back(s);
      }
    } else {
      stats->ranks.push_back(mine);
    }
  }
  return result;
}

}  // namespace lo
