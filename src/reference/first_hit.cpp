#include "reference/first_hit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "raytrace/ray_tracer.h"

namespace lo {

RgbImage renderFirstHits(const Scene& scene, const PinholeCamera& camera,
                         const FirstHitParams& params,
                         const std::function<Vec3(const FirstHit&)>& shade,
                         ProgressSink* progress) {
  if (params.width < 1 || params.height < 1)
    throw InputError("FirstHitParams: image size " + std::to_string(params.width) + " x " +
                     std::to_string(params.height) + " must be at least 1 x 1");
  if (params.samplesPerPixel < 1)
    throw InputError("FirstHitParams.samplesPerPixel must be >= 1, got " +
                     std::to_string(params.samplesPerPixel));
  if (!(camera.yfov > 0 && camera.yfov < kPi))
    throw InputError("camera: vertical field of view " + std::to_string(camera.yfov) +
                     " rad outside (0, pi)");
  RayTracer tracer(scene);
  RgbImage image(params.width, params.height);
  const Vec3 right = normalize(cross(camera.forward, camera.up));
  const float tanHalf = std::tan(0.5f * camera.yfov);
  const float aspect = float(params.width) / float(params.height);
  Progress bar(progress, "First hits", size_t(params.height));
  tbb::parallel_for(
      tbb::blocked_range<int>(0, params.height), [&](const tbb::blocked_range<int>& r) {
        for (int y = r.begin(); y != r.end(); ++y) {
          for (int x = 0; x < params.width; ++x) {
            const size_t i = size_t(y) * size_t(params.width) + size_t(x);
            Rng rng(params.seed, i);
            Vec3 sum{0, 0, 0};
            for (int s = 0; s < params.samplesPerPixel; ++s) {
              // The same jitter and ray as reference_internal::samplePixel.
              const float u = rng.uniform(), v = rng.uniform();
              const float sx =
                  (2.0f * (float(x) + u) / float(params.width) - 1.0f) * tanHalf * aspect;
              const float sy = (1.0f - 2.0f * (float(y) + v) / float(params.height)) * tanHalf;
              const Vec3 dir = normalize(camera.forward + right * sx + camera.up * sy);
              Hit hit;
              if (!tracer.intersectFromCamera(camera.eye, dir, hit)) continue;
              FirstHit first;
              first.position = camera.eye + dir * hit.t;
              first.normal =
                  dot(dir, hit.geometricNormal) < 0 ? hit.geometricNormal : -hit.geometricNormal;
              first.triangle = hit.triangle;
              sum += shade(first);
            }
            image.set(i, sum / float(params.samplesPerPixel));
          }
          bar.advance(1);
        }
      });
  return image;
}

RgbImage renderEdgeMask(const Scene& scene, const PinholeCamera& camera,
                        const FirstHitParams& params, float distance, ProgressSink* progress) {
  if (!(distance > 0) || !std::isfinite(distance)) {
    throw InputError("edge mask: distance " + std::to_string(distance) +
                     " must be finite and positive");
  }
  // Beyond the scene's diagonal every hit lies within the distance of every
  // edge: the mask is the same, and the probes stay where rays can go.
  const Bounds3 bounds = scene.bounds();
  if (!bounds.empty()) distance = std::min(distance, 2.0f * length(bounds.extent()) + 1e-30f);
  RayTracer tracer(scene);
  constexpr int kDirections = 16;
  const float lift = distance / 50.0f, dropLift = distance / 20.0f;
  auto nearEdge = [&](const FirstHit& h) -> Vec3 {
    const Vec3 n = h.normal;
    const Vec3 a = std::fabs(n.x) < 0.9f ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
    const Vec3 t1 = normalize(cross(n, a)), t2 = cross(n, t1);
    const Vec3 p = h.position + n * lift;
    for (int k = 0; k < kDirections; ++k) {
      const float phi = 2.0f * kPi * float(k) / float(kDirections);
      const Vec3 t = t1 * std::cos(phi) + t2 * std::sin(phi);
      if (tracer.occluded(p, t, distance)) return Vec3(1.0f);  // another surface across
      if (!tracer.occluded(h.position + t * distance + n * dropLift, -n, 2.0f * dropLift)) {
        return Vec3(1.0f);  // the surface ends or bends away
      }
    }
    return Vec3(0.0f);
  };
  return renderFirstHits(scene, camera, params, nearEdge, progress);
}

RgbImage renderOctreeIrradiance(const Scene& scene, const PinholeCamera& camera,
                                const GpuOctree& octree, const GpuOctree& volume,
                                const OctreeShadeParams& shade, const FirstHitParams& params) {
  return renderFirstHits(scene, camera, params, [&](const FirstHit& hit) {
    if (volume.depth > 0 && scene.isAdded(hit.triangle)) {
      return volumeIrradiance(volume, hit.position, hit.normal);
    }
    return octreeIrradiance(octree, hit.position, hit.normal, shade);
  });
}

}  // namespace lo
