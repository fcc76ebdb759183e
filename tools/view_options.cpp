#include "view_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>

#include "cli_checks.h"
#include "command_options.h"
#include "render/fly_camera.h"

namespace lo::tool {

ViewerParams ViewOptions::viewerParams(const Scene& loaded, const RenderSettings& settings,
                                       std::optional<CameraPath> path) const {
  ViewerParams params = view;
  params.render = settings.frame;
  params.exposure = shading.exposure;
  params.path = std::move(path);
  params.worldOrigin = loaded.origin;
  if (params.path) {
    for (CameraKey& key : params.path->keys) {  // the file's world coordinates
      key.eye = loaded.toLocal(Vec3d(key.eye));
      key.target = loaded.toLocal(Vec3d(key.target));
    }
  }
  PinholeCamera startCamera = chooseCamera(camera, loaded, scene);
  params.defaultFovDegrees = camera.fovDegrees > 0 ? camera.fovDegrees : 45.0f;
  params.start = FlyCamera::lookingAt(startCamera.eye, startCamera.eye + startCamera.forward,
                                      startCamera.yfov);
  const float diagonal = std::max(length(loaded.bounds().extent()), 1e-3f);
  params.start.speed = speed > 0 ? speed : 0.25f * diagonal;
  params.znear = 1e-3f * diagonal;
  return params;
}

ProgressiveParams ViewOptions::progressiveParams(const RenderSettings& settings,
                                                 const GlInfo& gl) const {
  ProgressiveParams params = bake;
  params.firstDepth = std::min(4, params.targetDepth);
  params.cluster.seed = params.photons.seed;
  params.octree = settings.octreeParams(&gl);
  return params;
}

void addViewOptions(CLI::App* cmd, ViewOptions& opt) {
  cmd->description(
      "Walk through a scene lit by its baked light octree in a window (GLFW); or play a "
      "recorded camera path and save the frames; or, with --progressive, bake from the scene "
      "while watching (depth 4, then 5, up to --depth).");
  cmd->footer(std::string("\n") + viewerKeyHelp() +
              "\nCamera path file (--camera-path, P appends to --record): one keyframe per "
              "line,\n  t ex ey ez tx ty tz [fov]\nseconds, eye, target, vertical fov in degrees; "
              "'#' starts a comment; linear interpolation.\n");
  addSceneFlags(cmd, opt);
  addLightsArgument(cmd, opt.lights, "; not with --progressive");
  addCameraOptions(cmd, opt.camera);
  addSizeOptions(cmd, opt.width, opt.height, "Window", "screen pixels", 16);
  cmd->add_option("--mode", opt.mode, "Start in full | direct | indirect | voxels (keys 1 2 3 4)")
      ->check(CLI::IsMember({"full", "direct", "indirect", "voxels"}))
      ->capture_default_str();
  addShadingOptions(cmd, opt.shading, true);
  cmd->add_option("--speed", opt.speed,
                  "Movement speed, scene units per second (default: a quarter of the scene's "
                  "diagonal)")
      ->check(numberIn(kPositiveNumber));
  cmd->add_option("--camera-path", opt.cameraPath,
                  "Play this camera path (format below) and exit at its end")
      ->check(existingFile());
  cmd->add_option("--save-frames", opt.view.saveFrames,
                  "Write every frame drawn as DIR/frame_00000.png, ... (created if missing)");
  cmd->add_option("--frames", opt.view.frames,
                  "Exit after N frames (with --camera-path: N frames evenly spaced along it; "
                  "with --progressive: N frames at the target depth)")
      ->check(wholeIn(0, 10000000));
  cmd->add_flag("--continuous", opt.view.continuous,
                "Redraw every iteration, even when nothing changed (by default a still view "
                "is not redrawn, which leaves the CPU to a --progressive bake)");
  cmd->add_option("--record", opt.view.record, "Path file the P key appends keyframes to")
      ->capture_default_str();
  cmd->add_flag("--progressive", opt.progressive,
                "Bake from the scene while viewing: trace photons once, show depth 4 as soon "
                "as it is ready, refine to --depth in the background");
  cmd->add_option("--photons", opt.bake.photons.storedPhotons, "Progressive: photons to store")
      ->check(numberIn(kPhotonsRange))
      ->capture_default_str();
  cmd->add_option("--depth", opt.bake.targetDepth, "Progressive: target octree depth")
      ->check(depthValidator())
      ->capture_default_str();
  cmd->add_option("--knn", opt.bake.gather.k, "Progressive: nearest photons gathered per voxel")
      ->check(numberIn(kKnnRange))
      ->capture_default_str();
  cmd->add_option("--seed", opt.bake.photons.seed, "Progressive: random seed")
      ->check(seedValidator())
      ->capture_default_str();
  // The options outlive the parse (the command's runner holds them).
  cmd->add_flag_callback(
      "--no-hud", [&opt] { opt.view.hud = false; },
      "No heads-up display in the window (frame time, mode, octree level, the "
      "progressive bake's progress; H shows the keys there)");
  cmd->add_option("--json", opt.json,
                  "Also write a JSON report when the window closes: the files read, time and "
                  "memory per start-up stage (load, grid, GL context, octree, shaders, lights, "
                  "geometry and textures, shadow maps) and the frames drawn (README.md, "
                  "\"Scripting\")");
  cmd->add_flag("-q,--quiet", opt.view.quiet, "Only errors");
}

}  // namespace lo::tool
