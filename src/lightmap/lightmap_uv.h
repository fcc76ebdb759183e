#pragma once
/// @file lightmap/lightmap_uv.h
/// @brief Lightmap UVs for the render-to-atlas path (paper §4.2.3): automatic
/// charts, a least-squares conformal map per chart (Lévy et al. 2002) and the
/// charts packed into square atlas pages. Geometry only: evaluating the light
/// grid at the texels and exporting the UVs belong to later steps, which take
/// the plain data below.
///
/// Spaces and units: chart geometry is measured in scene units (world space);
/// UVs are in [0, 1] of their page with the texel convention of OpenGL (texel i
/// covers [i, i + 1) of u * width, its centre at i + 0.5). Every non-degenerate
/// triangle is laid out counter-clockwise in the (u, v) plane (u right, v up)
/// when seen from the side its winding's normal points to: its signed UV area
/// is positive. Eigen (the LSCM solve) and stb_rect_pack (the packing) stay
/// inside this stage.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "image/image.h"
#include "scene/scene.h"

namespace lo {

/// @brief How charts are cut, flattened and packed. Defaults suit one 1024^2
/// page for a scene of a few hundred thousand triangles.
struct LightmapUvParams {
  /// World units (scene units) per texel. 0 = derive it from atlasSize so that
  /// all charts fill about one page (the largest texel density that packs).
  float texelSize = 0;
  int atlasSize = 1024;  ///< page width = height, texels; at least 2 * gutter + 1
  int gutter = 2;        ///< empty texels between charts and at page borders, >= 0
  /// Region growing: a face joins a chart when its normal is within this angle
  /// (degrees, in (0, 180]) of the chart's running area-weighted mean normal.
  float chartConeDegrees = 45;
  /// Split a chart when the L2 stretch (Sander et al. 2001) of its flattening,
  /// scaled to its 3D area, exceeds this (>= 1; 1 = isometric).
  float maxStretch = 2.0f;
};

/// @brief Per-triangle lightmap UVs and their atlas: plain data for the bake
/// (one texel per sample) and the glTF export (TEXCOORD_1 + page index).
struct LightmapUvs {
  int width = 0, height = 0;  ///< page size in texels
  int pageCount = 0;
  /// Empty texels the packing keeps between charts and at the page borders
  /// (LightmapUvParams::gutter); 0 where unknown (TEXCOORD_1). The atlas bake
  /// dilates this many rings by default (lightmap/lightmap_atlas.h).
  int gutter = 0;
  /// 6 floats per triangle: corner UVs (u0 v0 u1 v1 u2 v2) in [0, 1] of its
  /// page, corners in the order of Scene::indices.
  std::vector<float> uv;
  std::vector<int32_t> trianglePage;  ///< per triangle; 0 for degenerate triangles
  /// Per triangle; -1 for a degenerate triangle (zero area, or a height below
  /// the float resolution of the scene's or the atlas's coordinates): its uv is 0.
  std::vector<int32_t> triangleChart;
  int chartCount = 0;
  int degenerateTriangles = 0;  ///< triangles with triangleChart == -1
  float texelSize = 0;          ///< world units per texel actually used
  /// Chart area in texels over all texels of all pages (the fraction a
  /// conservative rasteriser would cover, less the partial edge texels).
  float utilisation = 0;
  float worstStretch = 1;  ///< max over charts of the L2 stretch (1 = isometric)

  std::string ToString() const;
};

/// @brief Cuts the scene's non-degenerate triangles into charts, flattens each
/// (planar charts by projection, the others by LSCM; a chart whose stretch
/// exceeds params.maxStretch or whose flattening folds is split), scales each
/// to its 3D area (one world texel density), and packs their bounding
/// rectangles plus gutter into pages of params.atlasSize. Deterministic: the
/// same scene and params give the same bytes.
/// @throws InputError for a bad parameter (naming the field) or bad indices
/// (checkSceneIndices).
LightmapUvs buildLightmapUvs(const Scene& scene, const LightmapUvParams& params);

/// @brief buildLightmapUvs in two steps: the charts cut and flattened once
/// (the constructor: params' chartConeDegrees and maxStretch), then packed
/// at any page and texel size (pack). What bakeLightmap's search for the
/// smallest page that holds them calls, once per size it tries (it cut and
/// flattened the scene anew for each: 19 s of 22 for a scene of 10^6
/// triangles). Holds a reference to `scene`; not thread-safe.
class LightmapCharts {
 public:
  /// @throws InputError as buildLightmapUvs.
  LightmapCharts(const Scene& scene, const LightmapUvParams& params);
  ~LightmapCharts();
  LightmapCharts(const LightmapCharts&) = delete;
  LightmapCharts& operator=(const LightmapCharts&) = delete;

  /// buildLightmapUvs(scene, params), the same bytes. @throws InputError as
  /// it does, and when params' chartConeDegrees or maxStretch are not the
  /// constructor's.
  LightmapUvs pack(const LightmapUvParams& params);

  /// True when pack(params) certainly needs more than one page: at params'
  /// texel size (> 0) the charts' rectangles take more area than a page has.
  /// False promises nothing. For the search for a page that holds them all,
  /// which need not pack the sizes that cannot (a million charts packed at
  /// every size tried took 43 s).
  bool exceedsOnePage(const LightmapUvParams& params) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// @brief The TEXCOORD_1 check: the scene's second UV set can serve as
/// lightmap UVs when it exists (2 floats per vertex), every value is finite
/// and inside [0, 1], and no two non-degenerate triangles overlap in UV space
/// (sharing an edge or a corner is fine; mirrored charts are fine).
/// @throws InputError naming what is wrong: "missing", the triangle, corner and
/// value "outside [0, 1]", or the two triangles that "overlap".
void checkLightmapTexcoords(const Scene& scene);

/// @brief Wraps texcoords1 into a LightmapUvs of one atlasSize^2 page after
/// checkLightmapTexcoords. Charts are the UV islands (triangles sharing an
/// edge in position and UV); texelSize is the mean world size of a texel,
/// worstStretch is measured as for buildLightmapUvs.
/// @throws InputError as checkLightmapTexcoords, or for atlasSize < 1.
LightmapUvs lightmapUvsFromTexcoord1(const Scene& scene, int atlasSize);

/// @brief A picture of page `page`'s layout: each texel whose centre lies in a
/// triangle takes its chart's colour (a hash of the chart index), chart
/// borders a darker shade of it, empty texels black. Row 0 is v = 0 (the
/// atlas convention: written as an image, the layout shows upside down).
/// For looking at charts (`lightmap --chart-image`, docs/lightmap.md).
/// @throws InputError when `page` is not a page of `uvs`.
RgbImage chartLayoutImage(const LightmapUvs& uvs, int page);

}  // namespace lo
