// `lightoctree render`: scene + baked .vdb -> GPU light octree -> image.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <memory>

#include "camera_options.h"
#include "cli_checks.h"
#include "command_options.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "image/image.h"
#include "json_report.h"
#include "picture_options.h"
#include "reference/first_hit.h"
#include "render/context.h"
#include "render/render_session.h"
#include "render_options.h"
#include "render_stages.h"
#include "scene/scene.h"
#include "scene_options.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

struct RenderOptions : SceneFlags {
  std::string lights;
  std::string output;
  CameraOptions camera;
  int width = 800, height = 600;
  std::string mode = "full";
  ShadingOptions shading;
  PictureOptions picture;  // --exposure, --tone-map
  std::string backend = "osmesa";
  int frames = 0;
  int irradianceSpp = 64;
  std::string json;  // --json FILE: tools/json_report.h
  bool quiet = false;
};

/// Writes the image and, with --json, the report, as one set; says how the
/// PNG was exposed and what share of it clips.
void writeRenderOutputs(const RenderOptions& opt, const RgbImage& image, JsonReport& report,
                        const std::vector<StageReport>& rows) {
  AtomicFileSet outputs;
  ToneReport tone;
  writeTonedImage(opt.output, image, opt.picture.toneParams(), &outputs, &tone);
  const bool png = hasExtension(opt.output, ".png");
  if (!opt.json.empty()) {
    report.figures["image"] = {{"width", image.width},
                               {"height", image.height},
                               {"mean_luminance", meanLuminance(image)}};
    if (png) {
      report.figures["image"]["exposure_ev"] = tone.exposureEv;
      report.figures["image"]["auto_exposure"] = tone.autoExposure;
      report.figures["image"]["tone_map"] = toString(tone.curve);
      report.figures["image"]["clipped_share"] = tone.clippedShare;
      report.figures["image"]["white_share"] = tone.whiteShare;
    }
    report.addTo(outputs, opt.json, rows);
  }
  outputs.commit();
  printPicture(opt.output, tone, opt.quiet);
}

/// `--mode irradiance`: the octree's indirect irradiance at the first hit,
/// evaluated on the CPU (octree/octree_irradiance.h: the shader's lookup and
/// interpolation with the cosine alone) at the reference renderer's first-hit
/// points, so that it compares with `reference --part irradiance`. Needs no
/// OpenGL. `--spp` jittered rays per pixel (64 by default) average over the
/// pixel's footprint as the reference's thousands of samples do: with 4, a
/// pixel across an edge mixes its two surfaces in steps of a quarter, an
/// error of up to a quarter of their difference that is the sampling's,
/// not the octree's.
int renderIrradiance(const RenderOptions& opt, const Scene& scene, const LoadedVdl& baked,
                     JsonReport& report, std::vector<StageReport>& rows) {
  if (opt.frames > 0) throw InputError("--frames: not with --mode irradiance (no GL frame)");
  PinholeCamera camera = chooseCamera(opt.camera, scene, opt.scene);
  const RenderSettings settings = opt.shading.settings(RenderMode::Full, opt.width, opt.height);
  FirstHitParams hits;
  hits.width = opt.width;
  hits.height = opt.height;
  hits.samplesPerPixel = opt.irradianceSpp;
  StageTimer renderTimer(rows, "render");
  // No GL context to ask: the octrees within the GL 3.3 limits we render with.
  const LookupOctrees octrees = buildLookupOctrees(scene, baked.grid, settings, opt.lights);
  printWarnings(octrees.warnings);
  if (!opt.quiet) std::printf("octree: %s\n", octrees.surface.ToString().c_str());
  const RgbImage image = renderOctreeIrradiance(scene, camera, octrees.surface, octrees.volume,
                                                shadeParamsOf(settings.frame), hits);
  renderTimer.finish(std::to_string(opt.irradianceSpp) + " rays per pixel");
  writeRenderOutputs(opt, image, report, rows);
  if (!opt.quiet) std::printf("wrote %s\n", opt.output.c_str());
  return 0;
}

int runRender(const RenderOptions& opt) {
  // Everything that can be checked before the work is checked first.
  checkOutputFolder(opt.output, "--output");
  if (!opt.json.empty()) checkOutputFolder(opt.json, "--json");
  NamedPaths inputs = sceneInputs(opt);
  inputs.push_back({"LIGHTS", opt.lights});
  checkDistinctFiles({{"--output", opt.output}, {"--json", opt.json}}, inputs);
  JsonReport report{"render", inputs, {{"mode", opt.mode}, {"width", opt.width}, {"height", opt.height}}};
  std::vector<StageReport> rows;
  checkOutputExtension(opt.output, "--output", {".png", ".exr"});
  checkCameraOptions(opt.camera);
  (void)opt.picture.toneParams();  // a bad --exposure is refused before the work
  Scene scene = loadSceneStage(opt, rows);
  LoadedVdl baked = readLightsStage(opt.lights, scene, rows);
  if (opt.mode == "irradiance") return renderIrradiance(opt, scene, baked, report, rows);
  const RenderSettings settings =
      opt.shading.settings(parseRenderMode(opt.mode), opt.width, opt.height);
  const RenderParams& params = settings.frame;
  PinholeCamera camera = chooseCamera(opt.camera, scene, opt.scene);
  if (params.mode == RenderMode::Full || params.mode == RenderMode::Direct) {
    const std::string twice =
        directTwiceWarning(baked.meta, "mode " + opt.mode, "use --mode indirect");
    if (!twice.empty())
      std::fprintf(stderr, "warning: %s: %s\n", opt.lights.c_str(), twice.c_str());
  }

  GlContextParams contextParams;
  contextParams.backend = parseGlBackend(opt.backend);
  std::unique_ptr<GlContext> context =
      openContextStage(contextParams, opt.backend, opt.quiet, report, rows);

  RenderSessionOptions sessionOptions;
  sessionOptions.gridName = opt.lights;
  RenderSession session(scene, std::move(baked.grid), *context, settings, sessionOptions);
  reportSession(session, /*showOctree=*/true, opt.quiet, report, rows);
  Renderer& renderer = session.renderer();
  StageTimer frameTimer(rows, "first frame");
  RgbImage image = renderer.render(camera, params);
  frameTimer.finish(std::to_string(opt.width) + " x " + std::to_string(opt.height));

  if (opt.frames > 0) {
    double seconds = renderer.timeFrames(camera, params, opt.frames);
    std::printf("frame time: %.2f ms (%d x %d, mode %s, mean of %d frames, glFinish each)\n",
                1000.0 * seconds / opt.frames, opt.width, opt.height, opt.mode.c_str(), opt.frames);
    report.figures["frame_ms"] = 1000.0 * seconds / opt.frames;
    report.figures["frames_timed"] = opt.frames;
  }
  writeRenderOutputs(opt, image, report, rows);
  if (!opt.quiet) std::printf("wrote %s\n", opt.output.c_str());
  return 0;
}

void addRenderOptions(CLI::App* cmd, RenderOptions& opt) {
  cmd->description(
      "Render a scene lit by its baked light octree (GPU octree of VDLs) plus direct light, "
      "headless, to a PNG or EXR image.");
  addSceneFlags(cmd, opt);
  addLightsArgument(cmd, opt.lights)->required();
  cmd->add_option("-o,--output", opt.output,
                  "Image: .exr (linear float radiance) or .png (--exposure, --tone-map, sRGB)")
      ->required();
  addCameraOptions(cmd, opt.camera);
  addSizeOptions(cmd, opt.width, opt.height);
  cmd->add_option("--mode", opt.mode,
                  "full | direct (emission + lights) | indirect (octree only) | voxels | "
                  "irradiance (the octree's indirect irradiance at the first hit, W/m^2, "
                  "on the CPU: compares with `reference --part irradiance`)")
      ->check(CLI::IsMember({"full", "direct", "indirect", "voxels", "irradiance"}))
      ->capture_default_str();
  addShadingOptions(cmd, opt.shading, false);
  addPictureOptions(cmd, opt.picture);
  cmd->add_option("--backend", opt.backend, "Headless OpenGL: osmesa (software) or egl")
      ->check(CLI::IsMember({"osmesa", "egl"}))
      ->capture_default_str();
  cmd->add_option("--json", opt.json,
                  "Also write a JSON report: the files read and written, the figures printed, "
                  "time and memory per stage (README.md, \"Scripting\")");
  cmd->add_option("--frames", opt.frames,
                  "Also time this many frames (no read-back) and print the mean frame time")
      ->check(wholeIn(0, 100000));
  cmd->add_option("--spp", opt.irradianceSpp,
                  "--mode irradiance: camera rays per pixel, averaged as the reference averages "
                  "its samples (pixels across an edge need many)")
      ->check(wholeIn(1, 4096))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opt.quiet, "Only errors");
}

}  // namespace

std::function<int()> addRenderCommand(CLI::App& app) {
  return addCommand(app, "render", addRenderOptions, runRender);
}

}  // namespace lo::tool
