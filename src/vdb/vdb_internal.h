#pragma once
/// @file vdb/vdb_internal.h
/// @brief Private to src/vdb and its tests: hooks that write deliberately
/// broken files and inspect point files, so that tests need no OpenVDB headers.

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "vdb/vdb_io.h"

namespace lo::vdb_internal {

/// Ways to damage a VDL file for reader tests.
struct Damage {
  std::string omitGrid;          ///< leave this grid out of the file ("" = none)
  std::string shiftGrid;         ///< give this grid a transform shifted by one voxel ("" = none)
  std::string emptyGrid;         ///< write this grid with no active voxel ("" = none)
  bool rotateTransform = false;  ///< every grid gets the same transform with a rotation
  VdlWriteOptions options;       ///< half floats / dropped grids, as writeVdlGrid
  /// Write this int32 as the file's format_version instead of kVdlFormatVersion
  /// (nullopt = leave the key out, as files written before it existed).
  std::optional<int> formatVersion = kVdlFormatVersion;
  /// Every grid on a transform of this scale instead of the frame's voxel
  /// size (0 = the frame's; negative mirrors the grid).
  double scale = 0;
  /// Write this as the file's depth metadata (0 = the grid's depth).
  int metadataDepth = 0;
  /// Every float metadata written as a double and every vec3s as a vec3d, as
  /// pyopenvdb writes a file back.
  bool doubleMetadata = false;
  /// Every int32 metadata written as an int64, as pyopenvdb writes Python ints.
  bool wideIntegers = false;
  /// String file metadata (key, value) written over what the writer wrote, as
  /// another tool may.
  std::vector<std::pair<std::string, std::string>> stringMetadata;
  /// int32 and float file metadata (key, value) written over what the writer
  /// wrote (or left out), as another tool may.
  std::vector<std::pair<std::string, int32_t>> intMetadata;
  std::vector<std::pair<std::string, float>> floatMetadata;
};

/// writeVdlGrid with damage applied (same metadata, same temp + rename).
void writeVdlGridDamaged(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                         const Damage& damage);

/// readVdlGrid without checkLightGridValues: the grid as the file holds it,
/// for `inspect` to report every check. @throws InputError as readVdlGrid
/// for what makes a file unreadable (contract, transforms, counts, NaN).
/// `origin`: as readVdlGrid's.
LoadedVdl readVdlStructure(const std::string& path,
                           const std::optional<Vec3d>& origin = std::nullopt);

/// What a photon point file holds, read back through OpenVDB.
struct PointFileInfo {
  std::vector<std::string> gridNames;
  uint64_t pointCount = 0;
  std::vector<std::string> attributes;  ///< in descriptor order ("P" first)
  Vec3 totalCd{0, 0, 0};                ///< sum of "Cd" over all points (double accumulation)
  int64_t totalBounce = 0;              ///< sum of "bounce"
  Bounds3 positionBounds;               ///< world-space bounds of "P"
};

/// @throws InputError if the file cannot be read or holds no "photons" grid.
PointFileInfo inspectPointFile(const std::string& path);

}  // namespace lo::vdb_internal
