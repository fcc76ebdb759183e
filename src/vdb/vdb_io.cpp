// .vdb files: the VDL grid contract (docs/vdb-contract.md) and the photon map
// as a PointDataGrid. The only translation unit that includes OpenVDB's IO and
// points headers, which compile slowly.

#include "vdb/vdb_io.h"

#include <openvdb/io/File.h>
#include <openvdb/io/GridDescriptor.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <octree_layout.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.h"
#include "core/file.h"
#include "core/isolate.h"
#include "vdb/vdb_file.h"
#include "vdb/vdb_internal.h"

namespace lo {
namespace vdb_internal {

void initOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

std::string clipped(const std::string& text) {
  constexpr size_t kMax = 400;
  if (text.size() <= kMax) return text;
  return text.substr(0, kMax) + "... (" + std::to_string(text.size() - kMax) + " more characters)";
}

IsolationLimits readLimits(uintmax_t fileBytes) {
  IsolationLimits limits;
  limits.memoryBytes = kReadMemoryBaseBytes + size_t(kReadMemoryPerFileByte * double(fileBytes));
  limits.seconds = kReadSecondsBase + double(fileBytes) * kReadSecondsPerByte;
  return limits;
}

OpenedFile openFile(const std::string& path) {
  initOpenVdb();
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) throw InputError(path + ": file does not exist");
  if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": not a regular file");
  // OpenVDB trusts the sizes a file states: a damaged file can make it
  // allocate gigabytes, loop for minutes or corrupt the heap. A child
  // process reads it first under limits; only a file it read whole is read
  // here (docs/robustness.md, "Reading untrusted files").
  const uintmax_t bytes = std::filesystem::file_size(path, ec);
  const IsolationLimits limits = readLimits(ec ? 0 : bytes);
  auto trialRead = [&](std::string&) {
    openvdb::io::File file(path);
    file.open(false);
    file.getMetadata();
    file.getGrids();
    file.close();
    return 0;
  };
  IsolatedRun trial = runIsolated(trialRead, limits);
  // A child forked from a process with other threads can, rarely, wait
  // forever on a lock one of them held at the fork: a wait past the time
  // limit, or a crash, is tried once more before the file is refused (a
  // damaged file fails again). A child that spent its whole CPU time reading
  // was not waiting: the file is refused at once.
  if ((trial.outcome == IsolatedRun::Outcome::TimedOut && !trial.usedItsCpu) ||
      trial.outcome == IsolatedRun::Outcome::Crashed) {
    trial = runIsolated(trialRead, limits);
  }
  if (trial.outcome == IsolatedRun::Outcome::Finished && trial.exitCode != 0) {
    throw InputError(path + ": cannot read as an OpenVDB file: " + clipped(trial.message));
  }
  if (trial.outcome != IsolatedRun::Outcome::Finished &&
      trial.outcome != IsolatedRun::Outcome::NotIsolated) {
    throw InputError(path + ": damaged or not an OpenVDB file: reading it " +
                     trial.ToString(limits));
  }
  OpenedFile f;
  try {
    openvdb::io::File file(path);
    // No delayed loading: every read error surfaces here, inside the try,
    // rather than on first access to a leaf.
    file.open(false);
    f.meta = file.getMetadata();
    f.grids = file.getGrids();
    file.close();
  } catch (const std::exception& e) {
    throw InputError(path + ": cannot read as an OpenVDB file: " + clipped(e.what()));
  }
  if (!f.grids || !f.meta) throw InputError(path + ": cannot read as an OpenVDB file");
  return f;
}

namespace {

namespace fs = std::filesystem;
using openvdb::FloatGrid;
using openvdb::Vec3SGrid;
using openvdb::math::Transform;

// ---------------------------------------------------------------------------
// Grid names and units of the contract (docs/vdb-contract.md).

constexpr const char* kIrradiance = "irradiance";
constexpr const char* kNormal = "normal";
constexpr const char* kPhotonCount = "photon_count";
constexpr const char* kAngularError = "angular_error";
constexpr const char* kVdlCount = "vdl_count";
constexpr const char* kRadius = "radius";
constexpr const char* kArea = "area";
constexpr const char* kIrradianceUnits = "W/m^2";

std::string vdlIrradianceName(int i) { return "vdl" + std::to_string(i) + "_irradiance"; }
std::string vdlDirectionName(int i) { return "vdl" + std::to_string(i) + "_direction"; }
// SH files (format version 3): "sh<i>" = term i of the irradiance's SH.
std::string shName(int i) { return "sh" + std::to_string(i); }
constexpr const char* kShUnits = "W/m^2 (SH term; E(n) = sum_i sh<i> Y_i(n))";

// Surface layers (docs/vdb-contract.md): "layer_point" holds layer 0's point
// on the voxels that have more layers; layer l's grids are "layer<l>_" + the
// name of the voxel grid they mirror, active on the voxels that have layer l.
constexpr const char* kLayerPoint = "layer_point";
std::string layerName(int layer, const std::string& name) {
  return "layer" + std::to_string(layer) + "_" + name;
}

// ---------------------------------------------------------------------------
// Deterministic bytes. io::Archive writes a random UUID (36 ASCII characters
// after the 21-byte header prefix: magic, file version, library version, the
// grid-offsets flag). The bake must give byte-identical files for identical
// inputs, so the UUID is replaced by one derived from the rest of the file:
// identical content, identical identity, which is what OpenVDB uses it for.

constexpr std::streamoff kUuidOffset = 8 + 4 + 4 + 4 + 1;
constexpr size_t kUuidLength = 36;

uint64_t fnv1a(uint64_t h, const char* data, size_t n) {
  for (size_t i = 0; i < n; ++i) {
    h ^= uint8_t(data[i]);
    h *= 0x100000001b3ull;
  }
  return h;
}

void makeUuidDeterministic(const std::string& file) {
  std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
  if (!f) throw std::runtime_error("cannot reopen the temporary file");
  char uuid[kUuidLength];
  f.seekg(kUuidOffset);
  f.read(uuid, kUuidLength);
  if (!f || uuid[8] != '-' || uuid[13] != '-' || uuid[18] != '-' || uuid[23] != '-') {
    throw std::runtime_error("unexpected OpenVDB header layout (UUID not found)");
  }
  uint64_t h1 = 0xcbf29ce484222325ull, h2 = 0x84222325cbf29ce4ull;
  std::vector<char> buffer(1 << 16);
  while (f) {
    f.read(buffer.data(), std::streamsize(buffer.size()));
    size_t got = size_t(f.gcount());
    h1 = fnv1a(h1, buffer.data(), got);
    h2 = fnv1a(h2, buffer.data(), got);
  }
  f.clear();
  char hex[33];
  std::snprintf(hex, sizeof(hex), "%016llx%016llx", static_cast<unsigned long long>(h1),
                static_cast<unsigned long long>(h2));
  hex[12] = '8';  // RFC 9562 version 8: "custom" (here: content hash)
  std::string text = std::string(hex, 8) + "-" + std::string(hex + 8, 4) + "-" +
                     std::string(hex + 12, 4) + "-" + std::string(hex + 16, 4) + "-" +
                     std::string(hex + 20, 12);
  f.seekp(kUuidOffset);
  f.write(text.data(), std::streamsize(text.size()));
  if (!f) throw std::runtime_error("cannot rewrite the file header");
}

/// One grid of a file, built when it is written (writeVdbFile): a file's
/// grids are never all in memory at once.
struct GridSource {
  std::string name;
  std::function<openvdb::GridBase::Ptr()> make;
};

/// io::File::write's archive, but each grid is built just before it is
/// written and freed after: the bytes io::Archive::write gives a file of
/// grids with distinct names (header, file metadata, grid count, then each
/// grid's descriptor, offsets and data), without every grid in memory at
/// once (a depth-8 Cornell box's grids take ~1 KB per voxel in OpenVDB's
/// dense 8^3 leaves).
class GridByGridArchive : public openvdb::io::Archive {
 public:
  void writeGrids(std::ostream& os, const std::vector<GridSource>& sources,
             const openvdb::MetaMap& meta) const {
    openvdb::io::StreamMetadata::Ptr streamMetadata(new openvdb::io::StreamMetadata);
    openvdb::io::setStreamMetadataPtr(os, streamMetadata, /*transfer=*/false);
    openvdb::io::setDataCompression(os, compression());
    openvdb::io::setWriteGridStatsMetadata(os, isGridStatsMetadataEnabled());
    writeHeader(os, /*seekable=*/true);
    meta.writeMeta(os);
    const int32_t count = int32_t(sources.size());
    os.write(reinterpret_cast<const char*>(&count), sizeof count);
    std::set<std::string> names;
    for (const GridSource& source : sources) {
      openvdb::GridBase::ConstPtr grid = source.make();
      // Archive::write would rename a repeated or empty name.
      LO_CHECK(!grid->getName().empty() && names.insert(grid->getName()).second);
      openvdb::io::GridDescriptor descriptor(grid->getName(), grid->type(),
                                             grid->saveFloatAsHalf());
      writeGrid(descriptor, grid, os, /*seekable=*/true);
      openvdb::io::setDataCompression(os, compression());
    }
  }
};

// Writes through a temporary file (core/file.h), grid by grid: a reader
// never sees a half file.
void writeVdbFile(const std::string& path, const std::vector<GridSource>& sources,
                  const openvdb::MetaMap& meta) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty() && !fs::is_directory(parent)) {
    throw IoError(path + ": cannot write: folder '" + parent.string() + "' does not exist");
  }
  writeAtomically(path, [&](const std::string& tmp) {
    {
      std::ofstream file(tmp, std::ios_base::out | std::ios_base::binary);
      if (!file) throw std::runtime_error("cannot open the file");
      GridByGridArchive().writeGrids(file, sources, meta);
      file.close();
      if (file.fail()) throw std::runtime_error("cannot write the file");
    }
    makeUuidDeterministic(tmp);
  });
}

// ---------------------------------------------------------------------------
// Writing the VDL grids.

openvdb::Vec3s toVdb(const Vec3& v) { return {v.x, v.y, v.z}; }
openvdb::Coord toVdb(const Coord& c) { return {c.x, c.y, c.z}; }
Vec3 fromVdb(const openvdb::Vec3s& v) { return {v.x(), v.y(), v.z()}; }

// Voxel (i,j,k) of a GridFrame covers origin + ijk * h .. + h; OpenVDB's
// integer index points are voxel centres, so index ijk must map to
// origin + (ijk + 0.5) * h.
Transform::Ptr frameTransform(const GridFrame& frame) {
  const double h = frame.voxelSize;
  Transform::Ptr xform = Transform::createLinearTransform(h);
  xform->postTranslate(openvdb::Vec3d(double(frame.origin.x) + 0.5 * h,
                                      double(frame.origin.y) + 0.5 * h,
                                      double(frame.origin.z) + 0.5 * h));
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

void checkArrays(const VdlGrid& g) {
  const size_t n = g.size();
  LO_CHECK_EQ(g.normals.size(), n);
  LO_CHECK_EQ(g.areas.size(), n);
  LO_CHECK_EQ(g.irradiance.size(), n);
  LO_CHECK_EQ(g.photonCount.size(), n);
  LO_CHECK_EQ(g.radius.size(), n);
  LO_CHECK_EQ(g.angularError.size(), n);
  LO_CHECK_EQ(g.vdlCount.size(), n);
  LO_CHECK_EQ(g.vdls.size(), n * size_t(g.maxVdls));
  LO_CHECK(g.shTerms == 0 || g.shTerms == 4 || g.shTerms == 9);
  LO_CHECK_EQ(g.sh.size(), n * size_t(g.shTerms));
  const VdlLayers& L = g.layers;
  const size_t ne = L.size();
  LO_CHECK_EQ(L.sh.size(), ne * size_t(g.shTerms));
  if (ne == 0) return;
  LO_CHECK_EQ(g.points.size(), n);
  LO_CHECK_EQ(L.normals.size(), ne);
  LO_CHECK_EQ(L.points.size(), ne);
  LO_CHECK_EQ(L.irradiance.size(), ne);
  LO_CHECK_EQ(L.photonCount.size(), ne);
  LO_CHECK_EQ(L.radius.size(), ne);
  LO_CHECK_EQ(L.angularError.size(), ne);
  LO_CHECK_EQ(L.vdlCount.size(), ne);
  LO_CHECK_EQ(L.vdls.size(), ne * size_t(g.maxVdls));
  for (size_t e = 0; e < ne; ++e) {
    LO_CHECK_LT(size_t(L.voxel[e]), n);
    if (e > 0) LO_CHECK_LE(L.voxel[e - 1], L.voxel[e]);
    if (e > 1) LO_CHECK(L.voxel[e - 2] != L.voxel[e]);  // at most kMaxLayers - 1 extra
  }
}

openvdb::MetaMap fileMetadata(const BakeMetadata& meta, const VdlGrid& grid) {
  openvdb::MetaMap m;
  m.insertMeta("generator", openvdb::StringMetadata(meta.generator));
  m.insertMeta("version", openvdb::StringMetadata(meta.version));
  m.insertMeta("source_scene", openvdb::StringMetadata(meta.sourceScene));
  // The grid's own frame is the truth for depth; see the check in writeVdlGrid.
  m.insertMeta("depth", openvdb::Int32Metadata(grid.frame.depth));
  m.insertMeta("photons", openvdb::Int64Metadata(meta.photons));
  m.insertMeta("emitted_paths", openvdb::Int64Metadata(meta.emittedPaths));
  m.insertMeta("knn", openvdb::Int32Metadata(meta.knn));
  m.insertMeta("radius", openvdb::FloatMetadata(meta.radius));
  m.insertMeta("vdls", openvdb::StringMetadata(meta.vdls));
  m.insertMeta("seed", openvdb::Int64Metadata(meta.seed));
  m.insertMeta("scene_bounds_min", openvdb::Vec3SMetadata(toVdb(meta.sceneBounds.lower)));
  m.insertMeta("scene_bounds_max", openvdb::Vec3SMetadata(toVdb(meta.sceneBounds.upper)));
  m.insertMeta("units", openvdb::StringMetadata(meta.units));
  m.insertMeta("max_vdls", openvdb::Int32Metadata(grid.maxVdls));
  // The lowest version that holds the file (lightgrid/vdl_grid.h).
  m.insertMeta("format_version", openvdb::Int32Metadata(grid.shTerms > 0 ? kVdlFormatVersion
                                                                          : kVdlFormatVersionVdl));
  if (grid.shTerms > 0) {
    m.insertMeta("representation",
                 openvdb::StringMetadata(grid.shTerms == 4 ? "sh1" : "sh2"));
  }
  if (!meta.convertedFrom.empty()) {
    m.insertMeta("converted_from", openvdb::StringMetadata(meta.convertedFrom));
  }
  if (meta.surfaceLayers >= 0) m.insertMeta("surface_layers", openvdb::Int32Metadata(meta.surfaceLayers));
  if (meta.gatherOcclusion >= 0) {
    m.insertMeta("gather_occlusion", openvdb::Int32Metadata(meta.gatherOcclusion));
  }
  if (meta.edgeCorrection >= 0) m.insertMeta("edge_correction", openvdb::Int32Metadata(meta.edgeCorrection));
  if (meta.includeDirect >= 0) m.insertMeta("include_direct", openvdb::Int32Metadata(meta.includeDirect));
  if (!meta.region.empty()) {
    m.insertMeta("region_min", openvdb::Vec3SMetadata(toVdb(meta.region.lower)));
    m.insertMeta("region_max", openvdb::Vec3SMetadata(toVdb(meta.region.upper)));
  }
  return m;
}

/// The grids of the VDL file contract for `g` (which must outlive them), in
/// file order.
std::vector<GridSource> vdlGridSources(const VdlGrid& g, const Transform::Ptr& xform) {
  const auto& c = g.coords;
  std::vector<GridSource> grids;
  auto add = [&](const std::string& name, std::function<openvdb::GridBase::Ptr()> make) {
    grids.push_back({name, std::move(make)});
  };
  add(kIrradiance, [&g, &c, xform] {
    return vectorGrid(kIrradiance, kIrradianceUnits, openvdb::VEC_INVARIANT, xform, c,
                      [&](size_t v) { return g.irradiance[v]; });
  });
  add(kNormal, [&g, &c, xform] {
    return vectorGrid(kNormal, "unit vector, world space", openvdb::VEC_COVARIANT_NORMALIZE, xform,
                      c, [&](size_t v) { return g.normals[v]; });
  });
  add(kPhotonCount, [&g, &c, xform] {
    return floatGrid(kPhotonCount, "photons", xform, c, [&](size_t v) { return g.photonCount[v]; });
  });
  add(kAngularError, [&g, &c, xform] {
    return floatGrid(kAngularError, "chord length (0..2), weighted std. deviation", xform, c,
                     [&](size_t v) { return g.angularError[v]; });
  });
  add(kVdlCount, [&g, &c, xform] {
    return floatGrid(kVdlCount, "count", xform, c, [&](size_t v) { return float(g.vdlCount[v]); });
  });
  add(kRadius, [&g, &c, xform] {
    return floatGrid(kRadius, "world units", xform, c, [&](size_t v) { return g.radius[v]; });
  });
  add(kArea, [&g, &c, xform] {
    return floatGrid(kArea, "world units^2", xform, c, [&](size_t v) { return g.areas[v]; });
  });
  // VDL i only where the voxel has more than i VDLs (sparse: a voxel with
  // fewer stores no zeros in the higher grids).
  for (int i = 0; i < g.maxVdls; ++i) {
    auto withVdl = [&g, &c, i](std::vector<size_t>& voxels, std::vector<Coord>& coords) {
      for (size_t v = 0; v < g.size(); ++v) {
        if (g.vdlCount[v] > i) {
          voxels.push_back(v);
          coords.push_back(c[v]);
        }
      }
    };
    add(vdlIrradianceName(i), [&g, xform, i, withVdl] {
      std::vector<size_t> voxels;
      std::vector<Coord> coords;
      withVdl(voxels, coords);
      return vectorGrid(vdlIrradianceName(i), kIrradianceUnits, openvdb::VEC_INVARIANT, xform,
                        coords, [&](size_t k) { return g.vdlsOf(voxels[k])[i].irradiance; });
    });
    add(vdlDirectionName(i), [&g, xform, i, withVdl] {
      std::vector<size_t> voxels;
      std::vector<Coord> coords;
      withVdl(voxels, coords);
      return vectorGrid(vdlDirectionName(i), "unit vector towards the light, world space",
                        openvdb::VEC_INVARIANT, xform, coords,
                        [&](size_t k) { return g.vdlsOf(voxels[k])[i].direction; });
    });
  }
  for (int i = 0; i < g.shTerms; ++i) {
    add(shName(i), [&g, &c, xform, i] {
      return vectorGrid(shName(i), kShUnits, openvdb::VEC_INVARIANT, xform, c,
                        [&](size_t v) { return g.shOf(v)[i]; });
    });
  }
  if (g.layers.size() == 0) return grids;

  // Surface layers: per layer index, its entries and their voxels.
  struct LayerIndex {
    std::vector<size_t> entries[kMaxLayers];
    std::vector<Coord> coords[kMaxLayers];
  };
  auto index = std::make_shared<LayerIndex>();
  const VdlLayers& L = g.layers;
  for (size_t e = 0; e < L.size(); ++e) {
    const int layer = e > 0 && L.voxel[e - 1] == L.voxel[e] ? 2 : 1;
    index->entries[layer].push_back(e);
    index->coords[layer].push_back(c[L.voxel[e]]);
    if (layer == 1) {
      index->entries[0].push_back(L.voxel[e]);
      index->coords[0].push_back(c[L.voxel[e]]);
    }
  }
  add(kLayerPoint, [&g, xform, index] {
    return vectorGrid(kLayerPoint, "world space", openvdb::VEC_CONTRAVARIANT_ABSOLUTE, xform,
                      index->coords[0], [&](size_t k) { return g.points[index->entries[0][k]]; });
  });
  for (int layer = 1; layer < kMaxLayers; ++layer) {
    if (index->entries[layer].empty()) continue;
    const std::vector<size_t>& es = index->entries[layer];
    const std::vector<Coord>& lc = index->coords[layer];
    auto name = [layer](const std::string& n) { return layerName(layer, n); };
    // Each source keeps the index alive; es and lc point into it.
    auto vector = [&](const std::string& n, const std::string& units, openvdb::VecType type,
                      std::function<Vec3(size_t)> value) {
      add(name(n), [n = name(n), units, type, value, xform, index, &lc] {
        return vectorGrid(n, units, type, xform, lc, value);
      });
    };
    auto scalar = [&](const std::string& n, const std::string& units,
                      std::function<float(size_t)> value) {
      add(name(n), [n = name(n), units, value, xform, index, &lc] {
        return floatGrid(n, units, xform, lc, value);
      });
    };
    vector(kIrradiance, kIrradianceUnits, openvdb::VEC_INVARIANT,
           [&L, &es](size_t k) { return L.irradiance[es[k]]; });
    vector(kNormal, "unit vector, world space", openvdb::VEC_COVARIANT_NORMALIZE,
           [&L, &es](size_t k) { return L.normals[es[k]]; });
    vector("point", "world space", openvdb::VEC_CONTRAVARIANT_ABSOLUTE,
           [&L, &es](size_t k) { return L.points[es[k]]; });
    scalar(kPhotonCount, "photons", [&L, &es](size_t k) { return L.photonCount[es[k]]; });
    scalar(kAngularError, "chord length (0..2), weighted std. deviation",
           [&L, &es](size_t k) { return L.angularError[es[k]]; });
    scalar(kVdlCount, "count", [&L, &es](size_t k) { return float(L.vdlCount[es[k]]); });
    scalar(kRadius, "world units", [&L, &es](size_t k) { return L.radius[es[k]]; });
    for (int i = 0; i < g.maxVdls; ++i) {
      auto withVdl = [&L, &es, &lc, i](std::vector<size_t>& entries, std::vector<Coord>& coords) {
        for (size_t k = 0; k < es.size(); ++k) {
          if (L.vdlCount[es[k]] > i) {
            entries.push_back(es[k]);
            coords.push_back(lc[k]);
          }
        }
      };
      add(name(vdlIrradianceName(i)), [&g, xform, index, i, withVdl, n = name(vdlIrradianceName(i))] {
        std::vector<size_t> ek;
        std::vector<Coord> kc;
        withVdl(ek, kc);
        return vectorGrid(n, kIrradianceUnits, openvdb::VEC_INVARIANT, xform, kc,
                          [&](size_t k) { return g.layerVdlsOf(ek[k])[i].irradiance; });
      });
      add(name(vdlDirectionName(i)), [&g, xform, index, i, withVdl, n = name(vdlDirectionName(i))] {
        std::vector<size_t> ek;
        std::vector<Coord> kc;
        withVdl(ek, kc);
        return vectorGrid(n, "unit vector towards the light, world space", openvdb::VEC_INVARIANT,
                          xform, kc, [&](size_t k) { return g.layerVdlsOf(ek[k])[i].direction; });
      });
    }
    for (int i = 0; i < g.shTerms; ++i) {
      vector(shName(i), kShUnits, openvdb::VEC_INVARIANT,
             [&g, &es, i](size_t k) { return g.layerShOf(es[k])[i]; });
    }
  }
  return grids;
}

bool isOptionalGrid(const std::string& name) {
  const auto& names = optionalVdlGridNames();
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Counts and areas stay 32-bit in half-float files (see VdlWriteOptions).
bool keepsFullPrecision(const std::string& name) {
  auto endsWith = [&](const std::string& tail) {
    return name.size() >= tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0;
  };
  return endsWith(kVdlCount) || endsWith(kPhotonCount) || name == kArea ||
         endsWith("point");
}

void writeVdl(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
              const VdlWriteOptions& options, const Damage* damage) {
  initOpenVdb();
  for (const std::string& name : options.drop) {
    if (!isOptionalGrid(name)) {
      std::string list;
      for (const auto& o : optionalVdlGridNames()) list += (list.empty() ? "" : ", ") + o;
      throw InputError(
          "--drop: grid '" + name + "' " +
          (name == kIrradiance || name == kNormal || name == kVdlCount || name.rfind("vdl", 0) == 0
               ? "is required by the VDL file contract"
               : "is not a grid of the VDL file contract") +
          "; only optional grids can be dropped: " + list);
    }
  }
  checkArrays(grid);
  LO_CHECK(grid.maxVdls >= 1 && grid.maxVdls <= kMaxVdls);
  if (meta.depth != 0) LO_CHECK_EQ(meta.depth, grid.frame.depth);
  if (!(grid.frame.voxelSize > 0) || !std::isfinite(grid.frame.voxelSize)) {
    throw InputError(path + ": cannot write a grid with voxel size " +
                     std::to_string(grid.frame.voxelSize));
  }
  Transform::Ptr xform = frameTransform(grid.frame);
  if (damage && damage->rotateTransform) xform->postRotate(0.3, openvdb::math::Z_AXIS);
  std::vector<GridSource> sources;
  for (GridSource& source : vdlGridSources(grid, xform)) {
    if (damage && source.name == damage->omitGrid) continue;
    if (std::find(options.drop.begin(), options.drop.end(), source.name) != options.drop.end()) {
      continue;
    }
    const std::string name = source.name;
    const bool half = options.halfFloat && !keepsFullPrecision(name);
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
  openvdb::MetaMap fileMeta = fileMetadata(meta, grid);
  if (damage && damage->formatVersion != kVdlFormatVersion) {
    fileMeta.removeMeta("format_version");
    if (damage->formatVersion != 0) {
      fileMeta.insertMeta("format_version", openvdb::Int32Metadata(damage->formatVersion));
    }
  }
  writeVdbFile(path, sources, fileMeta);
}

// ---------------------------------------------------------------------------
// Reading.

// The canonical voxel order readers get: by 8^3 block (floor(c / 8), compared
// x, then y, then z), then by offset inside the block (c & 7, x, y, z) --
// OpenVDB's leaf-local order. Arithmetic shift: floor division for negatives.
bool canonicalLess(const Coord& a, const Coord& b) {
  Coord ba{a.x >> 3, a.y >> 3, a.z >> 3}, bb{b.x >> 3, b.y >> 3, b.z >> 3};
  if (ba != bb) return ba < bb;
  Coord oa{a.x & 7, a.y & 7, a.z & 7}, ob{b.x & 7, b.y & 7, b.z & 7};
  return oa < ob;
}

openvdb::GridBase::Ptr findGrid(const OpenedFile& f, const std::string& name) {
  for (const auto& g : *f.grids) {
    if (g && g->getName() == name) return g;
  }
  return nullptr;
}

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

template <typename T>
T metaValue(const std::string& path, const openvdb::MetaMap& meta, const std::string& key,
            bool required, T fallback) {
  openvdb::Metadata::ConstPtr m = meta[key];
  if (!m) {
    if (required) throw InputError(path + ": missing file metadata '" + key + "'");
    return fallback;
  }
  auto typed = openvdb::DynamicPtrCast<const openvdb::TypedMetadata<T>>(m);
  if (!typed) {
    // Integers of the other width (pyopenvdb writes every Python int as
    // int32 when it fits, and int64 otherwise): the same value.
    if constexpr (std::is_same_v<T, int64_t>) {
      if (auto narrow = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(m)) {
        return int64_t(narrow->value());
      }
    }
    if constexpr (std::is_same_v<T, int32_t>) {
      if (auto wide = openvdb::DynamicPtrCast<const openvdb::Int64Metadata>(m)) {
        if (wide->value() >= std::numeric_limits<int32_t>::min() &&
            wide->value() <= std::numeric_limits<int32_t>::max()) {
          return int32_t(wide->value());
        }
      }
    }
    throw InputError(path + ": file metadata '" + key + "' has type " + m->typeName() +
                     ", expected " + openvdb::typeNameAsString<T>());
  }
  return typed->value();
}

BakeMetadata readMetadata(const std::string& path, const openvdb::MetaMap& m) {
  BakeMetadata meta;
  meta.generator = metaValue<std::string>(path, m, "generator", false, "");
  meta.version = metaValue<std::string>(path, m, "version", false, "");
  meta.sourceScene = metaValue<std::string>(path, m, "source_scene", false, "");
  meta.depth = metaValue<int32_t>(path, m, "depth", true, 0);
  meta.photons = metaValue<int64_t>(path, m, "photons", false, 0);
  meta.emittedPaths = metaValue<int64_t>(path, m, "emitted_paths", false, 0);
  meta.knn = metaValue<int32_t>(path, m, "knn", false, 0);
  meta.radius = metaValue<float>(path, m, "radius", false, 0.0f);
  meta.vdls = metaValue<std::string>(path, m, "vdls", false, "");
  meta.representation = metaValue<std::string>(path, m, "representation", false, "vdl");
  meta.seed = metaValue<int64_t>(path, m, "seed", false, 0);
  meta.sceneBounds.lower = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "scene_bounds_min", false, openvdb::Vec3s(INFINITY)));
  meta.sceneBounds.upper = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "scene_bounds_max", false, openvdb::Vec3s(-INFINITY)));
  meta.units = metaValue<std::string>(path, m, "units", false, "");
  meta.formatVersion = metaValue<int32_t>(path, m, "format_version", false, 0);
  meta.convertedFrom = metaValue<std::string>(path, m, "converted_from", false, "");
  meta.surfaceLayers = metaValue<int32_t>(path, m, "surface_layers", false, -1);
  meta.gatherOcclusion = metaValue<int32_t>(path, m, "gather_occlusion", false, -1);
  meta.edgeCorrection = metaValue<int32_t>(path, m, "edge_correction", false, -1);
  meta.includeDirect = metaValue<int32_t>(path, m, "include_direct", false, -1);
  meta.region.lower = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "region_min", false, openvdb::Vec3s(INFINITY)));
  meta.region.upper = fromVdb(
      metaValue<openvdb::Vec3s>(path, m, "region_max", false, openvdb::Vec3s(-INFINITY)));
  return meta;
}

GridFrame readFrame(const std::string& path, const Transform& xform, int depth) {
  const openvdb::math::MapBase::ConstPtr map = xform.baseMap();
  const bool axisAligned = map->isType<openvdb::math::UniformScaleTranslateMap>() ||
                           map->isType<openvdb::math::UniformScaleMap>();
  if (!xform.isLinear() || !axisAligned) {
    throw InputError(path + ": transform is " + xform.mapType() +
                     ", expected a uniform scale and translation");
  }
  const double h = xform.voxelSize()[0];
  const openvdb::Vec3d centre0 = xform.indexToWorld(openvdb::Vec3d(0.0));
  GridFrame frame;
  frame.voxelSize = float(h);
  frame.origin = Vec3(float(centre0.x() - 0.5 * h), float(centre0.y() - 0.5 * h),
                      float(centre0.z() - 0.5 * h));
  frame.depth = depth;
  return frame;
}

}  // namespace

void writeVdlGridDamaged(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                         const Damage& damage) {
  writeVdl(path, grid, meta, damage.options, &damage);
}

namespace {

/// What no reader of the file may draw or convert, refused at reading:
/// non-finite values (NaN, Inf) and a depth outside the octree's range.
/// inspect reports these (and the softer checks: signs, sums, units) as
/// failed checks.
void checkValues(const std::string& path, const VdlGrid& g) {
  if (g.frame.depth < 1 || g.frame.depth > kMaxGridDepth) {
    throw InputError(path + ": file metadata depth = " + std::to_string(g.frame.depth) +
                     " is outside [1, " + std::to_string(kMaxGridDepth) + "]");
  }
  auto fail = [&](const Coord& c, const std::string& what) {
    throw InputError(path + ": " + what + " at voxel " + c.ToString() +
                     " is not finite (NaN or Inf): the file is damaged");
  };
  for (size_t v = 0; v < g.size(); ++v) {
    const Coord& c = g.coords[v];
    if (!isFinite(g.irradiance[v])) fail(c, "irradiance");
    if (!isFinite(g.normals[v])) fail(c, "normal");
    if (!std::isfinite(g.photonCount[v]) || !std::isfinite(g.radius[v]) ||
        !std::isfinite(g.areas[v]) || !std::isfinite(g.angularError[v])) {
      fail(c, "photon_count, radius, area or angular_error");
    }
    for (int i = 0; i < g.vdlCount[v]; ++i) {
      const Vdl& vdl = g.vdlsOf(v)[i];
      if (!isFinite(vdl.irradiance) || !isFinite(vdl.direction)) fail(c, "VDL " + std::to_string(i));
    }
    for (int i = 0; i < g.shTerms; ++i) {
      if (!isFinite(g.shOf(v)[i])) fail(c, "SH term " + std::to_string(i));
    }
  }
  for (size_t e = 0; e < g.layers.size(); ++e) {
    const Coord& c = g.coords[g.layers.voxel[e]];
    if (!isFinite(g.layers.irradiance[e]) || !isFinite(g.layers.normals[e]) ||
        !isFinite(g.layers.points[e])) {
      fail(c, "a surface layer");
    }
    for (int i = 0; i < g.layers.vdlCount[e]; ++i) {
      const Vdl& vdl = g.layerVdlsOf(e)[i];
      if (!isFinite(vdl.irradiance) || !isFinite(vdl.direction)) fail(c, "a surface layer's VDL");
    }
    for (int i = 0; i < g.shTerms; ++i) {
      if (!isFinite(g.layerShOf(e)[i])) fail(c, "a surface layer's SH term");
    }
  }
}

/// The surface layers of a version-2 file (none when it has no
/// "layer1_normal" grid): every grid of a layer present, on the file's
/// transform, each layer's voxels among the file's voxels, layer 2's among
/// layer 1's.
void readLayers(const std::string& path, const OpenedFile& f, const Transform& xform, int maxVdls,
                LoadedVdl& out) {
  VdlGrid& g = out.grid;
  const size_t n = g.size();
  if (!findGrid(f, layerName(1, kNormal))) {
    for (const auto& grid : *f.grids) {
      if (grid && grid->getName().rfind("layer", 0) == 0) {
        throw InputError(path + ": grid '" + grid->getName() +
                         "' without 'layer1_normal': incomplete surface layers");
      }
    }
    return;
  }
  auto voxelOf = [&](const openvdb::Coord& c, const std::string& grid) -> uint32_t {
    const Coord k{c.x(), c.y(), c.z()};
    auto it = std::lower_bound(g.coords.begin(), g.coords.end(), k, canonicalLess);
    if (it == g.coords.end() || *it != k) {
      throw InputError(path + ": grid '" + grid + "' is active at " + k.ToString() +
                       ", which is not a voxel of the file");
    }
    return uint32_t(it - g.coords.begin());
  };
  auto checked = [&](const openvdb::GridBase::Ptr& grid) {
    if (!(grid->transform() == xform)) {
      throw InputError(path + ": mismatched transforms: grid '" + grid->getName() +
                       "' differs from 'vdl_count'");
    }
  };
  // Layer 0's points, on the voxels with layers.
  g.points.assign(n, Vec3{});
  for (size_t v = 0; v < n; ++v) {
    g.points[v] = g.frame.origin + (Vec3{float(g.coords[v].x), float(g.coords[v].y),
                                         float(g.coords[v].z)} + Vec3(0.5f)) * g.frame.voxelSize;
  }
  auto points = requireGrid<Vec3SGrid>(path, f, kLayerPoint);
  checked(points);
  for (auto it = points->cbeginValueOn(); it; ++it) {
    g.points[voxelOf(it.getCoord(), kLayerPoint)] = fromVdb(*it);
  }
  struct Entry {
    uint32_t voxel;
    int layer;
    openvdb::Coord coord;
  };
  std::vector<Entry> entries;
  std::vector<char> hasLayer1(n, 0);
  for (int layer = 1; layer < kMaxLayers; ++layer) {
    const std::string countName = layerName(layer, kVdlCount);
    if (!findGrid(f, countName)) {
      if (layer == 1) requireGrid<FloatGrid>(path, f, countName);  // names it as missing
      break;
    }
    auto count = requireGrid<FloatGrid>(path, f, countName);
    checked(count);
    for (auto it = count->cbeginValueOn(); it; ++it) {
      const uint32_t v = voxelOf(it.getCoord(), countName);
      if (layer == 1) hasLayer1[v] = 1;
      if (layer == 2 && !hasLayer1[v]) {
        throw InputError(path + ": voxel " + g.coords[v].ToString() +
                         " has surface layer 2 but not layer 1");
      }
      entries.push_back({v, layer, it.getCoord()});
    }
  }
  std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) {
    return a.voxel < b.voxel || (a.voxel == b.voxel && a.layer < b.layer);
  });
  for (size_t v = 0; v < n; ++v) {
    if (!hasLayer1[v]) continue;
    if (!points->tree().isValueOn(toVdb(g.coords[v]))) {
      throw InputError(path + ": grid 'layer_point' has no value at " + g.coords[v].ToString() +
                       ", a voxel with surface layers");
    }
  }
  VdlLayers& L = g.layers;
  const size_t ne = entries.size();
  L.voxel.resize(ne);
  L.normals.resize(ne);
  L.points.resize(ne);
  L.irradiance.resize(ne);
  L.photonCount.resize(ne);
  L.radius.resize(ne);
  L.angularError.resize(ne);
  L.vdlCount.resize(ne);
  L.vdls.resize(ne * size_t(maxVdls));
  L.sh.resize(ne * size_t(g.shTerms));
  for (int layer = 1; layer < kMaxLayers; ++layer) {
    if (!findGrid(f, layerName(layer, kVdlCount))) break;
    auto vec = [&](const std::string& name) {
      auto grid = requireGrid<Vec3SGrid>(path, f, layerName(layer, name));
      checked(grid);
      return grid;
    };
    auto flt = [&](const std::string& name) {
      auto grid = requireGrid<FloatGrid>(path, f, layerName(layer, name));
      checked(grid);
      return grid;
    };
    auto irr = vec(kIrradiance)->getConstAccessor();
    auto nrm = vec(kNormal)->getConstAccessor();
    auto pts = vec("point")->getConstAccessor();
    auto pc = flt(kPhotonCount)->getConstAccessor();
    auto ae = flt(kAngularError)->getConstAccessor();
    auto vc = flt(kVdlCount)->getConstAccessor();
    auto rad = flt(kRadius)->getConstAccessor();
    std::vector<openvdb::Vec3SGrid::ConstAccessor> vi, vd;
    for (int i = 0; i < maxVdls; ++i) {
      vi.push_back(vec(vdlIrradianceName(i))->getConstAccessor());
      vd.push_back(vec(vdlDirectionName(i))->getConstAccessor());
    }
    std::vector<openvdb::Vec3SGrid::ConstAccessor> sh;
    for (int i = 0; i < g.shTerms; ++i) sh.push_back(vec(shName(i))->getConstAccessor());
    for (size_t e = 0; e < ne; ++e) {
      if (entries[e].layer != layer) continue;
      const openvdb::Coord c = entries[e].coord;
      L.voxel[e] = entries[e].voxel;
      L.irradiance[e] = fromVdb(irr.getValue(c));
      L.normals[e] = fromVdb(nrm.getValue(c));
      L.points[e] = fromVdb(pts.getValue(c));
      L.photonCount[e] = pc.getValue(c);
      L.angularError[e] = ae.getValue(c);
      L.radius[e] = rad.getValue(c);
      const float count = vc.getValue(c);
      if (!(count >= 0 && count <= float(maxVdls)) || count != std::floor(count)) {
        throw InputError(path + ": " + layerName(layer, kVdlCount) + " at " +
                         g.coords[entries[e].voxel].ToString() + " is " + std::to_string(count) +
                         ", expected an integer in [0, " + std::to_string(maxVdls) + "]");
      }
      L.vdlCount[e] = uint8_t(count);
      for (int i = 0; i < maxVdls; ++i) {
        Vdl& vdl = L.vdls[e * size_t(maxVdls) + size_t(i)];
        vdl.irradiance = fromVdb(vi[size_t(i)].getValue(c));
        vdl.direction = fromVdb(vd[size_t(i)].getValue(c));
      }
      for (int i = 0; i < g.shTerms; ++i) {
        L.sh[e * size_t(g.shTerms) + size_t(i)] = fromVdb(sh[size_t(i)].getValue(c));
      }
    }
  }
}

LoadedVdl readVdl(const std::string& path) {
  OpenedFile f = openFile(path);
  LoadedVdl out;
  out.meta = readMetadata(path, *f.meta);
  if (out.meta.formatVersion == 0) {
    // Files baked before the key existed follow version 1 of the contract.
    out.meta.formatVersion = 1;
    out.notes.push_back("no format_version metadata: read as format version 1");
  } else if (out.meta.formatVersion > kVdlFormatVersion || out.meta.formatVersion < 1) {
    throw InputError(
        path + ": format_version " + std::to_string(out.meta.formatVersion) +
        " is not supported: this lightoctree (" LO_VERSION
        ") reads VDL files up to "
        "format version " +
        std::to_string(kVdlFormatVersion) +
        (out.meta.formatVersion > kVdlFormatVersion ? "; use a newer lightoctree" : ""));
  }
  const int maxVdls = metaValue<int32_t>(path, *f.meta, "max_vdls", true, 0);
  if (maxVdls < 1 || maxVdls > kMaxVdls) {
    throw InputError(path + ": file metadata max_vdls = " + std::to_string(maxVdls) +
                     " is outside [1, " + std::to_string(kMaxVdls) + "]");
  }

  // Every grid of the contract, typed, before anything is interpreted.
  auto irradiance = requireGrid<Vec3SGrid>(path, f, kIrradiance);
  auto normal = requireGrid<Vec3SGrid>(path, f, kNormal);
  auto vdlCount = requireGrid<FloatGrid>(path, f, kVdlCount);
  // Optional grids: absent ones read as 0 (a file converted with --drop).
  auto optionalGrid = [&](const char* name) -> FloatGrid::Ptr {
    if (!findGrid(f, name)) {
      out.absentGrids.push_back(name);
      return nullptr;
    }
    return requireGrid<FloatGrid>(path, f, name);
  };
  auto photonCount = optionalGrid(kPhotonCount);
  auto angularError = optionalGrid(kAngularError);
  auto radius = optionalGrid(kRadius);
  auto area = optionalGrid(kArea);
  out.halfFloat = irradiance->saveFloatAsHalf();
  std::vector<Vec3SGrid::Ptr> vdlIrr, vdlDir;
  for (int i = 0; i < maxVdls; ++i) {
    vdlIrr.push_back(requireGrid<Vec3SGrid>(path, f, vdlIrradianceName(i)));
    vdlDir.push_back(requireGrid<Vec3SGrid>(path, f, vdlDirectionName(i)));
  }
  // The representation: VDLs, or SH terms (format version 3).
  const std::string& representation = out.meta.representation;
  const int shTerms = representation == "sh1" ? 4 : representation == "sh2" ? 9 : 0;
  if (shTerms == 0 && representation != "vdl") {
    throw InputError(path + ": file metadata representation = '" + representation +
                     "'; expected vdl, sh1 or sh2");
  }
  if (shTerms > 0 && out.meta.formatVersion < 3) {
    throw InputError(path + ": representation " + representation + " in a format version " +
                     std::to_string(out.meta.formatVersion) +
                     " file (SH grids came with version 3): the file is inconsistent");
  }
  std::vector<Vec3SGrid::Ptr> shGrids;
  for (int i = 0; i < shTerms; ++i) shGrids.push_back(requireGrid<Vec3SGrid>(path, f, shName(i)));
  std::vector<openvdb::GridBase::Ptr> all = {irradiance, normal, vdlCount};
  for (const Vec3SGrid::Ptr& sg : shGrids) all.push_back(sg);
  for (const FloatGrid::Ptr& g : {photonCount, angularError, radius, area}) {
    if (g) all.push_back(g);
  }

  const Transform& xform = vdlCount->transform();
  const openvdb::Index64 active = vdlCount->activeVoxelCount();
  for (const auto& g : all) {
    if (!(g->transform() == xform)) {
      throw InputError(path + ": mismatched transforms: grid '" + g->getName() +
                       "' differs from 'vdl_count'");
    }
    if (g->activeVoxelCount() != active) {
      throw InputError(path + ": grid '" + g->getName() + "' has " +
                       std::to_string(g->activeVoxelCount()) + " active voxels, 'vdl_count' has " +
                       std::to_string(active));
    }
  }
  // VDL grids: active where the voxel has that VDL (sparse), or on every voxel
  // (files before version 2 store zeros); never beyond the voxels.
  for (const auto& vg : {vdlIrr, vdlDir}) {
    for (const auto& g : vg) {
      if (!(g->transform() == xform)) {
        throw InputError(path + ": mismatched transforms: grid '" + g->getName() +
                         "' differs from 'vdl_count'");
      }
      for (auto it = g->cbeginValueOn(); it; ++it) {
        if (!vdlCount->tree().isValueOn(it.getCoord())) {
          throw InputError(path + ": grid '" + g->getName() + "' is active at " +
                           Coord{it.getCoord().x(), it.getCoord().y(), it.getCoord().z()}.ToString() +
                           ", which is not a voxel of the file");
        }
      }
    }
  }

  VdlGrid& g = out.grid;
  g.frame = readFrame(path, xform, out.meta.depth);
  g.maxVdls = maxVdls;
  g.shTerms = shTerms;
  g.coords.reserve(size_t(active));
  for (auto it = vdlCount->cbeginValueOn(); it; ++it) {
    const openvdb::Coord c = it.getCoord();
    g.coords.push_back({c.x(), c.y(), c.z()});
  }
  std::sort(g.coords.begin(), g.coords.end(), canonicalLess);

  const size_t n = g.coords.size();
  g.normals.resize(n);
  g.areas.resize(n);
  g.irradiance.resize(n);
  g.photonCount.resize(n);
  g.radius.resize(n);
  g.angularError.resize(n);
  g.vdlCount.resize(n);
  g.vdls.resize(n * size_t(maxVdls));

  auto irrAcc = irradiance->getConstAccessor();
  auto nAcc = normal->getConstAccessor();
  auto vcAcc = vdlCount->getConstAccessor();
  auto readOptional = [&](const FloatGrid::Ptr& grid, std::vector<float>& dst) {
    if (!grid) return;
    auto acc = grid->getConstAccessor();
    for (size_t v = 0; v < n; ++v) dst[v] = acc.getValue(toVdb(g.coords[v]));
  };
  readOptional(photonCount, g.photonCount);
  readOptional(angularError, g.angularError);
  readOptional(radius, g.radius);
  readOptional(area, g.areas);
  for (size_t v = 0; v < n; ++v) {
    const openvdb::Coord c = toVdb(g.coords[v]);
    g.irradiance[v] = fromVdb(irrAcc.getValue(c));
    g.normals[v] = fromVdb(nAcc.getValue(c));
    const float count = vcAcc.getValue(c);
    if (!(count >= 0 && count <= float(maxVdls)) || count != std::floor(count)) {
      throw InputError(path + ": vdl_count at " + g.coords[v].ToString() + " is " +
                       std::to_string(count) + ", expected an integer in [0, " +
                       std::to_string(maxVdls) + "]");
    }
    g.vdlCount[v] = uint8_t(count);
  }
  for (int i = 0; i < maxVdls; ++i) {
    auto ia = vdlIrr[size_t(i)]->getConstAccessor();
    auto da = vdlDir[size_t(i)]->getConstAccessor();
    for (size_t v = 0; v < n; ++v) {
      const openvdb::Coord c = toVdb(g.coords[v]);
      Vdl& vdl = g.vdls[v * size_t(maxVdls) + size_t(i)];
      vdl.irradiance = fromVdb(ia.getValue(c));
      vdl.direction = fromVdb(da.getValue(c));
    }
  }
  g.sh.resize(n * size_t(shTerms));
  for (int i = 0; i < shTerms; ++i) {
    auto sa = shGrids[size_t(i)]->getConstAccessor();
    for (size_t v = 0; v < n; ++v) g.sh[v * size_t(shTerms) + size_t(i)] = fromVdb(sa.getValue(toVdb(g.coords[v])));
  }
  if (shTerms > 0) {
    for (size_t v = 0; v < n; ++v) {
      if (g.vdlCount[v] != 0) {
        throw InputError(path + ": voxel " + g.coords[v].ToString() + " of an " + representation +
                         " file has " + std::to_string(g.vdlCount[v]) +
                         " VDLs; SH files hold none");
      }
    }
  }
  readLayers(path, f, xform, maxVdls, out);
  checkValues(path, out.grid);
  return out;
}

// ---------------------------------------------------------------------------
// Photon points.

void writePoints(const std::string& path, const std::vector<Photon>& photons, float voxelSize) {
  if (!(voxelSize > 0) || !std::isfinite(voxelSize)) {
    throw InputError(path + ": photon point voxel size must be positive, got " +
                     std::to_string(voxelSize));
  }
  initOpenVdb();
  namespace pts = openvdb::points;
  const size_t n = photons.size();
  std::vector<openvdb::Vec3R> positions(n);
  std::vector<openvdb::Vec3s> power(n), direction(n), normal(n);
  std::vector<int32_t> bounce(n);
  for (size_t i = 0; i < n; ++i) {
    const Photon& p = photons[i];
    positions[i] = openvdb::Vec3R(p.position.x, p.position.y, p.position.z);
    power[i] = toVdb(p.power);
    direction[i] = toVdb(p.direction);
    normal[i] = toVdb(p.normal);
    bounce[i] = int32_t(p.bounce);
  }
  // Points are world space; the grid only buckets them (no translation).
  Transform::Ptr xform = Transform::createLinearTransform(double(voxelSize));
  pts::PointAttributeVector<openvdb::Vec3R> positionWrapper(positions);
  auto indexGrid =
      openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positionWrapper, *xform);
  // NullCodec: full float positions (relative to the voxel centre), no quantisation.
  pts::PointDataGrid::Ptr grid = pts::createPointDataGrid<pts::NullCodec, pts::PointDataGrid>(
      *indexGrid, positionWrapper, *xform);
  auto addVec3 = [&](const char* name, const std::vector<openvdb::Vec3s>& values) {
    pts::appendAttribute<openvdb::Vec3s>(grid->tree(), name);
    pts::PointAttributeVector<openvdb::Vec3s> wrapper(values);
    pts::populateAttribute(grid->tree(), indexGrid->tree(), name, wrapper);
  };
  addVec3("Cd", power);
  addVec3("direction", direction);
  addVec3("N", normal);
  pts::appendAttribute<int32_t>(grid->tree(), "bounce");
  pts::PointAttributeVector<int32_t> bounceWrapper(bounce);
  pts::populateAttribute(grid->tree(), indexGrid->tree(), "bounce", bounceWrapper);

  grid->setName("photons");
  grid->insertMeta("units",
                   openvdb::StringMetadata("P: world units; Cd: photon power, W (RGB); "
                                           "direction: unit, towards where the photon came from; "
                                           "N: unit surface normal"));
  openvdb::MetaMap meta;
  meta.insertMeta("generator", openvdb::StringMetadata("lightoctree"));
  meta.insertMeta("version", openvdb::StringMetadata(LO_VERSION));
  meta.insertMeta("photons", openvdb::Int64Metadata(int64_t(n)));
  writeVdbFile(path, {{"photons", [&grid] { return openvdb::GridBase::Ptr(grid); }}}, meta);
}

std::vector<Photon> readPoints(const std::string& path) {
  namespace pts = openvdb::points;
  OpenedFile f = openFile(path);
  if (!findGrid(f, "photons") && findGrid(f, kIrradiance)) {
    throw InputError(path + ": is a VDL file (written by `lightoctree bake -o`), not a photon "
                     "file (`bake --photon-map`)");
  }
  auto grid = requireGrid<pts::PointDataGrid>(path, f, "photons");
  std::vector<Photon> out;
  out.reserve(size_t(pts::pointCount(grid->tree())));
  auto leaf = grid->tree().cbeginLeaf();
  if (!leaf) return out;
  const auto& descriptor = leaf->attributeSet().descriptor();
  auto attribute = [&](const char* name) {
    const size_t index = descriptor.find(name);
    if (index == pts::AttributeSet::INVALID_POS) {
      throw InputError(path + ": photon grid has no attribute '" + name + "'");
    }
    return index;
  };
  const size_t pIndex = attribute("P"), cdIndex = attribute("Cd");
  const size_t dIndex = attribute("direction"), nIndex = attribute("N");
  const size_t bIndex = attribute("bounce");
  const Transform& xform = grid->transform();
  try {
    for (; leaf; ++leaf) {
      pts::AttributeHandle<openvdb::Vec3f> pHandle(leaf->constAttributeArray(pIndex));
      pts::AttributeHandle<openvdb::Vec3s> cdHandle(leaf->constAttributeArray(cdIndex));
      pts::AttributeHandle<openvdb::Vec3s> dHandle(leaf->constAttributeArray(dIndex));
      pts::AttributeHandle<openvdb::Vec3s> nHandle(leaf->constAttributeArray(nIndex));
      pts::AttributeHandle<int32_t> bHandle(leaf->constAttributeArray(bIndex));
      for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
        const openvdb::Vec3d world =
            xform.indexToWorld(pHandle.get(*idx) + idx.getCoord().asVec3d());
        Photon p;
        p.position = Vec3(float(world.x()), float(world.y()), float(world.z()));
        p.power = fromVdb(cdHandle.get(*idx));
        p.direction = fromVdb(dHandle.get(*idx));
        p.normal = fromVdb(nHandle.get(*idx));
        p.bounce = uint32_t(std::max(0, bHandle.get(*idx)));
        out.push_back(p);
      }
    }
  } catch (const openvdb::Exception& e) {
    throw InputError(path + ": cannot read the photon attributes: " + e.what());
  }
  return out;
}

}  // namespace

PointFileInfo inspectPointFile(const std::string& path) {
  namespace pts = openvdb::points;
  OpenedFile f = openFile(path);
  PointFileInfo info;
  for (const auto& g : *f.grids) info.gridNames.push_back(g->getName());
  auto grid = requireGrid<pts::PointDataGrid>(path, f, "photons");
  info.pointCount = pts::pointCount(grid->tree());
  auto leaf = grid->tree().cbeginLeaf();
  if (!leaf) return info;
  const auto& descriptor = leaf->attributeSet().descriptor();
  info.attributes.resize(descriptor.size());
  for (const auto& [name, index] : descriptor.map()) info.attributes[index] = name;
  const size_t cdIndex = descriptor.find("Cd"), bIndex = descriptor.find("bounce");
  const size_t pIndex = descriptor.find("P");
  double cd[3] = {0, 0, 0};
  for (; leaf; ++leaf) {
    pts::AttributeHandle<openvdb::Vec3s> cdHandle(leaf->constAttributeArray(cdIndex));
    pts::AttributeHandle<int32_t> bHandle(leaf->constAttributeArray(bIndex));
    pts::AttributeHandle<openvdb::Vec3f> pHandle(leaf->constAttributeArray(pIndex));
    for (auto idx = leaf->beginIndexOn(); idx; ++idx) {
      const openvdb::Vec3s c = cdHandle.get(*idx);
      for (int k = 0; k < 3; ++k) cd[k] += c[k];
      info.totalBounce += bHandle.get(*idx);
      const openvdb::Vec3d world =
          grid->transform().indexToWorld(pHandle.get(*idx) + idx.getCoord().asVec3d());
      info.positionBounds.extend(Vec3(float(world.x()), float(world.y()), float(world.z())));
    }
  }
  info.totalCd = Vec3(float(cd[0]), float(cd[1]), float(cd[2]));
  return info;
}

LoadedVdl readVdlStructure(const std::string& path) { return readVdl(path); }

}  // namespace vdb_internal

const std::vector<std::string>& optionalVdlGridNames() {
  static const std::vector<std::string> names = {vdb_internal::kPhotonCount,
                                                 vdb_internal::kAngularError, vdb_internal::kRadius,
                                                 vdb_internal::kArea};
  return names;
}

void writeVdlGrid(const std::string& path, const VdlGrid& grid, const BakeMetadata& meta,
                  const VdlWriteOptions& options) {
  vdb_internal::writeVdl(path, grid, meta, options, nullptr);
}

std::vector<Photon> readPhotonPoints(const std::string& path) {
  return vdb_internal::readPoints(path);
}

LoadedVdl readVdlGrid(const std::string& path) {
  LoadedVdl loaded = vdb_internal::readVdl(path);
  for (const VdbCheck& c : checkLightGridValues(loaded.grid, loaded.halfFloat)) {
    if (!c.passed) {
      throw InputError(path + ": check " + c.name + " fails: " + c.detail +
                       " (`lightoctree inspect` lists every check)");
    }
  }
  return loaded;
}

std::vector<VdbCheck> checkLightGridValues(const VdlGrid& g, bool halfFloat) {
  const double sumTol = halfFloat ? kVdlSumToleranceHalf : kVdlSumTolerance;
  const bool sh = g.shTerms > 0;
  auto num = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.4g", v);
    return std::string(text);
  };
  uint64_t badCount = 0, negative = 0, outOfRange = 0, notUnit = 0, badSum = 0;
  std::string firstCount, firstNegative, firstRange, firstNotUnit, firstSum;
  double worstUnit = 0, worstSum = 0;
  auto negativeIn = [](const Vec3& v) { return v.x < 0 || v.y < 0 || v.z < 0; };
  auto beyond = [](const Vec3& v) {
    return std::fabs(v.x) > kMaxStoredIrradiance || std::fabs(v.y) > kMaxStoredIrradiance ||
           std::fabs(v.z) > kMaxStoredIrradiance;
  };
  // One voxel's (or layer's) light: its checks, given where it is named.
  auto check = [&](const std::string& where, const Vec3& e, const Vec3& normal, int count,
                   const Vdl* vdls, const Vec3* terms, uint64_t& sums, std::string& firstSumText) {
    if (count < 0 || count > g.maxVdls) {
      if (badCount++ == 0) firstCount = where + " holds " + std::to_string(count);
      return;
    }
    bool neg = negativeIn(e), big = beyond(e);
    double sum[3] = {0, 0, 0};
    double scale = std::max({double(e.x), double(e.y), double(e.z)});
    for (int i = 0; i < count; ++i) {
      const Vdl& v = vdls[i];
      neg = neg || negativeIn(v.irradiance);
      big = big || beyond(v.irradiance);
      for (int k = 0; k < 3; ++k) {
        sum[k] += double(v.irradiance[k]);
        scale = std::max(scale, double(std::fabs(v.irradiance[k])));
      }
      const double dev = std::fabs(double(length(v.direction)) - 1.0);
      worstUnit = std::max(worstUnit, std::isfinite(dev) ? dev : 1e30);
      if (!(dev < kUnitDirectionTolerance) && notUnit++ == 0) {
        firstNotUnit = where + " VDL " + std::to_string(i) + " has a direction of length " +
                       num(double(length(v.direction)));
      }
    }
    if (sh) {
      const Vec3 n = normal;
      for (int k = 0; k < 3; ++k) sum[k] = 0;
      for (int i = 0; i < g.shTerms; ++i) {
        big = big || beyond(terms[i]);
        const double y = double(layout::loShBasis(uint32_t(i), n.x, n.y, n.z));
        for (int k = 0; k < 3; ++k) {
          sum[k] += double(terms[i][k]) * y;
          scale = std::max(scale, double(std::fabs(terms[i][k])));
        }
      }
    }
    if (neg && negative++ == 0) firstNegative = where;
    if (big && outOfRange++ == 0) firstRange = where;
    double diff = 0;
    for (int k = 0; k < 3; ++k) diff = std::max(diff, std::fabs(sum[k] - double(e[k])));
    const double rel = scale > 0 ? diff / scale : (diff > 0 ? 1e30 : 0.0);
    worstSum = std::max(worstSum, std::isfinite(rel) ? rel : 1e30);
    if (!(rel <= sumTol) && sums++ == 0) {
      firstSumText = where + (sh ? ": SH at the normal" : ": sum of VDLs") + " differs by " +
                     num(rel) + " of the irradiance";
    }
  };
  for (size_t v = 0; v < g.size(); ++v) {
    check("voxel " + g.coords[v].ToString(), g.irradiance[v], g.normals[v], g.vdlCount[v],
          g.vdlsOf(v), sh ? g.shOf(v) : nullptr, badSum, firstSum);
  }
  const std::string of = " of " + std::to_string(g.size()) + " voxels";
  std::vector<VdbCheck> checks;
  checks.push_back({"vdl_count", badCount == 0,
                    badCount ? std::to_string(badCount) + of + " hold more than " +
                                   std::to_string(g.maxVdls) + " VDLs; first " + firstCount
                             : "integers in [0, " + std::to_string(g.maxVdls) + "]"});
  checks.push_back({"irradiance_non_negative", negative == 0,
                    negative ? std::to_string(negative) + " voxels or layers with a negative "
                                   "channel; first " + firstNegative
                             : std::string(sh ? "irradiance >= 0" : "irradiance and VDL irradiance >= 0")});
  checks.push_back({"irradiance_range", outOfRange == 0,
                    outOfRange ? std::to_string(outOfRange) + " voxels or layers beyond " +
                                     num(kMaxStoredIrradiance) + " W/m^2; first " + firstRange
                               : "every value within " + num(kMaxStoredIrradiance) + " W/m^2"});
  checks.push_back({"unit_directions", notUnit == 0,
                    (notUnit ? std::to_string(notUnit) + " used VDL slots not unit; first " +
                                   firstNotUnit
                             : std::string("used VDL slots unit")) +
                        " (largest |length - 1| " + num(worstUnit) + ", allowed " +
                        num(kUnitDirectionTolerance) + ")"});
  checks.push_back({sh ? "sh_sum" : "vdl_sum", badSum == 0,
                    (badSum ? std::to_string(badSum) + of + " off; first " + firstSum
                            : std::string(sh ? "SH irradiance at each voxel's normal is its "
                                               "irradiance"
                                             : "VDLs sum to the irradiance")) +
                        " (largest relative difference " + num(worstSum) + ", allowed " +
                        num(sumTol) + (halfFloat ? ", half floats)" : ")")});
  if (g.layers.size() > 0) {
    uint64_t layerSums = 0;
    std::string firstLayerSum;
    const double voxelWorst = worstSum;
    worstSum = 0;
    for (size_t e = 0; e < g.layers.size(); ++e) {
      check("layer of voxel " + g.coords[g.layers.voxel[e]].ToString(), g.layers.irradiance[e],
            g.layers.normals[e], g.layers.vdlCount[e], g.layerVdlsOf(e),
            sh ? g.layerShOf(e) : nullptr, layerSums, firstLayerSum);
    }
    checks.push_back({"layers", layerSums == 0,
                      layerSums ? std::to_string(layerSums) + " of " +
                                      std::to_string(g.layers.size()) + " layers off; first " +
                                      firstLayerSum
                                : std::to_string(g.layers.size()) +
                                      " extra surface layers; their light sums to their "
                                      "irradiance (largest relative difference " +
                                      num(worstSum) + ")"});
    worstSum = voxelWorst;
  }
  return checks;
}

void writePhotonPoints(const std::string& path, const std::vector<Photon>& photons,
                       float voxelSize) {
  vdb_internal::writePoints(path, photons, voxelSize);
}

}  // namespace lo
