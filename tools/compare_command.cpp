// `lightoctree compare`: error of a test image against a reference image.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_checks.h"
#include "commands.h"
#include "core/error.h"
#include "image/compare.h"
#include "image/image.h"
#include "core/file.h"

namespace lo::tool {
namespace {

struct CompareOptions {
  std::string test, reference, mask, referenceError;
  bool ignoreBackground = false;
  int bin = 1;
  float clipPercentile = 100;
  std::string diff;
  float diffScale = 0;
  std::string json;
  bool quiet = false;
};

nlohmann::json toJson(const ChannelError& e) {
  return {{"rel_rmse", e.relRmse}, {"rel_mae", e.relMae}, {"max_abs", e.maxAbs}};
}

int runCompare(const CompareOptions& opt) {
  if (!opt.diff.empty()) {
    checkOutputFolder(opt.diff, "--diff");
    checkOutputExtension(opt.diff, "--diff", {".png", ".exr"});
  }
  if (!opt.json.empty()) checkOutputFile(opt.json, "--json", ".json");
  checkDistinctFiles({{"--diff", opt.diff}, {"--json", opt.json}},
                     {{"TEST", opt.test},
                      {"REFERENCE", opt.reference},
                      {"--mask", opt.mask},
                      {"--reference-error", opt.referenceError}});
  RgbImage test = readImage(opt.test);
  RgbImage reference = readImage(opt.reference);
  RgbImage mask;
  CompareParams params;
  params.ignoreBackground = opt.ignoreBackground;
  if (!opt.mask.empty()) {
    // 8-bit masks are read as plain numbers: any non-zero value selects.
    mask = readImage(opt.mask, /*linear8Bit=*/true);
    params.mask = &mask;
  }
  if (test.width != reference.width || test.height != reference.height) {
    throw InputError(opt.test + " is " + std::to_string(test.width) + " x " +
                     std::to_string(test.height) + " but " + opt.reference + " is " +
                     std::to_string(reference.width) + " x " + std::to_string(reference.height));
  }
  if (params.mask && (mask.width != reference.width || mask.height != reference.height)) {
    throw InputError("--mask: " + opt.mask + " is " + std::to_string(mask.width) + " x " +
                     std::to_string(mask.height) + ", the images are " +
                     std::to_string(reference.width) + " x " + std::to_string(reference.height));
  }
  RgbImage stdError;
  if (!opt.referenceError.empty()) {
    stdError = readImage(opt.referenceError);
    if (stdError.width != reference.width || stdError.height != reference.height) {
      throw InputError("--reference-error: " + opt.referenceError + " is " +
                       std::to_string(stdError.width) + " x " + std::to_string(stdError.height) +
                       ", the images are " + std::to_string(reference.width) + " x " +
                       std::to_string(reference.height));
    }
    checkStdError(stdError, "--reference-error: " + opt.referenceError);
  }
  CompareSettings settings;
  settings.bin = opt.bin;
  settings.clipPercentile = opt.clipPercentile;
  settings.ignoreBackground = opt.ignoreBackground;
  const CompareReport report =
      compareReport(std::move(test), std::move(reference), settings, params.mask,
                    opt.referenceError.empty() ? nullptr : &stdError);
  const CompareResult& result = report.result;
  const DarkHoles& holes = report.holes;
  const Vec3 clip = report.clip;
  const double noise = report.referenceNoise;
  if (!opt.quiet) {
    std::printf("%s against %s%s\n%s\n", opt.test.c_str(), opt.reference.c_str(),
                opt.bin > 1 ? (", binned " + std::to_string(opt.bin) + "x" +
                               std::to_string(opt.bin)).c_str()
                            : "",
                result.ToString().c_str());
    std::printf("black holes: %zu of %zu pixels (%.3f%%) below 2%% of the reference's mean Y "
                "where the reference is above 20%% of it\n",
                holes.pixels, holes.compared, 100.0 * holes.share());
    if (opt.clipPercentile < 100) {
      std::printf("clipped first at the reference's %g-th percentile: R %.4g, G %.4g, B %.4g\n",
                  double(opt.clipPercentile), double(clip.x), double(clip.y), double(clip.z));
    }
    if (noise >= 0) {
      std::printf("reference noise: %.3g relative RMS standard error of Y over the same pixels%s\n",
                  noise, opt.bin > 1 ? " and bins" : "");
    }
  }
  if (noise >= 0 && noise >= result.luminance.relRmse) {
    std::fprintf(stderr,
                 "warning: the reference's own noise (%.3g) is at or above the difference "
                 "measured (Y rel. RMSE %.3g): the reference cannot tell the images apart; "
                 "render it with more samples or compare over larger --bin blocks\n",
                 noise, result.luminance.relRmse);
  }
  // What the figures alone hide (pixels left out for NaN or inf, relative
  // errors against black), --quiet too.
  for (const std::string& w : report.warnings()) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (!opt.diff.empty()) {
    // Linear float values in an EXR; PNG keeps the false colour as it is.
    writeImage(opt.diff, differenceImage(report.test, report.reference, report.params(), opt.diffScale));
    if (!opt.quiet) std::printf("wrote %s\n", opt.diff.c_str());
  }
  if (!opt.json.empty()) {
    nlohmann::json j;
    j["test"] = opt.test;
    j["reference"] = opt.reference;
    j["bin"] = opt.bin;
    j["width"] = report.reference.width;
    j["height"] = report.reference.height;
    j["channels"] = {{"R", toJson(result.channel[0])},
                     {"G", toJson(result.channel[1])},
                     {"B", toJson(result.channel[2])},
                     {"Y", toJson(result.luminance)},
                     {"RGB", toJson(result.rgb)}};
    j["clip_percentile"] = opt.clipPercentile;
    if (opt.clipPercentile < 100) j["clip"] = {clip.x, clip.y, clip.z};
    j["black_hole_pixels"] = holes.pixels;
    j["black_hole_share"] = holes.share();
    j["compared_pixels"] = result.comparedPixels;
    j["ignored_pixels"] = result.ignoredPixels;
    j["non_finite_pixels"] = result.nonFinitePixels;
    j["non_finite_image_pixels"] = report.nonFiniteImagePixels;
    j["max_error_pixel"] = {result.maxErrorX, result.maxErrorY};
    j["mean_reference_luminance"] = result.meanReferenceLuminance;
    j["mean_test_luminance"] = result.meanTestLuminance;
    j["reference_noise"] = noise >= 0 ? nlohmann::json(noise) : nlohmann::json(nullptr);
    writeTextAtomically(opt.json, j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n");
    if (!opt.quiet) std::printf("wrote %s\n", opt.json.c_str());
  }
  return 0;
}

void addCompareOptions(CLI::App* cmd, CompareOptions& opt) {
  cmd->description(
      "Relative RMSE, relative mean absolute error and maximum error of a test image against "
      "a reference (per channel and luminance), a false-colour difference image, JSON.");
  cmd->add_option("test", opt.test, "Test image (.exr, or .png decoded to linear)")
      ->required()
      ->check(existingFile());
  cmd->add_option("reference", opt.reference, "Reference image, e.g. from `lightoctree reference`")
      ->required()
      ->check(existingFile());
  cmd->add_option("--mask", opt.mask,
                  "Image of the same size; pixels that are 0 in every channel are left out")
      ->check(existingFile());
  cmd->add_option("--reference-error", opt.referenceError,
                  "The reference's per-pixel standard error (`reference --std-error`): prints "
                  "its noise over the compared pixels (binned with --bin), the floor under the "
                  "error, and warns when the error measured is not above it")
      ->check(existingFile());
  cmd->add_flag("--ignore-background", opt.ignoreBackground,
                "Leave out pixels where the reference is exactly black (by value: `reference "
                "--geometry-mask` with --mask leaves out the background by what it shows)");
  cmd->add_option("--bin", opt.bin,
                  "Average both images (and the mask) over blocks of N x N pixels first: the "
                  "error at the scale of N pixels, without the reference's per-pixel noise "
                  "(--diff is then at that resolution too)")
      ->check(numberIn(kCompareBinRange))
      ->capture_default_str();
  cmd->add_option("--clip-percentile", opt.clipPercentile,
                  "Clip each channel of both images at the reference's P-th percentile (over the "
                  "compared pixels) before binning and comparing, so that a few visible lamps do "
                  "not rule the error (99 is the figure docs/accuracy.md quotes); 100 = off")
      ->check(numberIn(kClipPercentileRange))
      ->capture_default_str();
  cmd->add_option("--diff", opt.diff,
                  "Write |Y(test) - Y(reference)| in false colour (.png or .exr): black 0, blue, "
                  "green, yellow, red at --diff-scale; ignored pixels grey");
  cmd->add_option("--diff-scale", opt.diffScale,
                  "Error shown red in --diff, in the images' units (default: a quarter of the "
                  "mean reference luminance)")
      ->check(numberIn(kPositiveNumber));
  cmd->add_option("--json", opt.json, "Write the figures as JSON for scripts (a .json file)");
  cmd->add_flag("-q,--quiet", opt.quiet, "Print nothing (use with --json)");
}

}  // namespace

std::function<int()> addCompareCommand(CLI::App& app) {
  return addCommand(app, "compare", addCompareOptions, runCompare);
}

}  // namespace lo::tool
