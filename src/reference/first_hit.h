#pragma once
/// @file reference/first_hit.h
/// @brief Images of a quantity evaluated at the first surface each camera ray
/// hits (vertex 1 of renderReference), with the reference camera and pixel
/// sampling. Used to evaluate the light octree's irradiance at exactly the
/// points where the reference's ReferencePart::Irradiance is estimated, so
/// that the two are compared on the same quantity (docs/accuracy.md).

#include <cstdint>
#include <functional>

#include "core/math.h"
#include "core/progress.h"
#include "image/image.h"
#include "reference/path_tracer.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "scene/scene.h"

namespace lo {

/// The first surface a camera ray hits.
struct FirstHit {
  Vec3 position;          ///< world space
  Vec3 normal;            ///< unit geometric normal turned to the camera's side (as the reference)
  uint32_t triangle = 0;  ///< index into the Scene's triangles
};

struct FirstHitParams {
  int width = 256, height = 256;  ///< pixels
  /// Jittered camera rays per pixel (the reference's pixel footprint);
  /// the value is their mean, misses counting 0.
  int samplesPerPixel = 4;
  uint64_t seed = 1;
};

/// For every pixel, the mean of shade(hit) over samplesPerPixel jittered
/// camera rays. Parallel (TBB) and deterministic: pixel i draws its jitter
/// from Rng(seed, i). `shade` is called from several threads at once.
/// @throws InputError for bad sizes, sample counts or field of view.
RgbImage renderFirstHits(const Scene& scene, const PinholeCamera& camera,
                         const FirstHitParams& params,
                         const std::function<Vec3(const FirstHit&)>& shade,
                         ProgressSink* progress = nullptr);

/// @brief The light octree's indirect irradiance at the first hits, on the
/// CPU (octreeIrradiance: the shader's lookup with the cosine alone), the
/// objects added after the bake (Scene::isAdded) read from `volume`, their
/// free-space light, when it is not empty: the image that compares with the
/// reference's irradiance part (`render --mode irradiance`, the sweep).
RgbImage renderOctreeIrradiance(const Scene& scene, const PinholeCamera& camera,
                                const GpuOctree& octree, const GpuOctree& volume,
                                const OctreeShadeParams& shade, const FirstHitParams& params);

/// The pixels whose first hit lies within `distance` (scene units) of an
/// edge: where the surface meets another one (a wall joint, an object
/// resting on the floor) or ends or bends (a box's outer edge, a tight
/// curve). Per jittered ray of renderFirstHits, 1 at such a hit, else 0; a
/// pixel holds the share of its rays that hit near an edge. The test at a
/// hit p with normal n, over 16 directions t in its tangent plane: a ray
/// from p (lifted off the surface by distance / 50) along t that hits
/// geometry within `distance`, or a ray down along -n from p + distance t
/// (lifted by distance / 20) that finds no surface within twice the lift.
/// It is the mask of the accuracy issue's "pixels within one voxel of an
/// edge" (docs/accuracy.md), used with `compare --mask`.
/// @throws InputError for a distance that is not finite and positive, and
/// as renderFirstHits.
RgbImage renderEdgeMask(const Scene& scene, const PinholeCamera& camera,
                        const FirstHitParams& params, float distance,
                        ProgressSink* progress = nullptr);

}  // namespace lo
