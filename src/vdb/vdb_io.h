#pragma once
/// @file vdb/vdb_io.h
/// @brief .vdb files: the VDL grid contract users open in Houdini and Blender,
/// and the photon map as an OpenVDB PointDataGrid. OpenVDB is visible only in
/// src/grid and src/vdb. See docs/vdb-contract.md.

#include <cstdint>
#include <string>
#include <vector>

#include "cluster/vdl_grid.h"
#include "photon/photon_map.h"

namespace lo {

/// Version of the VDL file contract, written as the int32 file metadata
/// `format_version`. Readers refuse files with a higher number and read files
/// without the key (written before it existed) as version 1.
constexpr int kVdlFormatVersion = 1;

/// File-level metadata written beside the grids.
struct BakeMetadata {
  std::string generator = "lightoctree";
  std::string version = LO_VERSION;
  std::string sourceScene;
  int depth = 0;
  int64_t photons = 0;       ///< stored photons
  int64_t emittedPaths = 0;
  int knn = 0;
  float radius = 0;          ///< world units
  std::string vdls;          ///< "4" or "auto"
  int64_t seed = 0;
  Bounds3 sceneBounds;
  std::string units = "length: scene units (glTF metres); irradiance: W/m^2 (scene light units)";
  /// Always written as kVdlFormatVersion; on reading, the file's value (1 when absent).
  int formatVersion = kVdlFormatVersion;
  /// Set by `convert`: what the file was converted from, e.g. "cornell.vdb (depth 6)".
  std::string convertedFrom;
};

/// Grids of the contract a file may leave out (`convert --drop`): readVdlGrid
/// fills them with 0. The others (irradiance, normal, vdl_count, vdl<i>_*) are
/// required.
const std::vector<std::string>& optionalVdlGridNames();

/// How writeVdlGrid stores the grids.
struct VdlWriteOptions {
  /// Store irradiance, normal, VDL, angular_error and radius grids as 16-bit
  /// half floats (OpenVDB's setSaveFloatAsHalf): relative precision 2^-11,
  /// largest value 65504, values under 6.1e-5 lose relative precision.
  /// vdl_count, photon_count and area stay 32-bit: counts above 2048 and the
  /// small areas the coarsener weights by would not survive half precision.
  bool halfFloat = false;
  /// Optional grids (optionalVdlGridNames) to leave out. @throws InputError
  /// from writeVdlGrid for a required or unknown name.
  std::vector<std::string> drop;
};

/// Writes every grid of the contract (irradiance, normal, photon_count,
/// angular_error, vdl_count, vdl<i>_irradiance, vdl<i>_direction) on one
/// transform, to `path` + ".tmp" and then renames, so an interrupted write
/// never leaves a broken file. @throws IoError.
void writeVdlGrid(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                  const VdlWriteOptions& options = {});

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

/// Reads a file written by writeVdlGrid. @throws InputError naming the file and
/// the missing grid / mismatched transform / unreadable content.
/// Files with a format_version above kVdlFormatVersion are refused.
LoadedVdl readVdlGrid(const std::string& path);

/// Writes photons as a PointDataGrid named "photons" with attributes P,
/// Cd (RGB power, W), direction (wi), normal, bounce. Temp name + rename.
void writePhotonPoints(const std::string& path, const std::vector<Photon>& photons, float voxelSize);

/// Reads a photon file written by writePhotonPoints. Photons come back in the
/// file's (leaf) order, which is deterministic but not the order written.
/// @throws InputError naming the file when it cannot be read, holds no
/// "photons" point grid or lacks one of the attributes.
std::vector<Photon> readPhotonPoints(const std::string& path);

}  // namespace lo
