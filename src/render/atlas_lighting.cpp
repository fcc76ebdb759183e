#include "render/atlas_lighting.h"

#include <memory>

#include "render/atlas_gpu.h"

namespace lo {

OctreeShadeParams shadeParamsOf(const RenderParams& frame) {
  OctreeShadeParams shade;
  shade.interpolation = frame.interpolation;
  shade.maxVdls = frame.maxVdls;
  shade.normalOffset = frame.normalOffset;
  return shade;
}

std::optional<LightmapBake> prepareLighting(Renderer& renderer, const Scene& scene,
                                            const GpuOctree& octree,
                                            const LightingParams& params) {
  if (params.lighting != Lighting::Atlas) return std::nullopt;
  LightmapParams lightmap;
  lightmap.uvSource = params.uvSource;
  lightmap.atlas.shade = params.shade;
  lightmap.atlas.stitchSeams = params.stitchSeams;
  lightmap.maxPages = params.maxPages;
  lightmap.progress = params.progress;
  std::unique_ptr<GpuAtlasEvaluator> gpu;
  if (params.atlasOnGpu) {
    gpu = std::make_unique<GpuAtlasEvaluator>();
    lightmap.atlas.evaluator = gpu.get();
  }
  LightmapBake baked = bakeLightmap(scene, octree, lightmap);
  renderer.setAtlas(baked.uvs, baked.atlas);
  return baked;
}

}  // namespace lo
