#pragma once
/// @file export/lightmap_export.h
/// @brief A baked light grid as lightmaps other tools open, in one call
/// (`lightoctree lightmap`, docs/lightmap.md): the renderer's light octree,
/// lightmap UVs and their atlas (src/lightmap on the CPU, or render/atlas_gpu.h
/// in a headless GL context; with the reference path tracer's direct light
/// for AtlasContent::Full), the pages encoded (linear EXR or RGBM PNG), and
/// the scene written as glTF 2.0 with them (scene/gltf_export.h), optionally
/// with an unlit preview and chart layout images.
///
/// This stage sits after src/render and src/reference because it wires them
/// into the lightmap bake, which links neither a ray tracer nor GL itself.
///
/// Files, for params.output D/OUT.glb or D/OUT.gltf, in the order written:
///   D/OUT-lightmapN.exr | .png   one per atlas page
///   D/OUT-directionN.png         directionPages, one per atlas page
///   D/OUT.bin, D/OUT.gltf | D/OUT.glb
///   D/OUT-preview.glb            preview
///   D/OUT-chartsN.png            chartImages, one per page
/// Each is written atomically (core/file.h), and all of them as one: when
/// one cannot be written, those written before it are removed again. Files
/// an earlier export left beside OUT under those numbered names that this
/// one does not write (more pages, direction pages, the other page format)
/// are removed with the commit.

#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "core/file.h"
#include "core/file_set.h"
#include "core/progress.h"
#include <vector>

#include "core/resources.h"
#include "lightgrid/vdl_grid.h"
#include "lightmap/lightmap_bake.h"
#include "render/context.h"
#include "scene/scene.h"

namespace lo {

/// What the atlas holds.
enum class AtlasContent {
  Indirect,  ///< the light octree alone (what `bake` stores by default)
  Full,      ///< the direct light too, ray traced with soft shadows: a complete lightmap
};
/// "indirect" | "full". @throws InputError naming --content and the value.
AtlasContent parseAtlasContent(const std::string& name);
const char* toString(AtlasContent content);  ///< "indirect" | "full"
/// Whether an export of `content` writes direction pages: `directions` "on",
/// "off", or "" (not given: on for AtlasContent::Indirect; Full writes none,
/// its light holding direct light from other directions than the one a page
/// would give). @throws InputError naming `flag` for "on" with Full (it was
/// ignored without a word, H17-4-1) and for any other text.
bool directionPagesOf(const std::string& directions, AtlasContent content, const std::string& flag);

struct LightmapExportResult;

struct LightmapExportParams {
  std::string output;  ///< the lit glTF: .glb (one file) or .gltf (+ .bin)
  /// UVs and atlas settings. The octree lookup keeps its defaults (those of
  /// `render`), so that the atlas holds what the renderer computes;
  /// atlas.radiance, atlas.directLight and atlas.evaluator are set here from
  /// the fields below.
  LightmapParams lightmap;
  AtlasContent content = AtlasContent::Indirect;
  int directSamples = 64;  ///< Full: emitter samples per texel (shadow rays)
  /// Pages as RGBM in 8-bit PNGs, the range the next power of two at or
  /// above the brightest texel (recorded in the glTF); false: linear 32-bit
  /// float EXR, W/m^2.
  bool rgbm = false;
  /// Also OUT-preview.glb: every material unlit with the baked radiance
  /// (albedo / pi * E + emission) as its base colour, for any glTF viewer.
  bool preview = false;
  float previewExposureEv = 0;  ///< the preview's exposure, EV (radiance * 2^EV)
  bool chartImages = false;     ///< also OUT-chartsN.png, each page's UV layout
  /// Also OUT-directionN.png beside each page: the atlas's per-texel mean
  /// light direction (LightmapAtlas::direction, world space,
  /// encodeUnitVectorPng), named in extras.lightmap.direction, so a viewer
  /// can shade normal maps and glossy surfaces from the lightmap. Indirect
  /// content only: with the direct light in E (AtlasContent::Full) the
  /// atlas's direction would describe only its indirect part, so none are
  /// written.
  bool directionPages = true;
  /// Set: the octree is rendered into the atlas by GL in a headless context
  /// of this kind (OSMesa or EGL). Unset: on the CPU (the same bytes on every
  /// machine).
  std::optional<GlBackend> atlasGl;
  /// Called with the result and the export's set of files just before the
  /// set is renamed into place: a command adds its side files (its `--json`
  /// report) there, so that they appear with the set or not at all.
  std::function<void(const LightmapExportResult&, AtomicFileSet&)> beforeCommit;
  /// Told of each step (core/progress.h): "lightmap: octree", "lightmap:
  /// atlas", "lightmap: encode", then "lightmap: write", one step per file
  /// and the last before the commit. A sink that throws from begin() or
  /// from update() with done < total stops the export there: files not yet
  /// committed are removed, an earlier export's set stays as it was (the
  /// Python module's Ctrl-C; the command ends by the signal itself). Null:
  /// nothing told.
  ProgressSink* progress = nullptr;
  /// Told, by exportLightmap(scene, path), once it has read the grid and
  /// before the work, of what its metadata says against this export: baked
  /// from another version of the scene, under another sky (gridWarnings),
  /// or with the direct light in it that --content full traces again. A
  /// `warn` that throws (Python's warnings as errors) stops the export
  /// before any file is written. Null: nothing told.
  std::function<void(const std::string&)> warn;
};

struct LightmapExportResult {
  LightmapBake lightmap;  ///< the UVs and the atlas
  size_t octreeLeaves = 0, octreePoolBytes = 0, octreeVdlBytes = 0;
  std::string glInfo;  ///< with atlasGl: the context's GlInfo::ToString(), else ""
  /// One row each: octree, UVs, atlas: raster / evaluate / dilate / stitch,
  /// encode, write.
  std::vector<StageReport> stages;
  float rgbmRange = 0;                 ///< rgbm: the pages' range, W/m^2
  std::vector<std::string> pagePaths;  ///< per page, as written
  std::vector<std::string> directionPaths;  ///< directionPages: per page, else empty
  std::string output;                  ///< params.output
  std::string previewPath;             ///< preview: OUT-preview.glb, else ""
  std::vector<std::string> chartPaths;  ///< chartImages: per page
  size_t pageFileBytes = 0;             ///< the page files' sizes together
  size_t outputBytes = 0;               ///< the lit glTF's (and its .bin's) bytes
  size_t previewBytes = 0;              ///< the preview's bytes
  /// The grid file's metadata (exportLightmap of a .vdb path; else default).
  BakeMetadata gridMetadata;
};

/// @throws InputError naming `flag` when `output` ends in neither .glb nor
/// .gltf (checked by exportLightmap too; commands call it before any work).
void checkLightmapExportPath(const std::string& output, const char* flag = "--output");

/// D/OUT-lightmapN.exr (or .png with rgbm) for `output` D/OUT.glb or .gltf.
std::string lightmapPagePath(const std::string& output, int page, bool rgbm);
/// D/OUT-directionN.png, the direction image of page N.
std::string lightmapDirectionPath(const std::string& output, int page);

/// Refuses, before any work, an export some file of which would replace one
/// of `inputs` (the scene, its buffers and images, the grid: checkDistinctFiles'
/// pairs): the glTF, its .bin (a .gltf output), the preview, and any input
/// beside the output named like a numbered page (.exr or .png), direction
/// page or chart image: the export writes those, or removes the ones an
/// earlier export left that it does not write. @throws InputError naming both.
void checkLightmapOutputs(const std::string& output, bool preview, const NamedPaths& inputs);

/// @brief The export described in the file comment of `grid` over `scene`.
/// @throws InputError for a bad output path, unusable TEXCOORD_1 (see
/// bakeLightmap) or an export that does not match the scene; IoError naming
/// the file that could not be written (nothing is left behind); GlError when
/// the GL context or its evaluator fail.
LightmapExportResult exportLightmap(const Scene& scene, const VdlGrid& grid,
                                    const LightmapExportParams& params);

/// @brief exportLightmap of the grid in the .vdb file `lightsPath` (read in
/// the "octree" row). @throws as readVdlGrid (vdb/vdb_io.h) and as above.
LightmapExportResult exportLightmap(const Scene& scene, const std::string& lightsPath,
                                    const LightmapExportParams& params);

/// @brief What an export made, as `lightoctree lightmap` prints it after its
/// stage table, one line each: the UVs, the atlas (texels, seam mismatch
/// before and after stitching), the memory, the RGBM range (params.rgbm),
/// and every file written (pages, direction pages, the glTF, the preview,
/// chart images), each line ending in a newline.
std::string lightmapExportSummary(const LightmapExportResult& result,
                                  const LightmapExportParams& params);

}  // namespace lo
