#pragma once
/// @file raytrace/ray_tracer.h
/// @brief Closest-hit and shadow rays against a Scene's triangles. The only
/// place Embree is set up; the public API is plain values so that other
/// stages (src/reference) trace rays without seeing Embree.

#include <cstdint>
#include <limits>
#include <memory>

#include "core/math.h"
#include "scene/scene.h"

namespace lo {

/// Closest intersection along a ray.
struct Hit {
  float t = 0;            ///< ray parameter: hit point = org + dir * t (dir need not be unit)
  uint32_t triangle = 0;  ///< index into the Scene's triangles
  float b1 = 0, b2 = 0;   ///< barycentrics of vertices 1 and 2 (Scene::albedo's b1, b2)
  Vec3 geometricNormal;   ///< unit, from the winding: exactly Scene::faceNormal(triangle)
};

/// An acceleration structure over the scene (Embree 3, robust traversal so
/// that closed meshes do not leak rays through shared edges). Built once;
/// intersect/occluded are thread-safe. The Scene must outlive nothing: the
/// geometry is copied.
class RayTracer {
 public:
  /// @throws InputError when a triangle's vertex index is out of range;
  /// InternalError when Embree fails.
  explicit RayTracer(const Scene& scene);
  /// Which triangles the structure holds.
  enum class Objects {
    All,
    /// Every triangle but those of objects added after the bake
    /// (Scene::isAdded), which come last: the scene as it was baked.
    AsBaked,
  };
  RayTracer(const Scene& scene, Objects objects);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  /// Closest hit with t in [0, tmax]. Returns false (hit untouched) on a miss.
  bool intersect(const Vec3& org, const Vec3& dir, Hit& hit,
                 float tmax = std::numeric_limits<float>::infinity()) const;
  /// Closest hit with t in [tmin, tmax]: the next surface along a ray
  /// already stopped at tmin, from the same origin (no new origin to round).
  bool intersectBetween(const Vec3& org, const Vec3& dir, Hit& hit, float tmin, float tmax) const;
  /// True if anything lies along the ray with t in [0, tmax].
  bool occluded(const Vec3& org, const Vec3& dir, float tmax) const;
  /// intersect for a ray from the camera: what the rasteriser shows. The
  /// only rays that see unlit surfaces (Material::unlit; every other query
  /// passes through them), and rays that pass through the back of a face
  /// whose material the rasteriser culls (glTF's doubleSided false); light
  /// meets both sides of every surface.
  bool intersectFromCamera(const Vec3& org, const Vec3& dir, Hit& hit) const;

 private:
  bool trace(const Vec3& org, const Vec3& dir, Hit& hit, float tmin, float tmax,
             bool fromCamera) const;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lo
