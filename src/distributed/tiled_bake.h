#pragma once
/// @file distributed/tiled_bake.h
/// @brief The bake on several processes (docs/scale.md): the same .vdb
/// bytes as bake() (src/bake) with the same parameters, whatever the number
/// of ranks, while each rank holds only its share of the photons and voxels.
///
///  1. Photons by rank: each batch of the global path index space is split
///     into one contiguous range per rank (PhotonTracer), so the photon set
///     does not depend on the rank count; the counts per rank say where the
///     map's last photon is.
///  2. Tiles: the grid is cut into tiles of (2^depth / tilesPerAxis)^3
///     voxels, given to the ranks in contiguous runs along a Z-order curve,
///     balanced by estimated memory (the first batch's photons per tile, and
///     the voxels its geometry crosses). Each batch's photons are sent
///     (alltoallv) to the owner of their tile and to every rank whose tiles
///     lie within the halo: the gather's reach, the smoothing's neighbours
///     and the photon splat's one-voxel move (photonHaloVoxels).
///  3. Each rank voxelizes its tiles and their halo, splats its photons and
///     gathers + clusters its own voxels and the ring of neighbours the
///     smoothing reads, with the single-process stages unchanged; the bins'
///     margin is the global maximum.
///  4. The owned voxels go to rank 0, which merges them in canonical order.

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "distributed/communicator.h"

namespace lo {

/// Most tiles per axis: the tile tables are dense (64^3 entries at most).
constexpr int kMaxTilesPerAxis = 64;

struct TileParams {
  /// Tiles per axis of the grid: a power of two from 1 to
  /// maxTilesPerAxis(depth); 0 = auto (autoTilesPerAxis).
  int tilesPerAxis = 0;
  /// A given owner rank per tile (TilePlan::owner's layout) instead of the
  /// split by work: a boundary placed where a test wants it. Empty = by work.
  std::vector<int32_t> owner;
  /// The bins' margin (SurfaceGrid::binMargin, voxel sizes) the photon halo
  /// first assumes: a photon lies on a surface, so splatting moves it off
  /// its voxel only by the rounding of its hit point. When the bake finds a
  /// larger one, it starts again with the bound kMaxBinMarginVoxels.
  double assumedMarginVoxels = 0.25;
};

/// min(kMaxTilesPerAxis, 2^depth / 8), at least 1: tiles of at least one
/// 8^3 block.
int maxTilesPerAxis(int depth);
/// min(32, maxTilesPerAxis(depth)): enough tiles to balance a few dozen ranks.
int autoTilesPerAxis(int depth);

/// Which rank owns which tile of a grid.
struct TilePlan {
  int depth = 0;      ///< the grid's (2^depth voxels per axis)
  int tileShift = 0;  ///< tile edge = 2^tileShift voxels
  int tilesPerAxis = 1;
  int ranks = 1;
  int photonHalo = 0;          ///< voxels around a rank's tiles whose photons it receives
  std::vector<int32_t> owner;  ///< per tile, index (x * T + y) * T + z
  std::vector<double> work;    ///< estimated memory per tile, in stored photons' worth

  /// Index of tile (tx, ty, tz) in `owner` and `work`.
  size_t tileIndex(int tx, int ty, int tz) const {
    const size_t T = size_t(tilesPerAxis);
    return (size_t(tx) * T + size_t(ty)) * T + size_t(tz);
  }
  /// Tile of voxel c, clamped into the grid.
  size_t tileOf(const Coord& c) const;
  int ownerOf(const Coord& c) const { return owner[tileOf(c)]; }
  /// Calls f(tile index) for each tile meeting the voxels [lo, hi]
  /// (inclusive per axis, clamped into the grid).
  template <typename F>
  void forTilesIn(const Coord& lo, const Coord& hi, F&& f) const;
  /// Calls f(rank) once for each rank that owns a tile within `halo` voxels
  /// (per axis) of voxel c; none when c lies farther than that outside the grid.
  template <typename F>
  void forOwnersNear(const Coord& c, int halo, F&& f) const;
  std::string ToString() const;
};

/// The photon halo a gather with `gather` on `frame` needs: the bins it
/// reads (gatherReach grown by the bins' margin, `marginVoxels` voxel sizes,
/// as Gatherer counts voxels) around the voxels a rank computes (its own and
/// their neighbours, which the smoothing reads), and the neighbours a
/// splatted photon can move from. Voxels are voxelized one further out.
int photonHaloVoxels(const GatherParams& gather, const GridFrame& frame,
                     double marginVoxels = kMaxBinMarginVoxels);

/// The tiles of a grid (depth, tile count, edge), every one owned by rank 0:
/// tile lookups before the tiles are shared out. @throws InputError for a
/// bad tile count (`--tiles`).
TilePlan tileGrid(int depth, int tilesPerAxis);

/// Splits the tiles among `ranks`: along the Z-order curve of the tile grid,
/// rank r gets the tiles whose work midpoint lies in [r W / ranks,
/// (r + 1) W / ranks), W the total. Deterministic.
TilePlan planTiles(int depth, int tilesPerAxis, const std::vector<double>& work, int ranks,
                   int photonHalo);

/// Figures of one rank, for --stats-json and docs/scale.md.
struct RankStats {
  int32_t rank = 0;
  double traceSeconds = 0;     ///< tracing this rank's paths
  double exchangeSeconds = 0;  ///< sending and receiving photons (waits included)
  double voxelizeSeconds = 0, splatSeconds = 0, gatherClusterSeconds = 0;
  double mergeSeconds = 0;  ///< sending the voxels to rank 0 (and merging them there)
  double totalSeconds = 0;
  uint64_t bytesSent = 0, bytesReceived = 0;  ///< photons to and from other ranks
  uint64_t photonsTraced = 0;                 ///< of the map, traced here
  uint64_t photonsHeld = 0;                   ///< received: its tiles' and their halo's
  uint64_t tilesOwned = 0;
  double workShare = 0;  ///< of the estimated work, 0..1
  uint64_t voxelsOwned = 0, voxelsComputed = 0, voxelsHeld = 0;
  uint64_t peakRssBytes = 0;  ///< of this process (threads ranks share one)
};

struct DistributedStats {
  int tilesPerAxis = 0;
  int photonHalo = 0;
  /// 2 when the bins' margin was larger than first assumed and the bake ran
  /// again with the bound (photonHaloVoxels), else 1.
  int attempts = 1;
  double binMarginVoxels = 0;      ///< the bins' margin found, voxel sizes
  std::vector<int32_t> tileOwner;  ///< TilePlan::owner
  std::vector<double> tileWork;    ///< TilePlan::work
  std::vector<RankStats> ranks;    ///< rank 0: every rank's, in rank order; others: their own
};

/// @brief bake() on the ranks of `comm` (every rank calls it with the same
/// scene and parameters). Rank 0 returns the whole BakeResult (grid,
/// metadata, stats); the other ranks return an empty grid. The grid is the
/// one bake() returns, value for value. @throws InputError as bake() does,
/// and for BakeParams::keepPhotons (the map is spread over the ranks) or a
/// bad tile count. `outputs` names what rank 0 will write, as this rank was
/// told (the command's -o and side files): the ranks compare it with their
/// settings and scene (checkRanksAgree) before any work.
BakeResult distributedBake(const Scene& scene, const BakeParams& params, const TileParams& tiles,
                           Communicator& comm, ProgressSink* progress = nullptr,
                           DistributedStats* stats = nullptr, const std::string& outputs = {});

// ---------------------------------------------------------------------------

template <typename F>
void TilePlan::forTilesIn(const Coord& lo, const Coord& hi, F&& f) const {
  const int last = (1 << depth) - 1;
  const int a[3] = {std::max(0, lo.x) >> tileShift, std::max(0, lo.y) >> tileShift,
                    std::max(0, lo.z) >> tileShift};
  const int b[3] = {std::min(last, hi.x) >> tileShift, std::min(last, hi.y) >> tileShift,
                    std::min(last, hi.z) >> tileShift};
  for (int x = a[0]; x <= b[0]; ++x)
    for (int y = a[1]; y <= b[1]; ++y)
      for (int z = a[2]; z <= b[2]; ++z) f(tileIndex(x, y, z));
}

template <typename F>
void TilePlan::forOwnersNear(const Coord& c, int halo, F&& f) const {
  const int last = (1 << depth) - 1;
  for (int v : {c.x, c.y, c.z}) {
    if (v + halo < 0 || v - halo > last) return;
  }
  int seen[8];
  int nSeen = 0;
  std::vector<int> more;  // only for a halo wider than a tile
  forTilesIn({c.x - halo, c.y - halo, c.z - halo}, {c.x + halo, c.y + halo, c.z + halo},
             [&](size_t t) {
               const int r = owner[t];
               for (int i = 0; i < nSeen; ++i) {
                 if (seen[i] == r) return;
               }
               for (int m : more) {
                 if (m == r) return;
               }
               if (nSeen < 8) {
                 seen[nSeen++] = r;
               } else {
                 more.push_back(r);
               }
               f(r);
             });
}

}  // namespace lo
