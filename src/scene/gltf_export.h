#pragma once
/// @file scene/gltf_export.h
/// @brief The flattened Scene written back as glTF 2.0 with a lightmap laid
/// over it: lightmap UVs as TEXCOORD_1 and, on each material, `extras.lightmap`
/// naming the atlas page image beside the file (docs/lightmap.md, "Export",
/// has the schema). Optionally the unlit preview form: every material
/// KHR_materials_unlit with the baked radiance as its base colour texture, so
/// that any glTF viewer shows the lit scene as baked.
///
/// Plain data in, file out: this stage knows nothing of the lightmap stage's
/// types (src/scene is above src/lightmap in the pipeline); the caller copies
/// its UVs, page file names and encoded preview pages into LightmapExport.
///
/// What is written: the scene in world space as one mesh node (node
/// transforms were applied on load), one primitive per (material, lightmap
/// page) pair in the order of (material index, page), triangles in scene
/// order within each; vertices welded per primitive by (scene vertex,
/// lightmap UV). Attributes: POSITION, NORMAL (when the scene has vertex
/// normals), TANGENT (normal-mapped materials: the frame Scene::shadingNormal
/// uses, averaged per vertex, w = 1), TEXCOORD_0 (the scene's, or a copy of the lightmap UVs when
/// it has none: glTF wants TEXCOORD_n numbered from 0), TEXCOORD_1 = the lightmap UVs, and
/// TEXCOORD_2 = the scene's own second UV set where it differs from the lightmap UVs (its maps are
/// then pointed at texCoord 2). Materials keep their factors, alpha mode, doubleSided, emission
/// (strength through KHR_materials_emissive_strength when above 1), transmission, ior and volume,
/// and their textures re-encoded as 8-bit PNG from the Scene's decoded texels (colour maps back
/// through the sRGB curve, data maps as stored), with KHR_texture_transform kept as an extension.
/// Punctual lights (KHR_lights_punctual) and perspective cameras become nodes.

#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace lo {
class AtomicFileSet;  // core/file_set.h
}

namespace lo {

/// @brief A lightmap for writeLightmapGltf, as plain data.
struct LightmapExport {
  /// 6 floats per triangle: the lightmap UVs (u0 v0 u1 v1 u2 v2) in [0, 1] of
  /// the triangle's page, corners in the order of Scene::indices, written as
  /// TEXCOORD_1 as they are. glTF's convention, which the lightmap stage
  /// shares: v = 0 is the top row of a page image (row 0 of the file), so a
  /// texel row y of a page is image row y and no flip is needed anywhere.
  std::vector<float> uv;
  std::vector<int32_t> trianglePage;  ///< per triangle, in [0, pageUris.size())
  int width = 0, height = 0;          ///< page size in texels (recorded in the extras)
  /// Per page: the page image's file name relative to the glTF's folder
  /// (written there by the caller), percent-encoded on output as glTF uris are.
  std::vector<std::string> pageUris;
  /// Per page, or empty: the page's direction image (a directional lightmap,
  /// image/image.h encodeUnitVectorPng of LightmapAtlas::direction), named
  /// like pageUris; recorded as extras.lightmap.direction.
  std::vector<std::string> directionUris;
  /// How the page images hold E: "linear-exr" (32-bit float RGB, W/m^2 as is)
  /// or "rgbm-png" (image/image.h encodeRgbmPng with rgbmRange).
  std::string encoding = "linear-exr";
  float rgbmRange = 0;  ///< "rgbm-png": the range the pages were encoded with, > 0
  /// What E holds: "indirect" (the light octree: indirect light only; a
  /// viewer adds direct light from the scene's lights) or "full".
  std::string content = "indirect";
  /// The unlit preview form instead of the lit one (see the file comment).
  bool unlit = false;
  /// unlit: per page, an encoded PNG (sRGB) of the radiance to show
  /// (LightmapAtlas::radiance * 2^previewExposureEv, clamped), embedded.
  std::vector<std::vector<unsigned char>> previewPng;
  float previewExposureEv = 0;  ///< recorded in the preview's extras
};

/// The encoded files of an export, in memory.
struct GltfFiles {
  std::string gltf;    ///< the .glb, or the .gltf's JSON text
  std::string bin;     ///< the .gltf's buffer (empty for a .glb)
  std::string binUri;  ///< the .gltf's buffer file name beside it ("" for a .glb)
};

/// @brief Encodes the export (see the file comment) for `path`: a .glb (one
/// file, buffer in its BIN chunk) or a .gltf (JSON, and its buffer as
/// "<stem>.bin" beside it). Images (textures, preview pages) live in the
/// buffer, so neither form needs any other file; the lightmap pages of the
/// lit form are referenced from the extras only.
/// @throws InputError naming the field for a LightmapExport that does not
/// match the scene (sizes, pages, UVs outside [0, 1], encoding), an empty
/// scene, or an extension other than .glb / .gltf.
GltfFiles encodeLightmapGltf(const Scene& scene, const LightmapExport& lightmap,
                             const std::string& path);

/// @brief Writes `files`, encodeLightmapGltf's for `path` (a .gltf's .bin,
/// then the .gltf), as one set of outputs (core/file_set.h): into `set` when
/// given (renamed by its commit), else committed here.
/// @throws IoError naming the file.
void writeGltfFiles(const GltfFiles& files, const std::string& path, AtomicFileSet* set = nullptr);

/// @brief encodeLightmapGltf, then writeGltfFiles.
/// @throws InputError as encodeLightmapGltf; IoError naming the file.
void writeLightmapGltf(const Scene& scene, const LightmapExport& lightmap, const std::string& path);

}  // namespace lo
