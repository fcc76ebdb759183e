/// @file photon/ray_tracer.cpp
/// @brief Embree 3 scene setup and ray queries behind photon/ray_tracer.h.

#include "photon/ray_tracer.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <string>
#include <vector>

#include "core/error.h"

namespace lo {

struct RayTracer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<Vec3> faceNormals;

  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

namespace {

std::string errorCode(RTCDevice device) { return std::to_string(int(rtcGetDeviceError(device))); }

}  // namespace

RayTracer::RayTracer(const Scene& scene) : impl_(std::make_unique<Impl>()) {
  checkSceneIndices(scene);
  impl_->faceNormals.resize(scene.triangleCount());
  for (size_t t = 0; t < scene.triangleCount(); ++t) impl_->faceNormals[t] = scene.faceNormal(t);

  impl_->device = rtcNewDevice(nullptr);
  if (!impl_->device) throw InternalError("rtcNewDevice failed (error " + errorCode(nullptr) + ")");
  RTCDevice device = impl_->device;
  impl_->scene = rtcNewScene(device);
  // Robust traversal: the dragon has coincident opposite-winding triangles
  // and the closed test boxes must not leak rays through shared edges.
  rtcSetSceneFlags(impl_->scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_HIGH);
  if (scene.triangleCount() > 0) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Copied into Embree-owned buffers: Embree reads vertices as 16 bytes,
    // past the end of a tightly packed Vec3 array.
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), scene.positions.size()));
    auto* indices = static_cast<uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(uint32_t), scene.triangleCount()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geom);
      throw InternalError("Embree buffer allocation failed (error " + errorCode(device) + ")");
    }
    for (size_t i = 0; i < scene.positions.size(); ++i) {
      vertices[3 * i] = scene.positions[i].x;
      vertices[3 * i + 1] = scene.positions[i].y;
      vertices[3 * i + 2] = scene.positions[i].z;
    }
    std::copy(scene.indices.begin(), scene.indices.begin() + 3 * scene.triangleCount(), indices);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(impl_->scene, geom);
    rtcReleaseGeometry(geom);
  }
  rtcCommitScene(impl_->scene);
  if (rtcGetDeviceError(device) != RTC_ERROR_NONE)
    throw InternalError("Embree scene build failed (error " + errorCode(device) + ")");
}

RayTracer::~RayTracer() = default;

bool RayTracer::intersect(const Vec3& org, const Vec3& dir, Hit& hit, float tmax) const {
  RTCIntersectContext ictx;
  rtcInitIntersectContext(&ictx);
  RTCRayHit rh;
  rh.ray.org_x = org.x;
  rh.ray.org_y = org.y;
  rh.ray.org_z = org.z;
  rh.ray.tnear = 0.0f;
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
  rtcIntersect1(impl_->scene, &ictx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  hit.t = rh.ray.tfar;
  hit.triangle = rh.hit.primID;
  hit.b1 = rh.hit.u;
  hit.b2 = rh.hit.v;
  hit.geometricNormal = impl_->faceNormals[rh.hit.primID];
  return true;
}

bool RayTracer::occluded(const Vec3& org, const Vec3& dir, float tmax) const {
  RTCIntersectContext ictx;
  rtcInitIntersectContext(&ictx);
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
  rtcOccluded1(impl_->scene, &ictx, &ray);
  // Embree sets tfar to -inf when the ray is occluded.
  return ray.tfar < 0;
}

}  // namespace lo
