#pragma once
/// @file render/context.h
/// @brief OpenGL contexts: one interface, three back ends. OSMesa (software,
/// llvmpipe, no display needed), EGL (headless on a GPU or Mesa, no display)
/// and GLFW (a window). Every back end asks for a 4.5 core profile and falls
/// back to 3.3 core; the GL entry points are loaded through glad with the back
/// end's own get-proc-address, so the same renderer runs on all three.
/// Headless contexts have no usable default framebuffer: render into an FBO.

#include <memory>
#include <stdexcept>
#include <string>

namespace lo {

enum class GlBackend { OSMesa, Egl, Glfw };

/// "osmesa" | "egl" | "glfw". @throws InputError naming the value.
GlBackend parseGlBackend(const std::string& name);
std::string toString(GlBackend backend);

struct GlContextParams {
  GlBackend backend = GlBackend::OSMesa;
  int width = 800;                     ///< window size in screen pixels (GLFW only)
  int height = 600;                    ///< window size in screen pixels (GLFW only)
  std::string title = "Light Octree";  ///< window title (GLFW only)
  bool debugOutput = false;            ///< print GL_KHR_debug messages to stderr
};

/// What the context offers; the renderer passes the texture limits on to
/// GpuOctreeParams so that the octree is built for this context.
struct GlInfo {
  int major = 0, minor = 0;  ///< context version actually obtained
  int max3DTextureSize = 0;  ///< GL_MAX_3D_TEXTURE_SIZE, texels per axis
  int max2DTextureSize = 0;  ///< GL_MAX_TEXTURE_SIZE, texels per axis
  std::string vendor, renderer, version;
  std::string ToString() const;
};

/// Keys a window reports (the window back end translates its own codes), so
/// that input handling needs no windowing library's header.
enum class Key {
  Unknown, Escape, Space, LeftShift, RightShift, LeftControl, RightControl,
  Left, Right, Up, Down,
  A, D, E, G, H, I, M, P, Q, R, S, V, W,
  Num0, Num1, Num2, Num3, Num4,
  LeftBracket, RightBracket, Equal, Minus, KeypadAdd, KeypadSubtract, Comma, Period,
};
enum class MouseButton { Left, Right, Other };

/// Receives a window's input events, on the thread that polls them.
class InputHandler {
 public:
  virtual ~InputHandler() = default;
  /// A key went down (`repeat` false) or auto-repeats while held (true).
  virtual void onKey(Key key, bool repeat) = 0;
  virtual void onScroll(double dy) = 0;
  virtual void onMouseButton(MouseButton button, bool pressed) = 0;
  /// Cursor position in screen pixels (unbounded while the cursor is captured).
  virtual void onCursor(double x, double y) = 0;
  /// The window must be redrawn (exposed, resized).
  virtual void onDamage() = 0;
};

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  GlBackend backend() const { return backend_; }
  const GlInfo& info() const { return info_; }
  /// Makes the context current on this thread and (re)binds the glad entry
  /// points to this back end's library when another back end was current.
  void makeCurrent();

  // Window back end only; headless back ends do nothing / report false.
  virtual bool shouldClose() const { return false; }
  virtual void swapBuffers() {}
  virtual void setTitle(const std::string&) {}
  /// Framebuffer size of the window in pixels; headless: 0 x 0.
  virtual void framebufferSize(int& width, int& height) const { width = height = 0; }
  /// Input: events go to `handler` (may be null) during pollEvents / waitEvents.
  virtual void setInputHandler(InputHandler*) {}
  virtual void pollEvents() {}
  /// Waits up to `seconds` for an event, then handles what came.
  virtual void waitEvents(double /*seconds*/) {}
  virtual bool keyHeld(Key) const { return false; }
  virtual bool mouseHeld(MouseButton) const { return false; }
  /// Hides the cursor and reports unbounded relative motion (mouse look).
  virtual void setCursorCaptured(bool) {}
  /// Asks the window to close: shouldClose() becomes true.
  virtual void requestClose() {}

 protected:
  explicit GlContext(GlBackend backend) : backend_(backend) {}
  virtual void makeCurrentImpl() = 0;
  using ProcLoader = void (*(*)(const char*))();
  virtual ProcLoader procLoader() const = 0;
  /// Loads the entry points and fills info_; call once from the back end's
  /// constructor after its context is current.
  void initialize(bool debugOutput);

  GlBackend backend_;
  GlInfo info_;
};

/// Creates a context of the requested back end and makes it current.
/// @throws GlError when the back end cannot give a 3.3+ core context (no
/// display, no driver); the message names the back end and the failing call.
/// Also, at once, in a child forked after its parent made a context (and
/// from makeCurrent there): the driver's threads stayed in the parent, and
/// the child would wait for them forever; the message says to start
/// processes afresh ('spawn').
std::unique_ptr<GlContext> createGlContext(const GlContextParams& params = {});

/// An OpenGL failure: context creation, shader compilation, framebuffer setup.
class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace lo
