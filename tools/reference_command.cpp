// `lightoctree reference`: scene -> unbiased path-traced image (the ground truth).


#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "camera_options.h"
#include "picture_options.h"
#include "cli_checks.h"
#include "commands.h"
#include "scene_options.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/threads.h"
#include "image/image.h"
#include "lightgrid/grid_frame.h"
#include "reference/first_hit.h"
#include "reference/path_tracer.h"
#include "json_report.h"
#include "report.h"
#include "scene/scene.h"

namespace lo::tool {
namespace {

struct ReferenceOptions {
  std::string scene;
  SceneOptions sceneOptions;  // --sky
  AddedObjects objects;       // --add, --at
  std::string output;
  std::string stdErrorOutput;
  std::string emitterMaskOutput;
  CameraOptions camera;
  int width = 800, height = 600;  // as `render`, so that the images compare pixel for pixel
  int spp = 64;
  double timeBudget = 0;
  std::string part = "full";
  uint64_t seed = 1;
  int threads = 0;
  int maxBounces = 256;
  bool addedOnlyReceive = false;  // --added-only-receive
  PictureOptions picture;  // PNG only, as `render --exposure --tone-map`
  double edgeDistance = 0;  // 0 = one voxel of a depth-6 bake
  std::string json;  // --json FILE: tools/json_report.h
  bool quiet = false;
};

void checkImageOutput(const std::string& path, const char* flag) {
  checkOutputFolder(path, flag);
  if (!hasExtension(path, ".exr") && !hasExtension(path, ".png")) {
    throw InputError(std::string(flag) + ": '" + path + "' must end in .exr or .png");
  }
}

int runReference(const ReferenceOptions& opt) {
  checkImageOutput(opt.output, "--output");
  if (!opt.stdErrorOutput.empty()) checkImageOutput(opt.stdErrorOutput, "--std-error");
  if (!opt.emitterMaskOutput.empty()) checkImageOutput(opt.emitterMaskOutput, "--emitter-mask");
  if (!opt.json.empty()) checkOutputFolder(opt.json, "--json");
  const NamedPaths inputs = sceneInputs(opt.scene);
  checkDistinctFiles({{"--output", opt.output},
                      {"--std-error", opt.stdErrorOutput},
                      {"--emitter-mask", opt.emitterMaskOutput},
                      {"--json", opt.json}},
                     inputs);
  JsonReport report{"reference", inputs, {{"part", opt.part}, {"width", opt.width}, {"height", opt.height}}};
  std::vector<StageReport> rows;
  checkCameraOptions(opt.camera);
  (void)opt.picture.toneParams();  // a bad --exposure is refused before the work
  ThreadLimit threadLimit(opt.threads);

  Scene scene = loadSceneWith(opt.scene, opt.sceneOptions);
  placeObjects(scene, opt.objects);
  printSceneWarnings(scene);
  PinholeCamera camera = chooseCamera(opt.camera, scene, opt.scene);
  if (opt.addedOnlyReceive && opt.objects.empty())
    throw InputError("--added-only-receive: add an object first (--add, --at)");
  if (opt.part == "added-mask") {
    if (opt.objects.empty()) throw InputError("--part added-mask: add an object first (--add, --at)");
    FirstHitParams fp;
    fp.width = opt.width;
    fp.height = opt.height;
    fp.samplesPerPixel = std::min(opt.spp, 64);
    fp.seed = opt.seed;
    ConsoleProgress progress(opt.quiet);
    const RgbImage mask = renderFirstHits(
        scene, camera, fp,
        [&scene](const FirstHit& hit) {
          return scene.isAdded(hit.triangle) ? Vec3{1, 1, 1} : Vec3{0, 0, 0};
        },
        &progress);
    AtomicFileSet outputs;
    writeImage(opt.output, mask, 0.0f, &outputs);
    if (!opt.json.empty()) report.addTo(outputs, opt.json, rows);
    outputs.commit();
    if (!opt.quiet) std::printf("added-object mask: wrote %s\n", opt.output.c_str());
    return 0;
  }
  if (opt.part == "edge-mask") {
    FirstHitParams fp;
    fp.width = opt.width;
    fp.height = opt.height;
    fp.samplesPerPixel = std::min(opt.spp, 64);
    fp.seed = opt.seed;
    const float distance = opt.edgeDistance > 0 ? float(opt.edgeDistance)
                                                : makeGridFrame(scene.bounds(), 6).voxelSize;
    ConsoleProgress progress(opt.quiet);
    const RgbImage mask = renderEdgeMask(scene, camera, fp, distance, &progress);
    AtomicFileSet outputs;
    writeImage(opt.output, mask, 0.0f, &outputs);
    if (!opt.json.empty()) {
      report.figures["edge_distance"] = distance;
      report.addTo(outputs, opt.json, rows);
    }
    outputs.commit();
    if (!opt.quiet) {
      double covered = 0;
      for (size_t i = 0; i < mask.pixelCount(); ++i) covered += mask.at(i).x > 0 ? 1 : 0;
      std::printf("edge mask %s: %d x %d, within %g of an edge: %.1f%% of the pixels\nwrote %s\n",
                  opt.scene.c_str(), opt.width, opt.height, double(distance),
                  100.0 * covered / double(mask.pixelCount()), opt.output.c_str());
    }
    return 0;
  }
  ReferenceParams params;
  params.width = opt.width;
  params.height = opt.height;
  params.part = parseReferencePart(opt.part);
  params.samplesPerPixel = opt.spp;
  params.timeBudgetSeconds = opt.timeBudget;
  params.maxBounces = opt.maxBounces;
  params.addedOnlyReceive = opt.addedOnlyReceive;
  params.seed = opt.seed;

  ConsoleProgress progress(opt.quiet);
  StageTimer traceTimer(rows, "path trace");
  ReferenceImage result = renderReference(scene, camera, params, &progress);
  traceTimer.finish(std::to_string(result.samplesPerPixel) + " spp");
  // The image and its side images (and the report) appear together.
  AtomicFileSet outputs;
  ToneReport tone;
  writeTonedImage(opt.output, result.image, opt.picture.toneParams(), &outputs, &tone);
  if (!opt.stdErrorOutput.empty()) writeImage(opt.stdErrorOutput, result.stdError, 0.0f, &outputs);
  if (!opt.emitterMaskOutput.empty()) {
    writeImage(opt.emitterMaskOutput, result.emitterMask, 0.0f, &outputs);
  }
  if (!opt.json.empty()) {
    report.figures["samples_per_pixel"] = result.samplesPerPixel;
    report.figures["rays"] = result.raysTraced;
    report.figures["seconds"] = result.seconds;
    report.addTo(outputs, opt.json, rows);
  }
  outputs.commit();

  if (!opt.quiet && hasExtension(opt.output, ".png")) {
    std::printf("picture: %s\n", tone.ToString().c_str());
  }
  if (!opt.quiet) {
    // The mean standard error relative to the mean value: how far the
    // reference itself is from converged, to weigh errors measured against it.
    double sum = 0, se2 = 0;
    for (size_t i = 0; i < result.image.rgb.size(); ++i) {
      sum += result.image.rgb[i];
      se2 += double(result.stdError.rgb[i]) * result.stdError.rgb[i];
    }
    const double n = double(result.image.rgb.size());
    const double mean = sum / n, rmsSe = std::sqrt(se2 / n);
    std::printf(
        "%s %s: %d x %d, %d spp, %.2f s, %s rays, mean %.5g, RMS std. error %.5g (%.2f%%)\n",
        toString(params.part).c_str(), opt.scene.c_str(), opt.width, opt.height,
        result.samplesPerPixel, result.seconds, formatCount(result.raysTraced).c_str(), mean, rmsSe,
        mean > 0 ? 100.0 * rmsSe / mean : 0.0);
    std::printf("wrote %s%s%s\n", opt.output.c_str(), opt.stdErrorOutput.empty() ? "" : " and ",
                opt.stdErrorOutput.c_str());
  }
  return 0;
}

}  // namespace

std::function<int()> addReferenceCommand(CLI::App& app) {
  auto opt = std::make_shared<ReferenceOptions>();
  CLI::App* cmd = app.add_subcommand(
      "reference",
      "Path-trace the ground truth (unbiased, Embree) with the camera conventions of `render`: "
      "direct, indirect or full radiance, or the indirect irradiance at the first hit.");
  cmd->add_option("scene", opt->scene, "Scene: .gltf, .glb or .obj")
      ->required()
      ->check(CLI::ExistingFile);
  addSceneOptions(cmd, opt->sceneOptions);
  addObjectOptions(cmd, opt->objects);
  cmd->add_flag("--added-only-receive", opt->addedOnlyReceive,
                "With --add: the camera sees the added objects, no other ray does: they are lit "
                "by the scene as it was baked and neither shadow nor light it (not even their "
                "direct shadows, which `render --add` draws): on a convex object's own pixels, "
                "the judge of the free-space light alone");
  cmd->add_option("-o,--output", opt->output,
                  "Image: .exr (linear float) or .png (sRGB, for a quick look)")
      ->required();
  addCameraOptions(cmd, opt->camera);
  cmd->add_option("--width", opt->width, "Image width in pixels")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Image height in pixels")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  addPictureOptions(cmd, opt->picture);
  auto* spp = cmd->add_option("--spp", opt->spp, "Samples per pixel")
                  ->check(CLI::Range(1, 1000000))
                  ->capture_default_str();
  cmd->add_option("--time-budget", opt->timeBudget,
                  "Render passes of 1 sample per pixel until this many seconds have passed "
                  "(instead of --spp)")
      ->check(CLI::Range(1e-3, 1e7))
      ->excludes(spp);
  cmd->add_option("--part", opt->part,
                  "full | direct | indirect (what `render --mode indirect` approximates) | "
                  "irradiance (indirect irradiance at the first hit, W/m^2) | added-mask (the share of each pixel's rays that first hit an --add object) | edge-mask (1 where "
                  "the first hit lies within --edge-distance of an edge, for `compare --mask`; "
                  "--spp up to 64 rays per pixel)")
      ->check(CLI::IsMember({"full", "direct", "indirect", "irradiance", "edge-mask", "added-mask"}))
      ->capture_default_str();
  cmd->add_option("--edge-distance", opt->edgeDistance,
                  "With --part edge-mask: how near an edge, in scene units (default: one voxel "
                  "of a depth-6 bake of the scene)")
      ->check(finitePositive());
  cmd->add_option("--seed", opt->seed, "Random seed (same seed and --spp, same bytes)")
      ->check(seedValidator())
      ->capture_default_str();
  cmd->add_option("--threads", opt->threads, "Worker threads (0 = all cores)")
      ->check(CLI::Range(0, 1024))
      ->capture_default_str();
  cmd->add_option("--max-bounces", opt->maxBounces,
                  "Cap on scattering events after the first hit (Russian roulette ends "
                  "paths long before)")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  cmd->add_option("--std-error", opt->stdErrorOutput,
                  "Also write the per-pixel standard error of the mean (.exr or .png)");
  cmd->add_option("--emitter-mask", opt->emitterMaskOutput,
                  "Also write a mask for `compare --mask` (.png or .exr): white where the "
                  "pixel's centre sees no emissive surface, black on the light fixtures, whose "
                  "own pixels the octree and the path tracer define differently")
      ->check(CLI::NonexistentPath | CLI::ExistingFile);
  cmd->add_option("--json", opt->json,
                  "Also write a JSON report: the files read and written, samples, rays and time "
                  "(README.md, \"Scripting\")");
  cmd->add_flag("-q,--quiet", opt->quiet, "Only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runReference(*opt) : -1; };
}

}  // namespace lo::tool
