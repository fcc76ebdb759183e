// Viewer: the frame loop, input handling and redraw policy of `lightoctree view`.

#include "render/viewer.h"

#include "render/hud.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/resources.h"
#include "image/image.h"

namespace lo {
namespace viewer_internal {

constexpr float kMouseRadiansPerPixel = 0.0025f;
constexpr float kKeyTurnRadiansPerSecond = 1.5f;
constexpr float kSpeedStep = 1.25f;
constexpr float kExposureStep = 0.5f;

bool sameView(const PinholeCamera& a, const PinholeCamera& b) {
  return a.eye == b.eye && a.forward == b.forward && a.up == b.up && a.yfov == b.yfov &&
         a.znear == b.znear && a.zfar == b.zfar;
}

bool sameParams(const RenderParams& a, const RenderParams& b) {
  return a.width == b.width && a.height == b.height && a.mode == b.mode &&
         a.interpolation == b.interpolation && a.specular == b.specular && a.maxVdls == b.maxVdls &&
         a.normalOffset == b.normalOffset;
}

/// The keyframe `P` writes: the camera on screen, `time` seconds into the path.
CameraKey keyOf(const PinholeCamera& camera, float time) {
  CameraKey k;
  k.time = time;
  k.eye = camera.eye;
  k.target = camera.eye + camera.forward;
  k.fovDegrees = camera.yfov * 180.0f / kPi;
  return k;
}

/// Keyframes appended with `P` keep the pace at which they were recorded:
/// each gets the seconds since the first `P` of this session, after the
/// file's last keyframe (plus one second) when the file already has some.
class PathRecorder {
 public:
  PathRecorder(std::string path, const Vec3d& origin) : path_(std::move(path)), origin_(origin) {}
  void append(const PinholeCamera& camera) {
    if (!started_) {
      base_ = 0;
      if (std::filesystem::exists(path_)) base_ = readCameraPath(path_).endTime() + 1.0f;
      clock_.reset();
      started_ = true;
      last_ = -INFINITY;
    }
    float t = base_ + float(last_ == -INFINITY ? 0.0 : clock_.seconds());
    t = std::max(t, last_ + 0.001f);  // strictly increasing, even for two presses in a frame
    const CameraKey key = inWorld(keyOf(camera, t), camera);
    appendCameraKey(path_, key);
    last_ = t;
    std::printf("appended keyframe %s to %s\n", key.ToString().c_str(), path_.c_str());
  }

 private:
  /// The key in the file's world coordinates; far from the origin the target
  /// is put farther along the view than 1 unit, so that rounding the world
  /// positions to float leaves the direction precise.
  CameraKey inWorld(CameraKey key, const PinholeCamera& camera) const {
    if (origin_.x == 0 && origin_.y == 0 && origin_.z == 0) return key;
    const double reach =
        std::max(1.0, 1e-3 * std::max({std::fabs(origin_.x), std::fabs(origin_.y), std::fabs(origin_.z)}));
    key.eye = (Vec3d(camera.eye) + origin_).toVec3();
    key.target = (Vec3d(camera.eye) + Vec3d(camera.forward) * reach + origin_).toVec3();
    return key;
  }

  std::string path_;
  Vec3d origin_;
  bool started_ = false;
  float base_ = 0, last_ = 0;
  Stopwatch clock_;
};

std::string framePath(const std::string& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return (std::filesystem::path(dir) / name).string();
}

}  // namespace viewer_internal

const char* viewerKeyHelp() {
  return "Keys (view window):\n"
         "  W A S D           move forward / left / back / right\n"
         "  E or Space        move up;  Q or Ctrl: move down;  hold Shift: 4x faster\n"
         "  mouse drag        look around (hold the left or right button); arrow keys also turn\n"
         "  scroll, + / -     movement speed x1.25 / /1.25\n"
         "  1 2 3             full / direct / indirect (octree only) lighting\n"
         "  4 or V            voxel view (octree leaves coloured by a hash)\n"
         "  I                 trilinear interpolation on/off\n"
         "  G                 glossy (GGX) lobe on/off\n"
         "  [ / ]             fewer / more VDLs used per voxel (1..8)\n"
         "  , / .             exposure -0.5 / +0.5 EV;  0: back to --exposure\n"
         "  M + move keys     hold M: W A S D E Q move the objects added with --add instead\n"
         "  P                 append the current camera to the --record path file\n"
         "  R                 back to the start camera\n"
         "  H                 these keys on the screen (and printed, with the camera); H again hides them\n"
         "  Esc               quit\n";
}

/// The viewer's state, changed by the window's input events.
struct Viewer::Impl final : InputHandler {
  GlContext& window;
  Renderer& renderer;
  ViewerParams params;
  OctreeLevelSource* levels;

  FlyCamera fly;
  RenderParams render;
  float exposure = 0;
  bool looking = false;
  bool haveCursor = false;
  double cursorX = 0, cursorY = 0;
  float pendingYaw = 0, pendingPitch = 0;  // radians, from the mouse since the last frame
  bool appendKey = false;                  // P pressed: handled in the frame loop
  bool printHelp = false;
  bool showKeys = false;  // H: the keys on the HUD too
  bool damaged = false;  // the window needs a redraw (exposed, resized)
  Vec3 objectOffset{0, 0, 0};  // M + move keys: where the added objects are, from --at
  bool objectMoved = false;    // they moved this frame: redraw
  std::unique_ptr<HudOverlay> hud;  // made in run(), with the window's context current

  Impl(GlContext& w, Renderer& r, const ViewerParams& p, OctreeLevelSource* l)
      : window(w), renderer(r), params(p), levels(l), fly(p.start), render(p.render),
        exposure(p.exposure) {}

  void onKey(Key key, bool repeat) override {
    using namespace viewer_internal;
    const bool press = !repeat;
    RenderParams& p = render;
    switch (key) {
      case Key::Escape:
        window.requestClose();
        break;
      case Key::Num1:
        p.mode = RenderMode::Full;
        break;
      case Key::Num2:
        p.mode = RenderMode::Direct;
        break;
      case Key::Num3:
        p.mode = RenderMode::Indirect;
        break;
      case Key::Num4:
      case Key::V:
        p.mode = RenderMode::Voxels;
        break;
      case Key::I:
        if (press) p.interpolation = !p.interpolation;
        break;
      case Key::G:
        if (press) p.specular = !p.specular;
        break;
      case Key::LeftBracket:
        p.maxVdls = std::max(1, p.maxVdls - 1);
        break;
      case Key::RightBracket:
        p.maxVdls = std::min(kMaxVdls, p.maxVdls + 1);
        break;
      case Key::Equal:
      case Key::KeypadAdd:
        fly.speed *= kSpeedStep;
        break;
      case Key::Minus:
      case Key::KeypadSubtract:
        fly.speed /= kSpeedStep;
        break;
      case Key::Comma:
        exposure -= kExposureStep;
        break;
      case Key::Period:
        exposure += kExposureStep;
        break;
      case Key::Num0:
        exposure = params.exposure;
        break;
      case Key::R:
        if (press) {
          const float speed = fly.speed;
          fly = params.start;
          fly.speed = speed;
        }
        break;
      case Key::P:
        if (press) appendKey = true;
        break;
      case Key::H:
        if (press) {
          printHelp = true;
          showKeys = !showKeys;
        }
        break;
      default:
        break;
    }
  }

  void onScroll(double dy) override {
    fly.speed *= std::pow(viewer_internal::kSpeedStep, float(dy));
  }

  void onMouseButton(MouseButton button, bool pressed) override {
    if (button == MouseButton::Other) return;
    const bool anyHeld = window.mouseHeld(MouseButton::Left) || window.mouseHeld(MouseButton::Right);
    if (pressed && !looking) {
      looking = true;
      haveCursor = false;
      // Captured cursor: unbounded relative motion while the button is held.
      window.setCursorCaptured(true);
    } else if (!pressed && !anyHeld) {
      looking = false;
      window.setCursorCaptured(false);
    }
  }

  void onCursor(double x, double y) override {
    if (looking && haveCursor) {
      // Screen y grows downwards: moving the mouse down looks down.
      pendingYaw += float(x - cursorX) * viewer_internal::kMouseRadiansPerPixel;
      pendingPitch -= float(y - cursorY) * viewer_internal::kMouseRadiansPerPixel;
    }
    cursorX = x;
    cursorY = y;
    haveCursor = true;
  }

  void onDamage() override { damaged = true; }

  bool held(Key key) const { return window.keyHeld(key); }

  /// Keyboard movement and turning for one frame of `seconds`.
  void applyHeldKeys(float seconds) {
    Vec3 d(0, 0, 0);
    if (held(Key::W)) d.z += 1;
    if (held(Key::S)) d.z -= 1;
    if (held(Key::D)) d.x += 1;
    if (held(Key::A)) d.x -= 1;
    if (held(Key::E) || held(Key::Space)) d.y += 1;
    if (held(Key::Q) || held(Key::LeftControl) || held(Key::RightControl)) d.y -= 1;
    const bool fast = held(Key::LeftShift) || held(Key::RightShift);
    if (held(Key::M) && renderer.hasAddedObjects()) {
      // The added objects move instead of the camera: along the view's
      // horizontal forward and right, and up.
      if (d != Vec3(0, 0, 0)) {
        Vec3 forward = fly.forward();
        forward.y = 0;
        forward = lengthSquared(forward) > 0 ? normalize(forward) : Vec3(0, 0, -1);
        const Vec3 step = (forward * d.z + fly.right() * d.x + Vec3(0, 1, 0) * d.y) *
                          (fly.speed * seconds * (fast ? 4.0f : 1.0f));
        objectOffset += step;
        renderer.moveAddedObjects(objectOffset);
        objectMoved = true;
      }
      d = Vec3(0, 0, 0);
    }
    fly.move(d, seconds * (fast ? 4.0f : 1.0f));
    const float turn = viewer_internal::kKeyTurnRadiansPerSecond * seconds;
    float yaw = pendingYaw, pitch = pendingPitch;
    if (held(Key::Left)) yaw -= turn;
    if (held(Key::Right)) yaw += turn;
    if (held(Key::Up)) pitch += turn;
    if (held(Key::Down)) pitch -= turn;
    fly.turn(yaw, pitch);
    pendingYaw = pendingPitch = 0;
  }

  /// "full, interp on, 4 VDLs, EV +0.0": the settings on screen.
  std::string settingsText() const {
    char buf[128];
    std::snprintf(buf, sizeof buf, "%s, interp %s, %d VDL%s, EV %+.1f", toString(render.mode).c_str(),
                  render.interpolation ? "on" : "off", render.maxVdls, render.maxVdls == 1 ? "" : "s",
                  double(exposure));
    return buf;
  }

  /// "12.3 ms, 81.3 fps".
  static std::string frameText(double frameMs) {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%.1f ms, %.1f fps", frameMs, frameMs > 0 ? 1000.0 / frameMs : 0.0);
    return buf;
  }

  std::string title(double frameMs, const std::string& octreeText,
                    const std::string& pathText) const {
    char speed[32];
    std::snprintf(speed, sizeof speed, "%.3g", double(fly.speed));
    return "Light Octree | " + settingsText() + ", speed " + speed + "/s | " + frameText(frameMs) +
           " | " + octreeText + pathText;
  }

  /// The HUD's lines: what is on screen, then `H` for the keys (or the keys).
  std::vector<std::string> hudLines(double frameMs, const std::string& octreeText,
                                    const std::string& pathText) const {
    std::vector<std::string> lines{frameText(frameMs) + "   " + settingsText(), "octree: " + octreeText};
    if (!pathText.empty()) lines.push_back(pathText.substr(3));  // without " | "
    if (!showKeys) {
      lines.push_back("H: keys");
      return lines;
    }
    const std::string keys = viewerKeyHelp();
    for (size_t start = 0; start < keys.size();) {
      const size_t end = keys.find('\n', start);
      const std::string k = keys.substr(start, end == std::string::npos ? std::string::npos : end - start);
      if (!k.empty()) lines.push_back(k);
      if (end == std::string::npos) break;
      start = end + 1;
    }
    return lines;
  }

  ViewerStats run();
};

ViewerStats Viewer::Impl::run() {
  using namespace viewer_internal;
  const std::optional<CameraPath>& path = params.path;
  window.setInputHandler(this);
  PathRecorder recorder(params.record, params.worldOrigin);
  Stopwatch clock;
  ViewerStats stats;
  double lastTime = 0, titleTime = 0, pathStart = 0;
  int titleFrames = 0, framesCounted = 0;
  double titleMs = 0, titleDrawSeconds = 0;
  int shownDepth = params.shownDepth;
  const bool alwaysDraw =
      params.continuous || path || params.frames > 0 || !params.saveFrames.empty();
  PinholeCamera lastCamera;
  RenderParams lastParams;
  std::string lastHudState;
  float lastExposure = 0;
  bool justShown = false;  // a new level went on screen: reported once its first frame is drawn
  bool pathDone = false;

  while (!window.shouldClose()) {
    window.pollEvents();
    const double now = clock.seconds();
    const float dt = float(std::min(now - lastTime, 0.25));  // no jump after a stall
    lastTime = now;

    if (levels) {
      GpuOctree octree;
      int depth = 0;
      if (levels->takeNewest(octree, depth)) {
        // Levels finished during one frame: only the finest is uploaded.
        for (int d = std::max(shownDepth + 1, params.firstDepth); d < depth; ++d) {
          if (!params.quiet) std::printf("depth %d skipped: depth %d was ready first\n", d, depth);
        }
        renderer.setOctree(octree);
        shownDepth = depth;
        justShown = true;
      }
    }
    const bool refining = levels && !(levels->finished() && shownDepth == params.targetDepth);

    PinholeCamera camera;
    std::string pathText;
    if (path) {
      if (stats.framesDrawn == 0 || refining) pathStart = now;  // real time starts at the target
      float t = params.frames > 0 ? path->frameTime(framesCounted, params.frames)
                                  : path->startTime() + float(now - pathStart);
      if (refining) t = path->startTime();
      camera = path->sample(t).camera(params.defaultFovDegrees);
      char text[64];
      std::snprintf(text, sizeof text, " | path %.1f / %.1f s", double(t - path->startTime()),
                    double(path->duration()));
      pathText = text;
      pathDone = params.frames <= 0 && !refining && t >= path->endTime();
    } else {
      applyHeldKeys(dt);
      camera = fly.camera();
    }
    camera.znear = params.znear;

    std::string octreeText = "depth " + std::to_string(shownDepth);
    if (levels) {
      if (shownDepth == 0) {
        octreeText = "no octree yet (" + levels->status() + ")";
      } else if (refining) {
        octreeText = "depth " + std::to_string(shownDepth) + ", refining to " +
                     std::to_string(params.targetDepth) + " (" + levels->status() + ")";
      }
    }

    int width = 0, height = 0;
    window.framebufferSize(width, height);
    if (width <= 0 || height <= 0) {  // minimized
      window.waitEvents(0.1);
      continue;
    }
    render.width = width;
    render.height = height;

    // On demand: a frame is drawn only when something on screen would change
    // (camera, settings, window, a new level), so that a still view leaves
    // the cores to the bake; paths, --frames and --save-frames draw every
    // iteration, as does --continuous.
    const bool drawScene = alwaysDraw || stats.framesDrawn == 0 || damaged || justShown || objectMoved ||
                           !sameView(camera, lastCamera) || !sameParams(render, lastParams) ||
                           exposure != lastExposure;
    // The HUD's text but for its frame time: a change (the bake's progress,
    // the keys shown) redraws a still view too.
    const std::string hudState = octreeText + pathText + (showKeys ? "k" : "");
    const bool hudChanged = params.hud && hudState != lastHudState;
    const bool draw = drawScene || hudChanged;
    if (draw) {
      Stopwatch frameClock;
      renderer.drawToScreen(camera, render, exposure);
      if (params.hud) {
        if (!hud) hud = std::make_unique<HudOverlay>();
        hud->draw(hudLines(titleMs, octreeText, pathText), width, height);
        lastHudState = hudState;
      }
      if (!params.saveFrames.empty()) {
        writeImage(framePath(params.saveFrames, stats.framesSaved++),
                   renderer.render(camera, render), exposure);
      }
      window.swapBuffers();
      titleDrawSeconds += frameClock.seconds();
      ++titleFrames;
      ++stats.framesDrawn;
      damaged = false;
      objectMoved = false;
      lastCamera = camera;
      lastParams = render;
      lastExposure = exposure;
    }
    const double frameEnd = clock.seconds();

    if (justShown) {
      if (!params.quiet) {
        std::printf("%s\n", levels->shownReport().c_str());
        std::fflush(stdout);
      }
      justShown = false;
    }
    if (appendKey) {
      appendKey = false;
      try {
        recorder.append(camera);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "lightoctree view: cannot append the camera: %s\n", e.what());
      }
    }
    if (printHelp) {
      printHelp = false;
      std::printf("%scamera: %s\n", viewerKeyHelp(), keyOf(camera, 0).ToString().c_str());
    }

    // Frames that count towards --frames: with a level source only those at
    // the target depth (earlier ones are drawn, and saved, but not counted).
    if (draw && !refining) ++framesCounted;
    if (frameEnd - titleTime >= 0.5 || stats.framesDrawn == 1) {
      // Mean draw time of the frames drawn since the last update: what a
      // frame costs, whether frames are drawn continuously or on demand.
      if (titleFrames > 0) titleMs = 1000.0 * titleDrawSeconds / titleFrames;
      titleTime = frameEnd;
      titleFrames = 0;
      titleDrawSeconds = 0;
      window.setTitle(title(titleMs, octreeText, pathText));
    }
    if (params.frames > 0 && framesCounted >= params.frames) break;
    if (pathDone) break;
    if (!draw) window.waitEvents(levels && !levels->finished() ? 0.02 : 0.25);
  }
  window.setInputHandler(nullptr);
  stats.seconds = clock.seconds();
  return stats;
}

Viewer::Viewer(GlContext& window, Renderer& renderer, const ViewerParams& params,
               OctreeLevelSource* levels)
    : impl_(std::make_unique<Impl>(window, renderer, params, levels)) {}

Viewer::~Viewer() = default;

ViewerStats Viewer::run() { return impl_->run(); }

std::string ViewerStats::ToString(const std::string& saveFrames) const {
  char line[256];
  std::snprintf(line, sizeof line, "%d frames in %.2f s (%.1f ms per frame)", framesDrawn,
                seconds, framesDrawn ? 1000.0 * seconds / framesDrawn : 0.0);
  std::string text = line;
  if (framesSaved) text += ", " + std::to_string(framesSaved) + " saved to " + saveFrames;
  return text;
}

}  // namespace lo
