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

struct VdbCheck {
  std::string name;  ///< e.g. "unit_directions"
  bool passed = true;
  std::string detail;  ///< what was measured / the first offending voxel
};

struct VdbReport {
  std::string path;
  uint64_t fileBytes = 0;
  std::string kind;  ///< "vdl" (a lightoctree VDL file), "photons", or "other"
  std::vector<std::pair<std::string, std::string>> metadata;  ///< file metadata as text
  std::vector<GridSummary> grids;
  std::vector<VdbCheck> checks;

  bool ok() const {
    for (const VdbCheck& c : checks) {
      if (!c.passed) return false;
    }
    return true;
  }
};

/// Tolerance of the "vdl_sum" check (Σ VDL irradiance = irradiance), relative
/// to the voxel's largest irradiance channel: full floats, and half floats
/// (up to 9 values each rounded to 11 bits, ~2.4e-4 each).
constexpr double kVdlSumTolerance = 1e-4;
constexpr double kVdlSumToleranceHalf = 3e-3;
/// |length − 1| allowed for the directions of used VDL slots.
constexpr double kUnitDirectionTolerance = 1e-3;

/// Reads every grid of `path` and runs the checks. Checks of a VDL file:
/// contract (required grids with their types, max_vdls), format_version,
/// finite (no NaN/Inf), same_transform, same_active_voxels, vdl_count
/// (integers in [0, max_vdls]), irradiance_non_negative, unit_directions (for
/// slots i < vdl_count), vdl_sum. A file that is not a VDL file fails
/// "contract" (a photon file gets only the "photons" check).
/// @throws InputError naming the file when it is missing, truncated or not an
/// OpenVDB file.
VdbReport inspectVdb(const std::string& path);

}  // namespace lo
