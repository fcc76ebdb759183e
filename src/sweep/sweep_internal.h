#pragma once
/// @file sweep/sweep_internal.h
/// @brief What the sweep's files share, not its API: the harness
/// (sweep.cpp), the points and their fronts (sweep_points.cpp), the cache
/// of bakes, results and references (sweep_cache.cpp) and the report
/// (sweep_report.cpp).

#include <cstddef>
#include <string>
#include <vector>

#include "image/image.h"
#include "scene/pinhole_camera.h"
#include "sweep/sweep.h"

namespace lo {
namespace sweep_internal {

/// 600000 -> "600k", 2500000 -> "2.5M": the photon count in labels.
std::string photonsText(size_t n);

/// A fraction as a percentage rounded to 2 decimals.
double percent2(double fraction);

/// Bins of kSweepBin x kSweepBin pixels: the binned irradiance error, at
/// the scale of a few pixels without the reference's per-pixel noise.
constexpr int kSweepBin = 4;

struct References {
  RgbImage irradiance, indirect;
  /// reference --emitter-mask: the light fixtures' pixels are left out of
  /// every error (there the octree and the path tracer define irradiance
  /// differently).
  RgbImage emitterMask;
  /// The references' noise (referenceNoise) over the compared pixels,
  /// per pixel and over kSweepBin bins.
  double irradianceNoise = 0, indirectNoise = 0, irradianceBinnedNoise = 0;
  double seconds = 0;
};

/// The light octree's figures of one bake, as cached beside its .vdb.
struct BakeFigures {
  double traceSeconds = 0, voxelizeSeconds = 0, splatSeconds = 0, clusterSeconds = 0;
  double bakeSeconds = 0, peakRssBytes = 0, vdbBytes = 0, activeVoxels = 0, denseVoxels = 0;
  double storedPhotons = 0;
  double noiseFigure = -1;  ///< NoiseSummary::quantile; < 0: not recorded
};

/// The sweep's cache folder (SweepParams::outDir/cache): each bake's .vdb
/// and figures, each point's images and result, and the references, each
/// with the settings it was made under (the context: scene, image size,
/// samples, frames, threads, seed, version). An entry made under other
/// settings is stale: load* return false and the harness makes it again.
class SweepCache {
 public:
  SweepCache(const SweepParams& params, const std::string& dir);

  const std::string& dir() const { return dir_; }
  /// The .vdb of the point's bake (shared by points that differ only in the lookup).
  std::string vdbPath(const SweepPoint& point) const;
  /// The point's image `what` ("irradiance", "indirect") as EXR.
  std::string imagePath(const SweepPoint& point, const std::string& what) const;

  /// The references of `camera` (part of the key: a scene without a
  /// camera of its own is framed by a rule that may change).
  bool loadReferences(References& refs, const PinholeCamera& camera) const;
  void storeReferences(const References& refs, const PinholeCamera& camera) const;
  bool loadBake(const SweepPoint& point, BakeFigures& figures) const;
  void storeBake(const SweepPoint& point, const BakeFigures& figures) const;
  bool loadResult(const SweepPoint& point, SweepResult& result) const;
  void storeResult(const SweepResult& result) const;

 private:
  const SweepParams& params_;
  std::string dir_;
  std::string context_;  ///< the context as JSON text
};

/// Pictures of the paper's point and of the most accurate point on the time
/// front: reference | light octree | difference, as PNGs in params.outDir.
void writeSweepPictures(const SweepParams& params, const std::vector<SweepResult>& results,
                        const RgbImage& referenceIrradiance, const RgbImage& emitterMask,
                        const SweepCache& cache);

}  // namespace sweep_internal
}  // namespace lo
