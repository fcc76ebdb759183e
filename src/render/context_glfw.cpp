// GLFW back end: a window (needs a display).

#include <glad/gl.h>
// After glad: GLFW must not include the system GL header.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>

#include <string>

#include "render/context_internal.h"

namespace lo::render_internal {
namespace {

std::string glfwLastError() {
  const char* description = nullptr;
  glfwGetError(&description);
  return description ? description : "unknown error";
}

class GlfwContext final : public GlContext {
 public:
  explicit GlfwContext(const GlContextParams& params) : GlContext(GlBackend::Glfw) {
    if (!glfwInit()) throw GlError("glfw: glfwInit failed (" + glfwLastError() + ")");
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
      throw GlError("glfw: cannot open a core 4.5 or 3.3 window (" + why + ")");
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
  void* nativeWindow() const override { return window_; }

 protected:
  void makeCurrentImpl() override { glfwMakeContextCurrent(window_); }
  ProcLoader procLoader() const override { return &glfwGetProcAddress; }

 private:
  GLFWwindow* window_ = nullptr;
};

}  // namespace

std::unique_ptr<GlContext> createGlfwContext(const GlContextParams& params) {
  return std::make_unique<GlfwContext>(params);
}

}  // namespace lo::render_internal
