#pragma once
/// @file bake/progressive_bake.h
/// @brief Coarse-to-fine preview (paper §5.2): traces the photon map once,
/// then bakes octree levels firstDepth, firstDepth + 1, ..., targetDepth from
/// it in a background thread and hands each finished GpuOctree to the caller,
/// who polls from its frame loop (no GL here: the caller uploads on its own
/// GL thread). Levels are independent bakes of the same photons
/// (bake/bake.h, bakeLevel), not refinements of each other.

#include <chrono>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "octree/gpu_octree.h"
#include "octree/octree_level_source.h"
#include "photon/photon_map.h"
#include "scene/scene.h"

namespace lo {

struct ProgressiveParams {
  PhotonParams photons;    ///< photon tracing (stored photons, seed)
  int firstDepth = 4;      ///< first level shown (the paper's "rough visualisation")
  int targetDepth = 6;     ///< last level baked, >= firstDepth
  GatherParams gather;     ///< as `bake` (k = 300; radius 0 = kDefaultRadiusVoxels of each level)
  ClusterParams cluster;   ///< as `bake` (4 VDLs per voxel)
  GpuOctreeParams octree;  ///< texture limits of the context that will draw it
};

using SteadyTime = std::chrono::steady_clock::time_point;

/// One finished level.
struct ProgressiveLevel {
  int depth = 0;
  GpuOctree octree;
  LevelStats stats;          ///< voxelize / splat / gather + cluster times and counts
  double octreeSeconds = 0;  ///< buildGpuOctree wall time
  SteadyTime photonsTraced;  ///< when the photon map was ready (same for every level)
  SteadyTime ready;          ///< when this level's octree was ready
  /// Seconds from the photon map being ready to this level's octree.
  double secondsAfterPhotons() const {
    return std::chrono::duration<double>(ready - photonsTraced).count();
  }
};

/// What the background thread is doing, for a window title.
struct ProgressiveStatus {
  enum class Phase { Tracing, Baking, Done, Failed, Cancelled };
  Phase phase = Phase::Tracing;
  int depth = 0;       ///< level being baked (Baking)
  std::string task;    ///< current stage ("Tracing photons", "voxelize", ...)
  float fraction = 0;  ///< of the current stage, 0..1
  std::string error;   ///< Failed: the exception's message
  std::string ToString() const;
};

class ProgressiveBake {
 public:
  /// Starts the background thread, which first traces the photons.
  /// `scene` must outlive this object. @throws InputError (before starting)
  /// when the depths are outside [1, kMaxGridDepth] or firstDepth > targetDepth.
  ProgressiveBake(const Scene& scene, const ProgressiveParams& params);
  /// Starts from photons already traced (benchmarks, tests); `params.photons`
  /// is not used and photonsTraced is the moment of this call.
  ProgressiveBake(const Scene& scene, PhotonMap photons, const ProgressiveParams& params);
  /// Cancels (the bake stops at its next progress report) and joins.
  ~ProgressiveBake();
  ProgressiveBake(const ProgressiveBake&) = delete;
  ProgressiveBake& operator=(const ProgressiveBake&) = delete;

  /// The newest level finished since the last call (older unclaimed ones are
  /// dropped: the caller only ever wants the finest), else nothing. Never
  /// blocks on the bake. @throws the bake's exception (InputError for a level
  /// too large for the texture limits, ...) once, when the thread failed.
  std::optional<ProgressiveLevel> takeNewest();
  ProgressiveStatus status() const;
  /// True once every level is finished (or the bake failed or was cancelled).
  bool finished() const;
  /// Blocks until the thread ends.
  void wait();
  /// Asks the thread to stop at its next progress report; does not block.
  void cancel();

  /// Timing of every finished level so far, in order (octrees not included).
  struct LevelTiming {
    int depth = 0;
    LevelStats stats;
    double octreeSeconds = 0;
    double secondsAfterPhotons = 0;
  };
  std::vector<LevelTiming> timings() const;
  /// Photon map figures, once traced (zeroes before).
  size_t storedPhotons() const;
  double traceSeconds() const;  ///< 0 when the photons were given

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// `bake`'s levels as a viewer's OctreeLevelSource (octree/octree_level_source.h; the viewer draws them): each
/// level taken is reported with its timings once on screen, the one at
/// `targetDepth` marked as the target. `bake` must outlive the source.
std::unique_ptr<OctreeLevelSource> progressiveLevelSource(ProgressiveBake& bake, int targetDepth);

}  // namespace lo
