#include "reference_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>

#include "cli_checks.h"
#include "command_options.h"
#include "core/error.h"

namespace lo::tool {

ReferenceParams referenceParams(const ReferenceOptions& opt) {
  ReferenceParams params;
  params.width = opt.width;
  params.height = opt.height;
  params.part = parseReferencePart(opt.part);
  params.samplesPerPixel = opt.spp;
  params.timeBudgetSeconds = opt.timeBudget;
  params.maxBounces = opt.maxBounces;
  params.addedOnlyReceive = opt.addedOnlyReceive;
  params.seed = opt.seed;
  return params;
}

void checkStdErrorSamples(const ReferenceOptions& opt, bool wanted, int samplesMade) {
  if (!wanted) return;
  if (samplesMade < 0 && !(opt.timeBudget > 0) && opt.spp < 2) {
    throw InputError("--std-error needs --spp 2 or more: one sample per pixel says nothing of "
                     "its spread");
  }
  if (samplesMade >= 0 && samplesMade < 2) {
    throw InputError("--std-error: the --time-budget allowed one sample per pixel, which says "
                     "nothing of its spread: raise --time-budget (nothing was written)");
  }
}

FirstHitParams firstHitParams(const ReferenceOptions& opt) {
  FirstHitParams params;
  params.width = opt.width;
  params.height = opt.height;
  params.samplesPerPixel = std::min(opt.spp, 64);
  params.seed = opt.seed;
  return params;
}

void addReferenceOptions(CLI::App* cmd, ReferenceOptions& opt) {
  cmd->description(
      "Path-trace the ground truth (unbiased, Embree) with the camera conventions of `render`: "
      "direct, indirect or full radiance, or the indirect irradiance at the first hit.");
  addSceneFlags(cmd, opt);
  cmd->add_flag("--added-only-receive", opt.addedOnlyReceive,
                "With --add: the camera sees the added objects, no other ray does: they are lit "
                "by the scene as it was baked and neither shadow nor light it (not even their "
                "direct shadows, which `render --add` draws): on a convex object's own pixels, "
                "the judge of the free-space light alone");
  cmd->add_option("-o,--output", opt.output,
                  "Image: .exr (linear float) or .png (sRGB, for a quick look)")
      ->required();
  addCameraOptions(cmd, opt.camera);
  addSizeOptions(cmd, opt.width, opt.height);
  addPictureOptions(cmd, opt.picture);
  auto* spp = cmd->add_option("--spp", opt.spp, "Samples per pixel")
                  ->check(wholeIn(1, 1000000))
                  ->capture_default_str();
  cmd->add_option("--time-budget", opt.timeBudget,
                  "Render passes of 1 sample per pixel until this many seconds have passed "
                  "(instead of --spp)")
      ->check(numberIn({1e-3, 1e7}))
      ->excludes(spp);
  cmd->add_option("--part", opt.part,
                  "full | direct | indirect (what `render --mode indirect` approximates) | "
                  "irradiance (indirect irradiance at the first hit, W/m^2) | added-mask (the "
                  "share of each pixel's rays that first hit an --add object) | edge-mask (1 where "
                  "the first hit lies within --edge-distance of an edge, for `compare --mask`; "
                  "--spp up to 64 rays per pixel)")
      ->check(
          CLI::IsMember({"full", "direct", "indirect", "irradiance", "edge-mask", "added-mask"}))
      ->capture_default_str();
  cmd->add_option("--edge-distance", opt.edgeDistance,
                  "With --part edge-mask: how near an edge, in scene units (default: one voxel "
                  "of a depth-6 bake of the scene)")
      ->check(numberIn(kPositiveNumber));
  cmd->add_option("--seed", opt.seed, "Random seed (same seed and --spp, same bytes)")
      ->check(seedValidator())
      ->capture_default_str();
  addThreadsOption(cmd, opt.threads)->capture_default_str();
  cmd->add_option("--max-bounces", opt.maxBounces,
                  "Cap on scattering events after the first hit (Russian roulette ends "
                  "paths long before)")
      ->check(wholeIn(0, 100000))
      ->capture_default_str();
  cmd->add_option("--std-error", opt.stdErrorOutput,
                  "Also write the per-pixel standard error of the mean (.exr or .png); needs 2 or "
                  "more samples per pixel");
  cmd->add_option("--emitter-mask", opt.emitterMaskOutput,
                  "Also write a mask for `compare --mask` (.png or .exr): white where the "
                  "pixel's centre sees no emissive surface, black on the light fixtures, whose "
                  "own pixels the octree and the path tracer define differently")
      ->check(CLI::NonexistentPath | existingFile());
  cmd->add_option("--geometry-mask", opt.geometryMaskOutput,
                  "Also write a mask for `compare --mask` (.png or .exr): white where the "
                  "pixel's centre sees a surface that does not emit, black on the background "
                  "and on the light fixtures: the pixels left out by what they show, never by "
                  "their value (unlike `compare --ignore-background`)")
      ->check(CLI::NonexistentPath | existingFile());
  cmd->add_option("--json", opt.json,
                  "Also write a JSON report: the files read and written, samples, rays and time "
                  "(README.md, \"Scripting\")");
  cmd->add_flag("-q,--quiet", opt.quiet, "Only errors");
}

}  // namespace lo::tool
