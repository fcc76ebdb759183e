#pragma once
/// @file bake/convert.h
/// @brief A baked light grid to another depth or VDL count (docs/convert.md):
/// picks the method (merge children, interpolate parents, re-gather from the
/// photon map, re-cluster) from what is asked and what is given, and runs it.
/// Reading and writing the files is the caller's (src/vdb).

#include <string>
#include <vector>

#include "bake/bake.h"
#include "core/progress.h"
#include "core/resources.h"
#include "lightgrid/vdl_grid.h"
#include "scene/scene.h"

namespace lo {

struct ConvertParams {
  int depth = 0;  ///< output depth; 0 = the input's
  /// VDLs per voxel; empty = the input's (its metadata says "auto" or a count).
  std::string vdls;
  uint64_t seed = 1;  ///< K-means seed
  /// The baked scene: needed for a finer depth and for re-gathering (the
  /// voxels that hold geometry at the new depth). May be null.
  const Scene* scene = nullptr;
  /// Photons of the bake (`bake --photon-map`): re-gather at the new depth.
  /// Needs `scene`. May be null.
  const std::vector<Photon>* photons = nullptr;
  /// The region the photons were stored in (their bake's --bounds,
  /// PhotonMapInfo), in the scene's coordinates; empty = everywhere. A grid
  /// reaching beyond it is refused (its voxels there would gather nothing).
  Bounds3 photonRegion;
  /// The sky the photons were traced under (PhotonMapInfo::skyHash; "" = not
  /// recorded). A grid re-gathered from them holds their sky's light, so its
  /// metadata records this sky, not the input's (whose light it replaces).
  std::string photonSkyHash;
  /// Whether the photons hold the direct light (PhotonMapInfo::includeDirect;
  /// -1 = not recorded): a grid re-gathered from them records it, so that a
  /// renderer neither adds the direct light again nor leaves it out.
  int photonIncludeDirect = -1;
};

struct ConvertResult {
  VdlGrid grid;
  BakeMetadata metadata;  ///< the input's, with depth, vdls, knn, radius, photons updated
  std::string method;     ///< e.g. "area-weighted merge of the children"
  std::string vdls;       ///< what the output's metadata says: "auto" or a count
  size_t withoutParent = 0;  ///< interpolation: fine voxels none of whose parents is active
  std::vector<StageReport> stages;
};

/// The warning of a fixed photon budget spread thin (sparsePhotonsWarning)
/// for re-gathering `params.photons` at `params.depth` over `input`'s
/// voxels; empty without photons or a scene, or where they suffice.
std::string sparseRegatherWarning(const VdlGrid& input, const BakeMetadata& meta,
                                  const ConvertParams& params);

/// @brief Converts `input` (with its file metadata `meta`) as `params` asks.
/// `convertedFrom` is left to the caller, which knows the file name.
/// @throws InputError naming the flag when the request needs what was not
/// given (a finer depth without a scene, photons without a scene), the
/// scene does not match the grid's frame, or the photons' region does not
/// hold the grid's.
ConvertResult convertLightGrid(const VdlGrid& input, const BakeMetadata& meta,
                               const ConvertParams& params, ProgressSink* progress = nullptr);

/// Sum of irradiance x area over the voxels (W, channel mean): what a
/// conversion should keep.
double lightGridEnergy(const LightGridVoxels& grid);

}  // namespace lo
