#pragma once
/// @file render/renderer.h
/// @brief Real-time rendering of a scene lit by its light octree (paper §3.2,
/// §4.2): indirect light from the VDLs of the voxel under each fragment, plus
/// (hybrid, paper §3) direct light from punctual lights and emitters with
/// shadow maps. Needs a current GlContext (render/context.h). Output is linear
/// HDR radiance, W/(m^2 sr) in the scene's light units. See docs/render.md.

#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/math.h"
#include "core/progress.h"
#include "core/resources.h"
#include "image/image.h"
#include "lightmap/lightmap_atlas.h"
#include "lightmap/lightmap_uv.h"
#include "octree/gpu_octree.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"

namespace lo {

enum class RenderMode {
  Full,      ///< emission + direct + indirect
  Direct,    ///< emission + punctual lights + emitter lights (shadow-mapped)
  Indirect,  ///< the light octree only
  Voxels,    ///< leaves coloured by a hash of their voxel coordinate; empty = black
};
/// Where the indirect light comes from (paper §4.2): the light octree walked
/// per fragment, or the atlas it was rendered into (§4.2.3: one fetch).
enum class Lighting {
  Octree,  ///< the octree lookup per fragment (n_VDL + depth + 1 fetches, x8 interpolated)
  Atlas,   ///< the lightmap atlas (Renderer::setAtlas): irradiance and direction, one fetch each
};
/// "octree" | "atlas". @throws InputError naming the value.
Lighting parseLighting(const std::string& name);
std::string toString(Lighting lighting);

/// "full" | "direct" | "indirect" | "voxels". @throws InputError naming the value.
RenderMode parseRenderMode(const std::string& name);
std::string toString(RenderMode mode);

/// Per-frame settings (cheap to change between frames).
struct RenderParams {
  int width = 800, height = 600;  ///< pixels
  RenderMode mode = RenderMode::Full;
  bool interpolation = true;  ///< trilinear over the 8 neighbouring voxels (paper §4.2.1)
  bool specular = true;       ///< GGX lobe of the glTF BRDF; off = diffuse only
  int maxVdls = kMaxVdls;     ///< VDLs used per voxel, 1..kMaxVdls (the strongest come first)
  /// Lookup point offset along the surface normal, in voxel sizes (see
  /// docs/render.md: picks the voxel in front of a surface lying on a voxel face).
  float normalOffset = 0.01f;
  /// Environment reflections (paper §5.1, Fig. 12): glossy and metal surfaces
  /// take their specular indirect light from a box-projected cube map of the
  /// lit scene captured at the scene's centre; the VDLs keep the diffuse and
  /// rough-specular terms. Off: the VDLs light every term.
  bool reflections = true;
  /// Indirect light from the octree or from the atlas (setAtlas first).
  Lighting lighting = Lighting::Octree;
  /// Renderer::render only: each pixel the mean of supersample x supersample
  /// samples on a regular grid (the image drawn that much larger, then
  /// box-filtered): anti-aliased edges, as a path tracer integrates a pixel.
  int supersample = 1;
};

/// Pixels of the frame the renderer draws for `params`: width x height, times
/// supersample^2 unless it is 2 (rotated-grid supersampling draws frames of
/// the image's size, one after another).
double renderFramePixels(const RenderParams& params);

/// Bytes the renderer holds per pixel of that frame: 52 to 66 were measured
/// (peak resident memory of `render` on the Cornell box, 800 x 600 to
/// 1600 x 1200, --supersample 1, 2, 4): its render targets, the read-back, the
/// image and the file writer's copy.
constexpr double kRenderBytesPerFramePixel = 64;

/// @brief Refuses, before any work, a frame whose pixels
/// (kRenderBytesPerFramePixel each) need more than the memory available
/// (availableMemoryBytes, LIGHTOCTREE_MEMORY_LIMIT included): Python's
/// render, which no memory watch stops, grew to 3.5 GB under a 200 MiB limit.
/// @throws InputError naming the sizes, the figure and the memory.
void checkRenderMemory(const RenderParams& params);

/// Set once: resources built for the scene.
struct RendererParams {
  /// Texels per side of every shadow map layer, at most: with many shadowed
  /// lights (a VPL takes 6 layers) the maps are halved until they fit in
  /// 96 MiB (not below 256), so an emissive-textured asset's VPLs do not
  /// take hundreds of megabytes.
  int shadowMapSize = 1024;
  /// Emissive triangles are drawn as area lights (exact unshadowed irradiance
  /// of each triangle; triangles that share corners, a quad or a glowing
  /// cube, shadowed together, softly by their size) when the scene has at
  /// most LO_MAX_AREA_TRIANGLES (shaders/render_constants.h) of them; else,
  /// or when off, as `emitterLights` shadowed virtual point lights.
  bool areaLights = true;
  /// Emissive triangles become this many shadowed virtual point lights for the
  /// direct pass when they are not area lights (0 = none: then bake with
  /// --include-direct to see their light).
  int emitterLights = 8;
  /// Texture limits to respect; 0 = query the current context.
  int max3DTextureSize = 0, max2DTextureSize = 0;
  /// Texels per side of each face of the reflection probe's cube map
  /// (RenderParams::reflections); captured on the first frame that needs it.
  int probeSize = 128;
  /// Frames follow a moving camera (`view`): the sun's cascades, drawn again
  /// whenever they are refitted to it, are fitted only while one drawing of
  /// them covers at most a sixteenth of the shadow maps' fill budget (2^26
  /// texels, lights.cpp); beyond, they cover the whole scene, which no
  /// camera move redraws. Off: the whole budget.
  bool interactive = false;
};


class Renderer {
 public:
  /// Uploads the scene geometry, the octree textures and renders the shadow
  /// maps. Requires a current GL context.
  /// @throws InputError naming GL_MAX_3D_TEXTURE_SIZE / GL_MAX_TEXTURE_SIZE and
  /// by how much when the octree's textures exceed the context's limits;
  /// GlError on a GL failure.
  /// `textureUploaded`, when given, is called with each Scene::textures
  /// index whose GPU copy is made, after the constructor's last read of its
  /// texels: a caller that reads them no more may free them there, so that
  /// the scene's texels and their GPU copies are not all held at once (on a
  /// software GL both live in the process).
  Renderer(const Scene& scene, const GpuOctree& octree, const RendererParams& params = {},
           const std::function<void(int)>& textureUploaded = {});
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Replaces the light octree (e.g. a finer level of a progressive bake):
  /// uploads its textures in place of the old ones; geometry, lights and
  /// shadow maps stay. Requires the renderer's GL context to be current.
  /// @throws InputError like the constructor when the textures exceed the
  /// context's limits (the old octree is kept then).
  void setOctree(const GpuOctree& octree);

  /// The free-space light (buildVolumeOctree of VdlGrid::volume): what the
  /// objects added after the bake (Scene::movingMaterialsFrom) take their
  /// indirect light from, instead of the surfaces' octree, whose light
  /// belongs to the baked surfaces. Without it they read the surfaces'.
  /// @throws InputError like setOctree.
  void setFreeSpaceLight(const GpuOctree& volume);
  bool hasFreeSpaceLight() const;
  /// Whether the scene has objects added after the bake.
  bool hasAddedObjects() const;
  /// Moves the added objects by `offset` (world units) from where the scene
  /// put them: their vertices rewritten, the shadow maps drawn again (they
  /// cast where they are now), the reflection probe captured again. The
  /// baked light stays as it is.
  void moveAddedObjects(const Vec3& offset);

  /// Uploads lightmap UVs (per triangle corner, of the scene given to the
  /// constructor) and the pages baked for them, for RenderParams::lighting =
  /// Atlas: the indirect light of a fragment is then one VDL rebuilt from the
  /// atlas, E / max(n_bake . d, 0.05) along d, shaded by the same BRDF
  /// (exact for the diffuse term). Irradiance is stored as GL_RGB9_E5 (shared
  /// exponent, 4 B, no negatives), direction as GL_RGBA8_SNORM (4 B).
  /// @throws InputError when the UVs do not match the scene or the pages
  /// exceed the context's texture limits.
  void setAtlas(const LightmapUvs& uvs, const LightmapAtlas& atlas);
  bool hasAtlas() const;
  size_t atlasBytes() const;  ///< GPU bytes of the atlas textures (0 without one)
  /// What the constructor did, a row each with its time and the process's
  /// memory after it: shaders, octree upload, lights (the light block),
  /// geometry and textures (their count and GPU bytes), shadow maps (their
  /// layers and size).
  const std::vector<StageReport>& startupStages() const;

  /// Renders into an offscreen RGBA32F target and reads its RGB back.
  /// `progress` hears of each frame drawn ("render: frames", the four of the
  /// rotated grid or one); a sink that throws from its report stops the
  /// render between frames (Python's Ctrl-C).
  RgbImage render(const PinholeCamera& camera, const RenderParams& params,
                  ProgressSink* progress = nullptr);
  /// Renders into the currently bound framebuffer (a window); `exposure` in EV
  /// scales the radiance, then a clamp and sRGB encoding are applied.
  void drawToScreen(const PinholeCamera& camera, const RenderParams& params, float exposure);

  /// Seconds of GPU+CPU time for `frames` offscreen frames (glFinish after
  /// each), without the read-back: the real-time cost.
  double timeFrames(const PinholeCamera& camera, const RenderParams& params, int frames);

  /// Whether the scene has a surface the reflection probe serves (roughness,
  /// by factor or map, below the probe's cut-off, shaders/render_constants.h).
  bool hasReflectionProbe() const;
  /// Why the shadow maps are smaller than RendererParams::shadowMapSize
  /// beyond the memory budget (the scene covers them many times over:
  /// a budget of texels drawn), or "".
  const std::string& shadowMapNote() const;
  /// The last frame's sun cascades each cover the whole scene: fitted to its
  /// camera they would have covered more than the fill budget allows
  /// (RendererParams::interactive).
  bool cascadesCoverWholeScene() const;
  int emitterLightCount() const;  ///< virtual point lights on emissive triangles
  int areaLightCount() const;     ///< emissive triangles drawn as area lights (one-sided)
  int areaLightGroups() const;    ///< their groups, each shadowed from one cube map

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Compiles and links every shader program the renderer ships; throws GlError
/// naming the file on the first failure. For tests and `--check-shaders`.
void compileAllShaders();

}  // namespace lo
