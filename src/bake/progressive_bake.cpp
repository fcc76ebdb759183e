// ProgressiveBake: photons once, then octree levels coarse to fine in a thread.

#include "bake/progressive_bake.h"

#include <atomic>
#include <cstdio>
#include <exception>
#include <mutex>
#include <sstream>
#include <thread>

#include "core/error.h"
#include "core/resources.h"

namespace lo {
namespace {

/// Thrown from the progress sink to abandon the bake (caught in the thread).
struct Cancelled {};

}  // namespace

std::string ProgressiveStatus::ToString() const {
  std::ostringstream os;
  switch (phase) {
    case Phase::Tracing:
      os << "tracing photons " << int(fraction * 100.0f) << "%";
      break;
    case Phase::Baking:
      os << "baking depth " << depth << ": " << task << " " << int(fraction * 100.0f) << "%";
      break;
    case Phase::Done:
      os << "done";
      break;
    case Phase::Failed:
      os << "failed: " << error;
      break;
    case Phase::Cancelled:
      os << "cancelled";
      break;
  }
  return os.str();
}

/// The thread's state. It is also the progress sink of every stage, which is
/// how a cancel request reaches code that has no cancel flag of its own: the
/// next progress report throws Cancelled. Reports with done == total are never
/// thrown from, because Progress's destructor sends one (a throw there would
/// terminate), and by then the stage is finished anyway.
struct ProgressiveBake::Impl final : ProgressSink {
  const Scene& scene;
  ProgressiveParams params;
  PhotonMap photons;
  bool tracePhotonsFirst = true;

  mutable std::mutex mutex;  // guards everything below it
  ProgressiveStatus status;
  std::optional<ProgressiveLevel> newest;
  std::vector<LevelTiming> timings;
  std::exception_ptr error;
  bool errorReported = false;
  bool finished = false;
  size_t storedPhotons = 0;
  double traceSeconds = 0;

  std::atomic<bool> stop{false};
  std::atomic<bool> cancelThrown{false};
  std::thread thread;

  Impl(const Scene& s, const ProgressiveParams& p) : scene(s), params(p) {}

  void checkStop() {
    if (stop.load(std::memory_order_relaxed) && !cancelThrown.exchange(true)) throw Cancelled{};
  }
  void begin(const std::string& task, size_t) override {
    {
      std::lock_guard<std::mutex> lock(mutex);
      status.task = task;
      status.fraction = 0;
    }
    checkStop();
  }
  void update(size_t done, size_t total) override {
    {
      std::lock_guard<std::mutex> lock(mutex);
      status.fraction = total ? float(double(done) / double(total)) : 1.0f;
    }
    if (done < total) checkStop();
  }
  void end() override {}

  void run() {
    try {
      if (tracePhotonsFirst) {
        Stopwatch clock;
        photons = tracePhotons(scene, params.photons, this);
        std::lock_guard<std::mutex> lock(mutex);
        traceSeconds = clock.seconds();
      }
      SteadyTime traced = std::chrono::steady_clock::now();
      {
        std::lock_guard<std::mutex> lock(mutex);
        storedPhotons = photons.photons.size();
      }
      for (int depth = params.firstDepth; depth <= params.targetDepth; ++depth) {
        {
          std::lock_guard<std::mutex> lock(mutex);
          status.phase = ProgressiveStatus::Phase::Baking;
          status.depth = depth;
          status.task.clear();
          status.fraction = 0;
        }
        if (stop) throw Cancelled{};
        LevelParams levelParams;
        levelParams.grid.depth = depth;
        levelParams.gather = params.gather;
        levelParams.cluster = params.cluster;
        ProgressiveLevel level;
        level.depth = depth;
        VdlGrid vdls = bakeLevel(scene, photons.photons, levelParams, this, &level.stats);
        Stopwatch clock;
        level.octree = buildGpuOctree(vdls, params.octree);
        level.octreeSeconds = clock.seconds();
        level.photonsTraced = traced;
        level.ready = std::chrono::steady_clock::now();
        std::lock_guard<std::mutex> lock(mutex);
        timings.push_back({depth, level.stats, level.octreeSeconds, level.secondsAfterPhotons()});
        newest = std::move(level);
      }
      std::lock_guard<std::mutex> lock(mutex);
      status.phase = ProgressiveStatus::Phase::Done;
      finished = true;
    } catch (const Cancelled&) {
      std::lock_guard<std::mutex> lock(mutex);
      status.phase = ProgressiveStatus::Phase::Cancelled;
      finished = true;
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex);
      status.phase = ProgressiveStatus::Phase::Failed;
      status.error = e.what();
      error = std::current_exception();
      finished = true;
    } catch (...) {
      std::lock_guard<std::mutex> lock(mutex);
      status.phase = ProgressiveStatus::Phase::Failed;
      status.error = "unknown exception";
      error = std::current_exception();
      finished = true;
    }
  }
};

namespace {

void checkDepths(const ProgressiveParams& params) {
  for (int d : {params.firstDepth, params.targetDepth}) checkDepth(d, "progressive bake: depth");
  if (params.firstDepth > params.targetDepth) {
    throw InputError("progressive bake: first depth " + std::to_string(params.firstDepth) +
                     " is finer than the target depth " + std::to_string(params.targetDepth));
  }
}

/// The photons to trace and the finest level's voxels against the memory,
/// before any is traced, as bake checks them (checkBakeMemory): 2e8 photons
/// traced for a minute, growing, until an allocation failed.
void checkMemory(const Scene& scene, const ProgressiveParams& params) {
  BakeParams bake;
  bake.depth = params.targetDepth;
  bake.photons = params.photons.storedPhotons;
  checkBakeMemory(scene, bake);
}

}  // namespace

ProgressiveBake::ProgressiveBake(const Scene& scene, const ProgressiveParams& params)
    : impl_(std::make_unique<Impl>(scene, params)) {
  checkDepths(params);
  checkMemory(scene, params);
  impl_->thread = std::thread([this] { impl_->run(); });
}

ProgressiveBake::ProgressiveBake(const Scene& scene, PhotonMap photons,
                                 const ProgressiveParams& params)
    : impl_(std::make_unique<Impl>(scene, params)) {
  checkDepths(params);
  impl_->photons = std::move(photons);
  impl_->tracePhotonsFirst = false;
  impl_->status.phase = ProgressiveStatus::Phase::Baking;
  impl_->status.depth = params.firstDepth;
  impl_->thread = std::thread([this] { impl_->run(); });
}

ProgressiveBake::~ProgressiveBake() {
  cancel();
  wait();
}

std::optional<ProgressiveLevel> ProgressiveBake::takeNewest() {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  if (impl_->newest) {
    std::optional<ProgressiveLevel> level = std::move(impl_->newest);
    impl_->newest.reset();
    return level;
  }
  if (impl_->error && !impl_->errorReported) {
    impl_->errorReported = true;
    std::rethrow_exception(impl_->error);
  }
  return std::nullopt;
}

ProgressiveStatus ProgressiveBake::status() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->status;
}

bool ProgressiveBake::finished() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->finished;
}

void ProgressiveBake::wait() {
  if (impl_->thread.joinable()) impl_->thread.join();
}

void ProgressiveBake::cancel() { impl_->stop = true; }

std::vector<ProgressiveBake::LevelTiming> ProgressiveBake::timings() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->timings;
}

size_t ProgressiveBake::storedPhotons() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->storedPhotons;
}

double ProgressiveBake::traceSeconds() const {
  std::lock_guard<std::mutex> lock(impl_->mutex);
  return impl_->traceSeconds;
}

namespace {

/// ProgressiveBake as an OctreeLevelSource.
class ProgressiveLevels final : public OctreeLevelSource {
 public:
  ProgressiveLevels(ProgressiveBake& bake, int targetDepth)
      : bake_(bake), targetDepth_(targetDepth) {}
  bool takeNewest(GpuOctree& octree, int& depth) override {
    std::optional<ProgressiveLevel> level = bake_.takeNewest();
    if (!level) return false;
    octree = std::move(level->octree);
    depth = level->depth;
    level->octree = GpuOctree();
    last_ = std::move(level);
    return true;
  }
  std::string shownReport() const override {
    if (!last_) return {};
    const ProgressiveLevel& l = *last_;
    const double onScreen =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - l.photonsTraced).count();
    char line[512];
    std::snprintf(line, sizeof line,
                  "depth %d on screen %.2f s after the photons were traced (bake %.2f s: voxelize "
                  "%.2f, splat %.2f, gather + cluster %.2f; octree %.3f s; %zu voxels)%s",
                  l.depth, onScreen, l.stats.seconds(), l.stats.voxelizeSeconds,
                  l.stats.splatSeconds, l.stats.gatherClusterSeconds, l.octreeSeconds,
                  l.stats.activeVoxels, l.depth == targetDepth_ ? " (target)" : "");
    return line;
  }
  bool finished() const override { return bake_.finished(); }
  std::string status() const override { return bake_.status().ToString(); }

 private:
  ProgressiveBake& bake_;
  std::optional<ProgressiveLevel> last_;
  int targetDepth_;
};

}  // namespace

std::unique_ptr<OctreeLevelSource> progressiveLevelSource(ProgressiveBake& bake, int targetDepth) {
  return std::make_unique<ProgressiveLevels>(bake, targetDepth);
}

}  // namespace lo
