#pragma once
/// @file tools/scene_options.h
/// @brief The flags every command that loads a scene shares: --sky R,G,B (a
/// uniform sky over the upper hemisphere, scene/scene.h's Sky) and
/// --sky-image FILE (an equirectangular radiance map that --sky scales),
/// which replace the scene file's own sky. One parser, so `bake`, `render`,
/// `reference`, `lightmap` and `view` light a scene alike.

#include <string>
#include <vector>

#include "core/file.h"
#include "scene/scene.h"

namespace CLI {
class App;
}

namespace lo::tool {

struct SceneOptions {
  std::string sky;       ///< "r,g,b" radiance W/(m^2 sr); empty = the file's
  std::string skyImage;  ///< .exr or .hdr equirectangular map; empty = the file's
  std::string skyMesh;   ///< material of a sky box to take as the sky; empty = none
  float physicalSky = 0; ///< turbidity of a daylight sky for the scene's sun; 0 = none
};

/// Registers the SCENE argument (required, an existing .gltf, .glb or .obj)
/// on `cmd`; `bake` has its own wording.
void addSceneArgument(CLI::App* cmd, std::string& scene);

/// Registers --sky, --sky-image, --sky-mesh and --physical-sky on `cmd`.
void addSceneOptions(CLI::App* cmd, SceneOptions& opt);

/// The files loading `scene` reads, named for checkDistinctFiles ("SCENE",
/// then "SCENE's file 'tex.png'", ...; scene/scene_files.h; `role` for
/// SCENE): what no output of a command may replace.
NamedPaths sceneInputs(const std::string& scene, const std::string& role = "SCENE");

/// sceneInputs(scene) and the file the flags add to it: --sky-image.
NamedPaths sceneInputs(const std::string& scene, const SceneOptions& opt);

/// loadScene(path) with the flags applied. @throws InputError naming the flag
/// (a radiance that is negative or not a number) or the file.
Scene loadSceneWith(const std::string& path, const SceneOptions& opt);

/// Objects added to a baked scene (`render`, `view`, `reference`): --add
/// MODEL (repeatable) placed by the --at x,y,z[,yaw[,scale]] of the same rank.
struct AddedObjects {
  std::vector<std::string> models;
  std::vector<std::string> placements;
  bool empty() const { return models.empty(); }
};

/// Registers --add and --at on `cmd`.
void addObjectOptions(CLI::App* cmd, AddedObjects& opt);

/// Loads each --add model and joins it to `scene` at its --at
/// (scene/place_model.h). @throws InputError naming the flag when the counts
/// differ, a placement does not parse or a model does not load.
void placeObjects(Scene& scene, const AddedObjects& opt);

/// What `render`, `view` and `reference` load alike: SCENE, lit as the --sky
/// flags say, with the --add objects placed in it.
struct SceneFlags {
  std::string scene;
  SceneOptions sceneOptions;  // --sky
  AddedObjects objects;       // --add, --at
};

/// Every file loadSceneWith(opt) reads: the scene's and --sky-image
/// (sceneInputs), and each --add model's ("--add 'chair.obj'", "--add
/// 'chair.obj''s file 'chair.mtl'", ...).
NamedPaths sceneInputs(const SceneFlags& opt);

/// Registers SCENE (addSceneArgument), the --sky flags and --add, --at on `cmd`.
void addSceneFlags(CLI::App* cmd, SceneFlags& opt);

/// loadSceneWith with the --add objects placed. @throws as loadSceneWith and
/// placeObjects.
Scene loadSceneWith(const SceneFlags& opt);

}  // namespace lo::tool
