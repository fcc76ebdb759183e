#pragma once
/// @file vdb/vdb_contract.h
/// @brief Private to src/vdb: the names of the light-grid file contract
/// (docs/vdb-contract.md), taken from the light grid's field table
/// (lightgrid/light_grid_schema.h), and the deterministic file identity.
/// No OpenVDB types: the writer, the reader, the checks and `inspect` share it.

#include <string>
#include <type_traits>
#include <vector>

#include "lightgrid/light_grid_schema.h"

namespace lo::vdb_internal {

/// The display grid written beside the contract's (vdb_write.cpp,
/// droppableVdlGridNames): not part of the contract, ignored by the readers.
constexpr const char* kDensityGrid = "density";

/// The free-space light's grids (VdlGrid::volume), on their own coarser
/// transform, and the file metadata giving their depth.
constexpr const char* kVolumeIrradianceGrid = "volume_irradiance";
constexpr const char* kVolumeShPrefix = "volume_sh";
constexpr const char* kVolumeLitLowerGrid = "volume_lit_lower";
constexpr const char* kVolumeLitUpperGrid = "volume_lit_upper";
constexpr const char* kVolumeSegmentsGrid = "volume_segments";
constexpr const char* kMetaFreeSpaceDepth = "free_space_depth";

/// "layer<l>_": the prefix of surface layer l's grids (l = 1, 2).
std::string layerPrefix(int layer);

/// One .vdb grid of a field.
struct FieldGrid {
  std::string name;
  int slot = 0;                             ///< VDL slot or SH term; 0 otherwise
  const VdlComponent* component = nullptr;  ///< the Vdl member of a VDL grid
  const char* units = "";
  FieldVecType vecType = FieldVecType::None;
};

/// The grids `row` is stored as, in file order: the voxels' (layer 0) or
/// surface layer `layer`'s, for a grid with `maxVdls` VDL slots and
/// `shTerms` SH terms.
template <typename T>
std::vector<FieldGrid> fieldGrids(const LightGridField<T>& row, int layer, int maxVdls,
                                  int shTerms) {
  const std::string name =
      layer == 0 ? std::string(row.gridName) : layerPrefix(layer) + row.layerGridName;
  std::vector<FieldGrid> grids;
  if constexpr (std::is_same_v<T, Vdl>) {
    for (int i = 0; i < maxVdls; ++i) {
      for (const VdlComponent& c : kVdlComponents) {
        grids.push_back({name + std::to_string(i) + c.suffix, i, &c, c.units, c.vecType});
      }
    }
  } else if (row.arity == FieldArity::ShTerms) {
    for (int i = 0; i < shTerms; ++i) {
      grids.push_back({name + std::to_string(i), i, nullptr, row.units, row.vecType});
    }
  } else {
    grids.push_back({name, 0, nullptr, row.units, row.vecType});
  }
  return grids;
}

/// The voxels' grid of the row whose voxel array is `member`
/// (e.g. &VdlGrid::irradiance -> "irradiance").
template <typename T, typename C>
const char* gridNameOf(std::vector<T> C::*member) {
  const char* name = nullptr;
  forEachField([&](const auto& row) {
    using Row = std::decay_t<decltype(row)>;
    if constexpr (std::is_same_v<typename Row::Value, T>) {
      if (row.voxels == static_cast<std::vector<T> VdlGrid::*>(member)) name = row.gridName;
    }
  });
  return name;
}

/// Surface layer `layer`'s grid of the row whose voxel array is `member`
/// (e.g. &VdlGrid::normals, 1 -> "layer1_normal").
template <typename T, typename C>
std::string layerGridNameOf(std::vector<T> C::*member, int layer) {
  std::string name;
  forEachField([&](const auto& row) {
    using Row = std::decay_t<decltype(row)>;
    if constexpr (std::is_same_v<typename Row::Value, T>) {
      if (row.voxels == static_cast<std::vector<T> VdlGrid::*>(member) && row.layerGridName) {
        name = layerPrefix(layer) + row.layerGridName;
      }
    }
  });
  return name;
}

/// The grid whose active voxels are the file's voxels.
inline const char* keyGridName() { return gridNameOf(&VdlGrid::vdlCount); }

/// File metadata keys read or written in more than one place (the others
/// are written and read side by side: vdb_file.cpp).
inline constexpr const char* kMetaDepth = "depth";
inline constexpr const char* kMetaMaxVdls = "max_vdls";
inline constexpr const char* kMetaFormatVersion = "format_version";
inline constexpr const char* kMetaRepresentation = "representation";

/// Whether `name` is a grid of the voxels (not a layer's) a file must hold
/// for some max_vdls and representation.
bool isRequiredVoxelGrid(const std::string& name);

/// io::Archive writes a random UUID into the header; it is replaced by one
/// derived from the rest of the file, so identical content gives identical
/// bytes. @throws std::runtime_error when the header is not OpenVDB's.
void makeUuidDeterministic(const std::string& file);

/// @throws InputError naming `path`, `depth` and the range when the depth a
/// file's metadata states is not a light grid's (1 to kMaxGridDepth).
void checkDepthInRange(const std::string& path, int depth);

/// What no reader of the file may draw or convert, refused at reading:
/// non-finite values (NaN, Inf) in any field and a depth outside the
/// octree's range. @throws InputError naming `path`, the grid and the voxel.
void checkReadableValues(const std::string& path, const VdlGrid& g);

}  // namespace lo::vdb_internal
