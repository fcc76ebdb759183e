#pragma once
/// @file photon/photon_map.h
/// @brief Photon tracing with Embree (paper §4.1: the photon map the light
/// octree compresses). Embree is visible only inside src/photon.

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "lightgrid/photon.h"
#include "scene/scene.h"

namespace lo {

struct PhotonParams {
  size_t storedPhotons = 600000;  ///< photons to store (exact count unless the scene stores none)
  int maxBounces = 16;            ///< path length cap (Russian roulette usually ends paths first)
  bool includeDirect = false;     ///< also store bounce-0 hits (the GL pipeline renders direct light)
  uint64_t seed = 1;
  /// Stop after this many emitted paths even if fewer photons were stored
  /// (a scene whose light never reaches a diffuse surface). 0 = 64 * storedPhotons.
  size_t maxEmitted = 0;
  /// A region of interest (world space; empty = the whole scene): only
  /// photons inside it are stored, and directional lights emit over its
  /// footprint (a disc of its bounding sphere) instead of the whole scene's,
  /// starting outside the scene so that occluders beyond the region still cast.
  Bounds3 region;
};

struct PhotonMap {
  std::vector<Photon> photons;
  size_t emittedPaths = 0;      ///< paths traced to obtain `photons`
  size_t emptyPaths = 0;        ///< of those, paths that stored no photon
  Vec3 emittedPower{0, 0, 0};   ///< total RGB power of all lights, W
  size_t raysTraced = 0;        ///< for statistics
};

/// Traces photons from punctual lights and emissive triangles (area lights),
/// chosen in proportion to their power, through diffuse, glossy and
/// specular/transmissive (Fresnel) surfaces with Russian roulette.
/// Deterministic for a given seed whatever the number of TBB threads.
/// @throws InputError if the scene has no light with positive power.
PhotonMap tracePhotons(const Scene& scene, const PhotonParams& params,
                       ProgressSink* progress = nullptr);

}  // namespace lo
