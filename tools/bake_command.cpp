// `lightoctree bake`: scene -> photon map -> surface grid -> KNN + K-means VDLs -> .vdb

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cluster/vdl_grid.h"
#include "commands.h"
#include "core/error.h"
#include "gather/gather.h"
#include "grid/surface_grid.h"
#include "photon/photon_map.h"
#include "report.h"
#include "scene/scene.h"
#include "text_file.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

struct BakeOptions {
  std::string scene;
  std::string output;
  int depth = 6;
  size_t photons = 600000;
  int knn = 300;
  float radius = 0;  // 0 = auto
  std::string vdls = "4";
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  bool includeDirect = false;
  std::string photonMap;
  std::string statsJson;
  bool quiet = false;
};

int runBake(const BakeOptions& opt) {
  checkOutputFolder(opt.output, "--output");
  if (!opt.photonMap.empty()) checkOutputFolder(opt.photonMap, "--photon-map");
  if (!opt.statsJson.empty()) checkOutputFolder(opt.statsJson, "--stats-json");

  std::unique_ptr<tbb::global_control> threadLimit;
  if (opt.threads > 0) {
    threadLimit = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, size_t(opt.threads));
  }
  ConsoleProgress progress(opt.quiet);
  std::vector<StageReport> rows;

  StageTimer loadTimer(rows, "load scene");
  Scene scene = loadScene(opt.scene);
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.lights.size()) + " punctual lights");

  StageTimer traceTimer(rows, "trace photons");
  PhotonParams photonParams;
  photonParams.storedPhotons = opt.photons;
  photonParams.includeDirect = opt.includeDirect;
  photonParams.seed = opt.seed;
  PhotonMap photons = tracePhotons(scene, photonParams, &progress);
  traceTimer.finish(formatCount(photons.photons.size()) + " photons from " +
                    formatCount(photons.emittedPaths) + " paths");

  StageTimer gridTimer(rows, "voxelize");
  GridParams gridParams;
  gridParams.depth = opt.depth;
  SurfaceGrid grid = buildSurfaceGrid(scene, gridParams, &progress);
  size_t dense = size_t(1) << (3 * opt.depth);
  gridTimer.finish(formatCount(grid.size()) + " of " + formatCount(dense) + " voxels active");

  StageTimer splatTimer(rows, "splat photons");
  size_t dropped = splatPhotons(grid, photons.photons);
  splatTimer.finish(dropped ? formatCount(dropped) + " photons outside the grid" : "");

  GatherParams gatherParams;
  gatherParams.k = opt.knn;
  gatherParams.radius = opt.radius;
  ClusterParams clusterParams;
  clusterParams.seed = opt.seed;
  if (opt.vdls == "auto") {
    clusterParams.autoCount = true;
    clusterParams.vdls = kMaxVdls;
  } else {
    clusterParams.vdls = std::stoi(opt.vdls);
  }
  StageTimer clusterTimer(rows, "gather + cluster");
  BakeTimings timings;
  VdlGrid vdls = buildVdlGrid(grid, photons.photons, gatherParams, clusterParams, &progress,
                              &timings);
  char split[128];
  std::snprintf(split, sizeof split, "thread-seconds: gather %.3f, K-means %.3f",
                timings.gatherSeconds, timings.clusterSeconds);
  clusterTimer.finish(split);

  BakeMetadata meta;
  meta.sourceScene = std::filesystem::path(opt.scene).filename().string();
  meta.depth = opt.depth;
  meta.photons = int64_t(photons.photons.size());
  meta.emittedPaths = int64_t(photons.emittedPaths);
  meta.knn = opt.knn;
  meta.radius = resolveRadius(gatherParams, grid.frame);
  meta.vdls = opt.vdls;
  meta.seed = int64_t(opt.seed);
  meta.sceneBounds = scene.bounds();

  StageTimer writeTimer(rows, "write .vdb");
  writeVdlGrid(opt.output, vdls, meta);
  size_t fileBytes = size_t(std::filesystem::file_size(opt.output));
  writeTimer.finish(opt.output + " (" + formatBytes(fileBytes) + ")");

  if (!opt.photonMap.empty()) {
    StageTimer pointsTimer(rows, "write photon map");
    writePhotonPoints(opt.photonMap, photons.photons, grid.frame.voxelSize);
    pointsTimer.finish(opt.photonMap);
  }

  if (!opt.quiet) printSummary(stdout, rows);

  if (!opt.statsJson.empty()) {
    nlohmann::json j;
    j["scene"] = opt.scene;
    j["output"] = opt.output;
    j["parameters"] = {{"depth", opt.depth},         {"photons", opt.photons},
                       {"knn", opt.knn},             {"radius", meta.radius},
                       {"vdls", opt.vdls},           {"seed", opt.seed},
                       {"threads", opt.threads},     {"include_direct", opt.includeDirect}};
    j["counts"] = {{"triangles", scene.triangleCount()},
                   {"stored_photons", photons.photons.size()},
                   {"emitted_paths", photons.emittedPaths},
                   {"active_voxels", grid.size()},
                   {"dense_voxels", dense},
                   {"photons_outside_grid", dropped},
                   {"vdb_bytes", fileBytes}};
    j["thread_seconds"] = {{"gather", timings.gatherSeconds}, {"cluster", timings.clusterSeconds}};
    nlohmann::json stages = nlohmann::json::array();
    double total = 0;
    for (const StageReport& r : rows) {
      stages.push_back({{"name", r.name},
                        {"seconds", r.seconds},
                        {"rss_bytes", r.rssBytes},
                        {"peak_rss_bytes", r.peakBytes}});
      total += r.seconds;
    }
    j["stages"] = stages;
    j["total_seconds"] = total;
    j["peak_rss_bytes"] = peakRssBytes();
    writeTextAtomically(opt.statsJson, j.dump(2) + "\n");
  }
  std::printf("\nwrote %s\n", opt.output.c_str());
  return 0;
}

}  // namespace

std::function<int()> addBakeCommand(CLI::App& app) {
  auto opt = std::make_shared<BakeOptions>();
  CLI::App* cmd = app.add_subcommand(
      "bake",
      "Trace a photon map and compress it into a sparse grid of virtual directional lights "
      "(VDLs), written as a .vdb file.");
  cmd->add_option("scene", opt->scene, "Scene to bake: .gltf, .glb or .obj")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", opt->output, "Output .vdb file (written atomically)")->required();
  cmd->add_option("--depth", opt->depth,
                  "Octree depth: 2^depth voxels across the scene's bounding cube")
      ->check(CLI::Range(1, 12))
      ->capture_default_str();
  cmd->add_option("--photons", opt->photons, "Photons to store in the photon map")
      ->check(CLI::Range(size_t(1), size_t(200000000)))
      ->capture_default_str();
  cmd->add_option("--knn", opt->knn, "Nearest photons gathered per voxel (paper: 300)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--radius", opt->radius,
                  "Gathering radius in scene units (default: 1.5 voxel sizes)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--vdls", opt->vdls,
                  "VDLs per voxel, 1-8, or 'auto' for the fewest that keep the angular error "
                  "under 0.35 (about 20 degrees)")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            if (s == "auto") return {};
            try {
              size_t used = 0;
              int v = std::stoi(s, &used);
              if (used == s.size() && v >= 1 && v <= 8) return {};
            } catch (const std::exception&) {
            }
            return "must be an integer from 1 to 8 or 'auto', got '" + s + "'";
          },
          "1..8|auto", "VdlCount"))
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Random seed (same seed, same bytes)")->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_flag("--include-direct", opt->includeDirect,
                "Also store direct-light photons (by default the GL renderer draws direct light)");
  cmd->add_option("--photon-map", opt->photonMap,
                  "Also write the photons as an OpenVDB point grid for inspection");
  cmd->add_option("--stats-json", opt->statsJson, "Write the per-stage figures as JSON");
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress or summary, only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runBake(*opt) : -1; };
}

}  // namespace lo::tool
