// `lightoctree view`: a GLFW window walkthrough of a scene lit by its light
// octree, interactive or along a recorded camera path; with --progressive, the
// octree is baked coarse to fine in the background while the window shows
// the newest level (paper §5.2). The frame loop, input and redraw policy are
// the Viewer's (render/viewer.h); this file parses, sets up and reports.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "bake/bake.h"
#include "bake/progressive_bake.h"
#include "camera_options.h"
#include "cli_checks.h"
#include "commands.h"
#include "json_report.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "render/camera_path.h"
#include "render/context.h"
#include "render/fly_camera.h"
#include "render/render_session.h"
#include "render/viewer.h"
#include "render_options.h"
#include "report.h"
#include "scene/scene.h"
#include "scene_options.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

struct ViewOptions {
  std::string scene;
  SceneOptions sceneOptions;  // --sky
  AddedObjects objects;       // --add, --at
  std::string lights;
  CameraOptions camera;
  int width = 800, height = 600;
  std::string mode = "full";
  ShadingOptions shading;
  float speed = 0;  // 0 = a quarter of the scene's diagonal per second
  std::string cameraPath;
  ViewerParams view;  // the flags bound to it: --save-frames, --frames, --record, ...
  bool progressive = false;
  ProgressiveParams bake;  // --photons, --depth (target), --knn, --seed
  std::string json;        // --json: the start-up stages and the frames, as `render --json`
};

int runView(const ViewOptions& opt) {
  // Everything that can be checked before a window opens is checked first.
  if (opt.progressive && !opt.lights.empty()) {
    throw InputError("--progressive bakes the lights from the scene: give no LIGHTS.vdb ('" +
                     opt.lights + "')");
  }
  if (opt.progressive && opt.shading.lighting == "atlas") {
    throw InputError("--lighting atlas needs a finished bake: it cannot follow --progressive");
  }
  if (!opt.progressive && opt.lights.empty()) {
    throw InputError("LIGHTS.vdb is required (a bake of the scene), or use --progressive");
  }
  checkCameraOptions(opt.camera);
  if (!opt.json.empty()) checkOutputFolder(opt.json, "--json");
  NamedPaths inputs = sceneInputs(opt.scene);
  if (!opt.lights.empty()) inputs.push_back({"LIGHTS", opt.lights});
  if (!opt.cameraPath.empty()) inputs.push_back({"--camera-path", opt.cameraPath});
  // The file P appends to may be the path played: only --json must differ from it.
  inputs.push_back({"--record", opt.view.record});
  checkDistinctFiles({{"--json", opt.json}}, inputs);
  JsonReport report{"view", inputs,
                    {{"mode", opt.mode}, {"width", opt.width}, {"height", opt.height},
                     {"progressive", opt.progressive}}};
  std::vector<StageReport> rows;
  std::optional<CameraPath> path;
  if (!opt.cameraPath.empty()) path = readCameraPath(opt.cameraPath);
  if (!opt.view.saveFrames.empty()) makeOutputFolder(opt.view.saveFrames, "--save-frames");
  ViewerParams view = opt.view;
  const RenderSettings settings =
      opt.shading.settings(parseRenderMode(opt.mode), opt.width, opt.height);
  view.render = settings.frame;
  view.exposure = opt.shading.exposure;
  view.path = std::move(path);

  StageTimer loadTimer(rows, "load scene");
  Scene scene = loadSceneWith(opt.scene, opt.sceneOptions);
  placeObjects(scene, opt.objects);
  printSceneWarnings(scene);
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.textures.size()) + " textures");
  std::optional<LoadedVdl> baked;
  if (!opt.progressive) {
    StageTimer readTimer(rows, "read grid");
    baked = readVdlGrid(opt.lights, scene.origin);
    readTimer.finish(formatCount(baked->grid.size()) + " voxels");
    const std::string stale = staleBakeWarning(baked->meta, opt.scene);
    if (!stale.empty()) std::fprintf(stderr, "warning: %s: %s\n", opt.lights.c_str(), stale.c_str());
  }
  view.worldOrigin = scene.origin;
  if (view.path) {
    for (CameraKey& key : view.path->keys) {  // the file's world coordinates
      key.eye = scene.toLocal(Vec3d(key.eye));
      key.target = scene.toLocal(Vec3d(key.target));
    }
  }

  PinholeCamera startCamera = chooseCamera(opt.camera, scene, opt.scene);
  view.defaultFovDegrees = opt.camera.fovDegrees > 0 ? opt.camera.fovDegrees : 45.0f;
  view.start = FlyCamera::lookingAt(startCamera.eye, startCamera.eye + startCamera.forward,
                                    startCamera.yfov);
  const float diagonal = std::max(length(scene.bounds().extent()), 1e-3f);
  view.start.speed = opt.speed > 0 ? opt.speed : 0.25f * diagonal;
  view.znear = 1e-3f * diagonal;

  GlContextParams contextParams;
  contextParams.backend = GlBackend::Glfw;
  contextParams.width = opt.width;
  contextParams.height = opt.height;
  contextParams.title = "Light Octree: " + std::filesystem::path(opt.scene).filename().string();
  StageTimer contextTimer(rows, "GL context");
  std::unique_ptr<GlContext> context = createGlContext(contextParams);
  contextTimer.finish("glfw");
  if (!opt.view.quiet) std::printf("glfw: %s\n", context->info().ToString().c_str());
  report.figures["gl"] = context->info().ToString();

  // Progressive: the bake thread starts before the session's set-up (scene
  // upload, shadow maps) so that the two overlap; until the first level is
  // ready the window shows direct light over an empty octree.
  std::unique_ptr<ProgressiveBake> bake;
  std::unique_ptr<OctreeLevelSource> levels;
  if (opt.progressive) {
    StageTimer bakeTimer(rows, "start progressive bake");
    ProgressiveParams pp = opt.bake;
    pp.firstDepth = std::min(4, pp.targetDepth);
    pp.cluster.seed = pp.photons.seed;
    pp.octree = settings.octreeParams(&context->info());
    bake = std::make_unique<ProgressiveBake>(scene, pp);
    levels = progressiveLevelSource(*bake, pp.targetDepth);
    view.firstDepth = pp.firstDepth;
    view.targetDepth = pp.targetDepth;
    bakeTimer.finish("");
    if (!opt.view.quiet) {
      std::printf("progressive: tracing %zu photons, then depth %d to %d\n", pp.photons.storedPhotons,
                  pp.firstDepth, pp.targetDepth);
    }
  }
  // Without a bake tracing the scene beside it, nothing reads a texel after
  // the renderer's construction: each texture's are freed once on the GPU.
  RenderSessionOptions sessionOptions;
  sessionOptions.freeTexels = !bake;
  sessionOptions.gridName = opt.lights;
  RenderSession session(scene, baked ? std::move(baked->grid) : VdlGrid{}, *context, settings,
                        sessionOptions);
  baked.reset();
  rows.insert(rows.end(), session.stages().begin(), session.stages().end());
  printWarnings(session);
  if (!bake) {
    view.shownDepth = session.octreeDepth();
    if (!opt.view.quiet) std::printf("octree: %s\n", session.octreeSummary().c_str());
    report.figures["octree"] = session.octreeSummary();
  }
  if (!opt.view.quiet && !session.atlasSummary().empty()) {
    std::printf("atlas: %s\n", session.atlasSummary().c_str());
  }
  Renderer& renderer = session.renderer();
  if (!opt.view.quiet && !view.path) std::printf("%s", viewerKeyHelp());

  Viewer viewer(*context, renderer, view, levels.get());
  StageTimer framesTimer(rows, "frames");
  const ViewerStats stats = viewer.run();
  framesTimer.finish(stats.ToString(opt.view.saveFrames));
  if (!opt.view.quiet) std::printf("%s\n", stats.ToString(opt.view.saveFrames).c_str());
  if (!opt.json.empty()) {
    report.figures["frames"] = {{"drawn", stats.framesDrawn},
                                {"saved", stats.framesSaved},
                                {"seconds", stats.seconds},
                                {"ms_per_frame", stats.framesDrawn > 0
                                                     ? 1000.0 * stats.seconds / stats.framesDrawn
                                                     : 0.0}};
    AtomicFileSet outputs;
    report.addTo(outputs, opt.json, rows);
    outputs.commit();
  }
  return 0;
}

}  // namespace

std::function<int()> addViewCommand(CLI::App& app) {
  auto opt = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Walk through a scene lit by its baked light octree in a window (GLFW); or play a "
      "recorded camera path and save the frames; or, with --progressive, bake from the scene "
      "while watching (depth 4, then 5, up to --depth).");
  cmd->footer(std::string("\n") + viewerKeyHelp() +
              "\nCamera path file (--camera-path, P appends to --record): one keyframe per "
              "line,\n  t ex ey ez tx ty tz [fov]\nseconds, eye, target, vertical fov in degrees; "
              "'#' starts a comment; linear interpolation.\n");
  cmd->add_option("scene", opt->scene, "Scene: .gltf, .glb or .obj")
      ->required()
      ->check(CLI::ExistingFile);
  addSceneOptions(cmd, opt->sceneOptions);
  addObjectOptions(cmd, opt->objects);
  cmd->add_option("lights", opt->lights,
                  "Baked VDL grid (.vdb from `lightoctree bake`); not with --progressive")
      ->check(CLI::ExistingFile);
  addCameraOptions(cmd, opt->camera);
  cmd->add_option("--width", opt->width, "Window width in screen pixels")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  cmd->add_option("--height", opt->height, "Window height in screen pixels")
      ->check(CLI::Range(16, 16384))
      ->capture_default_str();
  cmd->add_option("--mode", opt->mode, "Start in full | direct | indirect | voxels (keys 1 2 3 4)")
      ->check(CLI::IsMember({"full", "direct", "indirect", "voxels"}))
      ->capture_default_str();
  addShadingOptions(cmd, opt->shading, true);
  cmd->add_option("--speed", opt->speed,
                  "Movement speed, scene units per second (default: a quarter of the scene's "
                  "diagonal)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--camera-path", opt->cameraPath,
                  "Play this camera path (format below) and exit at its end")
      ->check(CLI::ExistingFile);
  cmd->add_option("--save-frames", opt->view.saveFrames,
                  "Write every frame drawn as DIR/frame_00000.png, ... (created if missing)");
  cmd->add_option("--frames", opt->view.frames,
                  "Exit after N frames (with --camera-path: N frames evenly spaced along it; "
                  "with --progressive: N frames at the target depth)")
      ->check(CLI::Range(0, 10000000));
  cmd->add_flag("--continuous", opt->view.continuous,
                "Redraw every iteration, even when nothing changed (by default a still view "
                "is not redrawn, which leaves the CPU to a --progressive bake)");
  cmd->add_option("--record", opt->view.record, "Path file the P key appends keyframes to")
      ->capture_default_str();
  cmd->add_flag("--progressive", opt->progressive,
                "Bake from the scene while viewing: trace photons once, show depth 4 as soon "
                "as it is ready, refine to --depth in the background");
  cmd->add_option("--photons", opt->bake.photons.storedPhotons, "Progressive: photons to store")
      ->check(CLI::Range(size_t(1), size_t(200000000)))
      ->capture_default_str();
  cmd->add_option("--depth", opt->bake.targetDepth, "Progressive: target octree depth")
      ->check(depthValidator())
      ->capture_default_str();
  cmd->add_option("--knn", opt->bake.gather.k, "Progressive: nearest photons gathered per voxel")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", opt->bake.photons.seed, "Progressive: random seed")
      ->check(seedValidator())->capture_default_str();
  cmd->add_flag_callback("--no-hud", [opt] { opt->view.hud = false; },
                "No heads-up display in the window (frame time, mode, octree level, the "
                "progressive bake's progress; H shows the keys there)");
  cmd->add_option("--json", opt->json,
                  "Also write a JSON report when the window closes: the files read, time and "
                  "memory per start-up stage (load, grid, GL context, octree, shaders, lights, "
                  "geometry and textures, shadow maps) and the frames drawn (README.md, "
                  "\"Scripting\")");
  cmd->add_flag("-q,--quiet", opt->view.quiet, "Only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runView(*opt) : -1; };
}

}  // namespace lo::tool
