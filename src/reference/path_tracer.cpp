/// @file reference/path_tracer.cpp
/// @brief Path tracing with next-event estimation and multiple importance
/// sampling (Veach 1997, §9.2, power heuristic beta = 2) over raytrace/ray_tracer.h
/// and the photon tracer's material model material/bsdf.h.

#include "reference/path_tracer.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

#include "core/error.h"
#include "core/resources.h"
#include "core/rng.h"
#include "material/bsdf.h"
#include "raytrace/ray_tracer.h"
#include "reference/light_tree.h"
#include "scene/emitter_sampler.h"
#include "scene/sky_sampler.h"

namespace lo {

ReferencePart parseReferencePart(const std::string& name) {
  if (name == "direct") return ReferencePart::Direct;
  if (name == "indirect") return ReferencePart::Indirect;
  if (name == "full") return ReferencePart::Full;
  if (name == "irradiance") return ReferencePart::Irradiance;
  throw InputError("unknown reference part '" + name +
                   "' (expected direct, indirect, full or irradiance)");
}

std::string toString(ReferencePart part) {
  switch (part) {
    case ReferencePart::Direct:
      return "direct";
    case ReferencePart::Indirect:
      return "indirect";
    case ReferencePart::Full:
      return "full";
    case ReferencePart::Irradiance:
      return "irradiance";
  }
  return "?";
}


namespace reference_internal {

constexpr int kTileSize = 16;
/// Shadow rays to punctual lights per shading point, at most: a scene with
/// this many lights or fewer has each of them traced (exact, no noise), a
/// scene with more has this many drawn from its light tree (light_tree.h),
/// so that a sample costs the same with a hundred thousand lights as with
/// ten (issue 43, family 5: 28 s for 16 x 16 pixels at 4 spp).
constexpr int kPunctualDraws = 8;

struct Context {
  const Scene* scene = nullptr;
  const RayTracer* tracer = nullptr;        ///< every ray but the camera's
  const RayTracer* cameraTracer = nullptr;  ///< rays from the camera
  std::vector<BsdfLobes> lobes;    ///< per material
  EmitterSampler emitters;  ///< emissive triangles, picked by power
  std::vector<float>
      emitterPickPdf;  ///< per triangle: pick probability / area (0 = not an emitter)
  std::vector<const Light*> lights;  ///< punctual lights with positive intensity
  LightTree lightTree;               ///< the same, drawn by importance (many lights)
  SkySampler sky;                    ///< the sky's directions by radiance (empty: no sky)
  /// Ray origins leave their surface by kRayEpsilonScale x (epsilonSize +
  /// the larger of epsilonReach and the point's largest coordinate):
  /// epsilonSize the baked part's diagonal, epsilonReach its largest
  /// coordinate. An object added far away (--add at 1e5) made one offset of
  /// the whole scene's size, 2 units in a 1-unit room, and the room's
  /// picture 44% dark; now each point's offset follows its own precision.
  float epsilonSize = 0, epsilonReach = 0;
  int maxBounces = 0;
  int rouletteStart = 0;
  bool unlit = false;  ///< the scene has unlit materials: camera rays look for them first
};

/// One path's radiance, split by where the light was last emitted relative
/// to vertex 1 (see ReferencePart).
struct PathRadiance {
  Vec3 emitted;   ///< emission at vertex 1, or the sky seen by the camera
  Vec3 direct;    ///< emitter or sky -> vertex 1 (NEE at vertex 1, emission or sky at vertex 2)
  Vec3 indirect;  ///< everything else
  uint32_t rays = 0;
};

inline float powerHeuristic(float a, float b) {
  float a2 = a * a, b2 = b * b;
  return a2 + b2 > 0 ? a2 / (a2 + b2) : 0.0f;
}

/// Radiance emitted by triangle `tri` towards direction `w` (unit, away from
/// the surface): one-sided emitters emit on the winding side only, as the
/// photon tracer's emitters do.
inline Vec3 emittedRadiance(const Context& ctx, uint32_t tri, float b1, float b2,
                            const Vec3& normal, const Vec3& w) {
  const Material& m = ctx.scene->materials[ctx.scene->triangleMaterial[tri]];
  if (!m.isEmissive()) return Vec3{0, 0, 0};
  if (!m.doubleSided && dot(w, normal) <= 0) return Vec3{0, 0, 0};
  return m.emissiveTexture >= 0 ? ctx.scene->emission(tri, b1, b2) : m.emission;
}

inline Vec3 offsetOrigin(const Context& ctx, const Vec3& p, const Vec3& normal, const Vec3& dir) {
  const float reach =
      std::max({ctx.epsilonReach, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  const float epsilon = kRayEpsilonScale * std::max(ctx.epsilonSize + reach, 1e-6f);
  return p + (dot(dir, normal) > 0 ? normal : -normal) * epsilon;
}

/// Light from punctual light `light` reflected at p towards wo, shadow ray
/// included (counted in `rays`), without path throughput.
inline Vec3 punctualLight(const Context& ctx, const Light& light, const Vec3& p, const Vec3& normal,
                          const Vec3& n, const Vec3& wo, const BsdfLobes& lobes, const Vec3& albedo,
                          uint32_t& rays) {
  Vec3 wi;
  float dist = 0;
  const Vec3 irradiance = punctualIrradiance(light, p, wi, dist);  // before the cosine
  if (maxComponent(irradiance) <= 0) return Vec3{0, 0, 0};
  Vec3 f = evalBsdf(lobes, albedo, wo, wi, n);
  if (maxComponent(f) <= 0) return Vec3{0, 0, 0};
  Vec3 org = offsetOrigin(ctx, p, normal, wi);
  ++rays;
  if (ctx.tracer->occluded(org, wi, std::isinf(dist) ? dist : dist * (1.0f - 1e-4f))) {
    return Vec3{0, 0, 0};
  }
  return f * irradiance;
}

/// Every punctual light at p, each with its shadow ray: exact.
inline Vec3 allPunctualLights(const Context& ctx, const Vec3& p, const Vec3& normal, const Vec3& n,
                              const Vec3& wo, const BsdfLobes& lobes, const Vec3& albedo,
                              uint32_t& rays) {
  Vec3 sum{0, 0, 0};
  for (const Light* light : ctx.lights)
    sum += punctualLight(ctx, *light, p, normal, n, wo, lobes, albedo, rays);
  return sum;
}

/// The punctual lights at p by `draws` draws from the light tree, in
/// stratum `stratum` of `strata` equal parts of [0, 1) (the tree's order
/// keeps near lights near in u), each weighed by 1 / pmf: unbiased, as the
/// tree draws every light that can light p (a delta light has no MIS: BSDF
/// sampling never finds it).
inline Vec3 drawnPunctualLights(const Context& ctx, const Vec3& p, const Vec3& normal,
                                const Vec3& n, const Vec3& wo, const BsdfLobes& lobes,
                                const Vec3& albedo, Rng& rng, uint32_t& rays, int draws,
                                int stratum = 0, int strata = 1) {
  Vec3 sum{0, 0, 0};
  const std::vector<Light>& lights = ctx.scene->lights;
  const double cells = double(draws) * double(strata);
  for (int k = 0; k < draws; ++k) {
    const double u = (double(stratum) * draws + k + uniform53(rng)) / cells;
    uint32_t index = 0;
    float pmf = 0;
    if (!ctx.lightTree.sample(p, n, u, index, pmf)) continue;
    sum += punctualLight(ctx, lights[index], p, normal, n, wo, lobes, albedo, rays) /
           (pmf * float(draws));
  }
  return sum;
}

/// Next-event estimation at a surface point from the emitters and the sky:
/// one emissive triangle picked by power and one sky direction, each
/// MIS-weighted against BSDF sampling. Returns the reflected radiance
/// towards wo (without path throughput). With `misWeights` false the
/// emitter sample counts fully (light sampling alone estimates the
/// integral: DirectIrradiance).
inline Vec3 sampleEmitters(const Context& ctx, const Vec3& p, const Vec3& normal, const Vec3& n,
                           const Vec3& wo, const BsdfLobes& lobes, const Vec3& albedo, Rng& rng,
                           uint32_t& rays, bool misWeights = true, bool withSky = true) {
  Vec3 sum{0, 0, 0};
  if (!ctx.emitters.empty()) {
    const Scene& scene = *ctx.scene;
    uint32_t tri = ctx.emitters.triangles[ctx.emitters.pick(uniform53(rng))];
    float s = std::sqrt(rng.uniform());
    float b1 = 1.0f - s, b2 = rng.uniform() * s;
    const Vec3& p0 = scene.positions[scene.indices[3 * tri]];
    const Vec3& p1 = scene.positions[scene.indices[3 * tri + 1]];
    const Vec3& p2 = scene.positions[scene.indices[3 * tri + 2]];
    Vec3 q = p0 + (p1 - p0) * b1 + (p2 - p0) * b2;
    Vec3 d = q - p;
    float dist2 = lengthSquared(d);
    float dist = std::sqrt(dist2);
    if (dist > 0) {
      Vec3 wi = d / dist;
      Vec3 lightNormal = scene.faceNormal(tri);
      Vec3 le = emittedRadiance(ctx, tri, b1, b2, lightNormal, -wi);
      float cosLight = std::fabs(dot(lightNormal, wi));
      Vec3 f = maxComponent(le) > 0 && cosLight > 0 ? evalBsdf(lobes, albedo, wo, wi, n) : Vec3{};
      if (maxComponent(f) > 0) {
        float pdfLight = ctx.emitterPickPdf[tri] * dist2 / cosLight;  // solid angle
        float w = misWeights ? powerHeuristic(pdfLight, pdfBsdf(lobes, albedo, wo, wi, n)) : 1.0f;
        // Both ends lifted off their surfaces, the far one towards p's side
        // of the emitter: the segment never reaches the emitter's plane, at
        // any angle (stopping short along the ray instead does not clear
        // the plane when the ray meets it at a grazing angle).
        const Vec3 org = offsetOrigin(ctx, p, normal, wi);
        const Vec3 target = offsetOrigin(ctx, q, lightNormal, -wi);
        const Vec3 seg = target - org;
        const float segLength = length(seg);
        ++rays;
        if (segLength > 0 && dot(seg, wi) > 0 &&
            !ctx.tracer->occluded(org, seg / segLength, segLength * (1.0f - 1e-4f)))
          sum += f * le * (w / pdfLight);
      }
    }
  }

  // The sky: one direction by its radiance, MIS-weighted against BSDF
  // sampling (which finds it where a path escapes, tracePath).
  if (withSky && !ctx.sky.empty()) {
    const double u0 = uniform53(rng);
    const float u1 = rng.uniform(), u2 = rng.uniform();
    Vec3 towards;
    float pdfSky = 0;
    if (ctx.sky.sample(u0, u1, u2, towards, pdfSky) && dot(towards, normal) > 0) {
      const Vec3 f = evalBsdf(lobes, albedo, wo, towards, n);
      const Vec3 l = ctx.scene->sky.radianceFrom(towards);
      if (maxComponent(f) > 0 && maxComponent(l) > 0) {
        const float w = powerHeuristic(pdfSky, pdfBsdf(lobes, albedo, wo, towards, n));
        ++rays;
        if (!ctx.tracer->occluded(offsetOrigin(ctx, p, normal, towards), towards,
                                  std::numeric_limits<float>::infinity())) {
          sum += f * l * (w / pdfSky);
        }
      }
    }
  }
  return sum;
}

/// Next-event estimation at a path vertex: the punctual lights (each of them
/// when there are at most kPunctualDraws, else kPunctualDraws draws from the
/// light tree), then sampleEmitters.
inline Vec3 sampleLights(const Context& ctx, const Vec3& p, const Vec3& normal, const Vec3& n,
                         const Vec3& wo, const BsdfLobes& lobes, const Vec3& albedo, Rng& rng,
                         uint32_t& rays) {
  Vec3 sum =
      ctx.lights.size() <= size_t(kPunctualDraws)
          ? allPunctualLights(ctx, p, normal, n, wo, lobes, albedo, rays)
          : drawnPunctualLights(ctx, p, normal, n, wo, lobes, albedo, rng, rays, kPunctualDraws);
  return sum + sampleEmitters(ctx, p, normal, n, wo, lobes, albedo, rng, rays);
}

/// Traces one path from (org, dir) and splits its radiance by PathRadiance's
/// rules. The first surface hit is vertex 1; `fromCamera`: the first ray is
/// the camera's.
inline PathRadiance tracePath(const Context& ctx, Vec3 org, Vec3 dir, Rng& rng,
                              bool fromCamera = false) {
  PathRadiance out;
  Vec3 beta{1, 1, 1};
  bool prevDelta = true;  // the camera ray: emission at vertex 1 counts fully
  float prevPdf = 0;
  Hit hit;
  for (int depth = 1;; ++depth) {
    ++out.rays;
    const bool seen = depth == 1 && fromCamera
                          ? ctx.cameraTracer->intersectFromCamera(org, dir, hit)
                          : ctx.tracer->intersect(org, dir, hit);
    if (!seen) {
      // Escaped: the sky's light, MIS-weighted against the sky's light
      // sample at the previous vertex (none after a mirror or glass). Seen by
      // the camera it is the background; at vertex 2 it is direct light of
      // vertex 1.
      const Vec3 sky = ctx.scene->sky.radianceFrom(dir);
      if (maxComponent(sky) > 0) {
        const float w = prevDelta ? 1.0f : powerHeuristic(prevPdf, ctx.sky.pdf(dir));
        (depth == 1 ? out.emitted : depth == 2 ? out.direct : out.indirect) += beta * sky * w;
      }
      break;
    }
    Vec3 p = org + dir * hit.t;
    const Vec3& normal = hit.geometricNormal;
    bool frontFace = dot(dir, normal) < 0;
    // The shading normal: the geometric one, tilted by a normal map as the
    // renderer tilts it (Scene::shadingNormal); offsets and sides keep the
    // geometric one.
    const Vec3 n = ctx.scene->shadingNormal(hit.triangle, hit.b1, hit.b2,
                                            frontFace ? normal : -normal);
    Vec3 wo = -dir;
    Vec3 le = emittedRadiance(ctx, hit.triangle, hit.b1, hit.b2, normal, wo);
    if (maxComponent(le) > 0) {
      float w = 1;
      if (!prevDelta) {
        float cosLight = std::fabs(dot(normal, dir));
        float pdfLight =
            cosLight > 0 ? ctx.emitterPickPdf[hit.triangle] * hit.t * hit.t / cosLight : 0.0f;
        w = powerHeuristic(prevPdf, pdfLight);
      }
      Vec3 c = beta * le * w;
      (depth == 1 ? out.emitted : depth == 2 ? out.direct : out.indirect) += c;
    }
    // depth - 1 scattering events so far; one more is allowed below the cap.
    if (depth - 1 >= ctx.maxBounces) break;

    const BsdfLobes lobes = bsdfLobesAt(*ctx.scene, ctx.lobes[ctx.scene->triangleMaterial[hit.triangle]],
                                        hit.triangle, hit.b1, hit.b2);
    Vec3 albedo = ctx.scene->albedo(hit.triangle, hit.b1, hit.b2);
    if (lobes.hasSmoothLobe()) {
      // The geometric normal on the side the path arrives from: the sky is
      // sampled above it (a back face's sky lies below its winding).
      Vec3 l = sampleLights(ctx, p, frontFace ? normal : -normal, n, wo, lobes, albedo, rng,
                            out.rays);
      (depth == 1 ? out.direct : out.indirect) += beta * l;
    }
    BsdfSample sample;
    if (!sampleBsdf(lobes, albedo, wo, n, frontFace, rng, sample)) break;
    Vec3 newDir = normalize(sample.wi);
    if (lengthSquared(newDir) == 0) break;
    beta *= sample.weight;
    prevDelta = sample.delta;
    prevPdf = sample.delta ? 0.0f : pdfBsdf(lobes, albedo, wo, newDir, n);
    if (depth >= ctx.rouletteStart) {
      // Survive with probability min(1, max(beta)); the division keeps the
      // estimator unbiased.
      float q = std::min(1.0f, maxComponent(beta));
      if (!(q > 0) || rng.uniform() >= q) break;
      beta /= q;
    }
    org = offsetOrigin(ctx, p, normal, newDir);
    dir = newDir;
  }
  return out;
}

/// One sample of pixel (x, y) for `part`.
inline Vec3 samplePixel(const Context& ctx, const PinholeCamera& cam, const Vec3& right,
                        float tanHalf, float aspect, int x, int y, int width, int height,
                        ReferencePart part, Rng& rng, uint32_t& rays) {
  float u = rng.uniform(), v = rng.uniform();
  float sx = (2.0f * (float(x) + u) / float(width) - 1.0f) * tanHalf * aspect;
  float sy = (1.0f - 2.0f * (float(y) + v) / float(height)) * tanHalf;
  Vec3 dir = normalize(cam.forward + right * sx + cam.up * sy);
  if (ctx.unlit) {
    // An unlit surface in front: its base colour, seen by the camera alone.
    Hit seen;
    ++rays;
    if (ctx.cameraTracer->intersectFromCamera(cam.eye, dir, seen)) {
      const Material& m = ctx.scene->materials[size_t(ctx.scene->triangleMaterial[seen.triangle])];
      if (m.unlit) {
        const bool shown = part == ReferencePart::Full || part == ReferencePart::Direct;
        return shown ? ctx.scene->albedo(seen.triangle, seen.b1, seen.b2) : Vec3{0, 0, 0};
      }
    }
  }
  if (part != ReferencePart::Irradiance) {
    PathRadiance r = tracePath(ctx, cam.eye, dir, rng, true);
    rays += r.rays;
    switch (part) {
      case ReferencePart::Direct:
        return r.emitted + r.direct;
      case ReferencePart::Indirect:
        return r.indirect;
      default:
        return r.emitted + r.direct + r.indirect;
    }
  }
  // Irradiance at vertex 1 on the camera's side, from light that scattered
  // at least once: cosine-sample a direction (cos/pdf = pi), and take the
  // radiance arriving along it minus the emission of the surface it hits.
  Hit hit;
  ++rays;
  if (!ctx.cameraTracer->intersectFromCamera(cam.eye, dir, hit)) return Vec3{0, 0, 0};
  Vec3 p = cam.eye + dir * hit.t;
  const Vec3& normal = hit.geometricNormal;
  Vec3 n = dot(dir, normal) < 0 ? normal : -normal;
  Vec3 t, b;
  orthonormalBasis(n, t, b);
  float u1 = rng.uniform(), u2 = rng.uniform();
  Vec3 wi = normalize(fromLocal(cosineHemisphere(u1, u2), t, b, n));
  PathRadiance r = tracePath(ctx, offsetOrigin(ctx, p, normal, wi), wi, rng);
  rays += r.rays;
  return (r.direct + r.indirect) * kPi;
}

void buildContext(const Scene& scene, const ReferenceParams& params, Context& ctx) {
  ctx.scene = &scene;
  ctx.maxBounces = params.maxBounces;
  ctx.rouletteStart = params.rouletteStart;
  ctx.lobes.resize(scene.materials.size());
  for (const Material& m : scene.materials) ctx.unlit = ctx.unlit || m.unlit;
  for (size_t i = 0; i < scene.materials.size(); ++i) ctx.lobes[i] = bsdfLobes(scene.materials[i]);
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    int32_t m = scene.triangleMaterial[t];
    if (m < 0 || size_t(m) >= scene.materials.size())
      throw InputError("triangle " + std::to_string(t) + " has material index " +
                       std::to_string(m) + " outside [0, " +
                       std::to_string(scene.materials.size()) + ")");
  }
  ctx.emitters = buildEmitterSampler(scene);
  ctx.emitterPickPdf = ctx.emitters.areaPdfs(scene);
  ctx.sky = SkySampler(scene.sky);
  for (const Light& light : scene.lights)
    if (light.intensity > 0 && maxComponent(light.color) > 0) ctx.lights.push_back(&light);
  if (ctx.lights.size() > size_t(kPunctualDraws)) ctx.lightTree = LightTree(scene.lights);
  // The baked part's size (objects added after the bake left out: one far
  // away is no reason to offset every ray of the room by its distance).
  Bounds3 bounds;
  if (scene.hasAddedObjects()) {
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
      if (scene.isAdded(t)) continue;
      for (int k = 0; k < 3; ++k) bounds.extend(scene.positions[scene.indices[3 * t + size_t(k)]]);
    }
  }
  if (bounds.empty()) bounds = scene.bounds();
  if (!bounds.empty()) {
    Vec3 lo = bounds.lower, hi = bounds.upper;
    Vec3 a{std::fabs(lo.x), std::fabs(lo.y), std::fabs(lo.z)};
    Vec3 c{std::fabs(hi.x), std::fabs(hi.y), std::fabs(hi.z)};
    ctx.epsilonSize = length(bounds.extent());
    ctx.epsilonReach = maxComponent(max(a, c));
  }
}

/// Per-pixel running sums in double, in sample order.
struct PixelSums {
  double sum[3] = {0, 0, 0};
  double sumSq[3] = {0, 0, 0};
};

/// TBB body: `passSpp` more samples for every pixel of tiles [r.begin(), r.end()).
struct RenderTiles {
  const Context* ctx;
  const PinholeCamera* cam;
  Vec3 right;
  float tanHalf, aspect;
  int width, height, tilesX, passSpp;
  ReferencePart part;
  std::vector<Rng>* rngs;
  std::vector<PixelSums>* sums;
  std::atomic<uint64_t>* rays;
  Progress* progress;
  Progress* heartbeat = nullptr;  ///< under a time budget: the bar, told a tile ended

  void operator()(const tbb::blocked_range<size_t>& r) const {
    uint64_t localRays = 0;
    for (size_t tile = r.begin(); tile != r.end(); ++tile) {
      int x0 = int(tile % size_t(tilesX)) * kTileSize, y0 = int(tile / size_t(tilesX)) * kTileSize;
      for (int y = y0; y < std::min(height, y0 + kTileSize); ++y) {
        for (int x = x0; x < std::min(width, x0 + kTileSize); ++x) {
          size_t i = size_t(y) * size_t(width) + size_t(x);
          Rng& rng = (*rngs)[i];
          PixelSums& s = (*sums)[i];
          for (int k = 0; k < passSpp; ++k) {
            uint32_t n = 0;
            Vec3 v =
                samplePixel(*ctx, *cam, right, tanHalf, aspect, x, y, width, height, part, rng, n);
            localRays += n;
            if (!isFinite(v)) v = Vec3{0, 0, 0};  // never expected; keeps one NaN from spreading
            for (int c = 0; c < 3; ++c) {
              s.sum[c] += double(v[c]);
              s.sumSq[c] += double(v[c]) * double(v[c]);
            }
          }
        }
      }
      if (progress) progress->advance(1);
      if (heartbeat) heartbeat->heartbeat();
    }
    rays->fetch_add(localRays, std::memory_order_relaxed);
  }
};

}  // namespace reference_internal

size_t referenceBytesPerPixel() {
  using reference_internal::PixelSums;
  // 4 images of 3 floats; the file writer's copy at most 4 floats (EXR).
  return sizeof(Rng) + sizeof(PixelSums) + 4 * 3 * sizeof(float) + 4 * sizeof(float);
}

void checkReferenceMemory(const ReferenceParams& params) {
  const size_t available = availableMemoryBytes();
  const double needed = double(params.width) * double(params.height) *
                        double(referenceBytesPerPixel());
  if (available > 0 && needed > double(available)) {
    throw InputError("an image of " + std::to_string(params.width) + " x " +
                     std::to_string(params.height) + " pixels needs about " +
                     formatBytes(size_t(needed)) + " to path-trace (" +
                     std::to_string(referenceBytesPerPixel()) + " bytes per pixel), more than " +
                     "the " + formatBytes(available) + " of memory available: use a smaller " +
                     "--width and --height");
  }
}

ReferenceImage renderReference(const Scene& scene, const PinholeCamera& camera,
                               const ReferenceParams& params, ProgressSink* progress) {
  checkReferenceMemory(params);
  // Far from the origin, render in a frame centred on the scene (see
  // Scene::tracingOrigin); a translation changes no radiance.
  const Vec3 origin = scene.tracingOrigin();
  if (!(origin == Vec3{0, 0, 0})) {
    PinholeCamera local = camera;
    local.eye -= origin;
    return renderReference(scene.translated(-origin), local, params, progress);
  }
  using namespace reference_internal;
  if (params.width < 1 || params.height < 1)
    throw InputError("ReferenceParams: image size " + std::to_string(params.width) + " x " +
                     std::to_string(params.height) + " must be at least 1 x 1");
  if (!(params.timeBudgetSeconds > 0) && params.samplesPerPixel < 1)
    throw InputError("ReferenceParams.samplesPerPixel must be >= 1, got " +
                     std::to_string(params.samplesPerPixel));
  if (params.maxBounces < 0)
    throw InputError("ReferenceParams.maxBounces must be >= 0, got " +
                     std::to_string(params.maxBounces));
  if (!(camera.yfov > 0 && camera.yfov < kPi))
    throw InputError("camera: vertical field of view " + std::to_string(camera.yfov) +
                     " rad outside (0, pi)");
  checkSceneIndices(scene);

  auto start = std::chrono::steady_clock::now();
  Context ctx;
  buildContext(scene, params, ctx);
  RayTracer tracer(scene);
  ctx.cameraTracer = &tracer;
  std::unique_ptr<RayTracer> asBaked;
  if (params.addedOnlyReceive) {
    asBaked = std::make_unique<RayTracer>(scene, RayTracer::Objects::AsBaked);
    ctx.tracer = asBaked.get();
  } else {
    ctx.tracer = &tracer;
  }

  const size_t pixels = size_t(params.width) * size_t(params.height);
  std::vector<Rng> rngs;
  rngs.reserve(pixels);
  for (size_t i = 0; i < pixels; ++i) rngs.emplace_back(params.seed, i);
  std::vector<PixelSums> sums(pixels);
  std::atomic<uint64_t> rays{0};

  const int tilesX = (params.width + kTileSize - 1) / kTileSize;
  const int tilesY = (params.height + kTileSize - 1) / kTileSize;
  const size_t tiles = size_t(tilesX) * size_t(tilesY);
  RenderTiles body;
  body.ctx = &ctx;
  body.cam = &camera;
  body.right = normalize(cross(camera.forward, camera.up));
  body.tanHalf = std::tan(0.5f * camera.yfov);
  body.aspect = float(params.width) / float(params.height);
  body.width = params.width;
  body.height = params.height;
  body.tilesX = tilesX;
  body.part = params.part;
  body.rngs = &rngs;
  body.sums = &sums;
  body.rays = &rays;

  const bool budget = params.timeBudgetSeconds > 0;
  // Passes only change how often progress is reported: each pixel's samples
  // and sums happen in the same order whatever the pass size.
  const int passSpp = budget ? 1 : std::min(params.samplesPerPixel, 4);
  const int passes = budget ? 0 : (params.samplesPerPixel + passSpp - 1) / passSpp;
  int done = 0;
  {
    Progress bar(progress, budget ? "Path tracing (time budget, passes of 1 spp)" : "Path tracing",
                 budget ? tiles : tiles * size_t(passes));
    body.progress = budget ? nullptr : &bar;
    // Under a time budget a pass (1 sample of every pixel) says nothing of how
    // far it got, and took 1.25 s of a 30 s budget: its tiles keep the bar
    // alive, so that Ctrl-C is heard within a pass (H12-1-2).
    body.heartbeat = budget ? &bar : nullptr;
    size_t reportedTiles = 0;
    for (int pass = 0;; ++pass) {
      if (budget) {
        double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        if (pass > 0 && elapsed >= params.timeBudgetSeconds) break;
      } else if (done >= params.samplesPerPixel) {
        break;
      }
      body.passSpp = budget ? 1 : std::min(passSpp, params.samplesPerPixel - done);
      tbb::parallel_for(tbb::blocked_range<size_t>(0, tiles, 1), body, tbb::simple_partitioner());
      done += body.passSpp;
      if (budget) {
        double elapsed =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        size_t target = std::min(
            tiles, size_t(double(tiles) * std::min(1.0, elapsed / params.timeBudgetSeconds)));
        if (target > reportedTiles) {
          bar.advance(target - reportedTiles);
          reportedTiles = target;
        }
      }
    }
  }

  ReferenceImage result;
  result.image = RgbImage(params.width, params.height);
  result.stdError = RgbImage(params.width, params.height);
  result.samplesPerPixel = done;
  double n = double(done);
  for (size_t i = 0; i < pixels; ++i) {
    for (int c = 0; c < 3; ++c) {
      double mean = sums[i].sum[c] / n;
      double var = done > 1 ? std::max(0.0, (sums[i].sumSq[c] - n * mean * mean) / (n - 1.0)) : 0.0;
      result.image.rgb[3 * i + c] = float(mean);
      result.stdError.rgb[3 * i + c] = float(std::sqrt(var / n));
    }
  }
  result.emitterMask = RgbImage(params.width, params.height);
  result.geometryMask = RgbImage(params.width, params.height);
  for (int y = 0; y < params.height; ++y) {
    for (int x = 0; x < params.width; ++x) {
      const float sx = (2.0f * (float(x) + 0.5f) / float(params.width) - 1.0f) * body.tanHalf *
                       body.aspect;
      const float sy = (1.0f - 2.0f * (float(y) + 0.5f) / float(params.height)) * body.tanHalf;
      const Vec3 dir = normalize(camera.forward + body.right * sx + camera.up * sy);
      Hit seen;
      const bool surface = tracer.intersectFromCamera(camera.eye, dir, seen);
      const bool emitter =
          surface && scene.materials[size_t(scene.triangleMaterial[seen.triangle])].isEmissive();
      const size_t i = size_t(y) * size_t(params.width) + size_t(x);
      for (int c = 0; c < 3; ++c) {
        result.emitterMask.rgb[3 * i + c] = emitter ? 0.0f : 1.0f;
        result.geometryMask.rgb[3 * i + c] = surface && !emitter ? 1.0f : 0.0f;
      }
    }
  }
  result.raysTraced = rays.load();
  result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

struct DirectIrradiance::Impl {
  reference_internal::Context ctx;
  std::unique_ptr<RayTracer> tracer;
};

DirectIrradiance::DirectIrradiance(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  checkSceneIndices(scene);
  reference_internal::buildContext(scene, ReferenceParams{}, impl_->ctx);
  impl_->tracer = std::make_unique<RayTracer>(scene);
  impl_->ctx.tracer = impl_->tracer.get();
  impl_->ctx.cameraTracer = impl_->tracer.get();
}

DirectIrradiance::~DirectIrradiance() = default;

Vec3 DirectIrradiance::at(const Vec3& p, uint32_t triangle, const Vec3& n, int samples,
                          uint64_t seed, uint64_t index, uint64_t* shadowRays) const {
  const reference_internal::Context& ctx = impl_->ctx;
  // A Lambertian lobe of albedo pi: f cos = cos, so the light sum is E.
  BsdfLobes lambert;
  const Vec3 albedo{kPi, kPi, kPi};
  Vec3 normal = ctx.scene->faceNormal(triangle);
  if (dot(normal, n) < 0) normal = -normal;
  Rng rng(seed, index);
  uint32_t rays = 0;
  const int count = std::max(samples, 1);
  // Punctual lights: exact, once, while they are no more than the samples
  // (each would be traced again for every sample to the same value), else
  // one draw from the light tree per sample, the draws stratified.
  const bool exact =
      ctx.lights.size() <= size_t(std::max(count, reference_internal::kPunctualDraws));
  const Vec3 punctual =
      exact ? reference_internal::allPunctualLights(ctx, p, normal, n, n, lambert, albedo, rays)
            : Vec3{0, 0, 0};
  Vec3 sum{0, 0, 0};
  for (int i = 0; i < count; ++i) {
    if (!exact) {
      sum += reference_internal::drawnPunctualLights(ctx, p, normal, n, n, lambert, albedo, rng,
                                                     rays, 1, i, count);
    }
    // The sky is not direct light here: the octree carries all of it.
    sum += reference_internal::sampleEmitters(ctx, p, normal, n, n, lambert, albedo, rng, rays,
                                              /*misWeights=*/false, /*withSky=*/false);
  }
  if (shadowRays) *shadowRays += rays;
  return punctual + sum / float(count);
}

std::vector<Vec3> DirectIrradiance::atMany(const std::vector<Point>& points, int samples,
                                           uint64_t seed, uint64_t firstIndex,
                                           const std::function<void()>& chunkDone) const {
  std::vector<Vec3> out(points.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, points.size(), 64),
                    [&](const tbb::blocked_range<size_t>& r) {
                      for (size_t i = r.begin(); i != r.end(); ++i) {
                        const Point& q = points[i];
                        out[i] = at(q.position, q.triangle, q.normal, samples, seed, firstIndex + i);
                        // After each point: a chunk at 256 samples took 1.5 s (H13-2-59).
                        if (chunkDone) chunkDone();
                      }
                    });
  return out;
}

}  // namespace lo

