/// @file photon/ray_tracer.cpp
/// @brief Embree 3 scene setup and ray queries behind raytrace/ray_tracer.h.

#include "raytrace/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/resources.h"

namespace lo {

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<Vec3> faceNormals;
  /// Per triangle: whether the rasteriser culls its back (a glTF material
  /// not doubleSided): camera rays pass through it from behind.
  std::vector<uint8_t> cullsBack;
  /// A copy of the scene when some material has alpha (Mask or Blend): the
  /// filter below reads its coverage; null otherwise (no filter installed).
  std::unique_ptr<Scene> alphaScene;
  std::string lastError;  ///< Embree's text of its last error (rtcSetDeviceErrorFunction)

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

/// An Embree call that failed with `error` (rtcGetDeviceError, read once: it
/// clears the error, and a second read said "error 0"). Out of memory is the
/// machine's or the process's limit (ulimit -v), said as such, as the memory
/// checks before the work say it: "rtcNewDevice failed (error 4)" told
/// nothing. Anything else is a broken invariant.
/// `text`: Embree's own words, when it gave them (a build under ulimit -v
/// fails as RTC_ERROR_UNKNOWN, "pthread_create has failed": a thread's stack
/// is address space too).
[[noreturn]] void embreeFailed(const std::string& what, RTCError error,
                               const std::string& text = "") {
  const bool threads = text.find("pthread_create") != std::string::npos &&
                       addressSpaceRoomBytes() != SIZE_MAX;
  if (error == RTC_ERROR_OUT_OF_MEMORY || text.find("bad_alloc") != std::string::npos ||
      threads) {
    throw InputError("out of memory: the ray tracer (Embree) could not " + what +
                     (text.empty() ? "" : " (" + text + ")") + ": " + memoryShortfall());
  }
  throw InternalError("Embree could not " + what + " (error " + std::to_string(int(error)) +
                      (text.empty() ? "" : ": " + text) + ")");
}

void recordError(void* text, RTCError, const char* str) {
  *static_cast<std::string*>(text) = str ? str : "";
}

uint32_t floatBits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

/// A uniform number in [0, 1) from the ray and the triangle it hits: the
/// same ray through the same triangle always decides the same way, so
/// blended surfaces pass a fixed share of rays whatever the thread count.
float rayHash(uint32_t prim, const float org[3], const float dir[3]) {
  uint64_t h = 0x9E3779B97F4A7C15ull ^ prim;
  auto mix = [&h](uint32_t v) {
    h ^= v;
    h *= 0xFF51AFD7ED558CCDull;
    h ^= h >> 33;
  };
  for (int k = 0; k < 3; ++k) {
    mix(floatBits(org[k]));
    mix(floatBits(dir[k]));
  }
  h *= 0xC4CEB9FE1A85EC53ull;
  h ^= h >> 33;
  return float(h >> 40) * 0x1p-24f;
}

/// An intersection context that says whether the ray comes from the camera
/// (the only rays that see unlit surfaces, Material::unlit).
struct TracingContext {
  RTCIntersectContext embree;  // first: Embree hands the filter its address
  bool fromCamera = false;
};

/// Embree filter (intersection and occlusion): a hit where the material's
/// coverage (Scene::coverage: alpha against the cutoff for Mask, alpha for
/// Blend) says there is no surface is rejected, and the ray goes on; so is
/// a hit on an unlit surface by a ray that does not come from the camera.
void alphaFilter(const RTCFilterFunctionNArguments* args) {
  const Scene& scene = *static_cast<const Scene*>(args->geometryUserPtr);
  const bool fromCamera = reinterpret_cast<const TracingContext*>(args->context)->fromCamera;
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] != -1) continue;
    const uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
    const float b1 = RTCHitN_u(args->hit, args->N, i), b2 = RTCHitN_v(args->hit, args->N, i);
    const Material& m = scene.materials[size_t(scene.triangleMaterial[prim])];
    if (m.unlit && !fromCamera) {
      args->valid[i] = 0;
      continue;
    }
    if (!m.hasAlpha()) continue;
    const float coverage = scene.coverage(prim, b1, b2);
    if (coverage >= 1.0f) continue;
    bool keep = false;
    if (coverage > 0.0f) {
      RTCRayN* ray = args->ray;
      const float org[3] = {RTCRayN_org_x(ray, args->N, i), RTCRayN_org_y(ray, args->N, i),
                            RTCRayN_org_z(ray, args->N, i)};
      const float dir[3] = {RTCRayN_dir_x(ray, args->N, i), RTCRayN_dir_y(ray, args->N, i),
                            RTCRayN_dir_z(ray, args->N, i)};
      keep = rayHash(prim, org, dir) < coverage;
    }
    if (!keep) args->valid[i] = 0;
  }
}

}  // namespace

RayTracer::RayTracer(const Scene& scene) : RayTracer(scene, Objects::All) {}

RayTracer::RayTracer(const Scene& scene, Objects objects) : impl_(std::make_unique<Impl>()) {
  checkSceneIndices(scene);
  size_t triangles = scene.triangleCount();
  if (objects == Objects::AsBaked && scene.movingMaterialsFrom != SIZE_MAX) {
    while (triangles > 0 && scene.isAdded(triangles - 1)) --triangles;
    for (size_t t = 0; t < triangles; ++t) {
      if (scene.isAdded(t))
        throw InternalError("RayTracer: added objects' triangles must come last (triangle " +
                            std::to_string(t) + ")");
    }
  }
  impl_->faceNormals.resize(scene.triangleCount());
  for (size_t t = 0; t < scene.triangleCount(); ++t) impl_->faceNormals[t] = scene.faceNormal(t);
  impl_->cullsBack.resize(scene.triangleCount());
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const int m = scene.triangleMaterial[t];
    const bool culls = m >= 0 && size_t(m) < scene.materials.size() &&
                       scene.materials[size_t(m)].backFaceCulling &&
                       !scene.materials[size_t(m)].doubleSided;
    impl_->cullsBack[t] = culls ? 1 : 0;
  }

  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) embreeFailed("start (rtcNewDevice)", rtcGetDeviceError(nullptr));
  RTCDevice device = impl_->device;
  rtcSetDeviceErrorFunction(device, recordError, &impl_->lastError);
  impl_->scene = rtcNewScene(device);
  // Robust traversal: the dragon has coincident opposite-winding triangles
  // and the closed test boxes must not leak rays through shared edges.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (triangles > 0) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Copied into Embree-owned buffers: Embree reads vertices as 16 bytes,
    // past the end of a tightly packed Vec3 array.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), scene.positions.size()));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), triangles));
    if (!vertices || !indices) {
      const RTCError error = rtcGetDeviceError(device);
      rtcReleaseGeometry(geom);
      embreeFailed("allocate the scene's buffers", error, impl_->lastError);
    }
    for (size_t i = 0; i < scene.positions.size(); ++i) {
      vertices[3 * i] = scene.positions[i].x;
      vertices[3 * i + 1] = scene.positions[i].y;
      vertices[3 * i + 2] = scene.positions[i].z;
    }
    std::copy(scene.indices.begin(), scene.indices.begin() + 3 * triangles, indices);
    bool alpha = false;
    for (const Material& m : scene.materials) alpha = alpha || m.hasAlpha() || m.unlit;
    if (alpha) {
      impl_->alphaScene = std::make_unique<Scene>(scene);
      rtcSetGeometryUserData(geom, impl_->alphaScene.get());
      rtcSetGeometryIntersectFilterFunction(geom, alphaFilter);
      rtcSetGeometryOccludedFilterFunction(geom, alphaFilter);
    }
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(impl_->scene);
  if (const RTCError error = rtcGetDeviceError(device); error != RTC_ERROR_NONE) {
    embreeFailed("build the scene's hierarchy", error, impl_->lastError);
  }
}

RayTracer::~RayTracer() = default;

bool RayTracer::intersect(const Vec3& org, const Vec3& dir, Hit& hit, float tmax) const {
  return trace(org, dir, hit, 0.0f, tmax, false);
}

bool RayTracer::intersectBetween(const Vec3& org, const Vec3& dir, Hit& hit, float tmin,
                                 float tmax) const {
  return trace(org, dir, hit, tmin, tmax, false);
}

bool RayTracer::intersectFromCamera(const Vec3& org, const Vec3& dir, Hit& hit) const {
  // Past the backs of culled faces, as the rasteriser draws them (a bounded
  // number: a ray through a stack of culled sheets ends at the last).
  float from = 0.0f;
  for (int skipped = 0; skipped < 64; ++skipped) {
    if (!trace(org, dir, hit, from, std::numeric_limits<float>::infinity(), true)) return false;
    if (!impl_->cullsBack[hit.triangle] || dot(dir, hit.geometricNormal) < 0) return true;
    from = std::nextafter(hit.t, std::numeric_limits<float>::infinity());
  }
  return true;
}

namespace {

/// Embree asserts on a ray whose origin or direction has a coordinate beyond
/// +-1.844e18 (its FLT_LARGE) or not finite (RayK::valid; Debian builds it
/// with assertions): such a ray, which extreme settings can make (a gather
/// radius of 1e19 scene units), meets nothing here instead of aborting.
bool traceable(const Vec3& org, const Vec3& dir, float tmin, float tmax) {
  constexpr float kLargest = 1.8e18f;
  const auto within = [](const Vec3& v) {
    return std::fabs(v.x) <= kLargest && std::fabs(v.y) <= kLargest && std::fabs(v.z) <= kLargest;
  };
  return within(org) && within(dir) && tmin <= tmax;
}

}  // namespace

bool RayTracer::trace(const Vec3& org, const Vec3& dir, Hit& hit, float tmin, float tmax,
                      bool fromCamera) const {
  if (!traceable(org, dir, tmin, tmax)) return false;
  TracingContext context;
  rtcInitIntersectContext(&context.embree);
  context.fromCamera = fromCamera;
  RTCRayHit rh;
  rh.ray.org_x = org.x;
  rh.ray.org_y = org.y;
  rh.ray.org_z = org.z;
  rh.ray.tnear = tmin;
  rh.ray.dir_x = dir.x;
  rh.ray.dir_y = dir.y;
  rh.ray.dir_z = dir.z;
  rh.ray.time = 0.0f;
  rh.ray.tfar = tmax;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &context.embree, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.triangle = rh.hit.primID;
  hit.b1 = rh.hit.u;
  hit.b2 = rh.hit.v;
  hit.geometricNormal = impl_->faceNormals[rh.hit.primID];
  return true;
}

bool RayTracer::occluded(const Vec3& org, const Vec3& dir, float tmax) const {
  if (!traceable(org, dir, 0.0f, tmax)) return false;
  TracingContext context;
  rtcInitIntersectContext(&context.embree);
  RTCRay ray;
  ray.org_x = org.x;
  ray.org_y = org.y;
  ray.org_z = org.z;
  ray.tnear = 0.0f;
  ray.dir_x = dir.x;
  ray.dir_y = dir.y;
  ray.dir_z = dir.z;
  ray.time = 0.0f;
  ray.tfar = tmax;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  rtcOccluded1(impl_->scene, &context.embree, &ray);
  // Embree sets tfar to -inf when the ray is occluded.
  return ray.tfar < 0;
}

}  // namespace lo
