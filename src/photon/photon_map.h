#pragma once
/// @file photon/photon_map.h
/// @brief Photon tracing with Embree (paper §4.1: the photon map the light
/// octree compresses). Embree is visible only inside src/photon.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "lightgrid/photon.h"
#include "scene/scene.h"

namespace lo {

/// PhotonParams::maxSegments by default: 2M rays, 72 MB.
constexpr size_t kDefaultMaxSegments = size_t(2) << 20;

struct PhotonParams {
  size_t storedPhotons = 600000;  ///< photons to store (exact count unless the scene stores none)
  int maxBounces = 16;            ///< path length cap (Russian roulette usually ends paths first)
  bool includeDirect = false;     ///< also store bounce-0 hits (the GL pipeline renders direct light)
  uint64_t seed = 1;
  /// Stop after this many emitted paths even if fewer photons were stored
  /// (a scene whose light never reaches a diffuse surface). 0 = 64 * storedPhotons.
  size_t maxEmitted = 0;
  /// Also keep the rays the stored light travels along (PhotonMap::segments):
  /// what the free-space light of the octree is estimated from.
  bool segments = false;
  /// At most this many of them: the whole paths from path 0 on until the
  /// next would pass it (SegmentCollector). A coarse grid needs far fewer
  /// rays than the surfaces need photons; 36 bytes each.
  size_t maxSegments = kDefaultMaxSegments;
  /// A region of interest (world space; empty = the whole scene): only
  /// photons inside it are stored, and directional lights emit over its
  /// footprint (a disc of its bounding sphere) instead of the whole scene's,
  /// starting outside the scene so that occluders beyond the region still cast.
  Bounds3 region;
  /// Hand each path's first hit, when it is direct light the map does not
  /// store, to PhotonTracer::trace's DirectSink: what a target bake weighs
  /// the indirect light's noise against (the light a viewer sees there).
  bool countDirect = false;
  /// Send emissive triangles' light preferably the ways that meet the scene
  /// (photon/emission_guide.h): the same expected light, far fewer paths for
  /// an emissive object in the open; off, every direction as often as the
  /// cosine says (what the guide is tested against).
  bool guideEmission = true;
};

struct PhotonMap {
  std::vector<Photon> photons;
  /// With PhotonParams::segments: the rays of the first paths whose light the
  /// photons hold (lightgrid/photon.h), in path order, up to
  /// PhotonParams::maxSegments, powers divided by the paths they came from.
  std::vector<PhotonSegment> segments;
  size_t emittedPaths = 0;      ///< paths traced to obtain `photons`
  size_t emptyPaths = 0;        ///< of those, paths that stored no photon
  /// Of those, paths whose first ray hit no surface (light aimed beside the
  /// scene); the others that stored nothing hit but stored no photon (direct
  /// light left to the renderer, then absorbed or gone into the open).
  size_t missedPaths = 0;
  Vec3 emittedPower{0, 0, 0};   ///< total RGB power of all lights, W
  size_t raysTraced = 0;        ///< for statistics
  /// The lights (PhotonTracer::lightNames) whose paths, at least
  /// kDarkLightPaths of them, stored no photon: they reach no surface that
  /// holds light (under a floor, aimed away, outside --bounds).
  std::vector<std::string> darkLights;
};

/// Paths a light must have started before a map calls it dark.
constexpr size_t kDarkLightPaths = 4096;

/// Paths and stored photons per light (PhotonTracer::lightNames).
struct LightReach {
  std::vector<size_t> paths, photons;
  void add(uint32_t light, uint32_t stored);
  /// The lights of at least `minPaths` paths and no photon.
  std::vector<uint32_t> darkLights(size_t minPaths = kDarkLightPaths) const;
  /// The names of the lights of at least `minPaths` paths and no photon,
  /// each with its path count.
  std::vector<std::string> dark(const std::vector<std::string>& names,
                                size_t minPaths = kDarkLightPaths) const;
};

/// Traces photons from punctual lights and emissive triangles (area lights),
/// chosen in proportion to their power, through diffuse, glossy and
/// specular/transmissive (Fresnel) surfaces with Russian roulette.
/// Deterministic for a given seed whatever the number of TBB threads.
/// @throws InputError if the scene has no light with positive power.
PhotonMap tracePhotons(const Scene& scene, const PhotonParams& params,
                       ProgressSink* progress = nullptr);

/// Traces any range of a bake's global path index space: path i draws its
/// random numbers from Rng(seed, i) alone, so a photon map can be traced in
/// parts (tracePhotons' batches, or the ranks of a distributed bake, each
/// tracing a disjoint range) and the photons do not depend on the split.
/// A photon map is the photons of paths 0, 1, 2, ... in path order, cut at
/// PhotonParams::storedPhotons, with powers divided by the paths that made
/// them (scalePhotonPower).
class PhotonTracer {
 public:
  /// @throws InputError as tracePhotons does (no light, bad indices).
  PhotonTracer(const Scene& scene, const PhotonParams& params);
  ~PhotonTracer();
  PhotonTracer(const PhotonTracer&) = delete;
  PhotonTracer& operator=(const PhotonTracer&) = delete;

  /// Called once per path, in path order, with the path's photons (world
  /// space, power not yet scaled), their count, the rays it traced, whether
  /// its first ray hit nothing and the light it started from (an index into
  /// lightNames()); returning false stops handing on the call's remaining paths.
  using PathSink = std::function<bool(const Photon* photons, uint32_t count, uint32_t rays,
                                      bool missed, uint32_t light)>;
  /// Traces paths [first, first + count) in parallel (TBB) and hands each to
  /// `onPath` in path order. Not reentrant (one call at a time per tracer).
  /// With PhotonParams::segments, `onSegments` gets each path's segments
  /// just before `onPath` gets its photons.
  using SegmentSink = std::function<void(const PhotonSegment* segments, uint32_t count)>;
  /// With PhotonParams::countDirect: each path's unstored direct first hit
  /// (count 0 or 1; world space, power not yet scaled), just before its photons.
  using DirectSink = std::function<void(const Photon* hits, uint32_t count)>;
  void trace(uint64_t first, size_t count, const PathSink& onPath,
             const SegmentSink& onSegments = {}, const DirectSink& onDirect = {}) const;
  /// The same, appending the photons to `photons` and each path's photon
  /// count to `pathPhotons`.
  void trace(uint64_t first, size_t count, std::vector<Photon>& photons,
             std::vector<uint32_t>& pathPhotons) const;
  Vec3 emittedPower() const;  ///< total RGB power of all lights, W
  bool canStore() const;      ///< false when the scene has no triangle to store on
  /// The scene's lights as a person names them, where they are: each
  /// punctual light, the sky, the emissive triangles of each material.
  const std::vector<std::string>& lightNames() const;
  /// Traces no more paths from these lights (indices into lightNames()):
  /// the others are picked by their power among themselves. Every path
  /// stays an estimate of all the light (the others' photons carry their
  /// power over the new pick probability), so photons traced before and
  /// after sum by the paths traced (scalePhotonPower) as before; what is
  /// lost is the left-out lights' light, which a light whose thousands of
  /// paths stored nothing does not have. @throws InputError if none is left.
  void leaveOut(const std::vector<uint32_t>& lights);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

/// Paths of the next batch of a photon map that holds `stored` of `target`
/// photons from `emitted` paths: the paths the photons per path so far say
/// are still needed, with a margin, within [4096, 2^19] (the first batch:
/// min(target, 65536)), and never beyond `maxEmitted`. 0: stop, also once
/// kReachProbePaths paths say that `maxEmitted` would store under 1% of the
/// target, or sooner (from 16,384 paths) once even the Poisson bound of the
/// rate so far says it would store under 0.25% (by the last path, or by
/// kPathsPerPhoton paths per photon of the target if that comes first). Only the work wasted past
/// the target and that early stop depend on it, never the photons.
size_t photonBatchPaths(size_t target, size_t stored, size_t emitted, size_t maxEmitted);
/// Paths traced before photonBatchPaths judges whether the lights reach the
/// scene at all: from then on, a map that would hold under 1% of its
/// photons at maxEmitted paths stops (a light under the floor, seen in a
/// second rather than after a billion paths).
constexpr size_t kReachProbePaths = size_t(1) << 20;
/// The paths a map may trace per photon it is to store, by default.
constexpr size_t kPathsPerPhoton = 64;
/// PhotonParams::maxEmitted, or its default kPathsPerPhoton * storedPhotons.
size_t maxEmittedPaths(const PhotonParams& params);
/// Divides every photon's power by the paths emitted to obtain them (the
/// Monte Carlo estimator of the emitted flux): the last step of a map.
void scalePhotonPower(std::vector<Photon>& photons, size_t emittedPaths);
/// The rays a free-space light is made from: each path's segments handed
/// in path order, taken whole from path 0 on until the next path would pass
/// `cap` rays; then none. The estimate is the taken paths' alone, so their
/// powers are divided by the paths taken (take()), not by all emitted.
class SegmentCollector {
 public:
  explicit SegmentCollector(size_t cap) : cap_(cap) {}
  /// The next path's segments. @returns false once full.
  bool addPath(const PhotonSegment* segments, uint32_t count);
  bool full() const { return full_; }
  size_t paths() const { return paths_; }
  /// The segments taken, powers scaled by 1 / paths(); leaves it empty.
  std::vector<PhotonSegment> take();

 private:
  size_t cap_;
  std::vector<PhotonSegment> segments_;
  size_t paths_ = 0;
  bool full_ = false;
};

}  // namespace lo
