#pragma once
/// @file vdb/vdb_file.h
/// @brief Private to src/vdb (OpenVDB types): opening a .vdb file whole, for
/// the reader (vdb_io.cpp) and `inspect` (vdb_inspect.cpp).

#include <openvdb/openvdb.h>

#include <string>

namespace lo::vdb_internal {

struct OpenedFile {
  openvdb::GridPtrVecPtr grids;
  openvdb::MetaMap::Ptr meta;
};

/// Initializes OpenVDB once (thread-safe).
void initOpenVdb();

/// Reads every grid and the file metadata, without delayed loading so that
/// every read error surfaces here. @throws InputError naming the file when it
/// does not exist, is not a regular file or is not a readable OpenVDB file.
OpenedFile openFile(const std::string& path);

}  // namespace lo::vdb_internal
