#pragma once
/// @file render/atlas_lighting.h
/// @brief The indirect light a Renderer draws with, made ready before the
/// first frame: with Lighting::Atlas, lightmap UVs and the light octree
/// rendered into their pages (paper §4.2.3; src/lightmap on the CPU, or
/// render/atlas_gpu.h in the current GL context) with the frames' own lookup
/// settings, then handed to the renderer (Renderer::setAtlas). What `render`,
/// `view` and `bench_render` call.

#include <optional>

#include "lightmap/lightmap_bake.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "render/renderer.h"
#include "scene/scene.h"

namespace lo {

/// The most pages (of 1024^2 texels) the atlas of `render --lighting atlas`
/// and `view` takes at the default texel size: the public scenes of
/// docs/results take at most 3 (the game level); 200 stacked floors took 13
/// pages and 35 s, 5,000 grew without bound (H13-5-20). Beyond, a coarser
/// texel, with a warning (LightmapParams::maxPages).
constexpr int kRenderAtlasPages = 4;

struct LightingParams {
  /// Octree: the fragment shader walks the octree, nothing to prepare.
  /// Atlas: the atlas is baked and set on the renderer.
  Lighting lighting = Lighting::Octree;
  UvSource uvSource = UvSource::Default;  ///< where the lightmap UVs come from
  /// The atlas lookup's settings. Pass the frames' (shadeParamsOf), so that
  /// a texel holds what the octree lookup computes for those frames.
  OctreeShadeParams shade;
  bool stitchSeams = true;  ///< AtlasBakeParams::stitchSeams (docs/lightmap.md)
  /// Evaluate the octree per texel in the GL context current on this thread
  /// (GpuAtlasEvaluator: the scene shader's lookup); false: on the CPU.
  bool atlasOnGpu = false;
  int maxPages = kRenderAtlasPages;  ///< LightmapParams::maxPages
  ProgressSink* progress = nullptr;  ///< told of the UVs and the atlas; null: none
};

/// The octree lookup settings of frames drawn with `frame`: interpolation,
/// VDLs used and normal offset.
OctreeShadeParams shadeParamsOf(const RenderParams& frame);

/// @brief With params.lighting Atlas: bakeLightmap(scene, octree) with
/// `params` (other settings at LightmapParams' defaults), then
/// renderer.setAtlas; returns the bake, for its report. With Octree: nothing,
/// std::nullopt. `octree` is the one `renderer` draws.
/// @throws InputError as bakeLightmap (a required or present but unusable
/// TEXCOORD_1); GlError from the GPU evaluator.
std::optional<LightmapBake> prepareLighting(Renderer& renderer, const Scene& scene,
                                            const GpuOctree& octree,
                                            const LightingParams& params);

}  // namespace lo
