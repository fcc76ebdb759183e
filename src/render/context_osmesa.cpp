// OSMesa back end: Mesa's software rasterizer (llvmpipe) with no display.
//
// libOSMesa is opened on first use (dlopen), not linked: it brings LLVM,
// whose relocation alone makes ~50 MiB resident in every process that loads
// it, and the commands that never draw headless (bake, the ranks of a
// distributed bake) should not carry it.

#include <dlfcn.h>
#include <unistd.h>
#include <glad/gl.h>
// glad's header defines __gl_h_, so osmesa.h takes glad's GL types.
#include <GL/osmesa.h>

#include <algorithm>
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

/// OSMesa's attributes for a core profile of version major.minor (45: 4.5).
std::vector<int> contextAttributes(int majorMinor) {
  return {OSMESA_FORMAT,  OSMESA_RGBA,         OSMESA_DEPTH_BITS,           24,
          OSMESA_PROFILE, OSMESA_CORE_PROFILE, OSMESA_CONTEXT_MAJOR_VERSION, majorMinor / 10,
          OSMESA_CONTEXT_MINOR_VERSION, majorMinor % 10, 0};
}

/// Mesa's own settings the environment holds that change how it draws
/// (MESA_*, GALLIUM_*, LP_*, GALLIVM_*, as NAME=value), but for those that
/// only place its caches, set its log or pick one of the software
/// rasterizers this renderer is tested with.
std::vector<std::string> mesaSettings() {
  static const char* const kKept[] = {"GALLIUM_DRIVER=llvmpipe", "GALLIUM_DRIVER=softpipe",
                                      "MESA_SHADER_CACHE_", "MESA_GLSL_CACHE_", "MESA_DEBUG=",
                                      "MESA_LOG", "LP_NUM_THREADS="};
  std::vector<std::string> found;
  for (char** entry = environ; entry && *entry; ++entry) {
    const std::string text = *entry;
    bool mesa = false, kept = false;
    for (const char* prefix : {"MESA_", "GALLIUM_", "LP_", "GALLIVM_"}) {
      mesa = mesa || text.rfind(prefix, 0) == 0;
    }
    for (const char* prefix : kKept) kept = kept || text.rfind(prefix, 0) == 0;
    if (mesa && !kept) found.push_back(text);
  }
  return found;
}

/// Mesa's OSMesa crashed under some of its own settings, making its context
/// (GALLIUM_DRIVER=swr or zink, which this Mesa lacks,
/// MESA_GLSL_VERSION_OVERRIDE=100; H11-2-38, H12-2-1..19) or later, drawing
/// (LP_NATIVE_VECTOR_WIDTH=7, H13-2-22), ending the process, a Python
/// interpreter with it; GALLIUM_NOOP=1 drew an image of garbage (H13-2-5).
/// None of them is one a picture can be trusted under: refused, named.
void refuseMesaSettings() {
  const std::vector<std::string> settings = mesaSettings();
  if (settings.empty()) return;
  // The first three, each cut to 60 bytes: 5,000 of them made a line of
  // half a megabyte (H17-2-1).
  std::string named;
  for (size_t i = 0; i < std::min<size_t>(3, settings.size()); ++i) {
    named += (i ? ", " : "") + printableShort(settings[i]);
  }
  if (settings.size() > 3) named += " and " + formatCount(settings.size() - 3) + " more";
  throw GlError("osmesa: the environment changes how Mesa draws (" + named +
                "): unset it; lightoctree draws with Mesa's llvmpipe as it ships (GALLIUM_DRIVER "
                "may name llvmpipe or softpipe; Mesa's cache and log settings are kept)");
}

class OsMesaContext final : public GlContext {
 public:
  explicit OsMesaContext(const GlContextParams& params) : GlContext(GlBackend::OSMesa) {
    refuseMesaSettings();
    // Core profile 4.5 (llvmpipe in Mesa 22), else 3.3.
    for (int version : {45, 33}) {
      context_ = osMesa().createContextAttribs(contextAttributes(version).data(), nullptr);
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
