#include "render/atlas_gpu.h"

#include <glad/gl.h>

#include <string>

#include "core/error.h"
#include "render/context.h"
#include "render/gl_resources.h"
#include "render/gl_util.h"
#include "render/octree_textures.h"

namespace lo {

using namespace render_internal;

namespace {

/// One corner of a triangle as atlas_bake.vert reads it.
struct AtlasVertex {
  float texel[2];     ///< lightmap UV in texels of the page
  float position[3];  ///< world, relative to the octree's origin
  float normal[3];    ///< vertex normal, or zero
  int32_t triangle;
};

}  // namespace

struct GpuAtlasEvaluator::Impl {
  GlProgram program;
  GlVertexArray vao;
  GlBuffer vbo;
  GlFramebuffer fbo;
  GlRenderbuffer depth;
  GlRenderbuffer colour[3];  ///< irradiance, direction (RGBA32F), triangle (R32I)
  /// Per triangle, the side its texels hold (atlasSurfaceSides): a -1's
  /// corners go in the other order and its normals turned, so the shader's
  /// normal, the vertices' or the winding's, is the other side's.
  std::vector<int8_t> sides;
  OctreeTextures octree;
  const Scene* scene = nullptr;
  const LightmapUvs* uvs = nullptr;
  OctreeShadeParams shade;
  Vec3 origin{0, 0, 0};
  int width = 0, height = 0;

  void makeTarget() {
    GLint maxSize = 0;
    glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxSize);
    if (width > maxSize || height > maxSize) {
      throw InputError("atlas page of " + texelCount(width, height, 0) +
                       " texels exceeds GL_MAX_RENDERBUFFER_SIZE = " + std::to_string(maxSize) +
                       ": bake it with a smaller --atlas, or on the CPU");
    }
    fbo = GlFramebuffer::create();
    glBindFramebuffer(GL_FRAMEBUFFER, fbo.get());
    const GLenum formats[3] = {GL_RGBA32F, GL_RGBA32F, GL_R32I};
    for (int i = 0; i < 3; ++i) {
      colour[i] = GlRenderbuffer::create();
      glBindRenderbuffer(GL_RENDERBUFFER, colour[i].get());
      glRenderbufferStorage(GL_RENDERBUFFER, formats[i], width, height);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GLenum(GL_COLOR_ATTACHMENT0 + i), GL_RENDERBUFFER,
                                colour[i].get());
    }
    // Float depth: the squared distances compare exactly, as on the CPU.
    depth = GlRenderbuffer::create();
    glBindRenderbuffer(GL_RENDERBUFFER, depth.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT32F, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth.get());
    const GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    if (status != GL_FRAMEBUFFER_COMPLETE) {
      throw GlError("atlas framebuffer (" + texelCount(width, height, 0) +
                    ", RGBA32F x 2 + R32I + DEPTH32F) incomplete");
    }
    checkGl("creating the atlas framebuffer");
  }
};

GpuAtlasEvaluator::GpuAtlasEvaluator() : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.program = GlProgram(buildProgram({"atlas_bake.vert", "atlas_bake.geom", "atlas_bake.frag"}));
  r.vao = GlVertexArray::create();
  r.vbo = GlBuffer::create();
  glBindVertexArray(r.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, r.vbo.get());
  const GLsizei stride = sizeof(AtlasVertex);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(offsetof(AtlasVertex, texel)));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(offsetof(AtlasVertex, position)));
  glEnableVertexAttribArray(2);
  glVertexAttribPointer(2, 3, GL_FLOAT, GL_FALSE, stride,
                        reinterpret_cast<const void*>(offsetof(AtlasVertex, normal)));
  glEnableVertexAttribArray(3);
  glVertexAttribIPointer(3, 1, GL_INT, stride,
                         reinterpret_cast<const void*>(offsetof(AtlasVertex, triangle)));
  glBindVertexArray(0);
  checkGl("creating the atlas bake's vertex array");
}

GpuAtlasEvaluator::~GpuAtlasEvaluator() = default;

void GpuAtlasEvaluator::begin(const Scene& scene, const LightmapUvs& uvs, const GpuOctree& octree,
                              const OctreeShadeParams& shade) {
  Impl& r = *impl_;
  OctreeTextures::checkLimits(octree);
  r.octree.upload(octree);
  r.scene = &scene;
  r.uvs = &uvs;
  r.shade = shade;
  r.sides = atlasSurfaceSides(scene, octree, shade);
  r.origin = octree.origin;
  if (r.width != uvs.width || r.height != uvs.height || !r.fbo) {
    r.width = uvs.width;
    r.height = uvs.height;
    r.makeTarget();
  }
}

AtlasPageTexels GpuAtlasEvaluator::evaluatePage(int page, const std::vector<int32_t>& triangles) {
  Impl& r = *impl_;
  LO_CHECK(r.scene && r.uvs);
  const Scene& scene = *r.scene;
  const LightmapUvs& uvs = *r.uvs;
  (void)page;

  // Corners in the order given, positions relative to the octree's origin
  // (in double: exact near the scene, wherever it lies).
  std::vector<AtlasVertex> vertices(3 * triangles.size());
  for (size_t k = 0; k < triangles.size(); ++k) {
    const size_t t = size_t(triangles[k]);
    const bool back = t < r.sides.size() && r.sides[t] < 0;
    for (int c = 0; c < 3; ++c) {
      AtlasVertex& v = vertices[3 * k + size_t(back ? (3 - c) % 3 : c)];
      const uint32_t index = scene.indices[3 * t + size_t(c)];
      v.texel[0] = float(double(uvs.uv[6 * t + size_t(2 * c)]) * uvs.width);
      v.texel[1] = float(double(uvs.uv[6 * t + size_t(2 * c) + 1]) * uvs.height);
      const Vec3& p = scene.positions[index];
      for (int i = 0; i < 3; ++i) v.position[i] = float(double(p[i]) - double(r.origin[i]));
      const Vec3 n = scene.normals.empty() ? Vec3{0, 0, 0}
                                           : scene.normals[index] * (back ? -1.0f : 1.0f);
      for (int i = 0; i < 3; ++i) v.normal[i] = n[i];
      v.triangle = int32_t(t);
    }
  }

  glBindFramebuffer(GL_FRAMEBUFFER, r.fbo.get());
  const GLenum buffers[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
  glDrawBuffers(3, buffers);
  glViewport(0, 0, r.width, r.height);
  const float zero[4] = {0, 0, 0, 0};
  const GLint none[4] = {-1, -1, -1, -1};
  glClearBufferfv(GL_COLOR, 0, zero);
  glClearBufferfv(GL_COLOR, 1, zero);
  glClearBufferiv(GL_COLOR, 2, none);
  const float far = 1.0f;
  glClearBufferfv(GL_DEPTH, 0, &far);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glDepthMask(GL_TRUE);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);

  glUseProgram(r.program.get());
  auto loc = [&r](const char* name) { return glGetUniformLocation(r.program.get(), name); };
  glUniform2f(loc("uPageSize"), float(r.width), float(r.height));
  glUniform1f(loc("uVoxelSize"), r.octree.voxelSize);
  glUniform1i(loc("uDepth"), r.octree.depth);
  glUniform1f(loc("uNormalOffset"), r.shade.normalOffset);
  glUniform1i(loc("uInterpolation"), r.shade.interpolation ? 1 : 0);
  glUniform1i(loc("uMaxVdls"), r.shade.maxVdls);
  r.octree.bind(r.program.get(), 0, 1, 2);

  glBindVertexArray(r.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, r.vbo.get());
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(AtlasVertex)),
               vertices.empty() ? nullptr : vertices.data(), GL_STREAM_DRAW);
  if (!vertices.empty()) glDrawArrays(GL_TRIANGLES, 0, GLsizei(vertices.size()));
  glBindVertexArray(0);
  checkGl("drawing the triangles into the atlas");

  AtlasPageTexels out;
  out.irradiance = RgbImage(r.width, r.height);
  out.direction = RgbImage(r.width, r.height);
  out.triangle.assign(size_t(r.width) * size_t(r.height), -1);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, r.width, r.height, GL_RGB, GL_FLOAT, out.irradiance.rgb.data());
  glReadBuffer(GL_COLOR_ATTACHMENT1);
  glReadPixels(0, 0, r.width, r.height, GL_RGB, GL_FLOAT, out.direction.rgb.data());
  glReadBuffer(GL_COLOR_ATTACHMENT2);
  glReadPixels(0, 0, r.width, r.height, GL_RED_INTEGER, GL_INT, out.triangle.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGl("reading the atlas page back");
  return out;
}

}  // namespace lo
