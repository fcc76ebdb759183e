#pragma once
/// @file vdb/vdb_inspect.h
/// @brief What a .vdb file holds (grids, types, active voxels, value ranges,
/// memory, metadata) and whether a lightoctree VDL file keeps its contract
/// (docs/vdb-contract.md, docs/convert.md). Reads any OpenVDB file; the
/// contract checks run on files that look like VDL files.

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "lightgrid/grid_noise.h"
#include "vdb/vdb_io.h"

namespace lo {

struct GridSummary {
  std::string name;
  std::string type;       ///< OpenVDB grid type, e.g. "Tree_vec3s_5_4_3"
  std::string valueType;  ///< "float", "vec3s", "ptdataidx32", ...
  uint64_t activeVoxels = 0;
  uint64_t memoryBytes = 0;  ///< in-memory size (Grid::memUsage) once loaded
  bool halfFloat = false;    ///< stored as 16-bit floats
  /// Per component (1 for float, 3 for vec3s, 0 for other types) minimum and
  /// maximum over the active voxels' finite values; empty when none.
  std::vector<double> min, max;
  uint64_t nonFinite = 0;         ///< active values with a NaN or Inf component
  std::vector<double> voxelSize;  ///< x, y, z, world units
  std::vector<double> origin;     ///< world position of index (0,0,0)'s centre
  std::vector<std::pair<std::string, std::string>> metadata;  ///< as text
};


struct VdbReport {
  std::string path;
  uint64_t fileBytes = 0;
  std::string kind;  ///< "vdl" (a lightoctree VDL file), "photons", or "other"
  std::vector<std::pair<std::string, std::string>> metadata;  ///< file metadata as text
  std::vector<GridSummary> grids;
  std::vector<VdbCheck> checks;
  /// The bake's noise figure (summarizeNoise) of a readable VDL file with
  /// a `noise` grid; not recorded otherwise.
  NoiseSummary noise;

  bool ok() const {
    for (const VdbCheck& c : checks) {
      if (!c.passed) return false;
    }
    return true;
  }
};

/// Reads every grid of `path` and runs the checks. Checks of a VDL file: the
/// file's structure (contract: required grids with their types, max_vdls;
/// format_version; finite: no NaN/Inf in any grid; same_transform;
/// same_active_voxels; depth, transform, voxel_bounds), then "readable" (the
/// reader every command uses accepts it) and the values' meaning, the very
/// checks that reader runs (checkLightGridValues in vdb_io.h): so a file
/// passes inspect exactly when render and convert take it. A file that is
/// not a VDL file fails "contract" (a photon file gets only the "photons"
/// check).
/// @throws InputError naming the file when it is missing, truncated or not an
/// OpenVDB file.
VdbReport inspectVdb(const std::string& path);

}  // namespace lo
