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

#include "cluster/volume_light.h"
#include "core/error.h"
#include "core/resources.h"
#include "distributed/rank_agreement.h"
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
std::vector<double> estimateWork(const Scene& scene, const GridParams& grid, const GridFrame& frame,
                                 const TilePlan& tiles, const std::vector<uint64_t>& pilot,
                                 double photonScale) {
  std::vector<double> work(pilot.size(), 0.0);
  for (size_t t = 0; t < pilot.size(); ++t) work[t] = double(pilot[t]) * photonScale;
  if (tiles.tilesPerAxis > 1 && scene.triangleCount() > 0) {
    GridParams coarse = grid;
    coarse.depth = log2Exact(tiles.tilesPerAxis);
    coarse.keepBlock = nullptr;
    const SurfaceGrid areas = buildSurfaceGrid(scene, coarse);
    const double voxelArea = double(frame.voxelSize) * double(frame.voxelSize);
    for (size_t i = 0; i < areas.size(); ++i) {
      const Coord& c = areas.coords[i];
      const size_t t = tiles.tileIndex(c.x, c.y, c.z);
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
  /// Whether any tile of this rank lies within `halo` voxels of the block.
  bool keepBlock(const Coord& b) const {
    bool owned = false;
    plan->forTilesIn({b.x * 8 - halo, b.y * 8 - halo, b.z * 8 - halo},
                     {b.x * 8 + 7 + halo, b.y * 8 + 7 + halo, b.z * 8 + 7 + halo},
                     [&](size_t t) { owned = owned || plan->owner[t] == rank; });
    return owned;
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
  return tileIndex(int(x), int(y), int(z));
}

TilePlan tileGrid(int depth, int tilesPerAxis) {
  using namespace distributed_internal;
  checkTilesPerAxis(tilesPerAxis, depth);
  TilePlan plan;
  plan.depth = depth;
  plan.tilesPerAxis = tilesPerAxis;
  plan.tileShift = depth - log2Exact(tilesPerAxis);
  const size_t T = size_t(tilesPerAxis);
  plan.owner.assign(T * T * T, 0);
  plan.work.assign(T * T * T, 0.0);
  return plan;
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
  if (ranks < 1) throw InputError("ranks " + std::to_string(ranks) + " must be at least 1");
  TilePlan plan = tileGrid(depth, tilesPerAxis);
  plan.ranks = ranks;
  plan.photonHalo = photonHalo;
  LO_CHECK_EQ(work.size(), plan.owner.size());
  plan.work = work;
  std::vector<std::pair<uint32_t, size_t>> curve;
  curve.reserve(work.size());
  for (int x = 0; x < tilesPerAxis; ++x)
    for (int y = 0; y < tilesPerAxis; ++y)
      for (int z = 0; z < tilesPerAxis; ++z) {
        curve.emplace_back(mortonCode(uint32_t(x), uint32_t(y), uint32_t(z)),
                           plan.tileIndex(x, y, z));
      }
  std::sort(curve.begin(), curve.end());
  double total = 0;
  for (double w : work) total += std::max(0.0, w);
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

namespace distributed_internal {

/// One rank's distributed bake: the steps of tiled_bake.h as methods over
/// the state they hand on (the photons held, the tile plan, the local grid).
class RankBake {
 public:
  RankBake(const Scene& scene, const BakeParams& params, const TileParams& tiles,
           Communicator& comm, ProgressSink* progress)
      : scene_(scene),
        params_(params),
        tiles_(tiles),
        comm_(comm),
        progress_(progress),
        ranks_(comm.size()),
        me_(comm.rank()),
        level_(params.levelParams()),
        frame_(makeGridFrame(params.region.empty() ? scene.bounds() : params.region, params.depth,
                             level_.grid.padding)),
        tilesPerAxis_(tiles.tilesPerAxis != 0 ? tiles.tilesPerAxis
                                              : autoTilesPerAxis(params.depth)) {
    checkTilesPerAxis(tilesPerAxis_, params.depth);
  }

  BakeResult run(DistributedStats* stats) {
    Stopwatch total;
    // The halo first assumes a small bins' margin; a larger one found by
    // the splat starts the photon steps again with the bound (all ranks
    // see the same reduced margin, so all start again together).
    for (const double margin :
         {std::min(tiles_.assumedMarginVoxels, kMaxBinMarginVoxels), kMaxBinMarginVoxels}) {
      ++attempts_;
      halo_ = photonHaloVoxels(level_.gather, frame_, margin);
      st_ = BakeStats{};
      st_.triangles = scene_.triangleCount();
      st_.denseVoxels = size_t(1) << (3 * params_.depth);
      mine_ = RankStats{};
      mine_.rank = me_;
      traceAndExchange();
      voxelizeRegion();
      if (splat(margin)) break;
    }
    // The bound always holds: the second attempt never starts a third.
    LO_CHECK_LE(double(grid_.binMargin), kMaxBinMarginVoxels * double(frame_.voxelSize));
    binMargin_ = grid_.binMargin;
    gatherAndCluster();
    mergeOnRankZero();

    st_.level.radius = resolveRadius(level_.gather, frame_);
    st_.level.voxelizeSeconds = mine_.voxelizeSeconds;
    st_.level.splatSeconds = mine_.splatSeconds;
    st_.level.gatherClusterSeconds = mine_.gatherClusterSeconds;
    BakeResult result;
    result.grid = std::move(merged_);
    if (me_ == 0 && params_.freeSpace) {
      result.grid.volume =
          bakeFreeSpaceLight(collector_.take(), result.grid.frame, params_, progress_, st_.stages);
    }
    result.metadata =
        bakeMetadata(scene_, params_, int64_t(stored_), int64_t(emitted_), st_.level.radius);
    if (me_ == 0) {
      const VdlLayers& L = result.grid.layers;
      for (size_t e = 0; e < L.size(); ++e) {
        if (e == 0 || L.voxel[e] != L.voxel[e - 1]) ++st_.level.layeredVoxels;
      }
      st_.level.extraLayers = L.size();
    }
    result.stats = std::move(st_);
    mine_.totalSeconds = total.seconds();
    mine_.peakRssBytes = peakRssBytes();
    report(stats);
    return result;
  }

 private:
  /// 1. Photons by rank, sent batch by batch to the tiles that hold them.
  void traceAndExchange() {
    StageTimer timer(st_.stages, "trace + exchange");
    const PhotonParams photonParams = params_.photonParams();
    PhotonTracer tracer(scene_, photonParams);
    const size_t target = photonParams.storedPhotons;
    const size_t maxEmitted = maxEmittedPaths(photonParams);
    std::vector<Photon>().swap(held_);
    stored_ = emitted_ = empty_ = unsent_ = 0;
    bool planned = false;
    std::vector<Photon> batch;
    std::vector<uint32_t> pathPhotons;
    std::vector<PhotonSegment> segments;
    std::vector<uint32_t> pathSegments;
    collector_ = SegmentCollector(photonParams.maxSegments);
    bool segmentsFull = false;
    Progress bar(progress_, "Tracing photons", target);
    while (target > 0 && tracer.canStore() && stored_ < target) {
      const size_t paths = photonBatchPaths(target, size_t(stored_), size_t(emitted_), maxEmitted);
      if (paths == 0) break;
      // This rank's contiguous share of the batch's paths.
      const uint64_t first = emitted_ + uint64_t(paths) * uint64_t(me_) / uint64_t(ranks_);
      const uint64_t last = emitted_ + uint64_t(paths) * uint64_t(me_ + 1) / uint64_t(ranks_);
      batch.clear();
      pathPhotons.clear();
      segments.clear();
      pathSegments.clear();
      Stopwatch traceClock;
      tracer.trace(
          first, size_t(last - first),
          [&](const Photon* path, uint32_t n, uint32_t, bool, uint32_t) {
            if (n > 0) batch.insert(batch.end(), path, path + n);
            pathPhotons.push_back(n);
            return true;
          },
          params_.freeSpace && !segmentsFull
              ? PhotonTracer::SegmentSink([&](const PhotonSegment* p, uint32_t n) {
            segments.insert(segments.end(), p, p + n);
            pathSegments.push_back(n);
          })
                            : PhotonTracer::SegmentSink());
      mine_.traceSeconds += traceClock.seconds();

      // Where the map's last photon lies: the ranks before hold `before`.
      Stopwatch exchangeClock;
      const std::vector<uint64_t> counts = comm_.allgather(batch.size());
      uint64_t before = stored_;
      for (int r = 0; r < me_; ++r) before += counts[size_t(r)];
      uint64_t kept[3] = {0, 0, 0};  // paths, of them empty, photons
      for (size_t i = 0; i < pathPhotons.size() && before + kept[2] < target; ++i) {
        kept[2] += std::min<uint64_t>(pathPhotons[i], target - before - kept[2]);
        ++kept[0];
        kept[1] += pathPhotons[i] == 0;
      }
      batch.resize(size_t(kept[2]));
      if (params_.freeSpace && !segmentsFull) {
        // The kept paths' segments and their counts per path, to rank 0 in
        // rank (= path) order: the free-space light is made there from the
        // same whole paths as one process makes it from (the same bytes).
        const size_t paths = std::min<size_t>(size_t(kept[0]), pathSegments.size());
        size_t keep = 0;
        for (size_t i = 0; i < paths; ++i) keep += pathSegments[i];
        segments.resize(keep);
        pathSegments.resize(paths);
        const auto bytesOf = [](const auto& v) {
          const char* b = reinterpret_cast<const char*>(v.data());
          return std::vector<char>(b, b + v.size() * sizeof(v[0]));
        };
        const std::vector<std::vector<char>> parts = comm_.gatherBytes(bytesOf(segments), 0);
        const std::vector<std::vector<char>> counts = comm_.gatherBytes(bytesOf(pathSegments), 0);
        uint64_t full = 0;
        if (me_ == 0) {
          for (size_t r = 0; r < parts.size(); ++r) {
            std::vector<PhotonSegment> part(parts[r].size() / sizeof(PhotonSegment));
            std::vector<uint32_t> perPath(counts[r].size() / sizeof(uint32_t));
            if (!part.empty()) std::memcpy(static_cast<void*>(part.data()), parts[r].data(), parts[r].size());
            if (!perPath.empty()) std::memcpy(perPath.data(), counts[r].data(), counts[r].size());
            const PhotonSegment* next = part.data();
            for (uint32_t n : perPath) {
              if (!collector_.addPath(next, n)) break;
              next += n;
            }
          }
          full = collector_.full() ? 1 : 0;
        }
        // Every rank stops sending once rank 0 holds what it takes.
        comm_.allreduceSum(&full, 1);
        segmentsFull = full > 0;
      }
      mine_.photonsTraced += kept[2];
      comm_.allreduceSum(kept, 3);
      emitted_ += kept[0];
      empty_ += kept[1];
      stored_ += kept[2];
      const bool firstBatch = !planned;
      if (firstBatch) {
        makePlan(batch, kept[2]);
        planned = true;
      }
      const ExchangeResult ex = exchangePhotons(comm_, plan_, frame_, batch, held_);
      if (firstBatch && kept[2] > 0 && stored_ < target) {
        // This rank's share of the map, from the first batch's: reserved
        // once, not grown by doubling (which would hold up to twice it).
        const double share = double(held_.size()) / double(kept[2]);
        held_.reserve(size_t(share * double(target) * 1.02) + 4096);
      }
      mine_.bytesSent += ex.sent;
      mine_.bytesReceived += ex.received;
      unsent_ += ex.unsent;
      mine_.exchangeSeconds += exchangeClock.seconds();
      bar.advance(size_t(kept[2]));
    }
    if (!planned) makePlan({}, 0);
    // The tests' stand-in for a machine lost mid-bake (docs/scale.md): this
    // rank dies as a killed process does, between the exchange and the gather.
    if (testHook("LIGHTOCTREE_KILL_RANK") == std::to_string(me_)) std::raise(SIGKILL);
    scalePhotonPower(held_, size_t(emitted_));
    st_.storedPhotons = size_t(stored_);
    st_.emittedPaths = size_t(emitted_);
    st_.emptyPaths = size_t(empty_);
    checkPhotonsStored(params_, st_);
    mine_.photonsHeld = held_.size();
    double all = 0, own = 0;
    for (size_t t = 0; t < plan_.owner.size(); ++t) {
      all += plan_.work[t];
      if (plan_.owner[t] != me_) continue;
      own += plan_.work[t];
      if (plan_.work[t] > 0) ++mine_.tilesOwned;
    }
    mine_.workShare = all > 0 ? own / all : 0.0;
    st_.traceSeconds = timer.finish(formatCount(size_t(stored_)) + " photons from " +
                                    formatCount(size_t(emitted_)) + " paths on " +
                                    std::to_string(ranks_) + " ranks");
  }

  /// The tile plan from the first batch's photons (`pilot`, this rank's part
  /// of `pilotStored`): every rank computes the same one.
  void makePlan(const std::vector<Photon>& pilot, uint64_t pilotStored) {
    const TilePlan tiles = tileGrid(params_.depth, tilesPerAxis_);
    std::vector<uint64_t> counts(tiles.owner.size(), 0);
    for (const Photon& p : pilot) ++counts[tiles.tileOf(frame_.coordOf(p.position))];
    comm_.allreduceSum(counts.data(), counts.size());
    const double scale = pilotStored > 0 ? double(params_.photons) / double(pilotStored) : 0.0;
    plan_ =
        planTiles(params_.depth, tilesPerAxis_,
                  estimateWork(scene_, level_.grid, frame_, tiles, counts, scale), ranks_, halo_);
    if (tiles_.owner.empty()) return;
    if (tiles_.owner.size() != plan_.owner.size()) {
      throw InputError("a tile owner table of " + std::to_string(tiles_.owner.size()) +
                       " entries for " + std::to_string(plan_.owner.size()) + " tiles");
    }
    for (int32_t r : tiles_.owner) {
      if (r < 0 || r >= ranks_) {
        throw InputError("tile owner " + std::to_string(r) + " is not one of the " +
                         std::to_string(ranks_) + " ranks");
      }
    }
    plan_.owner = tiles_.owner;
  }

  /// 2. This rank's tiles and one voxel beyond the photon halo, voxelized.
  void voxelizeRegion() {
    StageTimer timer(st_.stages, "voxelize");
    const LocalRegion region{&plan_, me_, halo_ + 1};
    GridParams gridParams = level_.grid;
    const int res = 1 << params_.depth, edge = 1 << plan_.tileShift;
    Coord lo{res, res, res}, hi{-1, -1, -1};
    const size_t T = size_t(tilesPerAxis_);
    for (size_t t = 0; t < plan_.owner.size(); ++t) {
      if (plan_.owner[t] != me_) continue;
      const int x = int(t / (T * T)), y = int(t / T % T), z = int(t % T);
      lo = {std::min(lo.x, x * edge), std::min(lo.y, y * edge), std::min(lo.z, z * edge)};
      hi = {std::max(hi.x, x * edge + edge - 1), std::max(hi.y, y * edge + edge - 1),
            std::max(hi.z, z * edge + edge - 1)};
    }
    gridParams.clipLower = {lo.x - region.halo, lo.y - region.halo, lo.z - region.halo};
    gridParams.clipUpper = {hi.x + region.halo, hi.y + region.halo, hi.z + region.halo};
    gridParams.keepBlock = [&region](const Coord& b) { return region.keepBlock(b); };
    grid_ = buildSurfaceGrid(scene_, gridParams, progress_);
    mine_.voxelsHeld = grid_.size();
    mine_.voxelizeSeconds =
        timer.finish(formatCount(grid_.size()) + " voxels held on rank " + std::to_string(me_));
  }

  /// This rank's photons into its grid's bins, with the global bins'
  /// margin. False when that margin exceeds `assumedMargin` voxels (the
  /// halo was too thin: every rank starts again).
  bool splat(double assumedMargin) {
    StageTimer timer(st_.stages, "splat photons");
    splatPhotons(grid_, held_);
    double margin = double(grid_.binMargin);
    comm_.allreduceMax(&margin, 1);
    grid_.binMargin = float(margin);  // a float already: the maximum of the ranks' floats
    if (double(grid_.binMargin) > assumedMargin * double(frame_.voxelSize)) return false;
    // Photons outside every active voxel's neighbourhood, each counted by the
    // owner of its tile (or by its tracer, when no rank holds it).
    uint64_t dropped = unsent_;
    std::vector<char> binned(held_.size(), 0);
    for (uint32_t i : grid_.binPhotons) binned[i] = 1;
    for (size_t i = 0; i < held_.size(); ++i) {
      if (!binned[i] && plan_.ownerOf(frame_.coordOf(held_[i].position)) == me_) ++dropped;
    }
    comm_.allreduceSum(&dropped, 1);
    st_.level.droppedPhotons = size_t(dropped);
    // In bin order, so that the gather reads them in place (gather.h). The
    // grid's voxels follow their canonical key on every rank, so photons keep
    // the relative order they have in a one-process bake: the same ties, the
    // same bytes.
    sortPhotonsByBin(grid_, held_);
    mine_.splatSeconds = timer.finish();
    return true;
  }

  /// 3. Gather + cluster this rank's voxels and the neighbours the smoothing
  /// reads; smooth.
  void gatherAndCluster() {
    StageTimer timer(st_.stages, "gather + cluster");
    std::vector<char> compute(grid_.size(), 0);
    for (size_t v = 0; v < grid_.size(); ++v) {
      if (plan_.ownerOf(grid_.coords[v]) != me_) continue;
      owned_.push_back(uint32_t(v));
      compute[v] = 1;
      if (!level_.smoothing) continue;
      const Coord c = grid_.coords[v];
      for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dz = -1; dz <= 1; ++dz) {
            const int64_t w = grid_.find({c.x + dx, c.y + dy, c.z + dz});
            if (w >= 0) compute[size_t(w)] = 1;
          }
    }
    std::vector<uint32_t> computed;
    for (size_t v = 0; v < grid_.size(); ++v) {
      if (compute[v]) computed.push_back(uint32_t(v));
    }
    mine_.voxelsOwned = owned_.size();
    mine_.voxelsComputed = computed.size();
    GatherParams gather = level_.gather;
    std::unique_ptr<GatherOcclusion> occlusion;
    if (level_.occlusion && scene_.triangleCount() > 0) {
      occlusion = std::make_unique<GatherOcclusion>(scene_);
      gather.blocked = occlusion->test();
      if (gather.edgeCorrection) gather.surfaceAt = occlusion->surfaceProbe();
    }
    const LayerParams layerParams;
    local_ = buildVdlGrid(grid_, held_, gather, level_.cluster, progress_, &st_.level.threadSeconds,
                          level_.layers ? &layerParams : nullptr, &computed);
    if (level_.smoothing) smoothVdlGrid(grid_, local_);
    std::vector<Photon>().swap(held_);
    grid_ = SurfaceGrid{};
    mine_.gatherClusterSeconds =
        timer.finish(formatCount(owned_.size()) + " voxels owned, " + formatCount(computed.size()) +
                     " computed on rank " + std::to_string(me_));
  }

  /// 4. The owned voxels, merged on rank 0.
  void mergeOnRankZero() {
    StageTimer timer(st_.stages, "merge on rank 0");
    std::vector<std::vector<char>> parts =
        comm_.gatherBytes(serializeVdlGrid(selectVoxels(local_, owned_)), 0);
    local_ = VdlGrid{};
    if (me_ == 0) {
      std::vector<VdlGrid> grids;
      for (std::vector<char>& bytes : parts) {
        grids.push_back(deserializeVdlGrid(bytes));
        std::vector<char>().swap(bytes);
      }
      merged_ = mergeVdlGrids(std::move(grids));
    }
    uint64_t active = mine_.voxelsOwned;
    comm_.allreduceSum(&active, 1);
    st_.level.activeVoxels = size_t(active);
    mine_.mergeSeconds = timer.finish();
  }

  /// Every rank's figures to rank 0 (every rank takes part, whether or not
  /// it asked for them).
  void report(DistributedStats* stats) const {
    const std::vector<std::vector<char>> all = comm_.gatherBytes(rankStatsBytes(mine_), 0);
    if (!stats) return;
    stats->tilesPerAxis = tilesPerAxis_;
    stats->photonHalo = halo_;
    stats->attempts = attempts_;
    stats->binMarginVoxels = double(binMargin_) / double(frame_.voxelSize);
    stats->tileOwner = plan_.owner;
    stats->tileWork = plan_.work;
    stats->ranks.clear();
    if (me_ != 0) {
      stats->ranks.push_back(mine_);
      return;
    }
    for (const std::vector<char>& bytes : all) {
      LO_CHECK_EQ(bytes.size(), sizeof(RankStats));
      RankStats s;
      std::memcpy(&s, bytes.data(), sizeof s);
      stats->ranks.push_back(s);
    }
  }

  const Scene& scene_;
  const BakeParams& params_;
  const TileParams& tiles_;
  Communicator& comm_;
  ProgressSink* progress_;
  const int ranks_, me_;
  const LevelParams level_;
  const GridFrame frame_;
  const int tilesPerAxis_;

  int halo_ = 0, attempts_ = 0;
  float binMargin_ = 0;
  BakeStats st_;
  RankStats mine_;
  TilePlan plan_;
  /// This rank's tiles' and halo's photons, in map order (bin order after the splat).
  std::vector<Photon> held_;
  /// Rank 0 with BakeParams::freeSpace: the kept paths' segments, in path
  /// order, as one process collects them.
  SegmentCollector collector_{0};
  uint64_t stored_ = 0, emitted_ = 0, empty_ = 0, unsent_ = 0;
  SurfaceGrid grid_;             ///< this rank's tiles and halo
  std::vector<uint32_t> owned_;  ///< grid_ indices of this rank's voxels
  VdlGrid local_;                ///< the computed voxels, in grid_ order
  VdlGrid merged_;               ///< rank 0: every rank's voxels
};

}  // namespace distributed_internal

BakeResult distributedBake(const Scene& scene, const BakeParams& requested, const TileParams& tiles,
                           Communicator& comm, ProgressSink* progress, DistributedStats* stats,
                           const std::string& outputs) {
  // First, so that a rank whose own settings would be refused below does not
  // refuse alone while the others wait for it.
  checkRanksAgree(scene, requested, tiles, comm, outputs);
  if (requested.targetError > 0) {
    throw InputError("--target-error: the distributed bake (mpirun) traces a fixed photon "
                     "budget; give --photons");
  }
  const BakeParams params = checkedBakeParams(scene, requested, comm.size());
  if (params.keepPhotons) {
    throw InputError(
        "--photon-map: a bake on several processes keeps no photon map (each holds a part of "
        "it); write it from a bake on one process");
  }
  return distributed_internal::RankBake(scene, params, tiles, comm, progress).run(stats);
}

}  // namespace lo
