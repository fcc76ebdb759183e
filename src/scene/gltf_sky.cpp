/// @file scene/gltf_sky.cpp
/// @brief The glTF scene's sky (SceneBuilder::readSky, gltf_internal.h): its
/// extras.lightoctree_sky, _sky_image, _sky_mesh and _physical_sky.

#include "scene/gltf_internal.h"

#include <cmath>
#include <filesystem>
#include <string>

namespace lo::scene_internal::gltf_internal {

void SceneBuilder::readSky() {
  const auto& scenes = model_.scenes;
  const int s = model_.defaultScene >= 0 ? model_.defaultScene : scenes.empty() ? -1 : 0;
  if (s < 0 || size_t(s) >= scenes.size()) return;
  const tinygltf::Value& extras = scenes[size_t(s)].extras;
  if (!extras.IsObject()) return;
  if (extras.Has("lightoctree_sky_mesh")) {
    // The material of a sky box to take as the sky (skyFromMaterial).
    const tinygltf::Value& name = extras.Get("lightoctree_sky_mesh");
    const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_sky_mesh";
    if (!name.IsString() || name.Get<std::string>().empty()) {
      fail(path_, what + " must be the name of the sky box's material");
    }
    if (extras.Has("lightoctree_sky_image")) {
      fail(path_, what + " and extras.lightoctree_sky_image: give one sky");
    }
    skyMesh_ = name.Get<std::string>();
  }
  if (extras.Has("lightoctree_physical_sky")) {
    // The daylight sky of the scene's sun, at this turbidity (physicalSky).
    const tinygltf::Value& t = extras.Get("lightoctree_physical_sky");
    const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_physical_sky";
    if (!t.IsNumber() || !(t.GetNumberAsDouble() > 0)) {
      fail(path_, what + " must be the atmosphere's turbidity (a number, 2 to 10)");
    }
    if (extras.Has("lightoctree_sky_image") || extras.Has("lightoctree_sky_mesh")) {
      fail(path_, what + " and another sky (lightoctree_sky_image or _mesh): give one sky");
    }
    turbidity_ = float(t.GetNumberAsDouble());
  }
  skyScale_ = extras.Has("lightoctree_sky");
  if (extras.Has("lightoctree_sky_image")) {
    // An equirectangular radiance map beside the file (.exr or .hdr).
    const tinygltf::Value& uri = extras.Get("lightoctree_sky_image");
    const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_sky_image";
    if (!uri.IsString()) fail(path_, what + " must be a file name (.exr or .hdr)");
    std::string base = std::filesystem::path(path_).parent_path().string();
    if (base.empty()) base = ".";
    const std::string file = resolveInsideFolder(path_, base, uri.Get<std::string>(), what);
    try {
      scene_.sky.image = loadSkyImage(file);
    } catch (const InputError& e) {
      fail(path_, what + ": " + e.what());
    }
    scene_.sky.radiance = Vec3{1, 1, 1};  // unless lightoctree_sky scales it
  }
  if (!extras.Has("lightoctree_sky")) return;
  const tinygltf::Value& v = extras.Get("lightoctree_sky");
  const std::string what = "scene " + std::to_string(s) + ": extras.lightoctree_sky";
  if (!v.IsArray() || v.ArrayLen() != 3) {
    fail(path_, what + " must be an array of 3 numbers (radiance, W/(m^2 sr))");
  }
  for (int c = 0; c < 3; ++c) {
    const tinygltf::Value& x = v.Get(c);
    if (!x.IsNumber()) fail(path_, what + " must be an array of 3 numbers (radiance, W/(m^2 sr))");
    const double value = x.GetNumberAsDouble();
    if (!std::isfinite(value) || value < 0 || value > 1e9) {
      fail(path_, what + "[" + std::to_string(c) + "] = " + std::to_string(value) +
                      " is not a radiance (finite, 0 to 1e9)");
    }
    scene_.sky.radiance[c] = float(value);
  }
}

}  // namespace lo::scene_internal::gltf_internal
