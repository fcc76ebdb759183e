#include "scene_options.h"

#include <CLI/CLI.hpp>

#include <cmath>
#include <filesystem>

#include "camera_options.h"
#include "cli_checks.h"
#include "core/error.h"
#include "scene/place_model.h"
#include "scene/scene_files.h"

namespace lo::tool {

void addSceneArgument(CLI::App* cmd, std::string& scene) {
  cmd->add_option("scene", scene, "Scene: .gltf, .glb or .obj")->required()->check(existingFile());
}

void addSceneOptions(CLI::App* cmd, SceneOptions& opt) {
  cmd->add_option("--sky", opt.sky,
                  "Light the scene with a uniform sky over the upper hemisphere (+Y): radiance "
                  "R,G,B in W/(m^2 sr) (an open surface under it receives pi times that, W/m^2); "
                  "0,0,0 turns the scene file's sky off (docs/scene.md, \"Sky\")");
  cmd->add_option("--sky-image", opt.skyImage,
                  "Light the scene with an equirectangular radiance map (.exr or .hdr, linear; "
                  "its upper half, row 0 at the zenith), scaled by --sky (default 1,1,1)")
      ->check(existingFile());
  cmd->add_option("--sky-mesh", opt.skyMesh,
                  "Take the triangles of this material (a sky box or dome around the scene) out "
                  "of the geometry and light the scene with them as its sky: their emission, or "
                  "their base colour (texture included) as radiance, scaled by --sky")
      ->excludes("--sky-image");
  cmd->add_option("--physical-sky", opt.physicalSky,
                  "Light the scene with the daylight sky of its sun (its first directional "
                  "light), an atmosphere of this turbidity (2: very clear, 3: clear, 6: hazy; "
                  "Preetham et al. 1999), as bright beside the sun as that sky is beside the "
                  "sun through it; scaled by --sky")
      ->check(numberIn({1.7, 10.0}))  // kMinTurbidity, kMaxTurbidity (as doubles: 1.7f > 1.7)
      ->excludes("--sky-image")
      ->excludes("--sky-mesh");
}

NamedPaths sceneInputs(const std::string& scene, const std::string& role) {
  NamedPaths inputs;
  const std::string folder = std::filesystem::path(scene).parent_path().string();
  for (const std::string& file : sceneFiles(scene)) {
    if (inputs.empty()) {
      inputs.push_back({role, file});
      continue;
    }
    std::error_code ec;
    const std::string name =
        std::filesystem::relative(file, folder.empty() ? "." : folder, ec).generic_string();
    inputs.push_back({role + "'s file '" + (ec || name.empty() ? file : name) + "'", file});
  }
  return inputs;
}

NamedPaths sceneInputs(const std::string& scene, const SceneOptions& opt) {
  NamedPaths inputs = sceneInputs(scene);
  if (!opt.skyImage.empty()) inputs.push_back({"--sky-image", opt.skyImage});
  return inputs;
}

NamedPaths sceneInputs(const SceneFlags& opt) {
  NamedPaths inputs = sceneInputs(opt.scene, opt.sceneOptions);
  for (const std::string& model : opt.objects.models) {
    const NamedPaths files = sceneInputs(model, "--add '" + model + "'");
    inputs.insert(inputs.end(), files.begin(), files.end());
  }
  return inputs;
}

namespace {

/// The scene at `path` with its sky replaced as the flags say (unchecked).
Scene applySkyFlags(const std::string& path, const SceneOptions& opt) {
  Vec3 sky{0, 0, 0};
  if (!opt.sky.empty()) {
    // A radiance, not a position: its range is kMaxRadiance's, in double
    // before it becomes a float (3.5e38 would be one's infinity).
    const Vec3d given = parseThreeNumbers(opt.sky, "--sky");
    for (const double c : {given.x, given.y, given.z}) {
      if (!(c >= 0 && c <= double(kMaxRadiance))) {
        throw InputError("--sky: '" + opt.sky +
                         "' is not a radiance (three numbers from 0 to 1e9, W/(m^2 sr))");
      }
    }
    sky = given.toVec3();
  }
  std::shared_ptr<const Texture> image;
  if (!opt.skyImage.empty()) {
    try {
      image = loadSkyImage(opt.skyImage);
    } catch (const InputError& e) {
      throw InputError(std::string("--sky-image: ") + e.what());
    }
  }
  Scene scene;
  try {
    scene = loadScene(path, opt.skyMesh);
  } catch (const InputError& e) {
    // A sky-mesh name the scene lacks is the flag's problem.
    const std::string what = e.what();
    if (!opt.skyMesh.empty() && what.find("sky mesh") != std::string::npos) {
      throw InputError("--sky-mesh: " + what);
    }
    throw;
  }
  if (!opt.skyMesh.empty() || opt.physicalSky > 0) {
    if (opt.physicalSky > 0) {
      try {
        physicalSky(scene, opt.physicalSky);
      } catch (const InputError& e) {
        throw InputError(std::string("--physical-sky: ") + e.what());
      }
    }
    if (!opt.sky.empty()) scene.sky.radiance = sky;
    return scene;
  }
  if (image) {
    scene.sky.image = std::move(image);
    scene.sky.radiance = opt.sky.empty() ? Vec3{1, 1, 1} : sky;
  } else if (!opt.sky.empty()) {
    scene.sky.radiance = sky;
    scene.sky.image.reset();
  }
  return scene;
}

}  // namespace

Scene loadSceneWith(const std::string& path, const SceneOptions& opt) {
  Scene scene = applySkyFlags(path, opt);
  // The sky the flags made, checked as loadScene checks the file's (and a
  // --sky-mesh's): every command, bake and reference alike, takes the same skies.
  if (opt.sky.empty() && opt.skyImage.empty() && !(opt.physicalSky > 0)) return scene;
  const std::string flag = !opt.skyImage.empty() ? "--sky-image '" + opt.skyImage + "'"
                           : opt.physicalSky > 0 ? std::string("--physical-sky")
                                                 : std::string("--sky");
  checkSkyRadiance(scene.sky, flag + (opt.sky.empty() || flag == "--sky" ? "" : " with --sky"));
  return scene;
}

void addObjectOptions(CLI::App* cmd, AddedObjects& opt) {
  cmd->add_option(
         "--add", opt.models,
         "A model (.gltf, .glb or .obj) added to the baked scene, not in the bake: lit "
         "by the bake's free-space light, casting shadows (repeatable; each needs an --at)")
      ->check(existingFile());
  cmd->add_option("--at", opt.placements,
                  "Where the --add of the same rank goes: x,y,z[,yaw[,scale]] (its origin to "
                  "x,y,z in scene units, turned yaw degrees about +Y, scaled)");
}

void placeObjects(Scene& scene, const AddedObjects& opt) {
  if (opt.models.size() != opt.placements.size()) {
    throw InputError("--add and --at: " + std::to_string(opt.models.size()) + " models and " +
                     std::to_string(opt.placements.size()) +
                     " placements; give one --at per --add, in the same order");
  }
  std::vector<AddedModel> models;
  for (size_t i = 0; i < opt.models.size(); ++i) {
    models.push_back({opt.models[i], parsePlacement(opt.placements[i])});
  }
  placeModels(scene, models);
}

void addSceneFlags(CLI::App* cmd, SceneFlags& opt) {
  addSceneArgument(cmd, opt.scene);
  addSceneOptions(cmd, opt.sceneOptions);
  addObjectOptions(cmd, opt.objects);
}

Scene loadSceneWith(const SceneFlags& opt) {
  Scene scene = loadSceneWith(opt.scene, opt.sceneOptions);
  placeObjects(scene, opt.objects);
  return scene;
}

}  // namespace lo::tool
