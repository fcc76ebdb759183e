#pragma once
/// @file tools/camera_options.h
/// @brief The camera flags `render` and `reference` share: --camera NAME, or
/// --eye x,y,z with --target x,y,z, and --fov DEG. One parser, so both
/// commands see the same view from the same flags.

#include <string>

#include "core/math.h"
#include "scene/pinhole_camera.h"
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

/// "" for a camera name given, else what is wrong with it: an empty name
/// drew from the default camera without a word (H17-4-1). The rule of
/// --camera and of the Python module's camera=.
std::string cameraNameProblem(const std::string& name);

/// Checks what can be checked before the scene is loaded (--eye/--target
/// pairing and syntax). @throws InputError naming the flag.
void checkCameraOptions(const CameraOptions& opt);

/// "x,y,z" -> three finite numbers, any size (a radiance, a scale).
/// @throws InputError naming `flag`.
Vec3d parseThreeNumbers(const std::string& text, const char* flag);
/// "x,y,z" -> a position within kMaxCoordinate of the origin.
/// @throws InputError naming `flag`.
Vec3 parseVec3(const std::string& text, const char* flag);
/// The same in double (world positions, before Scene::toLocal).
Vec3d parseVec3d(const std::string& text, const char* flag);

/// The chosen scene camera: null for --eye/--target or a scene without
/// cameras. @throws InputError naming --camera and the scene's cameras.
const Camera* findSceneCamera(const CameraOptions& opt, const Scene& scene,
                              const std::string& scenePath);

/// The view the flags select (the GL renderer, the reference renderer and
/// the viewer share the camera type). Without --eye or a scene camera, the
/// scene bounds are framed from +Z. @throws InputError naming the flag.
PinholeCamera chooseCamera(const CameraOptions& opt, const Scene& scene,
                           const std::string& scenePath);

}  // namespace lo::tool
