#include "reference/first_hit.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "photon/ray_tracer.h"

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
              if (!tracer.intersect(camera.eye, dir, hit)) continue;
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

}  // namespace lo
