#pragma once
/// @file scene/place_model.h
/// @brief Objects added to a baked scene (`render`/`view`/`reference --add`):
/// a model's triangles, materials and textures joined to the scene where the
/// user puts it. The renderer lights them from the free-space light
/// (Scene::movingMaterialsFrom); the path tracer traces them as any surface
/// (or, with ReferenceParams::addedOnlyReceive, meets them with camera rays
/// alone).

#include <string>
#include <vector>

#include "core/math.h"
#include "scene/scene.h"

namespace lo {

/// Where an added model goes: its own origin to `at` (world space), turned
/// `yawDegrees` about +Y (glTF's up) and scaled by `scale`.
struct Placement {
  Vec3d at;
  float yawDegrees = 0;
  float scale = 1;
};

/// The largest yaw `--at` takes, either way, degrees: a turn covers every
/// orientation, and single precision turns a larger angle less exactly.
constexpr double kMaxYawDegrees = 360;

/// Parses "x,y,z[,yaw[,scale]]" (scene units, degrees). @throws InputError
/// naming the value when it is not 3 to 5 finite numbers, and naming the
/// part when x, y or z lies beyond kMaxCoordinate, the yaw beyond
/// kMaxYawDegrees, or the scale outside (0, 1e6] or below what single
/// precision holds (1.2e-38: a smaller one became 0).
Placement parsePlacement(const std::string& text);

/// Joins `model` to `scene` at `placement`: its vertices (positions, normals,
/// tangents turned with it; UV sets kept), triangles, materials and textures
/// appended. The first model added sets Scene::movingMaterialsFrom. The
/// model's lights are left out (a warning says so: an added object does not
/// change the baked light), and its cameras. @throws InputError when the
/// placed vertices lie beyond kMaxCoordinate.
void placeModel(Scene& scene, Scene model, const Placement& placement);

/// One object to add: a model file (`--add`) and where it goes (`--at`).
struct AddedModel {
  std::string path;
  Placement placement;
};

/// @brief The objects of `render`/`view`/`reference --add`: each model file
/// loaded once (loadScene, whose own checks count its triangles and
/// textures), then joined at every placement that names it (placeModel),
/// its copies sharing its textures. The joined scene's triangles are counted
/// against the memory before any is joined, by the rule of a glTF's node
/// tree (256 bytes each within half the memory available, 32-bit indices):
/// a model added many times grew until the system ended the process.
/// @throws InputError "--add: ..." naming the file that cannot be loaded, or
/// the triangles the scene and its added objects would make (`scene` is
/// then left as it was), or placeModel's.
void placeModels(Scene& scene, const std::vector<AddedModel>& models);

}  // namespace lo
