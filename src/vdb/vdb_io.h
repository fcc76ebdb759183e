#pragma once
/// @file vdb/vdb_io.h
/// @brief .vdb files: the VDL grid contract users open in Houdini and Blender,
/// and the photon map as an OpenVDB PointDataGrid. OpenVDB is visible only in
/// src/grid and src/vdb. See docs/vdb-contract.md.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "lightgrid/photon.h"
#include "lightgrid/vdl_grid.h"

namespace lo {

class AtomicFileSet;  // core/file_set.h

/// Grids of the contract a file may leave out (`convert --drop`): readVdlGrid
/// fills them with 0. The others (irradiance, normal, vdl_count, vdl<i>_*) are
/// required.
const std::vector<std::string>& optionalVdlGridNames();

/// What `convert --drop` may leave out: the optional grids and the display
/// grid `density` (the irradiance luminance over the brightest voxel's, in
/// [0, 1], written for viewers' default volume import; the readers ignore it).
const std::vector<std::string>& droppableVdlGridNames();

/// How writeVdlGrid stores the grids.
struct VdlWriteOptions {
  /// Store irradiance, normal, VDL, angular_error and radius grids as 16-bit
  /// half floats (OpenVDB's setSaveFloatAsHalf): relative precision 2^-11,
  /// largest value 65504, values under 6.1e-5 lose relative precision.
  /// vdl_count, photon_count and area stay 32-bit: counts above 2048 and the
  /// small areas the coarsener weights by would not survive half precision.
  bool halfFloat = false;
  /// Grids (droppableVdlGridNames) to leave out. @throws InputError
  /// from writeVdlGrid for a required or unknown name.
  std::vector<std::string> drop;
};

/// Writes every grid of the contract (irradiance, normal, photon_count,
/// angular_error, vdl_count, vdl<i>_irradiance, vdl<i>_direction) on one
/// transform, through a temporary name renamed at the end (core/file.h), so an
/// interrupted write never leaves a broken file. With `into`, the file joins
/// that set of outputs instead (core/file_set.h: renamed with the others by
/// its commit, so a side file that fails later leaves the old file in
/// place). @throws IoError; InputError when the grid fails the readers'
/// checks (nothing written).
void writeVdlGrid(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                  const VdlWriteOptions& options = {}, AtomicFileSet* into = nullptr);

struct LoadedVdl {
  VdlGrid grid;
  BakeMetadata meta;
  /// Optional grids the file did not hold (their arrays are filled with 0).
  std::vector<std::string> absentGrids;
  /// Things a user converting or inspecting the file should know, e.g. that it
  /// carries no format_version and was read as version 1.
  std::vector<std::string> notes;
  bool halfFloat = false;  ///< the irradiance grid was stored as half floats
};

/// One check of a light grid's meaning, as `inspect` reports it.
struct VdbCheck {
  std::string name;  ///< e.g. "unit_directions"
  bool passed = true;
  std::string detail;  ///< what was measured / the first offending voxel
};

/// Tolerance of the sum checks ("vdl_sum": Σ VDL irradiance = irradiance;
/// "sh_sum": E(normal) = irradiance), relative to the voxel's largest
/// irradiance channel: full floats, and half floats (up to 9 values each
/// rounded to 11 bits, ~2.4e-4 each).
constexpr double kVdlSumTolerance = 1e-4;
constexpr double kVdlSumToleranceHalf = 3e-3;
/// |length − 1| allowed for the directions of used VDL slots.
constexpr double kUnitDirectionTolerance = 1e-3;
/// Largest irradiance (any channel, any VDL or SH term) a file may hold,
/// W/m^2: far above any light (the sun gives 1.4e3), far enough below
/// float's 3.4e38 that the shader's sums and the cosine correction (x4)
/// stay finite.
constexpr double kMaxStoredIrradiance = 1e30;

/// The meaning of a light grid's values, one validation for every reader
/// (readVdlGrid refuses a grid that fails any; `inspect` reports them all):
/// vdl_count (integers within max_vdls), irradiance_non_negative (the
/// voxels' and VDLs' irradiance; SH terms may be negative),
/// irradiance_range (kMaxStoredIrradiance), unit_directions (used VDL
/// slots), vdl_sum or sh_sum, and layers (the same for surface layers, when
/// there are any). `halfFloat`: the grids were stored as halves (the sum
/// tolerance follows the storage precision).
std::vector<VdbCheck> checkLightGridValues(const VdlGrid& grid, bool halfFloat);

/// Reads a file written by writeVdlGrid. @throws InputError naming the file and
/// the missing grid / mismatched transform / unreadable content, or the first
/// check of checkLightGridValues it fails (the check `inspect` names).
/// Files with a format_version above kVdlFormatVersion are refused.
/// `origin`: the coordinates the grid is wanted in (Scene::origin of the
/// scene it lights; by default the baked scene's, file metadata
/// scene_origin): the frame comes back relative to it (frame.offset =
/// origin), computed in double from the file's world transform.
LoadedVdl readVdlGrid(const std::string& path,
                      const std::optional<Vec3d>& origin = std::nullopt);

/// What a photon file records besides its photons.
struct PhotonMapInfo {
  /// The content hash of the scene the photons were traced in
  /// (BakeMetadata::sourceSceneHash), file metadata "source_scene_hash", so
  /// that a reader can tell a photon map of another scene; "" = none.
  std::string sourceSceneHash;
  /// The bake's region (`bake --bounds`, BakeMetadata::region), outside
  /// which no photon was stored; empty = the whole scene (or not recorded).
  /// In the coordinates of the photons' positions: file metadata
  /// "region_min" and "region_max" in world coordinates.
  Bounds3 region;
  /// Sky::fingerprint of the sky the photons were traced under
  /// (BakeMetadata::skyHash), file metadata "sky_hash", so that a grid
  /// re-gathered from them records the sky its light is of; "" = not recorded.
  std::string skyHash;
  /// 1: the photons hold the light's first hits too (bake --include-direct,
  /// BakeMetadata::includeDirect), file metadata "include_direct"; 0: only
  /// what bounced; -1: not recorded.
  int includeDirect = -1;
};

/// What a photon file of the bake of `meta` records.
inline PhotonMapInfo photonMapInfo(const BakeMetadata& meta) {
  return {meta.sourceSceneHash, meta.region, meta.skyHash, meta.includeDirect};
}

/// Writes photons as a PointDataGrid named "photons" with attributes P,
/// Cd (RGB power, W), direction (wi), normal, bounce. Temp name + rename.
/// `offset`: Scene::origin of the photons' scene; the file's positions are
/// world positions (offset + position, in double), as the region of `info`.
void writePhotonPoints(const std::string& path, const std::vector<Photon>& photons, float voxelSize,
                       const Vec3d& offset = Vec3d(), AtomicFileSet* into = nullptr,
                       const PhotonMapInfo& info = {});

/// Reads a photon file written by writePhotonPoints. Photons come back in the
/// file's (leaf) order, which is deterministic but not the order written.
/// @throws InputError naming the file when it cannot be read, holds no
/// "photons" point grid or lacks one of the attributes.
/// Positions come back relative to `origin` (computed in double), as the
/// region `info` receives (with the scene hash: "" when the file has none).
std::vector<Photon> readPhotonPoints(const std::string& path, const Vec3d& origin = Vec3d(),
                                     PhotonMapInfo* info = nullptr);

}  // namespace lo
