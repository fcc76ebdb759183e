#pragma once
/// @file render/atlas_gpu.h
/// @brief Render to atlas on the GPU (paper §4.2.3: "rendering the 3D octree
/// in the atlas, capturing it"): every triangle drawn at its lightmap UV into
/// a page-sized framebuffer, conservatively (every texel its UV footprint
/// overlaps gets a fragment), and the light octree evaluated per texel by the
/// lookup the scene shader uses (shaders/octree_lookup.h, loOctreeIrradiance;
/// shaders/atlas_bake.*). It does steps 1 and 2 of bakeLightmapAtlas
/// (lightmap/lightmap_atlas.h) by that function's rules; dilation, seams,
/// direct light and radiance stay on the CPU. The CPU path computes the same
/// texels in double precision where this one uses the GPU's floats: a test
/// holds the two to each other (tests/render/test_atlas_gpu.cpp).

#include <memory>
#include <vector>

#include "lightmap/lightmap_atlas.h"

namespace lo {

/// Pass as AtlasBakeParams::evaluator (or LightmapParams::atlas.evaluator).
/// Requires a current GL context (render/context.h) for its whole life, the
/// same one for every call.
class GpuAtlasEvaluator final : public AtlasPageEvaluator {
 public:
  /// Builds the program. @throws GlError when it does not compile or link.
  GpuAtlasEvaluator();
  ~GpuAtlasEvaluator() override;
  GpuAtlasEvaluator(const GpuAtlasEvaluator&) = delete;
  GpuAtlasEvaluator& operator=(const GpuAtlasEvaluator&) = delete;

  /// Uploads the octree and the page size. @throws InputError when the
  /// octree's textures or a page exceed the context's limits (naming which).
  void begin(const Scene& scene, const LightmapUvs& uvs, const GpuOctree& octree,
             const OctreeShadeParams& shade) override;
  /// Draws `triangles` (in that order) and reads the page back.
  AtlasPageTexels evaluatePage(int page, const std::vector<int32_t>& triangles) override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace lo
