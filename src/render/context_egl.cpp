// EGL back end: headless, no window system. Tries the EGL devices first
// (EGL_EXT_device_enumeration + EGL_EXT_platform_device: a GPU driver), then
// Mesa's surfaceless platform (EGL_MESA_platform_surfaceless). No pbuffer: the
// context is made current with EGL_NO_SURFACE (EGL_KHR_surfaceless_context)
// and the renderer draws into FBOs.

#include <glad/gl.h>
// After glad: eglplatform.h must not pull in the system GL header.
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstdio>
#include <string>
#include <vector>

#include "render/context_internal.h"

namespace lo::render_internal {
namespace {

std::string eglErrorString() {
  char buf[32];
  std::snprintf(buf, sizeof buf, "0x%04x", unsigned(eglGetError()));
  return buf;
}

/// Displays to try, best first.
std::vector<EGLDisplay> candidateDisplays() {
  std::vector<EGLDisplay> displays;
  auto queryDevices =
      reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
  if (queryDevices) {
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (queryDevices(16, devices, &count)) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay d = eglGetPlatformDisplay(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d != EGL_NO_DISPLAY) displays.push_back(d);
      }
    }
  }
  EGLDisplay d = eglGetPlatformDisplay(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
  if (d != EGL_NO_DISPLAY) displays.push_back(d);
  return displays;
}

class EglContext final : public GlContext {
 public:
  explicit EglContext(const GlContextParams& params) : GlContext(GlBackend::Egl) {
    std::string why = "no EGL display (device or surfaceless)";
    for (EGLDisplay d : candidateDisplays()) {
      if (tryDisplay(d, why)) break;
    }
    if (context_ == EGL_NO_CONTEXT) throw GlError("egl: " + why);
    initialize(params.debugOutput);
  }
  ~EglContext() override {
    eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    eglTerminate(display_);
  }

 protected:
  void makeCurrentImpl() override {
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_)) {
      throw GlError("egl: eglMakeCurrent failed (" + eglErrorString() + ")");
    }
  }
  ProcLoader procLoader() const override { return &loader; }

 private:
  static void (*loader(const char* name))() { return eglGetProcAddress(name); }

  bool tryDisplay(EGLDisplay d, std::string& why) {
    EGLint major = 0, minor = 0;
    if (!eglInitialize(d, &major, &minor)) {
      why = "eglInitialize failed (" + eglErrorString() + ")";
      return false;
    }
    if (!eglBindAPI(EGL_OPENGL_API)) {
      why = "eglBindAPI(EGL_OPENGL_API) failed";
      eglTerminate(d);
      return false;
    }
    const EGLint configAttribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint configs = 0;
    // Without a matching config, EGL_KHR_no_config_context still allows a context.
    if (!eglChooseConfig(d, configAttribs, &config, 1, &configs) || configs == 0) {
      config = EGL_NO_CONFIG_KHR;
    }
    for (int version : {45, 33}) {
      const EGLint attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                version / 10,
                                EGL_CONTEXT_MINOR_VERSION,
                                version % 10,
                                EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                EGL_NONE};
      EGLContext c = eglCreateContext(d, config, EGL_NO_CONTEXT, attribs);
      if (c == EGL_NO_CONTEXT) continue;
      if (!eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) {
        why = "eglMakeCurrent without a surface failed (" + eglErrorString() + ")";
        eglDestroyContext(d, c);
        continue;
      }
      display_ = d;
      context_ = c;
      return true;
    }
    if (why.empty() || why.rfind("eglMakeCurrent", 0) != 0) {
      why = "eglCreateContext failed for core 4.5 and 3.3 (" + eglErrorString() + ")";
    }
    eglTerminate(d);
    return false;
  }

  EGLDisplay display_ = EGL_NO_DISPLAY;
  EGLContext context_ = EGL_NO_CONTEXT;
};

}  // namespace

std::unique_ptr<GlContext> createEglContext(const GlContextParams& params) {
  return std::make_unique<EglContext>(params);
}

}  // namespace lo::render_internal
