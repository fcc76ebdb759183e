// `lightoctree view`: a GLFW window walkthrough of a scene lit by its light
// octree, interactive or along a recorded camera path; with --progressive, the
// octree is baked coarse to fine in the background while the window shows
// the newest level (paper §5.2). The frame loop, input and redraw policy are
// the Viewer's (render/viewer.h); this file parses, sets up and reports.

#include <CLI/CLI.hpp>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>

#include "bake/progressive_bake.h"
#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "json_report.h"
#include "render/camera_path.h"
#include "render/context.h"
#include "render/render_session.h"
#include "render/viewer.h"
#include "render_stages.h"
#include "scene/scene.h"
#include "vdb/vdb_io.h"
#include "view_options.h"

namespace lo::tool {
namespace {

/// Whether the viewer may write `name` into its --save-frames folder: it
/// writes frame_00000.png, frame_00001.png, ... (render/viewer.h), as many
/// as it draws, six digits and more past 99,999.
bool isSavedFrameName(const std::string& name) {
  const std::string head = "frame_", tail = ".png";
  if (name.size() < head.size() + 5 + tail.size() || name.compare(0, head.size(), head) != 0 ||
      name.compare(name.size() - tail.size(), tail.size(), tail) != 0) {
    return false;
  }
  return name.find_first_not_of("0123456789", head.size()) == name.size() - tail.size();
}

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
  NamedPaths inputs = sceneInputs(opt);
  if (!opt.lights.empty()) inputs.push_back({"LIGHTS", opt.lights});
  // The file P appends to may be the path played, and nothing else read.
  checkDistinctFiles({{"--record", opt.view.record}}, inputs);
  if (!opt.cameraPath.empty()) inputs.push_back({"--camera-path", opt.cameraPath});
  if (!opt.view.saveFrames.empty()) {
    checkFolderOutputs(
        opt.view.saveFrames,
        [](const std::string& name) {
          return isSavedFrameName(name) ? "frame '" + name + "' of --save-frames" : std::string();
        },
        "--save-frames", inputs);
  }
  inputs.push_back({"--record", opt.view.record});
  checkDistinctFiles({{"--json", opt.json}}, inputs);
  JsonReport report{"view", inputs,
                    {{"mode", opt.mode}, {"width", opt.width}, {"height", opt.height},
                     {"progressive", opt.progressive}}};
  std::vector<StageReport> rows;
  std::optional<CameraPath> path;
  if (!opt.cameraPath.empty()) path = readCameraPath(opt.cameraPath);
  if (!opt.view.saveFrames.empty()) makeOutputFolder(opt.view.saveFrames, "--save-frames");
  RenderSettings settings = opt.shading.settings(parseRenderMode(opt.mode), opt.width, opt.height);
  settings.renderer.interactive = true;

  Scene scene = loadSceneStage(opt, rows);
  std::optional<LoadedVdl> baked;
  if (!opt.progressive) baked = readLightsStage(opt.lights, scene, rows);
  ViewerParams view = opt.viewerParams(scene, settings, std::move(path));

  GlContextParams contextParams;
  contextParams.backend = GlBackend::Glfw;
  contextParams.width = opt.width;
  contextParams.height = opt.height;
  contextParams.title = "Light Octree: " + std::filesystem::path(opt.scene).filename().string();
  std::unique_ptr<GlContext> context =
      openContextStage(contextParams, "glfw", opt.view.quiet, report, rows);

  // Progressive: the bake thread starts before the session's set-up (scene
  // upload, shadow maps) so that the two overlap; until the first level is
  // ready the window shows direct light over an empty octree.
  std::unique_ptr<ProgressiveBake> bake;
  std::unique_ptr<OctreeLevelSource> levels;
  if (opt.progressive) {
    StageTimer bakeTimer(rows, "start progressive bake");
    const ProgressiveParams pp = opt.progressiveParams(settings, context->info());
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
  // A progressive bake's levels arrive later: no octree to show yet.
  reportSession(session, /*showOctree=*/!bake, opt.view.quiet, report, rows);
  if (!bake) view.shownDepth = session.octreeDepth();
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
  return addCommand(app, "view", addViewOptions, runView);
}

}  // namespace lo::tool
