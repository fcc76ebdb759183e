// `lightoctree bake`: parses (bake_options.h), calls bake() (src/bake) or, under
// mpirun, distributedBake(), writes the .vdb and reports.

#include <CLI/CLI.hpp>

#include <cstdio>
#include <filesystem>

#include "bake/bake.h"
#include "bake/stats_json.h"
#include "bake_options.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/threads.h"
#include "distributed/mpi_session.h"
#include "distributed/distributed_stats.h"
#include "distributed/rank_agreement.h"
#include "distributed/tiled_bake.h"
#include "report.h"
#include "scene/scene.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

int runBakeOn(const BakeOptions& options, Communicator* comm) {
  const int rank = comm ? comm->rank() : 0;
  BakeOptions opt = options;
  // Only rank 0 reports and writes; the others bake their tiles in silence.
  opt.quiet = opt.quiet || rank != 0;
  if (rank == 0) {  // the one that writes: another machine may lack the folder
    checkOutputFile(opt.output, "--output", ".vdb");
    if (!opt.photonMap.empty()) checkOutputFile(opt.photonMap, "--photon-map", ".vdb");
    if (!opt.statsJson.empty()) checkOutputFile(opt.statsJson, "--stats-json", ".json");
    checkDistinctFiles(
        {{"--output", opt.output}, {"--photon-map", opt.photonMap}, {"--stats-json", opt.statsJson}},
        sceneInputs(opt.scene, opt.sceneOptions));
  }

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
  Scene scene;
  if (comm) {
    // Each rank reads its own copy: one that fails ends them all with its words.
    std::string failure;
    try {
      scene = loadSceneWith(opt.scene, opt.sceneOptions);
    } catch (const std::exception& e) {
      failure = e.what();
    }
    checkRanksSucceeded(*comm, failure);
  } else {
    scene = loadSceneWith(opt.scene, opt.sceneOptions);
  }
  printSceneWarnings(scene);
  if (opt.bounds.empty() && !scene.region.empty() && !opt.quiet) {
    Bounds3 world;  // the file's coordinates
    world.extend(scene.toWorld(scene.region.lower).toVec3());
    world.extend(scene.toWorld(scene.region.upper).toVec3());
    std::printf("region of interest marked in the scene: %s (--bounds overrides it)\n",
                world.ToString().c_str());
  }
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.lights.size()) + " punctual lights");

  BakeParams params = opt.bakeParams(scene);
  if (comm && opt.photons == 0 && opt.targetError == 0) {
    // A target bake runs in one process: under mpirun the default is the
    // paper's fixed budget.
    params.targetError = 0;
    params.photons = BakeParams{}.photons;
    if (!opt.quiet) {
      std::printf("under mpirun the bake stores a fixed %s photons (--photons); "
                  "--target-error needs one process\n",
                  formatCount(params.photons).c_str());
    }
  }
  DistributedStats distributed;
  TileParams tiles;
  tiles.tilesPerAxis = opt.tiles == "auto" ? 0 : std::stoi(opt.tiles);
  // The names as given (machines may differ in their working folders).
  const std::string outputNames = opt.output + '\n' + opt.statsJson;
  BakeResult baked =
      comm ? distributedBake(scene, params, tiles, *comm, &progress, &distributed, outputNames)
           : bake(scene, params, &progress);
  if (rank != 0) return 0;
  rows.insert(rows.end(), baked.stats.stages.begin(), baked.stats.stages.end());
  const std::string missed = photonBudgetWarning(params, baked.stats);
  if (!missed.empty()) std::fprintf(stderr, "warning: %s\n", missed.c_str());
  recordSourceScene(baked.metadata, scene);

  // The .vdb, the photon map and the stats appear together or not at all: a
  // side file that fails (a full disk, a name refused) leaves the old .vdb.
  AtomicFileSet outputs;
  StageTimer writeTimer(rows, "write .vdb");
  writeVdlGrid(opt.output, baked.grid, baked.metadata, {}, &outputs);
  const size_t fileBytes = size_t(outputs.bytesOf(opt.output));
  writeTimer.finish(opt.output + " (" + formatBytes(fileBytes) + ")");

  if (!opt.photonMap.empty()) {
    StageTimer pointsTimer(rows, "write photon map");
    writePhotonPoints(opt.photonMap, baked.photons.photons, baked.grid.frame.voxelSize,
                      scene.origin, &outputs, photonMapInfo(baked.metadata));
    pointsTimer.finish(opt.photonMap);
  }

  if (!opt.quiet) {
    printSummary(stdout, rows);
    const BakeStats& st = baked.stats;
    for (size_t i = 0; i < st.passes.size(); ++i) {
      std::printf("pass %zu: %s photons, %s\n", i + 1, formatCount(st.passes[i].photons).c_str(),
                  st.passes[i].noise.ToString().c_str());
    }
    if (!st.passes.empty()) {
      std::printf("target error %s: %s after %zu pass%s, %s photons\n",
                  formatNumber(params.targetError).c_str(), st.targetStop.c_str(),
                  st.passes.size(), st.passes.size() == 1 ? "" : "es",
                  formatCount(st.storedPhotons).c_str());
    } else {
      std::printf("%s\n", st.noise.ToString().c_str());
    }
  }
  // Running out of paths is photonBudgetWarning's, with its advice.
  if (!baked.stats.passes.empty() && baked.stats.targetStop != "target reached" &&
      baked.stats.targetStop != "no more paths") {
    std::fprintf(stderr,
                 "warning: the noise target %s was not reached (%s): the grid's %s; raise "
                 "--max-photons, bake at a smaller --depth or ask for a larger --target-error\n",
                 formatNumber(params.targetError).c_str(), baked.stats.targetStop.c_str(),
                 baked.stats.noise.ToString().c_str());
  }
  if (!opt.quiet && comm) std::printf("%s", ranksTable(distributed, baked.stats.storedPhotons).c_str());

  if (!opt.statsJson.empty()) {
    BakeStatsRecord record;
    record.scene = opt.scene;
    record.output = opt.output;
    record.params = params;
    record.radius = baked.metadata.radius;
    record.threads = opt.threads;
    record.vdbBytes = fileBytes;
    record.stages = rows;
    record.peakRssBytes = peakRssBytes();
    if (comm) {
      record.sections.emplace_back(
          "distributed", distributedStatsJson(distributed, comm->size(), baked.stats.storedPhotons));
    }
    outputs.addText(opt.statsJson, bakeStatsJson(baked.stats, record));
  }
  outputs.commit();
  if (!opt.quiet) std::printf("\nwrote %s\n", opt.output.c_str());
  return 0;
}

/// Under mpirun (an MPI build), every rank bakes its tiles; a rank that fails
/// ends the job (MpiSession::abort), saying why: none waits forever, rank 0
/// writes nothing. What all refuse together (RanksRefuseError) rank 0 says.
int runBake(const BakeOptions& opt) {
  const int launched = mpiLaunchSize();
  if (launched == 0 || (launched == 1 && !mpiAvailable())) return runBakeOn(opt, nullptr);
  MpiSession session;  // throws, naming the fix, when built without MPI
  const int rank = session.world().rank();
  try {
    return runBakeOn(opt, &session.world());
  } catch (const RanksRefuseError& e) {
    // Every rank threw it at once: rank 0 says it, and each ends normally.
    if (rank == 0) std::fprintf(stderr, "lightoctree: error: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    // An error of this rank alone (its memory, its machine), said by it.
    std::fprintf(stderr, "lightoctree: error%s: %s\n",
                 rank == 0 ? "" : (" on rank " + std::to_string(rank)).c_str(), e.what());
    std::fflush(stderr);
    session.abort(1);
  }
}

}  // namespace

std::function<int()> addBakeCommand(CLI::App& app) {
  return addCommand(app, "bake", addBakeOptions, runBake);
}

}  // namespace lo::tool
