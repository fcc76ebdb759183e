#pragma once
/// @file lightmap/lightmap_bake.h
/// @brief The render-to-atlas path in one call (paper §4.2.3): lightmap UVs
/// chosen as the user asked (the asset's TEXCOORD_1, or automatic charts),
/// then the light octree baked into their pages on the CPU. What `render
/// --lighting atlas`, `view` and `bench_render` call.

#include <string>

#include "lightmap/lightmap_atlas.h"
#include "lightmap/lightmap_uv.h"
#include "octree/gpu_octree.h"
#include "scene/scene.h"

namespace lo {

/// Where lightmap UVs come from.
enum class UvSource {
  Default,    ///< the scene's TEXCOORD_1 when it has one (an invalid one is an error), else charts
  Charts,     ///< automatic charts, whatever the scene has (`--uv auto`)
  Texcoord1,  ///< the scene's TEXCOORD_1, required (`--uv texcoord1`)
};
/// "default" | "auto" | "texcoord1". @throws InputError naming the value.
UvSource parseUvSource(const std::string& name);

struct LightmapParams {
  UvSource uvSource = UvSource::Default;
  /// Charts and packing (automatic charts only). uv.texelSize = 0 here means
  /// a quarter of the octree's voxel (the octree holds nothing finer;
  /// interpolated, its light bends within a voxel, and bilinear texels follow
  /// it to within 1% at a quarter voxel, 3% at a half: tests/render), on the
  /// smallest page (a multiple of 16 texels, at least 64) that holds every
  /// chart, up to uv.atlasSize (then more pages).
  LightmapUvParams uv;
  AtlasBakeParams atlas;  ///< the octree lookup's settings, dilation, seams
  /// With the default texel size (uv.texelSize 0, automatic charts): the
  /// most pages of uv.atlasSize^2 the atlas may take; beyond, the texel is
  /// made coarser until it fits (LightmapBake::note says so). 0: no cap.
  /// `render --lighting atlas` caps (kRenderAtlasPages); `lightmap`, whose
  /// pages are its output, does not.
  int maxPages = 0;
  /// Told of the UVs ("lightmap: UVs", one step) and, unless atlas.progress
  /// is set, the atlas (AtlasBakeParams::progress); a sink that throws from
  /// a report stops the bake there. Null: none.
  ProgressSink* progress = nullptr;
};

struct LightmapBake {
  LightmapUvs uvs;
  LightmapAtlas atlas;
  bool fromTexcoord1 = false;  ///< the UVs are the scene's TEXCOORD_1
  double uvSeconds = 0, atlasSeconds = 0;
  /// Why the texel is coarser than the default (LightmapParams::maxPages),
  /// for a warning; empty when it is not.
  std::string note;
  std::string ToString() const;  ///< one line: UV source, charts, pages, texels, seconds
};

/// @brief UVs by `params.uvSource`, then bakeLightmapAtlas. @throws InputError
/// when TEXCOORD_1 is required or present but unusable (the message names the
/// problem, checkLightmapTexcoords, and suggests `--uv auto`).
LightmapBake bakeLightmap(const Scene& scene, const GpuOctree& octree,
                          const LightmapParams& params = {});

/// The texel size bakeLightmap uses by default: a quarter voxel of `octree`.
float defaultLightmapTexel(const GpuOctree& octree);

}  // namespace lo
