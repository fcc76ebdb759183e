#pragma once
/// @file lightgrid/vdl_grid.h
/// @brief The bake's product, read by every later stage (.vdb files, the GPU
/// octree, the renderers, the sweep): per active voxel the data every light
/// representation shares, plus the representation's payload, here the
/// virtual directional lights (VDLs, paper §3.1.2). Depends on core only.
///
/// The seam for a second representation (spherical harmonics, surface layers)
/// is LightGridVoxels: a new payload derives from it the way VdlGrid does, and
/// the stages that only need positions, normals and total irradiance take the
/// base. See docs/architecture.md, "Where to add a stage".

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "core/math.h"
#include "lightgrid/grid_frame.h"
#include "lightgrid/volume_light.h"

namespace lo {

/// Paper §3.1.2: "we fixed the maximum number of VDLs to 8". The one constant
/// of the VDL limit in C++; shaders/octree_layout.h has LO_MAX_VDLS, and a
/// test asserts that both agree.
constexpr int kMaxVdls = 8;

/// A virtual directional light: irradiance arriving from one direction.
struct Vdl {
  Vec3 irradiance{0, 0, 0};  ///< RGB, W/m^2
  Vec3 direction{0, 0, 0};   ///< unit, world space, towards the light (like wi)
};

/// What every light representation stores per active voxel, in the surface
/// grid's canonical order (sorted by 8^3 block, then position in the block).
struct LightGridVoxels {
  GridFrame frame;
  std::vector<Coord> coords;
  std::vector<Vec3> normals;        ///< unit (oriented towards the light), or zero
  std::vector<float> areas;         ///< geometry area in the voxel, world units^2
  std::vector<Vec3> irradiance;     ///< total RGB irradiance, W/m^2
  /// The share of `irradiance` the voxel's surface reflects, RGB 0..1: the
  /// gathered photons' Photon::reflectance weighted by their power. A
  /// surface that sees this one from below its horizon (a step's riser, a
  /// rail, thinner than a voxel and lit by its floor's VDLs) receives its
  /// light from there (shaders/octree_lookup.h, loSurfaceBelow).
  /// Zero where nothing was gathered or the file does not record it.
  std::vector<Vec3> reflectance;
  std::vector<float> photonCount;   ///< photons gathered for the estimate
  /// The estimate's photon noise: its relative standard error (standard
  /// deviation / luminance of `irradiance`), from the gathered photons'
  /// powers and carried through smoothing and resampling
  /// (docs/accuracy.md, "How good is a bake"); 0 where nothing was gathered
  /// or the file does not record it.
  std::vector<float> noise;
  std::vector<float> radius;        ///< r_k reached, world units

  size_t size() const { return coords.size(); }
};

/// Most surface layers a voxel keeps (docs/accuracy.md, "Surface layers").
constexpr int kMaxLayers = 3;

/// The second and third surface layers of the voxels that have them. A voxel
/// whose photons land on surfaces facing clearly different ways (the faces
/// meeting at an edge, the two sides of a thin wall) keeps one layer per
/// orientation, each with its own normal, gather and VDLs; layer 0 is the
/// voxel's entry in VdlGrid's own arrays, as for every voxel, and layers 1
/// and 2 are the entries here, with the same meaning per field.
struct VdlLayers {
  /// The voxel (index into VdlGrid::coords) each entry belongs to:
  /// ascending, a voxel's layer 1 before its layer 2.
  std::vector<uint32_t> voxel;
  std::vector<Vec3> normals;      ///< unit, facing the side the layer's light arrives from
  std::vector<Vec3> points;       ///< a point of the layer's surface, world space
  std::vector<Vec3> irradiance;   ///< W/m^2, the sum of the layer's VDLs
  std::vector<Vec3> reflectance;  ///< as LightGridVoxels::reflectance
  std::vector<float> photonCount;
  std::vector<float> noise;
  std::vector<float> radius;
  std::vector<float> angularError;
  std::vector<uint8_t> vdlCount;
  std::vector<Vdl> vdls;          ///< size() * VdlGrid::maxVdls, strongest first
  std::vector<Vec3> sh;           ///< size() * VdlGrid::shTerms (SH grids only)

  size_t size() const { return voxel.size(); }
};

/// How a voxel's directional light is stored: VDLs (the paper's), or the
/// irradiance as spherical harmonics of order 1 (4 terms) or 2 (9 terms),
/// the paper's future work (docs/accuracy.md, "Spherical harmonics").
enum class LightRepresentation { Vdl, Sh1, Sh2 };

/// 0 for VDLs, else the SH terms per voxel (4 or 9).
inline int shTermsOf(LightRepresentation r) {
  return r == LightRepresentation::Sh1 ? 4 : r == LightRepresentation::Sh2 ? 9 : 0;
}
/// The representation with `terms` SH terms per voxel (0: VDLs); false
/// when no representation has that many.
inline bool representationOfShTerms(int terms, LightRepresentation* out) {
  for (LightRepresentation r :
       {LightRepresentation::Vdl, LightRepresentation::Sh1, LightRepresentation::Sh2}) {
    if (shTermsOf(r) == terms) {
      *out = r;
      return true;
    }
  }
  return false;
}
/// "vdl", "sh1", "sh2": the flag's and the file metadata's spelling, the
/// one place it is written (parseRepresentation reads it).
inline const char* representationName(LightRepresentation r) {
  return r == LightRepresentation::Sh1 ? "sh1" : r == LightRepresentation::Sh2 ? "sh2" : "vdl";
}
/// representationName's inverse: false for any other text.
inline bool parseRepresentation(const std::string& text, LightRepresentation* out) {
  for (LightRepresentation r :
       {LightRepresentation::Vdl, LightRepresentation::Sh1, LightRepresentation::Sh2}) {
    if (text == representationName(r)) {
      *out = r;
      return true;
    }
  }
  return false;
}
/// Every representation's name, for flag checks and messages.
inline std::vector<std::string> representationNames() {
  return {representationName(LightRepresentation::Vdl), representationName(LightRepresentation::Sh1),
          representationName(LightRepresentation::Sh2)};
}
/// The names as a message lists them: "vdl, sh1 or sh2".
inline std::string representationChoices() {
  const std::vector<std::string> names = representationNames();
  std::string text;
  for (size_t i = 0; i < names.size(); ++i) {
    text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  }
  return text;
}

/// LightGridVoxels with up to `maxVdls` VDLs per voxel (paper §3.1.2); the
/// total irradiance is the sum of the voxel's VDLs. Unused slots are zero.
///
/// Or, when shTerms > 0, the SH representation: per voxel (and layer)
/// shTerms RGB coefficients E_i of the irradiance E(n) = sum_i E_i Y_i(n)
/// (Y_i: shaders/octree_layout.h's loShBasis), scaled so that E at the
/// voxel's normal is its gathered irradiance; the VDL slots are then all
/// empty (counts 0).
struct VdlGrid : LightGridVoxels {
  int maxVdls = 4;
  int shTerms = 0;                  ///< 0: VDLs; 4 or 9: SH of order 1 or 2
  std::vector<Vec3> sh;             ///< size() * shTerms
  std::vector<float> angularError;  ///< weighted std. deviation of chord length (paper §5.3.2)
  std::vector<uint8_t> vdlCount;
  std::vector<Vdl> vdls;            ///< size() * maxVdls, strongest first per voxel
  /// Per voxel, a point of layer 0's surface (world space): what the
  /// renderer's side test (shaders/octree_lookup.h) measures the other
  /// layers' planes against. Used only where the voxel has more layers;
  /// empty = none recorded (files without layers).
  std::vector<Vec3> points;
  VdlLayers layers;  ///< layers 1 and 2 of the voxels that have them
  /// The free-space light (empty when not baked): not a voxel array of the
  /// table above; it has its own, coarser voxels.
  VolumeLight volume;

  const Vdl* vdlsOf(size_t v) const { return vdls.data() + v * size_t(maxVdls); }
  const Vdl* layerVdlsOf(size_t e) const { return layers.vdls.data() + e * size_t(maxVdls); }
  const Vec3* shOf(size_t v) const { return sh.data() + v * size_t(shTerms); }
  const Vec3* layerShOf(size_t e) const { return layers.sh.data() + e * size_t(shTerms); }
  /// The representation the payload holds (shTerms: 0, 4 or 9).
  LightRepresentation representation() const {
    LightRepresentation r = LightRepresentation::Vdl;
    representationOfShTerms(shTerms, &r);
    return r;
  }
  /// Whether voxel v carries light to draw (VDLs, or SH terms).
  bool lit(size_t v) const {
    return shTerms > 0 ? (irradiance[v].x != 0 || irradiance[v].y != 0 || irradiance[v].z != 0)
                       : vdlCount[v] > 0;
  }
};

/// Version of the light-grid file contract (docs/vdb-contract.md), written as
/// the int32 file metadata `format_version`. Readers refuse files with a
/// higher number and read files without the key (written before it existed)
/// as version 1. Version 2 added the surface layers (`layer*` grids);
/// version 3 the SH representation (`sh<i>` grids). A file is written with
/// the lowest version that holds it: VDL files stay version 2, readable by
/// the readers of version 2.
constexpr int kVdlFormatVersion = 3;
constexpr int kVdlFormatVersionVdl = 2;

/// What a light grid means: the settings that made it, stored beside the grids
/// as file metadata.
struct BakeMetadata {
  std::string generator = "lightoctree";
  std::string version = LO_VERSION;
  std::string sourceScene;  ///< the scene file's name ("source_scene")
  /// The scene file as the bake was given it, made absolute
  /// ("source_scene_path"), and sceneContentHash of it and of every file it
  /// reads ("source_scene_hash"), so a reader can tell whether the scene has
  /// changed since (bake.h recordSourceScene); "" when not recorded.
  std::string sourceScenePath, sourceSceneHash;
  int depth = 0;
  int64_t photons = 0;       ///< stored photons
  int64_t emittedPaths = 0;
  int knn = 0;
  float radius = 0;          ///< world units
  std::string vdls;          ///< "4" or "auto"
  /// "vdl", "sh1" or "sh2" (representationName); files before format
  /// version 3 hold VDLs.
  std::string representation = "vdl";
  int64_t seed = 0;
  /// The scene's bounds and (below) the region, in the scene's coordinates:
  /// relative to `sceneOrigin`.
  Bounds3 sceneBounds;
  /// Scene::origin of the baked scene in the file's world coordinates
  /// ("scene_origin", written from the grid's frame.offset when it is not 0;
  /// the grids' transform is in world coordinates, this offset included).
  Vec3d sceneOrigin;
  std::string units = "length: scene units (glTF metres); irradiance: W/m^2 (scene light units)";
  /// Written as kVdlFormatVersion for SH files, kVdlFormatVersionVdl for
  /// VDL files; on reading, the file's value (1 when absent).
  int formatVersion = kVdlFormatVersion;
  /// Set by `convert`: what the file was converted from, e.g. "cornell.vdb (depth 6)".
  std::string convertedFrom;
  /// The gather's accuracy options (docs/accuracy.md); -1 = not recorded
  /// (files written before format version 2).
  int surfaceLayers = -1, gatherOcclusion = -1, edgeCorrection = -1;
  /// 1: the photon map held direct light too (bake --include-direct), so the
  /// VDLs carry it and a renderer must not add it again; 0: indirect only;
  /// -1: not recorded (older files).
  int includeDirect = -1;
  /// The bake's region of interest (`bake --bounds`); empty = the whole scene.
  Bounds3 region;
  /// Sky::fingerprint of the sky the bake lit the scene with ("sky_hash";
  /// "none" without a sky); "" when not recorded (older files).
  std::string skyHash;
};

}  // namespace lo
