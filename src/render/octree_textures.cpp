#include "render/octree_textures.h"

#include <algorithm>
#include <cstdint>
#include <sstream>

#include "core/error.h"
#include "render/gl_util.h"

namespace lo::render_internal {

std::string texelCount(int w, int h, int d) {
  std::ostringstream os;
  os << w << " x " << h;
  if (d > 0) os << " x " << d;
  return os.str();
}

void OctreeTextures::checkLimits(const GpuOctree& octree, int max3D, int max2D) {
  if (max3D <= 0) glGetIntegerv(GL_MAX_3D_TEXTURE_SIZE, &max3D);
  if (max2D <= 0) glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max2D);
  const int largest3D = std::max({octree.poolWidth(), octree.poolHeight(), octree.poolDepth()});
  if (largest3D > max3D) {
    throw InputError("octree pool of " +
                     texelCount(octree.poolWidth(), octree.poolHeight(), octree.poolDepth()) +
                     " texels exceeds GL_MAX_3D_TEXTURE_SIZE = " + std::to_string(max3D) + " by " +
                     std::to_string(largest3D - max3D) + " texels: rebake with a smaller --depth");
  }
  const int largest2D = std::max(octree.vdlWidth, octree.vdlHeight);
  if (largest2D > max2D) {
    throw InputError("VDL texture of " + texelCount(octree.vdlWidth, octree.vdlHeight, 0) +
                     " texels exceeds GL_MAX_TEXTURE_SIZE = " + std::to_string(max2D) + " by " +
                     std::to_string(largest2D - max2D) +
                     " texels: rebake with a smaller --depth or fewer --vdls");
  }
}

void OctreeTextures::upload(const GpuOctree& octree) {
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  pool = GlTexture::create();
  glBindTexture(GL_TEXTURE_3D, pool.get());
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  const uint8_t emptyTexel[4] = {0, 0, 0, 0};  // LO_FLAG_EMPTY: keeps the sampler complete
  const size_t expected =
      size_t(octree.poolWidth()) * octree.poolHeight() * octree.poolDepth() * 4;
  const bool hasPool = expected > 0;
  if (hasPool) LO_CHECK_EQ(octree.pool.size(), expected);
  glTexImage3D(GL_TEXTURE_3D, 0, GL_RGBA8UI, hasPool ? octree.poolWidth() : 1,
               hasPool ? octree.poolHeight() : 1, hasPool ? octree.poolDepth() : 1, 0,
               GL_RGBA_INTEGER, GL_UNSIGNED_BYTE, hasPool ? octree.pool.data() : emptyTexel);
  checkGl("uploading the octree pool (GL_TEXTURE_3D, GL_RGBA8UI)");

  auto makeTexture = [](GlTexture& texture) {
    texture = GlTexture::create();
    glBindTexture(GL_TEXTURE_2D, texture.get());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  };
  const size_t vdlTexels = size_t(octree.vdlWidth) * octree.vdlHeight * 4;
  half = octree.halfFloat && vdlTexels > 0;
  compact = half && octree.compact;
  scale = octree.irradianceScale;
  shTerms = octree.shTerms;
  surfaceTexels = octree.surfaceTexels;
  const float zero[4] = {0, 0, 0, 0};
  const uint16_t zeroHalf[4] = {0, 0, 0, 0};
  makeTexture(vdl);
  if (vdlTexels > 0 && !half) {
    LO_CHECK_EQ(octree.vdlTexels.size(), vdlTexels);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, octree.vdlWidth, octree.vdlHeight, 0, GL_RGBA,
                 GL_FLOAT, octree.vdlTexels.data());
  } else {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, 1, 1, 0, GL_RGBA, GL_FLOAT, zero);
  }
  makeTexture(vdlHalf);
  if (half) {
    LO_CHECK_EQ(octree.vdlTexelsHalf.size(), vdlTexels);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16UI, octree.vdlWidth, octree.vdlHeight, 0,
                 GL_RGBA_INTEGER, GL_UNSIGNED_SHORT, octree.vdlTexelsHalf.data());
  } else {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16UI, 1, 1, 0, GL_RGBA_INTEGER, GL_UNSIGNED_SHORT,
                 zeroHalf);
  }
  checkGl("uploading the VDL texture (GL_TEXTURE_2D)");
  depth = octree.depth;
  origin = octree.origin;
  voxelSize = octree.depth > 0 ? octree.cubeSize / float(1 << octree.depth) : octree.cubeSize;
}

void OctreeTextures::bind(GLuint program, int poolUnit, int vdlUnit, int halfUnit) const {
  glUniform1i(glGetUniformLocation(program, "uOctree"), poolUnit);
  glUniform1i(glGetUniformLocation(program, "uVdls"), vdlUnit);
  glUniform1i(glGetUniformLocation(program, "uVdlsHalf"), halfUnit);
  glUniform1i(glGetUniformLocation(program, "uHalfVdls"), half ? 1 : 0);
  glUniform1i(glGetUniformLocation(program, "uCompactVdls"), compact ? 1 : 0);
  glUniform1f(glGetUniformLocation(program, "uVdlScale"), scale);
  glUniform1i(glGetUniformLocation(program, "uShTerms"), shTerms);
  glUniform1i(glGetUniformLocation(program, "uSurfaceTexels"), surfaceTexels ? 1 : 0);
  glActiveTexture(GLenum(GL_TEXTURE0 + poolUnit));
  glBindTexture(GL_TEXTURE_3D, pool.get());
  glActiveTexture(GLenum(GL_TEXTURE0 + vdlUnit));
  glBindTexture(GL_TEXTURE_2D, vdl.get());
  glActiveTexture(GLenum(GL_TEXTURE0 + halfUnit));
  glBindTexture(GL_TEXTURE_2D, vdlHalf.get());
  glActiveTexture(GL_TEXTURE0);
}

}  // namespace lo::render_internal
