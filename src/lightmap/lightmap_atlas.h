#pragma once
/// @file lightmap/lightmap_atlas.h
/// @brief Render to atlas (paper §4.2.3), the CPU path: the light octree
/// evaluated at every texel the lightmap UVs' triangles touch, the empty
/// texels around the charts filled, and the charts' seams stitched. What the
/// renderer's octree lookup gives at a surface point, stored per texel, so a
/// renderer may read a texture instead of walking the octree.
///
/// Texels and spaces: texel (x, y) of page p covers u in [x, x + 1) / width
/// and v in [y, y + 1) / height of the page (LightmapUvs' convention) and is
/// pixel (x, y) of the page's images (index y * width + x). Row 0 is v = 0:
/// the order of a GL upload and of glTF, whose v = 0 is an image's top row;
/// a picture of a page shows the UV layout upside down (v grows downwards).
/// Positions and directions are world space; irradiance is W/m^2.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "core/progress.h"
#include "image/image.h"
#include "lightmap/lightmap_uv.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "scene/scene.h"

namespace lo {

/// LightmapAtlas::coverage values.
constexpr uint8_t kAtlasEmpty = 0;    ///< no triangle, not dilated: black
constexpr uint8_t kAtlasCovered = 1;  ///< a triangle's UV footprint overlaps the texel
constexpr uint8_t kAtlasDilated = 2;  ///< filled from its neighbours by dilation

/// A covered texel's surface point, as AtlasBakeParams::directLight gets it.
struct AtlasSurfacePoint {
  Vec3 position;          ///< world space
  uint32_t triangle = 0;  ///< the scene triangle the texel samples
  Vec3 normal;            ///< unit, the interpolated vertex normal (the side baked)
};

/// One page rasterised and evaluated (steps 1 and 2 of bakeLightmapAtlas),
/// each vector or image width x height texels of the page.
struct AtlasPageTexels {
  std::vector<int32_t> triangle;  ///< the scene triangle owning each texel, -1 = none
  RgbImage irradiance;            ///< E at the owner's surface point (0 where none)
  RgbImage direction;             ///< unit direction sum, or zero (LightmapAtlas::direction)
};

/// Steps 1 and 2 of bakeLightmapAtlas done by another implementation: the
/// GPU's, lo_render's GpuAtlasEvaluator (render/atlas_gpu.h), which draws the
/// triangles at their lightmap UVs and runs the same octree lookup in a
/// fragment shader. It must follow the rules of those steps (which texels a
/// triangle covers, which triangle owns a texel, the surface point and normal
/// it is evaluated at); the rest of the bake (direct light, dilation, seams,
/// radiance) stays bakeLightmapAtlas's.
class AtlasPageEvaluator {
 public:
  virtual ~AtlasPageEvaluator() = default;
  /// Called once per bake, before the pages: the inputs, already checked.
  virtual void begin(const Scene& scene, const LightmapUvs& uvs, const GpuOctree& octree,
                     const OctreeShadeParams& shade) = 0;
  /// The triangles of `page` (those with a chart and UV area, in index order).
  virtual AtlasPageTexels evaluatePage(int page, const std::vector<int32_t>& triangles) = 0;
};

/// Which side of each triangle's surface its texels hold: +1 the side its
/// shading normal faces, -1 the other. A texel holds one side's light; a
/// surface drawn from both sides (glTF doubleSided, OBJ) whose normals face
/// away from its light (a room modelled with outward normals) held the dark
/// outside, and the room's lightmap was three quarters black where the
/// renderer shows it lit. Such a triangle's texels take the side whose
/// irradiance (the octree's, each point's own voxel alone, summed over seven
/// points spread over the triangle) is larger; a one-sided one keeps its
/// normal's. Both the CPU
/// bake and GpuAtlasEvaluator follow it.
std::vector<int8_t> atlasSurfaceSides(const Scene& scene, const GpuOctree& octree,
                                      const OctreeShadeParams& shade);

/// Peak memory per page texel of a lightmap bake and its export, measured
/// (`lightmap` on the Cornell box, one 4096^2 page: 634 MB peak without the
/// preview, 1.19 GB with it): the pages, coverage, the triangle and surface
/// point per texel, the images written. checkAtlasMemory refuses a bake
/// beyond the memory available with these before any page is allocated.
constexpr size_t kAtlasBytesPerTexel = 40;
/// What AtlasBakeParams::radiance (the preview) adds per texel.
constexpr size_t kAtlasRadianceBytesPerTexel = 36;

/// @throws InputError, before any page exists, when `uvs`' pages need more
/// memory than is available (kAtlasBytesPerTexel, plus
/// kAtlasRadianceBytesPerTexel with `radiance`), naming --texel-size and the
/// figures.
void checkAtlasMemory(const LightmapUvs& uvs, bool radiance);

struct AtlasBakeParams {
  /// The lookup's settings (interpolation, VDLs used, normal offset): pass
  /// the renderer's, so that the atlas holds what it would compute.
  OctreeShadeParams shade;
  /// Rings of empty texels around the covered ones to fill (8-neighbours),
  /// >= -1. -1 = LightmapUvs::gutter, at least 1: one ring is what a bilinear
  /// lookup anywhere on a triangle reads beyond the covered texels; the
  /// gutter is the most that packing left free between charts. 0 = none.
  int dilation = -1;
  /// Make the bilinear lookups on the two sides of every chart seam agree
  /// (a sparse least-squares solve over the texels those lookups read).
  /// Stitching runs after dilation: the lookups at a chart's border read
  /// the first dilated ring.
  bool stitchSeams = true;
  /// Also bake LightmapAtlas::radiance: what a viewer should show of a
  /// diffuse surface, albedo / pi * E + emission, for previews in tools
  /// that know no lightmaps (the glTF export's unlit form).
  bool radiance = false;
  /// Set: E also holds the direct light (`lightmap --content full`), this
  /// function's value at the covered texels' surface points (the lightmap
  /// command passes the path tracer's DirectIrradiance::atMany: ray-traced
  /// soft shadows; this stage itself links no ray tracer). The direction
  /// keeps the indirect light's. Called once per page, points in texel order;
  /// it calls `alive` (on any thread) as it goes, so that the bake's progress
  /// reports stay a quarter second apart (Progress::heartbeat).
  std::function<std::vector<Vec3>(const std::vector<AtlasSurfacePoint>&, int page,
                                  const std::function<void()>& alive)>
      directLight;
  /// Set: steps 1 and 2 are done by it (not owned; it must outlive the
  /// call), its time counted as LightmapAtlas::evaluateSeconds. Null: on
  /// the CPU, with octreeIrradianceSample.
  AtlasPageEvaluator* evaluator = nullptr;
  /// Told of the work ("lightmap: atlas": each row of texels evaluated,
  /// each page dilated, the seams stitched); a sink that throws from a
  /// report stops the bake there (the Python module's Ctrl-C). Null: none.
  ProgressSink* progress = nullptr;
};

/// The baked pages. Each vector holds pageCount entries, each page width x
/// height texels.
struct LightmapAtlas {
  int width = 0, height = 0, pageCount = 0;
  /// E (W/m^2, RGB) per texel: octreeIrradiance at the texel's surface point
  /// and shading normal. Dilated texels: the mean of their filled
  /// neighbours. Empty texels: 0. Stitching then moves the texels that the
  /// lookups along seams read by the least change that joins the two sides,
  /// mostly the dilated ones (which may go below zero there: a renderer sees
  /// them only blended with the covered texels beside them).
  std::vector<RgbImage> irradiance;
  /// A directional lightmap: the unit luminance-weighted mean VDL direction
  /// (OctreeIrradianceSample::directionSum normalized; world space, towards
  /// the light; components may be negative, stored as is), zero where no
  /// light arrives. With E and the shading normal n a renderer rebuilds one
  /// VDL per texel for its specular term.
  std::vector<RgbImage> direction;
  /// Only with AtlasBakeParams::radiance (else empty): per texel the
  /// outgoing radiance of a Lambertian surface, W/(m^2 sr) (RGB):
  ///   L = albedo / pi * E + emission,
  /// albedo = Scene::albedo and emission = Scene::emission of the texel's
  /// triangle at its surface point (the one E is evaluated at), E the
  /// texel's final (stitched) irradiance. Dilated texels take the mean albedo
  /// and emission of their filled neighbours, ring by ring as E does, so the
  /// gutter continues the chart beside it. Not stitched itself: where E
  /// agrees across a seam, L agrees wherever the albedo does, and a change of
  /// material at a seam stays sharp. L follows E's sign: a dilated texel that
  /// stitching pushed below zero gives L below the emission there.
  std::vector<RgbImage> radiance;
  /// Per page, width * height values kAtlasEmpty / kAtlasCovered / kAtlasDilated.
  std::vector<std::vector<uint8_t>> coverage;

  int dilation = 0;             ///< rings dilated (the resolved parameter)
  size_t coveredTexels = 0;     ///< texels with kAtlasCovered, all pages
  size_t dilatedTexels = 0;     ///< texels with kAtlasDilated, all pages
  size_t skippedTriangles = 0;  ///< charted triangles with zero UV area (no texel)
  size_t seamEdges = 0;         ///< mesh edges whose two sides differ in UV or page
  size_t seamSamples = 0;       ///< points stitched along them (about 2 per texel)
  size_t stitchedTexels = 0;    ///< texels the stitching solve could move
  /// Largest |E_a - E_b| (W/m^2, any channel) between the bilinear lookups
  /// of the two sides of a seam sample, before and after stitching (equal
  /// when stitchSeams is off).
  float seamMismatchBefore = 0, seamMismatchAfter = 0;
  /// Wall time of each phase, seconds.
  double rasterSeconds = 0, evaluateSeconds = 0, dilateSeconds = 0, stitchSeconds = 0;

  double seconds() const { return rasterSeconds + evaluateSeconds + dilateSeconds + stitchSeconds; }
  std::string ToString() const;  ///< sizes, counts and times
};

/// @brief Bakes `octree` into the atlas of `uvs` (paper §4.2.3, render to
/// atlas; docs/lightmap.md, "Octree into atlas"):
///  1. conservative rasterisation in UV space: every texel whose square
///     overlaps a triangle's UV footprint (separating axes; touching is not
///     overlapping) belongs to the triangle whose footprint contains the
///     texel centre, else to the nearest (in UV), ties to the lower triangle
///     index;
///  2. each covered texel evaluated at the point of its triangle nearest to
///     its centre (in UV), mapped to world space by barycentrics, with the
///     interpolated vertex normal (Scene::normals, else the face normal);
///  3. `dilation` rings of empty texels filled with the mean of their
///     filled 8-neighbours;
///  4. seams stitched (params.stitchSeams): along every edge that two
///     triangles share in 3D (welded by exact position, consistently
///     oriented) but not in UV, about two points per texel; the texels that
///     the bilinear lookups at those points read on both sides are moved by
///     the least (weighted) change that makes the two sides' lookups agree.
/// Triangles without a chart (LightmapUvs::triangleChart -1) get no texel.
/// Deterministic: the same inputs give the same bytes.
/// @throws InputError for a bad parameter (naming the field), UVs that do
/// not match the scene (naming the array), or bad indices (checkSceneIndices).
LightmapAtlas bakeLightmapAtlas(const Scene& scene, const LightmapUvs& uvs, const GpuOctree& octree,
                                const AtlasBakeParams& params = {});

}  // namespace lo
