// `lightoctree view`: a GLFW window walkthrough of a scene lit by its light
// octree, interactive or along a recorded camera path; with --progressive, the
// octree is baked coarse to fine in the background while the window shows
// the newest level (paper §5.2). Camera math and path files: render/fly_camera.h
// and render/camera_path.h; this file is only GLFW input, the frame loop and
// reporting.

#include <CLI/CLI.hpp>
// The renderer loads GL itself (render/context.h): GLFW is here for input only.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include "camera_options.h"
#include "cli_checks.h"
#include "commands.h"
#include "core/error.h"
#include "core/resources.h"
#include "octree/gpu_octree.h"
#include "bake/progressive_bake.h"
#include "render/camera_path.h"
#include "render/context.h"
#include "render/fly_camera.h"
#include "render/image_io.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

const char* const kKeys =
    "Keys (view window):\n"
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
    "  P                 append the current camera to the --record path file\n"
    "  R                 back to the start camera;  H: print these keys and the camera\n"
    "  Esc               quit\n";

struct ViewOptions {
  std::string scene;
  std::string lights;
  CameraOptions camera;
  int width = 800, height = 600;
  std::string mode = "full";
  std::string interpolation = "on";
  std::string specular = "on";
  float exposure = 0;
  int vdls = 8;
  int emitterLights = 8;
  int shadowMapSize = 1024;
  bool halfFloat = false;
  std::string cosineCorrection = "on";
  float speed = 0;  // 0 = a quarter of the scene's diagonal per second
  std::string cameraPath;
  std::string saveFrames;
  int frames = 0;
  std::string record = "camera-path.txt";
  bool continuous = false;
  bool progressive = false;
  size_t photons = 600000;
  int depth = 6;
  int knn = 300;
  uint64_t seed = 1;
  bool quiet = false;
};

/// Everything the GLFW callbacks change. Reached through the window's user pointer.
struct ViewState {
  FlyCamera fly;
  FlyCamera start;
  RenderParams params;
  float exposure = 0, startExposure = 0;
  bool looking = false;
  bool haveCursor = false;
  double cursorX = 0, cursorY = 0;
  float pendingYaw = 0, pendingPitch = 0;  // radians, from the mouse since the last frame
  bool appendKey = false;                  // P pressed: handled in the frame loop
  bool printHelp = false;
  bool damaged = false;  // the window needs a redraw (exposed, resized)
};

constexpr float kMouseRadiansPerPixel = 0.0025f;
constexpr float kKeyTurnRadiansPerSecond = 1.5f;
constexpr float kSpeedStep = 1.25f;
constexpr float kExposureStep = 0.5f;

ViewState& stateOf(GLFWwindow* window) {
  return *static_cast<ViewState*>(glfwGetWindowUserPointer(window));
}

void onKey(GLFWwindow* window, int key, int, int action, int) {
  if (action != GLFW_PRESS && action != GLFW_REPEAT) return;
  ViewState& s = stateOf(window);
  RenderParams& p = s.params;
  bool press = action == GLFW_PRESS;
  switch (key) {
    case GLFW_KEY_ESCAPE:
      glfwSetWindowShouldClose(window, GLFW_TRUE);
      break;
    case GLFW_KEY_1:
      p.mode = RenderMode::Full;
      break;
    case GLFW_KEY_2:
      p.mode = RenderMode::Direct;
      break;
    case GLFW_KEY_3:
      p.mode = RenderMode::Indirect;
      break;
    case GLFW_KEY_4:
    case GLFW_KEY_V:
      p.mode = RenderMode::Voxels;
      break;
    case GLFW_KEY_I:
      if (press) p.interpolation = !p.interpolation;
      break;
    case GLFW_KEY_G:
      if (press) p.specular = !p.specular;
      break;
    case GLFW_KEY_LEFT_BRACKET:
      p.maxVdls = std::max(1, p.maxVdls - 1);
      break;
    case GLFW_KEY_RIGHT_BRACKET:
      p.maxVdls = std::min(kMaxVdls, p.maxVdls + 1);
      break;
    case GLFW_KEY_EQUAL:
    case GLFW_KEY_KP_ADD:
      s.fly.speed *= kSpeedStep;
      break;
    case GLFW_KEY_MINUS:
    case GLFW_KEY_KP_SUBTRACT:
      s.fly.speed /= kSpeedStep;
      break;
    case GLFW_KEY_COMMA:
      s.exposure -= kExposureStep;
      break;
    case GLFW_KEY_PERIOD:
      s.exposure += kExposureStep;
      break;
    case GLFW_KEY_0:
      s.exposure = s.startExposure;
      break;
    case GLFW_KEY_R:
      if (press) {
        float speed = s.fly.speed;
        s.fly = s.start;
        s.fly.speed = speed;
      }
      break;
    case GLFW_KEY_P:
      if (press) s.appendKey = true;
      break;
    case GLFW_KEY_H:
      if (press) s.printHelp = true;
      break;
    default:
      break;
  }
}

void onScroll(GLFWwindow* window, double, double dy) {
  ViewState& s = stateOf(window);
  s.fly.speed *= std::pow(kSpeedStep, float(dy));
}

void onMouseButton(GLFWwindow* window, int button, int action, int) {
  if (button != GLFW_MOUSE_BUTTON_LEFT && button != GLFW_MOUSE_BUTTON_RIGHT) return;
  ViewState& s = stateOf(window);
  bool anyHeld = glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_LEFT) == GLFW_PRESS ||
                 glfwGetMouseButton(window, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
  if (action == GLFW_PRESS && !s.looking) {
    s.looking = true;
    s.haveCursor = false;
    // Disabled cursor: unbounded relative motion while the button is held.
    glfwSetInputMode(window, GLFW_CURSOR, GLFW_CURSOR_DISABLED);
  } else if (action == GLFW_RELEASE && !anyHeld) {
    s.looking = false;
    glfwSetInputMode(window, GLFW_CURSOR, GLFW_CURSOR_NORMAL);
  }
}

void onCursor(GLFWwindow* window, double x, double y) {
  ViewState& s = stateOf(window);
  if (s.looking && s.haveCursor) {
    // Screen y grows downwards: moving the mouse down looks down.
    s.pendingYaw += float(x - s.cursorX) * kMouseRadiansPerPixel;
    s.pendingPitch -= float(y - s.cursorY) * kMouseRadiansPerPixel;
  }
  s.cursorX = x;
  s.cursorY = y;
  s.haveCursor = true;
}

void onRefresh(GLFWwindow* window) { stateOf(window).damaged = true; }

bool sameView(const RenderCamera& a, const RenderCamera& b) {
  return a.eye == b.eye && a.forward == b.forward && a.up == b.up && a.yfov == b.yfov &&
         a.znear == b.znear && a.zfar == b.zfar;
}

bool sameParams(const RenderParams& a, const RenderParams& b) {
  return a.width == b.width && a.height == b.height && a.mode == b.mode &&
         a.interpolation == b.interpolation && a.specular == b.specular && a.maxVdls == b.maxVdls &&
         a.normalOffset == b.normalOffset;
}

bool held(GLFWwindow* window, int key) { return glfwGetKey(window, key) == GLFW_PRESS; }

/// Keyboard movement and turning for one frame of `seconds`.
void applyHeldKeys(GLFWwindow* window, ViewState& s, float seconds) {
  Vec3 d(0, 0, 0);
  if (held(window, GLFW_KEY_W)) d.z += 1;
  if (held(window, GLFW_KEY_S)) d.z -= 1;
  if (held(window, GLFW_KEY_D)) d.x += 1;
  if (held(window, GLFW_KEY_A)) d.x -= 1;
  if (held(window, GLFW_KEY_E) || held(window, GLFW_KEY_SPACE)) d.y += 1;
  if (held(window, GLFW_KEY_Q) || held(window, GLFW_KEY_LEFT_CONTROL) ||
      held(window, GLFW_KEY_RIGHT_CONTROL)) {
    d.y -= 1;
  }
  bool fast = held(window, GLFW_KEY_LEFT_SHIFT) || held(window, GLFW_KEY_RIGHT_SHIFT);
  s.fly.move(d, seconds * (fast ? 4.0f : 1.0f));
  float turn = kKeyTurnRadiansPerSecond * seconds;
  float yaw = s.pendingYaw, pitch = s.pendingPitch;
  if (held(window, GLFW_KEY_LEFT)) yaw -= turn;
  if (held(window, GLFW_KEY_RIGHT)) yaw += turn;
  if (held(window, GLFW_KEY_UP)) pitch += turn;
  if (held(window, GLFW_KEY_DOWN)) pitch -= turn;
  s.fly.turn(yaw, pitch);
  s.pendingYaw = s.pendingPitch = 0;
}

/// The keyframe `P` writes: the camera on screen, `time` seconds into the path.
CameraKey keyOf(const RenderCamera& camera, float time) {
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
  explicit PathRecorder(std::string path) : path_(std::move(path)) {}
  void append(const RenderCamera& camera) {
    if (!started_) {
      base_ = 0;
      if (std::filesystem::exists(path_)) base_ = readCameraPath(path_).endTime() + 1.0f;
      clock_.reset();
      started_ = true;
      last_ = -INFINITY;
    }
    float t = base_ + float(last_ == -INFINITY ? 0.0 : clock_.seconds());
    t = std::max(t, last_ + 0.001f);  // strictly increasing, even for two presses in a frame
    appendCameraKey(path_, keyOf(camera, t));
    last_ = t;
    std::printf("appended keyframe %s to %s\n", keyOf(camera, t).ToString().c_str(), path_.c_str());
  }

 private:
  std::string path_;
  bool started_ = false;
  float base_ = 0, last_ = 0;
  Stopwatch clock_;
};

std::string formatTitle(const ViewState& s, double frameMs, const std::string& octreeText,
                        const std::string& pathText) {
  char buf[512];
  std::snprintf(buf, sizeof buf,
                "Light Octree | %s, interp %s, %d VDL%s, EV %+.1f, speed %.3g/s | %.1f ms, "
                "%.1f fps | %s%s",
                toString(s.params.mode).c_str(), s.params.interpolation ? "on" : "off",
                s.params.maxVdls, s.params.maxVdls == 1 ? "" : "s", double(s.exposure),
                double(s.fly.speed), frameMs, frameMs > 0 ? 1000.0 / frameMs : 0.0,
                octreeText.c_str(), pathText.c_str());
  return buf;
}

std::string framePath(const std::string& dir, int index) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%05d.png", index);
  return (std::filesystem::path(dir) / name).string();
}

int runView(const ViewOptions& opt) {
  // Everything that can be checked before a window opens is checked first.
  if (opt.progressive && !opt.lights.empty()) {
    throw InputError("--progressive bakes the lights from the scene: give no LIGHTS.vdb ('" +
                     opt.lights + "')");
  }
  if (!opt.progressive && opt.lights.empty()) {
    throw InputError("LIGHTS.vdb is required (a bake of the scene), or use --progressive");
  }
  checkCameraOptions(opt.camera);
  std::optional<CameraPath> path;
  if (!opt.cameraPath.empty()) path = readCameraPath(opt.cameraPath);
  if (!opt.saveFrames.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(opt.saveFrames, ec);
    if (!std::filesystem::is_directory(opt.saveFrames)) {
      throw InputError("--save-frames: cannot create the folder '" + opt.saveFrames + "'" +
                       (ec ? " (" + ec.message() + ")" : ""));
    }
  }
  ViewState state;
  state.params.mode = parseRenderMode(opt.mode);
  state.params.interpolation = opt.interpolation == "on";
  state.params.specular = opt.specular == "on";
  state.params.maxVdls = opt.vdls;
  state.exposure = state.startExposure = opt.exposure;

  Scene scene = loadScene(opt.scene);
  std::optional<LoadedVdl> baked;
  if (!opt.progressive) baked = readVdlGrid(opt.lights);

  RenderCamera startCamera = chooseCamera(opt.camera, scene, opt.scene);
  float defaultFovDegrees = opt.camera.fovDegrees > 0 ? opt.camera.fovDegrees : 45.0f;
  state.start = FlyCamera::lookingAt(startCamera.eye, startCamera.eye + startCamera.forward,
                                     startCamera.yfov);
  float diagonal = std::max(length(scene.bounds().extent()), 1e-3f);
  state.start.speed = opt.speed > 0 ? opt.speed : 0.25f * diagonal;
  state.fly = state.start;

  GlContextParams contextParams;
  contextParams.backend = GlBackend::Glfw;
  contextParams.width = opt.width;
  contextParams.height = opt.height;
  contextParams.title = "Light Octree: " + std::filesystem::path(opt.scene).filename().string();
  std::unique_ptr<GlContext> context;
  try {
    context = createGlContext(contextParams);
  } catch (const GlError& e) {
    throw GlError(std::string(e.what()) +
                  "; `view` needs a display (on a machine without one: xvfb-run -a lightoctree "
                  "view ..., or `lightoctree render` for images)");
  }
  if (!opt.quiet) std::printf("glfw: %s\n", context->info().ToString().c_str());

  GpuOctreeParams octreeParams;
  octreeParams.halfFloat = opt.halfFloat;
  octreeParams.cosineCorrection = opt.cosineCorrection == "on";
  octreeParams.max3DTextureSize = context->info().max3DTextureSize;
  octreeParams.max2DTextureSize = context->info().max2DTextureSize;

  // Progressive: the bake thread starts before the renderer's set-up (scene
  // upload, shadow maps) so that the two overlap; until the first level is
  // ready the window shows direct light over an empty octree.
  std::unique_ptr<ProgressiveBake> bake;
  GpuOctree octree;
  int shownDepth = 0;
  if (opt.progressive) {
    ProgressiveParams pp;
    pp.photons.storedPhotons = opt.photons;
    pp.photons.seed = opt.seed;
    pp.targetDepth = opt.depth;
    pp.firstDepth = std::min(4, opt.depth);
    pp.gather.k = opt.knn;
    pp.cluster.seed = opt.seed;
    pp.octree = octreeParams;
    bake = std::make_unique<ProgressiveBake>(scene, pp);
    if (!opt.quiet) {
      std::printf("progressive: tracing %zu photons, then depth %d to %d\n", opt.photons,
                  pp.firstDepth, pp.targetDepth);
    }
  } else {
    octree = buildGpuOctree(baked->grid, octreeParams);
    shownDepth = octree.depth;
    if (!opt.quiet) std::printf("octree: %s\n", octree.ToString().c_str());
  }

  RendererParams rendererParams;
  rendererParams.emitterLights = opt.emitterLights;
  rendererParams.shadowMapSize = opt.shadowMapSize;
  Renderer renderer(scene, octree, rendererParams);
  octree = GpuOctree();  // uploaded; the CPU copy is not needed any more

  GLFWwindow* window = static_cast<GLFWwindow*>(context->nativeWindow());
  glfwSetWindowUserPointer(window, &state);
  glfwSetKeyCallback(window, onKey);
  glfwSetScrollCallback(window, onScroll);
  glfwSetMouseButtonCallback(window, onMouseButton);
  glfwSetCursorPosCallback(window, onCursor);
  glfwSetWindowRefreshCallback(window, onRefresh);
  if (!opt.quiet && !path) std::printf("%s", kKeys);

  PathRecorder recorder(opt.record);
  Stopwatch clock;
  double lastTime = 0, titleTime = 0, pathStart = 0;
  int titleFrames = 0, framesDrawn = 0, framesCounted = 0, savedFrames = 0;
  double titleMs = 0, titleDrawSeconds = 0;
  const bool alwaysDraw = opt.continuous || path || opt.frames > 0 || !opt.saveFrames.empty();
  RenderCamera lastCamera;
  RenderParams lastParams;
  float lastExposure = 0;
  // A level that went on screen: reported once its first frame is drawn.
  std::optional<ProgressiveLevel> justShown;
  bool pathDone = false;

  while (!context->shouldClose()) {
    glfwPollEvents();
    double now = clock.seconds();
    float dt = float(std::min(now - lastTime, 0.25));  // no jump after a stall
    lastTime = now;

    if (bake) {
      if (std::optional<ProgressiveLevel> level = bake->takeNewest()) {
        // Levels finished during one frame: only the finest is uploaded.
        for (int d = std::max(shownDepth + 1, std::min(4, opt.depth)); d < level->depth; ++d) {
          if (!opt.quiet)
            std::printf("depth %d skipped: depth %d was ready first\n", d, level->depth);
        }
        renderer.setOctree(level->octree);
        shownDepth = level->depth;
        level->octree = GpuOctree();
        justShown = std::move(level);
      }
    }
    bool refining = bake && !(bake->finished() && shownDepth == opt.depth);

    RenderCamera camera;
    std::string pathText;
    if (path) {
      if (framesDrawn == 0 || refining) pathStart = now;  // real time starts at the target depth
      float t = opt.frames > 0 ? path->frameTime(framesCounted, opt.frames)
                               : path->startTime() + float(now - pathStart);
      if (refining) t = path->startTime();
      camera = path->sample(t).camera(defaultFovDegrees);
      char text[64];
      std::snprintf(text, sizeof text, " | path %.1f / %.1f s", double(t - path->startTime()),
                    double(path->duration()));
      pathText = text;
      pathDone = opt.frames <= 0 && !refining && t >= path->endTime();
    } else {
      applyHeldKeys(window, state, dt);
      camera = state.fly.camera();
    }
    camera.znear = 1e-3f * diagonal;

    int width = 0, height = 0;
    context->framebufferSize(width, height);
    if (width <= 0 || height <= 0) {  // minimized
      glfwWaitEventsTimeout(0.1);
      continue;
    }
    state.params.width = width;
    state.params.height = height;

    // On demand: a frame is drawn only when something on screen would change
    // (camera, settings, window, a new level), so that a still view leaves
    // the cores to the bake; paths, --frames and --save-frames draw every
    // iteration, as does --continuous.
    bool draw = alwaysDraw || framesDrawn == 0 || state.damaged || justShown ||
                !sameView(camera, lastCamera) || !sameParams(state.params, lastParams) ||
                state.exposure != lastExposure;
    if (draw) {
      Stopwatch frameClock;
      renderer.drawToScreen(camera, state.params, state.exposure);
      if (!opt.saveFrames.empty()) {
        writeImage(framePath(opt.saveFrames, savedFrames++), renderer.render(camera, state.params),
                   state.exposure);
      }
      context->swapBuffers();
      titleDrawSeconds += frameClock.seconds();
      ++titleFrames;
      ++framesDrawn;
      state.damaged = false;
      lastCamera = camera;
      lastParams = state.params;
      lastExposure = state.exposure;
    }
    double frameEnd = clock.seconds();

    if (justShown) {
      if (!opt.quiet) {
        const ProgressiveLevel& l = *justShown;
        double onScreen =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - l.photonsTraced)
                .count();
        std::printf(
            "depth %d on screen %.2f s after the photons were traced (bake %.2f s: voxelize "
            "%.2f, splat %.2f, gather + cluster %.2f; octree %.3f s; %zu voxels)%s\n",
            l.depth, onScreen, l.stats.seconds(), l.stats.voxelizeSeconds, l.stats.splatSeconds,
            l.stats.gatherClusterSeconds, l.octreeSeconds, l.stats.activeVoxels,
            l.depth == opt.depth ? " (target)" : "");
        std::fflush(stdout);
      }
      justShown.reset();
    }
    if (state.appendKey) {
      state.appendKey = false;
      try {
        recorder.append(camera);
      } catch (const std::exception& e) {
        std::fprintf(stderr, "lightoctree view: cannot append the camera: %s\n", e.what());
      }
    }
    if (state.printHelp) {
      state.printHelp = false;
      std::printf("%scamera: %s\n", kKeys, keyOf(camera, 0).ToString().c_str());
    }

    // Frames that count towards --frames: in progressive mode only those at
    // the target depth (earlier ones are drawn, and saved, but not counted).
    if (draw && !refining) ++framesCounted;
    if (frameEnd - titleTime >= 0.5 || framesDrawn == 1) {
      // Mean draw time of the frames drawn since the last update: what a
      // frame costs, whether frames are drawn continuously or on demand.
      if (titleFrames > 0) titleMs = 1000.0 * titleDrawSeconds / titleFrames;
      titleTime = frameEnd;
      titleFrames = 0;
      titleDrawSeconds = 0;
      std::string octreeText;
      if (bake) {
        ProgressiveStatus st = bake->status();
        if (shownDepth == 0) {
          octreeText = "no octree yet (" + st.ToString() + ")";
        } else if (refining) {
          octreeText = "depth " + std::to_string(shownDepth) + ", refining to " +
                       std::to_string(opt.depth) + " (" + st.ToString() + ")";
        } else {
          octreeText = "depth " + std::to_string(shownDepth);
        }
      } else {
        octreeText = "depth " + std::to_string(shownDepth);
      }
      context->setTitle(formatTitle(state, titleMs, octreeText, pathText));
    }
    if (opt.frames > 0 && framesCounted >= opt.frames) break;
    if (pathDone) break;
    if (!draw) glfwWaitEventsTimeout(bake && !bake->finished() ? 0.02 : 0.25);
  }
  double seconds = clock.seconds();
  if (!opt.quiet) {
    std::printf("%d frames in %.2f s (%.1f ms per frame)", framesDrawn, seconds,
                framesDrawn ? 1000.0 * seconds / framesDrawn : 0.0);
    if (savedFrames) std::printf(", %d saved to %s", savedFrames, opt.saveFrames.c_str());
    std::printf("\n");
  }
  return 0;
}

CLI::Validator onOff() { return CLI::IsMember({"on", "off"}); }

}  // namespace

std::function<int()> addViewCommand(CLI::App& app) {
  auto opt = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand(
      "view",
      "Walk through a scene lit by its baked light octree in a window (GLFW); or play a "
      "recorded camera path and save the frames; or, with --progressive, bake from the scene "
      "while watching (depth 4, then 5, up to --depth).");
  cmd->footer(std::string("\n") + kKeys +
              "\nCamera path file (--camera-path, P appends to --record): one keyframe per "
              "line,\n  t ex ey ez tx ty tz [fov]\nseconds, eye, target, vertical fov in degrees; "
              "'#' starts a comment; linear interpolation.\n");
  cmd->add_option("scene", opt->scene, "Scene: .gltf, .glb or .obj")
      ->required()
      ->check(CLI::ExistingFile);
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
  cmd->add_option("--interpolation", opt->interpolation, "Start with interpolation on/off (I)")
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--specular", opt->specular, "Start with the GGX lobe on/off (G)")
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--exposure", opt->exposure, "Exposure in EV (radiance * 2^EV; keys , .)")
      ->check(CLI::Range(-30.0f, 30.0f))
      ->capture_default_str();
  cmd->add_option("--vdls", opt->vdls, "VDLs used per voxel at the start, 1-" + std::to_string(kMaxVdls) + " (keys [ ])")
      ->check(CLI::Range(1, kMaxVdls))
      ->capture_default_str();
  cmd->add_option("--emitter-lights", opt->emitterLights,
                  "Shadowed virtual point lights sampled on emissive triangles (0: none)")
      ->check(CLI::Range(0, 16))
      ->capture_default_str();
  cmd->add_option("--shadow-map-size", opt->shadowMapSize, "Shadow map resolution per face")
      ->check(CLI::Range(16, 8192))
      ->capture_default_str();
  cmd->add_flag("--half-float", opt->halfFloat, "VDL texture with half-float irradiance");
  cmd->add_option("--cosine-correction", opt->cosineCorrection,
                  "Divide each VDL by the cosine to its voxel's normal on upload (as `render`)")
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--speed", opt->speed,
                  "Movement speed, scene units per second (default: a quarter of the scene's "
                  "diagonal)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--camera-path", opt->cameraPath,
                  "Play this camera path (format below) and exit at its end")
      ->check(CLI::ExistingFile);
  cmd->add_option("--save-frames", opt->saveFrames,
                  "Write every frame drawn as DIR/frame_00000.png, ... (created if missing)");
  cmd->add_option("--frames", opt->frames,
                  "Exit after N frames (with --camera-path: N frames evenly spaced along it; "
                  "with --progressive: N frames at the target depth)")
      ->check(CLI::Range(0, 10000000));
  cmd->add_flag("--continuous", opt->continuous,
                "Redraw every iteration, even when nothing changed (by default a still view "
                "is not redrawn, which leaves the CPU to a --progressive bake)");
  cmd->add_option("--record", opt->record, "Path file the P key appends keyframes to")
      ->capture_default_str();
  cmd->add_flag("--progressive", opt->progressive,
                "Bake from the scene while viewing: trace photons once, show depth 4 as soon "
                "as it is ready, refine to --depth in the background");
  cmd->add_option("--photons", opt->photons, "Progressive: photons to store")
      ->check(CLI::Range(size_t(1), size_t(200000000)))
      ->capture_default_str();
  cmd->add_option("--depth", opt->depth, "Progressive: target octree depth")
      ->check(depthValidator())
      ->capture_default_str();
  cmd->add_option("--knn", opt->knn, "Progressive: nearest photons gathered per voxel")
      ->check(CLI::Range(1, 100000))
      ->capture_default_str();
  cmd->add_option("--seed", opt->seed, "Progressive: random seed")->capture_default_str();
  cmd->add_flag("-q,--quiet", opt->quiet, "Only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runView(*opt) : -1; };
}

}  // namespace lo::tool
