// The reflection probe (paper §5.1, Fig. 12: cube maps with the VDLs): the
// lit scene seen from its centre, drawn by the scene pass itself.

#include <glad/gl.h>
#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "core/error.h"
#include "render/context.h"
#include "render/gl_util.h"
#include "render/renderer_impl.h"

namespace lo {

using namespace render_internal;

namespace {

/// The direction (not unit) through the centre of texel (x, y) of an n x n
/// face of a GL cube map: the OpenGL specification's cube-face table, s
/// along x, t along y, both in [-1, 1].
glm::vec3 cubeTexelDirection(int face, int x, int y, int n) {
  const float s = 2.0f * (float(x) + 0.5f) / float(n) - 1.0f;
  const float t = 2.0f * (float(y) + 0.5f) / float(n) - 1.0f;
  switch (face) {
    case 0:
      return {1.0f, -t, -s};
    case 1:
      return {-1.0f, -t, s};
    case 2:
      return {s, 1.0f, t};
    case 3:
      return {s, -1.0f, -t};
    case 4:
      return {s, -t, 1.0f};
    default:
      return {-s, -t, -1.0f};
  }
}

}  // namespace

/// The six faces are 90-degree views from the scene's centre in GL's
/// cube-face orientations; the mips are box-filtered (a blur that grows with
/// roughness, not a GGX prefilter).
void Renderer::Impl::captureProbe(const RenderParams& rp) {
  const int size = params.probeSize;
  if (!probe.texture) {
    // Two cube maps alike: the faces are drawn into one while the other is
    // bound to the scene shader's probe unit. The software rasteriser
    // compiles a shader variant per set of bound texture and target formats
    // (seconds each for the scene shader): drawn into the render target's
    // format (RGBA32F) with the same textures bound as the frame after it,
    // the six faces compile the variants the frame then uses, instead of a
    // set of their own (docs/render.md, "The first frame").
    probe.levels = 1;
    while ((size >> probe.levels) > 0) ++probe.levels;
    for (GlTexture* t : {&probe.texture, &probe.spare}) {
      *t = GlTexture::create();
      glBindTexture(GL_TEXTURE_CUBE_MAP, t->get());
      for (int level = 0; level < probe.levels; ++level) {
        for (int f = 0; f < 6; ++f) {
          glTexImage2D(GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), level, GL_RGBA32F,
                       std::max(1, size >> level), std::max(1, size >> level), 0, GL_RGBA,
                       GL_FLOAT, nullptr);
        }
      }
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_CUBE_MAP, GL_TEXTURE_WRAP_R, GL_CLAMP_TO_EDGE);
    }
    glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
    probe.fbo = GlFramebuffer::create();
    probe.depth = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, probe.depth.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, size, size);
    checkGl("allocating the reflection probe");
  }
  GLint previous = 0;
  glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
  glBindFramebuffer(GL_FRAMEBUFFER, probe.fbo.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                            probe.depth.get());
  const Vec3 forward[kProbeFaces] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                     {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
  const Vec3 up[kProbeFaces] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1},
                                {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
  RenderParams face = rp;
  face.mode = RenderMode::Full;
  face.reflections = false;
  probe.capturing = true;
  for (int f = 0; f < kProbeFaces; ++f) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                           GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), probe.spare.get(), 0);
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
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X, 0, 0);
  std::swap(probe.texture, probe.spare);
  glBindTexture(GL_TEXTURE_CUBE_MAP, probe.texture.get());
  glGenerateMipmap(GL_TEXTURE_CUBE_MAP);
  projectProbeIrradiance();
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous));
  probe.valid = true;
  checkGl("capturing the reflection probe");
}

/// The probe's irradiance as SH terms (octree_layout.h's basis and bands, as
/// the octree's sh2 leaves hold theirs), from the mip level whose faces are
/// 16 texels wide (the base level of a smaller probe), read back: each
/// texel's radiance projected with its solid angle, (2/n)^2 / (1 + s^2 +
/// t^2)^(3/2), the sum scaled so that the texels cover 4 pi.
void Renderer::Impl::projectProbeIrradiance() {
  const int level = std::max(0, probe.levels - 5);
  const int n = std::max(1, params.probeSize >> level);
  std::vector<float> texels(size_t(n) * size_t(n) * 4);
  double sum[9][3] = {};
  double solidAngle = 0;
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  for (int f = 0; f < 6; ++f) {
    glGetTexImage(GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), level, GL_RGBA, GL_FLOAT,
                  texels.data());
    for (int y = 0; y < n; ++y) {
      for (int x = 0; x < n; ++x) {
        const glm::vec3 d = cubeTexelDirection(f, x, y, n);
        const double r2 = double(glm::dot(d, d));
        const double w = 4.0 / (double(n) * double(n) * r2 * std::sqrt(r2));
        const glm::vec3 u = glm::normalize(d);
        const float* radiance = &texels[(size_t(y) * size_t(n) + size_t(x)) * 4];
        for (uint32_t i = 0; i < 9; ++i) {
          const double yw = w * double(layout::loShBasis(i, u.x, u.y, u.z));
          for (int a = 0; a < 3; ++a) sum[i][a] += yw * double(radiance[a]);
        }
        solidAngle += w;
      }
    }
  }
  const double scale = 4.0 * double(kPi) / solidAngle;
  for (uint32_t i = 0; i < 9; ++i) {
    const double band = double(layout::loShCosineBand(i)) * scale;
    probe.irradiance[i] =
        glm::vec3(float(sum[i][0] * band), float(sum[i][1] * band), float(sum[i][2] * band));
  }
  checkGl("projecting the reflection probe's irradiance");
}

}  // namespace lo
