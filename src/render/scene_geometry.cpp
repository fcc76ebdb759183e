// The scene on the GPU: one vertex buffer grouped by material in draw order,
// the materials' textures, and the depth-only draws the pre-pass and the
// shadow maps share.

#include <glad/gl.h>

#include <algorithm>
#include <cstring>
#include <glm/gtc/type_ptr.hpp>

#include "core/error.h"
#include "core/resources.h"
#include "render/gl_util.h"
#include "render/renderer_impl.h"
#include "scene/texture_mips.h"

namespace lo::render_internal {
namespace {

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
  // Unlit surfaces are drawn range by range in depth passes, as masked
  // ones are: the camera's pre-pass has them, the shadow maps do not.
  if (m.alphaMode == AlphaMode::Mask || m.unlit) return kMasked;
  return kSolid;
}

}  // namespace

/// Uploads a texture with its glTF sampler's filters and wrap modes; mipmaps
/// and anisotropic filtering where the minification filter uses mipmaps
/// (glTF's default). `read` is the channels the scene shader reads of it
/// (kReadR | ...). 8-bit texels go up as they are stored: sRGB colour maps
/// as GL_SRGB8_ALPHA8, whose fetches the GPU decodes to linear before it
/// filters (as Texture::lookup does), data maps as GL_RGBA8, or as GL_R8
/// (occlusion: R read) and GL_RG8 swizzled back to .gb (metallic-roughness:
/// G and B read), a quarter and a half of the bytes. 16-bit and float
/// texels go up as linear half floats.
GlTexture SceneGeometry::uploadTexture(const Texture& t, unsigned read) {
  GlTexture id = GlTexture::create();
  glBindTexture(GL_TEXTURE_2D, id.get());
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  // The glTF sampler (its codes are OpenGL's); an undefined minFilter is
  // trilinear, as glTF viewers draw it.
  const TextureSampler& sampler = t.sampler;
  const GLint minFilter = sampler.minFilter ? sampler.minFilter : GL_LINEAR_MIPMAP_LINEAR;
  const bool mipmapped = minFilter != GL_NEAREST && minFilter != GL_LINEAR;
  // The base level, and its mip levels built on the CPU (scene/texture_mips.h):
  // a software rasteriser's glGenerateMipmap draws them on one thread.
  auto upload8 = [&](const uint8_t* texels, int channels, GLint internal, GLenum format) {
    glTexImage2D(GL_TEXTURE_2D, 0, internal, t.width, t.height, 0, format, GL_UNSIGNED_BYTE,
                 texels);
    if (!mipmapped) return;
    const bool srgb = internal == GL_SRGB8_ALPHA8;
    const std::vector<MipLevel<uint8_t>> levels =
        mipLevels(texels, t.width, t.height, channels, srgb);
    for (size_t l = 0; l < levels.size(); ++l) {
      glTexImage2D(GL_TEXTURE_2D, GLint(l + 1), internal, levels[l].width, levels[l].height, 0,
                   format, GL_UNSIGNED_BYTE, levels[l].texels.data());
    }
  };
  const size_t n = t.texelCount(), c = size_t(t.channels);
  size_t texelBytes = 4;
  if (t.format == TexelFormat::Unorm8) {
    // A grey value is its texel's R, G and B.
    auto channel = [&](size_t i, int k) { return t.unorm8[i * c + (c >= 3 ? size_t(k) : 0)]; };
    if (!t.srgb && (read & ~kReadR) == 0) {
      std::vector<uint8_t> r(n);
      for (size_t i = 0; i < n; ++i) r[i] = channel(i, 0);
      upload8(r.data(), 1, GL_R8, GL_RED);
      texelBytes = 1;
    } else if (!t.srgb && (read & ~(kReadG | kReadB)) == 0) {
      std::vector<uint8_t> gb(2 * n);
      for (size_t i = 0; i < n; ++i) {
        gb[2 * i] = channel(i, 1);
        gb[2 * i + 1] = channel(i, 2);
      }
      upload8(gb.data(), 2, GL_RG8, GL_RG);
      const GLint swizzle[4] = {GL_ZERO, GL_RED, GL_GREEN, GL_ONE};
      glTexParameteriv(GL_TEXTURE_2D, GL_TEXTURE_SWIZZLE_RGBA, swizzle);
      texelBytes = 2;
    } else if (c == 3 || c == 4) {
      // RGB and RGBA go up as they are (the driver adds RGB's alpha).
      upload8(t.unorm8.data(), int(c), t.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8,
              c == 3 ? GL_RGB : GL_RGBA);
    } else {
      // Grey (and grey + alpha) spread to RGBA.
      std::vector<uint8_t> rgba(n * 4);
      for (size_t i = 0; i < n; ++i) {
        const uint8_t* p = t.unorm8.data() + i * c;
        rgba[4 * i] = rgba[4 * i + 1] = rgba[4 * i + 2] = p[0];
        rgba[4 * i + 3] = t.hasAlpha() ? p[c - 1] : 255;
      }
      upload8(rgba.data(), 4, t.srgb ? GL_SRGB8_ALPHA8 : GL_RGBA8, GL_RGBA);
    }
  } else {
    // Half floats: linear colour with 11 bits of precision, filterable and
    // mipmappable on every GL 3.3 context.
    std::vector<float> rgba(n * 4);
    for (size_t i = 0; i < n; ++i) {
      const int x = int(i % size_t(t.width)), y = int(i / size_t(t.width));
      const Vec3 v = t.texel(x, y);
      rgba[4 * i] = v.x;
      rgba[4 * i + 1] = v.y;
      rgba[4 * i + 2] = v.z;
      rgba[4 * i + 3] = t.texelAlpha(x, y);
    }
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA16F, t.width, t.height, 0, GL_RGBA, GL_FLOAT,
                 rgba.data());
    if (mipmapped) {
      const std::vector<MipLevel<float>> levels = mipLevels(rgba.data(), t.width, t.height, 4);
      for (size_t l = 0; l < levels.size(); ++l) {
        glTexImage2D(GL_TEXTURE_2D, GLint(l + 1), GL_RGBA16F, levels[l].width, levels[l].height,
                     0, GL_RGBA, GL_FLOAT, levels[l].texels.data());
      }
    }
    texelBytes = 8;
  }
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  const size_t levelBytes = t.texelCount() * texelBytes;
  textureBytes += mipmapped ? levelBytes + levelBytes / 3 : levelBytes;
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, minFilter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, sampler.magFilter);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, sampler.wrapS);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, sampler.wrapT);
  // Anisotropic filtering only where the sampler filters linearly: some
  // drivers (llvmpipe) let it override a NEAREST magnification filter.
  if (maxAnisotropy > 1 && mipmapped && sampler.magFilter == GL_LINEAR) {
    glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_MAX_ANISOTROPY, maxAnisotropy);
  }
  checkGl("uploading a base colour texture");
  return id;
}

void SceneGeometry::setLodBias(float bias) const {
  for (const GlTexture& t : textures) {
    if (!t) continue;
    glBindTexture(GL_TEXTURE_2D, t.get());
    glTexParameterf(GL_TEXTURE_2D, GL_TEXTURE_LOD_BIAS, bias);
  }
  glBindTexture(GL_TEXTURE_2D, 0);
}

namespace {

const Material& materialOf(const Scene& scene, size_t t) {
  static const Material fallback;
  const int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
  return m >= 0 && size_t(m) < scene.materials.size() ? scene.materials[size_t(m)] : fallback;
}

/// Triangles in runs of one material (so that the scene pass binds each
/// material's textures once), in DrawCategory order: opaque first,
/// transmissive runs last, drawn after the opaque scene they show.
std::vector<std::vector<size_t>> trianglesByMaterial(const Scene& scene) {
  const size_t slots = scene.materials.size() + 1;
  std::vector<std::vector<size_t>> byMaterial(kCategories * slots);
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const int m = t < scene.triangleMaterial.size() ? scene.triangleMaterial[t] : -1;
    const size_t slot = m >= 0 && size_t(m) < scene.materials.size() ? size_t(m) + 1 : 0;
    byMaterial[size_t(categoryOf(materialOf(scene, t))) * slots + slot].push_back(t);
  }
  return byMaterial;
}

const std::vector<float>& uvSet(const Scene& scene, int texCoord) {
  return texCoord == 1 ? scene.texcoords1 : scene.texcoords0;
}

bool usable(const Scene& scene, int texture, int texCoord) {
  return texture >= 0 && size_t(texture) < scene.textures.size() &&
         uvSet(scene, texCoord).size() == 2 * scene.positions.size();
}

/// The channels of each Scene::textures entry the scene shader reads, over
/// every material that uses it (render_scene.frag, render_alpha.h).
std::vector<unsigned> channelsReadOf(const Scene& scene) {
  std::vector<unsigned> read(scene.textures.size(), 0);
  auto add = [&](int texture, int texCoord, unsigned channels) {
    if (usable(scene, texture, texCoord)) read[size_t(texture)] |= channels;
  };
  const unsigned rgb = kReadR | kReadG | kReadB;
  for (const Material& m : scene.materials) {
    add(m.baseColorTexture, m.baseColorTexCoord, rgb | kReadA);
    add(m.emissiveTexture, m.emissiveTexCoord, rgb);
    add(m.normalTexture, m.normalTexCoord, rgb);
    add(m.metallicRoughnessTexture, m.metallicRoughnessTexCoord, kReadG | kReadB);
    add(m.occlusionTexture, m.occlusionTexCoord, kReadR);
  }
  return read;
}

/// Corner k of triangle t as drawn with `range` (which textures it reads).
Vertex makeVertex(const Scene& scene, const RenderSpace& space, const Material& mat,
                  const DrawRange& range, size_t t, int k, const Vec3& faceNormal) {
  const uint32_t index = scene.indices[t * 3 + size_t(k)];
  // Texture transforms are affine: applied per vertex they are exact.
  auto setUv = [&](float* out, int texCoord, const TextureTransform& transform) {
    const std::vector<float>& uv = uvSet(scene, texCoord);
    out[0] = uv[2 * index];
    out[1] = uv[2 * index + 1];
    transform.apply(out[0], out[1]);
  };
  Vertex v{};
  const Vec3 p = space.toRender(scene.positions[index]);
  // No vertex normal (none, or zero: Scene::normals): the face's.
  const Vec3 n = scene.normals.empty() || lengthSquared(scene.normals[index]) == 0
                     ? faceNormal
                     : scene.normals[index];
  std::memcpy(v.position, &p, sizeof v.position);
  std::memcpy(v.normal, &n, sizeof v.normal);
  float alpha;  // the corner's own vertex colour: barycentrics (0, 0), (1, 0), (0, 1)
  const Vec3 color =
      mat.baseColor * scene.vertexColor(t, k == 1 ? 1.0f : 0.0f, k == 2 ? 1.0f : 0.0f, &alpha);
  std::memcpy(v.baseColor, &color, 3 * sizeof(float));
  v.baseColor[3] = mat.baseAlpha * alpha;
  v.metallicRoughness[0] = mat.metallic;
  v.metallicRoughness[1] = mat.roughness;
  std::memcpy(v.emission, &mat.emission, sizeof v.emission);
  if (range.texture >= 0) setUv(v.uv, mat.baseColorTexCoord, mat.baseColorTransform);
  if (range.normalTexture >= 0) setUv(v.normalUv, mat.normalTexCoord, mat.normalTransform);
  if (range.metallicRoughnessTexture >= 0) {
    setUv(v.metallicRoughnessUv, mat.metallicRoughnessTexCoord, mat.metallicRoughnessTransform);
  }
  if (range.occlusionTexture >= 0) {
    setUv(v.occlusionUv, mat.occlusionTexCoord, mat.occlusionTransform);
  }
  if (range.emissiveTexture >= 0) setUv(v.emissiveUv, mat.emissiveTexCoord, mat.emissiveTransform);
  if (scene.tangents.size() == 4 * scene.positions.size()) {
    std::memcpy(v.tangent, &scene.tangents[4 * size_t(index)], sizeof v.tangent);
  }
  return v;
}

}  // namespace

int SceneGeometry::useTexture(const Scene& scene, int index, const TextureUploads& uploads) {
  if (!textures[size_t(index)]) {
    textures[size_t(index)] =
        uploadTexture(scene.textures[size_t(index)], uploads.channelsRead[size_t(index)]);
    if (uploads.uploaded) uploads.uploaded(index);
  }
  return index;
}

DrawRange SceneGeometry::rangeOf(const Scene& scene, const Material& mat,
                                 const TextureUploads& uploads) {
  DrawRange range;
  range.transmission = mat.transmission;
  range.thickness = mat.thickness;
  range.ior = mat.ior;
  range.dielectricF0 = mat.dielectricF0();
  range.specular = mat.specular;
  range.alphaMode = alphaModeOf(mat);
  range.alphaCutoff = mat.alphaCutoff;
  range.doubleSided = mat.doubleSided || !mat.backFaceCulling;
  range.emitsBothSides = mat.doubleSided;
  range.unlit = mat.unlit;
  if (usable(scene, mat.emissiveTexture, mat.emissiveTexCoord) && mat.isEmissive()) {
    range.emissiveTexture = useTexture(scene, mat.emissiveTexture, uploads);
  }
  if (usable(scene, mat.baseColorTexture, mat.baseColorTexCoord)) {
    range.texture = useTexture(scene, mat.baseColorTexture, uploads);
  }
  if (usable(scene, mat.normalTexture, mat.normalTexCoord)) {
    range.normalTexture = useTexture(scene, mat.normalTexture, uploads);
    range.normalScale = mat.normalScale;
  }
  if (usable(scene, mat.metallicRoughnessTexture, mat.metallicRoughnessTexCoord)) {
    range.metallicRoughnessTexture = useTexture(scene, mat.metallicRoughnessTexture, uploads);
  }
  if (usable(scene, mat.occlusionTexture, mat.occlusionTexCoord)) {
    range.occlusionTexture = useTexture(scene, mat.occlusionTexture, uploads);
    range.occlusionStrength = mat.occlusionStrength;
  }
  return range;
}

void checkGeometryMemory(size_t triangles, size_t added) {
  const size_t available = availableMemoryBytes();
  const double needed =
      double(triangles) * kRenderBytesPerTriangle + double(added) * 3.0 * sizeof(Vertex);
  if (available == 0 || needed <= double(available)) return;
  throw InputError("render: the scene's " + formatCount(triangles) + " triangles need about " +
                   formatBytes(size_t(std::min(needed, 1e18))) + " in the GL driver (" +
                   formatNumber(kRenderBytesPerTriangle) + " bytes each), more than the " +
                   formatBytes(available) +
                   " of memory available: draw a smaller scene or fewer --add objects, or give "
                   "the process more memory");
}

void SceneGeometry::upload(const Scene& scene, const RenderSpace& space,
                           const std::function<void(int)>& textureUploaded) {
  // Anisotropic filtering: core in GL 4.6, an extension before.
  if (GLAD_GL_ARB_texture_filter_anisotropic || GLAD_GL_EXT_texture_filter_anisotropic) {
    glGetFloatv(GL_MAX_TEXTURE_MAX_ANISOTROPY, &maxAnisotropy);
    maxAnisotropy = std::min(maxAnisotropy, 16.0f);
  }
  textures.clear();
  textures.resize(scene.textures.size());
  const TextureUploads uploads{channelsReadOf(scene), textureUploaded};
  const size_t total = scene.triangleCount() * 3;
  size_t added = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) added += scene.isAdded(t) ? 1 : 0;
  checkGeometryMemory(scene.triangleCount(), added);
  // The buffer made at its size, filled a chunk at a time: the vertices
  // built whole beside the driver's copy of them doubled the peak (730
  // bytes a triangle, H17-5-1).
  vao = GlVertexArray::create();
  glBindVertexArray(vao.get());
  vbo = GlBuffer::create();
  glBindBuffer(GL_ARRAY_BUFFER, vbo.get());
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(total * sizeof(Vertex)), nullptr, GL_STATIC_DRAW);
  checkGl("making the scene's vertex buffer");
  constexpr size_t kChunkVertices = size_t(3) << 14;
  std::vector<Vertex> chunk;
  chunk.reserve(std::min(total, kChunkVertices));
  size_t written = 0;  // vertices in the buffer
  auto flush = [&] {
    if (chunk.empty()) return;
    glBindBuffer(GL_ARRAY_BUFFER, vbo.get());  // a texture's upload may bind another
    glBufferSubData(GL_ARRAY_BUFFER, GLintptr(written * sizeof(Vertex)),
                    GLsizeiptr(chunk.size() * sizeof(Vertex)), chunk.data());
    written += chunk.size();
    chunk.clear();
  };
  vertexCorner.reserve(total);
  for (const std::vector<size_t>& group : trianglesByMaterial(scene)) {
    if (group.empty()) continue;
    const Material& mat = materialOf(scene, group.front());
    const DrawCategory category = categoryOf(mat);
    DrawRange range = rangeOf(scene, mat, uploads);
    range.moving = scene.isAdded(group.front());
    range.first = GLint(written + chunk.size());
    for (size_t t : group) {
      const Vec3 faceNormal = scene.faceNormal(t);
      for (int k = 0; k < 3; ++k) {
        chunk.push_back(makeVertex(scene, space, mat, range, t, k, faceNormal));
        vertexCorner.push_back(uint32_t(3 * t + size_t(k)));
        if (range.moving) movingVertices.push_back(chunk.back());
      }
      if (category == kBlended) {
        const Vertex* tri = &chunk[chunk.size() - 3];
        blendCentroids.push_back((glm::make_vec3(tri[0].position) +
                                  glm::make_vec3(tri[1].position) +
                                  glm::make_vec3(tri[2].position)) /
                                 3.0f);
      }
      if (chunk.size() >= kChunkVertices) flush();
    }
    const size_t end = written + chunk.size();
    range.count = GLsizei(end) - range.first;
    ranges.push_back(range);
    rangeCategory.push_back(category);
    if (category == kSolid) opaqueCount = GLsizei(end);
    if (category < kBlended) blendFirst = GLsizei(end);
  }
  flush();
  setVertexAttributes();
}

void SceneGeometry::setVertexAttributes() {
  glBindVertexArray(vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, vbo.get());
  auto attrib = [](GLuint location, GLint size, size_t offset) {
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, size, GL_FLOAT, GL_FALSE, sizeof(Vertex),
                          reinterpret_cast<const void*>(offset));
  };
  attrib(0, 3, offsetof(Vertex, position));
  attrib(1, 3, offsetof(Vertex, normal));
  attrib(2, 4, offsetof(Vertex, baseColor));
  attrib(3, 2, offsetof(Vertex, metallicRoughness));
  attrib(4, 3, offsetof(Vertex, emission));
  attrib(5, 2, offsetof(Vertex, uv));
  attrib(6, 2, offsetof(Vertex, normalUv));
  attrib(7, 2, offsetof(Vertex, metallicRoughnessUv));
  attrib(8, 2, offsetof(Vertex, occlusionUv));
  attrib(9, 2, offsetof(Vertex, emissiveUv));
  attrib(11, 4, offsetof(Vertex, tangent));
  if (!blendCentroids.empty()) blendEbo = GlBuffer::create();
  glBindVertexArray(0);
  emptyVao = GlVertexArray::create();
  checkGl("uploading the scene");
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
void SceneGeometry::drawDepthOnly(GLuint program, bool shadows) const {
  const GLint alphaTest = glGetUniformLocation(program, "uAlphaTest");
  glUniform1i(alphaTest, 0);
  // The camera's pre-pass culls what the colour pass culls (else a culled
  // back face would keep its depth and show the background: a black hole);
  // shadow maps see both sides.
  auto cull = [shadows](const DrawRange& range) {
    if (!shadows && !range.doubleSided) {
      glEnable(GL_CULL_FACE);
    } else {
      glDisable(GL_CULL_FACE);
    }
  };
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  if (shadows) {
    glDrawArrays(GL_TRIANGLES, 0, opaqueCount);
  } else {
    for (size_t i = 0; i < ranges.size(); ++i) {
      if (rangeCategory[i] != kSolid) continue;
      cull(ranges[i]);
      glDrawArrays(GL_TRIANGLES, ranges[i].first, ranges[i].count);
    }
  }
  glUniform1i(glGetUniformLocation(program, "uBaseColorTexture"), 4);
  const GLint hasTexture = glGetUniformLocation(program, "uHasBaseColorTexture");
  const GLint cutoff = glGetUniformLocation(program, "uAlphaCutoff");
  for (size_t i = 0; i < ranges.size(); ++i) {
    const DrawRange& range = ranges[i];
    if (rangeCategory[i] != kMasked && !(shadows && rangeCategory[i] == kBlended)) continue;
    if (shadows && range.unlit) continue;  // light passes unlit surfaces
    glUniform1i(alphaTest, 1);
    glUniform1i(hasTexture, range.texture >= 0 ? 1 : 0);
    // An unlit opaque range keeps every fragment (cutoff 0).
    const bool masked = range.alphaMode == shader::LO_ALPHA_MASK;
    glUniform1f(cutoff, rangeCategory[i] == kMasked ? (masked ? range.alphaCutoff : 0.0f) : 0.5f);
    glActiveTexture(GL_TEXTURE4);
    glBindTexture(GL_TEXTURE_2D, texture(range.texture));
    cull(range);
    glDrawArrays(GL_TRIANGLES, range.first, range.count);
  }
  glDisable(GL_CULL_FACE);
  if (shadows) {
    glUniform1i(alphaTest, 0);
    drawVolumes();
  }
  glActiveTexture(GL_TEXTURE0);
}

void SceneGeometry::drawVolumes() const {
  glDisable(GL_CULL_FACE);
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (rangeCategory[i] == kTransmissive && ranges[i].thickness > 0) {
      glDrawArrays(GL_TRIANGLES, ranges[i].first, ranges[i].count);
    }
  }
}

/// Writes the blended triangles' vertex indices into blendEbo, each
/// range's triangles from the farthest to the nearest centroid (render
/// space distance to `eye`): the order in which blending composes them.
void SceneGeometry::sortBlended(const glm::vec3& eye) {
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
      for (uint32_t c = 0; c < 3; ++c)
        indices[3 * tri + c] = uint32_t(blendFirst) + 3 * order[k] + c;
    }
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, blendEbo.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices.size() * sizeof(uint32_t)),
               indices.data(), GL_STREAM_DRAW);
}

void SceneGeometry::offsetMovingVertices(const Vec3& offset) {
  glBindBuffer(GL_ARRAY_BUFFER, vbo.get());
  size_t k = 0;
  std::vector<Vertex> moved;
  for (size_t ri = 0; ri < ranges.size(); ++ri) {
    const DrawRange& range = ranges[ri];
    if (!range.moving) continue;
    moved.assign(movingVertices.begin() + std::ptrdiff_t(k),
                 movingVertices.begin() + std::ptrdiff_t(k + size_t(range.count)));
    for (Vertex& v : moved) {
      v.position[0] += offset.x;
      v.position[1] += offset.y;
      v.position[2] += offset.z;
    }
    if (rangeCategory[ri] == kBlended) {
      // Their centroids move with them: the back-to-front sort reads them.
      const size_t firstTriangle = size_t(range.first - blendFirst) / 3;
      for (size_t t = 0; 3 * t + 2 < moved.size(); ++t) {
        blendCentroids[firstTriangle + t] = (glm::make_vec3(moved[3 * t].position) +
                                             glm::make_vec3(moved[3 * t + 1].position) +
                                             glm::make_vec3(moved[3 * t + 2].position)) /
                                            3.0f;
      }
    }
    glBufferSubData(GL_ARRAY_BUFFER, GLintptr(size_t(range.first) * sizeof(Vertex)),
                    GLsizeiptr(moved.size() * sizeof(Vertex)), moved.data());
    k += size_t(range.count);
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
  checkGl("moving the added objects");
}

}  // namespace lo::render_internal
