#pragma once
/// @file vdb/vdb_file.h
/// @brief Private to src/vdb (OpenVDB types): opening a .vdb file whole (for
/// the reader, the photon points and `inspect`), writing one grid by grid,
/// the file metadata both ways, and the grid look-ups they share.

#include <openvdb/openvdb.h>

#include <functional>
#include <string>
#include <vector>

#include "core/error.h"
#include "vdb/vdb_internal.h"
#include "vdb/vdb_io.h"

namespace lo::vdb_internal {

struct OpenedFile {
  openvdb::GridPtrVecPtr grids;
  openvdb::MetaMap::Ptr meta;
};

/// Initializes OpenVDB once (thread-safe).
void initOpenVdb();

/// Reading untrusted files: a child process reads the file first with at
/// most kReadMemoryBaseBytes + kReadMemoryPerFileByte x its size of memory
/// and kReadSecondsBase + kReadSecondsPerByte x its size of time
/// (core/isolate.h); a file it cannot read within them, or that crashes it
/// (twice: a time-out or crash is tried again once), is refused without
/// being read here. What the child read it hands back through memory,
/// written anew by OpenVDB's writer: the parent never reads the file's own
/// bytes, so a file that corrupts the child's heap without crashing it
/// cannot reach the parent.
constexpr size_t kReadMemoryBaseBytes = size_t(512) << 20;
constexpr double kReadMemoryPerFileByte = 64;
constexpr double kReadSecondsBase = 10;
constexpr double kReadSecondsPerByte = 1e-7;  // 10 s per 100 MB

/// Reads every grid and the file metadata, without delayed loading so that
/// every read error surfaces here; first in a child process under the
/// limits above. @throws InputError naming the file when it does not
/// exist, is not a regular file, is not a readable OpenVDB file or exceeds
/// the limits (error texts cut at 400 characters).
OpenedFile openFile(const std::string& path);

/// One grid of a file, built when it is written (writeVdbFile): a file's
/// grids are never all in memory at once.
struct GridSource {
  std::string name;
  std::function<openvdb::GridBase::Ptr()> make;
  bool halfFloat = false;  ///< may be stored as half floats (VdlWriteOptions)
};

/// Writes the grids `sources` make, in order, with the file metadata `meta`
/// to `path` through a temporary file (core/file.h), then gives the file
/// its deterministic UUID (vdb_contract.h). With `into`, the file joins that
/// set (written under its temporary name, renamed by the set's commit).
/// @throws IoError.
void writeVdbFile(const std::string& path, const std::vector<GridSource>& sources,
                  const openvdb::MetaMap& meta, AtomicFileSet* into = nullptr);

/// The file metadata of a light grid (docs/vdb-contract.md).
openvdb::MetaMap fileMetadata(const BakeMetadata& meta, const VdlGrid& grid);
/// BakeMetadata from a file's metadata. @throws InputError naming `path`
/// and the key when a required key is missing or a key has another type.
BakeMetadata readMetadata(const std::string& path, const openvdb::MetaMap& m);
/// The int32 file metadata `key`; `fallback` when absent and not required.
/// @throws InputError as readMetadata.
int32_t metaInt(const std::string& path, const openvdb::MetaMap& m, const std::string& key,
                bool required, int32_t fallback);
/// A switch of the bake in the file metadata (include_direct, ...): 0 or 1,
/// -1 when absent. @throws InputError for any other integer or another type.
int32_t metaOnOff(const std::string& path, const openvdb::MetaMap& m, const std::string& key);

/// The file's format_version by the one rule the reader and `inspect` share
/// (they disagreed: the reader took a stored 0 for a missing key, inspect
/// failed it): a missing key is a file written before the key existed, read
/// as version 1; a stored value is an integer in [1, kVdlFormatVersion].
struct FormatVersion {
  int version = 1;
  bool absent = false;  ///< no key: read as version 1
  std::string problem;  ///< why the file is refused ("" = readable), without the path
};
FormatVersion formatVersionOf(const openvdb::MetaMap& m);

inline openvdb::Vec3s toVdb(const Vec3& v) { return {v.x, v.y, v.z}; }
inline openvdb::Coord toVdb(const Coord& c) { return {c.x, c.y, c.z}; }
inline Vec3 fromVdb(const openvdb::Vec3s& v) { return {v.x(), v.y(), v.z()}; }
inline Coord fromVdb(const openvdb::Coord& c) { return {c.x(), c.y(), c.z()}; }

/// One check of the file's grids among themselves, as `inspect` reports it.
struct GridsCheck {
  bool passed = true;
  std::string detail;  ///< what holds, or the first grid that breaks it (without the path)
};

/// Grids whose names start "volume_": the free-space light, on a coarser
/// transform and voxels of their own.
bool isFreeSpaceGrid(const std::string& name);

/// The one rule `inspect` ("same_transform", "same_active_voxels") and every
/// reader (readVdlStructure) apply to a file's grids, so that a file passes
/// inspect exactly when the readers take it: every grid on one transform
/// (the free-space grids on theirs); the grids of one set of voxels (the
/// voxels', surface layer l's, one VDL slot's, the free-space voxels') with
/// the same number of active voxels over the same bounding box. A file with
/// a surface layer's grid zeroed was read as a layer of zeros.
GridsCheck sameTransform(const OpenedFile& f);
GridsCheck sameActiveVoxels(const OpenedFile& f);

/// The grid of the file named `name`, or null.
openvdb::GridBase::Ptr findGrid(const OpenedFile& f, const std::string& name);

/// The grid named `name`, of type GridT. @throws InputError naming `path`
/// and the grid when it is missing or of another type.
template <typename GridT>
typename GridT::Ptr requireGrid(const std::string& path, const OpenedFile& f,
                                const std::string& name) {
  openvdb::GridBase::Ptr base = findGrid(f, name);
  if (!base) {
    throw InputError(path + ": missing grid '" + name + "' \u2014 not a lightoctree VDL file?");
  }
  typename GridT::Ptr typed = openvdb::gridPtrCast<GridT>(base);
  if (!typed) {
    throw InputError(path + ": grid '" + name + "' has type " + base->valueType() + ", expected " +
                     openvdb::typeNameAsString<typename GridT::ValueType>());
  }
  return typed;
}

}  // namespace lo::vdb_internal
