#include "scene_options.h"

#include <CLI/CLI.hpp>

#include <cmath>

#include "camera_options.h"
#include "core/error.h"

namespace lo::tool {

void addSceneOptions(CLI::App* cmd, SceneOptions& opt) {
  cmd->add_option("--sky", opt.sky,
                  "Light the scene with a uniform sky over the upper hemisphere (+Y): radiance "
                  "R,G,B in W/(m^2 sr) (an open surface under it receives pi times that, W/m^2); "
                  "0,0,0 turns the scene file's sky off (docs/scene.md, \"Sky\")");
}

Scene loadSceneWith(const std::string& path, const SceneOptions& opt) {
  Vec3 sky{0, 0, 0};
  if (!opt.sky.empty()) {
    sky = parseVec3(opt.sky, "--sky");
    for (int c = 0; c < 3; ++c) {
      if (!std::isfinite(sky[c]) || sky[c] < 0 || sky[c] > 1e9f) {
        throw InputError("--sky: '" + opt.sky +
                         "' is not a radiance (three numbers from 0 to 1e9, W/(m^2 sr))");
      }
    }
  }
  Scene scene = loadScene(path);
  if (!opt.sky.empty()) scene.sky.radiance = sky;
  return scene;
}

}  // namespace lo::tool
