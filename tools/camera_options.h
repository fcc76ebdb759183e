#pragma once
/// @file tools/camera_options.h
/// @brief The camera flags `render` and `reference` share: --camera NAME, or
/// --eye x,y,z with --target x,y,z, and --fov DEG. One parser, so both
/// commands see the same view from the same flags.

#include <string>

#include "core/error.h"
#include "core/math.h"
#include "scene/scene.h"

namespace CLI {
class App;
}

namespace lo::tool {

struct CameraOptions {
  std::string camera;       ///< scene camera by name; empty = the first one
  std::string eye, target;  ///< "x,y,z", both or neither
  float fovDegrees = 0;     ///< 0 = the scene camera's, else 45
};

/// Registers --camera, --eye, --target, --fov on `cmd`.
void addCameraOptions(CLI::App* cmd, CameraOptions& opt);

/// Checks what can be checked before the scene is loaded (--eye/--target
/// pairing and syntax). @throws InputError naming the flag.
void checkCameraOptions(const CameraOptions& opt);

/// "x,y,z" -> Vec3. @throws InputError naming `flag`.
Vec3 parseVec3(const std::string& text, const char* flag);

/// The chosen scene camera: null for --eye/--target or a scene without
/// cameras. @throws InputError naming --camera and the scene's cameras.
const Camera* findSceneCamera(const CameraOptions& opt, const Scene& scene,
                              const std::string& scenePath);

/// The view the flags select, in the conventions both renderers share
/// (`Cam` is RenderCamera or ReferenceCamera: fromScene, lookAt, framing).
/// Without --eye or a scene camera, the scene bounds are framed from +Z.
template <typename Cam>
Cam chooseCamera(const CameraOptions& opt, const Scene& scene, const std::string& scenePath) {
  const float fov = (opt.fovDegrees > 0 ? opt.fovDegrees : 45.0f) * kPi / 180.0f;
  if (!opt.eye.empty()) {
    const Vec3 eye = parseVec3(opt.eye, "--eye"), target = parseVec3(opt.target, "--target");
    if (eye == target) throw InputError("--eye and --target: the same point");
    return Cam::lookAt(eye, target, fov);
  }
  const Camera* chosen = findSceneCamera(opt, scene, scenePath);
  if (!chosen) return Cam::framing(scene.bounds(), fov);
  Cam camera = Cam::fromScene(*chosen);
  if (opt.fovDegrees > 0) camera.yfov = fov;
  return camera;
}

}  // namespace lo::tool
