// `lightoctree render`: scene + baked .vdb -> GPU light octree -> image.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <sstream>

#include "camera_options.h"
#include "render_options.h"
#include "scene_options.h"
#include "commands.h"
#include "bake/bake.h"
#include "core/resources.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/error.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "reference/first_hit.h"
#include "render/context.h"
#include "json_report.h"
#include "report.h"
#include "image/image.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

struct RenderOptions {
  std::string scene;
  SceneOptions sceneOptions;  // --sky
  AddedObjects objects;       // --add, --at
  std::string lights;
  std::string output;
  CameraOptions camera;
  int width = 800, height = 600;
  std::string mode = "full";
  ShadingOptions shading;
  std::string backend = "osmesa";
  int frames = 0;
  int irradianceSpp = 64;
  std::string json;  // --json FILE: tools/json_report.h
  bool quiet = false;
};

/// Mean Rec. 709 luminance of a linear image (the report's figure).
double meanLuminance(const RgbImage& image) {
  double sum = 0;
  for (size_t i = 0; i < image.pixelCount(); ++i) sum += double(luminance(image.at(i)));
  return image.pixelCount() ? sum / double(image.pixelCount()) : 0.0;
}

/// Writes the image and, with --json, the report, as one set.
void writeRenderOutputs(const RenderOptions& opt, const RgbImage& image, JsonReport& report,
                        const std::vector<StageReport>& rows) {
  AtomicFileSet outputs;
  writeImage(opt.output, image, opt.shading.exposure, &outputs);
  if (!opt.json.empty()) {
    report.figures["image"] = {{"width", image.width},
                               {"height", image.height},
                               {"mean_luminance", meanLuminance(image)},
                               {"exposure_ev", opt.shading.exposure}};
    report.addTo(outputs, opt.json, rows);
  }
  outputs.commit();
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
  // No GL context to ask: the limits of the GL 3.3 contexts we render with.
  GpuOctree octree = buildGpuOctree(baked.grid, opt.shading.octreeParams());
  if (!opt.quiet) std::printf("octree: %s\n", octree.ToString().c_str());
  OctreeShadeParams shade;
  shade.interpolation = opt.shading.interpolation == "on";
  shade.maxVdls = opt.shading.vdls;
  shade.normalOffset = RenderParams().normalOffset;
  FirstHitParams params;
  params.width = opt.width;
  params.height = opt.height;
  params.samplesPerPixel = opt.irradianceSpp;
  StageTimer renderTimer(rows, "render");
  // Added objects read the free-space light (the renderer's LO_FREE_SPACE).
  GpuOctree volume;
  if (!opt.objects.empty() && hasLightForAddedObjects(baked.grid, opt.lights)) {
    volume = buildVolumeOctree(baked.grid.volume, opt.shading.octreeParams());
  }
  RgbImage image = renderFirstHits(scene, camera, params, [&](const FirstHit& hit) {
    if (scene.isAdded(hit.triangle) && volume.depth > 0) return volumeIrradiance(volume, hit.position, hit.normal);
    return octreeIrradiance(octree, hit.position, hit.normal, shade);
  });
  renderTimer.finish(std::to_string(opt.irradianceSpp) + " rays per pixel");
  writeRenderOutputs(opt, image, report, rows);
  if (!opt.quiet) std::printf("wrote %s\n", opt.output.c_str());
  return 0;
}

int runRender(const RenderOptions& opt) {
  // Everything that can be checked before the work is checked first.
  checkOutputFolder(opt.output, "--output");
  if (!opt.json.empty()) checkOutputFolder(opt.json, "--json");
  NamedPaths inputs = sceneInputs(opt.scene);
  inputs.push_back({"LIGHTS", opt.lights});
  checkDistinctFiles({{"--output", opt.output}, {"--json", opt.json}}, inputs);
  JsonReport report{"render", inputs, {{"mode", opt.mode}, {"width", opt.width}, {"height", opt.height}}};
  std::vector<StageReport> rows;
  if (!hasExtension(opt.output, ".png") && !hasExtension(opt.output, ".exr")) {
    throw InputError("--output: '" + opt.output + "' must end in .png or .exr");
  }
  checkCameraOptions(opt.camera);
  StageTimer loadTimer(rows, "load scene");
  Scene scene = loadSceneWith(opt.scene, opt.sceneOptions);
  placeObjects(scene, opt.objects);
  printSceneWarnings(scene);
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.textures.size()) + " textures");
  StageTimer readTimer(rows, "read grid");
  LoadedVdl baked = readVdlGrid(opt.lights, scene.origin);
  readTimer.finish(formatCount(baked.grid.size()) + " voxels");
  const std::string stale = staleBakeWarning(baked.meta, opt.scene);
  if (!stale.empty()) std::fprintf(stderr, "warning: %s: %s\n", opt.lights.c_str(), stale.c_str());
  if (opt.mode == "irradiance") return renderIrradiance(opt, scene, baked, report, rows);
  RenderParams params = opt.shading.renderParams(parseRenderMode(opt.mode));
  params.width = opt.width;
  params.height = opt.height;

  PinholeCamera camera = chooseCamera(opt.camera, scene, opt.scene);
  if (baked.meta.includeDirect == 1 &&
      (params.mode == RenderMode::Full || params.mode == RenderMode::Direct)) {
    std::fprintf(stderr,
                 "warning: %s was baked with --include-direct: its VDLs hold the direct light, "
                 "which mode %s draws again (counted twice); use --mode indirect\n",
                 opt.lights.c_str(), opt.mode.c_str());
  }

  StageTimer contextTimer(rows, "GL context");
  GlContextParams contextParams;
  contextParams.backend = parseGlBackend(opt.backend);
  std::unique_ptr<GlContext> context = createGlContext(contextParams);
  contextTimer.finish(opt.backend);
  if (!opt.quiet) std::printf("%s: %s\n", opt.backend.c_str(), context->info().ToString().c_str());
  report.figures["gl"] = context->info().ToString();

  StageTimer octreeTimer(rows, "octree");
  GpuOctree octree = buildGpuOctree(baked.grid, opt.shading.octreeParams(&context->info()));
  if (opt.objects.empty()) {
    // The octree holds all the renderer reads of the grid; only the added
    // objects' free-space light reads it again.
    baked.grid = VdlGrid{};
    returnFreeMemory();
  }
  octreeTimer.finish("");
  if (!opt.quiet) std::printf("octree: %s\n", octree.ToString().c_str());
  report.figures["octree"] = octree.ToString();

  // Nothing after the renderer's construction reads a texel: each texture's
  // are freed as soon as its GPU copy is made.
  Renderer renderer(scene, octree, opt.shading.rendererParams(), freeTexelsOnUpload(scene));
  rows.insert(rows.end(), renderer.startupStages().begin(), renderer.startupStages().end());
  scene.releaseTexels();  // those no material draws with
  returnFreeMemory();
  if (!opt.objects.empty()) {
    StageTimer volumeTimer(rows, "free-space light");
    setAddedObjectsLight(renderer, baked.grid, opt.shading, opt.shading.octreeParams(&context->info()),
                         opt.lights);
    volumeTimer.finish(renderer.hasFreeSpaceLight() ? "for the added objects" : "none in the bake");
  }
  StageTimer lightingTimer(rows, "prepare lighting");
  opt.shading.prepareLighting(renderer, scene, octree, opt.quiet);
  lightingTimer.finish(renderer.hasAtlas() ? "lightmap atlas" : "");
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

}  // namespace

std::function<int()> addRenderCommand(CLI::App& app) {
  auto opt = std::make_shared<RenderOptions>();
  CLI::App* cmd = app.add_subcommand(
      "render",
      "Render a scene lit by its baked light octree (GPU octree of VDLs) plus direct light, "
      "headless, to a PNG or EXR image.");
  cmd->add_option("scene", opt->scene, "Scene: .gltf, .glb or .obj")
      ->required()
      ->check(CLI::ExistingFile);
  addSceneOptions(cmd, opt->sceneOptions);
  addObjectOptions(cmd, opt->objects);
  cmd->add_option("lights", opt->lights, "Baked VDL grid (.vdb from `lightoctree bake`)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", opt->output,
                  "Image: .exr (linear float radiance) or .png (exposure, sRGB)")
      ->required();
  addCameraOptions(cmd, opt->camera);
  cmd->add_option("--width", opt->width, "Image width in pixels")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Image height in pixels")
      ->check(CLI::Range(1, 16384))
      ->capture_default_str();
  cmd->add_option("--mode", opt->mode,
                  "full | direct (emission + lights) | indirect (octree only) | voxels | "
                  "irradiance (the octree's indirect irradiance at the first hit, W/m^2, "
                  "on the CPU: compares with `reference --part irradiance`)")
      ->check(CLI::IsMember({"full", "direct", "indirect", "voxels", "irradiance"}))
      ->capture_default_str();
  addShadingOptions(cmd, opt->shading, false);
  cmd->add_option("--backend", opt->backend, "Headless OpenGL: osmesa (software) or egl")
      ->check(CLI::IsMember({"osmesa", "egl"}))
      ->capture_default_str();
  cmd->add_option("--json", opt->json,
                  "Also write a JSON report: the files read and written, the figures printed, "
                  "time and memory per stage (README.md, \"Scripting\")");
  cmd->add_option("--frames", opt->frames,
                  "Also time this many frames (no read-back) and print the mean frame time")
      ->check(CLI::Range(0, 100000));
  cmd->add_option("--spp", opt->irradianceSpp,
                  "--mode irradiance: camera rays per pixel, averaged as the reference averages "
                  "its samples (pixels across an edge need many)")
      ->check(CLI::Range(1, 4096))
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opt->quiet, "Only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runRender(*opt) : -1; };
}

}  // namespace lo::tool
