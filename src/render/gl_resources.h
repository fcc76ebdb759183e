#pragma once
// Internal to src/render: move-only owners of GL object names, so that an
// object is deleted exactly once, by whoever holds it last, also when a
// constructor throws half way. Need the context that made them current when
// they are destroyed (as any GL call does).

#include <glad/gl.h>

#include <utility>

namespace lo::render_internal {

/// Owns one GL object name of the kind `Kind` describes (create, destroy).
/// Zero is "no object": destroying it is a no-op, as in GL.
template <class Kind>
class GlHandle {
 public:
  GlHandle() = default;
  /// Takes ownership of `id` (from buildProgram, say).
  explicit GlHandle(GLuint id) : id_(id) {}
  /// A new object of this kind.
  static GlHandle create() { return GlHandle(Kind::create()); }
  ~GlHandle() { reset(); }
  GlHandle(GlHandle&& other) noexcept : id_(std::exchange(other.id_, 0u)) {}
  GlHandle& operator=(GlHandle&& other) noexcept {
    if (this != &other) {
      reset();
      id_ = std::exchange(other.id_, 0u);
    }
    return *this;
  }
  GlHandle(const GlHandle&) = delete;
  GlHandle& operator=(const GlHandle&) = delete;

  GLuint get() const { return id_; }
  explicit operator bool() const { return id_ != 0; }
  /// Hands the object over to the caller, who deletes it.
  GLuint release() { return std::exchange(id_, 0u); }
  /// Deletes the object now (if any); the handle holds none after.
  void reset() {
    if (id_) Kind::destroy(id_);
    id_ = 0;
  }

 private:
  GLuint id_ = 0;
};

namespace gl_kind {
struct Texture {
  static GLuint create() {
    GLuint id = 0;
    glGenTextures(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteTextures(1, &id); }
};
struct Buffer {
  static GLuint create() {
    GLuint id = 0;
    glGenBuffers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteBuffers(1, &id); }
};
struct Framebuffer {
  static GLuint create() {
    GLuint id = 0;
    glGenFramebuffers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteFramebuffers(1, &id); }
};
struct Renderbuffer {
  static GLuint create() {
    GLuint id = 0;
    glGenRenderbuffers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteRenderbuffers(1, &id); }
};
struct VertexArray {
  static GLuint create() {
    GLuint id = 0;
    glGenVertexArrays(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteVertexArrays(1, &id); }
};
struct Sampler {
  static GLuint create() {
    GLuint id = 0;
    glGenSamplers(1, &id);
    return id;
  }
  static void destroy(GLuint id) { glDeleteSamplers(1, &id); }
};
struct Program {
  static GLuint create() { return glCreateProgram(); }
  static void destroy(GLuint id) { glDeleteProgram(id); }
};
struct Shader {
  static void destroy(GLuint id) { glDeleteShader(id); }
};
}  // namespace gl_kind

using GlTexture = GlHandle<gl_kind::Texture>;
using GlBuffer = GlHandle<gl_kind::Buffer>;
using GlFramebuffer = GlHandle<gl_kind::Framebuffer>;
using GlRenderbuffer = GlHandle<gl_kind::Renderbuffer>;
using GlVertexArray = GlHandle<gl_kind::VertexArray>;
using GlSampler = GlHandle<gl_kind::Sampler>;
using GlProgram = GlHandle<gl_kind::Program>;
/// Shaders are made per stage (glCreateShader(stage)): wrap the name.
using GlShader = GlHandle<gl_kind::Shader>;

}  // namespace lo::render_internal
