// Renderer: scene + light octree -> linear HDR pixels (paper §3.2, §4.2).

#include "render/renderer.h"

#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <array>
#include <sstream>

#include <render_constants.h>

#include "core/error.h"
#include "render/context.h"
#include "render/gl_util.h"
#include "render/layout_probe.h"
#include "render/octree_textures.h"
#include "scene/emitter_sampler.h"

namespace lo {
namespace render_internal {

// Shared with the shader (shaders/render_constants.h).
constexpr int kMaxLights = shader::LO_MAX_LIGHTS;
constexpr int kMaxShadowLayers = shader::LO_MAX_SHADOW_LAYERS;
constexpr int kPoint = shader::LO_LIGHT_POINT;
constexpr int kSpot = shader::LO_LIGHT_SPOT;
constexpr int kDirectional = shader::LO_LIGHT_DIRECTIONAL;
constexpr int kEmitter = shader::LO_LIGHT_EMITTER;
constexpr int kArea = shader::LO_LIGHT_AREA;

constexpr int kCascades = shader::LO_SUN_CASCADES;

/// Shadow map layers a light of shader type `type` takes: a cube (6) for
/// lights that shine all around a point, one per cascade for directional
/// lights, one for spot lights.
int shadowLayersOf(int type) {
  if (type == kDirectional) return kCascades;
  return type == kPoint || type == kEmitter || type == kArea ? 6 : 1;
}

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

/// std140 twin of `struct Light` in shaders/render_scene.frag.
struct GpuLight {
  float positionType[4];
  float directionRange[4];
  float colorFar[4];
  float params[4];
  float corner0[4];  ///< area lights: the triangle's corners (render space); corner0.w = sqrt(area)
  float corner1[4];
  float corner2[4];
};
static_assert(sizeof(GpuLight) == 112, "std140 Light is 7 vec4");

/// std140 twin of `uniform LightBlock` in shaders/render_scene.frag.
struct LightBlock {
  GpuLight lights[kMaxLights];
  float shadowMatrices[kMaxShadowLayers][16];
  int32_t lightCount[4];
  float shadowParams[4];
};
static_assert(sizeof(LightBlock) == kMaxLights * 112 + kMaxShadowLayers * 64 + 16 + 16,
              "std140 LightBlock layout");

struct Vertex {
  float position[3];
  float normal[3];
  float baseColor[3];  ///< the material's base colour factor (textures apply per pixel)
  float metallicRoughness[2];
  float emission[3];
  float uv[2];  ///< the texture coordinates the base colour texture names (TEXCOORD_0 or _1)
  float normalUv[2];  ///< the texture coordinates of the normal map
  float metallicRoughnessUv[2];
  float occlusionUv[2];
  float emissiveUv[2];
  float tangent[4];  ///< glTF TANGENT (xyz, w = +-1), w = 0 without: derived in the shader
};

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
  float baseAlpha = 1;
  float alphaCutoff = 0.5f;
  bool doubleSided = true;  ///< false: back faces culled from the camera's view (glTF)
  GLint first = 0;
  GLsizei count = 0;
  float transmission = 0;  ///< > 0: drawn after the opaque scene, see-through
  float thickness = 0;     ///< KHR_materials_volume: > 0 refracts the image behind
  float ior = 1.5f;
};

/// Draw order of the scene pass: plain opaque ranges first (one call in the
/// depth-only passes), then alpha-tested ones, then blended ones (sorted back
/// to front, no depth writes), then transmissive ones over a copy of the rest.
enum DrawCategory { kSolid = 0, kMasked = 1, kBlended = 2, kTransmissive = 3, kCategories = 4 };

int alphaModeOf(const Material& m) {
  switch (m.alphaMode) {
    case AlphaMode::Mask:
      return shader::LO_ALPHA_MASK;
    case AlphaMode::Blend:
      return shader::LO_ALPHA_BLEND;
    case AlphaMode::Opaque:
      break;
  }
  return shader::LO_ALPHA_OPAQUE;
}

DrawCategory categoryOf(const Material& m) {
  if (m.transmission > 0) return kTransmissive;
  if (m.alphaMode == AlphaMode::Blend) return kBlended;
  if (m.alphaMode == AlphaMode::Mask) return kMasked;
  return kSolid;
}

glm::vec3 toGlm(const Vec3& v) { return {v.x, v.y, v.z}; }

void setVec4(float* dst, const Vec3& v, float w) {
  dst[0] = v.x;
  dst[1] = v.y;
  dst[2] = v.z;
  dst[3] = w;
}

/// Any unit vector orthogonal to unit d.
glm::vec3 perpendicular(const glm::vec3& d) {
  glm::vec3 a = std::fabs(d.y) < 0.9f ? glm::vec3(0, 1, 0) : glm::vec3(1, 0, 0);
  return glm::normalize(glm::cross(d, glm::cross(a, d)));
}

}  // namespace render_internal

using namespace render_internal;

Lighting parseLighting(const std::string& name) {
  if (name == "octree") return Lighting::Octree;
  if (name == "atlas") return Lighting::Atlas;
  throw InputError("unknown lighting '" + name + "' (expected octree or atlas)");
}

std::string toString(Lighting lighting) {
  return lighting == Lighting::Atlas ? "atlas" : "octree";
}

RenderMode parseRenderMode(const std::string& name) {
  if (name == "full") return RenderMode::Full;
  if (name == "direct") return RenderMode::Direct;
  if (name == "indirect") return RenderMode::Indirect;
  if (name == "voxels") return RenderMode::Voxels;
  throw InputError("unknown render mode '" + name + "' (expected full, direct, indirect, voxels)");
}

std::string toString(RenderMode mode) {
  switch (mode) {
    case RenderMode::Full:
      return "full";
    case RenderMode::Direct:
      return "direct";
    case RenderMode::Indirect:
      return "indirect";
    case RenderMode::Voxels:
      return "voxels";
  }
  return "?";
}

struct Renderer::Impl {
  RendererParams params;
  /// World position of render space's origin: the centre of the scene's
  /// bounds. Everything the GPU sees (vertices, lights, shadow matrices, the
  /// camera, the octree) is in render space, world - renderOrigin computed in
  /// double, so that a scene far from the world origin keeps the precision of
  /// one near it in every shader computation (view transform, depth, shadow
  /// lookups, the octree lookup, screen-space derivatives).
  Vec3 renderOrigin{0, 0, 0};
  Bounds3 bounds;  ///< the scene's bounds, render space
  float sceneSize = 1;  // bounds diagonal, world units
  int depth = 0;
  Vec3 octreeOrigin;
  float voxelSize = 1;

  /// The scene pass in two variants: with the direct light compiled in (full,
  /// direct) and without it (indirect, voxels), so the octree-only modes do
  /// not pay for the lights' code on a software rasterizer.
  GLuint sceneProgram = 0, sceneIndirectProgram = 0;
  /// The same two with the atlas lookup compiled in place of the octree's
  /// (LO_ATLAS_LIGHTING), built on the first atlas frame.
  GLuint sceneAtlasProgram = 0, sceneIndirectAtlasProgram = 0;
  GLuint shadowProgram = 0, depthProgram = 0, probeProgram = 0;
  GLuint vao = 0, vbo = 0, emptyVao = 0;
  std::vector<DrawRange> ranges;        ///< the vertex buffer by material, in DrawCategory order
  std::vector<DrawCategory> rangeCategory;  ///< per range
  GLsizei opaqueCount = 0;              ///< vertices of the kSolid ranges (one call in depth passes)
  /// Blended triangles' centroids (render space), one per triangle of the
  /// kBlended ranges, from vertex blendFirst on; sorted per frame into blendEbo.
  std::vector<glm::vec3> blendCentroids;
  GLint blendFirst = 0;
  GLuint blendEbo = 0;
  GLuint behindTexture = 0;             ///< the opaque image, seen through transmissive surfaces
  int behindWidth = 0, behindHeight = 0;
  bool behindFloat = false;
  std::vector<GLuint> textures;         ///< per Scene::textures entry; 0 = not used
  /// Per vertex of the vertex buffer: 3 x its Scene triangle + its corner
  /// (the buffer is grouped by material, not in triangle order).
  std::vector<uint32_t> vertexCorner;
  size_t sceneTriangles = 0;
  GLuint atlasVbo = 0, atlasIrradiance = 0, atlasDirection = 0;
  size_t atlasTextureBytes = 0;
  float maxAnisotropy = 1;              ///< of the context (1: no anisotropic filtering)
  OctreeTextures octreeTextures;
  GLuint shadowTexture = 0, lightUbo = 0;
  GLuint shadowFbo = 0;
  GLuint targetFbo = 0, targetColor = 0, targetDepth = 0;
  int targetWidth = 0, targetHeight = 0;
  int emitterLights = 0;
  int areaLightCount = 0;
  /// Directional lights with cascaded shadow maps (indices into the light
  /// block), their cascades refitted when the camera moves.
  std::vector<int> sunLights;
  float cascadeFar[4] = {0, 0, 0, 0};      ///< view depth where each cascade ends
  float cascadeTexel[4] = {0, 0, 0, 0};    ///< world size of one texel of each cascade
  float cascadeDepth[4] = {1, 1, 1, 1};    ///< world depth range of each cascade's map
  /// The reflection probe: a mipmapped RGBA16F cube map of the lit scene seen
  /// from the scene's centre (render space origin), parallax-corrected to
  /// the scene's bounds in the shader. Captured on the first frame that
  /// wants it, again after setOctree.
  bool probeWanted = false;
  bool probeValid = false;
  bool capturingProbe = false;
  GLuint probeTexture = 0, probeFbo = 0, probeDepth = 0;
  int probeLevels = 1;
  std::array<float, 12> fittedCamera{};    ///< the camera the cascades were fitted to

  GLuint depthSampler = 0;  ///< reads the shadow maps' depths (no comparison): PCSS blocker search

  LightBlock lightBlock{};

  /// World -> render space, in double: exact for points near the scene.
  Vec3 toRender(const Vec3& world) const {
    return {float(double(world.x) - double(renderOrigin.x)),
            float(double(world.y) - double(renderOrigin.y)),
            float(double(world.z) - double(renderOrigin.z))};
  }

  ~Impl() {
    GLuint programs[] = {sceneProgram, sceneIndirectProgram, sceneAtlasProgram,
                         sceneIndirectAtlasProgram, shadowProgram, depthProgram,
                         probeProgram};
    for (GLuint p : programs) {
      if (p) glDeleteProgram(p);
    }
    GLuint own[] = {shadowTexture, targetColor};
    glDeleteTextures(2, own);
    if (!textures.empty()) glDeleteTextures(GLsizei(textures.size()), textures.data());
    if (behindTexture) glDeleteTextures(1, &behindTexture);
    glDeleteBuffers(1, &vbo);
    glDeleteBuffers(1, &lightUbo);
    if (blendEbo) glDeleteBuffers(1, &blendEbo);
    if (probeTexture) glDeleteTextures(1, &probeTexture);
    if (probeFbo) glDeleteFramebuffers(1, &probeFbo);
    if (probeDepth) glDeleteRenderbuffers(1, &probeDepth);
    if (atlasVbo) glDeleteBuffers(1, &atlasVbo);
    GLuint atlasTextures[] = {atlasIrradiance, atlasDirection};
    glDeleteTextures(2, atlasTextures);
    glDeleteVertexArrays(1, &vao);
    glDeleteVertexArrays(1, &emptyVao);
    glDeleteFramebuffers(1, &shadowFbo);
    if (depthSampler) glDeleteSamplers(1, &depthSampler);
    glDeleteFramebuffers(1, &targetFbo);
    glDeleteRenderbuffers(1, &targetDepth);
  }

  void uploadOctree(const GpuOctree& octree) {
    OctreeTextures::checkLimits(octree, params.max3DTextureSize, params.max2DTextureSize);
    octreeTextures.upload(octree);
    octreeOrigin = toRender(octree.origin);
    depth = octree.depth;
    voxelSize = octreeTextures.voxelSize;
  }

  /// Uploads a texture (linear RGB, and its alpha where it has one) with
  /// mipmaps, trilinear and anisotropic filtering, repeat wrap (glTF's
  /// default sampler).
  GLuint uploadTexture(const Texture& t) {
    GLuint id = 0;
    glGenTextures(1, &id);
    glBindTexture(GL_TEXTURE_2D, id);
    std::vector<float> rgba(t.texels.size() * 4);
    for (size_t i = 0; i < t.texels.size(); ++i) {
      rgba[4 * i] = t.texels[i].x;
      rgba[4 * i + 1] = t.texels[i].y;
      rgba[4 * i + 2] = t.texels[i].z;
      rgba[4 * i + 3] = t.alpha.empty() ? 1.0f : t.alpha[i];
    }
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    // Half floats: linear colour with 11 bits of precision, filterable and
    // mipmappable on every GL 3.3 context.
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, t.width, t.height, 0, GL_RGBA, GL_FLOAT,
                 rgba.data());
    glGenerateMipmap(GL_TEXTURE_2D);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_REPEAT);
    if (maxAnisotropy > 1) glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY, maxAnisotropy);
    checkGl("uploading a base colour texture");
    return id;
  }

  void uploadScene(const Scene& scene) {
    // Anisotropic filtering: core in GL 4.6, an extension before.
    if (GLAD_GL_ARB_texture_filter_anisotropic || GLAD_GL_EXT_texture_filter_anisotropic) {
      glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &maxAnisotropy);
      maxAnisotropy = std::min(maxAnisotropy, 16.0f);
    }
    // Triangles in runs of one material (so that the scene pass binds each
    // material's textures once), opaque first; transmissive runs last, drawn
    // after the opaque scene they show.
    const Material fallback;
    auto materialOf = [&](size_t t) -> const Material& {
      const int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
      return m >= 0 && size_t(m) < scene.materials.size() ? scene.materials[size_t(m)] : fallback;
    };
    const size_t slots = scene.materials.size() + 1;
    std::vector<std::vector<size_t>> byMaterial(kCategories * slots);
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
      const int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
      const size_t slot = m >= 0 && size_t(m) < scene.materials.size() ? size_t(m) + 1 : 0;
      byMaterial[size_t(categoryOf(materialOf(t))) * slots + slot].push_back(t);
    }
    auto uvSet = [&](int texCoord) -> const std::vector<float>& {
      return texCoord == 1 ? scene.texcoords1 : scene.texcoords0;
    };
    auto usable = [&](int texture, int texCoord) {
      return texture >= 0 && size_t(texture) < scene.textures.size() &&
             uvSet(texCoord).size() == 2 * scene.positions.size();
    };
    std::vector<Vertex> vertices;
    vertices.reserve(scene.triangleCount() * 3);
    textures.assign(scene.textures.size(), 0);
    auto textureId = [&](int texture) {
      if (!textures[size_t(texture)]) textures[size_t(texture)] = uploadTexture(scene.textures[size_t(texture)]);
      return texture;
    };
    for (const std::vector<size_t>& group : byMaterial) {
      if (group.empty()) continue;
      const Material& mat = materialOf(group.front());
      DrawRange range;
      const DrawCategory category = categoryOf(mat);
      range.transmission = mat.transmission;
      range.thickness = mat.thickness;
      range.ior = mat.ior;
      range.alphaMode = alphaModeOf(mat);
      range.baseAlpha = mat.baseAlpha;
      range.alphaCutoff = mat.alphaCutoff;
      range.doubleSided = mat.doubleSided;
      if (usable(mat.emissiveTexture, mat.emissiveTexCoord) && mat.isEmissive()) {
        range.emissiveTexture = textureId(mat.emissiveTexture);
      }
      if (usable(mat.baseColorTexture, mat.baseColorTexCoord)) range.texture = textureId(mat.baseColorTexture);
      if (usable(mat.normalTexture, mat.normalTexCoord)) {
        range.normalTexture = textureId(mat.normalTexture);
        range.normalScale = mat.normalScale;
      }
      if (usable(mat.metallicRoughnessTexture, mat.metallicRoughnessTexCoord)) {
        range.metallicRoughnessTexture = textureId(mat.metallicRoughnessTexture);
      }
      if (usable(mat.occlusionTexture, mat.occlusionTexCoord)) {
        range.occlusionTexture = textureId(mat.occlusionTexture);
        range.occlusionStrength = mat.occlusionStrength;
      }
      range.first = GLint(vertices.size());
      for (size_t t : group) {
        Vec3 faceN = scene.faceNormal(t);
        for (int k = 0; k < 3; ++k) {
          uint32_t index = scene.indices[t * 3 + size_t(k)];
          // Texture transforms are affine: applied per vertex they are exact.
          auto setUv = [&](float* out, int texCoord, const TextureTransform& transform) {
            const std::vector<float>& uv = uvSet(texCoord);
            out[0] = uv[2 * index];
            out[1] = uv[2 * index + 1];
            transform.apply(out[0], out[1]);
          };
          Vertex v{};
          Vec3 p = toRender(scene.positions[index]);
          Vec3 n = scene.normals.empty() ? faceN : scene.normals[index];
          std::memcpy(v.position, &p, sizeof v.position);
          std::memcpy(v.normal, &n, sizeof v.normal);
          std::memcpy(v.baseColor, &mat.baseColor, sizeof v.baseColor);
          v.metallicRoughness[0] = mat.metallic;
          v.metallicRoughness[1] = mat.roughness;
          std::memcpy(v.emission, &mat.emission, sizeof v.emission);
          if (range.texture >= 0) setUv(v.uv, mat.baseColorTexCoord, mat.baseColorTransform);
          if (range.normalTexture >= 0) setUv(v.normalUv, mat.normalTexCoord, mat.normalTransform);
          if (range.metallicRoughnessTexture >= 0) {
            setUv(v.metallicRoughnessUv, mat.metallicRoughnessTexCoord,
                  mat.metallicRoughnessTransform);
          }
          if (range.occlusionTexture >= 0) {
            setUv(v.occlusionUv, mat.occlusionTexCoord, mat.occlusionTransform);
          }
          if (range.emissiveTexture >= 0) {
            setUv(v.emissiveUv, mat.emissiveTexCoord, mat.emissiveTransform);
          }
          if (scene.tangents.size() == 4 * scene.positions.size()) {
            std::memcpy(v.tangent, &scene.tangents[4 * size_t(index)], sizeof v.tangent);
          }
          vertices.push_back(v);
          vertexCorner.push_back(uint32_t(3 * t + size_t(k)));
        }
        if (category == kBlended) {
          const Vertex* tri = &vertices[vertices.size() - 3];
          blendCentroids.push_back(
              (glm::make_vec3(tri[0].position) + glm::make_vec3(tri[1].position) +
               glm::make_vec3(tri[2].position)) / 3.0f);
        }
      }
      range.count = GLsizei(vertices.size()) - range.first;
      ranges.push_back(range);
      rangeCategory.push_back(category);
      if (category == kSolid) opaqueCount = GLsizei(vertices.size());
      if (category < kBlended) blendFirst = GLsizei(vertices.size());
    }
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(vertices.size() * sizeof(Vertex)),
                 vertices.empty() ? nullptr : vertices.data(), GL_STATIC_DRAW);
    auto attrib = [](GLuint location, GLint size, size_t offset) {
      glEnableVertexAttribArray(location);
      glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                            reinterpret_cast<const void*>(offset));
    };
    attrib(0, 3, offsetof(Vertex, position));
    attrib(1, 3, offsetof(Vertex, normal));
    attrib(2, 3, offsetof(Vertex, baseColor));
    attrib(3, 2, offsetof(Vertex, metallicRoughness));
    attrib(4, 3, offsetof(Vertex, emission));
    attrib(5, 2, offsetof(Vertex, uv));
    attrib(6, 2, offsetof(Vertex, normalUv));
    attrib(7, 2, offsetof(Vertex, metallicRoughnessUv));
    attrib(8, 2, offsetof(Vertex, occlusionUv));
    attrib(9, 2, offsetof(Vertex, emissiveUv));
    attrib(11, 4, offsetof(Vertex, tangent));
    if (!blendCentroids.empty()) glGenBuffers(1, &blendEbo);
    glBindVertexArray(0);
    glGenVertexArrays(1, &emptyVao);
    checkGl("uploading the scene");
  }

  /// Emissive triangles -> area lights, when there are at most
  /// LO_MAX_AREA_LIGHTS of them (else empty: they become VPLs). The shader
  /// integrates each exactly (unshadowed, Lambertian) and softens its shadow
  /// by the light's size (PCSS, see docs/render.md); the shadow cube sits at
  /// the triangle's centroid, just in front of it.
  std::vector<GpuLight> areaLights(const Scene& scene) {
    std::vector<GpuLight> out;
    for (size_t t = 0; t < scene.triangleCount(); ++t) {
      int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
      if (m < 0 || size_t(m) >= scene.materials.size()) continue;
      const Vec3 emission = scene.triangleEmission(t);
      const float area = scene.triangleArea(t);
      if (!(maxComponent(emission) > 0) || !(area > 0)) continue;
      if (out.size() == size_t(shader::LO_MAX_AREA_LIGHTS)) return {};
      const Vec3 p0 = toRender(scene.positions[scene.indices[t * 3]]);
      const Vec3 p1 = toRender(scene.positions[scene.indices[t * 3 + 1]]);
      const Vec3 p2 = toRender(scene.positions[scene.indices[t * 3 + 2]]);
      const Vec3 n = scene.faceNormal(t);
      GpuLight l{};
      setVec4(l.positionType, (p0 + p1 + p2) / 3.0f + n * (1e-3f * sceneSize), float(kArea));
      setVec4(l.directionRange, n, 0);
      setVec4(l.colorFar, emission, 0);  // the mean radiance of a textured emitter
      setVec4(l.params, Vec3(-1, 1, -1), area);
      setVec4(l.corner0, p0, std::sqrt(area));
      setVec4(l.corner1, p1, 0);
      setVec4(l.corner2, p2, 0);
      out.push_back(l);
    }
    return out;
  }

  /// Emissive triangles -> `count` virtual point lights, chosen in proportion
  /// to emitted power (EmitterSampler: the tracers' distribution) by
  /// stratified, deterministic sampling; each carries the power of its
  /// stratum as the intensity of a one-sided Lambertian patch I(theta) =
  /// L A cos(theta). A double-sided emitter's samples alternate sides.
  std::vector<GpuLight> emitterVpls(const Scene& scene, int count) {
    const EmitterSampler emitters = buildEmitterSampler(scene);
    std::vector<GpuLight> out;
    if (emitters.empty() || count <= 0) return out;
    const double total = emitters.total();
    for (int i = 0; i < count; ++i) {
      double u = (i + 0.5) / count;
      size_t k = emitters.pick(u);
      size_t t = emitters.triangles[k];
      double lo = k > 0 ? emitters.cdf[k - 1] : 0.0;
      float s = float((u * total - lo) / (emitters.cdf[k] - lo));
      // Second coordinate from the base-2 radical inverse of i.
      uint32_t bits = uint32_t(i);
      bits = (bits << 16u) | (bits >> 16u);
      bits = ((bits & 0x55555555u) << 1u) | ((bits & 0xAAAAAAAAu) >> 1u);
      bits = ((bits & 0x33333333u) << 2u) | ((bits & 0xCCCCCCCCu) >> 2u);
      bits = ((bits & 0x0F0F0F0Fu) << 4u) | ((bits & 0xF0F0F0F0u) >> 4u);
      bits = ((bits & 0x00FF00FFu) << 8u) | ((bits & 0xFF00FF00u) >> 8u);
      float r = float(bits) * 2.3283064365386963e-10f;
      float su = std::sqrt(std::clamp(s, 0.0f, 1.0f));
      float b1 = su * (1 - r), b2 = su * r;
      const Vec3 p0 = toRender(scene.positions[scene.indices[t * 3]]);
      const Vec3 p1 = toRender(scene.positions[scene.indices[t * 3 + 1]]);
      const Vec3 p2 = toRender(scene.positions[scene.indices[t * 3 + 2]]);
      const bool back = scene.materials[size_t(scene.triangleMaterial[t])].doubleSided && (i & 1);
      Vec3 n = back ? -scene.faceNormal(t) : scene.faceNormal(t);
      Vec3 p = p0 * (1 - b1 - b2) + p1 * b1 + p2 * b2 + n * (1e-3f * sceneSize);
      const Vec3 emission = scene.triangleEmission(t);
      // Area this sample stands for: the emitted power shared by count, as
      // one side of a Lambertian patch (power pi L A).
      float area = float(total / (kPi * double(average(emission))) / count);
      GpuLight l{};
      setVec4(l.positionType, p, float(kEmitter));
      setVec4(l.directionRange, n, 0);
      setVec4(l.colorFar, emission * area, 0);
      setVec4(l.params, Vec3(-1, 1, -1), area);
      out.push_back(l);
    }
    return out;
  }

  void setupLights(const Scene& scene) {
    std::vector<GpuLight> lights;
    for (const Light& light : scene.lights) {
      GpuLight l{};
      Vec3 color = light.color * light.intensity;
      int type = light.type == Light::Type::Point  ? kPoint
                 : light.type == Light::Type::Spot ? kSpot
                                                   : kDirectional;
      setVec4(l.positionType, toRender(light.position), float(type));
      setVec4(l.directionRange, normalize(light.direction), light.range);
      setVec4(l.colorFar, color, 0);
      setVec4(l.params, Vec3(std::cos(light.outerConeAngle), std::cos(light.innerConeAngle), -1),
              0);
      lights.push_back(l);
    }
    std::vector<GpuLight> emitters = params.areaLights ? areaLights(scene) : std::vector<GpuLight>{};
    if (emitters.empty()) {
      emitters = emitterVpls(scene, params.emitterLights);
      emitterLights = int(emitters.size());
    } else {
      areaLightCount = int(emitters.size());
    }
    lights.insert(lights.end(), emitters.begin(), emitters.end());
    if (lights.size() > size_t(kMaxLights)) {
      throw InputError("scene has " + std::to_string(lights.size()) +
                       " punctual + emitter lights; the renderer draws at most " +
                       std::to_string(kMaxLights) + " (lower --emitter-lights)");
    }

    // Shadow map layers: 6 per point light / emitter VPL (cube faces), 1 per
    // spot or directional light, while layers last (further lights unshadowed).
    int layers = 0;
    glm::vec3 center = toGlm(bounds.center());
    float radius = 0.5f * sceneSize;
    float nearPlane = 1e-3f * sceneSize;
    for (GpuLight& l : lights) {
      int type = int(l.positionType[3]);
      int need = shadowLayersOf(type);
      if (layers + need > kMaxShadowLayers) continue;
      glm::vec3 pos(l.positionType[0], l.positionType[1], l.positionType[2]);
      glm::vec3 dir(l.directionRange[0], l.directionRange[1], l.directionRange[2]);
      float far = glm::length(pos - center) + radius + nearPlane;
      l.params[2] = float(layers);
      if (need == 6) {
        const glm::vec3 axes[6] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                   {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};
        glm::mat4 proj = glm::perspective(glm::radians(90.0f), 1.0f, nearPlane, far);
        for (int f = 0; f < 6; ++f) {
          glm::mat4 m = proj * glm::lookAt(pos, pos + axes[f], perpendicular(axes[f]));
          std::memcpy(lightBlock.shadowMatrices[layers + f], glm::value_ptr(m), 64);
        }
        l.colorFar[3] = far;
      } else if (type == kSpot) {
        float fov = std::min(2.0f * std::acos(std::clamp(l.params[0], -1.0f, 1.0f)) + 0.05f, 3.0f);
        glm::mat4 m = glm::perspective(fov, 1.0f, nearPlane, far) *
                      glm::lookAt(pos, pos + dir, perpendicular(dir));
        std::memcpy(lightBlock.shadowMatrices[layers], glm::value_ptr(m), 64);
        l.colorFar[3] = far;
      } else {
        // Cascades fitted to the camera's view each frame (fitCascades); until
        // the first frame, every cascade covers the whole scene.
        glm::vec3 eye = center - dir * (2.0f * radius);
        glm::mat4 m = glm::ortho(-radius, radius, -radius, radius, 0.0f, 4.0f * radius) *
                      glm::lookAt(eye, center, perpendicular(dir));
        for (int c = 0; c < kCascades; ++c) {
          std::memcpy(lightBlock.shadowMatrices[layers + c], glm::value_ptr(m), 64);
        }
        l.colorFar[3] = 0;
        sunLights.push_back(int(&l - lights.data()));
      }
      layers += need;
    }
    std::copy(lights.begin(), lights.end(), lightBlock.lights);
    lightBlock.lightCount[0] = int32_t(lights.size());
    lightBlock.lightCount[1] = int32_t(areaLightCount);  // appended last
    // Depth bias as a fraction of the far plane and a normal offset, both
    // about one shadow texel at the scene's scale.
    float texel = 2.0f * sceneSize / float(params.shadowMapSize);
    lightBlock.shadowParams[0] = 0.5f * texel / std::max(sceneSize, 1e-6f);
    lightBlock.shadowParams[1] = 1.5f * texel;

    glGenBuffers(1, &lightUbo);
    glBindBuffer(GL_UNIFORM_BUFFER, lightUbo);
    glBufferData(GL_UNIFORM_BUFFER, sizeof(LightBlock), &lightBlock, GL_STATIC_DRAW);
    glBindBuffer(GL_UNIFORM_BUFFER, 0);

    glGenTextures(1, &shadowTexture);
    glBindTexture(GL_TEXTURE_2D_ARRAY, shadowTexture);
    int size = layers > 0 ? params.shadowMapSize : 1;
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT24, size, size, std::max(layers, 1), 0,
                 GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
    checkGl("allocating the shadow maps");

    // The same maps read as plain depths (PCSS's blocker search): a sampler
    // object without comparison, bound to its own unit.
    glGenSamplers(1, &depthSampler);
    glSamplerParameteri(depthSampler, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glSamplerParameteri(depthSampler, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glSamplerParameteri(depthSampler, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glSamplerParameteri(depthSampler, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glSamplerParameteri(depthSampler, GL_TEXTURE_COMPARE_MODE, GL_NONE);

    glGenFramebuffers(1, &shadowFbo);
    glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo);
    glDrawBuffer(GL_NONE);
    glReadBuffer(GL_NONE);
    glViewport(0, 0, size, size);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glUseProgram(shadowProgram);
    glBindVertexArray(vao);
    for (int i = 0; i < lightBlock.lightCount[0]; ++i) {
      const GpuLight& l = lightBlock.lights[i];
      if (l.params[2] < 0) continue;
      int type = int(l.positionType[3]);
      int n = shadowLayersOf(type);
      glUniform3fv(glGetUniformLocation(shadowProgram, "uLightPosition"), 1, l.positionType);
      glUniform1f(glGetUniformLocation(shadowProgram, "uFar"), l.colorFar[3]);
      for (int f = 0; f < n; ++f) {
        int layer = int(l.params[2]) + f;
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, shadowTexture, 0, layer);
        if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
          throw GlError("shadow map framebuffer incomplete");
        }
        glClear(GL_DEPTH_BUFFER_BIT);
        glUniformMatrix4fv(glGetUniformLocation(shadowProgram, "uViewProj"), 1, GL_FALSE,
                           lightBlock.shadowMatrices[layer]);
        // Transmissive surfaces cast no shadow (light passes; not tinted).
        drawDepthOnly(shadowProgram, true);
      }
    }
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl("rendering the shadow maps");
  }

  /// Cascaded shadow maps of the directional lights (Engel 2006; Zhang et
  /// al. 2006, parallel-split): the camera's view depth up to the scene's far
  /// end is split into kCascades slices, half logarithmic and half uniform,
  /// and each slice's frustum gets its own orthographic map around the
  /// slice's bounding sphere (a square of the sphere's diameter, so the
  /// texel size does not change as the camera turns), its centre snapped to
  /// whole texels (no shimmer as the camera moves), its depth range the
  /// whole scene's along the light (casters outside the slice still cast).
  /// Re-renders those layers when the camera differs from the last fit.
  void fitCascades(const glm::vec3& eye, const glm::vec3& forward, const glm::vec3& up,
                   float yfov, float aspect, float znear, float zfar) {
    if (sunLights.empty()) return;
    const std::array<float, 12> key = {eye.x,     eye.y, eye.z, forward.x, forward.y, forward.z,
                                       up.x,      up.y,  up.z,  yfov,      aspect,    znear};
    if (key == fittedCamera) return;
    fittedCamera = key;
    const glm::vec3 center = toGlm(bounds.center());
    const float sceneRadius = 0.5f * sceneSize;
    // The slices end where the scene ends along the view.
    float farthest = 0;
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? bounds.upper.x : bounds.lower.x,
                             (c & 2) ? bounds.upper.y : bounds.lower.y,
                             (c & 4) ? bounds.upper.z : bounds.lower.z);
      farthest = std::max(farthest, glm::dot(corner - eye, forward));
    }
    const float n = std::max(znear, 1e-4f * sceneSize);
    const float f = std::max(std::min(zfar, farthest), 2.0f * n);
    float splits[kCascades + 1];
    splits[0] = n;
    for (int i = 1; i <= kCascades; ++i) {
      const float t = float(i) / float(kCascades);
      splits[i] = 0.5f * n * std::pow(f / n, t) + 0.5f * (n + (f - n) * t);
    }
    const float th = std::tan(0.5f * yfov), tw = th * aspect;
    glBindBuffer(GL_UNIFORM_BUFFER, lightUbo);
    for (int c = 0; c < kCascades; ++c) {
      // The slice's bounding sphere: centred on the view axis where it is
      // equidistant from the near and far corners.
      const float d0 = splits[c], d1 = splits[c + 1];
      const float k2 = tw * tw + th * th;
      float z = 0.5f * (d0 + d1) * (1.0f + k2);
      z = std::min(z, d1);
      const float r0 = std::sqrt((z - d0) * (z - d0) + d0 * d0 * k2);
      const float r1 = std::sqrt((d1 - z) * (d1 - z) + d1 * d1 * k2);
      float radius = std::max(r0, r1);
      glm::vec3 sphere = eye + forward * z;
      if (radius >= sceneRadius) {
        radius = sceneRadius;
        sphere = center;
      }
      cascadeFar[c] = c + 1 == kCascades ? 1e30f : d1;
      cascadeTexel[c] = 2.0f * radius / float(params.shadowMapSize);
      for (int light : sunLights) {
        const GpuLight& l = lightBlock.lights[light];
        const glm::vec3 dir(l.directionRange[0], l.directionRange[1], l.directionRange[2]);
        const glm::mat4 view0 = glm::lookAt(glm::vec3(0.0f), dir, perpendicular(dir));
        // Snap the centre to whole texels in the light's view plane.
        glm::vec3 ls = glm::vec3(view0 * glm::vec4(sphere, 1.0f));
        ls.x = std::floor(ls.x / cascadeTexel[c]) * cascadeTexel[c];
        ls.y = std::floor(ls.y / cascadeTexel[c]) * cascadeTexel[c];
        const glm::vec3 snapped = glm::vec3(glm::inverse(view0) * glm::vec4(ls, 1.0f));
        // Depth: the whole scene along the light, from the map's centre.
        float before = 0, after = 0;
        for (int k = 0; k < 8; ++k) {
          const glm::vec3 corner((k & 1) ? bounds.upper.x : bounds.lower.x,
                                 (k & 2) ? bounds.upper.y : bounds.lower.y,
                                 (k & 4) ? bounds.upper.z : bounds.lower.z);
          const float along = glm::dot(corner - snapped, dir);
          before = std::max(before, -along);
          after = std::max(after, along);
        }
        const float margin = 1e-3f * sceneSize;
        const glm::vec3 lightEye = snapped - dir * (before + margin);
        cascadeDepth[c] = before + after + 2.0f * margin;
        const glm::mat4 m =
            glm::ortho(-radius, radius, -radius, radius, 0.0f, cascadeDepth[c]) *
            glm::lookAt(lightEye, snapped, perpendicular(dir));
        const int layer = int(l.params[2]) + c;
        std::memcpy(lightBlock.shadowMatrices[layer], glm::value_ptr(m), 64);
        glBufferSubData(GL_UNIFORM_BUFFER, GLintptr(offsetof(LightBlock, shadowMatrices) + 64 * size_t(layer)),
                        64, lightBlock.shadowMatrices[layer]);
      }
    }
    glBindBuffer(GL_UNIFORM_BUFFER, 0);
    // Render the cascades' layers.
    GLint previous = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
    glBindFramebuffer(GL_FRAMEBUFFER, shadowFbo);
    glViewport(0, 0, params.shadowMapSize, params.shadowMapSize);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glUseProgram(shadowProgram);
    glBindVertexArray(vao);
    glUniform1f(glGetUniformLocation(shadowProgram, "uFar"), 0.0f);
    for (int light : sunLights) {
      const GpuLight& l = lightBlock.lights[light];
      for (int c = 0; c < kCascades; ++c) {
        const int layer = int(l.params[2]) + c;
        glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, shadowTexture, 0, layer);
        glClear(GL_DEPTH_BUFFER_BIT);
        glUniformMatrix4fv(glGetUniformLocation(shadowProgram, "uViewProj"), 1, GL_FALSE,
                           lightBlock.shadowMatrices[layer]);
        drawDepthOnly(shadowProgram, true);
      }
    }
    glBindVertexArray(0);
    glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous));
    checkGl("rendering the cascaded shadow maps");
  }

  /// Renders the probe's six faces (90-degree views from the scene's centre,
  /// GL's cube-face orientations) with the full scene program, reflections
  /// off, then builds the mip chain that rough surfaces read (box-filtered
  /// mips: a blur that grows with roughness, not a GGX prefilter).
  void captureProbe(const RenderParams& rp) {
    const int size = params.probeSize;
    if (!probeTexture) {
      glGenTextures(1, &probeTexture);
      glBindTexture(GL_TEXTURE_CUBE_MAP, probeTexture);
      probeLevels = 1;
      while ((size >> probeLevels) > 0) ++probeLevels;
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
      glGenFramebuffers(1, &probeFbo);
      glGenRenderbuffers(1, &probeDepth);
      glBindRenderbuffer(GL_RENDERBUFFER, probeDepth);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, size, size);
      checkGl("allocating the reflection probe");
    }
    GLint previous = 0;
    glGetIntegerv(GL_FRAMEBUFFER_BINDING, &previous);
    glBindFramebuffer(GL_FRAMEBUFFER, probeFbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, probeDepth);
    const Vec3 forward[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const Vec3 up[6] = {{0, -1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}, {0, -1, 0}, {0, -1, 0}};
    RenderParams face = rp;
    face.mode = RenderMode::Full;
    face.reflections = false;
    capturingProbe = true;
    for (int f = 0; f < 6; ++f) {
      glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0,
                             GLenum(GL_TEXTURE_CUBE_MAP_POSITIVE_X + f), probeTexture, 0);
      GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
      glDrawBuffers(1, &drawBuffer);
      if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
        capturingProbe = false;
        throw GlError("reflection probe framebuffer incomplete");
      }
      PinholeCamera camera;
      camera.eye = renderOrigin;  // render space (0, 0, 0): the scene's centre
      camera.forward = forward[f];
      camera.up = up[f];
      camera.yfov = 0.5f * kPi;
      camera.znear = 1e-3f * sceneSize;
      camera.zfar = 2.0f * sceneSize;
      draw(camera, face, size, size, 1.0f, false);
    }
    capturingProbe = false;
    glBindTexture(GL_TEXTURE_CUBE_MAP, probeTexture);
    glGenerateMipmap(GL_TEXTURE_CUBE_MAP);
    glBindFramebuffer(GL_FRAMEBUFFER, GLuint(previous));
    probeValid = true;
    checkGl("capturing the reflection probe");
  }

  /// The geometry of a depth-only pass (depth pre-pass or shadow map) with
  /// `program` in use: the solid ranges in one call, then the masked ranges
  /// alpha-tested one by one, and with `shadows` (a shadow map) the blended
  /// ranges too (a shadow map has no partial coverage: they cast a shadow
  /// where their alpha is at least 1/2) and the transmissive ones with a
  /// volume (a solid glass body focuses what it lets through into a caustic,
  /// which the photon map carries as indirect light: its direct shadow is
  /// dark). Thin-walled transmissive ranges cast no shadow: light passes
  /// them straight, as direct light (the photon tracer agrees).
  void drawDepthOnly(GLuint program, bool shadows) {
    const GLint alphaTest = glGetUniformLocation(program, "uAlphaTest");
    glUniform1i(alphaTest, 0);
    glDrawArrays(GL_TRIANGLES, 0, opaqueCount);
    glUniform1i(glGetUniformLocation(program, "uBaseColorTexture"), 4);
    const GLint hasTexture = glGetUniformLocation(program, "uHasBaseColorTexture");
    const GLint baseAlpha = glGetUniformLocation(program, "uBaseAlpha");
    const GLint cutoff = glGetUniformLocation(program, "uAlphaCutoff");
    for (size_t i = 0; i < ranges.size(); ++i) {
      const DrawRange& range = ranges[i];
      if (rangeCategory[i] != kMasked && !(shadows && rangeCategory[i] == kBlended)) continue;
      glUniform1i(alphaTest, 1);
      glUniform1i(hasTexture, range.texture >= 0 ? 1 : 0);
      glUniform1f(baseAlpha, range.baseAlpha);
      glUniform1f(cutoff, rangeCategory[i] == kMasked ? range.alphaCutoff : 0.5f);
      glActiveTexture(GL_TEXTURE4);
      glBindTexture(GL_TEXTURE_2D, range.texture >= 0 ? textures[size_t(range.texture)] : 0);
      glDrawArrays(GL_TRIANGLES, range.first, range.count);
    }
    if (shadows) {
      glUniform1i(alphaTest, 0);
      for (size_t i = 0; i < ranges.size(); ++i) {
        if (rangeCategory[i] == kTransmissive && ranges[i].thickness > 0) {
          glDrawArrays(GL_TRIANGLES, ranges[i].first, ranges[i].count);
        }
      }
    }
    glActiveTexture(GL_TEXTURE0);
  }

  /// Writes the blended triangles' vertex indices into blendEbo, each
  /// range's triangles from the farthest to the nearest centroid (render
  /// space distance to `eye`): the order in which blending composes them.
  void sortBlended(const glm::vec3& eye) {
    if (blendCentroids.empty()) return;
    std::vector<uint32_t> order(blendCentroids.size());
    std::vector<float> distance(blendCentroids.size());
    for (size_t t = 0; t < blendCentroids.size(); ++t) {
      order[t] = uint32_t(t);
      const glm::vec3 d = blendCentroids[t] - eye;
      distance[t] = glm::dot(d, d);
    }
    std::vector<uint32_t> indices(3 * order.size());
    size_t tri = 0;
    for (size_t i = 0; i < ranges.size(); ++i) {
      if (rangeCategory[i] != kBlended) continue;
      const size_t begin = size_t(ranges[i].first - blendFirst) / 3;
      const size_t end = begin + size_t(ranges[i].count) / 3;
      std::stable_sort(order.begin() + long(begin), order.begin() + long(end),
                       [&](uint32_t a, uint32_t b) { return distance[a] > distance[b]; });
      for (size_t k = begin; k < end; ++k, ++tri) {
        for (uint32_t c = 0; c < 3; ++c) indices[3 * tri + c] = uint32_t(blendFirst) + 3 * order[k] + c;
      }
    }
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, blendEbo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)),
                 indices.data(), GL_STREAM_DRAW);
  }

  void ensureTarget(int width, int height) {
    if (targetFbo && width == targetWidth && height == targetHeight) return;
    if (!targetFbo) {
      glGenFramebuffers(1, &targetFbo);
      glGenTextures(1, &targetColor);
      glGenRenderbuffers(1, &targetDepth);
    }
    glBindTexture(GL_TEXTURE_2D, targetColor);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, width, height, 0, GL_RGBA, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glBindRenderbuffer(GL_RENDERBUFFER, targetDepth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, targetFbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, targetColor, 0);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, targetDepth);
    GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
    glDrawBuffers(1, &drawBuffer);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw GlError("render target framebuffer (RGBA32F " + texelCount(width, height, 0) +
                    ") incomplete");
    }
    targetWidth = width;
    targetHeight = height;
  }

  /// Copies the bound framebuffer's colour into behindTexture (float for
  /// the offscreen RGBA32F target, 8-bit for a window's back buffer).
  void copyBehind(int width, int height, bool floatTarget) {
    if (!behindTexture || behindWidth != width || behindHeight != height ||
        behindFloat != floatTarget) {
      if (!behindTexture) glGenTextures(1, &behindTexture);
      glBindTexture(GL_TEXTURE_2D, behindTexture);
      glTexImage2D(GL_TEXTURE_2D, 0, floatTarget ? GL_RGBA32F : GL_RGBA8, width, height, 0,
                   GL_RGBA, floatTarget ? GL_FLOAT : GL_UNSIGNED_BYTE, nullptr);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
      behindWidth = width;
      behindHeight = height;
      behindFloat = floatTarget;
    }
    glBindTexture(GL_TEXTURE_2D, behindTexture);
    glCopyTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, 0, 0, width, height);
    checkGl("copying the opaque image for transmissive surfaces");
  }

  void draw(const PinholeCamera& camera, const RenderParams& rp, int width, int height,
            float exposureScale, bool encodeSrgb) {
    if (width < 1 || height < 1) throw InputError("render: image size must be at least 1 x 1");
    if (rp.maxVdls < 1 || rp.maxVdls > kMaxVdls) {
      throw InputError("render: VDLs per voxel must be 1.." + std::to_string(kMaxVdls) + ", got " +
                       std::to_string(rp.maxVdls));
    }
    // The probe shows the lit scene: captured before the first frame that
    // reflects it (it draws six frames of its own through this function).
    const bool reflect = rp.reflections && probeWanted && !capturingProbe &&
                         (rp.mode == RenderMode::Full || rp.mode == RenderMode::Indirect);
    if (reflect && !probeValid) captureProbe(rp);
    const Vec3 eyeRender = toRender(camera.eye);
    glm::vec3 eye = toGlm(eyeRender);
    float zfar = camera.zfar > 0 ? camera.zfar
                                 : glm::length(eye - toGlm(bounds.center())) + sceneSize + 1e-3f;
    float znear = std::min(camera.znear > 0 ? camera.znear : 0.01f, 0.5f * zfar);
    glm::mat4 viewProj = glm::perspective(camera.yfov, float(width) / float(height), znear, zfar) *
                         glm::lookAt(eye, eye + toGlm(camera.forward), toGlm(camera.up));
    if (rp.mode == RenderMode::Full || rp.mode == RenderMode::Direct) {
      fitCascades(eye, glm::normalize(toGlm(camera.forward)), toGlm(camera.up), camera.yfov,
                  float(width) / float(height), znear, zfar);
    }

    glViewport(0, 0, width, height);
    glClearColor(0, 0, 0, 1);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glEnable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    // Depth pre-pass: the scene shader then shades each pixel once, not once
    // per overlapping surface. It pays where shading is dear (shadow lookups
    // of the direct pass, 8-voxel interpolation); for the cheap modes the
    // second geometry pass costs more than the overdraw it saves (measured,
    // docs/results/render.md), so they draw with a plain depth test.
    const bool prePass =
        rp.interpolation || rp.mode == RenderMode::Full || rp.mode == RenderMode::Direct;
    glDepthFunc(GL_LESS);
    if (prePass) {
      glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
      glUseProgram(depthProgram);
      glUniformMatrix4fv(glGetUniformLocation(depthProgram, "uViewProj"), 1, GL_FALSE,
                         glm::value_ptr(viewProj));
      glBindVertexArray(vao);
      drawDepthOnly(depthProgram, false);
      glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
      glDepthFunc(GL_LEQUAL);
      glDepthMask(GL_FALSE);
    }
    const bool withDirect = rp.mode == RenderMode::Full || rp.mode == RenderMode::Direct;
    const bool atlasProgram = rp.lighting == Lighting::Atlas && !capturingProbe &&
                              rp.mode != RenderMode::Voxels && atlasVbo;
    if (atlasProgram && !sceneAtlasProgram) {
      sceneAtlasProgram = buildProgram({"render_scene.vert", "render_scene.frag"},
                                       {"LO_DIRECT_LIGHT", "LO_ATLAS_LIGHTING"});
      glUniformBlockBinding(sceneAtlasProgram,
                            glGetUniformBlockIndex(sceneAtlasProgram, "LightBlock"), 0);
      sceneIndirectAtlasProgram =
          buildProgram({"render_scene.vert", "render_scene.frag"}, {"LO_ATLAS_LIGHTING"});
    }
    GLuint p = atlasProgram ? (withDirect ? sceneAtlasProgram : sceneIndirectAtlasProgram)
                            : (withDirect ? sceneProgram : sceneIndirectProgram);
    glUseProgram(p);
    auto loc = [p](const char* name) { return glGetUniformLocation(p, name); };
    glUniformMatrix4fv(loc("uViewProj"), 1, GL_FALSE, glm::value_ptr(viewProj));
    glUniform3f(loc("uOctreeOrigin"), octreeOrigin.x, octreeOrigin.y, octreeOrigin.z);
    glUniform1f(loc("uVoxelSize"), voxelSize);
    glUniform1i(loc("uDepth"), depth);
    glUniform3f(loc("uEye"), eyeRender.x, eyeRender.y, eyeRender.z);
    glUniform1i(loc("uMode"), shaderMode(rp.mode));
    const glm::vec3 forward = glm::normalize(toGlm(camera.forward));
    glUniform3f(loc("uViewForward"), forward.x, forward.y, forward.z);
    glUniform4fv(loc("uCascadeFar"), 1, cascadeFar);
    glUniform4fv(loc("uCascadeTexel"), 1, cascadeTexel);
    glUniform4fv(loc("uCascadeDepth"), 1, cascadeDepth);
    if (rp.lighting == Lighting::Atlas && !atlasVbo) {
      throw InputError("render: lighting 'atlas' needs an atlas (Renderer::setAtlas, or "
                       "`render --lighting atlas`, which bakes one)");
    }
    const bool atlas = rp.lighting == Lighting::Atlas && !capturingProbe;
    // The probe leaves out emitters that the direct pass draws as lights:
    // their reflection comes from the lights' specular term already.
    glUniform1f(loc("uEmissionScale"),
                capturingProbe && (areaLightCount > 0 || emitterLights > 0) ? 0.0f : 1.0f);
    glUniform1i(loc("uAtlas"), atlas ? 1 : 0);
    glUniform1i(loc("uAtlasIrradiance"), 12);
    glUniform1i(loc("uAtlasDirection"), 13);
    glActiveTexture(GL_TEXTURE12);
    glBindTexture(GL_TEXTURE_2D_ARRAY, atlas ? atlasIrradiance : 0);
    glActiveTexture(GL_TEXTURE13);
    glBindTexture(GL_TEXTURE_2D_ARRAY, atlas ? atlasDirection : 0);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(loc("uHasProbe"), reflect ? 1 : 0);
    glUniform1i(loc("uProbe"), 11);
    glUniform3f(loc("uProbeBoxMin"), bounds.lower.x, bounds.lower.y, bounds.lower.z);
    glUniform3f(loc("uProbeBoxMax"), bounds.upper.x, bounds.upper.y, bounds.upper.z);
    glUniform1f(loc("uProbeMaxLod"), float(probeLevels - 1));
    glActiveTexture(GL_TEXTURE11);
    glBindTexture(GL_TEXTURE_CUBE_MAP, reflect ? probeTexture : 0);
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
    glBindTexture(GL_TEXTURE_2D_ARRAY, shadowTexture);
    glActiveTexture(GL_TEXTURE0);
    glUniform1i(loc("uBaseColorTexture"), 4);
    glUniform1i(loc("uShadowDepths"), 5);
    glActiveTexture(GL_TEXTURE5);
    glBindTexture(GL_TEXTURE_2D_ARRAY, shadowTexture);
    glBindSampler(5, depthSampler);
    glActiveTexture(GL_TEXTURE0);
    glBindBufferBase(GL_UNIFORM_BUFFER, 0, lightUbo);
    glBindVertexArray(vao);
    const GLint hasTexture = loc("uHasBaseColorTexture");
    const GLint hasNormal = loc("uHasNormalTexture");
    const GLint normalScale = loc("uNormalScale");
    glUniform1i(loc("uNormalTexture"), 7);
    glUniform1i(loc("uMetallicRoughnessTexture"), 8);
    glUniform1i(loc("uOcclusionTexture"), 9);
    const GLint hasMr = loc("uHasMetallicRoughnessTexture");
    const GLint hasOcclusion = loc("uHasOcclusionTexture");
    const GLint occlusionStrength = loc("uOcclusionStrength");
    const GLint transmission = loc("uTransmission");
    glUniform1i(loc("uBehind"), 6);
    glUniform1i(loc("uEmissiveTexture"), 10);
    const GLint hasEmissive = loc("uHasEmissiveTexture");
    const GLint alphaMode = loc("uAlphaMode");
    const GLint baseAlpha = loc("uBaseAlpha");
    const GLint alphaCutoff = loc("uAlphaCutoff");
    const GLint thickness = loc("uThickness");
    const GLint ior = loc("uIor");
    glUniform1f(transmission, 0.0f);
    // glTF: single-sided materials are culled from behind (counter-clockwise
    // winding in front, as the loader keeps it).
    glFrontFace(GL_CCW);
    glCullFace(GL_BACK);
    bool copied = false, blending = false;
    for (size_t i = 0; i < ranges.size(); ++i) {
      const DrawRange& range = ranges[i];
      const bool blended = rangeCategory[i] == kBlended;
      if (blended && !blending) {
        // Over the opaque scene, back to front, without depth writes.
        sortBlended(eye);
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
        glActiveTexture(GL_TEXTURE6);
        glBindTexture(GL_TEXTURE_2D, behindTexture);
        glDepthMask(GL_TRUE);  // the nearest transmissive surface wins
        glDepthFunc(GL_LESS);
        copied = true;
      }
      auto bind = [this](GLenum unit, int texture) {
        glActiveTexture(unit);
        glBindTexture(GL_TEXTURE_2D, texture >= 0 ? textures[size_t(texture)] : 0);
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
      bind(GL_TEXTURE10, range.emissiveTexture);
      glActiveTexture(GL_TEXTURE0);
      glUniform1i(hasEmissive, range.emissiveTexture >= 0 ? 1 : 0);
      glUniform1i(alphaMode, range.alphaMode);
      glUniform1f(baseAlpha, range.baseAlpha);
      glUniform1f(alphaCutoff, range.alphaCutoff);
      if (range.doubleSided) {
        glDisable(GL_CULL_FACE);
      } else {
        glEnable(GL_CULL_FACE);
      }
      if (blended) {
        glDrawElements(GL_TRIANGLES, range.count, GL_UNSIGNED_INT,
                       reinterpret_cast<const void*>(size_t(range.first - blendFirst) * 4));
      } else {
        glDrawArrays(GL_TRIANGLES, range.first, range.count);
      }
    }
    if (blending) glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    glBindVertexArray(0);
    glBindSampler(5, 0);
    glDepthMask(GL_TRUE);
    glDepthFunc(GL_LESS);
    checkGl("drawing the scene");
  }
};

Renderer::Renderer(const Scene& scene, const GpuOctree& octree, const RendererParams& params)
    : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.params = params;
  if (params.shadowMapSize < 1 || params.shadowMapSize > 16384) {
    throw InputError("shadow map size must be 1..16384, got " +
                     std::to_string(params.shadowMapSize));
  }
  if (params.emitterLights < 0) throw InputError("emitter lights must be >= 0");
  if (params.probeSize < 4 || params.probeSize > 4096) {
    throw InputError("reflection probe size must be 4..4096, got " +
                     std::to_string(params.probeSize));
  }
  OctreeTextures::checkLimits(octree, params.max3DTextureSize, params.max2DTextureSize);
  Bounds3 world = scene.bounds();
  if (world.empty()) world.extend(Vec3(0, 0, 0));
  r.renderOrigin = world.center();
  r.bounds.extend(r.toRender(world.lower));
  r.bounds.extend(r.toRender(world.upper));
  r.sceneSize = std::max(length(r.bounds.extent()), 1e-3f);
  r.sceneProgram = buildProgram({"render_scene.vert", "render_scene.frag"}, {"LO_DIRECT_LIGHT"});
  glUniformBlockBinding(r.sceneProgram, glGetUniformBlockIndex(r.sceneProgram, "LightBlock"), 0);
  r.sceneIndirectProgram = buildProgram({"render_scene.vert", "render_scene.frag"});
  r.shadowProgram = buildProgram({"render_shadow.vert", "render_shadow.frag"});
  r.depthProgram = buildProgram({"render_depth.vert", "render_depth.frag"});
  r.uploadOctree(octree);
  r.uploadScene(scene);
  r.sceneTriangles = scene.triangleCount();
  r.setupLights(scene);
  for (const Material& m : scene.materials) {
    r.probeWanted = r.probeWanted || m.roughness < shader::LO_PROBE_NONE ||
                    m.metallicRoughnessTexture >= 0;
  }
}

bool Renderer::hasReflectionProbe() const { return impl_->probeWanted; }

bool Renderer::hasAtlas() const { return impl_->atlasVbo != 0; }

size_t Renderer::atlasBytes() const { return impl_->atlasTextureBytes; }

void Renderer::setAtlas(const LightmapUvs& uvs, const LightmapAtlas& atlas) {
  Impl& r = *impl_;
  const size_t triangles = r.sceneTriangles;
  if (uvs.uv.size() != 6 * triangles || uvs.trianglePage.size() != triangles) {
    throw InputError("atlas: lightmap UVs for " + std::to_string(uvs.trianglePage.size()) +
                     " triangles, the scene has " + std::to_string(triangles));
  }
  if (atlas.pageCount < 1 || atlas.width < 1 || atlas.height < 1 ||
      atlas.irradiance.size() != size_t(atlas.pageCount) ||
      atlas.direction.size() != size_t(atlas.pageCount)) {
    throw InputError("atlas: no pages to upload");
  }
  GLint maxSize = 0, maxLayers = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxSize);
  glGetIntegerv(GL_MAX_ARRAY_TEXTURE_LAYERS, &maxLayers);
  if (atlas.width > maxSize || atlas.height > maxSize || atlas.pageCount > maxLayers) {
    throw InputError("atlas of " + std::to_string(atlas.pageCount) + " pages of " +
                     texelCount(atlas.width, atlas.height, 0) +
                     " texels exceeds GL_MAX_TEXTURE_SIZE = " + std::to_string(maxSize) +
                     " or GL_MAX_ARRAY_TEXTURE_LAYERS = " + std::to_string(maxLayers));
  }
  // Per vertex: the lightmap UV of its triangle corner and the page.
  std::vector<float> attribute(3 * r.vertexCorner.size());
  for (size_t i = 0; i < r.vertexCorner.size(); ++i) {
    const size_t t = r.vertexCorner[i] / 3, k = r.vertexCorner[i] % 3;
    attribute[3 * i] = uvs.uv[6 * t + 2 * k];
    attribute[3 * i + 1] = uvs.uv[6 * t + 2 * k + 1];
    attribute[3 * i + 2] = float(uvs.trianglePage[t]);
  }
  if (!r.atlasVbo) glGenBuffers(1, &r.atlasVbo);
  glBindVertexArray(r.vao);
  glBindBuffer(GL_ARRAY_BUFFER, r.atlasVbo);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(attribute.size() * sizeof(float)),
               attribute.empty() ? nullptr : attribute.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(10);
  glVertexAttribPointer(10, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindVertexArray(0);
  // Pages as layers: bilinear, no mipmaps (they would bleed across charts).
  auto upload = [&](GLuint& texture, GLenum format, const std::vector<RgbImage>& pages,
                    bool clampNegative) {
    if (!texture) glGenTextures(1, &texture);
    glBindTexture(GL_TEXTURE_2D_ARRAY, texture);
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GLint(format), atlas.width, atlas.height,
                 atlas.pageCount, 0, GL_RGB, GL_FLOAT, nullptr);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    for (int p = 0; p < atlas.pageCount; ++p) {
      std::vector<float> texels = pages[size_t(p)].rgb;
      if (clampNegative) {
        for (float& v : texels) v = std::max(v, 0.0f);  // stitching may dip the gutter below 0
      }
      glTexSubImage3D(GL_TEXTURE_2D_ARRAY, 0, 0, 0, p, atlas.width, atlas.height, 1, GL_RGB,
                      GL_FLOAT, texels.data());
    }
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D_ARRAY, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  };
  upload(r.atlasIrradiance, GL_RGB9_E5, atlas.irradiance, true);
  upload(r.atlasDirection, GL_RGBA8_SNORM, atlas.direction, false);
  r.atlasTextureBytes = size_t(atlas.width) * size_t(atlas.height) * size_t(atlas.pageCount) * 8;
  checkGl("uploading the lightmap atlas");
}

Renderer::~Renderer() = default;

int Renderer::emitterLightCount() const { return impl_->emitterLights; }

int Renderer::areaLightCount() const { return impl_->areaLightCount; }

void Renderer::setOctree(const GpuOctree& octree) {
  impl_->uploadOctree(octree);
  impl_->probeValid = false;  // it shows the old octree's light
}

RgbImage Renderer::render(const PinholeCamera& camera, const RenderParams& params) {
  Impl& r = *impl_;
  const int s = params.supersample;
  if (s < 1 || s > 16) {
    throw InputError("render: supersampling must be 1..16, got " + std::to_string(s));
  }
  const int w = params.width * s, h = params.height * s;
  r.ensureTarget(w, h);
  glBindFramebuffer(GL_FRAMEBUFFER, r.targetFbo);
  r.draw(camera, params, w, h, 1.0f, false);
  std::vector<float> raw(size_t(w) * size_t(h) * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, raw.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGl("reading back the image");
  // GL rows go bottom-up; image rows top-down. Alpha is dropped; each output
  // pixel is the mean of its s x s block.
  RgbImage image(params.width, params.height);
  const float norm = 1.0f / float(s * s);
  for (int y = 0; y < params.height; ++y) {
    float* dst = image.rgb.data() + size_t(y) * size_t(params.width) * 3;
    for (int sy = 0; sy < s; ++sy) {
      const float* src = raw.data() + size_t(h - 1 - (y * s + sy)) * size_t(w) * 4;
      for (int x = 0; x < params.width; ++x) {
        for (int sx = 0; sx < s; ++sx) {
          for (int c = 0; c < 3; ++c) dst[3 * x + c] += src[4 * (x * s + sx) + c] * norm;
        }
      }
    }
  }
  return image;
}

void Renderer::drawToScreen(const PinholeCamera& camera, const RenderParams& params,
                            float exposure) {
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  impl_->draw(camera, params, params.width, params.height, std::exp2(exposure), true);
}

double Renderer::timeFrames(const PinholeCamera& camera, const RenderParams& params, int frames) {
  Impl& r = *impl_;
  r.ensureTarget(params.width, params.height);
  glBindFramebuffer(GL_FRAMEBUFFER, r.targetFbo);
  r.draw(camera, params, params.width, params.height, 1.0f, false);  // warm-up
  glFinish();
  auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < frames; ++i) {
    r.draw(camera, params, params.width, params.height, 1.0f, false);
    glFinish();
  }
  auto stop = std::chrono::steady_clock::now();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return std::chrono::duration<double>(stop - start).count();
}

void compileAllShaders() {
  for (const std::vector<std::string>& files : allPrograms()) {
    glDeleteProgram(buildProgram(files));
  }
  glDeleteProgram(buildProgram({"render_scene.vert", "render_scene.frag"}, {"LO_DIRECT_LIGHT"}));
  glDeleteProgram(buildProgram({"render_scene.vert", "render_scene.frag"},
                               {"LO_DIRECT_LIGHT", "LO_ATLAS_LIGHTING"}));
  glDeleteProgram(buildProgram({"render_scene.vert", "render_scene.frag"}, {"LO_ATLAS_LIGHTING"}));
}

std::vector<std::array<float, 4>> runLayoutProbe(LayoutProbe function,
                                                 const std::vector<std::array<float, 4>>& inputs) {
  int n = int(inputs.size());
  std::vector<std::array<float, 4>> out(inputs.size());
  if (n == 0) return out;
  GLuint program = buildProgram({"render_fullscreen.vert", "render_layout_probe.frag"});
  GLuint textures[2], fbo, vao;
  glGenTextures(2, textures);
  glBindTexture(GL_TEXTURE_2D, textures[0]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, n, 1, 0, GL_RGBA, GL_FLOAT, inputs.data());
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glBindTexture(GL_TEXTURE_2D, textures[1]);
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA32F, n, 1, 0, GL_RGBA, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, textures[1], 0);
  GLenum drawBuffer = GL_COLOR_ATTACHMENT0;
  glDrawBuffers(1, &drawBuffer);
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glViewport(0, 0, n, 1);
  glDisable(GL_DEPTH_TEST);
  glUseProgram(program);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, textures[0]);
  glUniform1i(glGetUniformLocation(program, "uInputs"), 0);
  glUniform1i(glGetUniformLocation(program, "uFunction"), int(function));
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, n, 1, GL_RGBA, GL_FLOAT, out.data());
  glBindVertexArray(0);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  glDeleteVertexArrays(1, &vao);
  glDeleteFramebuffers(1, &fbo);
  glDeleteTextures(2, textures);
  glDeleteProgram(program);
  checkGl("layout probe");
  return out;
}

}  // namespace lo
