#pragma once
// Internal to src/render: the renderer's parts, one file each.
//   scene_geometry.cpp   the scene on the GPU: vertices by material, textures,
//                        draw order, depth-only draws, the blended sort
//   light_list.cpp       area lights and VPLs (no GL: light_list.h)
//   lights.cpp           the light block, shadow maps, sun cascades (lights.h)
//   reflection_probe.cpp the probe's cube map, captured with the scene pass
//   scene_pass.cpp       a frame: depth pre-pass, the scene pass, transmission
//   renderer.cpp         the public Renderer, which ties them together
// GL objects are held by the handles of gl_resources.h.
// Render space: world minus the centre of the scene's bounds (see RenderSpace).

#include <render_constants.h>

#include <array>
#include <cstdint>
#include <functional>
#include <glm/glm.hpp>
#include <map>
#include <vector>

#include "core/math.h"
#include "render/gl_resources.h"
#include "render/lights.h"
#include "render/octree_textures.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace lo {
namespace render_internal {

/// One vertex of the scene's vertex buffer (attribute locations 0-9, 11 of
/// render_scene.vert; 10 is the lightmap's, in a buffer of its own).
struct Vertex {
  float position[3];
  float normal[3];
  /// The material's base colour factor and its alpha times the vertex
  /// colour (COLOR_0; textures apply per pixel).
  float baseColor[4];
  float metallicRoughness[2];
  float emission[3];
  float uv[2];        ///< the texture coordinates the base colour texture names (TEXCOORD_0 or _1)
  float normalUv[2];  ///< the texture coordinates of the normal map
  float metallicRoughnessUv[2];
  float occlusionUv[2];
  float emissiveUv[2];
  float tangent[4];  ///< glTF TANGENT (xyz, w = +-1), w = 0 without: derived in the shader
};

/// The memory the scene's vertices take in the GL driver, per triangle:
/// three vertices and, beside them, its corners' triangle indices
/// (SceneGeometry::vertexCorner) and the lightmap attribute's floats; the
/// vertices are built a chunk at a time, so their building copy is bounded.
constexpr double kRenderBytesPerTriangle = 3.0 * (sizeof(Vertex) + 4 + 12);

/// @throws InputError when `triangles` need more than the memory available
/// (kRenderBytesPerTriangle each, and for the `added` ones of objects added
/// after the bake, their vertices' copy that moving them starts from): the
/// scene loader's budget (256 bytes a triangle) let a scene through whose
/// vertices then ran the machine out of memory in the driver (H17-5-1).
void checkGeometryMemory(size_t triangles, size_t added);

/// Draw order of the scene pass: plain opaque ranges first (one call in the
/// depth-only passes), then alpha-tested ones, then blended ones (sorted back
/// to front, no depth writes), then transmissive ones over a copy of the rest.
enum DrawCategory { kSolid = 0, kMasked = 1, kBlended = 2, kTransmissive = 3, kCategories = 4 };

/// A run of the vertex buffer drawn with one material's textures.
struct DrawRange {
  int texture = -1;        ///< base colour texture, index into Scene::textures (-1: none)
  int normalTexture = -1;  ///< normal map, index into Scene::textures (-1: none)
  float normalScale = 1;
  int metallicRoughnessTexture = -1;
  int occlusionTexture = -1;
  float occlusionStrength = 1;
  int emissiveTexture = -1;
  int alphaMode = shader::LO_ALPHA_OPAQUE;
  float alphaCutoff = 0.5f;
  bool doubleSided = true;  ///< false: back faces culled from the camera's view (glTF)
  /// Material::doubleSided: emission shows from both sides (else from the
  /// winding's front only, as every tracer emits it; an OBJ face, never
  /// culled, shows none from behind).
  bool emitsBothSides = false;
  GLint first = 0;
  GLsizei count = 0;
  float transmission = 0;  ///< > 0: drawn after the opaque scene, see-through
  float thickness = 0;     ///< KHR_materials_volume: > 0 refracts the image behind
  float ior = 1.5f;
  float dielectricF0 = 0.04f;  ///< the dielectric's specular layer (Material::dielectricF0)
  float specular = 1;          ///< its weight (KHR_materials_specular)
  bool unlit = false;          ///< Material::unlit: unshaded, no shadow
  /// An object added after the bake (Scene::movingMaterialsFrom): lit by
  /// the free-space light when the renderer has it.
  bool moving = false;
};

/// Channels of a texture the scene shader reads (SceneGeometry::uploadTexture).
enum : unsigned { kReadR = 1, kReadG = 2, kReadB = 4, kReadA = 8 };

/// The scene's triangles on the GPU, grouped by material in DrawCategory
/// order, and its textures (scene_geometry.cpp).
struct SceneGeometry {
  GlVertexArray vao;
  GlBuffer vbo;
  GlVertexArray emptyVao;
  std::vector<DrawRange> ranges;  ///< the vertex buffer by material, in DrawCategory order
  std::vector<DrawCategory> rangeCategory;  ///< per range
  GLsizei opaqueCount = 0;  ///< vertices of the kSolid ranges (one call in depth passes)
  /// Blended triangles' centroids (render space), one per triangle of the
  /// kBlended ranges, from vertex blendFirst on; sorted per frame into blendEbo.
  std::vector<glm::vec3> blendCentroids;
  GLint blendFirst = 0;
  GlBuffer blendEbo;
  std::vector<GlTexture> textures;  ///< per Scene::textures entry; 0 = not used
  size_t textureBytes = 0;           ///< their GPU bytes (mipmaps included)
  /// Per vertex of the vertex buffer: 3 x its Scene triangle + its corner
  /// (the buffer is grouped by material, not in triangle order).
  std::vector<uint32_t> vertexCorner;
  size_t sceneTriangles = 0;
  float maxAnisotropy = 1;  ///< of the context (1: no anisotropic filtering)
  /// The vertices of the added objects' ranges as uploaded (render space),
  /// range by range: what moveAddedObjects offsets.
  std::vector<Vertex> movingVertices;

  /// Uploads the vertices and the textures the materials use, calling
  /// `textureUploaded` (when set) with each texture's index once it is on
  /// the GPU (Renderer's constructor).
  void upload(const Scene& scene, const RenderSpace& space,
              const std::function<void(int)>& textureUploaded = {});
  /// The GL name of Scene::textures[texture], 0 for -1.
  GLuint texture(int index) const { return index >= 0 ? textures[size_t(index)].get() : 0; }
  /// Every texture's level-of-detail bias (GL_TEXTURE_LOD_BIAS): -log2 s
  /// while s x s samples share a pixel in frames of the image's size, so
  /// that each sample reads the mip level of its own footprint.
  void setLodBias(float bias) const;
  /// The geometry of a depth-only pass (depth pre-pass or shadow map) with
  /// `program` in use and the vao bound; see scene_geometry.cpp.
  void drawDepthOnly(GLuint program, bool shadows) const;
  /// Writes the blended triangles' vertex indices into blendEbo, back to front from `eye`.
  void sortBlended(const glm::vec3& eye);
  /// Draws the transmissive ranges with a volume, both sides (vao bound).
  void drawVolumes() const;

 private:
  GlTexture uploadTexture(const Texture& t, unsigned read);
  /// What upload() hands on to each texture's upload: the channels read of
  /// each (kReadR | ...) and the caller's callback.
  struct TextureUploads {
    std::vector<unsigned> channelsRead;
    const std::function<void(int)>& uploaded;
  };
  /// Scene::textures[index] on the GPU, uploaded on first use; returns index.
  int useTexture(const Scene& scene, int index, const TextureUploads& uploads);
  /// The textures and uniforms material `mat` draws with.
  DrawRange rangeOf(const Scene& scene, const Material& mat, const TextureUploads& uploads);
  /// The vertex attributes of the buffer (upload, the vao and vbo bound).
  void setVertexAttributes();

 public:
  /// Rewrites the added objects' vertices in the buffer moved by `offset`
  /// (render space units) from where they were uploaded.
  void offsetMovingVertices(const Vec3& offset);
};

/// The reflection probe: a mipmapped RGBA16F cube map of the lit scene seen
/// from the scene's centre (render space origin), parallax-corrected to the
/// scene's bounds in the shader. Captured on the first frame that wants it,
/// again after setOctree (reflection_probe.cpp).
constexpr int kProbeFaces = 6;  ///< the cube map's faces, one frame drawn each

struct ReflectionProbe {
  bool wanted = false;
  bool valid = false;
  bool capturing = false;
  GlTexture texture;  ///< the probe the scene shader reads
  GlTexture spare;    ///< the next capture's target (RGBA32F as the frame's)
  GlFramebuffer fbo;
  GlRenderbuffer depth;
  int levels = 1;
  /// Its irradiance at the centre as 9 SH terms (octree_layout.h's basis
  /// convolved with the clamped cosine: E(n) = sum_i E_i Y_i(n), W/m^2),
  /// projected after each capture: the scene shader scales the probe's
  /// light by the octree's irradiance over this (render_scene_probe.glsl).
  std::array<glm::vec3, 9> irradiance{};
};

}  // namespace render_internal

struct Renderer::Impl {
  RendererParams params;
  std::vector<StageReport> startup;  ///< Renderer::startupStages
  render_internal::RenderSpace space;
  /// The corners of an even sample of the scene's triangles (2^14 at most,
  /// render space): the camera's near plane stays nearer than the nearest
  /// of them (nearPlane).
  std::vector<glm::vec3> nearSample;
  int depth = 0;
  Vec3 octreeOrigin;
  float voxelSize = 1;
  /// The sky's radiance (Scene::sky), drawn as the background; its light
  /// reaches the surfaces through the octree only.
  Vec3 sky{0, 0, 0};

  /// The scene has a volume (KHR_materials_volume with transmission): its
  /// programs are built with LO_VOLUMES, the glass followed through the
  /// solid (render_scene.frag), and its frames draw the volumes' back faces
  /// (volumeBacks); without, that code is left out (the software
  /// rasteriser's compile time follows the shader's size).
  bool volumes = false;
  /// The scene program's files built with `defines`, plus LO_VOLUMES where
  /// the scene has a volume, and LO_ALPHA_CUT (the masked materials' cut);
  /// its twin without the cut goes to uncutTwins. Both have their LightBlock,
  /// where they use one, at binding 0.
  GLuint buildSceneProgram(std::vector<std::string> defines);
  /// Each scene program's twin built without the alpha cut's `discard`,
  /// which draws every material but the masked ones: the software
  /// rasteriser depth- and stencil-tests the fragments of a shader without
  /// one before shading them, so that surfaces at one depth shade a pixel
  /// once (drawRanges); with one, it shades first and tests after.
  std::map<GLuint, render_internal::GlProgram> uncutTwins;
  /// `program`'s twin in uncutTwins (0 for 0).
  GLuint uncut(GLuint program) const;
  /// The scene pass in two variants: with the direct light compiled in (full,
  /// direct) and without it (indirect, voxels), so the octree-only modes do
  /// not pay for the lights' code on a software rasterizer.
  render_internal::GlProgram sceneProgram, sceneIndirectProgram;
  /// The same two with the atlas lookup compiled in place of the octree's
  /// (LO_ATLAS_LIGHTING), built on the first atlas frame.
  render_internal::GlProgram sceneAtlasProgram, sceneIndirectAtlasProgram;
  render_internal::GlProgram depthProgram;
  render_internal::GlProgram skyProgram;  ///< the sky's background, built when the scene has one
  render_internal::GlTexture skyImage;    ///< Sky::image (RGB32F), when the sky has one
  render_internal::SceneGeometry geometry;
  render_internal::SceneLights lights;
  render_internal::ReflectionProbe probe;
  render_internal::OctreeTextures octreeTextures;
  /// The free-space light (setFreeSpaceLight) and the scene programs that
  /// draw the added objects with it (LO_FREE_SPACE), with and without the
  /// direct light; empty until set.
  render_internal::OctreeTextures volumeTextures;
  bool hasVolume = false;
  Vec3 volumeOrigin{0, 0, 0};  ///< render space
  render_internal::GlProgram sceneMovingProgram, sceneIndirectMovingProgram;
  bool hasMovingRanges = false;

  render_internal::GlBuffer atlasVbo;
  render_internal::GlTexture atlasIrradiance, atlasDirection;
  size_t atlasTextureBytes = 0;

  render_internal::GlFramebuffer targetFbo;
  render_internal::GlTexture targetColor;
  render_internal::GlRenderbuffer targetDepth;
  int targetWidth = 0, targetHeight = 0;

  render_internal::GlTexture
      behindTexture;  ///< the opaque image, seen through transmissive surfaces
  int behindWidth = 0, behindHeight = 0;
  bool behindFloat = false;
  /// Thick glass (KHR_materials_volume), made when the scene has a volume:
  /// the opaque image's depth (unit 14), and the nearest back face of the
  /// volumes at each pixel (unit 15: its render-space position, and in w its
  /// outward normal, octahedral, 10 bits a side, plus 1; 0: none), the same
  /// size as behindTexture.
  struct VolumeBacks {
    render_internal::GlTexture opaqueDepth, faces;
    render_internal::GlFramebuffer fbo;
    render_internal::GlRenderbuffer depth;
    render_internal::GlProgram program;
    int width = 0, height = 0;
    bool depthCopied = false;  ///< this frame's opaque depth is in opaqueDepth
  } volumeBacks;

  void uploadOctree(const GpuOctree& octree);

  // scene_pass.cpp
  void ensureTarget(int width, int height);
  void ensureBehind(int width, int height, bool floatTarget);
  void copyBehind(int width, int height, bool floatTarget);
  /// Thick glass: volumeBacks at behindTexture's size (made on first use),
  /// bound to units 14 and 15 (ensureBehind calls it).
  void ensureVolumeBacks();
  /// Copies the opaque depth and draws the volumes' back faces into
  /// volumeBacks (made by the ensureBehind of copyBehind just before), the
  /// bound framebuffer then bound again.
  void drawVolumeBacks(int width, int height, const glm::mat4& viewProj, const glm::vec3& eye);
  /// One frame into the bound framebuffer: depth pre-pass, then the scene
  /// pass (opaque, masked, blended back to front, transmissive).
  void draw(const PinholeCamera& camera, const RenderParams& rp, int width, int height,
            float exposureScale, bool encodeSrgb);
  /// Where draw samples each pixel, in pixels from its centre (Renderer::
  /// render's rotated grid); the probe's faces are drawn at the centres.
  glm::vec2 pixelOffset{0.0f, 0.0f};
  GLuint sceneProgramFor(const RenderParams& rp, bool withDirect);
  void setFrameUniforms(GLuint program, const PinholeCamera& camera, const RenderParams& rp,
                        const glm::mat4& viewProj, bool reflect, float exposureScale,
                        bool encodeSrgb);
  /// `movingProgram` (0: none) draws the ranges of added objects, with the
  /// free-space light's textures bound in place of the octree's.
  /// `oncePerPixel` (after the depth pre-pass): the opaque ranges shade a
  /// pixel once, the first fragment at the pre-pass's depth (the stencil).
  void drawRanges(int width, int height, bool encodeSrgb, const glm::vec3& eye,
                  const glm::mat4& viewProj, GLuint program, GLuint movingProgram,
                  bool oncePerPixel);

  // reflection_probe.cpp
  /// Renders the probe's six faces with the full scene program, reflections
  /// off, then builds the mip chain that rough surfaces read.
  void captureProbe(const RenderParams& rp);
  /// probe.irradiance from the captured cube map (its texture bound).
  void projectProbeIrradiance();
};

}  // namespace lo
