#pragma once
/// @file vdb/vdb_file.h
/// @brief Private to src/vdb (OpenVDB types): opening a .vdb file whole, for
/// the reader (vdb_io.cpp) and `inspect` (vdb_inspect.cpp).

#include <openvdb/openvdb.h>

#include <string>

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
/// being read here.
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

/// readVdlGrid without checkLightGridValues: the grid as the file holds it,
/// for `inspect` to report every check. @throws InputError as readVdlGrid
/// for what makes a file unreadable (contract, transforms, counts, NaN).
LoadedVdl readVdlStructure(const std::string& path);

}  // namespace lo::vdb_internal
