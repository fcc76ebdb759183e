#pragma once
/// @file render/render_session.h
/// @brief The front door of rendering, as bake() is the bake's: typed
/// settings whose defaults are the command line's, and the one session that
/// assembles a render from a scene and its baked grid: the GPU light octree
/// built within the GL context's limits, the renderer (scene upload, lights,
/// shadow maps, texels freed as they reach the GPU), the free-space light of
/// the objects added after the bake, and the indirect lighting (the octree,
/// or the atlas it is rendered into), each stage timed. `render`, `view`,
/// the benchmarks, the sweep and the Python module all go through it, so
/// that the same settings draw the same picture everywhere.

#include <memory>
#include <string>
#include <vector>

#include "core/progress.h"
#include "core/resources.h"
#include "image/image.h"
#include "lightgrid/vdl_grid.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "render/atlas_lighting.h"
#include "render/context.h"
#include "render/renderer.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"

namespace lo {

/// The GPU octree settings of a render, where they differ from the octree
/// stage's own (GpuOctreeParams: the lossless form): compact VDL texels,
/// adaptive leaves at 0.1 (2.5x less GPU memory at equal irradiance error on
/// the test scenes, docs/octree.md) and free-space leaves merged at 0.4.
GpuOctreeParams renderOctreeDefaults();

/// The frame settings of a picture, where they differ from the renderer's
/// own (RenderParams: one sample per pixel, a real-time frame's): 2 x 2
/// samples per pixel, as the path tracer integrates a pixel. With one, a
/// silhouette pixel whose centre falls on the background or a far surface is
/// black where the reference averages it (0.17-0.27% of the pixels on the
/// public scenes, counted as black holes), and texture and specular detail
/// alias; 2 x 2 costs 1.2-1.8x a 320 x 240 frame on the software rasteriser
/// (docs/render.md).
RenderParams renderFrameDefaults();

/// "float" | "half" | "compact": the VDL texels of `octree` (RGBA32F, half
/// floats, or shared-exponent RGB9E5 with a scale per octree).
/// @throws InputError naming the value.
void setTexels(GpuOctreeParams& octree, const std::string& name);

/// The ranges of the settings a caller chooses, shared by the command's
/// flags and the Python keywords (frame.width and height: 1..kMaxImageSide,
/// image/image.h).
constexpr int kMaxSupersample = 16;   ///< frame.supersample: 1..
constexpr int kMaxEmitterLights = 16; ///< renderer.emitterLights: 0..
constexpr int kMinShadowMapSize = 16, kMaxShadowMapSize = 8192;  ///< renderer.shadowMapSize

/// Everything that decides the picture, defaults as the command line's.
struct RenderSettings {
  /// Per frame: size, mode, interpolation, GGX lobe, reflections, lighting
  /// source, supersampling, VDLs used.
  RenderParams frame = renderFrameDefaults();
  /// Built once: area lights, emitter VPLs, shadow map size, probe size.
  RendererParams renderer;
  /// How the grid becomes the GPU octree (texel format, cosine correction,
  /// adaptive leaves); the texture limits are the context's, set by the
  /// session.
  GpuOctreeParams octree = renderOctreeDefaults();
  /// With frame.lighting Atlas: where the lightmap UVs come from, whether the
  /// seams are stitched, whether the atlas is evaluated on the GPU.
  UvSource uvSource = UvSource::Default;
  bool stitchSeams = true;
  bool atlasOnGpu = false;

  /// `octree` within `limits`' texture sizes (none: the GL 3.3 limits the
  /// octree stage assumes).
  GpuOctreeParams octreeParams(const GlInfo* limits = nullptr) const;
  /// The atlas settings, with the frames' lookup (shadeParamsOf(frame)).
  LightingParams lightingParams() const;
  /// @throws InputError naming the setting that is out of its range (the
  /// constants above; VDLs 1..kMaxVdls; tolerances 0..1, NaN refused), and a
  /// frame that the memory available cannot hold (checkRenderMemory).
  void check() const;
};

/// What the caller allows the session to do with its inputs.
struct RenderSessionOptions {
  /// Free each texture's texels as its GPU copy is made, and those no
  /// material draws with after the upload (software GL holds both copies in
  /// the process). Off when something else reads them later (a progressive
  /// bake tracing the same scene).
  bool freeTexels = true;
  /// Keep the CPU copies of the octree and, with an atlas, of its bake after
  /// the upload (octree(), atlas()).
  bool keepOctree = false;
  /// The grid's name in warnings (its file).
  std::string gridName = "the grid";
  /// Told of the set-up's stages ("render: set-up": octree, renderer,
  /// free-space light, lighting) and of each frame render() draws; a sink
  /// that throws from a report stops the session there (the Python module's
  /// Ctrl-C). Null: no reports. Must outlive the session.
  ProgressSink* progress = nullptr;
};

/// @brief One render assembled: see the file's comment. The scene must
/// outlive the session and the context must be current on this thread for
/// its whole life.
class RenderSession {
 public:
  /// @param grid the baked light; consumed (freed once its octrees are
  /// built). An empty grid gives an empty octree: direct light alone until
  /// setOctree (a progressive bake's first level).
  /// @throws InputError when the scene's added objects meet --lighting atlas
  /// (the atlas has no texels for them) or the octree exceeds the context's
  /// texture limits; as prepareLighting.
  RenderSession(Scene& scene, VdlGrid grid, const GlContext& context,
                const RenderSettings& settings, const RenderSessionOptions& options = {});
  ~RenderSession();
  RenderSession(const RenderSession&) = delete;
  RenderSession& operator=(const RenderSession&) = delete;

  Renderer& renderer();
  const RenderSettings& settings() const;
  /// The frame settings at `mode` (and the session's size unless given).
  RenderParams frame(RenderMode mode) const;
  /// One frame, linear radiance.
  RgbImage render(const PinholeCamera& camera, RenderMode mode = RenderMode::Full);

  /// Replaces the light with another grid's, built with the session's
  /// octree settings (the sweep's next point; geometry and shadow maps stay).
  void setGrid(const VdlGrid& grid, const GpuOctreeParams& octree);

  /// Depth of the octree drawn (0: none).
  int octreeDepth() const;
  /// The CPU copy of the octree drawn (empty unless options.keepOctree).
  const GpuOctree& octree() const;
  /// The atlas's bake (null unless options.keepOctree and frame.lighting Atlas).
  const LightmapBake* atlas() const;
  /// The set-up's stages, in order: octree, the renderer's own (shaders,
  /// upload, lights, geometry and textures, shadow maps), free-space light,
  /// prepare lighting.
  const std::vector<StageReport>& stages() const;
  /// Summaries for the report: the octree's and, with an atlas, the atlas's.
  std::string octreeSummary() const;
  std::string atlasSummary() const;
  /// What the user should know (e.g. a grid without free-space light for
  /// added objects); the caller prints them.
  const std::vector<std::string>& warnings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The octree a session builds from `grid` with `settings`, without a GL
/// context (the GL 3.3 texture limits): for the CPU lookup.
GpuOctree buildRenderOctree(const VdlGrid& grid, const RenderSettings& settings);

/// The octrees of a CPU lookup of `grid` (the shader's, octree_irradiance.h)
/// as a session builds them without a GL context (the GL 3.3 texture
/// limits): the surfaces' and, when the scene has objects added after the
/// bake, the grid's free-space light for them (reference/first_hit.h's
/// renderOctreeIrradiance draws the image).
struct LookupOctrees {
  GpuOctree surface;
  GpuOctree volume;  ///< empty without added objects or free-space light
  std::vector<std::string> warnings;
};
LookupOctrees buildLookupOctrees(const Scene& scene, const VdlGrid& grid,
                                 const RenderSettings& settings,
                                 const std::string& gridName = "the grid");

}  // namespace lo
