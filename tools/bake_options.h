#pragma once
/// @file tools/bake_options.h
/// @brief The flags of `bake` and their translation into BakeParams.

#include "scene_options.h"
#include <cstdint>
#include <string>
#include <vector>

#include "bake/bake.h"

namespace CLI {
class App;
}

namespace lo::tool {

/// The flags of `bake`, as given.
struct BakeOptions {
  std::string scene;
  SceneOptions sceneOptions;  // --sky
  std::string output;
  std::string depth = "auto";
  size_t photons = 0;        // 0: not given (a target bake)
  double targetError = 0;    // 0: not given (kDefaultTargetError unless --photons)
  std::string targetLight = "seen";
  size_t maxPhotons = kDefaultMaxPhotons;
  double maxSeconds = 0;
  int knn = 300;
  double radius = 0;  // 0 = auto
  std::string vdls = "4";
  std::string representation = "vdl";
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  bool includeDirect = false;
  std::string layers = "on";
  std::string occlusion = "on";
  std::string edgeCorrection = "on";
  std::string separateCaustics = "on";
  std::string smoothing = "on";
  std::string freeSpace = "on";
  int freeSpaceLevels = 2;
  int freeSpaceOrder = 1;
  int autoCap = BakeParams{}.autoCap;
  float autoThreshold = BakeParams{}.autoThreshold;
  std::vector<double> bounds;  // x0 y0 z0 x1 y1 z1, empty = the whole scene
  std::string photonMap;
  std::string statsJson;
  std::string tiles = "auto";
  bool quiet = false;

  /// The bake's settings from the flags (keepPhotons: --photon-map given).
  /// The bake's parameters; --bounds (the file's world coordinates) taken
  /// to the scene's (Scene::origin).
  BakeParams bakeParams(const Scene& scene) const;
};

/// Registers the description and the flags of `bake` on `cmd`.
void addBakeOptions(CLI::App* cmd, BakeOptions& opt);

}  // namespace lo::tool
