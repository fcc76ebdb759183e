#pragma once
/// @file reference/path_tracer.h
/// @brief Unbiased reference renderer: a path tracer over the same Scene and
/// the same material model (material/bsdf.h) as the photon tracer, to measure
/// the light octree's error. See docs/reference.md for the estimator.
///
/// Output is linear radiance W/(m^2 sr) in the scene's light units
/// (scene/scene.h), or, for Part::Irradiance, irradiance W/m^2.

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "image/image.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"

namespace lo {

/// Which light paths a reference image contains. Vertex 1 is the first
/// surface the camera ray hits.
enum class ReferencePart {
  /// Emission seen at vertex 1, plus light that reaches vertex 1 straight
  /// from an emitter (punctual light, or emissive triangle at vertex 2).
  Direct,
  /// Everything else: light that scattered at least once before vertex 1.
  /// The quantity `render --mode indirect` approximates with the octree.
  Indirect,
  Full,  ///< Direct + Indirect (one estimator: the sum is exact)
  /// Irradiance at vertex 1 from indirect light only, on the side facing the
  /// camera: E = integral of L_indirect cos over the hemisphere, W/m^2.
  Irradiance,
};
/// "direct" | "indirect" | "full" | "irradiance". @throws InputError naming the value.
ReferencePart parseReferencePart(const std::string& name);
std::string toString(ReferencePart part);


struct ReferenceParams {
  int width = 256, height = 256;  ///< pixels
  ReferencePart part = ReferencePart::Full;
  /// Samples per pixel; ignored when timeBudgetSeconds > 0.
  int samplesPerPixel = 64;
  /// > 0: render passes of 1 sample per pixel until this many seconds have
  /// passed (at least one pass). Not byte-reproducible across machines: the
  /// number of passes depends on speed. A budget run that made N passes
  /// equals an spp = N run byte for byte.
  double timeBudgetSeconds = 0;
  /// Path length cap in scattering events after vertex 1. Russian roulette
  /// ends almost every path long before; the cap only bounds the worst case.
  int maxBounces = 256;
  /// Russian roulette starts after this many scattering events.
  int rouletteStart = 3;
  uint64_t seed = 1;
  /// Objects added after the bake (Scene::isAdded) seen by the camera
  /// alone: every later ray, of light or shadow, passes through them, so
  /// that they are lit by the scene as it was baked, neither shadowing nor
  /// lighting it: on a convex added object's own pixels, the light the
  /// free-space light stands for (docs/render.md), its judge. Not `render
  /// --add`'s whole picture: there the objects also cast direct shadows, on
  /// the scene and on each other. Added objects that emit light are not
  /// meant for it (their light still reaches the scene by light samples).
  bool addedOnlyReceive = false;
};

struct ReferenceImage {
  RgbImage image;     ///< the mean over samples
  RgbImage stdError;  ///< per pixel and channel: standard error of that mean
  /// 1 where the ray through the pixel's centre meets no emissive surface,
  /// 0 where it does (`reference --emitter-mask`, for `compare --mask`: the
  /// octree and the path tracer define irradiance differently on a light
  /// fixture's own pixels, docs/accuracy.md).
  RgbImage emitterMask;
  /// 1 where the ray through the pixel's centre meets a surface that does
  /// not emit, 0 on the background (sky, nothing) and on emitters
  /// (`reference --geometry-mask`): the pixels `compare --mask` judges, left
  /// out by what the pixel sees, never by its value.
  RgbImage geometryMask;
  int samplesPerPixel = 0;
  double seconds = 0;      ///< wall-clock rendering time
  uint64_t raysTraced = 0; ///< closest-hit plus shadow rays
};

/// Bytes renderReference holds per pixel of `params`' image: each pixel's
/// random stream and sums (two doubles per channel), its four images (the
/// mean, the standard error, the two masks) and the file writer's copy.
size_t referenceBytesPerPixel();

/// @brief Refuses, before any work, an image whose pixels
/// (referenceBytesPerPixel each) need more than the memory available
/// (availableMemoryBytes): 16384 x 16384 grew to the whole machine and was
/// killed by the kernel, without a word. renderReference calls it.
/// @throws InputError naming the size, the figure and the memory.
void checkReferenceMemory(const ReferenceParams& params);

/// Renders `part` of `scene` seen by `camera`. Parallel over tiles (TBB);
/// pixel i draws its random numbers from Rng(seed, i), so the result is the
/// same bytes for any thread count (spp mode).
/// @throws InputError for bad params (sizes, spp) or bad triangle indices.
ReferenceImage renderReference(const Scene& scene, const PinholeCamera& camera,
                               const ReferenceParams& params, ProgressSink* progress = nullptr);

/// @brief Direct irradiance E(p, n) (W/m^2) from every light, with shadow
/// rays, by the path tracer's own light sampling: punctual lights exactly
/// (more of them than samples by `samples` draws from their light tree),
/// emissive triangles by `samples` samples, each an emitter picked by power
/// (mean emission x area) and a uniform point on it (emissive textures and
/// one-sided emission as the path tracer reads them). Not the sky's: the
/// bake stores all of its light in the octree. For lightmaps that hold the
/// direct light too (`lightmap --content full`). Thread-safe.
class DirectIrradiance {
 public:
  /// @throws InputError for bad scene indices; builds an Embree scene.
  explicit DirectIrradiance(const Scene& scene);
  ~DirectIrradiance();
  DirectIrradiance(const DirectIrradiance&) = delete;
  DirectIrradiance& operator=(const DirectIrradiance&) = delete;

  /// E at surface point `p` of triangle `triangle` (its geometric normal
  /// offsets the shadow rays' origins) for the unit normal `n`, on n's side.
  /// Deterministic: the same (seed, index) give the same value. Punctual
  /// lights cost at most max(8, samples) shadow rays: each light once when
  /// there are no more, else one drawn from the light tree per sample
  /// (reference/light_tree.h; the draws stratified over the samples); each
  /// sample traces one to an emitter. `shadowRays`, when given, has the rays
  /// traced added to it.
  Vec3 at(const Vec3& p, uint32_t triangle, const Vec3& n, int samples, uint64_t seed,
          uint64_t index, uint64_t* shadowRays = nullptr) const;

  /// A surface point: position, triangle (for the ray offset), unit normal.
  struct Point {
    Vec3 position;
    uint32_t triangle = 0;
    Vec3 normal;
  };
  /// `at` for many points in parallel (TBB); point i uses index
  /// firstIndex + i: the result does not depend on the thread count.
  /// `chunkDone` (if set) is called, on any thread, after each point: a
  /// caller's Progress::heartbeat.
  std::vector<Vec3> atMany(const std::vector<Point>& points, int samples, uint64_t seed,
                           uint64_t firstIndex = 0,
                           const std::function<void()>& chunkDone = {}) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lo
