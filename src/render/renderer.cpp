// Renderer: scene + light octree -> linear HDR pixels (paper §3.2, §4.2).
// Its parts live in their own files (render/renderer_impl.h lists them).

#include "render/renderer.h"

#include <glad/gl.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "core/error.h"
#include "core/resources.h"
#include "render/context.h"
#include "render/gl_util.h"
#include "render/renderer_impl.h"

namespace lo {

using namespace render_internal;

Lighting parseLighting(const std::string& name) {
  if (name == "octree") return Lighting::Octree;
  if (name == "atlas") return Lighting::Atlas;
  throw InputError("unknown lighting '" + name + "' (expected octree or atlas)");
}

std::string toString(Lighting lighting) { return lighting == Lighting::Atlas ? "atlas" : "octree"; }

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

void Renderer::Impl::uploadOctree(const GpuOctree& octree) {
  OctreeTextures::checkLimits(octree, params.max3DTextureSize, params.max2DTextureSize);
  octreeTextures.upload(octree);
  octreeOrigin = space.toRender(octree.origin);
  depth = octree.depth;
  voxelSize = octreeTextures.voxelSize;
}

Renderer::Renderer(const Scene& scene, const GpuOctree& octree, const RendererParams& params,
                   const std::function<void(int)>& textureUploaded)
    : impl_(std::make_unique<Impl>()) {
  Impl& r = *impl_;
  r.params = params;
  StageTimer shaders(r.startup, "shaders");
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
  r.space.origin = world.center();
  r.space.bounds.extend(r.space.toRender(world.lower));
  r.space.bounds.extend(r.space.toRender(world.upper));
  r.space.sceneSize = std::max(length(r.space.bounds.extent()), 1e-3f);
  r.nearSample = sampledCorners(scene, r.space, size_t(1) << 14);
  r.sky = scene.sky.radiance;
  for (const Material& m : scene.materials) r.volumes |= m.transmission > 0 && m.thickness > 0;
  r.sceneProgram = GlProgram(r.buildSceneProgram({"LO_DIRECT_LIGHT"}));
  r.sceneIndirectProgram = GlProgram(r.buildSceneProgram({}));
  r.depthProgram = GlProgram(buildProgram({"render_depth.vert", "render_depth.frag"}));
  if (maxComponent(r.sky) > 0) {
    r.skyProgram = GlProgram(buildProgram({"render_fullscreen.vert", "render_sky.frag"}));
    if (scene.sky.image) {
      const Texture& image = *scene.sky.image;
      r.skyImage = GlTexture::create();
      glBindTexture(GL_TEXTURE_2D, r.skyImage.get());
      glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
      // Float: a sun in a sky image exceeds half floats' 65504. Float RGB
      // texels (what loadSkyImage and Texture::fromLinear make) go up as they
      // are, without a copy of what may be a gigabyte; others are converted.
      std::vector<float> converted;
      if (image.format != TexelFormat::Float32 || image.channels != 3) {
        converted.resize(image.texelCount() * 3);
        for (size_t i = 0; i < image.texelCount(); ++i) {
          const Vec3 v = image.texelAt(i);
          converted[3 * i] = v.x;
          converted[3 * i + 1] = v.y;
          converted[3 * i + 2] = v.z;
        }
      }
      glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, image.width, image.height, 0, GL_RGB, GL_FLOAT,
                   converted.empty() ? image.floats.data() : converted.data());
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_REPEAT);
      glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      glBindTexture(GL_TEXTURE_2D, 0);
      checkGl("uploading the sky image");
    }
  }
  shaders.finish(maxComponent(r.sky) > 0 && scene.sky.image ? "and the sky image" : "");
  StageTimer octreeTimer(r.startup, "octree upload");
  r.uploadOctree(octree);
  octreeTimer.finish(formatCount(octree.leafCount) + " leaves");
  // The lights first: emitter VPLs read the emissive texels, which
  // `textureUploaded` may free once the textures are on the GPU.
  StageTimer lightsTimer(r.startup, "lights");
  r.lights.build(scene, r.space, params);
  lightsTimer.finish(std::to_string(r.lights.block.uLightCount[0]) + " in the light block");
  StageTimer geometryTimer(r.startup, "geometry and textures");
  r.geometry.upload(scene, r.space, textureUploaded);
  for (const DrawRange& range : r.geometry.ranges) r.hasMovingRanges = r.hasMovingRanges || range.moving;
  r.geometry.sceneTriangles = scene.triangleCount();
  size_t textures = 0;
  for (const auto& t : r.geometry.textures) textures += t.get() != 0 ? 1 : 0;
  geometryTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                       formatCount(textures) + " textures (" +
                       formatBytes(r.geometry.textureBytes) + " on the GPU)");
  StageTimer shadowTimer(r.startup, "shadow maps");
  r.lights.createShadowMaps(r.geometry.vao.get(), [&r](GLuint program, bool shadows) {
    r.geometry.drawDepthOnly(program, shadows);
  });
  shadowTimer.finish(std::to_string(r.lights.layerCount()) + " layers of " +
                     std::to_string(r.lights.shadowMapSize) + "^2, covered " +
                     formatNumber(std::round(10.0 * r.lights.shadowOverlap) / 10.0) +
                     " times over" + (r.lights.shadowMapNote.empty() ? "" : " (fill budget)"));
  for (const Material& m : scene.materials) {
    r.probe.wanted =
        r.probe.wanted || m.roughness < shader::LO_PROBE_NONE || m.metallicRoughnessTexture >= 0;
  }
}

bool Renderer::hasReflectionProbe() const { return impl_->probe.wanted; }

const std::string& Renderer::shadowMapNote() const { return impl_->lights.shadowMapNote; }
bool Renderer::cascadesCoverWholeScene() const { return impl_->lights.cascadesWhole; }

const std::vector<StageReport>& Renderer::startupStages() const { return impl_->startup; }

bool Renderer::hasAtlas() const { return bool(impl_->atlasVbo); }

size_t Renderer::atlasBytes() const { return impl_->atlasTextureBytes; }

void Renderer::setAtlas(const LightmapUvs& uvs, const LightmapAtlas& atlas) {
  Impl& r = *impl_;
  const size_t triangles = r.geometry.sceneTriangles;
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
  const std::vector<uint32_t>& vertexCorner = r.geometry.vertexCorner;
  std::vector<float> attribute(3 * vertexCorner.size());
  for (size_t i = 0; i < vertexCorner.size(); ++i) {
    const size_t t = vertexCorner[i] / 3, k = vertexCorner[i] % 3;
    attribute[3 * i] = uvs.uv[6 * t + 2 * k];
    attribute[3 * i + 1] = uvs.uv[6 * t + 2 * k + 1];
    attribute[3 * i + 2] = float(uvs.trianglePage[t]);
  }
  if (!r.atlasVbo) r.atlasVbo = GlBuffer::create();
  glBindVertexArray(r.geometry.vao.get());
  glBindBuffer(GL_ARRAY_BUFFER, r.atlasVbo.get());
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(attribute.size() * sizeof(float)),
               attribute.empty() ? nullptr : attribute.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(10);
  glVertexAttribPointer(10, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
  glBindVertexArray(0);
  // Pages as layers: bilinear, no mipmaps (they would bleed across charts).
  auto upload = [&](GlTexture& texture, GLenum format, const std::vector<RgbImage>& pages,
                    bool clampNegative) {
    if (!texture) texture = GlTexture::create();
    glBindTexture(GL_TEXTURE_2D_ARRAY, texture.get());
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GLint(format), atlas.width, atlas.height, atlas.pageCount,
                 0, GL_RGB, GL_FLOAT, nullptr);
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

int Renderer::emitterLightCount() const { return impl_->lights.emitterLights; }

int Renderer::areaLightCount() const { return impl_->lights.areaTriangleCount; }
int Renderer::areaLightGroups() const { return impl_->lights.areaLightCount; }

void Renderer::setOctree(const GpuOctree& octree) {
  impl_->uploadOctree(octree);
  impl_->probe.valid = false;  // it shows the old octree's light
}

void Renderer::setFreeSpaceLight(const GpuOctree& volume) {
  Impl& r = *impl_;
  OctreeTextures::checkLimits(volume, r.params.max3DTextureSize, r.params.max2DTextureSize);
  if (!r.sceneMovingProgram) {
    r.sceneMovingProgram = GlProgram(r.buildSceneProgram({"LO_DIRECT_LIGHT", "LO_FREE_SPACE"}));
    r.sceneIndirectMovingProgram =
        GlProgram(r.buildSceneProgram({"LO_FREE_SPACE"}));
  }
  r.volumeTextures.upload(volume);
  r.volumeOrigin = r.space.toRender(volume.origin);
  r.hasVolume = true;
  r.probe.valid = false;
}

bool Renderer::hasFreeSpaceLight() const { return impl_->hasVolume; }

bool Renderer::hasAddedObjects() const { return impl_->hasMovingRanges; }

void Renderer::moveAddedObjects(const Vec3& offset) {
  Impl& r = *impl_;
  if (!r.hasMovingRanges) return;
  // A translation: the same in render space as in the world.
  r.geometry.offsetMovingVertices(offset);
  r.lights.redrawShadowMaps(r.geometry.vao.get(), [&r](GLuint program, bool shadows) {
    r.geometry.drawDepthOnly(program, shadows);
  });
  r.probe.valid = false;
}

namespace {

/// The drawn frame's side per image side for `supersample` samples a side:
/// 1 for two (the rotated grid's frames are the image's size), else itself.
int frameScale(int supersample) { return supersample == 2 ? 1 : supersample; }

}  // namespace

double renderFramePixels(const RenderParams& params) {
  const double block = double(frameScale(params.supersample));
  return double(params.width) * double(params.height) * block * block;
}

void checkRenderMemory(const RenderParams& params) {
  const size_t available = availableMemoryBytes();
  const double needed = renderFramePixels(params) * kRenderBytesPerFramePixel;
  if (available > 0 && needed > double(available)) {
    throw InputError("render: a frame of --width " + std::to_string(params.width) +
                     ", --height " + std::to_string(params.height) + ", --supersample " +
                     std::to_string(params.supersample) + " needs about " +
                     formatBytes(size_t(needed)) + " (" +
                     formatCount(size_t(renderFramePixels(params))) + " pixels drawn, " +
                     formatNumber(kRenderBytesPerFramePixel) +
                     " bytes each), more than the " + formatBytes(available) +
                     " of memory available: lower them");
  }
}

RgbImage Renderer::render(const PinholeCamera& camera, const RenderParams& params,
                          ProgressSink* progress) {
  Impl& r = *impl_;
  const int s = params.supersample;
  if (s < 1 || s > 16) {
    throw InputError("render: supersampling must be 1..16, got " + std::to_string(s));
  }
  // Two: four frames of the image's size, each sampling the pixels at one
  // point of a rotated grid (RGSS: the four points on four distinct rows
  // and columns, so a near-horizontal or near-vertical edge gets five
  // levels of coverage where an ordered 2 x 2 grid gives three: the window
  // room's edge pixels, the Cornell box's light). Otherwise one frame s
  // times larger, each output pixel the mean of its s x s block.
  const bool rotated = s == 2;
  const int block = frameScale(s);
  const int w = params.width * block, h = params.height * block;
  // The frame the driver draws into, checked before it is made: a side
  // beyond its largest texture, render buffer or viewport, or a target it
  // cannot hold, failed inside the driver ("GL error 0x0501").
  GLint maxTexture = 0, maxRenderbuffer = 0, maxViewport[2] = {0, 0};
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &maxTexture);
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxRenderbuffer);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, maxViewport);
  const int maxSide = std::min({maxTexture, maxRenderbuffer, maxViewport[0], maxViewport[1]});
  const std::string frame = std::to_string(w) + " x " + std::to_string(h) + " (--width " +
                            std::to_string(params.width) + ", --height " +
                            std::to_string(params.height) + ", --supersample " + std::to_string(s) + ")";
  if (maxSide > 0 && (w > maxSide || h > maxSide)) {
    throw InputError("render: a frame of " + frame + " has a side beyond the " +
                     std::to_string(maxSide) + " the GL driver draws: lower them");
  }
  try {
    r.ensureTarget(w, h);
  } catch (const GlError& e) {
    throw InputError("render: a frame of " + frame + " is more than the GL driver can draw into (" +
                     e.what() + "): lower them");
  }
  constexpr float kRotated[4][2] = {
      {-0.125f, -0.375f}, {0.375f, -0.125f}, {0.125f, 0.375f}, {-0.375f, 0.125f}};
  const int passes = rotated ? 4 : 1;
  // The four frames' textures read a level finer, as the frame twice as
  // large does (its samples' footprints are half a pixel wide).
  struct LodBias {
    const render_internal::SceneGeometry& geometry;
    bool set;
    ~LodBias() {
      if (set) geometry.setLodBias(0.0f);
    }
  } lodBias{r.geometry, rotated};
  if (rotated) r.geometry.setLodBias(-1.0f);
  RgbImage image(params.width, params.height);
  std::vector<float> raw(size_t(w) * size_t(h) * 4);
  const float norm = 1.0f / float(s * s);
  Progress frames(progress, "render: frames", size_t(passes));
  for (int pass = 0; pass < passes; ++pass) {
    r.pixelOffset = rotated ? glm::vec2(kRotated[pass][0], kRotated[pass][1]) : glm::vec2(0.0f);
    glBindFramebuffer(GL_FRAMEBUFFER, r.targetFbo.get());
    r.draw(camera, params, w, h, 1.0f, false);
    r.pixelOffset = glm::vec2(0.0f);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadBuffer(GL_COLOR_ATTACHMENT0);
    glReadPixels(0, 0, w, h, GL_RGBA, GL_FLOAT, raw.data());
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    checkGl("reading back the image");
    // GL rows go bottom-up; image rows top-down. Alpha is dropped.
    for (int y = 0; y < params.height; ++y) {
      float* dst = image.rgb.data() + size_t(y) * size_t(params.width) * 3;
      for (int sy = 0; sy < block; ++sy) {
        const float* src = raw.data() + size_t(h - 1 - (y * block + sy)) * size_t(w) * 4;
        for (int x = 0; x < params.width; ++x) {
          for (int sx = 0; sx < block; ++sx) {
            for (int c = 0; c < 3; ++c) dst[3 * x + c] += src[4 * (x * block + sx) + c] * norm;
          }
        }
      }
    }
    frames.advance();
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
  glBindFramebuffer(GL_FRAMEBUFFER, r.targetFbo.get());
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
    const GlProgram program(buildProgram(files));
  }
  for (const std::vector<std::string>& defines : std::vector<std::vector<std::string>>{
           {"LO_DIRECT_LIGHT"},
           {"LO_DIRECT_LIGHT", "LO_ATLAS_LIGHTING"},
           {"LO_ATLAS_LIGHTING"},
           {"LO_DIRECT_LIGHT", "LO_FREE_SPACE"},
           {"LO_FREE_SPACE"},
           {"LO_DIRECT_LIGHT", "LO_VOLUMES"},
           {"LO_VOLUMES"}}) {
    // Each with and without the alpha cut (Renderer::Impl::uncutTwins).
    std::vector<std::string> cut = defines;
    cut.push_back("LO_ALPHA_CUT");
    const GlProgram program(buildProgram({"render_scene.vert", "render_scene.frag"}, defines));
    const GlProgram cutProgram(buildProgram({"render_scene.vert", "render_scene.frag"}, cut));
  }
}

}  // namespace lo
