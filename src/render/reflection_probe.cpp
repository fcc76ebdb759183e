// The reflection probe (paper §5.1, Fig. 12: cube maps with the VDLs): the
// lit scene seen from its centre, drawn by the scene pass itself.

#include <glad/gl.h>

#include "core/error.h"
#include "render/context.h"
#include "render/gl_util.h"
#include "render/renderer_impl.h"

namespace lo {

using namespace render_internal;

/// The six faces are 90-degree views from the scene's centre in GL's
/// cube-face orientations; the mips are box-filtered (a blur that grows with
/// roughness, not a GGX prefilter).
void Renderer::Impl::captureProbe(const RenderParams& rp) {
  const int size = params.probeSize;
  if (!probe.texture) {
    probe.texture = GlTexture::create();
    glBindTexture(GL_TEXTURE_CUBE_MAP, probe.texture.get());
    probe.levels = 1;
    while ((size >> probe.levels) > 0) ++probe.levels;
    for (int f = 0; f < 6; ++f) {
      glTexImage2D(GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), 0, GL_RGBA16F, size, size, 0,
                   GL_RGBA, GL_FLOAT, nullptr);
    }
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    probe.fbo = GlFramebuffer::create();
    probe.depth = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, probe.depth.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size, size);
    checkGl("allocating the reflection probe");
  }
  GLint previous = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
  glBindFramebuffer(GL_FRAMEBUFFER, probe.fbo.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER,
                            probe.depth.get());
  const Vec3 forward[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  const Vec3 up[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  RenderParams face = rp;
  face.mode = RenderMode::Full;
  face.reflections = false;
  probe.capturing = true;
  for (int f = 0; f < 6; ++f) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                           GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), probe.texture.get(), 0);
    GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &drawBuffer);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      probe.capturing = false;
      throw GlError("reflection probe framebuffer incomplete");
    }
    PinholeCamera camera;
    camera.eye = space.origin;  // render space (0, 0, 0): the scene's centre
    camera.forward = forward[f];
    camera.up = up[f];
    camera.yfov = 0.5f * kPi;
    camera.znear = 1e-3f * space.sceneSize;
    camera.zfar = 2.0f * space.sceneSize;
    draw(camera, face, size, size, 1.0f, false);
  }
  probe.capturing = false;
  glBindTexture(GL_TEXTURE_CUBE_MAP, probe.texture.get());
  glGenerateMipmap(GL_TEXTURE_CUBE_MAP);
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous));
  probe.valid = true;
  checkGl("capturing the reflection probe");
}

}  // namespace lo
