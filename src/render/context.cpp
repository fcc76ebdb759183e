// GlContext: what every back end shares (entry-point loading, limits query).

#include "render/context.h"

#include <glad/gl.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <thread>

#include "core/error.h"
#include "core/resources.h"
#include "render/context_internal.h"

namespace lo {
namespace {

/// glad 2 keeps one global table of entry points. OSMesa and libEGL/libGL hand
/// out different function pointers, so the table must follow whichever back end
/// is current (tests create both in one process).
const GlContext* gLoadedFor = nullptr;

/// The process that made the first GL context, 0 before any. A GL driver
/// keeps process-wide state from its first context on (Mesa's llvmpipe: its
/// rasterising threads), which a child forked afterwards inherits without
/// the threads: a render there waited forever (issue 43, family 1:
/// `lightoctree.render` in an os.fork child after one in the parent).
std::atomic<pid_t> gFirstGlProcess{0};

/// Refuses GL in a child forked after its parent used GL; records the first
/// process that uses it.
void checkGlProcess() {
  const pid_t self = ::getpid();
  pid_t first = 0;
  if (gFirstGlProcess.compare_exchange_strong(first, self) || first == self) return;
  throw GlError("OpenGL was first used in process " + std::to_string(first) +
                " and this is process " + std::to_string(self) +
                ", forked from it afterwards: the GL driver's threads do not survive a fork, and "
                "a render here would wait forever. Render in processes started afresh (Python: "
                "multiprocessing's 'spawn' or 'forkserver' start method, "
                "multiprocessing.get_context('spawn')), or fork before the first render");
}

void GLAD_API_PTR debugCallback(GLenum, GLenum type, GLuint, GLenum severity, GLsizei,
                                const GLchar* message, const void*) {
  if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
  std::fprintf(stderr, "GL debug (type 0x%x): %s\n", type, message);
}

std::string glString(GLenum name) {
  const GLubyte* s = glGetString(name);
  return s ? reinterpret_cast<const char*>(s) : "";
}

}  // namespace

GlBackend parseGlBackend(const std::string& name) {
  if (name == "osmesa") return GlBackend::OSMesa;
  if (name == "egl") return GlBackend::Egl;
  if (name == "glfw") return GlBackend::Glfw;
  throw InputError("unknown GL back end '" + name + "' (expected osmesa, egl or glfw)");
}

std::string toString(GlBackend backend) {
  switch (backend) {
    case GlBackend::OSMesa:
      return "osmesa";
    case GlBackend::Egl:
      return "egl";
    case GlBackend::Glfw:
      return "glfw";
  }
  return "?";
}

std::string GlInfo::ToString() const {
  std::ostringstream os;
  os << "OpenGL " << major << "." << minor << " (" << version << ", " << renderer << ", " << vendor
     << "), max 3D texture " << max3DTextureSize << ", max 2D texture " << max2DTextureSize;
  return os.str();
}

void GlContext::makeCurrent() {
  checkGlProcess();
  makeCurrentImpl();
  if (gLoadedFor != this) {
    if (!gladLoadGL(reinterpret_cast<GLADloadfunc>(procLoader()))) {
      throw GlError(toString(backend_) + ": gladLoadGL failed");
    }
    gLoadedFor = this;
  }
}

void GlContext::initialize(bool debugOutput) {
  gLoadedFor = nullptr;  // a new context may reuse an old one's address
  int version = gladLoadGL(reinterpret_cast<GLADloadfunc>(procLoader()));
  if (!version) throw GlError(toString(backend_) + ": gladLoadGL failed (no GL entry points)");
  gLoadedFor = this;
  info_.major = GLAD_VERSION_MAJOR(version);
  info_.minor = GLAD_VERSION_MINOR(version);
  if (info_.major * 10 + info_.minor < 33) {
    throw GlError(toString(backend_) + ": OpenGL 3.3 core or later needed, got " +
                  std::to_string(info_.major) + "." + std::to_string(info_.minor));
  }
  info_.vendor = glString(GL_VENDOR);
  info_.renderer = glString(GL_RENDERER);
  info_.version = glString(GL_VERSION);
  glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &info_.max3DTextureSize);
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &info_.max2DTextureSize);
  if (debugOutput && GLAD_GL_KHR_debug) {
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(debugCallback, nullptr);
  }
}

namespace {

/// The address space llvmpipe maps beyond what the process maps when its
/// context is made, as it compiles and draws (its threads, the JIT's code,
/// the render targets): a 64 x 64 Cornell box rose from 241 MiB to 858 MiB
/// (VmPeak), 1024 x 768 to 906 MiB (the frame's own memory is checkRenderMemory's).
/// Under `ulimit -v` limits that leave less, Mesa failed at random: a
/// segmentation fault inside it, GL errors, a false refusal of the frame's
/// size (450 to 850 MB, H15-2-1). Refused before the context, naming the
/// limit: for every back end, `view`'s GLFW and EGL too (a GPU's driver maps
/// more; H16-2-1: `view` crashed at 630 to 700 MiB).
constexpr size_t kGlAddressSpaceBytes = size_t(640) << 20;

void requireAddressSpaceForGl(const std::string& backend) {
  const size_t room = addressSpaceRoomBytes();
  if (room >= kGlAddressSpaceBytes) return;
  throw GlError(backend + ": out of memory: the GL driver (llvmpipe, in software) maps about " +
                formatBytes(kGlAddressSpaceBytes) + " of address space as it draws, and " +
                memoryShortfall());
}

/// llvmpipe starts a thread per core to rasterise and waits for ever for one
/// it could not start: under `ulimit -u` 8 or 10 every render hung (H16-2-2).
/// Where a limit on threads holds, it is told to start no more than leave
/// room for the rest of the process (LP_NUM_THREADS, unless the user set
/// it; 0 rasterises on the drawing thread). Software GL only: a GPU's driver
/// reads no such variable.
void fitRasterThreadsToLimit() {
  if (std::getenv("LP_NUM_THREADS")) return;
  const long room = threadRoom();
  if (room < 0) return;
  constexpr long kKeep = 8;  // the process's own workers yet to start, and Mesa's queues
  const long cores = std::max(1L, long(std::thread::hardware_concurrency()));
  const long threads = std::clamp(room - kKeep, 0L, cores);
  ::setenv("LP_NUM_THREADS", std::to_string(threads).c_str(), 0);
}

}  // namespace

std::unique_ptr<GlContext> createGlContext(const GlContextParams& params) {
  checkGlProcess();
  requireAddressSpaceForGl(toString(params.backend));
  fitRasterThreadsToLimit();
  switch (params.backend) {
    case GlBackend::OSMesa:
      return render_internal::createOsMesaContext(params);
    case GlBackend::Egl:
      return render_internal::createEglContext(params);
    case GlBackend::Glfw:
      return render_internal::createGlfwContext(params);
  }
  throw InputError("unknown GL back end");
}

}  // namespace lo
