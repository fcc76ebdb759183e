#include "camera_options.h"

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <sstream>

#include "cli_checks.h"
#include "core/error.h"
#include "core/printable.h"

namespace lo::tool {

std::string cameraNameProblem(const std::string& name) {
  return name.empty() ? "an empty name: name one of the scene's cameras, or leave it out for the "
                        "first"
                      : "";
}

void addCameraOptions(CLI::App* cmd, CameraOptions& opt) {
  auto* camera = cmd->add_option("--camera", opt.camera, "Scene camera by name (default: first)")
                     ->check(cameraNameProblem, "NAME");
  auto* eye = cmd->add_option("--eye", opt.eye, "Camera position x,y,z (with --target)");
  cmd->add_option("--target", opt.target, "Point the camera looks at, x,y,z (with --eye)");
  camera->excludes(eye);
  cmd->add_option("--fov", opt.fovDegrees, "Vertical field of view in degrees (default 45)")
      ->check(numberIn(kFovDegreesRange));
}

Vec3d parseThreeNumbers(const std::string& text, const char* flag) {
  Vec3d v;
  char c1 = 0, c2 = 0;
  std::istringstream is(text);
  if (!(is >> v.x >> c1 >> v.y >> c2 >> v.z) || c1 != ',' || c2 != ',' || !is.eof() ||
      !std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) {
    throw InputError(std::string(flag) + ": expected three numbers x,y,z, got '" + text + "'");
  }
  return v;
}

Vec3d parseVec3d(const std::string& text, const char* flag) {
  const Vec3d v = parseThreeNumbers(text, flag);
  if (std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > double(kMaxCoordinate)) {
    throw InputError(std::string(flag) + ": '" + text +
                     "' lies beyond 1e12 scene units from the origin, where no scene reaches");
  }
  return v;
}

Vec3 parseVec3(const std::string& text, const char* flag) { return parseVec3d(text, flag).toVec3(); }

void checkCameraOptions(const CameraOptions& opt) {
  if (!opt.eye.empty() != !opt.target.empty()) {
    throw InputError("--eye and --target must be given together");
  }
  if (!opt.eye.empty()) {
    parseVec3(opt.eye, "--eye");
    parseVec3(opt.target, "--target");
  }
}

const Camera* findSceneCamera(const CameraOptions& opt, const Scene& scene,
                              const std::string& scenePath) {
  for (const Camera& c : scene.cameras) {
    if (opt.camera.empty() || c.name == opt.camera) return &c;
  }
  if (!opt.camera.empty()) {
    // The first few names: 20,000 cameras made a line of 249 KB (H14-5-2).
    constexpr size_t kNamesShown = 10;
    std::string names;
    const size_t count = scene.cameras.size();
    for (size_t i = 0; i < std::min(count, kNamesShown); ++i) {
      names += (names.empty() ? "'" : ", '") + printableShort(scene.cameras[i].name) + "'";
    }
    if (count > kNamesShown) names += " and " + std::to_string(count - kNamesShown) + " more";
    throw InputError("--camera: no camera named '" + printableShort(opt.camera) + "' in " +
                     scenePath + (names.empty() ? " (it has none)" : " (it has " + names + ")"));
  }
  return nullptr;
}

PinholeCamera chooseCamera(const CameraOptions& opt, const Scene& scene,
                           const std::string& scenePath) {
  const float fov = (opt.fovDegrees > 0 ? opt.fovDegrees : 45.0f) * kPi / 180.0f;
  if (!opt.eye.empty()) {
    // The file's world coordinates, taken to the scene's (Scene::origin).
    const Vec3 eye = scene.toLocal(parseVec3d(opt.eye, "--eye"));
    const Vec3 target = scene.toLocal(parseVec3d(opt.target, "--target"));
    if (eye == target) throw InputError("--eye and --target: the same point");
    return PinholeCamera::lookAt(eye, target, fov);
  }
  const Camera* chosen = findSceneCamera(opt, scene, scenePath);
  if (!chosen) return PinholeCamera::framing(scene, fov);
  PinholeCamera camera = PinholeCamera::fromScene(*chosen);
  if (opt.fovDegrees > 0) camera.yfov = fov;
  return camera;
}

}  // namespace lo::tool
