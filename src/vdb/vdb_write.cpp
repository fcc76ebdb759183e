// Writing a light grid as .vdb grids (docs/vdb-contract.md): one source per
// grid of the field table (lightgrid/light_grid_schema.h), built just before
// it is written.

#include <openvdb/openvdb.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_file.h"
#include "vdb/vdb_internal.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace vdb_internal {
namespace {

using openvdb::FloatGrid;
using openvdb::Vec3SGrid;
using openvdb::math::Transform;

// Voxel (i,j,k) of a GridFrame covers origin + ijk * h .. + h; OpenVDB's
// integer index points are voxel centres, so index ijk must map to
// origin + (ijk + 0.5) * h.
Transform::Ptr frameTransform(const GridFrame& frame) {
  const double h = frame.voxelSize;
  Transform::Ptr xform = Transform::createLinearTransform(h);
  xform->postTranslate(openvdb::Vec3d(frame.offset.x + double(frame.origin.x) + 0.5 * h,
                                      frame.offset.y + double(frame.origin.y) + 0.5 * h,
                                      frame.offset.z + double(frame.origin.z) + 0.5 * h));
  return xform;
}

template <typename GridT>
void describe(GridT& grid, const std::string& name, const std::string& units,
              const Transform::Ptr& xform) {
  grid.setName(name);
  grid.setTransform(xform);
  grid.setGridClass(openvdb::GRID_UNKNOWN);
  grid.setSaveFloatAsHalf(false);
  grid.insertMeta("units", openvdb::StringMetadata(units));
}

template <typename Fn>
FloatGrid::Ptr floatGrid(const std::string& name, const std::string& units,
                         const Transform::Ptr& xform, const std::vector<Coord>& coords, Fn value) {
  FloatGrid::Ptr grid = FloatGrid::create(0.0f);
  describe(*grid, name, units, xform);
  auto acc = grid->getAccessor();
  for (size_t v = 0; v < coords.size(); ++v) acc.setValueOn(toVdb(coords[v]), value(v));
  return grid;
}

template <typename Fn>
Vec3SGrid::Ptr vectorGrid(const std::string& name, const std::string& units,
                          openvdb::VecType vecType, const Transform::Ptr& xform,
                          const std::vector<Coord>& coords, Fn value) {
  Vec3SGrid::Ptr grid = Vec3SGrid::create(openvdb::Vec3s(0.0f));
  describe(*grid, name, units, xform);
  grid->setVectorType(vecType);
  auto acc = grid->getAccessor();
  for (size_t v = 0; v < coords.size(); ++v) acc.setValueOn(toVdb(coords[v]), toVdb(value(v)));
  return grid;
}

openvdb::VecType vecTypeOf(FieldVecType type) {
  switch (type) {
    case FieldVecType::CovariantNormalize: return openvdb::VEC_COVARIANT_NORMALIZE;
    case FieldVecType::ContravariantAbsolute: return openvdb::VEC_CONTRAVARIANT_ABSOLUTE;
    case FieldVecType::Invariant:
    case FieldVecType::None: break;
  }
  return openvdb::VEC_INVARIANT;
}

/// The entries one group of grids covers: the voxels, the voxels with
/// surface layers (layer 0's points) or surface layer l's entries.
struct Level {
  int layer = 0;          ///< grid names: 0 the voxels' grids, l "layer<l>_"
  bool ofLayers = false;  ///< the values: VdlLayers' arrays, else VdlGrid's
  std::vector<size_t> entries;  ///< array index of value k; empty: k itself
  std::vector<Coord> coords;    ///< voxel of value k; empty: the grid's coords
  size_t entry(size_t k) const { return entries.empty() ? k : entries[k]; }
};

/// The grids of `row` at `level`. Each source keeps the level alive; `g`
/// must outlive the sources.
template <typename T>
void addFieldSources(std::vector<GridSource>& out, const VdlGrid& g, const LightGridField<T>& row,
                     const std::shared_ptr<const Level>& level, const Transform::Ptr& xform) {
  const std::vector<T>& values = level->ofLayers ? g.layers.*row.layers : g.*row.voxels;
  const size_t per = level->ofLayers ? valuesPerLayer(g, row) : valuesPerVoxel(g, row);
  const std::vector<Coord>& coords = level->coords.empty() ? g.coords : level->coords;
  for (const FieldGrid& grid : fieldGrids(row, level->layer, g.maxVdls, g.shTerms)) {
    auto make = [&g, &values, &coords, per, grid, level, xform]() -> openvdb::GridBase::Ptr {
      (void)g;  // read by the VDL rows' branch only
      const size_t slot = size_t(grid.slot);
      if constexpr (std::is_same_v<T, Vdl>) {
        // VDL slot i only where the voxel has more than i VDLs (sparse: a
        // voxel with fewer stores no zeros in the higher grids).
        const std::vector<uint8_t>& count = level->ofLayers ? g.layers.vdlCount : g.vdlCount;
        std::vector<size_t> used;
        std::vector<Coord> usedCoords;
        for (size_t k = 0; k < coords.size(); ++k) {
          if (count[level->entry(k)] > grid.slot) {
            used.push_back(level->entry(k));
            usedCoords.push_back(coords[k]);
          }
        }
        const Vec3 Vdl::*member = grid.component->member;
        return vectorGrid(grid.name, grid.units, vecTypeOf(grid.vecType), xform, usedCoords,
                          [&](size_t k) { return values[used[k] * per + slot].*member; });
      } else if constexpr (std::is_same_v<T, Vec3>) {
        return vectorGrid(grid.name, grid.units, vecTypeOf(grid.vecType), xform, coords,
                          [&](size_t k) { return values[level->entry(k) * per + slot]; });
      } else {
        return floatGrid(grid.name, grid.units, xform, coords,
                         [&](size_t k) { return float(values[level->entry(k) * per + slot]); });
      }
    };
    out.push_back({grid.name, make, row.halfFloat});
  }
}

/// The grids of the VDL file contract for `g` (which must outlive them), in
/// file order: the voxels' grids in table order, then, with surface layers,
/// the OneOrNone rows on the voxels with layers ("layer_point") and each
/// layer's grids in table order.
std::vector<GridSource> vdlGridSources(const VdlGrid& g, const Transform::Ptr& xform) {
  std::vector<GridSource> grids;
  auto voxels = std::make_shared<const Level>();
  forEachField([&](const auto& row) {
    if (row.arity != FieldArity::OneOrNone) addFieldSources(grids, g, row, voxels, xform);
  });
  if (g.layers.size() == 0) return grids;

  std::array<std::shared_ptr<Level>, kMaxLayers> levels;
  for (int l = 0; l < kMaxLayers; ++l) {
    levels[size_t(l)] = std::make_shared<Level>();
    levels[size_t(l)]->layer = l;
    levels[size_t(l)]->ofLayers = l > 0;
  }
  const VdlLayers& L = g.layers;
  for (size_t e = 0; e < L.size(); ++e) {
    const int layer = e > 0 && L.voxel[e - 1] == L.voxel[e] ? 2 : 1;
    levels[size_t(layer)]->entries.push_back(e);
    levels[size_t(layer)]->coords.push_back(g.coords[L.voxel[e]]);
    if (layer == 1) {
      levels[0]->entries.push_back(L.voxel[e]);
      levels[0]->coords.push_back(g.coords[L.voxel[e]]);
    }
  }
  forEachField([&](const auto& row) {
    if (row.arity == FieldArity::OneOrNone) addFieldSources(grids, g, row, levels[0], xform);
  });
  for (int l = 1; l < kMaxLayers; ++l) {
    if (levels[size_t(l)]->entries.empty()) continue;
    forEachField([&](const auto& row) {
      if (row.layers) addFieldSources(grids, g, row, levels[size_t(l)], xform);
    });
  }
  return grids;
}

/// The display grid viewers read by default (Blender's and Houdini's volume
/// import show a `density` fog): each voxel's irradiance luminance over the
/// brightest voxel's, in [0, 1], on every voxel. Not part of the contract:
/// the readers ignore it.
FloatGrid::Ptr densityGrid(const VdlGrid& g, const Transform::Ptr& xform) {
  float brightest = 0;
  for (const Vec3& e : g.irradiance) brightest = std::max(brightest, luminance(e));
  FloatGrid::Ptr grid = floatGrid(kDensityGrid, "irradiance luminance / the brightest voxel's", xform,
                                  g.coords, [&](size_t v) {
                                    return brightest > 0 ? std::clamp(luminance(g.irradiance[v]) / brightest, 0.0f, 1.0f) : 0.0f;
                                  });
  grid->setGridClass(openvdb::GRID_FOG_VOLUME);
  return grid;
}

/// The free-space light's grids (docs/vdb-contract.md), on its own
/// coarser transform: volume_irradiance, volume_sh<i>, volume_lit_lower,
/// volume_lit_upper, volume_segments.
void addVolumeSources(std::vector<GridSource>& out, const VolumeLight& v, bool halfAsked) {
  if (v.empty()) return;
  // Halves overflow at 65504: a light brighter than that stays in floats.
  float largest = 0;
  for (const Vec3& e : v.irradiance) largest = std::max(largest, maxComponent(max(e, -e)));
  for (const Vec3& e : v.sh) largest = std::max(largest, maxComponent(max(e, -e)));
  const bool half = halfAsked && largest <= 65504.0f;
  const Transform::Ptr xform = frameTransform(v.frame);
  auto vec = [&](const std::string& name, const std::string& units, bool mayHalve,
                 std::function<Vec3(size_t)> value) {
    out.push_back({name, [&v, xform, name, units, value, half, mayHalve]() -> openvdb::GridBase::Ptr {
                     auto g = vectorGrid(name, units, openvdb::VEC_INVARIANT, xform, v.coords, value);
                     if (half && mayHalve) g->setSaveFloatAsHalf(true);
                     return g;
                   }});
  };
  vec(kVolumeIrradianceGrid, "W/m^2 (mean over a surface's orientations: fluence / 4)", true,
      [&v](size_t k) { return v.irradiance[k]; });
  for (int i = 0; i < v.shTerms; ++i) {
    vec(std::string(kVolumeShPrefix) + std::to_string(i),
        "W/m^2 (SH term; E(n) = sum_i volume_sh<i> Y_i(n))", true,
        [&v, i](size_t k) { return v.sh[k * size_t(v.shTerms) + size_t(i)]; });
  }
  vec(kVolumeLitLowerGrid, "voxel units from the voxel's lower corner", false,
      [&v](size_t k) { return v.litLower[k]; });
  vec(kVolumeLitUpperGrid, "voxel units from the voxel's lower corner", false,
      [&v](size_t k) { return v.litUpper[k]; });
  out.push_back({kVolumeSegmentsGrid, [&v, xform]() -> openvdb::GridBase::Ptr {
                   return floatGrid(kVolumeSegmentsGrid, "light rays", xform, v.coords,
                                    [&v](size_t k) { return v.segments[k]; });
                 }});
}

void writeVdl(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
              const VdlWriteOptions& options, const Damage* damage, AtomicFileSet* into) {
  initOpenVdb();
  for (const std::string& name : options.drop) {
    const auto& droppable = droppableVdlGridNames();
    if (std::find(droppable.begin(), droppable.end(), name) == droppable.end()) {
      std::string list;
      for (const auto& o : droppable) list += (list.empty() ? "" : ", ") + o;
      throw InputError("--drop: grid '" + name + "' " +
                       (isRequiredVoxelGrid(name) ? "is required by the VDL file contract"
                                                  : "is not a grid of the VDL file contract") +
                       "; only optional grids can be dropped: " + list);
    }
  }
  checkLightGridArrays(grid);
  LO_CHECK(grid.maxVdls >= 1 && grid.maxVdls <= kMaxVdls);
  if (meta.depth != 0) LO_CHECK_EQ(meta.depth, grid.frame.depth);
  if (!(grid.frame.voxelSize > 0) || !std::isfinite(grid.frame.voxelSize)) {
    throw InputError(path + ": cannot write a grid with voxel size " +
                     std::to_string(grid.frame.voxelSize));
  }
  Transform::Ptr xform = frameTransform(grid.frame);
  if (damage && damage->scale != 0) {
    const openvdb::Vec3d centre0 = xform->indexToWorld(openvdb::Vec3d(0.0));
    xform = Transform::createLinearTransform(damage->scale);
    xform->postTranslate(centre0);
  }
  if (damage && damage->rotateTransform) xform->postRotate(0.3, openvdb::math::Z_AXIS);
  std::vector<GridSource> sources;
  for (GridSource& source : vdlGridSources(grid, xform)) {
    if (damage && source.name == damage->omitGrid) continue;
    if (std::find(options.drop.begin(), options.drop.end(), source.name) != options.drop.end()) {
      continue;
    }
    const std::string name = source.name;
    const bool half = options.halfFloat && source.halfFloat;
    const bool shift = damage && name == damage->shiftGrid;
    sources.push_back({name, [make = std::move(source.make), half, shift, xform, &grid] {
                         openvdb::GridBase::Ptr g = make();
                         if (half) g->setSaveFloatAsHalf(true);
                         if (shift) {
                           Transform::Ptr shifted = xform->copy();
                           shifted->postTranslate(openvdb::Vec3d(grid.frame.voxelSize, 0, 0));
                           g->setTransform(shifted);
                         }
                         return g;
                       }});
  }
  if (std::find(options.drop.begin(), options.drop.end(), kDensityGrid) == options.drop.end()) {
    sources.push_back({kDensityGrid, [&grid, xform, half = options.halfFloat] {
                         openvdb::GridBase::Ptr g = densityGrid(grid, xform);
                         if (half) g->setSaveFloatAsHalf(true);
                         return g;
                       }});
  }
  addVolumeSources(sources, grid.volume, options.halfFloat);
  if (damage && !damage->emptyGrid.empty()) {
    for (GridSource& source : sources) {
      if (source.name != damage->emptyGrid) continue;
      source.make = [make = std::move(source.make)] {
        openvdb::GridBase::Ptr g = make();
        g->clear();
        return g;
      };
    }
  }
  openvdb::MetaMap fileMeta = fileMetadata(meta, grid);
  if (!grid.volume.empty()) {
    fileMeta.insertMeta(kMetaFreeSpaceDepth, openvdb::Int32Metadata(grid.volume.frame.depth));
  }
  if (damage && damage->formatVersion != kVdlFormatVersion) {
    fileMeta.removeMeta(kMetaFormatVersion);
    if (damage->formatVersion) {
      fileMeta.insertMeta(kMetaFormatVersion, openvdb::Int32Metadata(*damage->formatVersion));
    }
  }
  if (damage && damage->metadataDepth != 0) {
    fileMeta.removeMeta(kMetaDepth);
    fileMeta.insertMeta(kMetaDepth, openvdb::Int32Metadata(damage->metadataDepth));
  }
  if (damage && (damage->doubleMetadata || damage->wideIntegers)) {
    openvdb::MetaMap wide;
    for (auto it = fileMeta.beginMeta(); it != fileMeta.endMeta(); ++it) {
      const bool floats = damage->doubleMetadata, integers = damage->wideIntegers;
      if (auto f = openvdb::DynamicPtrCast<openvdb::FloatMetadata>(it->second); f && floats) {
        wide.insertMeta(it->first, openvdb::DoubleMetadata(double(f->value())));
      } else if (auto i = openvdb::DynamicPtrCast<openvdb::Int32Metadata>(it->second);
                 i && integers) {
        wide.insertMeta(it->first, openvdb::Int64Metadata(int64_t(i->value())));
      } else if (auto v = openvdb::DynamicPtrCast<openvdb::Vec3SMetadata>(it->second);
                 v && floats) {
        const openvdb::Vec3s x = v->value();
        wide.insertMeta(it->first, openvdb::Vec3DMetadata(openvdb::Vec3d(x.x(), x.y(), x.z())));
      } else {
        wide.insertMeta(it->first, *it->second);
      }
    }
    fileMeta = wide;
  }
  if (damage) {
    for (const auto& [key, value] : damage->stringMetadata) {
      fileMeta.removeMeta(key);
      fileMeta.insertMeta(key, openvdb::StringMetadata(value));
    }
    for (const auto& [key, value] : damage->intMetadata) {
      fileMeta.removeMeta(key);
      fileMeta.insertMeta(key, openvdb::Int32Metadata(value));
    }
    for (const auto& [key, value] : damage->floatMetadata) {
      fileMeta.removeMeta(key);
      fileMeta.insertMeta(key, openvdb::FloatMetadata(value));
    }
  }
  writeVdbFile(path, sources, fileMeta, into);
}

}  // namespace

void writeVdlGridDamaged(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                         const Damage& damage) {
  writeVdl(path, grid, meta, damage.options, &damage, nullptr);
}

}  // namespace vdb_internal

void writeVdlGrid(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                  const VdlWriteOptions& options, AtomicFileSet* into) {
  // What every reader will check, checked before anything is written: a file
  // the commands would refuse never replaces a good one (bake, convert).
  try {
    vdb_internal::checkReadableValues(path, grid);
  } catch (const InputError& e) {
    throw InputError(std::string(e.what()) + "; not written, the file there is left as it was");
  }
  for (const VdbCheck& c : checkLightGridValues(grid, options.halfFloat)) {
    if (!c.passed) {
      throw InputError(path + ": not written: the light grid fails check " + c.name + " (" +
                       c.detail + "); the file there is left as it was");
    }
  }
  vdb_internal::writeVdl(path, grid, meta, options, nullptr, into);
}

}  // namespace lo
