// A frame (paper §3.2, §4.2): depth pre-pass, then the scene pass in draw
// order: opaque, alpha-tested, blended back to front, transmissive over a
// copy of the opaque image.

#include <glad/gl.h>

#include <algorithm>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <limits>

#include "core/error.h"
#include "render/context.h"
#include "render/gl_util.h"
#include "render/renderer_impl.h"

namespace lo {

using namespace render_internal;

namespace {

/// Distance from p to the triangle abc: its closest point by the regions of
/// the triangle's corners and edges (Ericson, Real-Time Collision Detection,
/// 5.1.5).
float distanceToTriangle(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b,
                         const glm::vec3& c) {
  const glm::vec3 ab = b - a, ac = c - a, ap = p - a;
  const float d1 = glm::dot(ab, ap), d2 = glm::dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return glm::length(ap);
  const glm::vec3 bp = p - b;
  const float d3 = glm::dot(ab, bp), d4 = glm::dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return glm::length(bp);
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return glm::length(p - (a + ab * (d1 / (d1 - d3))));
  const glm::vec3 cp = p - c;
  const float d5 = glm::dot(ab, cp), d6 = glm::dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return glm::length(cp);
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return glm::length(p - (a + ac * (d2 / (d2 - d6))));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return glm::length(p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)))));
  }
  const float denom = va + vb + vc;
  if (!(std::fabs(denom) > 0)) return glm::length(ap);  // degenerate: a corner's distance
  return glm::length(p - (a + ab * (vb / denom) + ac * (vc / denom)));
}

/// The camera's near plane, raised where the 24-bit depth buffer needs it
/// (a 1 km scene seen with a glTF's znear of 1 cm z-fights: a surface 1 m
/// below another flickers through it): outside the scene's box, to 90% of
/// the eye's distance from the box (nothing lies nearer); and at least
/// 1e-4 of the far plane (depth steps under 1e-3 of the distance to its end).
/// But never past 90% of the distance to the nearest triangle of `sample`
/// (nor below 1e-6 of the far plane): a room on a ground 10^4 units wide
/// lay nearer than 1e-4 of the far plane, and every pixel was black
/// (H16-4-1). An authored near plane at or beyond the far one would clip
/// the whole scene, which the tracers (that have none) draw: left out (the
/// scene loader warns of it).
float nearPlane(const PinholeCamera& camera, const RenderSpace& space, float zfar,
                const std::vector<glm::vec3>& sample) {
  const Vec3 eye = space.toRender(camera.eye);
  const Bounds3& box = space.bounds;
  float outside = 0;
  for (int a = 0; a < 3; ++a) {
    const float d = std::max({box.lower[a] - eye[a], eye[a] - box.upper[a], 0.0f});
    outside += d * d;
  }
  const float authored = camera.znear > 0 && camera.znear < zfar ? camera.znear : 0.01f;
  float znear = std::max({authored, 0.9f * std::sqrt(outside), 1e-4f * zfar});
  const glm::vec3 p(eye.x, eye.y, eye.z);
  float nearest = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i + 2 < sample.size(); i += 3) {
    nearest = std::min(nearest, distanceToTriangle(p, sample[i], sample[i + 1], sample[i + 2]));
  }
  if (nearest < std::numeric_limits<float>::infinity()) {
    znear = std::min(znear, std::max(0.9f * nearest, 1e-6f * zfar));
  }
  return std::min(znear, 0.5f * zfar);
}

glm::vec3 toGlm(const Vec3& v) { return {v.x, v.y, v.z}; }

/// uMode of the scene shader for a render mode.
int shaderMode(RenderMode mode) {
  switch (mode) {
    case RenderMode::Full:
      return shader::LO_MODE_FULL;
    case RenderMode::Direct:
      return shader::LO_MODE_DIRECT;
    case RenderMode::Indirect:
      return shader::LO_MODE_INDIRECT;
    case RenderMode::Voxels:
      return shader::LO_MODE_VOXELS;
  }
  return shader::LO_MODE_FULL;
}

bool drawsDirectLight(RenderMode mode) {
  return mode == RenderMode::Full || mode == RenderMode::Direct;
}

}  // namespace

void Renderer::Impl::ensureTarget(int width, int height) {
  if (targetFbo && width == targetWidth && height == targetHeight) return;
  if (!targetFbo) {
    targetFbo = GlFramebuffer::create();
    targetColor = GlTexture::create();
    targetDepth = GlRenderbuffer::create();
  }
  glBindTexture(GL_TEXTURE_2D, targetColor.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glBindRenderbuffer(GL_RENDERBUFFER, targetDepth.get());
  // With a stencil: the scene pass shades each pixel once (drawRanges).
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH24_STENCIL8, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, targetFbo.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, targetColor.get(), 0);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_STENCIL_ATTACHMENT, GL_RENDERBUFFER,
                            targetDepth.get());
  GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &drawBuffer);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw GlError("render target framebuffer (RGBA32F " + texelCount(width, height, 0) +
                  ") incomplete");
  }
  targetWidth = width;
  targetHeight = height;
}

/// Makes behindTexture (float for the offscreen RGBA32F target, 8-bit for a
/// window's back buffer) hold at least width x height texels, and binds it to
/// its unit. It only grows, and never to a power of two on either side: the
/// software rasteriser compiles a shader variant per set of bound texture
/// states, whether a side is a power of two among them, so the reflection
/// probe's 128-texel faces and a 320 x 240 frame, both drawn with it bound
/// (from the first draw: before, nothing was bound until the first
/// transmissive surface), share their variants.
void Renderer::Impl::ensureBehind(int width, int height, bool floatTarget) {
  GLint maxSide = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSide);
  // A side at the driver's largest stays as it is (a power of two then).
  auto notPowerOfTwo = [maxSide](int n) { return (n & (n - 1)) == 0 && n < maxSide ? n + 1 : n; };
  if (!behindTexture || behindWidth < width || behindHeight < height ||
      behindFloat != floatTarget) {
    if (!behindTexture) behindTexture = GlTexture::create();
    behindWidth = notPowerOfTwo(std::max(width, behindWidth));
    behindHeight = notPowerOfTwo(std::max(height, behindHeight));
    glBindTexture(GL_TEXTURE_2D, behindTexture.get());
    glTexImage2D(GL_TEXTURE_2D, 0, floatTarget ? GL_RGBA32F : GL_RGBA8, behindWidth, behindHeight,
                 0, GL_RGBA, floatTarget ? GL_FLOAT : GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    behindFloat = floatTarget;
  }
  glActiveTexture(GL_TEXTURE6);
  glBindTexture(GL_TEXTURE_2D, behindTexture.get());
  glActiveTexture(GL_TEXTURE0);
  if (volumes) ensureVolumeBacks();
}

void Renderer::Impl::ensureVolumeBacks() {
  VolumeBacks& b = volumeBacks;
  if (!b.program) {
    b.program = GlProgram(buildProgram({"render_scene.vert", "render_volume_back.frag"}));
  }
  if (!b.fbo || b.width != behindWidth || b.height != behindHeight) {
    if (!b.fbo) {
      b.fbo = GlFramebuffer::create();
      b.opaqueDepth = GlTexture::create();
      b.faces = GlTexture::create();
      b.depth = GlRenderbuffer::create();
    }
    b.width = behindWidth;
    b.height = behindHeight;
    glBindTexture(GL_TEXTURE_2D, b.opaqueDepth.get());
    glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, b.width, b.height, 0, GL_DEPTH_COMPONENT,
                 GL_UNSIGNED_INT, nullptr);
    for (const GlTexture* t : {&b.opaqueDepth, &b.faces}) {
      glBindTexture(GL_TEXTURE_2D, t->get());
      if (t != &b.opaqueDepth) {
        glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, b.width, b.height, 0, GL_RGBA, GL_FLOAT, nullptr);
      }
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    glBindRenderbuffer(GL_RENDERBUFFER, b.depth.get());
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, b.width, b.height);
    GLint bound = 0;
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
    glBindFramebuffer(GL_FRAMEBUFFER, b.fbo.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, b.faces.get(), 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, b.depth.get());
    const GLenum buffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &buffer);
    const bool complete = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glBindFramebuffer(GL_FRAMEBUFFER, GLuint(bound));
    if (!complete) throw GlError("the volumes' back-face framebuffer is incomplete");
  }
  glActiveTexture(GL_TEXTURE14);
  glBindTexture(GL_TEXTURE_2D, b.opaqueDepth.get());
  glActiveTexture(GL_TEXTURE15);
  glBindTexture(GL_TEXTURE_2D, b.faces.get());
  glActiveTexture(GL_TEXTURE0);
  checkGl("making the volumes' back-face textures");
}

void Renderer::Impl::drawVolumeBacks(int width, int height, const glm::mat4& viewProj,
                                     const glm::vec3& eye) {
  VolumeBacks& b = volumeBacks;
  GLint bound = 0, program = 0;
  glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &bound);
  glGetIntegerv(GL_CURRENT_PROGRAM, &program);
  // The opaque depth, for the refracted ray's march, into the texture on
  // its unit (a window's depth buffer may not copy into a texture: the
  // march then falls back).
  glActiveTexture(GL_TEXTURE14);
  glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width, height);
  b.depthCopied = glGetError() == GL_NO_ERROR;
  glActiveTexture(GL_TEXTURE0);
  glBindFramebuffer(GL_FRAMEBUFFER, b.fbo.get());
  glDepthMask(GL_TRUE);  // before the clear, which it masks
  glDepthFunc(GL_LESS);
  glClearColor(0, 0, 0, 0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glUseProgram(b.program.get());
  glUniformMatrix4fv(glGetUniformLocation(b.program.get(), "uViewProj"), 1, GL_FALSE,
                     glm::value_ptr(viewProj));
  glUniform3fv(glGetUniformLocation(b.program.get(), "uEye"), 1, glm::value_ptr(eye));
  geometry.drawVolumes();
  glBindFramebuffer(GL_FRAMEBUFFER, GLuint(bound));
  glUseProgram(GLuint(program));
  checkGl("drawing the volumes' back faces");
}

/// Copies the bound framebuffer's colour (width x height) into the corner
/// of behindTexture.
void Renderer::Impl::copyBehind(int width, int height, bool floatTarget) {
  ensureBehind(width, height, floatTarget);
  glBindTexture(GL_TEXTURE_2D, behindTexture.get());
  glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width, height);
  checkGl("copying the opaque image for transmissive surfaces");
}

GLuint Renderer::Impl::buildSceneProgram(std::vector<std::string> defines) {
  if (volumes) defines.push_back("LO_VOLUMES");
  auto withLightBlock = [](GLuint program) {
    const GLuint block = glGetUniformBlockIndex(program, "LightBlock");
    if (block != GL_INVALID_INDEX) glUniformBlockBinding(program, block, 0);
    return program;
  };
  GlProgram twin(withLightBlock(buildProgram({"render_scene.vert", "render_scene.frag"}, defines)));
  defines.push_back("LO_ALPHA_CUT");
  const GLuint program =
      withLightBlock(buildProgram({"render_scene.vert", "render_scene.frag"}, defines));
  uncutTwins[program] = std::move(twin);
  return program;
}

GLuint Renderer::Impl::uncut(GLuint program) const {
  return program ? uncutTwins.at(program).get() : 0;
}

/// The scene program for a frame: with or without the direct light, with
/// the octree's lookup or the atlas's (built on first use).
GLuint Renderer::Impl::sceneProgramFor(const RenderParams& rp, bool withDirect) {
  const bool atlasProgram = rp.lighting == Lighting::Atlas && !probe.capturing &&
                            rp.mode != RenderMode::Voxels && atlasVbo;
  if (atlasProgram && !sceneAtlasProgram) {
    sceneAtlasProgram = GlProgram(buildSceneProgram({"LO_DIRECT_LIGHT", "LO_ATLAS_LIGHTING"}));
    sceneIndirectAtlasProgram =
        GlProgram(buildSceneProgram({"LO_ATLAS_LIGHTING"}));
  }
  const GlProgram& p = atlasProgram ? (withDirect ? sceneAtlasProgram : sceneIndirectAtlasProgram)
                                    : (withDirect ? sceneProgram : sceneIndirectProgram);
  return p.get();
}

/// The uniforms and textures of the scene program `p` (in use) that hold
/// for the whole frame.
void Renderer::Impl::setFrameUniforms(GLuint p, const PinholeCamera& camera, const RenderParams& rp,
                                      const glm::mat4& viewProj, bool reflect, float exposureScale,
                                      bool encodeSrgb) {
  auto loc = [p](const char* name) { return glGetUniformLocation(p, name); };
  const Vec3 eyeRender = space.toRender(camera.eye);
  const Bounds3& bounds = space.bounds;
  glUniformMatrix4fv(loc("uViewProj"), 1, GL_FALSE, glm::value_ptr(viewProj));
  glUniform3f(loc("uOctreeOrigin"), octreeOrigin.x, octreeOrigin.y, octreeOrigin.z);
  glUniform1f(loc("uVoxelSize"), voxelSize);
  glUniform1i(loc("uDepth"), depth);
  glUniform3f(loc("uEye"), eyeRender.x, eyeRender.y, eyeRender.z);
  glUniform1i(loc("uMode"), shaderMode(rp.mode));
  const glm::vec3 forward = glm::normalize(toGlm(camera.forward));
  glUniform3f(loc("uViewForward"), forward.x, forward.y, forward.z);
  glUniform4fv(loc("uCascadeFar"), 1, lights.cascadeFar);
  glUniform4fv(loc("uCascadeTexel"), 1, lights.cascadeTexel);
  glUniform4fv(loc("uCascadeDepth"), 1, lights.cascadeDepth);
  const bool atlas = rp.lighting == Lighting::Atlas && !probe.capturing;
  // The probe leaves out emitters that the direct pass draws as lights:
  // their reflection comes from the lights' specular term already.
  glUniform1f(
      loc("uEmissionScale"),
      probe.capturing && (lights.areaLightCount > 0 || lights.emitterLights > 0) ? 0.0f : 1.0f);
  glUniform1i(loc("uAtlas"), atlas ? 1 : 0);
  glUniform1i(loc("uAtlasIrradiance"), 12);
  glUniform1i(loc("uAtlasDirection"), 13);
  glActiveTexture(GL_TEXTURE12);
  glBindTexture(GL_TEXTURE_2D_ARRAY, atlas ? atlasIrradiance.get() : 0);
  glActiveTexture(GL_TEXTURE13);
  glBindTexture(GL_TEXTURE_2D_ARRAY, atlas ? atlasDirection.get() : 0);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(loc("uHasProbe"), reflect ? 1 : 0);
  glUniform1i(loc("uProbe"), 11);
  glUniform3f(loc("uProbeBoxMin"), bounds.lower.x, bounds.lower.y, bounds.lower.z);
  glUniform3f(loc("uProbeBoxMax"), bounds.upper.x, bounds.upper.y, bounds.upper.z);
  glUniform1f(loc("uProbeMaxLod"), float(probe.levels - 1));
  glUniform3fv(loc("uProbeIrradiance"), 9, glm::value_ptr(probe.irradiance[0]));
  glActiveTexture(GL_TEXTURE11);
  // Bound whenever it exists, read only where uHasProbe says: the probe's
  // capture draws with the same textures bound as the frames after it
  // (one set of shader variants on the software rasteriser).
  glBindTexture(GL_TEXTURE_CUBE_MAP, probe.texture ? probe.texture.get() : 0);
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(loc("uInterpolation"), rp.interpolation ? 1 : 0);
  glUniform1i(loc("uSpecular"), rp.specular ? 1 : 0);
  glUniform1i(loc("uMaxVdls"), rp.maxVdls);
  glUniform1f(loc("uNormalOffset"), rp.normalOffset);
  glUniform1f(loc("uExposureScale"), exposureScale);
  glUniform1i(loc("uEncodeSrgb"), encodeSrgb ? 1 : 0);
  octreeTextures.bind(p, 0, 1, 3);
  glUniform1i(loc("uShadowMaps"), 2);
  glActiveTexture(GL_TEXTURE2);
  glBindTexture(GL_TEXTURE_2D_ARRAY, lights.shadowTexture.get());
  glActiveTexture(GL_TEXTURE0);
  glUniform1i(loc("uBaseColorTexture"), 4);
  glUniform1i(loc("uShadowDepths"), 5);
  glActiveTexture(GL_TEXTURE5);
  glBindTexture(GL_TEXTURE_2D_ARRAY, lights.shadowTexture.get());
  glBindSampler(5, lights.depthSampler.get());
  glActiveTexture(GL_TEXTURE0);
  glBindBufferBase(GL_UNIFORM_BUFFER, 0, lights.ubo.get());
  glUniform1i(loc("uNormalTexture"), 7);
  glUniform1i(loc("uMetallicRoughnessTexture"), 8);
  glUniform1i(loc("uOcclusionTexture"), 9);
  glUniform1i(loc("uBehind"), 6);
  glUniform1i(loc("uOpaqueDepth"), 14);
  glUniform1i(loc("uBackFaces"), 15);
  glUniform1i(loc("uHasVolumeBacks"), 0);  // drawVolumeBacks sets it
  glUniform1i(loc("uHasOpaqueDepth"), 0);
  glUniform1i(loc("uEmissiveTexture"), 10);
  glUniform1f(loc("uTransmission"), 0.0f);
  glUniform2f(loc("uDielectric"), 0.04f, 1.0f);
}

/// The scene's ranges in draw order with the program `p` in use: each with
/// its material's textures and uniforms; blended ones sorted back to front
/// from `eye` without depth writes; transmissive ones over a copy of what
/// was drawn before them.
void Renderer::Impl::drawRanges(int width, int height, bool encodeSrgb, const glm::vec3& eye,
                                const glm::mat4& viewProj, GLuint staticProgram,
                                GLuint movingProgram, bool oncePerPixel) {
  glBindVertexArray(geometry.vao.get());
  GLuint p = 0;
  GLint hasTexture = -1, hasNormal = -1, normalScale = -1, hasMr = -1, hasOcclusion = -1,
        occlusionStrength = -1, transmission = -1, hasEmissive = -1, alphaMode = -1,
        alphaCutoff = -1, thickness = -1, ior = -1, dielectric = -1, unlit = -1,
        emitsBothSides = -1;
  // The program of a range, in use with its octree's textures bound.
  auto use = [&](GLuint program, bool movingLight) {
    if (program == p) return;
    p = program;
    glUseProgram(p);
    if (movingLight) {
      volumeTextures.bind(p, 0, 1, 3);
    } else {
      octreeTextures.bind(p, 0, 1, 3);
    }
    auto loc = [p](const char* name) { return glGetUniformLocation(p, name); };
    hasTexture = loc("uHasBaseColorTexture");
    hasNormal = loc("uHasNormalTexture");
    normalScale = loc("uNormalScale");
    hasMr = loc("uHasMetallicRoughnessTexture");
    hasOcclusion = loc("uHasOcclusionTexture");
    occlusionStrength = loc("uOcclusionStrength");
    transmission = loc("uTransmission");
    hasEmissive = loc("uHasEmissiveTexture");
    alphaMode = loc("uAlphaMode");
    alphaCutoff = loc("uAlphaCutoff");
    thickness = loc("uThickness");
    ior = loc("uIor");
    dielectric = loc("uDielectric");
    unlit = loc("uUnlit");
    emitsBothSides = loc("uEmitsBothSides");
  };
  // glTF: single-sided materials are culled from behind (counter-clockwise
  // winding in front, as the loader keeps it).
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  bool copied = false, blending = false;
  for (size_t i = 0; i < geometry.ranges.size(); ++i) {
    const DrawRange& range = geometry.ranges[i];
    // Masked materials with their cut, the others without (uncutTwins).
    const bool movingLight = range.moving && movingProgram;
    const GLuint program = movingLight ? movingProgram : staticProgram;
    use(range.alphaMode == shader::LO_ALPHA_MASK ? program : uncut(program), movingLight);
    const bool blended = geometry.rangeCategory[i] == kBlended;
    // Surfaces at one depth (coplanar copies) shaded every fragment: 3,000
    // coplanar quads took 140 s for a 128 x 96 frame. The first opaque
    // fragment at the pre-pass's depth marks its pixel and the others are
    // not shaded. Masked surfaces (decals on a wall's plane), blended and
    // transmissive ones draw over what is drawn, unmarked, as before.
    if (oncePerPixel) {
      if (geometry.rangeCategory[i] == kSolid) {
        glEnable(GL_STENCIL_TEST);
      } else {
        glDisable(GL_STENCIL_TEST);
      }
    }
    if (blended && !blending) {
      // Over the opaque scene, back to front, without depth writes.
      geometry.sortBlended(eye);
      glEnable(GL_BLEND);
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ZERO, GL_ONE);
      glDepthMask(GL_FALSE);
      blending = true;
    } else if (!blended && blending) {
      glDisable(GL_BLEND);
      blending = false;
    }
    if (range.transmission > 0 && !copied) {
      // The opaque scene as drawn so far, for the surfaces in front of it
      // to show (thin-walled transmission: seen straight through).
      copyBehind(width, height, !encodeSrgb);
      // Thick glass: the opaque depth and the volumes' back faces, where
      // the refracted rays leave them (render_scene.frag).
      if (volumes) {
        drawVolumeBacks(width, height, viewProj, eye);
        for (GLuint program :
             {staticProgram, uncut(staticProgram), movingProgram, uncut(movingProgram)}) {
          if (!program) continue;
          glUseProgram(program);
          glUniform1i(glGetUniformLocation(program, "uHasVolumeBacks"), 1);
          glUniform1i(glGetUniformLocation(program, "uHasOpaqueDepth"),
                      volumeBacks.depthCopied ? 1 : 0);
        }
        glUseProgram(p);
      }
      glActiveTexture(GL_TEXTURE6);
      glBindTexture(GL_TEXTURE_2D, behindTexture.get());
      glDepthMask(GL_TRUE);  // the nearest transmissive surface wins
      glDepthFunc(GL_LESS);
      copied = true;
    }
    auto bind = [this](GLenum unit, int texture) {
      glActiveTexture(unit);
      glBindTexture(GL_TEXTURE_2D, geometry.texture(texture));
    };
    bind(GL_TEXTURE4, range.texture);
    bind(GL_TEXTURE7, range.normalTexture);
    bind(GL_TEXTURE8, range.metallicRoughnessTexture);
    bind(GL_TEXTURE9, range.occlusionTexture);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(hasMr, range.metallicRoughnessTexture >= 0 ? 1 : 0);
    glUniform1i(hasOcclusion, range.occlusionTexture >= 0 ? 1 : 0);
    glUniform1f(occlusionStrength, range.occlusionStrength);
    glUniform1i(hasTexture, range.texture >= 0 ? 1 : 0);
    glUniform1i(hasNormal, range.normalTexture >= 0 ? 1 : 0);
    glUniform1f(normalScale, range.normalScale);
    glUniform1f(transmission, range.transmission);
    glUniform1f(thickness, range.thickness);
    glUniform1f(ior, range.ior);
    glUniform2f(dielectric, range.dielectricF0, range.specular);
    glUniform1i(unlit, range.unlit ? 1 : 0);
    glUniform1i(emitsBothSides, range.emitsBothSides ? 1 : 0);
    bind(GL_TEXTURE10, range.emissiveTexture);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(hasEmissive, range.emissiveTexture >= 0 ? 1 : 0);
    glUniform1i(alphaMode, range.alphaMode);
    glUniform1f(alphaCutoff, range.alphaCutoff);
    if (range.doubleSided) {
      glDisable(GL_CULL_FACE);
    } else {
      glEnable(GL_CULL_FACE);
    }
    if (blended) {
      glDrawElements(GL_TRIANGLES, range.count, GL_UNSIGNED_INT,
                     reinterpret_cast<const void*>(size_t(range.first - geometry.blendFirst) * 4));
    } else {
      glDrawArrays(GL_TRIANGLES, range.first, range.count);
    }
  }
  if (blending) glDisable(GL_BLEND);
  glDisable(GL_STENCIL_TEST);
}

void Renderer::Impl::draw(const PinholeCamera& camera, const RenderParams& rp, int width,
                          int height, float exposureScale, bool encodeSrgb) {
  if (width < 1 || height < 1) throw InputError("render: image size must be at least 1 x 1");
  if (rp.maxVdls < 1 || rp.maxVdls > kMaxVdls) {
    throw InputError("render: VDLs per voxel must be 1.." + std::to_string(kMaxVdls) + ", got " +
                     std::to_string(rp.maxVdls));
  }
  if (rp.lighting == Lighting::Atlas && !atlasVbo) {
    throw InputError(
        "render: lighting 'atlas' needs an atlas (Renderer::setAtlas, or "
        "`render --lighting atlas`, which bakes one)");
  }
  // The probe shows the lit scene: captured before the first frame that
  // reflects it (it draws six frames of its own through this function).
  const bool reflect = rp.reflections && probe.wanted && !probe.capturing &&
                       (rp.mode == RenderMode::Full || rp.mode == RenderMode::Indirect);
  if (reflect && !probe.valid) captureProbe(rp);
  const glm::vec3 eye = toGlm(space.toRender(camera.eye));
  // Nothing of the scene lies farther than its box: an authored far plane
  // beyond it only spends the depth buffer's precision (a zfar of 1e30
  // raised the near plane past the whole scene).
  const float farthest = glm::length(eye - toGlm(space.bounds.center())) + space.sceneSize + 1e-3f;
  const float zfar = camera.zfar > 0 ? std::min(camera.zfar, farthest) : farthest;
  const float znear = nearPlane(camera, space, zfar, nearSample);
  const float aspect = float(width) / float(height);
  // The pixel's sample point moved by pixelOffset: the image shifted the
  // other way, by a translation after the projection.
  const glm::vec2 offset = probe.capturing ? glm::vec2(0.0f) : pixelOffset;
  const glm::vec3 shiftNdc(-2.0f * offset.x / float(width), -2.0f * offset.y / float(height), 0.0f);
  const glm::mat4 shift = glm::translate(glm::mat4(1.0f), shiftNdc);
  const glm::mat4 viewProj = shift * glm::perspective(camera.yfov, aspect, znear, zfar) *
                             glm::lookAt(eye, eye + toGlm(camera.forward), toGlm(camera.up));
  const bool withDirect = drawsDirectLight(rp.mode);
  if (withDirect) {
    lights.fitCascades(
        space, eye, glm::normalize(toGlm(camera.forward)), toGlm(camera.up), camera.yfov, aspect,
        znear, zfar, probe.capturing ? kProbeFaces : 1, geometry.vao.get(),
        [this](GLuint program, bool shadows) { geometry.drawDepthOnly(program, shadows); });
  }

  glViewport(0, 0, width, height);
  glClearColor(0, 0, 0, 1);
  glClearStencil(0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT | GL_STENCIL_BUFFER_BIT);
  if (skyProgram) {
    // The background: the sky above the horizon, black below.
    const float tanHalf = std::tan(0.5f * camera.yfov);
    const glm::vec3 forward = glm::normalize(toGlm(camera.forward));
    const glm::vec3 up = glm::normalize(toGlm(camera.up));
    const glm::vec3 right = glm::normalize(glm::cross(forward, up)) * (tanHalf * aspect);
    const GLuint program = skyProgram.get();
    glUseProgram(program);
    const Vec3 radiance = sky * exposureScale;
    glUniform3f(glGetUniformLocation(program, "uSky"), radiance.x, radiance.y, radiance.z);
    glUniform3fv(glGetUniformLocation(program, "uForward"), 1, glm::value_ptr(forward));
    glUniform3fv(glGetUniformLocation(program, "uRight"), 1, glm::value_ptr(right));
    const glm::vec3 upScaled = up * tanHalf;
    glUniform3fv(glGetUniformLocation(program, "uUp"), 1, glm::value_ptr(upScaled));
    glUniform2f(glGetUniformLocation(program, "uViewport"), float(width), float(height));
    glUniform2fv(glGetUniformLocation(program, "uPixelOffset"), 1, glm::value_ptr(offset));
    glUniform1i(glGetUniformLocation(program, "uEncodeSrgb"), encodeSrgb ? 1 : 0);
    glUniform1i(glGetUniformLocation(program, "uHasSkyImage"), skyImage ? 1 : 0);
    glUniform1i(glGetUniformLocation(program, "uSkyImage"), 11);
    glActiveTexture(GL_TEXTURE11);
    glBindTexture(GL_TEXTURE_2D, skyImage ? skyImage.get() : 0);
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glBindVertexArray(geometry.emptyVao.get());
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDepthMask(GL_TRUE);
  }
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  // Depth pre-pass: the scene shader then shades each pixel once, not once
  // per overlapping surface. It pays where shading is dear (shadow lookups
  // of the direct pass, 8-voxel interpolation); for the cheap modes the
  // second geometry pass costs more than the overdraw it saves (measured,
  // docs/results/render.md), so they draw with a plain depth test.
  const bool prePass = rp.interpolation || withDirect;
  glDepthFunc(GL_LESS);
  if (prePass) {
    glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glUseProgram(depthProgram.get());
    glUniformMatrix4fv(glGetUniformLocation(depthProgram.get(), "uViewProj"), 1, GL_FALSE,
                       glm::value_ptr(viewProj));
    glBindVertexArray(geometry.vao.get());
    geometry.drawDepthOnly(depthProgram.get(), false);
    glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthFunc(GL_LEQUAL);
    glDepthMask(GL_FALSE);
  }
  // Each program with its twin without the alpha cut (uncutTwins), the
  // program last in use.
  const GLuint p = sceneProgramFor(rp, withDirect);
  for (const GLuint variant : {uncut(p), p}) {
    glUseProgram(variant);
    setFrameUniforms(variant, camera, rp, viewProj, reflect, exposureScale, encodeSrgb);
  }
  // The opaque image's copy for transmissive surfaces: bound from the first
  // draw, its share that this frame fills.
  ensureBehind(width, height, !encodeSrgb);
  const glm::vec2 behindScale(float(width) / float(behindWidth),
                              float(height) / float(behindHeight));
  for (const GLuint variant : {uncut(p), p}) {
    glUseProgram(variant);
    glUniform2fv(glGetUniformLocation(variant, "uBehindScale"), 1, glm::value_ptr(behindScale));
  }
  // Added objects: the free-space light's program, its frame uniforms, and
  // the free-space octree's frame in place of the surfaces'.
  GLuint moving = 0;
  if (hasVolume && hasMovingRanges && rp.mode != RenderMode::Voxels &&
      rp.lighting == Lighting::Octree) {
    moving = withDirect ? sceneMovingProgram.get() : sceneIndirectMovingProgram.get();
    for (const GLuint variant : {uncut(moving), moving}) {
      glUseProgram(variant);
      setFrameUniforms(variant, camera, rp, viewProj, reflect, exposureScale, encodeSrgb);
      glUniform2fv(glGetUniformLocation(variant, "uBehindScale"), 1, glm::value_ptr(behindScale));
      glUniform3f(glGetUniformLocation(variant, "uOctreeOrigin"), volumeOrigin.x, volumeOrigin.y,
                  volumeOrigin.z);
      glUniform1f(glGetUniformLocation(variant, "uVoxelSize"), volumeTextures.voxelSize);
      glUniform1i(glGetUniformLocation(variant, "uDepth"), volumeTextures.depth);
    }
  }
  glStencilFunc(GL_EQUAL, 0, 0xff);
  glStencilOp(GL_KEEP, GL_KEEP, GL_INCR);
  drawRanges(width, height, encodeSrgb, eye, viewProj, p, moving, prePass);
  glDisable(GL_CULL_FACE);
  glBindVertexArray(0);
  glBindSampler(5, 0);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  checkGl("drawing the scene");
}

}  // namespace lo
