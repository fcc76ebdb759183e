// GLFW back end: a window (needs a display).

#include <glad/gl.h>
// After glad: GLFW must not include the system GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <array>
#include <string>

#include "render/context_internal.h"

namespace lo::render_internal {
namespace {

Key keyOf(int key) {
  switch (key) {
    case GLFW_KEY_ESCAPE: return Key::Escape;
    case GLFW_KEY_SPACE: return Key::Space;
    case GLFW_KEY_LEFT_SHIFT: return Key::LeftShift;
    case GLFW_KEY_RIGHT_SHIFT: return Key::RightShift;
    case GLFW_KEY_LEFT_CONTROL: return Key::LeftControl;
    case GLFW_KEY_RIGHT_CONTROL: return Key::RightControl;
    case GLFW_KEY_LEFT: return Key::Left;
    case GLFW_KEY_RIGHT: return Key::Right;
    case GLFW_KEY_UP: return Key::Up;
    case GLFW_KEY_DOWN: return Key::Down;
    case GLFW_KEY_A: return Key::A;
    case GLFW_KEY_D: return Key::D;
    case GLFW_KEY_E: return Key::E;
    case GLFW_KEY_G: return Key::G;
    case GLFW_KEY_H: return Key::H;
    case GLFW_KEY_I: return Key::I;
    case GLFW_KEY_M: return Key::M;
    case GLFW_KEY_P: return Key::P;
    case GLFW_KEY_Q: return Key::Q;
    case GLFW_KEY_R: return Key::R;
    case GLFW_KEY_S: return Key::S;
    case GLFW_KEY_V: return Key::V;
    case GLFW_KEY_W: return Key::W;
    case GLFW_KEY_0: return Key::Num0;
    case GLFW_KEY_1: return Key::Num1;
    case GLFW_KEY_2: return Key::Num2;
    case GLFW_KEY_3: return Key::Num3;
    case GLFW_KEY_4: return Key::Num4;
    case GLFW_KEY_LEFT_BRACKET: return Key::LeftBracket;
    case GLFW_KEY_RIGHT_BRACKET: return Key::RightBracket;
    case GLFW_KEY_EQUAL: return Key::Equal;
    case GLFW_KEY_MINUS: return Key::Minus;
    case GLFW_KEY_KP_ADD: return Key::KeypadAdd;
    case GLFW_KEY_KP_SUBTRACT: return Key::KeypadSubtract;
    case GLFW_KEY_COMMA: return Key::Comma;
    case GLFW_KEY_PERIOD: return Key::Period;
    default: return Key::Unknown;
  }
}

/// GLFW's code of `key`: keyOf inverted once, not searched per call (the
/// viewer asks for a dozen held keys every frame).
int glfwKeyOf(Key key) {
  static const std::array<int, size_t(Key::Period) + 1> table = [] {
    std::array<int, size_t(Key::Period) + 1> t;
    t.fill(GLFW_KEY_UNKNOWN);
    for (int k = GLFW_KEY_SPACE; k <= GLFW_KEY_LAST; ++k) {
      const Key mapped = keyOf(k);
      if (mapped != Key::Unknown) t[size_t(mapped)] = k;
    }
    return t;
  }();
  return size_t(key) < table.size() ? table[size_t(key)] : GLFW_KEY_UNKNOWN;
}

int glfwButtonOf(MouseButton b) {
  return b == MouseButton::Left    ? GLFW_MOUSE_BUTTON_LEFT
         : b == MouseButton::Right ? GLFW_MOUSE_BUTTON_RIGHT
                                   : GLFW_MOUSE_BUTTON_MIDDLE;
}

std::string glfwLastError() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown error";
}

/// What a user without a display can do instead.
constexpr const char* kNeedsDisplay =
    "; a window needs a display (on a machine without one: xvfb-run -a lightoctree view ..., "
    "or `lightoctree render` for images)";

class GlfwContext final : public GlContext {
 public:
  explicit GlfwContext(const GlContextParams& params) : GlContext(GlBackend::Glfw) {
    if (!glfwInit()) {
      throw GlError("glfw: glfwInit failed (" + glfwLastError() + ")" + kNeedsDisplay);
    }
    for (int version : {45, 33}) {
      glfwDefaultWindowHints();
      glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, version / 10);
      glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, version % 10);
      glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
      glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
      window_ =
          glfwCreateWindow(params.width, params.height, params.title.c_str(), nullptr, nullptr);
      if (window_) break;
    }
    if (!window_) {
      std::string why = glfwLastError();
      glfwTerminate();
      throw GlError("glfw: cannot open a core 4.5 or 3.3 window (" + why + ")" + kNeedsDisplay);
    }
    makeCurrentImpl();
    glfwSwapInterval(0);  // frame times are measured, not capped by vsync
    initialize(params.debugOutput);
  }
  ~GlfwContext() override {
    glfwDestroyWindow(window_);
    glfwTerminate();
  }

  bool shouldClose() const override { return glfwWindowShouldClose(window_); }
  void swapBuffers() override { glfwSwapBuffers(window_); }
  void setTitle(const std::string& title) override { glfwSetWindowTitle(window_, title.c_str()); }
  void framebufferSize(int& width, int& height) const override {
    glfwGetFramebufferSize(window_, &width, &height);
  }
  void setInputHandler(InputHandler* handler) override {
    handler_ = handler;
    glfwSetWindowUserPointer(window_, this);
    glfwSetKeyCallback(window_, [](GLFWwindow* w, int key, int, int action, int) {
      InputHandler* h = self(w)->handler_;
      if (h && (action == GLFW_PRESS || action == GLFW_REPEAT)) {
        h->onKey(keyOf(key), action == GLFW_REPEAT);
      }
    });
    glfwSetScrollCallback(window_, [](GLFWwindow* w, double, double dy) {
      if (InputHandler* h = self(w)->handler_) h->onScroll(dy);
    });
    glfwSetMouseButtonCallback(window_, [](GLFWwindow* w, int button, int action, int) {
      InputHandler* h = self(w)->handler_;
      if (!h) return;
      const MouseButton b = button == GLFW_MOUSE_BUTTON_LEFT    ? MouseButton::Left
                            : button == GLFW_MOUSE_BUTTON_RIGHT ? MouseButton::Right
                                                                : MouseButton::Other;
      h->onMouseButton(b, action == GLFW_PRESS);
    });
    glfwSetCursorPosCallback(window_, [](GLFWwindow* w, double x, double y) {
      if (InputHandler* h = self(w)->handler_) h->onCursor(x, y);
    });
    glfwSetWindowRefreshCallback(window_, [](GLFWwindow* w) {
      if (InputHandler* h = self(w)->handler_) h->onDamage();
    });
  }
  void pollEvents() override { glfwPollEvents(); }
  void waitEvents(double seconds) override { glfwWaitEventsTimeout(seconds); }
  bool keyHeld(Key key) const override {
    const int k = glfwKeyOf(key);
    return k != GLFW_KEY_UNKNOWN && glfwGetKey(window_, k) == GLFW_PRESS;
  }
  bool mouseHeld(MouseButton b) const override {
    return glfwGetMouseButton(window_, glfwButtonOf(b)) == GLFW_PRESS;
  }
  void setCursorCaptured(bool captured) override {
    glfwSetInputMode(window_, GLFW_CURSOR, captured ? GLFW_CURSOR_DISABLED : GLFW_CURSOR_NORMAL);
  }
  void requestClose() override { glfwSetWindowShouldClose(window_, GLFW_TRUE); }

 protected:
  void makeCurrentImpl() override { glfwMakeContextCurrent(window_); }
  ProcLoader procLoader() const override { return &glfwGetProcAddress; }

 private:
  static GlfwContext* self(GLFWwindow* w) {
    return static_cast<GlfwContext*>(glfwGetWindowUserPointer(w));
  }

  GLFWwindow* window_ = nullptr;
  InputHandler* handler_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> createGlfwContext(const GlContextParams& params) {
  return std::make_unique<GlfwContext>(params);
}

}  // namespace lo::render_internal
