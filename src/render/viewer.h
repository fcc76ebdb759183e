#pragma once
/// @file render/viewer.h
/// @brief The walkthrough of `lightoctree view`: the frame loop of a window
/// (render/context.h, GLFW back end) drawing a Renderer, with key and mouse
/// handling through the context's input events, the redraw policy (a still
/// view is not redrawn), camera paths (play, record with P), saved frames and
/// the window title. New octree levels (a progressive bake) come from an
/// OctreeLevelSource (octree/octree_level_source.h), so this stage needs no
/// bake. See docs/view.md.

#include <memory>
#include <optional>
#include <string>

#include "octree/gpu_octree.h"
#include "octree/octree_level_source.h"
#include "render/camera_path.h"
#include "render/context.h"
#include "render/fly_camera.h"
#include "render/renderer.h"

namespace lo {

/// The keys of the viewer, as `view --help` and the H key print them.
const char* viewerKeyHelp();

struct ViewerParams {
  RenderParams render;       ///< start mode, interpolation, GGX lobe, VDLs (size: the window's)
  float exposure = 0;        ///< EV at the start (key 0 returns to it)
  FlyCamera start;           ///< start camera and movement speed
  float znear = 1e-3f;       ///< near plane, scene units
  std::optional<CameraPath> path;  ///< play this path instead of the keyboard, exit at its end
  float defaultFovDegrees = 45;    ///< for path keyframes without a field of view
  std::string saveFrames;    ///< folder: every frame drawn as frame_00000.png, ...; "" = none
  int frames = 0;            ///< exit after this many frames (at the target depth); 0 = no limit
  std::string record = "camera-path.txt";  ///< the file P appends keyframes to
  /// Scene::origin: keyframes are recorded in the file's world coordinates
  /// (the camera's position plus this), as --eye and camera paths take them.
  Vec3d worldOrigin;
  bool continuous = false;   ///< redraw every iteration even when nothing changed
  int shownDepth = 0;        ///< depth of the octree the renderer starts with (0 = none)
  int firstDepth = 0;        ///< the level source's first depth (progressive)
  int targetDepth = 0;       ///< the level source's last depth (progressive)
  bool quiet = false;        ///< no terminal output
  /// The HUD in the window (render/hud.h): frame time, mode, octree level,
  /// the progressive bake's progress, `H` for the keys. Saved frames
  /// (--save-frames) never hold it.
  bool hud = true;
};

struct ViewerStats {
  int framesDrawn = 0;
  int framesSaved = 0;
  double seconds = 0;
  /// "N frames in S s (M ms per frame)", and where the saved ones went
  /// (`saveFrames`, the folder), for the terminal; no newline.
  std::string ToString(const std::string& saveFrames) const;
};

class Viewer {
 public:
  /// `window` must be a window context (GLFW) and current; `renderer` draws
  /// into it; `levels` may be null. All must outlive the viewer.
  Viewer(GlContext& window, Renderer& renderer, const ViewerParams& params,
         OctreeLevelSource* levels = nullptr);
  ~Viewer();
  Viewer(const Viewer&) = delete;
  Viewer& operator=(const Viewer&) = delete;

  /// Runs the frame loop until the window closes, the camera path ends or
  /// `frames` frames are drawn.
  ViewerStats run();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lo
