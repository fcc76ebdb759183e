#pragma once
/// @file tools/view_options.h
/// @brief The flags of `view` and their translation into the Viewer's and the
/// progressive bake's parameters, as bake_options.h is for `bake`.

#include <optional>
#include <string>

#include "bake/progressive_bake.h"
#include "camera_options.h"
#include "render/camera_path.h"
#include "render/render_session.h"
#include "render/viewer.h"
#include "render_options.h"
#include "scene/scene.h"
#include "scene_options.h"

namespace CLI {
class App;
}

namespace lo::tool {

/// The flags of `view`, as given.
struct ViewOptions : SceneFlags {
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

  /// The Viewer's parameters: the flags bound to `view`, the first frame's
  /// `settings`, the camera `path` (read from --camera-path, in the file's
  /// world coordinates) taken to the scene's, the start camera the camera
  /// flags choose, moving at --speed, and a near plane, both from the size of
  /// the `loaded` scene. @throws InputError naming --camera (chooseCamera).
  ViewerParams viewerParams(const Scene& loaded, const RenderSettings& settings,
                            std::optional<CameraPath> path) const;

  /// --progressive's bake: depth 4 first (paper §5.2; the target if that is
  /// shallower), the K-means seeded as the photons, each level's octree
  /// within the limits of the context `gl`.
  ProgressiveParams progressiveParams(const RenderSettings& settings, const GlInfo& gl) const;
};

/// Registers the description and the flags of `view` on `cmd`, and the
/// window's keys and the camera path format as its help's footer.
void addViewOptions(CLI::App* cmd, ViewOptions& opt);

}  // namespace lo::tool
