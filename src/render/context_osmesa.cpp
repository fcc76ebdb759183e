// OSMesa back end: Mesa's software rasterizer (llvmpipe) with no display.
//
// libOSMesa is opened on first use (dlopen), not linked: it brings LLVM,
// whose relocation alone makes ~50 MiB resident in every process that loads
// it, and the commands that never draw headless (bake, the ranks of a
// distributed bake) should not carry it.

#include <dlfcn.h>
#include <glad/gl.h>
// glad's header defines __gl_h_, so osmesa.h takes glad's GL types.
#include <GL/osmesa.h>

#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "core/printable.h"
#include "core/resources.h"
#include "render/context_internal.h"

namespace lo::render_internal {
namespace {

/// The OSMesa entry points the context uses, from the library opened once.
struct OsMesaApi {
  decltype(&OSMesaCreateContextAttribs) createContextAttribs = nullptr;
  decltype(&OSMesaMakeCurrent) makeCurrent = nullptr;
  decltype(&OSMesaGetProcAddress) getProcAddress = nullptr;
  decltype(&OSMesaDestroyContext) destroyContext = nullptr;
};

const OsMesaApi& osMesa() {
  static OsMesaApi api;
  static std::string error;
  static std::once_flag once;
  std::call_once(once, [] {
    void* lib = nullptr;
    for (const char* name : {"libOSMesa.so.8", "libOSMesa.so"}) {
      lib = dlopen(name, RTLD_NOW | RTLD_LOCAL);
      if (lib) break;
    }
    if (!lib) {
      const char* reason = dlerror();
      const std::string why = reason ? reason : "?";
      // A library that is there but cannot be mapped (ENOMEM: "failed to map
      // segment", under ulimit -v) is a memory limit, not a missing package;
      // thrown, not kept, so that a later context tries again.
      if (why.find("failed to map segment") != std::string::npos ||
          why.find("Cannot allocate memory") != std::string::npos) {
        throw GlError("osmesa: out of memory: cannot load libOSMesa.so.8 (" + why + "): " +
                      memoryShortfall());
      }
      error = "osmesa: cannot open libOSMesa.so.8 (" + why +
              "): install libosmesa6 (tools/setup.sh does)";
      return;
    }
    // Never closed: the GL functions glad loaded point into it.
    api.createContextAttribs = reinterpret_cast<decltype(api.createContextAttribs)>(
        dlsym(lib, "OSMesaCreateContextAttribs"));
    api.makeCurrent = reinterpret_cast<decltype(api.makeCurrent)>(dlsym(lib, "OSMesaMakeCurrent"));
    api.getProcAddress =
        reinterpret_cast<decltype(api.getProcAddress)>(dlsym(lib, "OSMesaGetProcAddress"));
    api.destroyContext =
        reinterpret_cast<decltype(api.destroyContext)>(dlsym(lib, "OSMesaDestroyContext"));
    if (!api.createContextAttribs || !api.makeCurrent || !api.getProcAddress ||
        !api.destroyContext) {
      api = OsMesaApi{};
      error = "osmesa: libOSMesa lacks OSMesaCreateContextAttribs (Mesa 11.2 or later needed)";
    }
  });
  if (!api.createContextAttribs) throw GlError(error);
  return api;
}

/// Mesa's OSMesa picks its rasterizer by GALLIUM_DRIVER: a name it lacks
/// made OSMesaCreateContextAttribs crash (H11-2-38). The software ones it
/// has are taken; another is refused, named, before Mesa sees it.
void checkGalliumDriver() {
  const char* driver = std::getenv("GALLIUM_DRIVER");
  if (!driver || !*driver) return;
  for (const char* known : {"llvmpipe", "softpipe", "swr", "zink"}) {
    if (std::strcmp(driver, known) == 0) return;
  }
  throw GlError("osmesa: GALLIUM_DRIVER='" + printable(driver) +
                "' names no software rasterizer OSMesa has (llvmpipe, softpipe): unset it "
                "or set it to llvmpipe");
}

class OsMesaContext final : public GlContext {
 public:
  explicit OsMesaContext(const GlContextParams& params) : GlContext(GlBackend::OSMesa) {
    checkGalliumDriver();
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
      context_ = osMesa().createContextAttribs(attribs, nullptr);
      if (context_) break;
    }
    if (!context_) {
      throw GlError("osmesa: OSMesaCreateContextAttribs failed for core 4.5 and 3.3");
    }
    makeCurrentImpl();
    initialize(params.debugOutput);
  }
  ~OsMesaContext() override { osMesa().destroyContext(context_); }

 protected:
  void makeCurrentImpl() override {
    // The renderer draws into its own FBOs; OSMesa still wants a colour buffer
    // to make the context current, so a small one is enough.
    if (!osMesa().makeCurrent(context_, buffer_.data(), GL_UNSIGNED_BYTE, kSize, kSize)) {
      throw GlError("osmesa: OSMesaMakeCurrent failed");
    }
  }
  ProcLoader procLoader() const override { return &loader; }

 private:
  static void (*loader(const char* name))() {
    return reinterpret_cast<void (*)()>(osMesa().getProcAddress(name));
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
