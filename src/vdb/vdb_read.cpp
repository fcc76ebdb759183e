// Reading a light grid from .vdb grids (docs/vdb-contract.md): the grids of
// the field table (lightgrid/light_grid_schema.h), checked for structure
// (types, transforms, active voxels) before any value is read.

#include <openvdb/openvdb.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.h"
#include "core/printable.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_file.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace vdb_internal {
namespace {

using openvdb::FloatGrid;
using openvdb::Vec3SGrid;
using openvdb::math::Transform;

// The canonical voxel order readers get: by 8^3 block (floor(c / 8), compared
// x, then y, then z), then by offset inside the block (c & 7, x, y, z) --
// OpenVDB's leaf-local order. Arithmetic shift: floor division for negatives.
bool canonicalLess(const Coord& a, const Coord& b) {
  Coord ba{a.x >> 3, a.y >> 3, a.z >> 3}, bb{b.x >> 3, b.y >> 3, b.z >> 3};
  if (ba != bb) return ba < bb;
  Coord oa{a.x & 7, a.y & 7, a.z & 7}, ob{b.x & 7, b.y & 7, b.z & 7};
  return oa < ob;
}

GridFrame readFrame(const std::string& path, const Transform& xform, int depth,
                    const Vec3d& offset) {
  const openvdb::math::MapBase::ConstPtr map = xform.baseMap();
  const bool axisAligned = map->isType<openvdb::math::UniformScaleTranslateMap>() ||
                           map->isType<openvdb::math::UniformScaleMap>();
  if (!xform.isLinear() || !axisAligned) {
    throw InputError(path + ": transform is " + xform.mapType() +
                     ", expected a uniform scale and translation");
  }
  // The size a voxel has, from the map's own scale, not the voxel size a file
  // states beside it: a negative scale (a mirror), a NaN or a size the map
  // does not have would place every voxel wrongly. Read from the map, not as
  // the difference of two mapped points: far from the origin (9.9e11, within
  // kMaxCoordinate) that difference keeps only the translation's last bits
  // (0.0356445 for 0.035649) and a grid the bake wrote was refused.
  openvdb::Vec3d scale, centre0;
  if (const auto st = xform.constMap<openvdb::math::UniformScaleTranslateMap>()) {
    scale = st->getScale();
    centre0 = st->getTranslation();
  } else {
    scale = xform.constMap<openvdb::math::UniformScaleMap>()->getScale();
    centre0 = openvdb::Vec3d(0.0);
  }
  const double h = scale.x();
  const openvdb::Vec3d stated = xform.voxelSize();
  if (!(h > 0) || !std::isfinite(h) || !(float(h) >= std::numeric_limits<float>::min())) {
    char text[64];
    std::snprintf(text, sizeof text, "%.6g", h);
    throw InputError(path + ": transform has voxel size " + text +
                     ", expected a finite size > 0 (a uniform scale and translation)");
  }
  if (!(std::fabs(stated[0] - h) <= 1e-6 * h) || !std::isfinite(centre0.x()) ||
      !std::isfinite(centre0.y()) || !std::isfinite(centre0.z())) {
    char text[320];
    std::snprintf(text, sizeof text,
                  "transform's scale %.9g differs from the voxel size %.9g the file states, or its "
                  "translation (%.6g, %.6g, %.6g) is not finite",
                  h, stated[0], centre0.x(), centre0.y(), centre0.z());
    throw InputError(path + ": " + text + ": the file is inconsistent");
  }
  GridFrame frame;
  frame.voxelSize = float(h);
  frame.origin = Vec3(float(centre0.x() - 0.5 * h - offset.x), float(centre0.y() - 0.5 * h - offset.y),
                      float(centre0.z() - 0.5 * h - offset.z));
  frame.offset = offset;
  frame.depth = depth;
  return frame;
}

/// The OpenVDB grid type a row of value type T is stored as.
template <typename T>
using GridOf =
    std::conditional_t<std::is_same_v<T, Vec3> || std::is_same_v<T, Vdl>, Vec3SGrid, FloatGrid>;

/// The depth the metadata states against the voxels: 2^depth voxels of the
/// file's size span the cube the bake made around the scene's bounds (or its
/// region), which the metadata records. A depth that is not the voxels' (a
/// file edited to claim depth 6 over depth-4 voxels) makes that cube 2^k
/// times too large or small, and `convert` would resample into a wrongly
/// sized grid. Files without recorded bounds are taken as they are.
void checkDepthAgainstBounds(const std::string& path, const BakeMetadata& meta,
                             const GridFrame& frame) {
  const Bounds3& bounds = meta.region.empty() ? meta.sceneBounds : meta.region;
  if (bounds.empty() || !isFinite(bounds.lower) || !isFinite(bounds.upper)) return;
  const double extent = double(maxComponent(bounds.upper - bounds.lower));
  if (!(extent > 0)) return;
  const double cube = double(frame.voxelSize) * double(1 << frame.depth);
  const double ratio = cube / extent;
  // Padding is 1% each side; a depth off by one level is a factor of 2.
  if (ratio > 0.7 && ratio < 1.42) return;
  char text[200];
  std::snprintf(text, sizeof text,
                "file metadata depth = %d over voxels of %.6g spans a cube of %.6g, where the "
                "recorded %s is %.6g across: the voxels are of depth %.3g",
                frame.depth, double(frame.voxelSize), cube,
                meta.region.empty() ? "scene_bounds" : "region", extent,
                std::log2(extent * 1.02 / double(frame.voxelSize)));
  throw InputError(path + ": " + text + "; the file is inconsistent");
}

void checkTransform(const std::string& path, const openvdb::GridBase& grid, const Transform& xform) {
  if (!(grid.transform() == xform)) {
    throw InputError(path + ": mismatched transforms: grid '" + grid.getName() +
                     "' differs from '" + keyGridName() + "'");
  }
}

/// Reads the grids of `row` (the voxels' for layer 0, else surface layer
/// `layer`'s) at `coords` into values[entries[k] * per + slot] (entries
/// empty: k). Absent optional grids of the voxels leave zeros. With `xform`,
/// each grid must be on it (the voxels' grids were checked before).
template <typename T>
void readField(const std::string& path, const OpenedFile& f, const LightGridField<T>& row,
               int layer, int maxVdls, int shTerms, const Transform* xform,
               const std::vector<Coord>& coords, const std::vector<size_t>& entries,
               std::vector<T>& values) {
  const size_t per = row.arity == FieldArity::VdlSlots  ? size_t(maxVdls)
                     : row.arity == FieldArity::ShTerms ? size_t(shTerms)
                                                        : 1;
  for (const FieldGrid& fg : fieldGrids(row, layer, maxVdls, shTerms)) {
    if (layer == 0 && row.optional && !findGrid(f, fg.name)) continue;
    auto grid = requireGrid<GridOf<T>>(path, f, fg.name);
    if (xform) checkTransform(path, *grid, *xform);
    auto acc = grid->getConstAccessor();
    for (size_t k = 0; k < coords.size(); ++k) {
      const size_t at = (entries.empty() ? k : entries[k]) * per + size_t(fg.slot);
      const auto value = acc.getValue(toVdb(coords[k]));
      if constexpr (std::is_same_v<T, Vdl>) {
        values[at].*(fg.component->member) = fromVdb(value);
      } else if constexpr (std::is_same_v<T, Vec3>) {
        values[at] = fromVdb(value);
      } else if constexpr (std::is_same_v<T, uint8_t>) {
        // Counts of VDL slots.
        if (!(value >= 0 && value <= float(maxVdls)) || value != std::floor(value)) {
          throw InputError(path + ": " + fg.name + " at " + coords[k].ToString() + " is " +
                           std::to_string(value) + ", expected an integer in [0, " +
                           std::to_string(maxVdls) + "]");
        }
        values[at] = uint8_t(value);
      } else {
        values[at] = value;
      }
    }
  }
}

/// The surface layers of a version-2 file (none when it has no
/// "layer1_normal" grid): every grid of a layer present, on the file's
/// transform, each layer's voxels among the file's voxels, layer 2's among
/// layer 1's.
void readLayers(const std::string& path, const OpenedFile& f, const Transform& xform,
                LoadedVdl& out) {
  VdlGrid& g = out.grid;
  const size_t n = g.size();
  const std::string firstNormal = layerGridNameOf(&VdlGrid::normals, 1);
  if (!findGrid(f, firstNormal)) {
    for (const auto& grid : *f.grids) {
      if (grid && grid->getName().rfind("layer", 0) == 0) {
        throw InputError(path + ": grid '" + grid->getName() + "' without '" + firstNormal +
                         "': incomplete surface layers");
      }
    }
    return;
  }
  auto voxelOf = [&](const openvdb::Coord& c, const std::string& grid) -> uint32_t {
    const Coord k = fromVdb(c);
    auto it = std::lower_bound(g.coords.begin(), g.coords.end(), k, canonicalLess);
    if (it == g.coords.end() || *it != k) {
      throw InputError(path + ": grid '" + grid + "' is active at " + k.ToString() +
                       ", which is not a voxel of the file");
    }
    return uint32_t(it - g.coords.begin());
  };
  // Layer 0's points (the one OneOrNone row), on the voxels with layers;
  // the voxel's centre elsewhere.
  const std::string pointName = gridNameOf(&VdlGrid::points);
  g.points.assign(n, Vec3{});
  for (size_t v = 0; v < n; ++v) {
    g.points[v] = g.frame.origin + (Vec3{float(g.coords[v].x), float(g.coords[v].y),
                                         float(g.coords[v].z)} + Vec3(0.5f)) * g.frame.voxelSize;
  }
  auto points = requireGrid<Vec3SGrid>(path, f, pointName);
  checkTransform(path, *points, xform);
  for (auto it = points->cbeginValueOn(); it; ++it) {
    g.points[voxelOf(it.getCoord(), pointName)] = fromVdb(*it);
  }
  struct Entry {
    uint32_t voxel;
    int layer;
  };
  std::vector<Entry> entries;
  std::vector<char> hasLayer1(n, 0);
  for (int layer = 1; layer < kMaxLayers; ++layer) {
    const std::string countName = layerGridNameOf(&VdlGrid::vdlCount, layer);
    if (!findGrid(f, countName)) {
      if (layer == 1) requireGrid<FloatGrid>(path, f, countName);  // names it as missing
      break;
    }
    auto count = requireGrid<FloatGrid>(path, f, countName);
    checkTransform(path, *count, xform);
    for (auto it = count->cbeginValueOn(); it; ++it) {
      const uint32_t v = voxelOf(it.getCoord(), countName);
      if (layer == 1) hasLayer1[v] = 1;
      if (layer == 2 && !hasLayer1[v]) {
        throw InputError(path + ": voxel " + g.coords[v].ToString() +
                         " has surface layer 2 but not layer 1");
      }
      entries.push_back({v, layer});
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.voxel < b.voxel || (a.voxel == b.voxel && a.layer < b.layer);
  });
  for (size_t v = 0; v < n; ++v) {
    if (!hasLayer1[v]) continue;
    if (!points->tree().isValueOn(toVdb(g.coords[v]))) {
      throw InputError(path + ": grid '" + pointName + "' has no value at " +
                       g.coords[v].ToString() + ", a voxel with surface layers");
    }
  }
  resizeLayerArrays(g, entries.size());
  for (size_t e = 0; e < entries.size(); ++e) g.layers.voxel[e] = entries[e].voxel;
  for (int layer = 1; layer < kMaxLayers; ++layer) {
    std::vector<size_t> at;
    std::vector<Coord> coords;
    for (size_t e = 0; e < entries.size(); ++e) {
      if (entries[e].layer != layer) continue;
      at.push_back(e);
      coords.push_back(g.coords[entries[e].voxel]);
    }
    if (at.empty()) continue;
    forEachField([&](const auto& row) {
      if (row.layers) {
        readField(path, f, row, layer, g.maxVdls, g.shTerms, &xform, coords, at,
                  g.layers.*row.layers);
      }
    });
  }
}

/// The free-space light (vdb_write.cpp addVolumeSources) into g.volume,
/// when the file has it. @throws InputError for grids that disagree or
/// values a renderer cannot draw.
void readVolume(const std::string& path, const OpenedFile& f, VdlGrid& g) {
  const int depth = metaInt(path, *f.meta, kMetaFreeSpaceDepth, false, 0);
  if (depth == 0 && !findGrid(f, kVolumeIrradianceGrid)) return;
  if (depth < 1 || depth > g.frame.depth) {
    throw InputError(path + ": file metadata " + kMetaFreeSpaceDepth + " = " +
                     std::to_string(depth) + " is outside [1, depth " +
                     std::to_string(g.frame.depth) + "]");
  }
  auto key = requireGrid<Vec3SGrid>(path, f, kVolumeIrradianceGrid);
  const Transform& xform = key->transform();
  VolumeLight& v = g.volume;
  v.frame = readFrame(path, xform, depth, g.frame.offset);
  const float expected = g.frame.voxelSize * float(1 << (g.frame.depth - depth));
  if (!(std::fabs(v.frame.voxelSize - expected) <= 1e-4f * expected) ||
      !(length(v.frame.origin - g.frame.origin) <= 1e-3f * expected)) {
    throw InputError(path + ": grid '" + kVolumeIrradianceGrid + "' is not on the light grid's cube " +
                     std::to_string(g.frame.depth - depth) + " levels coarser");
  }
  v.frame.origin = g.frame.origin;
  v.frame.voxelSize = expected;
  // Before any voxel is listed: a few bytes of file may stand for tiles of
  // millions of active voxels.
  const int res = 1 << depth;
  const openvdb::CoordBBox box = key->evalActiveVoxelBoundingBox();
  if (key->activeVoxelCount() > openvdb::Index64(res) * openvdb::Index64(res) * openvdb::Index64(res) ||
      (key->activeVoxelCount() > 0 &&
       (box.min().x() < 0 || box.min().y() < 0 || box.min().z() < 0 || box.max().x() >= res ||
        box.max().y() >= res || box.max().z() >= res))) {
    throw InputError(path + ": grid '" + kVolumeIrradianceGrid + "' has " +
                     std::to_string(key->activeVoxelCount()) +
                     " active voxels, some outside [0, " + std::to_string(res) + ")^3");
  }
  for (auto it = key->cbeginValueOn(); it; ++it) v.coords.push_back(fromVdb(it.getCoord()));
  std::sort(v.coords.begin(), v.coords.end(), canonicalLess);
  int terms = 0;
  while (terms < 9 && findGrid(f, kVolumeShPrefix + std::to_string(terms))) ++terms;
  if (terms != 4 && terms != 9) {
    throw InputError(path + ": " + std::to_string(terms) + " '" + kVolumeShPrefix +
                     "<i>' grids; the free-space light has 4 or 9");
  }
  v.shTerms = terms;
  const size_t n = v.coords.size();
  auto readVec = [&](const std::string& name, std::vector<Vec3>& out, size_t per, size_t slot) {
    auto grid = requireGrid<Vec3SGrid>(path, f, name);
    checkTransform(path, *grid, xform);
    if (grid->activeVoxelCount() != openvdb::Index64(n)) {
      throw InputError(path + ": grid '" + name + "' has " +
                       std::to_string(grid->activeVoxelCount()) + " active voxels, '" +
                       kVolumeIrradianceGrid + "' has " + std::to_string(n));
    }
    out.resize(n * per);
    auto acc = grid->getConstAccessor();
    for (size_t k = 0; k < n; ++k) {
      const Vec3 value = fromVdb(acc.getValue(toVdb(v.coords[k])));
      if (!isFinite(value) || std::fabs(maxComponent(max(value, -value))) > kMaxStoredIrradiance) {
        throw InputError(path + ": grid '" + name + "' at " + v.coords[k].ToString() + " holds " +
                         value.ToString());
      }
      out[k * per + slot] = value;
    }
  };
  readVec(kVolumeIrradianceGrid, v.irradiance, 1, 0);
  for (int i = 0; i < terms; ++i) {
    readVec(kVolumeShPrefix + std::to_string(i), v.sh, size_t(terms), size_t(i));
  }
  readVec(kVolumeLitLowerGrid, v.litLower, 1, 0);
  readVec(kVolumeLitUpperGrid, v.litUpper, 1, 0);
  v.segments.assign(n, 0.0f);
  if (auto segments = openvdb::gridPtrCast<FloatGrid>(findGrid(f, kVolumeSegmentsGrid))) {
    checkTransform(path, *segments, xform);
    auto acc = segments->getConstAccessor();
    for (size_t k = 0; k < n; ++k) v.segments[k] = acc.getValue(toVdb(v.coords[k]));
  }
  // The values: checkReadableValues, after.
}

}  // namespace

LoadedVdl readVdlStructure(const std::string& path, const std::optional<Vec3d>& origin) {
  OpenedFile f = openFile(path);
  // The other .vdb a bake writes: said so, where its missing metadata
  // ("missing file metadata 'depth'") told nothing of what it is.
  if (findGrid(f, "photons") && !findGrid(f, gridNameOf(&VdlGrid::irradiance))) {
    throw InputError(path +
                     ": this is a photon map (a .vdb of photons, written by `bake "
                     "--photon-map`), not a light grid (the .vdb `bake -o` and `convert` write): "
                     "a photon map is read only beside its grid, by `convert --photon-map`");
  }
  LoadedVdl out;
  out.meta = readMetadata(path, *f.meta);
  // Before anything sizes or places a voxel by it: a depth out of range was
  // refused late, or blamed on another check.
  checkDepthInRange(path, out.meta.depth);
  if (formatVersionOf(*f.meta).absent) {
    out.notes.push_back("no format_version metadata: read as format version 1");
  }
  const int maxVdls = metaInt(path, *f.meta, kMetaMaxVdls, true, 0);
  if (maxVdls < 1 || maxVdls > kMaxVdls) {
    throw InputError(path + ": file metadata max_vdls = " + std::to_string(maxVdls) +
                     " is outside [1, " + std::to_string(kMaxVdls) + "]");
  }
  // The representation: VDLs, or SH terms (format version 3).
  const std::string& representation = out.meta.representation;
  LightRepresentation parsed = LightRepresentation::Vdl;
  if (!parseRepresentation(representation, &parsed)) {
    throw InputError(path + ": file metadata representation = '" + printable(representation) +
                     "'; expected " + representationChoices());
  }
  const int shTerms = shTermsOf(parsed);
  if (shTerms > 0 && out.meta.formatVersion < 3) {
    throw InputError(path + ": representation " + representation + " in a format version " +
                     std::to_string(out.meta.formatVersion) +
                     " file (SH grids came with version 3): the file is inconsistent");
  }

  // Every grid of the voxels, typed, before anything is interpreted.
  // Optional grids may be absent (a file converted with --drop): read as 0.
  std::vector<openvdb::GridBase::Ptr> dense, sparse;
  forEachField([&](const auto& row) {
    using T = typename std::decay_t<decltype(row)>::Value;
    if (row.arity == FieldArity::OneOrNone) return;  // surface layers: readLayers
    for (const FieldGrid& fg : fieldGrids(row, 0, maxVdls, shTerms)) {
      if (row.optional && !findGrid(f, fg.name)) {
        out.absentGrids.push_back(fg.name);
        continue;
      }
      openvdb::GridBase::Ptr grid = requireGrid<GridOf<T>>(path, f, fg.name);
      (std::is_same_v<T, Vdl> ? sparse : dense).push_back(grid);
    }
  });
  out.halfFloat = findGrid(f, gridNameOf(&VdlGrid::irradiance))->saveFloatAsHalf();
  auto key = requireGrid<FloatGrid>(path, f, keyGridName());
  // inspect's same_transform and same_active_voxels, by the same functions:
  // a layer grid zeroed by damage was read as a layer of zeros.
  if (const GridsCheck c = sameTransform(f); !c.passed) {
    throw InputError(path + ": mismatched transforms: " + c.detail);
  }
  if (const GridsCheck c = sameActiveVoxels(f); !c.passed) {
    throw InputError(path + ": " + c.detail + ": grids of one set of voxels differ; the file is "
                     "damaged (`lightoctree inspect` lists every check)");
  }

  const Transform& xform = key->transform();
  const openvdb::Index64 active = key->activeVoxelCount();
  for (const auto& grid : dense) {
    checkTransform(path, *grid, xform);
    if (grid->activeVoxelCount() != active) {
      throw InputError(path + ": grid '" + grid->getName() + "' has " +
                       std::to_string(grid->activeVoxelCount()) + " active voxels, '" +
                       keyGridName() + "' has " + std::to_string(active));
    }
  }
  // VDL grids: active where the voxel has that VDL (sparse), or on every voxel
  // (files before version 2 store zeros); never beyond the voxels.
  for (const auto& grid : sparse) {
    checkTransform(path, *grid, xform);
    auto typed = openvdb::gridPtrCast<Vec3SGrid>(grid);
    for (auto it = typed->cbeginValueOn(); it; ++it) {
      if (!key->tree().isValueOn(it.getCoord())) {
        throw InputError(path + ": grid '" + grid->getName() + "' is active at " +
                         fromVdb(it.getCoord()).ToString() + ", which is not a voxel of the file");
      }
    }
  }

  VdlGrid& g = out.grid;
  g.frame = readFrame(path, xform, out.meta.depth, origin.value_or(out.meta.sceneOrigin));
  if (out.meta.depth >= 1 && out.meta.depth <= kMaxGridDepth) {
    checkDepthAgainstBounds(path, out.meta, g.frame);
  }
  if (origin) {
    // The metadata's bounds too, from the baked scene's origin to `origin`.
    const Vec3d from = out.meta.sceneOrigin;
    const Vec3 shift((from - *origin).toVec3());
    for (Bounds3* b : {&out.meta.sceneBounds, &out.meta.region}) {
      if (!b->empty()) {
        b->lower += shift;
        b->upper += shift;
      }
    }
    out.meta.sceneOrigin = *origin;
  }
  g.maxVdls = maxVdls;
  g.shTerms = shTerms;
  g.coords.reserve(size_t(active));
  for (auto it = key->cbeginValueOn(); it; ++it) g.coords.push_back(fromVdb(it.getCoord()));
  std::sort(g.coords.begin(), g.coords.end(), canonicalLess);
  resizeVoxelArrays(g);
  forEachField([&](const auto& row) {
    if (row.arity == FieldArity::OneOrNone) return;
    readField(path, f, row, 0, maxVdls, shTerms, nullptr, g.coords, {}, g.*row.voxels);
  });
  if (shTerms > 0) {
    for (size_t v = 0; v < g.size(); ++v) {
      if (g.vdlCount[v] != 0) {
        throw InputError(path + ": voxel " + g.coords[v].ToString() + " of an " + representation +
                         " file has " + std::to_string(g.vdlCount[v]) +
                         " VDLs; SH files hold none");
      }
    }
  }
  readLayers(path, f, xform, out);
  readVolume(path, f, out.grid);
  checkReadableValues(path, out.grid);
  return out;
}

}  // namespace vdb_internal

LoadedVdl readVdlGrid(const std::string& path, const std::optional<Vec3d>& origin) {
  LoadedVdl loaded = vdb_internal::readVdlStructure(path, origin);
  for (const VdbCheck& c : checkLightGridValues(loaded.grid, loaded.halfFloat)) {
    if (!c.passed) {
      throw InputError(path + ": check " + c.name + " fails: " + c.detail +
                       " (`lightoctree inspect` lists every check)");
    }
  }
  return loaded;
}

}  // namespace lo
