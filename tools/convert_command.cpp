// `lightoctree convert`: a baked .vdb to another depth, VDL count or storage
// (docs/convert.md). The methods live in src/cluster/resample.h; this file
// parses, picks the method, reports.

#include <tbb/global_control.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cluster/resample.h"
#include "cluster/vdl_grid.h"
#include "commands.h"
#include "core/error.h"
#include "gather/gather.h"
#include "grid/surface_grid.h"
#include "report.h"
#include "scene/scene.h"
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
  bool quiet = false;
};

double energy(const VdlGrid& g) {
  double e = 0;
  for (size_t v = 0; v < g.size(); ++v) e += double(average(g.irradiance[v])) * g.areas[v];
  return e;
}

int runConvert(const ConvertOptions& opt) {
  {
    std::filesystem::path parent = std::filesystem::path(opt.output).parent_path();
    if (!parent.empty() && !std::filesystem::is_directory(parent)) {
      throw InputError("--output: folder '" + parent.string() + "' does not exist");
    }
  }
  const auto& optional = optionalVdlGridNames();
  for (const std::string& name : opt.drop) {
    if (std::find(optional.begin(), optional.end(), name) == optional.end()) {
      std::string list;
      for (const auto& o : optional) list += (list.empty() ? "" : ", ") + o;
      throw InputError("--drop: '" + name + "' is not an optional grid; only " + list +
                       " can be dropped (the others are required by the VDL file contract)");
    }
  }
  std::unique_ptr<tbb::global_control> threadLimit;
  if (opt.threads > 0) {
    threadLimit = std::make_unique<tbb::global_control>(
        tbb::global_control::max_allowed_parallelism, size_t(opt.threads));
  }
  ConsoleProgress progress(opt.quiet);

  LoadedVdl in = readVdlGrid(opt.input);
  const int inDepth = in.grid.frame.depth;
  const size_t inVoxels = in.grid.size();
  const double inEnergy = energy(in.grid);
  const int depth = opt.depth > 0 ? opt.depth : inDepth;
  if (!opt.quiet) {
    for (const std::string& note : in.notes)
      std::printf("note: %s: %s\n", opt.input.c_str(), note.c_str());
  }
  if (depth > inDepth && opt.scene.empty()) {
    throw InputError("--depth " + std::to_string(depth) + " is finer than the input's depth " +
                     std::to_string(inDepth) +
                     ": converting to a finer grid needs --scene SCENE to know which voxels "
                     "hold geometry");
  }
  if (!opt.photonMap.empty() && opt.scene.empty()) {
    throw InputError(
        "--photon-map needs --scene SCENE: re-gathering voxelizes the scene at depth " +
        std::to_string(depth));
  }

  ClusterParams cluster;
  cluster.seed = opt.seed;
  std::string vdls = opt.vdls.empty() ? in.meta.vdls : opt.vdls;
  if (vdls == "auto") {
    cluster.autoCount = true;
    cluster.vdls = opt.vdls.empty() ? in.grid.maxVdls : kMaxVdls;
  } else {
    cluster.vdls = opt.vdls.empty() ? in.grid.maxVdls : std::stoi(opt.vdls);
    vdls = std::to_string(cluster.vdls);
  }

  BakeMetadata meta = in.meta;
  meta.depth = depth;
  meta.vdls = vdls;
  meta.convertedFrom = std::filesystem::path(opt.input).filename().string() + " (depth " +
                       std::to_string(inDepth) + ", " + std::to_string(in.grid.maxVdls) +
                       " VDL slots)";

  std::vector<StageReport> rows;
  VdlGrid out;
  std::string method;
  if (!opt.scene.empty() && (depth != inDepth || !opt.photonMap.empty())) {
    StageTimer loadTimer(rows, "load + voxelize scene");
    Scene scene = loadScene(opt.scene);
    GridParams gridParams;
    gridParams.depth = depth;
    SurfaceGrid grid = buildSurfaceGrid(scene, gridParams, &progress);
    // The bake voxelized the same scene with makeGridFrame, whose origin does
    // not depend on the depth: a different scene shows up here.
    checkNestedFrames(in.grid.frame, grid.frame, ("--scene " + opt.scene).c_str());
    loadTimer.finish(formatCount(grid.size()) + " voxels active at depth " + std::to_string(depth));
    if (!opt.photonMap.empty()) {
      StageTimer gatherTimer(rows, "re-gather");
      std::vector<Photon> photons = readPhotonPoints(opt.photonMap);
      splatPhotons(grid, photons);
      GatherParams gather;
      gather.k = in.meta.knn > 0 ? in.meta.knn : GatherParams{}.k;
      gather.radius = 0;  // the default for the new depth: kDefaultRadiusVoxels voxels
      out = buildVdlGrid(grid, photons, gather, cluster, &progress);
      meta.knn = gather.k;
      meta.radius = resolveRadius(gather, grid.frame);
      meta.photons = int64_t(photons.size());
      method = "re-gathered " + formatCount(photons.size()) + " photons";
      gatherTimer.finish(method);
    } else if (depth > inDepth) {
      StageTimer refineTimer(rows, "interpolate");
      RefineStats stats;
      out = refineVdlGrid(in.grid, grid, cluster, &stats);
      method = "trilinear interpolation of the parents";
      refineTimer.finish(stats.withoutParent
                             ? formatCount(stats.withoutParent) + " voxels without a parent (dark)"
                             : "");
    } else {
      StageTimer mergeTimer(rows, "merge");
      out = coarsenVdlGrid(in.grid, depth, cluster);
      method = "area-weighted merge of the children";
      mergeTimer.finish("");
    }
  } else if (depth < inDepth) {
    StageTimer mergeTimer(rows, "merge");
    out = coarsenVdlGrid(in.grid, depth, cluster);
    method = "area-weighted merge of the children";
    mergeTimer.finish("");
  } else if (cluster.vdls != in.grid.maxVdls || cluster.autoCount != (in.meta.vdls == "auto") ||
             !opt.vdls.empty()) {
    StageTimer clusterTimer(rows, "re-cluster");
    out = reclusterVdlGrid(in.grid, cluster);
    method = "re-clustered the VDLs";
    clusterTimer.finish("");
  } else {
    out = std::move(in.grid);
    method = "same grid";
  }

  StageTimer writeTimer(rows, "write .vdb");
  VdlWriteOptions write;
  write.halfFloat = opt.half;
  write.drop = opt.drop;
  writeVdlGrid(opt.output, out, meta, write);
  writeTimer.finish(opt.output + " (" +
                    formatBytes(size_t(std::filesystem::file_size(opt.output))) + ")");
  if (!opt.quiet) {
    printSummary(stdout, rows);
    std::printf("\n%s: depth %d -> %d, %s -> %s voxels, %s VDLs; %s\n", opt.input.c_str(), inDepth,
                depth, formatCount(inVoxels).c_str(), formatCount(out.size()).c_str(), vdls.c_str(),
                method.c_str());
    std::printf("sum of irradiance x area (W, channel mean): %.6g in, %.6g out\n", inEnergy,
                energy(out));
    std::printf("wrote %s\n", opt.output.c_str());
  }
  return 0;
}

}  // namespace

std::function<int()> addConvertCommand(CLI::App& app) {
  auto opt = std::make_shared<ConvertOptions>();
  CLI::App* cmd = app.add_subcommand(
      "convert",
      "Convert a baked .vdb to another depth (merge children / interpolate parents, or re-gather "
      "from a photon map), VDL count or storage.");
  cmd->add_option("input", opt->input, "Baked VDL file (.vdb)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", opt->output, "Output .vdb file (written atomically)")->required();
  cmd->add_option("--depth", opt->depth, "Output depth (default: the input's)")
      ->check(CLI::Range(1, 12));
  cmd->add_option("--vdls", opt->vdls, "VDLs per voxel, 1-8 or 'auto' (default: the input's)")
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
          "1..8|auto", "VdlCount"));
  cmd->add_flag("--half", opt->half,
                "Store irradiance, normal, VDL, angular_error and radius grids as half floats");
  cmd->add_option("--drop", opt->drop,
                  "Optional grids to leave out: photon_count, angular_error, radius, area")
      ->delimiter(',');
  cmd->add_option("--scene", opt->scene,
                  "The baked scene: needed for a finer --depth and for --photon-map")
      ->check(CLI::ExistingFile);
  cmd->add_option("--photon-map", opt->photonMap,
                  "Photon file written by 'bake --photon-map': re-gather at the new depth")
      ->check(CLI::ExistingFile);
  cmd->add_option("--seed", opt->seed, "K-means seed")->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 1024));
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress or summary, only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runConvert(*opt) : -1; };
}

}  // namespace lo::tool
