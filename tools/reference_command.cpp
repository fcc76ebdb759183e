// `lightoctree reference`: scene -> unbiased path-traced image (the ground truth).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>

#include "camera_options.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/threads.h"
#include "image/compare.h"
#include "image/image.h"
#include "json_report.h"
#include "lightgrid/grid_frame.h"
#include "picture_options.h"
#include "reference/first_hit.h"
#include "reference/path_tracer.h"
#include "reference_options.h"
#include "report.h"
#include "scene/scene.h"
#include "scene_options.h"

namespace lo::tool {
namespace {

void checkImageOutput(const std::string& path, const char* flag) {
  checkOutputFolder(path, flag);
  checkOutputExtension(path, flag, {".exr", ".png"});
}

/// --part added-mask | edge-mask: a mask of the first hits, no paths traced;
/// up to 64 rays per pixel give the share of each pixel that is selected.
int renderMask(const ReferenceOptions& opt, const Scene& scene, const PinholeCamera& camera,
               JsonReport& report, const std::vector<StageReport>& rows) {
  const bool added = opt.part == "added-mask";
  if (added && opt.objects.empty()) {
    throw InputError("--part added-mask: add an object first (--add, --at)");
  }
  const FirstHitParams fp = firstHitParams(opt);
  ConsoleProgress progress(opt.quiet);
  RgbImage mask;
  float distance = 0;  // edge-mask: how near an edge, scene units
  if (added) {
    mask = renderFirstHits(
        scene, camera, fp,
        [&scene](const FirstHit& hit) {
          return scene.isAdded(hit.triangle) ? Vec3{1, 1, 1} : Vec3{0, 0, 0};
        },
        &progress);
  } else {
    distance =
        opt.edgeDistance > 0 ? float(opt.edgeDistance) : makeGridFrame(scene.bounds(), 6).voxelSize;
    mask = renderEdgeMask(scene, camera, fp, distance, &progress);
    report.figures["edge_distance"] = distance;
  }
  AtomicFileSet outputs;
  writeImage(opt.output, mask, 0.0f, &outputs);
  if (!opt.json.empty()) report.addTo(outputs, opt.json, rows);
  outputs.commit();
  if (opt.quiet) return 0;
  if (added) {
    std::printf("added-object mask: wrote %s\n", opt.output.c_str());
    return 0;
  }
  double covered = 0;
  for (size_t i = 0; i < mask.pixelCount(); ++i) covered += mask.at(i).x > 0 ? 1 : 0;
  std::printf("edge mask %s: %d x %d, within %g of an edge: %.1f%% of the pixels\nwrote %s\n",
              opt.scene.c_str(), opt.width, opt.height, double(distance),
              100.0 * covered / double(mask.pixelCount()), opt.output.c_str());
  return 0;
}

int runReference(const ReferenceOptions& opt) {
  checkImageOutput(opt.output, "--output");
  if (!opt.stdErrorOutput.empty()) checkImageOutput(opt.stdErrorOutput, "--std-error");
  if (!opt.emitterMaskOutput.empty()) checkImageOutput(opt.emitterMaskOutput, "--emitter-mask");
  if (!opt.geometryMaskOutput.empty()) checkImageOutput(opt.geometryMaskOutput, "--geometry-mask");
  if (!opt.json.empty()) checkOutputFolder(opt.json, "--json");
  const NamedPaths inputs = sceneInputs(opt);
  checkDistinctFiles({{"--output", opt.output},
                      {"--std-error", opt.stdErrorOutput},
                      {"--emitter-mask", opt.emitterMaskOutput},
                      {"--geometry-mask", opt.geometryMaskOutput},
                      {"--json", opt.json}},
                     inputs);
  JsonReport report{"reference", inputs, {{"part", opt.part}, {"width", opt.width}, {"height", opt.height}}};
  std::vector<StageReport> rows;
  checkCameraOptions(opt.camera);
  (void)opt.picture.toneParams();  // a bad --exposure is refused before the work
  ThreadLimit threadLimit(opt.threads);

  Scene scene = loadSceneWith(opt);
  printSceneWarnings(scene);
  PinholeCamera camera = chooseCamera(opt.camera, scene, opt.scene);
  if (opt.addedOnlyReceive && opt.objects.empty())
    throw InputError("--added-only-receive: add an object first (--add, --at)");
  if (opt.part == "added-mask" || opt.part == "edge-mask") {
    return renderMask(opt, scene, camera, report, rows);
  }
  checkStdErrorSamples(opt, !opt.stdErrorOutput.empty());
  const ReferenceParams params = referenceParams(opt);
  ConsoleProgress progress(opt.quiet);
  StageTimer traceTimer(rows, "path trace");
  ReferenceImage result = renderReference(scene, camera, params, &progress);
  traceTimer.finish(std::to_string(result.samplesPerPixel) + " spp");
  // A scene with no light drew black, exit 0, without a word (H16-4-2).
  const std::vector<float>& rgb = result.image.rgb;
  if (std::all_of(rgb.begin(), rgb.end(), [](float v) { return v == 0; })) {
    printWarning(opt.output + ": every pixel is black: no light reaches what the camera sees (a " +
                 "scene without a light of positive power, an emissive surface or a sky?)");
  }
  checkStdErrorSamples(opt, !opt.stdErrorOutput.empty(), result.samplesPerPixel);
  // The image and its side images (and the report) appear together.
  AtomicFileSet outputs;
  ToneReport tone;
  writeTonedImage(opt.output, result.image, opt.picture.toneParams(), &outputs, &tone);
  if (!opt.stdErrorOutput.empty()) writeImage(opt.stdErrorOutput, result.stdError, 0.0f, &outputs);
  if (!opt.emitterMaskOutput.empty()) writeImage(opt.emitterMaskOutput, result.emitterMask, 0.0f, &outputs);
  if (!opt.geometryMaskOutput.empty()) {
    writeImage(opt.geometryMaskOutput, result.geometryMask, 0.0f, &outputs);
  }
  if (!opt.json.empty()) {
    report.figures["samples_per_pixel"] = result.samplesPerPixel;
    report.figures["rays"] = result.raysTraced;
    report.figures["seconds"] = result.seconds;
    report.addTo(outputs, opt.json, rows);
  }
  outputs.commit();

  printPicture(opt.output, tone, opt.quiet);
  if (!opt.quiet) {
    // How far the reference itself is from converged, to weigh errors
    // measured against it.
    const ImageNoise noise = imageNoise(result.image, result.stdError);
    char spread[96] = "std. error unknown (one sample per pixel)";
    if (result.samplesPerPixel >= 2) {
      std::snprintf(spread, sizeof spread, "RMS std. error %.5g (%.2f%%)", noise.rmsStdError,
                    noise.percent());
    }
    std::printf("%s %s: %d x %d, %d spp, %.2f s, %s rays, mean %.5g, %s\n",
                toString(params.part).c_str(), opt.scene.c_str(), opt.width, opt.height,
                result.samplesPerPixel, result.seconds, formatCount(result.raysTraced).c_str(),
                noise.mean, spread);
    std::printf("wrote %s%s%s\n", opt.output.c_str(), opt.stdErrorOutput.empty() ? "" : " and ",
                opt.stdErrorOutput.c_str());
  }
  return 0;
}

}  // namespace

std::function<int()> addReferenceCommand(CLI::App& app) {
  return addCommand(app, "reference", addReferenceOptions, runReference);
}

}  // namespace lo::tool
