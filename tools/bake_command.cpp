// `lightoctree bake`: parses, calls bake() (src/bake), writes the .vdb and reports.

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "bake/bake.h"
#include "cli_checks.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "core/threads.h"
#include "distributed/mpi_session.h"
#include "distributed/tiled_bake.h"
#include "report.h"
#include "scene/scene.h"
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
  std::string representation = "vdl";
  uint64_t seed = 1;
  int threads = 0;  // 0 = all cores
  bool includeDirect = false;
  std::string layers = "on";
  std::string occlusion = "on";
  std::string edgeCorrection = "on";
  std::string smoothing = "on";
  int autoCap = BakeParams{}.autoCap;
  float autoThreshold = BakeParams{}.autoThreshold;
  std::vector<double> bounds;  // x0 y0 z0 x1 y1 z1, empty = the whole scene
  std::string photonMap;
  std::string statsJson;
  std::string tiles = "auto";
  bool quiet = false;
};

/// One row per rank of a distributed bake.
void printRanks(const DistributedStats& d, size_t storedPhotons) {
  std::printf("\n%d^3 tiles, photon halo %d voxels%s\n", d.tilesPerAxis, d.photonHalo,
              d.attempts > 1 ? " (second attempt: the bins' margin exceeded the first halo's)" : "");
  std::printf("%4s %12s %12s %10s %10s %7s %12s %10s %8s\n", "rank", "photons", "held",
              "voxels", "computed", "work", "sent", "peak RSS", "seconds");
  for (const RankStats& r : d.ranks) {
    std::printf("%4d %12s %12s %10s %10s %6.1f%% %12s %10s %8.2f\n", r.rank,
                formatCount(size_t(r.photonsTraced)).c_str(),
                formatCount(size_t(r.photonsHeld)).c_str(),
                formatCount(size_t(r.voxelsOwned)).c_str(),
                formatCount(size_t(r.voxelsComputed)).c_str(), 100.0 * r.workShare,
                formatBytes(size_t(r.bytesSent)).c_str(), formatBytes(size_t(r.peakRssBytes)).c_str(),
                r.totalSeconds);
  }
  uint64_t sent = 0;
  for (const RankStats& r : d.ranks) sent += r.bytesSent;
  if (storedPhotons > 0) {
    std::printf("photons exchanged: %.1f bytes per stored photon\n",
                double(sent) / double(storedPhotons));
  }
}

int runBakeOn(const BakeOptions& options, Communicator* comm) {
  const int rank = comm ? comm->rank() : 0;
  BakeOptions opt = options;
  // Only rank 0 reports and writes; the others bake their tiles in silence.
  opt.quiet = opt.quiet || rank != 0;
  checkOutputFolder(opt.output, "--output");
  if (!opt.photonMap.empty()) checkOutputFolder(opt.photonMap, "--photon-map");
  if (!opt.statsJson.empty()) checkOutputFolder(opt.statsJson, "--stats-json");
  checkDistinctFiles(
      {{"--output", opt.output}, {"--photon-map", opt.photonMap}, {"--stats-json", opt.statsJson}},
      {{"SCENE", opt.scene}});

  ThreadLimit threadLimit(opt.threads);
  ConsoleProgress progress(opt.quiet);
  if (comm && !opt.quiet) {
    std::printf("baking on %d ranks (mpirun)\n", comm->size());
  }
  // Each rank runs its stages on threads; a rank pinned to one core (mpirun's
  // default binding) runs them one at a time.
  if (comm && usableCores() < hardwareThreads() && usableCores() < 2) {
    std::fprintf(stderr,
                 "warning: rank %d may use %d of this machine's %d cores (mpirun binds each rank "
                 "to a core by default): run mpirun --bind-to none, or one rank per machine\n",
                 rank, usableCores(), hardwareThreads());
  }
  std::vector<StageReport> rows;

  StageTimer loadTimer(rows, "load scene");
  Scene scene = loadScene(opt.scene);
  printSceneWarnings(scene);
  if (opt.bounds.empty() && !scene.region.empty() && !opt.quiet) {
    std::printf("region of interest marked in the scene: %s (--bounds overrides it)\n",
                scene.region.ToString().c_str());
  }
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.lights.size()) + " punctual lights");

  BakeParams params;
  params.depth = opt.depth;
  params.photons = opt.photons;
  params.knn = opt.knn;
  params.radius = opt.radius;
  params.vdls = parseVdlCount(opt.vdls);
  params.seed = opt.seed;
  params.includeDirect = opt.includeDirect;
  params.layers = opt.layers == "on";
  params.occlusion = opt.occlusion == "on";
  params.edgeCorrection = opt.edgeCorrection == "on";
  params.smoothing = opt.smoothing == "on";
  params.autoCap = opt.autoCap;
  params.autoThreshold = opt.autoThreshold;
  parseRepresentation(opt.representation, &params.representation);  // checked by the flag
  if (!opt.bounds.empty()) {
    params.region.extend(Vec3{float(opt.bounds[0]), float(opt.bounds[1]), float(opt.bounds[2])});
    params.region.extend(Vec3{float(opt.bounds[3]), float(opt.bounds[4]), float(opt.bounds[5])});
  }
  params.keepPhotons = !opt.photonMap.empty();
  DistributedStats distributed;
  TileParams tiles;
  tiles.tilesPerAxis = opt.tiles == "auto" ? 0 : std::stoi(opt.tiles);
  BakeResult baked = comm ? distributedBake(scene, params, tiles, *comm, &progress, &distributed)
                          : bake(scene, params, &progress);
  if (rank != 0) return 0;
  rows.insert(rows.end(), baked.stats.stages.begin(), baked.stats.stages.end());
  const std::string missed = photonBudgetWarning(params, baked.stats);
  if (!missed.empty()) std::fprintf(stderr, "warning: %s\n", missed.c_str());
  baked.metadata.sourceScene = std::filesystem::path(opt.scene).filename().string();

  StageTimer writeTimer(rows, "write .vdb");
  writeVdlGrid(opt.output, baked.grid, baked.metadata);
  size_t fileBytes = size_t(std::filesystem::file_size(opt.output));
  writeTimer.finish(opt.output + " (" + formatBytes(fileBytes) + ")");

  if (!opt.photonMap.empty()) {
    StageTimer pointsTimer(rows, "write photon map");
    writePhotonPoints(opt.photonMap, baked.photons.photons, baked.grid.frame.voxelSize);
    pointsTimer.finish(opt.photonMap);
  }

  if (!opt.quiet) printSummary(stdout, rows);
  if (!opt.quiet && comm) printRanks(distributed, baked.stats.storedPhotons);

  if (!opt.statsJson.empty()) {
    const BakeStats& st = baked.stats;
    nlohmann::json j;
    j["scene"] = opt.scene;
    j["output"] = opt.output;
    j["parameters"] = {{"depth", opt.depth},         {"photons", opt.photons},
                       {"knn", opt.knn},             {"radius", baked.metadata.radius},
                       {"vdls", opt.vdls},           {"representation", opt.representation},
                       {"seed", opt.seed},
                       {"threads", opt.threads},     {"include_direct", opt.includeDirect},
                       {"layers", opt.layers},       {"gather_occlusion", opt.occlusion},
                       {"edge_correction", opt.edgeCorrection}, {"smoothing", opt.smoothing}};
    j["counts"] = {{"triangles", st.triangles},
                   {"stored_photons", st.storedPhotons},
                   {"emitted_paths", st.emittedPaths},
                   {"active_voxels", st.level.activeVoxels},
                   {"dense_voxels", st.denseVoxels},
                   {"photons_outside_grid", st.level.droppedPhotons},
                   {"vdb_bytes", fileBytes}};
    j["thread_seconds"] = {{"gather", st.level.threadSeconds.gatherSeconds},
                           {"cluster", st.level.threadSeconds.clusterSeconds}};
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
    if (comm) {
      nlohmann::json ranks = nlohmann::json::array();
      uint64_t sent = 0;
      for (const RankStats& r : distributed.ranks) {
        sent += r.bytesSent;
        ranks.push_back({{"rank", r.rank},
                         {"photons_traced", r.photonsTraced},
                         {"photons_held", r.photonsHeld},
                         {"tiles_owned", r.tilesOwned},
                         {"work_share", r.workShare},
                         {"voxels_owned", r.voxelsOwned},
                         {"voxels_computed", r.voxelsComputed},
                         {"voxels_held", r.voxelsHeld},
                         {"bytes_sent", r.bytesSent},
                         {"bytes_received", r.bytesReceived},
                         {"peak_rss_bytes", r.peakRssBytes},
                         {"seconds", {{"trace", r.traceSeconds},
                                      {"exchange", r.exchangeSeconds},
                                      {"voxelize", r.voxelizeSeconds},
                                      {"splat", r.splatSeconds},
                                      {"gather_cluster", r.gatherClusterSeconds},
                                      {"merge", r.mergeSeconds},
                                      {"total", r.totalSeconds}}}});
      }
      j["distributed"] = {
          {"ranks", comm->size()},
          {"tiles_per_axis", distributed.tilesPerAxis},
          {"photon_halo_voxels", distributed.photonHalo},
          {"attempts", distributed.attempts},
          {"bin_margin_voxels", distributed.binMarginVoxels},
          {"bytes_exchanged_per_photon",
           st.storedPhotons ? double(sent) / double(st.storedPhotons) : 0.0},
          {"per_rank", ranks},
          // Tile (x * T + y) * T + z: its rank and estimated work (docs/scale.md).
          {"tile_owner", distributed.tileOwner},
          {"tile_work", distributed.tileWork}};
    }
    writeTextAtomically(opt.statsJson, j.dump(2) + "\n");
  }
  if (!opt.quiet) std::printf("\nwrote %s\n", opt.output.c_str());
  return 0;
}

/// Under mpirun (an MPI build), every rank bakes its tiles; a rank that
/// fails ends the whole job (MpiSession::abort), so none waits forever and
/// rank 0 writes nothing.
int runBake(const BakeOptions& opt) {
  const int launched = mpiLaunchSize();
  if (launched == 0 || (launched == 1 && !mpiAvailable())) return runBakeOn(opt, nullptr);
  MpiSession session;  // throws, naming the fix, when built without MPI
  const int rank = session.world().rank();
  try {
    return runBakeOn(opt, &session.world());
  } catch (const std::exception& e) {
    // Rank 0 says what went wrong; the others add only what is their own.
    if (rank == 0 || !dynamic_cast<const InputError*>(&e)) {
      std::fprintf(stderr, "lightoctree: error%s: %s\n",
                   rank == 0 ? "" : (" on rank " + std::to_string(rank)).c_str(), e.what());
    }
    std::fflush(stderr);
    session.abort(1);
  }
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
      ->check(depthValidator())
      ->capture_default_str();
  cmd->add_option("--photons", opt->photons, "Photons to store in the photon map")
      ->check(CLI::Range(size_t(1), size_t(200000000)))
      ->capture_default_str();
  cmd->add_option("--knn", opt->knn, "Nearest photons gathered per voxel (paper: 300)")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--radius", opt->radius,
                  "Gathering radius in scene units (default: " + formatNumber(kDefaultRadiusVoxels) + " voxel sizes)")
      ->check(finitePositive());
  cmd->add_option("--vdls", opt->vdls,
                  "VDLs per voxel, 1-" + std::to_string(kMaxVdls) + ", or 'auto' for the fewest (up to --auto-cap) whose "
                  "angular error is under --auto-threshold")
      ->check(vdlCountValidator())
      ->capture_default_str();
  cmd->add_option("--representation", opt->representation,
                  "How each voxel stores its light: 'vdl' (virtual directional lights, the "
                  "paper's), or the irradiance as spherical harmonics of order 1 ('sh1', 4 terms) "
                  "or 2 ('sh2', 9 terms); docs/accuracy.md compares them")
      ->check(CLI::IsMember(representationNames()))
      ->capture_default_str();
  cmd->add_option("--auto-cap", opt->autoCap, "With --vdls auto: at most this many VDLs per voxel")
      ->check(CLI::Range(1, kMaxVdls))
      ->capture_default_str();
  cmd->add_option("--auto-threshold", opt->autoThreshold,
                  "With --vdls auto: the fewest VDLs whose angular error (chord-length deviation, "
                  "0..2; 0.35 is about 20 degrees) is under this")
      ->check(finitePositive())
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Random seed (same seed, same bytes)")
      ->check(seedValidator())->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_flag("--include-direct", opt->includeDirect,
                "Also store direct-light photons (by default the GL renderer draws direct light)");
  cmd->add_option("--layers", opt->layers,
                  "Surface layers: a voxel whose photons land on surfaces facing clearly "
                  "different ways (an edge, the two sides of a thin wall) keeps one gather and "
                  "one set of VDLs per orientation (docs/accuracy.md)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--gather-occlusion", opt->occlusion,
                  "Leave out photons that lie behind geometry seen from the voxel: no light "
                  "gathered through thin walls (one shadow ray per neighbouring photon group)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--edge-correction", opt->edgeCorrection,
                  "Divide the gathered power by the part of the gather disc that lies on the "
                  "surface, not the whole disc: next to an edge the plain estimate is too dark")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--smoothing", opt->smoothing,
                  "Smooth each voxel's estimate with its neighbours on the same surface, where "
                  "they differ by no more than the photon noise explains (shadow edges kept)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--bounds", opt->bounds,
                  "A region of interest, x0,y0,z0,x1,y1,z1 in scene units: the grid covers it "
                  "alone, photons are stored only inside it and suns shine on its footprint "
                  "(a room on a large ground plane)")
      ->expected(6)
      ->delimiter(',');
  cmd->add_option("--photon-map", opt->photonMap,
                  "Also write the photons as an OpenVDB point grid for inspection");
  cmd->add_option("--stats-json", opt->statsJson,
                  "Write the per-stage figures as JSON (under mpirun, per rank too: time, "
                  "bytes sent, peak memory)");
  cmd->add_option("--tiles", opt->tiles,
                  "Under mpirun (mpirun -np N lightoctree bake ...): tiles per axis the grid is "
                  "cut into and shared among the ranks by estimated memory, a power of two with "
                  "tiles of at least 8^3 voxels, or 'auto' (32, fewer for shallow grids). The "
                  ".vdb bytes are the one-process bake's whatever the tiles and ranks "
                  "(docs/scale.md)")
      ->check(tilesValidator())
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opt->quiet, "No progress or summary, only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runBake(*opt) : -1; };
}

}  // namespace lo::tool
