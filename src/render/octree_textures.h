#pragma once
// Internal to src/render: the light octree's textures on the GPU (paper
// §4.2.1), shared by the renderer and the GPU lightmap bake, which run the
// same lookup (shaders/octree_lookup.h) on them.

#include <glad/gl.h>

#include <string>

#include "core/math.h"
#include "octree/gpu_octree.h"
#include "render/gl_resources.h"

namespace lo::render_internal {

/// "W x H x D" (or "W x H" for d = 0), for messages about texture sizes.
std::string texelCount(int w, int h, int d);

/// The pool (GL_TEXTURE_3D, RGBA8UI) and the VDL texels (GL_TEXTURE_2D:
/// RGBA32F, or RGBA16UI half-floats). Both VDL textures always exist, the
/// one not in use a 1x1 dummy, so a program is valid whichever precision
/// the octree has. Requires a current GL context; owns its textures.
class OctreeTextures {
 public:
  /// @throws InputError naming GL_MAX_3D_TEXTURE_SIZE / GL_MAX_TEXTURE_SIZE
  /// and by how much when `octree` exceeds them (0 = the context's limit).
  static void checkLimits(const GpuOctree& octree, int max3D = 0, int max2D = 0);
  /// Replaces the textures by `octree`'s (checkLimits first).
  void upload(const GpuOctree& octree);
  /// Binds the pool, the float VDLs and the half VDLs to texture units
  /// `poolUnit`, `vdlUnit` and `halfUnit`, and points `program`'s samplers
  /// uOctree, uVdls, uVdlsHalf at them, and uHalfVdls, uCompactVdls,
  /// uVdlScale, uShTerms and uSurfaceTexels at `half`, `compact`, `scale`,
  /// `shTerms` and `surfaceTexels`; the program must be in use.
  void bind(GLuint program, int poolUnit, int vdlUnit, int halfUnit) const;

  GlTexture pool, vdl, vdlHalf;
  bool half = false;       ///< the VDL texels are the 16-bit ones
  bool compact = false;    ///< ... holding compact (RGB9E5) irradiance
  float scale = 1;         ///< the compact texels' irradiance scale
  int shTerms = 0;         ///< GpuOctree::shTerms
  bool surfaceTexels = false;  ///< GpuOctree::surfaceTexels
  int depth = 0;           ///< the octree's depth
  float voxelSize = 1;     ///< world units
  Vec3 origin{0, 0, 0};    ///< world position of the cube's corner
};

}  // namespace lo::render_internal
