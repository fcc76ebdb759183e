/// @file photon/photon_batches.cpp
/// @brief How a photon map grows batch by batch and ends: the batch sizes
/// (and the early stop when the lights reach almost nothing), the paths and
/// photons per light, the scaling by the paths traced, the free-space rays
/// kept of whole paths.

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include "core/resources.h"
#include "photon/photon_map.h"

namespace lo {
namespace {

constexpr size_t kMinBatchPaths = 4096;
constexpr size_t kMaxBatchPaths = size_t(1) << 19;

}  // namespace

size_t photonBatchPaths(size_t target, size_t stored, size_t emitted, size_t maxEmitted) {
  if (emitted >= maxEmitted) return 0;
  if (emitted == 0) return std::min(maxEmitted, std::clamp(target, kMinBatchPaths, size_t(65536)));
  // Lights that reach (almost) nothing: the rate so far would store under
  // 1% of the target by the last path a map may trace.
  if (emitted >= kReachProbePaths &&
      double(stored) * double(maxEmitted) < 0.01 * double(target) * double(emitted)) {
    return 0;
  }
  // Sooner where the paths so far already say so beyond doubt: even a rate
  // at the top of its Poisson bound (stored + 3 + 3 sqrt(stored) photons,
  // ~99.7%) would store under a quarter of that 1% by the last path, or by
  // the default budget's (kPathsPerPhoton per photon of the target) when
  // that comes first: a target bake's pass may trace up to the whole bake's
  // paths for its pilot's few photons. Paths that cost much (3,000 coplanar
  // floors under a sun, every ray through each: H16-5-1) ended after 100,000
  // paths, not 1.5 million.
  const double horizon = std::min(double(maxEmitted), double(kPathsPerPhoton) * double(target));
  const double bound = double(stored) + 3.0 + 3.0 * std::sqrt(double(stored));
  if (emitted >= 4 * kMinBatchPaths &&
      bound * horizon < 0.0025 * double(target) * double(emitted)) {
    return 0;
  }
  // The paths the photons-per-path ratio so far says are still needed, plus
  // a margin. Only the amount of wasted work depends on it.
  double need = stored > 0 ? double(target - stored) * double(emitted) / double(stored) * 1.03 + 1024
                           : 4.0 * double(emitted);
  need = std::clamp(need, double(kMinBatchPaths), double(kMaxBatchPaths));
  return std::min(maxEmitted - emitted, size_t(need));
}

void LightReach::add(uint32_t light, uint32_t stored) {
  if (light >= paths.size()) {
    paths.resize(light + 1, 0);
    photons.resize(light + 1, 0);
  }
  ++paths[light];
  photons[light] += stored;
}

std::vector<uint32_t> LightReach::darkLights(size_t minPaths) const {
  std::vector<uint32_t> out;
  for (size_t k = 0; k < paths.size(); ++k) {
    if (paths[k] >= minPaths && photons[k] == 0) out.push_back(uint32_t(k));
  }
  return out;
}

std::vector<std::string> LightReach::dark(const std::vector<std::string>& names,
                                          size_t minPaths) const {
  std::vector<std::string> out;
  for (uint32_t k : darkLights(minPaths)) {
    if (k < names.size()) out.push_back(names[k] + ", " + formatCount(paths[k]) + " paths");
  }
  return out;
}

size_t maxEmittedPaths(const PhotonParams& params) {
  return params.maxEmitted ? params.maxEmitted : kPathsPerPhoton * params.storedPhotons;
}

void scalePhotonPower(std::vector<Photon>& photons, size_t emittedPaths) {
  const float invPaths = emittedPaths > 0 ? float(1.0 / double(emittedPaths)) : 0.0f;
  for (Photon& ph : photons) ph.power *= invPaths;
}

bool SegmentCollector::addPath(const PhotonSegment* segments, uint32_t count) {
  if (full_) return false;
  if (segments_.size() + count > cap_) {
    full_ = true;
    return false;
  }
  segments_.insert(segments_.end(), segments, segments + count);
  ++paths_;
  return true;
}

std::vector<PhotonSegment> SegmentCollector::take() {
  const float invPaths = paths_ > 0 ? float(1.0 / double(paths_)) : 0.0f;
  for (PhotonSegment& segment : segments_) segment.power *= invPaths;
  std::vector<PhotonSegment> out = std::move(segments_);
  segments_ = std::vector<PhotonSegment>();
  return out;
}

}  // namespace lo
