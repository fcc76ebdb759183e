// OSMesa back end: Mesa's software rasterizer (llvmpipe) with no display.

#include <glad/gl.h>
// glad's header defines __gl_h_, so osmesa.h takes glad's GL types.
#include <GL/osmesa.h>

#include <vector>

#include "render/context_internal.h"

namespace lo::render_internal {
namespace {

class OsMesaContext final : public GlContext {
 public:
  explicit OsMesaContext(const GlContextParams& params) : GlContext(GlBackend::OSMesa) {
    // Core profile 4.5 (llvmpipe in Mesa 22), else 3.3.
    for (int minorMajor : {45, 33}) {
      const int attribs[] = {OSMESA_FORMAT,
                             OSMESA_RGBA,
                             OSMESA_DEPTH_BITS,
                             24,
                             OSMESA_PROFILE,
                             OSMESA_CORE_PROFILE,
                             OSMESA_CONTEXT_MAJOR_VERSION,
                             minorMajor / 10,
                             OSMESA_CONTEXT_MINOR_VERSION,
                             minorMajor % 10,
                             0};
      context_ = OSMesaCreateContextAttribs(attribs, nullptr);
      if (context_) break;
    }
    if (!context_) {
      throw GlError("osmesa: OSMesaCreateContextAttribs failed for core 4.5 and 3.3");
    }
    makeCurrentImpl();
    initialize(params.debugOutput);
  }
  ~OsMesaContext() override { OSMesaDestroyContext(context_); }

 protected:
  void makeCurrentImpl() override {
    // The renderer draws into its own FBOs; OSMesa still wants a colour buffer
    // to make the context current, so a small one is enough.
    if (!OSMesaMakeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, kSize, kSize)) {
      throw GlError("osmesa: OSMesaMakeCurrent failed");
    }
  }
  ProcLoader procLoader() const override { return &loader; }

 private:
  static void (*loader(const char* name))() {
    return reinterpret_cast<void (*)()>(OSMesaGetProcAddress(name));
  }
  static constexpr int kSize = 16;
  OSMesaContext context_ = nullptr;
  std::vector<unsigned char> buffer_ = std::vector<unsigned char>(kSize * kSize * 4);
};

}  // namespace

std::unique_ptr<GlContext> createOsMesaContext(const GlContextParams& params) {
  return std::make_unique<OsMesaContext>(params);
}

}  // namespace lo::render_internal
