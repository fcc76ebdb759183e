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
};

/// Writes every grid of the contract (irradiance, normal, photon_count,
/// angular_error, vdl_count, vdl<i>_irradiance, vdl<i>_direction) on one
/// transform, to `path` + ".tmp" and then renames, so an interrupted write
/// never leaves a broken file. @throws IoError.
void writeVdlGrid(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta);

struct LoadedVdl {
  VdlGrid grid;
  BakeMetadata meta;
};

/// Reads a file written by writeVdlGrid. @throws InputError naming the file and
/// the missing grid / mismatched transform / unreadable content.
LoadedVdl readVdlGrid(const std::string& path);

/// Writes photons as a PointDataGrid named "photons" with attributes P,
/// Cd (RGB power, W), direction (wi), normal, bounce. Temp name + rename.
void writePhotonPoints(const std::string& path, const std::vector<Photon>& photons, float voxelSize);

}  // namespace lo
