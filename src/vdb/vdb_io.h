#pragma once
/// @file vdb/vdb_io.h
/// @brief .vdb files: the VDL grid contract users open in Houdini and Blender,
/// and the photon map as an OpenVDB PointDataGrid. OpenVDB is visible only in
/// src/grid and src/vdb. See docs/vdb-contract.md.

#include <cstdint>
#include <string>
#include <vector>

#include "lightgrid/photon.h"
#include "lightgrid/vdl_grid.h"

namespace lo {

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
