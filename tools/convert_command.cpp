// `lightoctree convert`: a baked .vdb to another depth, VDL count or storage
// (docs/convert.md). convertLightGrid (src/bake) picks the method
// and runs it; this file parses, reads, writes and reports.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/convert.h"
#include "cli_checks.h"
#include "command_options.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/threads.h"
#include "json_report.h"
#include "report.h"
#include "scene/scene.h"
#include "scene/scene_files.h"
#include "scene_options.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

struct ConvertOptions {
  std::string input;
  std::string output;
  int depth = 0;     // 0 = the input's
  std::string vdls;  // "" = the input's
  bool half = false;
  std::vector<std::string> drop;
  std::string scene;
  std::string photonMap;
  uint64_t seed = 1;
  int threads = 0;
  std::string json;  // --json FILE: tools/json_report.h
  bool quiet = false;
};

void addConvertOptions(CLI::App* cmd, ConvertOptions& opt) {
  cmd->description(
      "Convert a baked .vdb to another depth (merge children / interpolate parents, or re-gather "
      "from a photon map), VDL count or storage.");
  cmd->add_option("input", opt.input, "Baked VDL file (.vdb)")->required()->check(existingFile());
  cmd->add_option("-o,--output", opt.output, "Output .vdb file (written atomically)")->required();
  cmd->add_option("--depth", opt.depth, "Output depth (default: the input's)")
      ->check(depthValidator());
  cmd->add_option(
         "--vdls", opt.vdls,
         "VDLs per voxel, 1-" + std::to_string(kMaxVdls) + " or 'auto' (default: the input's)")
      ->check(vdlCountValidator());
  cmd->add_flag("--half", opt.half,
                "Store irradiance, normal, VDL, angular_error and radius grids as half floats");
  cmd->add_option("--drop", opt.drop,
                  "Grids to leave out: the optional photon_count, noise, angular_error, radius, "
                  "area, and the display grid density")
      ->delimiter(',');
  cmd->add_option("--scene", opt.scene,
                  "The baked scene: needed for a finer --depth and for --photon-map")
      ->check(existingFile());
  cmd->add_option("--photon-map", opt.photonMap,
                  "Photon file written by 'bake --photon-map': re-gather at the new depth")
      ->check(existingFile());
  cmd->add_option("--seed", opt.seed, "K-means seed")
      ->check(seedValidator())
      ->capture_default_str();
  addThreadsOption(cmd, opt.threads);
  cmd->add_option("--json", opt.json,
                  "Also write a JSON report (a .json file): the files read and written, depths, voxels, method, "
                  "energy in and out (README.md, \"Scripting\")");
  cmd->add_flag("-q,--quiet", opt.quiet, "No progress or summary, only errors");
}

int runConvert(const ConvertOptions& opt) {
  checkOutputFile(opt.output, "--output", ".vdb");
  if (!opt.json.empty()) checkOutputFile(opt.json, "--json", ".json");
  NamedPaths inputs{{"IN", opt.input}};
  if (!opt.scene.empty()) {
    const NamedPaths scene = sceneInputs(opt.scene, "--scene");
    inputs.insert(inputs.end(), scene.begin(), scene.end());
  }
  inputs.push_back({"--photon-map", opt.photonMap});
  checkDistinctFiles({{"--output", opt.output}, {"--json", opt.json}}, inputs);
  const auto& optional = droppableVdlGridNames();
  for (const std::string& name : opt.drop) {
    if (std::find(optional.begin(), optional.end(), name) == optional.end()) {
      std::string list;
      for (const auto& o : optional) list += (list.empty() ? "" : ", ") + o;
      throw InputError("--drop: '" + name + "' is not a grid that may be left out; only " + list +
                       " can be dropped (the others are required by the VDL file contract)");
    }
  }
  ThreadLimit threadLimit(opt.threads);
  ConsoleProgress progress(opt.quiet);

  LoadedVdl in = readVdlGrid(opt.input);
  if (!opt.quiet) {
    for (const std::string& note : in.notes)
      std::printf("note: %s: %s\n", opt.input.c_str(), note.c_str());
  }
  std::vector<StageReport> rows;
  ConvertParams params;
  params.depth = opt.depth;
  params.vdls = opt.vdls;
  params.seed = opt.seed;
  Scene scene;
  const bool needsScene = (opt.depth > 0 && opt.depth != in.grid.frame.depth) || !opt.photonMap.empty();
  if (!opt.scene.empty() && needsScene) {
    StageTimer loadTimer(rows, "load scene");
    scene = loadScene(opt.scene);
    printSceneWarnings(scene);
    // The grid in the scene's coordinates (its origin may differ from the
    // one the file was baked in: a file from before rebasing, say).
    const Vec3d& a = scene.origin;
    const Vec3d& b = in.grid.frame.offset;
    if (a.x != b.x || a.y != b.y || a.z != b.z) in = readVdlGrid(opt.input, scene.origin);
    params.scene = &scene;
    loadTimer.finish(formatCount(scene.triangleCount()) + " triangles");
  }
  // Every input made from a scene is checked against the scene given with it
  // (the hashes of bake's metadata): a photon map of another scene was taken
  // without a word, and lost 29% of the light.
  const std::string sceneHash = opt.scene.empty() ? "" : sceneContentHash(opt.scene);
  auto warn = [](const std::string& warning) {
    if (!warning.empty()) std::fprintf(stderr, "warning: %s\n", warning.c_str());
  };
  if (!opt.scene.empty()) {
    warn(sceneMismatchWarning("IN '" + opt.input + "'", in.meta.sourceSceneHash, opt.scene,
                              sceneHash));
  }
  std::vector<Photon> photons;
  if (!opt.photonMap.empty()) {
    StageTimer readTimer(rows, "read photon map");
    PhotonMapInfo info;
    photons = readPhotonPoints(opt.photonMap, in.grid.frame.offset, &info);
    params.photons = &photons;
    params.photonRegion = info.region;
    params.photonSkyHash = info.skyHash;
    params.photonIncludeDirect = info.includeDirect;
    readTimer.finish(formatCount(photons.size()) + " photons");
    const std::string what = "--photon-map '" + opt.photonMap + "'";
    if (!opt.scene.empty()) {
      warn(sceneMismatchWarning(what, info.sourceSceneHash, opt.scene, sceneHash));
    }
    warn(photonSkyMismatchWarning(what, info.skyHash, "IN '" + opt.input + "'", in.meta.skyHash));
    warn(photonDirectMismatchWarning(what, info.includeDirect, "IN '" + opt.input + "'",
                                     in.meta.includeDirect));
    warn(sparseRegatherWarning(in.grid, in.meta, params));
  }
  ConvertResult out = convertLightGrid(in.grid, in.meta, params, &progress);
  rows.insert(rows.end(), out.stages.begin(), out.stages.end());
  const int inDepth = in.grid.frame.depth;
  out.metadata.convertedFrom = std::filesystem::path(opt.input).filename().string() + " (depth " +
                               std::to_string(inDepth) + ", " + std::to_string(in.grid.maxVdls) +
                               " VDL slots)";

  StageTimer writeTimer(rows, "write .vdb");
  VdlWriteOptions write;
  write.halfFloat = opt.half;
  write.drop = opt.drop;
  AtomicFileSet outputs;
  writeVdlGrid(opt.output, out.grid, out.metadata, write, &outputs);
  writeTimer.finish(opt.output + " (" + formatBytes(size_t(outputs.bytesOf(opt.output))) + ")");
  if (!opt.json.empty()) {
    JsonReport report{"convert", inputs,
                      {{"depth", {{"in", inDepth}, {"out", out.metadata.depth}}},
                       {"voxels", {{"in", in.grid.size()}, {"out", out.grid.size()}}},
                       {"vdls", out.vdls},
                       {"method", out.method},
                       {"energy", {{"in", lightGridEnergy(in.grid)}, {"out", lightGridEnergy(out.grid)}}}}};
    report.addTo(outputs, opt.json, rows);
  }
  outputs.commit();
  if (!opt.quiet) {
    printSummary(stdout, rows);
    std::printf("\n%s: depth %d -> %d, %s -> %s voxels, %s VDLs; %s\n", opt.input.c_str(), inDepth,
                out.metadata.depth, formatCount(in.grid.size()).c_str(),
                formatCount(out.grid.size()).c_str(), out.vdls.c_str(), out.method.c_str());
    std::printf("sum of irradiance x area (W, channel mean): %.6g in, %.6g out\n",
                lightGridEnergy(in.grid), lightGridEnergy(out.grid));
    std::printf("wrote %s\n", opt.output.c_str());
  }
  return 0;
}

}  // namespace

std::function<int()> addConvertCommand(CLI::App& app) {
  return addCommand(app, "convert", addConvertOptions, runConvert);
}

}  // namespace lo::tool
