// `lightoctree sweep`: the speed/accuracy trade of the bake, measured (src/sweep/sweep.h).

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>

#include "cli_checks.h"
#include "command_options.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "report.h"
#include "scene_options.h"
#include "sweep/sweep.h"

namespace lo::tool {
namespace {

struct SweepOptions {
  std::string scene;
  std::string out;
  bool quick = false;
  bool tiny = false;
  int width = 0, height = 0, spp = 0, frames = -1;  // 0 / -1: the scale's default
  int threads = 0;
  uint64_t seed = 1;
  bool quiet = false;
};

int runSweepCommand(const SweepOptions& opt) {
  if (opt.quick && opt.tiny) throw InputError("--quick and --tiny: choose one");
  const SweepScale scale = opt.tiny    ? SweepScale::Tiny
                           : opt.quick ? SweepScale::Quick
                                       : SweepScale::Full;
  SweepParams params = sweepDefaults(scale);
  params.scene = opt.scene;
  params.outDir = opt.out;
  if (opt.width > 0) params.width = opt.width;
  if (opt.height > 0) params.height = opt.height;
  if (opt.spp > 0) params.referenceSpp = opt.spp;
  if (opt.frames >= 0) params.frames = opt.frames;
  params.threads = opt.threads;
  params.seed = opt.seed;
  ConsoleProgress progress(opt.quiet);
  params.progress = &progress;
  // A results folder: an existing one is reused; a new one needs its parent.
  checkResultsFolder(opt.out, "--out");
  // Its tables, pictures, plot data and cache take names of their own
  // (src/sweep): a folder holding a file the scene reads is not one.
  const NamedPaths inputs = sceneInputs(opt.scene);
  for (const std::string& folder : {opt.out, opt.out + "/cache", opt.out + "/plot-data"}) {
    checkFolderOutputs(
        folder, [&](const std::string&) { return "results written to '" + folder + "'"; }, "--out",
        inputs);
  }
  std::filesystem::create_directories(opt.out);
  std::FILE* log = opt.quiet ? nullptr : stdout;
  std::vector<SweepResult> results = runSweep(params, log);
  writeSweepReport(params, results, log);
  if (log) std::fprintf(log, "wrote %s/sweep.md, sweep.csv and plots\n", opt.out.c_str());
  return 0;
}

void addSweepOptions(CLI::App* cmd, SweepOptions& opt) {
  cmd->description(
      "Measure the speed/accuracy trade: bake at settings around the paper's (depth, photons, "
      "KNN k, radius, VDLs, interpolation, half floats), compare each with a path-traced "
      "reference, write a table, CSV and plots with the Pareto front.");
  addSceneArgument(cmd, opt.scene);
  cmd->add_option("--out", opt.out,
                  "Results folder (created); bakes and images go to its cache/ subfolder, "
                  "which a rerun reuses")
      ->required();
  cmd->add_flag("--quick", opt.quick, "A reduced sweep: fewer points, smaller images");
  cmd->add_flag("--tiny", opt.tiny, "Three tiny points (a smoke test)")->group("");
  cmd->add_option("--width", opt.width, "Image width (default: 160, quick 96)")
      ->check(wholeIn(1, 4096));
  cmd->add_option("--height", opt.height, "Image height (default: 120, quick 72)")
      ->check(wholeIn(1, 4096));
  cmd->add_option("--spp", opt.spp, "Reference samples per pixel (default: 8192, quick 2048)")
      ->check(wholeIn(1, 1000000));
  cmd->add_option("--frames", opt.frames,
                  "Frames timed per point with OSMesa (0: no GL render; default 5, quick 2)")
      ->check(wholeIn(0, 1000));
  addThreadsOption(cmd, opt.threads)->capture_default_str();
  cmd->add_option("--seed", opt.seed, "Random seed of bakes and references")
      ->check(seedValidator())
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opt.quiet, "Only errors");
}

}  // namespace

std::function<int()> addSweepCommand(CLI::App& app) {
  return addCommand(app, "sweep", addSweepOptions, runSweepCommand);
}

}  // namespace lo::tool
