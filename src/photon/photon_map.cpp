/// @file photon/photon_map.cpp
/// @brief Photon tracing (paper §4.1) through raytrace/ray_tracer.h (Embree 3)
/// and the shared material model material/bsdf.h. See docs/photon.md for
/// the method, units and the determinism scheme.
///
/// Units: photon power is flux in W (RGB). A path starts with the power of its
/// emitter divided by the probability of picking that emitter; after tracing,
/// every stored power is divided once by the number of emitted paths, so the
/// sum of the bounce-0 photons estimates the total emitted power.

#include "photon/photon_map.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/partitioner.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>

#include "core/discrete_distribution.h"
#include "core/error.h"
#include "core/resources.h"
#include "core/rng.h"
#include "material/bsdf.h"
#include "photon/emission_guide.h"
#include "photon/light_footprint.h"
#include "raytrace/ray_tracer.h"
#include "scene/emitter_sampler.h"
#include "scene/sky_sampler.h"

namespace lo {

namespace photon_internal {

/// Paths per work item: the unit TBB schedules and the unit whose photons stay
/// in path order inside one buffer.
constexpr size_t kChunkPaths = 256;
/// A path ends after this many rays whatever its bounce count (passes
/// through thin walls do not count as bounces).
constexpr uint32_t kMaxPathRays = 1024;

/// Per-triangle data read at every hit.
struct TriangleInfo {
  Vec3 normal;  ///< unit geometric normal from the winding (Scene::faceNormal)
  uint32_t material = 0;
};

struct Emitter {
  enum class Kind { Point, Spot, Directional, Triangle, Sky };
  Kind kind = Kind::Point;
  uint32_t index = 0;  ///< into Scene::lights or triangle index
  uint32_t entry = 0;  ///< Triangle: its entry in Context::triangleEmitters
  Vec3 power;          ///< W, RGB, what this emitter actually emits
  /// W, RGB, the power of the distribution sampled before any rejection (a
  /// spot's full outer cone); also the selection weight (its average).
  Vec3 samplePower;
  Vec3 pathPower;  ///< samplePower / pick probability: the power a path starts with
  /// Directional: its footprint in Context::footprints, or -1 (no triangle
  /// to aim at: the covered box's silhouette).
  int footprint = -1;
  /// Point and spot lights outside the scene's bounding sphere: directions
  /// drawn in the cone the sphere subtends (axis, cosine of its half-angle)
  /// rather than over the whole sphere or spot cone, which would send most
  /// paths past every surface (aimAtScene). cosAim = -2: not aimed.
  Vec3 aimAxis{0, 0, 1};
  float cosAim = -2;
  /// Its pick weight is average(samplePower) times this: an emissive
  /// triangle's EmissionGuide::pickFactor, 1 for every other emitter.
  float pickFactor = 1;
};

/// How far around a region of interest the sun and the sky send photons, in
/// multiples of the region's size per side (emitBoxOfRegion).
constexpr float kRegionEmitMargin = 1.0f;

struct Context {
  const Scene* scene = nullptr;
  const RayTracer* tracer = nullptr;
  std::vector<TriangleInfo> triangles;
  std::vector<BsdfLobes> materials;
  std::vector<Emitter> emitters;
  /// Which emitter a path starts from: by average(samplePower), across kinds.
  DiscreteDistribution emitterPick;
  EmitterSampler triangleEmitters;  ///< the emissive triangles (where on them light starts)
  EmissionGuide emissionGuide;      ///< which way their light goes (PhotonParams::guideEmission)
  std::vector<LightFootprint> footprints;  ///< of the directional lights
  /// The sky's directions: an image's texels weighted by the covered box's
  /// silhouette seen from them; a uniform sky's hemisphere.
  SkySampler skySampler;
  Bounds3 bounds;
  Bounds3 region;       ///< photons stored only inside (empty: everywhere)
  /// What the sun and the sky cover: the bounds, or the region with a
  /// margin (emitBoxOfRegion).
  Bounds3 emitBounds;
  float epsilon = 0;
  /// Where a ray that hits nothing ends as a PhotonSegment: beyond the scene.
  float farDistance = 0;
  int maxBounces = 0;
  bool includeDirect = false;
  bool segments = false;  ///< PhotonParams::segments
  bool countDirect = false;  ///< PhotonParams::countDirect
  uint64_t seed = 0;
};

/// Photons and statistics of consecutive paths, in path order.
struct ChunkResult {
  std::vector<Photon> photons;
  std::vector<uint32_t> pathPhotons;  ///< stored photons per path
  std::vector<uint32_t> pathRays;     ///< rays per path
  std::vector<uint8_t> pathMissed;    ///< 1: the path's first ray hit nothing
  std::vector<uint32_t> pathLight;    ///< the emitter each path started from
  std::vector<Photon> direct;         ///< with countDirect: unstored direct first hits
  std::vector<uint8_t> pathDirect;    ///< direct first hits per path (0 or 1)
  std::vector<PhotonSegment> segments;   ///< with PhotonParams::segments
  std::vector<uint32_t> pathSegments;    ///< segments per path
};

inline Vec3 uniformSphere(float u1, float u2) {
  float z = 1.0f - 2.0f * u1;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Direction in the cone around +z with cos(theta) >= cosMax, uniform in solid angle.
inline Vec3 uniformCone(float u1, float u2, float cosMax) {
  float z = 1.0f - u1 * (1.0f - cosMax);
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

/// Power of a spot light with the glTF falloff integrated over the cone:
/// 2 pi I [(1 - cosInner) + (cosInner - cosOuter) / 3]. Light::power ignores
/// the falloff; the photons follow the falloff, so this is what they carry.
inline Vec3 spotPower(const Light& light) {
  float cosOuter = std::cos(light.outerConeAngle);
  float cosInner = std::max(cosOuter, std::cos(light.innerConeAngle));
  float solid = 2.0f * kPi * ((1.0f - cosInner) + (cosInner - cosOuter) / 3.0f);
  return light.color * light.intensity * solid;
}

inline Vec3 abs3(const Vec3& v) { return {std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}; }

/// Starting ray and power of one path. Returns false if the emitter sample
/// is rejected (spot falloff), which ends the path with no photon.
struct EmittedRay {
  Vec3 origin, direction, power;
  uint32_t light = 0;  ///< the emitter picked (Context::emitters)
  bool punctual = false;
  float range = 0;
  /// Stored at its first hit even without --include-direct: light the
  /// renderer does not draw per frame (the sky's) lives in the octree whole.
  bool storeFirstHit = false;
};

/// Where the sun and the sky send photons for a region of interest: the
/// region grown by kRegionEmitMargin of its size on every side, within the
/// scene's bounds. Light that lands just outside the region and bounces in
/// (a sunlit ground under a window) belongs to it; aiming at the region
/// alone left a room lit through a window 20% too dark.
inline Bounds3 emitBoxOfRegion(const Bounds3& region, const Bounds3& scene) {
  const Vec3 grow = region.extent() * kRegionEmitMargin;
  Bounds3 box;
  box.lower = max(region.lower - grow, scene.lower);
  box.upper = min(region.upper + grow, scene.upper);
  if (box.empty()) return region;
  box.lower = min(box.lower, region.lower);
  box.upper = max(box.upper, region.upper);
  return box;
}

/// A start for a ray travelling along `d` (unit) from beyond the scene into
/// the covered box (ctx.emitBounds): a point on one of the faces the ray
/// enters through, picked by their projected areas, moved back against `d`
/// to outside the whole scene (occluders beyond a region of interest still
/// cast). `projectedArea` receives the box's silhouette area seen along d,
/// what the start's density is one over. No path is spent on the empty
/// corners of a bounding disc.
inline Vec3 startThroughBox(const Context& ctx, const Vec3& d, Rng& rng, float& projectedArea) {
  const Bounds3& box = ctx.emitBounds;
  const Vec3 ext = box.extent();
  const float w[3] = {std::fabs(d.x) * ext.y * ext.z, std::fabs(d.y) * ext.x * ext.z,
                      std::fabs(d.z) * ext.x * ext.y};
  projectedArea = w[0] + w[1] + w[2];
  const float u0 = rng.uniform() * projectedArea;
  const int axis = u0 < w[0] ? 0 : (u0 < w[0] + w[1] ? 1 : 2);
  const float u1 = rng.uniform(), u2 = rng.uniform();
  Vec3 q;
  const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
  q[axis] = d[axis] > 0 ? box.lower[axis] : box.upper[axis];
  q[a1] = box.lower[a1] + u1 * ext[a1];
  q[a2] = box.lower[a2] + u2 * ext[a2];
  // Where the ray q - s d leaves the scene's bounds (and the box): the
  // nearest slab it crosses.
  Bounds3 all = ctx.bounds;
  all.extend(box);
  float exit = std::numeric_limits<float>::infinity();
  for (int i = 0; i < 3; ++i) {
    if (d[i] > 0) exit = std::min(exit, (q[i] - all.lower[i]) / d[i]);
    if (d[i] < 0) exit = std::min(exit, (q[i] - all.upper[i]) / d[i]);
  }
  return q - d * (std::max(0.0f, exit) + 4.0f * ctx.epsilon);
}

/// The silhouette area of the covered box seen along d (unit).
inline float boxSilhouette(const Bounds3& box, const Vec3& d) {
  const Vec3 e = box.extent();
  return std::fabs(d.x) * e.y * e.z + std::fabs(d.y) * e.x * e.z + std::fabs(d.z) * e.x * e.y;
}

/// A sky photon: a direction from Context::skySampler (an image's texels by
/// radiance times the covered box's silhouette and solid angle; a uniform
/// sky's hemisphere), a start through the box; the path carries
/// L A(d) / pdf(d) of the sky's power (Sky::power: pi L S / 2, or the same
/// sum over an image's texel centres).
inline bool emitFromSky(const Context& ctx, const Emitter& e, Rng& rng, EmittedRay& out) {
  const double u0 = ctx.scene->sky.image ? uniform53(rng) : 0.0;  // no texel to pick
  const float u1 = rng.uniform(), u2 = rng.uniform();
  Vec3 towards;
  float pdf = 0;
  if (!ctx.skySampler.sample(u0, u1, u2, towards, pdf)) return false;
  const Vec3 d = -towards;
  float area = 0;
  out.origin = startThroughBox(ctx, d, rng, area);
  out.direction = d;
  const Vec3 carried = ctx.scene->sky.radianceFrom(towards) * float(double(area) / double(pdf));
  for (int c = 0; c < 3; ++c) {
    out.power[c] = e.samplePower[c] > 0 ? out.power[c] * carried[c] / e.samplePower[c] : 0.0f;
  }
  out.storeFirstHit = true;
  return true;
}

inline bool emit(const Context& ctx, Rng& rng, EmittedRay& out) {
  const Scene& scene = *ctx.scene;
  // 53 random bits (scenes with millions of emissive triangles).
  const size_t k = ctx.emitterPick.sample(uniform53(rng));
  const Emitter& e = ctx.emitters[k];
  out.light = uint32_t(k);
  out.power = e.pathPower;
  out.punctual = false;
  out.storeFirstHit = false;
  out.range = 0;
  switch (e.kind) {
    case Emitter::Kind::Point: {
      const Light& light = scene.lights[e.index];
      out.origin = light.position;
      float u1 = rng.uniform(), u2 = rng.uniform();
      if (e.cosAim > -1.5f) {
        Vec3 t, b;
        orthonormalBasis(e.aimAxis, t, b);
        out.direction = normalize(fromLocal(uniformCone(u1, u2, e.cosAim), t, b, e.aimAxis));
      } else {
        out.direction = uniformSphere(u1, u2);
      }
      out.punctual = true;
      out.range = light.range;
      return true;
    }
    case Emitter::Kind::Spot: {
      const Light& light = scene.lights[e.index];
      float cosOuter = std::cos(light.outerConeAngle);
      float cosInner = std::max(cosOuter, std::cos(light.innerConeAngle));
      float u1 = rng.uniform(), u2 = rng.uniform();
      const Vec3 n = normalize(light.direction);
      // Uniform in the spot's outer cone, or in the narrower cone aimed at
      // the scene; then rejection against the falloff (0 outside the outer
      // cone) keeps every photon's power equal: the path carries the power
      // of the cone sampled (samplePower), the accepted fraction brings the
      // expectation down to spotPower.
      const bool aimed = e.cosAim > -1.5f;
      const Vec3 axis = aimed ? e.aimAxis : n;
      const Vec3 local = uniformCone(u1, u2, aimed ? e.cosAim : cosOuter);
      Vec3 t, b;
      orthonormalBasis(axis, t, b);
      const Vec3 d = normalize(fromLocal(local, t, b, axis));
      if (rng.uniform() >= spotFalloff(aimed ? dot(d, n) : local.z, cosInner, cosOuter)) return false;
      out.origin = light.position;
      out.direction = d;
      out.punctual = true;
      out.range = light.range;
      return true;
    }
    case Emitter::Kind::Directional: {
      const Light& light = scene.lights[e.index];
      // Aimed at the scene's footprint seen from the light (its power is
      // E times the footprint's area), else at the covered box's silhouette.
      const Vec3 d = normalize(light.direction);
      if (e.footprint >= 0) {
        const float u0 = rng.uniform(), u1 = rng.uniform(), u2 = rng.uniform();
        out.origin = ctx.footprints[size_t(e.footprint)].sample(u0, u1, u2);
      } else {
        float area = 0;
        out.origin = startThroughBox(ctx, d, rng, area);
      }
      out.direction = d;
      return true;
    }
    case Emitter::Kind::Sky:
      return emitFromSky(ctx, e, rng, out);
    case Emitter::Kind::Triangle: {
      size_t tri = e.index;
      const Vec3& p0 = scene.positions[scene.indices[3 * tri]];
      const Vec3& p1 = scene.positions[scene.indices[3 * tri + 1]];
      const Vec3& p2 = scene.positions[scene.indices[3 * tri + 2]];
      // An emissive texture: the triangle was picked by its mean radiance
      // and the point by its cells' (EmitterSampler::samplePoint); the
      // photon carries the ratio of the radiance where it starts to the
      // mean, times how much less likely than uniform its point was.
      // (Untextured: two numbers drawn, a uniform point, as always.)
      const bool textured = scene.materials[ctx.triangles[tri].material].emissiveTexture >= 0;
      float b1 = 0, b2 = 0, weight = 1;
      const float cell = textured ? rng.uniform() : 0.0f;
      const float a1 = rng.uniform(), a2 = rng.uniform();
      ctx.triangleEmitters.samplePoint(e.entry, cell, a1, a2, b1, b2, weight);
      Vec3 p = p0 + (p1 - p0) * b1 + (p2 - p0) * b2;
      Vec3 n = ctx.triangles[tri].normal;
      if (textured) {
        const Vec3& mean = ctx.triangleEmitters.emission[e.entry];
        const Vec3 here = scene.emission(tri, b1, b2);
        for (int c = 0; c < 3; ++c) out.power[c] *= mean[c] > 0 ? weight * here[c] / mean[c] : 0.0f;
      }
      // One-sided emitters emit on the side of the winding normal;
      // double-sided ones pick a side (their power counts both).
      const bool back =
          ctx.scene->materials[ctx.triangles[tri].material].doubleSided && rng.uniform() < 0.5f;
      if (back) n = -n;
      Vec3 t, b;
      orthonormalBasis(n, t, b);
      float u1 = 0, u2 = 0;
      if (ctx.emissionGuide.guided(e.entry, back)) {
        // Toward the cells whose probes met the scene (EmissionGuide).
        const float u0 = rng.uniform();
        u1 = rng.uniform();
        u2 = rng.uniform();
        float weight = 1;
        ctx.emissionGuide.sample(e.entry, back, u0, u1, u2, weight);
        out.power *= weight;
      } else {
        u1 = rng.uniform();
        u2 = rng.uniform();
      }
      out.direction = normalize(fromLocal(cosineHemisphere(u1, u2), t, b, n));
      out.origin = p + n * ctx.epsilon;
      return true;
    }
  }
  return false;
}

/// Russian roulette on the tint of one scattering event: survive with
/// probability min(1, max(tint)) and divide by it, so the expected power
/// after the event is exactly power * tint. Returns false if the path ends.
inline bool roulette(Rng& rng, const Vec3& tint, Vec3& power) {
  float q = std::min(1.0f, maxComponent(tint));
  if (!(q > 0)) return false;
  if (q < 1.0f && rng.uniform() >= q) return false;
  power *= tint / q;
  return true;
}

/// Traces path `pathIndex` and appends its stored photons (unscaled power) to `out`.
/// With ctx.segments, also appends to `segments` every ray whose light a
/// stored photon would carry (PhotonSegment), and counts them in segmentCount.
inline void tracePath(const Context& ctx, uint64_t pathIndex, std::vector<Photon>& out,
                      uint32_t& photonCount, uint32_t& rayCount, bool& missed, uint32_t& light,
                      std::vector<PhotonSegment>& segments, uint32_t& segmentCount,
                      std::vector<Photon>& direct, uint8_t& directCount) {
  Rng rng(ctx.seed, pathIndex);
  segmentCount = 0;
  directCount = 0;
  photonCount = 0;
  rayCount = 0;
  missed = false;
  EmittedRay start;
  const bool emitted = emit(ctx, rng, start);
  light = start.light;
  if (!emitted) return;
  Vec3 org = start.origin, dir = start.direction, power = start.power;
  // A black texel of an emissive texture: a path, but nothing to carry.
  if (!(maxComponent(power) > 0)) return;

  Hit hit;
  // Every scattering event so far was specular (a mirror, glass or a metal
  // too smooth to store photons): the next stored photon is a caustic's.
  bool specularChain = true;
  for (uint32_t bounce = 0;; ++bounce) {
    ++rayCount;
    // The light of this ray is what the octree holds (a photon at its end
    // would be stored): bounced light, the sky's, or direct with --include-direct.
    const bool held = bounce > 0 || ctx.includeDirect || start.storeFirstHit;
    if (!ctx.tracer->intersect(org, dir, hit)) {
      missed = bounce == 0;
      if (ctx.segments && held) {
        segments.push_back({org, org + dir * ctx.farDistance, power});
        ++segmentCount;
      }
      return;
    }

    float t = hit.t;
    // glTF range cut-off of punctual lights, applied as roulette at the first hit.
    if (bounce == 0 && start.punctual && start.range > 0 &&
        rng.uniform() >= rangeWindow(t, start.range))
      return;
    // From the ray parameter rather than the barycentrics: exactly coincident
    // triangles give the same t whichever of them Embree reports.
    Vec3 p = org + dir * t;
    if (ctx.segments && held) {
      segments.push_back({org, p, power});
      ++segmentCount;
    }
    const TriangleInfo& tri = ctx.triangles[hit.triangle];
    const BsdfLobes mat =
        bsdfLobesAt(*ctx.scene, ctx.materials[tri.material], hit.triangle, hit.b1, hit.b2);
    const Vec3& normal = hit.geometricNormal;
    bool frontFace = dot(dir, normal) < 0;
    Vec3 n = frontFace ? normal : -normal;  // faces the incoming side
    Vec3 wo = -dir;

    const bool inRegion =
        ctx.region.empty() || (p.x >= ctx.region.lower.x && p.y >= ctx.region.lower.y &&
                               p.z >= ctx.region.lower.z && p.x <= ctx.region.upper.x &&
                               p.y <= ctx.region.upper.y && p.z <= ctx.region.upper.z);
    const bool stored = bounce > 0 || ctx.includeDirect || start.storeFirstHit;
    const Vec3 albedo = ctx.scene->albedo(hit.triangle, hit.b1, hit.b2);
    if (mat.storesPhotons && inRegion && (stored || ctx.countDirect)) {
      Photon ph;
      setReflectance(ph, hemisphericalReflectance(mat, albedo));
      ph.position = p;
      ph.direction = wo;
      ph.power = power;
      ph.normal = n;
      ph.bounce = uint16_t(std::min<uint32_t>(bounce, 0xffffu));
      ph.caustic = bounce > 0 && specularChain ? 1 : 0;
      if (stored) {
        out.push_back(ph);
        ++photonCount;
      } else {
        direct.push_back(ph);  // counted, not stored (PhotonParams::countDirect)
        directCount = 1;
      }
    }
    if (int(bounce) >= ctx.maxBounces || rayCount > kMaxPathRays) return;

    // Scattering about the shading normal (vertex normals, the normal map),
    // as the path tracer and the renderer shade; the stored photon keeps the
    // geometric one, which the gather compares with the voxel's.
    const Vec3 ns = ctx.scene->shadingNormal(hit.triangle, hit.b1, hit.b2, n);
    BsdfSample sample;
    // A lost sample (GGX reflection below the surface) is the lobe's energy loss.
    if (!sampleBsdf(mat, albedo, wo, ns, frontFace, rng, sample)) return;
    // An opaque surface's reflection below its geometric plane (a tilted
    // shading normal) is lost too: no light through the surface.
    if (mat.transmissionWeight <= 0 && !(dot(sample.wi, n) > 0)) return;
    const Vec3& tint = sample.weight;
    const Vec3& newDir = sample.wi;
    if (!roulette(rng, tint, power)) return;
    dir = normalize(newDir);
    if (lengthSquared(dir) == 0) return;
    // Offset to the side the new ray leaves on (refraction crosses over).
    org = p + (dot(dir, normal) > 0 ? normal : -normal) * ctx.epsilon;
    // Through a thin wall the light is still direct light: the renderer
    // draws it so (thin-walled glass casts no shadow), so the photon keeps
    // its bounce count (--include-direct decides whether it is stored).
    if (sample.passThrough) {
      --bounce;
    } else {
      specularChain = specularChain && (sample.delta || !mat.storesPhotons);
    }
  }
}

/// Aims a point or spot light outside the scene's bounding sphere (grown by
/// 1%) at the sphere: its directions are drawn in the cone the sphere
/// subtends, when that cone is narrower than what the light would sample
/// (the whole sphere, a spot's outer cone), and the light's sample power
/// becomes its intensity times that cone's solid angle. No surface lies
/// outside the cone, so the photons' expected power on every surface is
/// unchanged (test PhotonAim.*), and a spot 10 m above a toy car no longer
/// sends almost all of its paths past it.
inline void aimAtScene(const Light& light, const Bounds3& bounds, Emitter& e) {
  if (bounds.empty()) return;
  const Vec3 centre = bounds.center();
  const float radius = 0.5f * length(bounds.extent()) * 1.01f + 1e-6f;
  const Vec3 toCentre = centre - light.position;
  const float d = length(toCentre);
  if (!(d > radius) || !std::isfinite(d)) return;
  const float sinAim = radius / d;
  const float cosAim = std::sqrt(std::max(0.0f, 1.0f - sinAim * sinAim));
  const float aimSolidAngle = 2.0f * kPi * (1.0f - cosAim);
  const float sampled = light.type == Light::Type::Spot
                            ? 2.0f * kPi * (1.0f - std::cos(light.outerConeAngle))
                            : 4.0f * kPi;
  if (!(aimSolidAngle < sampled)) return;
  e.aimAxis = toCentre / d;
  e.cosAim = cosAim;
  e.samplePower = light.color * (light.intensity * aimSolidAngle);
}

/// Which emitter a path starts from: by average(samplePower) times its
/// pickFactor, never the emitters `leftOut` (by index; empty: none); a path
/// starts with its emitter's sample power over that probability.
void pickEmitters(Context& ctx, const std::vector<bool>& leftOut);

/// Fills the emitter table; throws if the scene emits nothing.
inline void buildEmitters(const Scene& scene, Context& ctx, Vec3& totalPower) {
  totalPower = Vec3{0, 0, 0};
  // Directional lights of one direction share its footprint (a footprint
  // is a pass over every triangle; 10,000 suns made 10,000 of them), and
  // the footprints of different directions are made at once, in the order
  // of their first light: index -1 for one that covers nothing.
  std::map<std::array<float, 3>, int> footprintOf;
  {
    std::vector<Vec3> directions;
    std::vector<std::array<float, 3>> keys;
    for (const Light& light : scene.lights) {
      if (light.type != Light::Type::Directional) continue;
      const std::array<float, 3> key{light.direction.x, light.direction.y, light.direction.z};
      if (footprintOf.emplace(key, -1).second) {
        directions.push_back(light.direction);
        keys.push_back(key);
      }
    }
    std::vector<LightFootprint> made(directions.size());
    const float margin = 1e-3f * length(ctx.emitBounds.extent());
    tbb::parallel_for(size_t(0), directions.size(), [&](size_t d) {
      made[d] = LightFootprint(scene, directions[d], ctx.emitBounds, margin);
    });
    for (size_t d = 0; d < made.size(); ++d) {
      if (made[d].empty() || !std::isfinite(made[d].area())) continue;
      footprintOf[keys[d]] = int(ctx.footprints.size());
      ctx.footprints.push_back(std::move(made[d]));
    }
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& light = scene.lights[i];
    Emitter e;
    e.index = uint32_t(i);
    switch (light.type) {
      case Light::Type::Point:
        e.kind = Emitter::Kind::Point;
        e.power = light.power(ctx.bounds);
        break;
      case Light::Type::Spot:
        e.kind = Emitter::Kind::Spot;
        e.power = spotPower(light);
        e.samplePower = light.power(ctx.bounds);
        break;
      case Light::Type::Directional: {
        e.kind = Emitter::Kind::Directional;
        e.power = light.power(ctx.emitBounds);
        const int footprint =
            footprintOf.at({light.direction.x, light.direction.y, light.direction.z});
        if (footprint >= 0) {
          const double area = ctx.footprints[size_t(footprint)].area();
          e.power = light.color * float(double(light.intensity) * area);
          e.footprint = footprint;
        }
        break;
      }
    }
    if (light.type != Light::Type::Spot) e.samplePower = e.power;
    if (light.type != Light::Type::Directional) aimAtScene(light, ctx.bounds, e);
    if (!isFinite(e.samplePower))
      throw InputError("light " + std::to_string(i) + " '" + light.name +
                       "' has non-finite power " + e.samplePower.ToString());
    if (average(e.power) > 0) ctx.emitters.push_back(e);
  }
  if (scene.sky.present()) {
    Emitter e;
    e.kind = Emitter::Kind::Sky;
    e.power = scene.sky.power(ctx.emitBounds);
    e.samplePower = e.power;
    if (!isFinite(e.power)) {
      throw InputError("the sky has non-finite power " + e.power.ToString());
    }
    if (average(e.power) > 0) ctx.emitters.push_back(e);
    const Bounds3 box = ctx.emitBounds;
    ctx.skySampler =
        SkySampler(scene.sky, [box](const Vec3& d) { return boxSilhouette(box, d); });
  }
  ctx.triangleEmitters = buildEmitterSampler(scene);
  const EmitterSampler& triangles = ctx.triangleEmitters;
  for (size_t k = 0; k < triangles.size(); ++k) {
    Emitter e;
    e.kind = Emitter::Kind::Triangle;
    e.index = triangles.triangles[k];
    e.entry = uint32_t(k);
    e.power = triangles.power[k];
    e.samplePower = e.power;
    ctx.emitters.push_back(e);
  }
  double pickable = 0;
  for (const Emitter& e : ctx.emitters) {
    pickable += double(average(e.samplePower));
    totalPower += e.power;
  }
  if (ctx.emitters.empty() || !(pickable > 0)) {
    std::ostringstream os;
    os << "scene has no light with positive power (" << scene.lights.size()
       << " punctual lights, no emissive triangle with positive emission, no sky) in '"
       << scene.sourcePath
       << "'";
    throw InputError(os.str());
  }
  pickEmitters(ctx, {});
}

void pickEmitters(Context& ctx, const std::vector<bool>& leftOut) {
  DiscreteDistribution pick;
  pick.reserve(ctx.emitters.size());
  for (size_t k = 0; k < ctx.emitters.size(); ++k) {
    const Emitter& e = ctx.emitters[k];
    const bool out = !leftOut.empty() && leftOut[k];
    pick.add(out ? 0.0 : double(average(e.samplePower)) * double(e.pickFactor));
  }
  ctx.emitterPick = std::move(pick);
  for (size_t k = 0; k < ctx.emitters.size(); ++k) {
    Emitter& e = ctx.emitters[k];
    const double pmf = ctx.emitterPick.pmf(k);
    e.pathPower = pmf > 0 ? e.samplePower * float(1.0 / pmf) : Vec3{0, 0, 0};
  }
}

/// TBB body: traces the chunks [r.begin(), r.end()) of a batch.
struct TraceChunks {
  const Context* ctx;
  std::vector<ChunkResult>* chunks;
  uint64_t firstPath;
  size_t batchPaths;

  void operator()(const tbb::blocked_range<size_t>& r) const {
    for (size_t c = r.begin(); c != r.end(); ++c) {
      ChunkResult& out = (*chunks)[c];
      out.photons.clear();
      out.pathPhotons.clear();
      out.pathRays.clear();
      out.pathMissed.clear();
      out.pathLight.clear();
      out.direct.clear();
      out.pathDirect.clear();
      out.segments.clear();
      out.pathSegments.clear();
      size_t begin = c * kChunkPaths, end = std::min(batchPaths, begin + kChunkPaths);
      for (size_t i = begin; i < end; ++i) {
        uint32_t photons = 0, rays = 0, segments = 0, light = 0;
        uint8_t direct = 0;
        bool missed = false;
        tracePath(*ctx, firstPath + i, out.photons, photons, rays, missed, light, out.segments,
                  segments, out.direct, direct);
        if (ctx->countDirect) out.pathDirect.push_back(direct);
        if (ctx->segments) out.pathSegments.push_back(segments);
        out.pathPhotons.push_back(photons);
        out.pathRays.push_back(rays);
        out.pathMissed.push_back(missed ? 1 : 0);
        out.pathLight.push_back(light);
      }
    }
  }
};

}  // namespace photon_internal

/// The tracing context of one scene: the emitters, materials and the Embree
/// scene, in a frame centred on the scene when it lies far from the origin
/// (Scene::tracingOrigin): only the stored photons' final positions round
/// to world floats.
struct PhotonTracer::State {
  std::unique_ptr<Scene> shifted;  ///< the scene moved by -origin, when origin is not 0
  Vec3 origin{0, 0, 0};
  photon_internal::Context ctx;
  std::unique_ptr<RayTracer> tracer;
  Vec3 emittedPower{0, 0, 0};
  mutable std::vector<photon_internal::ChunkResult> chunks;
  std::vector<uint32_t> lightGroup;     ///< per emitter: its group (lightNames)
  std::vector<std::string> lightNames;  ///< per group
};

namespace photon_internal {

std::string formatPoint(const Vec3& p) {
  std::ostringstream os;
  os << "(" << p.x << ", " << p.y << ", " << p.z << ")";
  return os.str();
}

/// The emitters as a person names them: each punctual light, the sky, and
/// the emissive triangles of one material together (with where they lie),
/// in world space (`origin` added back).
void nameLightGroups(const Context& ctx, const Vec3& origin, std::vector<uint32_t>& group,
                     std::vector<std::string>& names) {
  const Scene& scene = *ctx.scene;
  struct Emissive {
    size_t material = 0, triangles = 0, group = 0;
    Bounds3 bounds;
  };
  std::vector<int> slotOfMaterial(scene.materials.size(), -1);
  std::vector<Emissive> emissive;
  group.assign(ctx.emitters.size(), 0);
  for (size_t k = 0; k < ctx.emitters.size(); ++k) {
    const Emitter& e = ctx.emitters[k];
    if (e.kind == Emitter::Kind::Triangle) {
      const size_t m = ctx.triangles[e.index].material;
      if (slotOfMaterial[m] < 0) {
        slotOfMaterial[m] = int(emissive.size());
        emissive.push_back({m, 0, names.size(), Bounds3()});
        names.emplace_back();  // named below, once its bounds are known
      }
      Emissive& slot = emissive[size_t(slotOfMaterial[m])];
      for (int v = 0; v < 3; ++v)
        slot.bounds.extend(scene.positions[scene.indices[3 * e.index + v]] + origin);
      ++slot.triangles;
      group[k] = uint32_t(slot.group);
      continue;
    }
    group[k] = uint32_t(names.size());
    if (e.kind == Emitter::Kind::Sky) {
      names.push_back("the sky");
      continue;
    }
    const Light& light = scene.lights[e.index];
    const std::string name = light.name.empty() ? "" : " '" + light.name + "'";
    if (e.kind == Emitter::Kind::Directional) {
      names.push_back("directional light" + name);
    } else {
      names.push_back((e.kind == Emitter::Kind::Spot ? "spot light" : "point light") + name +
                      " at " + formatPoint(light.position + origin));
    }
  }
  for (const Emissive& slot : emissive) {
    names[slot.group] = formatCount(slot.triangles) + " emissive triangle(s) of material '" +
                        scene.materials[slot.material].name + "' within " +
                        formatPoint(slot.bounds.lower) + " - " + formatPoint(slot.bounds.upper);
  }
}

}  // namespace photon_internal

PhotonTracer::PhotonTracer(const Scene& scene, const PhotonParams& params)
    : state_(std::make_unique<State>()) {
  using namespace photon_internal;
  if (params.maxBounces < 0)
    throw InputError("PhotonParams.maxBounces must be >= 0, got " +
                     std::to_string(params.maxBounces));
  State& st = *state_;
  st.origin = scene.tracingOrigin();
  Bounds3 region = params.region;
  if (st.origin != Vec3{0, 0, 0}) {
    st.shifted = std::make_unique<Scene>(scene.translated(-st.origin));
    if (!region.empty()) {
      region.lower -= st.origin;
      region.upper -= st.origin;
    }
  }
  const Scene& traced = st.shifted ? *st.shifted : scene;
  checkSceneIndices(traced);

  Context& ctx = st.ctx;
  ctx.scene = &traced;
  ctx.bounds = traced.bounds();
  ctx.region = region;
  ctx.emitBounds = region.empty() ? ctx.bounds : emitBoxOfRegion(region, ctx.bounds);
  ctx.maxBounces = params.maxBounces;
  ctx.includeDirect = params.includeDirect;
  ctx.segments = params.segments;
  ctx.countDirect = params.countDirect;
  ctx.seed = params.seed;

  ctx.triangles.resize(traced.triangleCount());
  for (size_t t = 0; t < traced.triangleCount(); ++t) {
    const int32_t m = traced.triangleMaterial[t];
    ctx.triangles[t].normal = traced.faceNormal(t);
    ctx.triangles[t].material = uint32_t(m);
  }
  ctx.materials.resize(traced.materials.size());
  for (size_t i = 0; i < traced.materials.size(); ++i) {
    ctx.materials[i] = bsdfLobes(traced.materials[i]);
  }
  buildEmitters(traced, ctx, st.emittedPower);
  nameLightGroups(ctx, st.origin, st.lightGroup, st.lightNames);
  if (traced.triangleCount() == 0) return;

  Vec3 ext = ctx.bounds.extent();
  float scale = length(ext) + maxComponent(max(abs3(ctx.bounds.lower), abs3(ctx.bounds.upper)));
  ctx.epsilon = kRayEpsilonScale * std::max(scale, 1e-6f);
  ctx.farDistance = 2.0f * std::max(scale, 1e-6f);
  st.tracer = std::make_unique<RayTracer>(traced);
  ctx.tracer = st.tracer.get();
  if (params.guideEmission && !ctx.triangleEmitters.empty()) {
    ctx.emissionGuide =
        EmissionGuide(traced, ctx.triangleEmitters, *st.tracer, ctx.epsilon, ctx.farDistance);
    for (Emitter& e : ctx.emitters) {
      if (e.kind == Emitter::Kind::Triangle) e.pickFactor = ctx.emissionGuide.pickFactor(e.entry);
    }
    pickEmitters(ctx, {});
  }
}

PhotonTracer::~PhotonTracer() = default;

Vec3 PhotonTracer::emittedPower() const { return state_->emittedPower; }

bool PhotonTracer::canStore() const { return state_->tracer != nullptr; }

const std::vector<std::string>& PhotonTracer::lightNames() const { return state_->lightNames; }

void PhotonTracer::leaveOut(const std::vector<uint32_t>& lights) {
  using namespace photon_internal;
  State& st = *state_;
  std::vector<bool> out(st.lightNames.size(), false);
  for (uint32_t k : lights) {
    if (k < out.size()) out[k] = true;
  }
  Context& ctx = st.ctx;
  std::vector<bool> leftOut(ctx.emitters.size(), false);
  bool any = false;
  for (size_t k = 0; k < ctx.emitters.size(); ++k) {
    leftOut[k] = out[st.lightGroup[k]];
    any = any || (!leftOut[k] && average(ctx.emitters[k].samplePower) > 0);
  }
  if (!any) throw InputError("PhotonTracer::leaveOut: every light would be left out");
  pickEmitters(ctx, leftOut);
}

void PhotonTracer::trace(uint64_t first, size_t count, const PathSink& onPath,
                         const SegmentSink& onSegments, const DirectSink& onDirect) const {
  using namespace photon_internal;
  if (count == 0) return;
  if (!state_->tracer) {
    for (size_t i = 0; i < count; ++i) {
      if (!onPath(nullptr, 0, 0, true, 0)) return;
    }
    return;
  }
  std::vector<ChunkResult>& chunks = state_->chunks;
  const size_t nChunks = (count + kChunkPaths - 1) / kChunkPaths;
  if (chunks.size() < nChunks) chunks.resize(nChunks);
  TraceChunks body{&state_->ctx, &chunks, first, count};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nChunks, 1), body, tbb::simple_partitioner());
  const Vec3 origin = state_->origin;
  for (size_t c = 0; c < nChunks; ++c) {
    ChunkResult& chunk = chunks[c];
    if (origin != Vec3{0, 0, 0}) {
      for (Photon& photon : chunk.photons) photon.position += origin;
      for (Photon& photon : chunk.direct) photon.position += origin;
      for (PhotonSegment& segment : chunk.segments) {
        segment.from += origin;
        segment.to += origin;
      }
    }
    const Photon* photons = chunk.photons.data();
    const PhotonSegment* segments = chunk.segments.data();
    const Photon* direct = chunk.direct.data();
    for (size_t i = 0; i < chunk.pathPhotons.size(); ++i) {
      if (!chunk.pathDirect.empty()) {
        if (onDirect) onDirect(direct, chunk.pathDirect[i]);
        direct += chunk.pathDirect[i];
      }
      if (onSegments && !chunk.pathSegments.empty()) {
        onSegments(segments, chunk.pathSegments[i]);
        segments += chunk.pathSegments[i];
      }
      const uint32_t group = state_->lightGroup[chunk.pathLight[i]];
      if (!onPath(photons, chunk.pathPhotons[i], chunk.pathRays[i], chunk.pathMissed[i] != 0,
                  group)) {
        return;
      }
      photons += chunk.pathPhotons[i];
    }
  }
}

void PhotonTracer::trace(uint64_t first, size_t count, std::vector<Photon>& photons,
                         std::vector<uint32_t>& pathPhotons) const {
  pathPhotons.reserve(pathPhotons.size() + count);
  trace(first, count, [&](const Photon* path, uint32_t n, uint32_t, bool, uint32_t) {
    if (n > 0) photons.insert(photons.end(), path, path + n);
    pathPhotons.push_back(n);
    return true;
  });
}

PhotonMap tracePhotons(const Scene& scene, const PhotonParams& params, ProgressSink* progress) {
  PhotonTracer tracer(scene, params);
  PhotonMap map;
  map.emittedPower = tracer.emittedPower();
  if (params.storedPhotons == 0 || !tracer.canStore()) return map;

  const size_t target = params.storedPhotons;
  const size_t maxEmitted = maxEmittedPaths(params);
  Progress bar(progress, "Tracing photons", target);
  map.photons.reserve(target);

  size_t emitted = 0;  // paths whose photons are in map.photons
  size_t empty = 0;    // of those, paths that stored nothing
  size_t rays = 0;
  // Each path's photons go straight into the map, in path order; the path
  // that reaches the target is the last one taken.
  size_t missed = 0;   // of those, paths whose first ray hit nothing
  LightReach reach;
  const PhotonTracer::PathSink take = [&](const Photon* photons, uint32_t n, uint32_t pathRays,
                                          bool pathMissed, uint32_t light) {
    missed += pathMissed;
    reach.add(light, n);
    const size_t kept = std::min<size_t>(n, target - map.photons.size());
    if (kept > 0) map.photons.insert(map.photons.end(), photons, photons + kept);
    rays += pathRays;
    ++emitted;
    empty += n == 0;
    return map.photons.size() < target;
  };
  SegmentCollector collector(params.maxSegments);
  const PhotonTracer::SegmentSink keepSegments =
      params.segments ? PhotonTracer::SegmentSink([&](const PhotonSegment* segments, uint32_t n) {
        collector.addPath(segments, n);
      })
                      : PhotonTracer::SegmentSink();
  while (map.photons.size() < target) {
    const size_t batch = photonBatchPaths(target, map.photons.size(), emitted, maxEmitted);
    if (batch == 0) break;
    const size_t before = map.photons.size();
    tracer.trace(uint64_t(emitted), batch, take, keepSegments);
    bar.advance(map.photons.size() - before);
  }

  map.emittedPaths = emitted;
  map.emptyPaths = empty;
  map.missedPaths = missed;
  map.raysTraced = rays;
  map.darkLights = reach.dark(tracer.lightNames());
  scalePhotonPower(map.photons, emitted);
  map.segments = collector.take();
  return map;
}

}  // namespace lo
