// `lightoctree inspect`: a generic report of an OpenVDB file and the checks of
// the VDL contract. Own translation unit so that it and the reader and writer
// compile in parallel; they include OpenVDB, nothing outside src/vdb does.

#include "vdb/vdb_inspect.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "lightgrid/vdl_grid.h"
#include "core/error.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_file.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace vdb_inspect_internal {
namespace {

namespace fs = std::filesystem;
using openvdb::FloatGrid;
using openvdb::Vec3SGrid;

std::string metaText(const openvdb::Metadata& m) {
  std::string s = m.str();
  if (s.size() > 200) s = s.substr(0, 200) + "...";
  return s;
}

std::vector<std::pair<std::string, std::string>> metaList(const openvdb::MetaMap& meta) {
  std::vector<std::pair<std::string, std::string>> out;
  for (auto it = meta.beginMeta(); it != meta.endMeta(); ++it) {
    if (it->second) out.emplace_back(it->first, metaText(*it->second));
  }
  return out;
}

template <typename T>
bool finiteValue(const T& v) {
  if constexpr (std::is_same_v<T, float>) {
    return std::isfinite(v);
  } else {
    return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
  }
}

template <typename GridT>
void summarizeValues(const GridT& grid, GridSummary& s) {
  using V = typename GridT::ValueType;
  constexpr int kComponents = std::is_same_v<V, float> ? 1 : 3;
  std::vector<double> lo(kComponents, std::numeric_limits<double>::infinity());
  std::vector<double> hi(kComponents, -std::numeric_limits<double>::infinity());
  bool any = false;
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    const V v = *it;
    if (!finiteValue(v)) {
      ++s.nonFinite;
      continue;
    }
    any = true;
    for (int c = 0; c < kComponents; ++c) {
      double x;
      if constexpr (std::is_same_v<V, float>) {
        x = v;
      } else {
        x = v[c];
      }
      lo[size_t(c)] = std::min(lo[size_t(c)], x);
      hi[size_t(c)] = std::max(hi[size_t(c)], x);
    }
  }
  if (any) {
    s.min = lo;
    s.max = hi;
  }
}

GridSummary summarize(const openvdb::GridBase& g) {
  GridSummary s;
  s.name = g.getName();
  s.type = g.type();
  s.valueType = g.valueType();
  s.activeVoxels = g.activeVoxelCount();
  s.memoryBytes = g.memUsage();
  s.halfFloat = g.saveFloatAsHalf();
  const openvdb::Vec3d vs = g.voxelSize();
  s.voxelSize = {vs.x(), vs.y(), vs.z()};
  const openvdb::Vec3d o = g.transform().indexToWorld(openvdb::Vec3d(0.0));
  s.origin = {o.x(), o.y(), o.z()};
  s.metadata = metaList(g);
  if (const auto* f = dynamic_cast<const FloatGrid*>(&g)) summarizeValues(*f, s);
  if (const auto* v = dynamic_cast<const Vec3SGrid*>(&g)) summarizeValues(*v, s);
  return s;
}

using vdb_internal::OpenedFile;

OpenedFile openAll(const std::string& path) {
  OpenedFile f = vdb_internal::openFile(path);
  // OpenVDB reads a file cut inside its header as an empty file; no file we
  // write is empty (even an empty bake has its grids), so say what it is.
  if (f.grids->empty() && f.meta->metaCount() == 0) {
    throw InputError(path + ": holds no grids and no metadata (truncated?)");
  }
  return f;
}

std::string coordText(const openvdb::Coord& c) {
  return "(" + std::to_string(c.x()) + ", " + std::to_string(c.y()) + ", " + std::to_string(c.z()) +
         ")";
}


/// The VDL contract checks; `add` records one result.
class VdlChecker {
 public:
  VdlChecker(const OpenedFile& f, VdbReport& r) : f_(f), r_(r) {}

  void run() {
    const int maxVdls = readMaxVdls();
    const bool contract = checkContract(maxVdls);
    checkFormatVersion();
    checkFinite();
    checkSameTransform();
    checkSameActive();
    checkDepthAndBounds();
    if (!contract) return;  // the value checks need every required grid
    checkValues();
  }

 private:
  void add(const std::string& name, bool passed, const std::string& detail) {
    r_.checks.push_back({name, passed, detail});
  }

  openvdb::GridBase::Ptr find(const std::string& name) const {
    for (const auto& g : *f_.grids) {
      if (g && g->getName() == name) return g;
    }
    return nullptr;
  }

  /// SH terms per voxel from the metadata `representation`: 0 for VDLs (and
  /// files without the key), shTermsOf the representation it names, -1 for
  /// anything else.
  int readShTerms() const {
    const openvdb::Metadata::ConstPtr m = (*f_.meta)[vdb_internal::kMetaRepresentation];
    auto typed = openvdb::DynamicPtrCast<const openvdb::StringMetadata>(m);
    if (!typed) return m ? -1 : 0;
    LightRepresentation r = LightRepresentation::Vdl;
    return parseRepresentation(typed->value(), &r) ? shTermsOf(r) : -1;
  }

  /// An integer of the file metadata as the readers take it (metaInt: of
  /// either width, pyopenvdb writes Python ints as int64); -1 when missing
  /// or not such an integer.
  int readInt(const char* key) const {
    try {
      return vdb_internal::metaInt("", *f_.meta, key, false, -1);
    } catch (const InputError&) {
      return -1;
    }
  }

  int readMaxVdls() const { return readInt(vdb_internal::kMetaMaxVdls); }

  bool checkContract(int maxVdls) {
    std::string problems;
    auto need = [&](const std::string& name, const char* valueType, bool required) {
      auto g = find(name);
      if (!g) {
        if (required) problems += (problems.empty() ? "" : "; ") + ("missing grid '" + name + "'");
        return;
      }
      if (g->valueType() != valueType) {
        problems += (problems.empty() ? "" : "; ") +
                    ("grid '" + name + "' has type " + g->valueType() + ", expected " + valueType);
      }
    };
    const bool maxVdlsValid = maxVdls >= 1 && maxVdls <= kMaxVdls;
    if (!maxVdlsValid) {
      problems = "file metadata max_vdls is " +
                 (maxVdls < 0 ? std::string("missing or not an integer") : std::to_string(maxVdls)) +
                 ", expected 1.." + std::to_string(kMaxVdls);
    }
    const int shTerms = readShTerms();
    if (shTerms < 0) {
      problems += std::string(problems.empty() ? "" : "; ") +
                  "file metadata representation is not " + representationChoices();
    }
    // The voxels' required grids of the field table.
    // The optional ones, where present, with their types too.
    std::string absent;
    forEachField([&](const auto& row) {
      using T = typename std::decay_t<decltype(row)>::Value;
      if (row.arity == FieldArity::OneOrNone) return;
      const char* type = std::is_same_v<T, Vec3> || std::is_same_v<T, Vdl> ? "vec3s" : "float";
      if (row.optional) {
        need(row.gridName, type, false);
        if (!find(row.gridName)) absent += (absent.empty() ? "" : ", ") + std::string(row.gridName);
        return;
      }
      for (const vdb_internal::FieldGrid& grid :
           vdb_internal::fieldGrids(row, 0, maxVdlsValid ? maxVdls : 0, std::max(shTerms, 0))) {
        need(grid.name, type, true);
      }
    });
    add("contract", problems.empty(),
        problems.empty()
            ? "all required grids present with their types" +
                  (absent.empty() ? std::string() : "; optional grids absent: " + absent)
            : problems);
    return problems.empty();
  }

  /// The reader's rule (formatVersionOf): inspect passes what render reads.
  void checkFormatVersion() {
    const vdb_internal::FormatVersion v = vdb_internal::formatVersionOf(*f_.meta);
    if (!v.problem.empty()) {
      add("format_version", false, v.problem);
    } else if (v.absent) {
      add("format_version", true, "absent: a file written before format_version 1 (read as 1)");
    } else {
      add("format_version", true,
          std::to_string(v.version) + " (this lightoctree reads 1.." +
              std::to_string(kVdlFormatVersion) + ")");
    }
  }

  void checkFinite() {
    uint64_t bad = 0;
    std::string first;
    for (const GridSummary& s : r_.grids) {
      if (s.nonFinite && first.empty()) first = s.name;
      bad += s.nonFinite;
    }
    add("finite", bad == 0,
        bad == 0 ? "no NaN or Inf"
                 : std::to_string(bad) + " active values with NaN/Inf (first in '" + first + "')");
  }

  static bool isVolumeGrid(const std::string& name) { return vdb_internal::isFreeSpaceGrid(name); }

  void checkSameTransform() {
    const vdb_internal::GridsCheck c = vdb_internal::sameTransform(f_);
    add("same_transform", c.passed, c.detail);
  }

  /// What the reader (readVdlGrid) and the GPU octree refuse, checked the
  /// same way here so that inspect never passes a file render refuses: the
  /// depth metadata within [1, kMaxGridDepth], a transform of uniform scale
  /// and translation only, and every voxel within [0, 2^depth) on each axis.
  void checkDepthAndBounds() {
    auto m = (*f_.meta)[vdb_internal::kMetaDepth];
    int depth = -1;
    if (auto i32 = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(m)) depth = i32->value();
    if (auto i64 = openvdb::DynamicPtrCast<const openvdb::Int64Metadata>(m)) {
      depth = i64->value() >= 0 && i64->value() <= 64 ? int(i64->value()) : -1;
    }
    const bool depthOk = depth >= 1 && depth <= kMaxGridDepth;
    add("depth", depthOk,
        depthOk ? std::to_string(depth) + " (2^" + std::to_string(depth) + " voxels per axis)"
                : (m ? "depth " + m->str() + " in the file's metadata"
                     : std::string("no depth in the file's metadata")) +
                      ": a light grid's depth is 1 to " + std::to_string(kMaxGridDepth));
    std::string transform;
    for (const auto& g : *f_.grids) {
      if (!g || !transform.empty()) continue;
      const auto map = g->transform().baseMap();
      const bool axisAligned = map->isType<openvdb::math::UniformScaleTranslateMap>() ||
                               map->isType<openvdb::math::UniformScaleMap>();
      if (!g->transform().isLinear() || !axisAligned) {
        transform = "grid '" + g->getName() + "' has a " + g->transform().mapType() +
                    " transform, expected a uniform scale and translation";
      }
    }
    add("transform", transform.empty(),
        transform.empty() ? "uniform scale and translation" : transform);
    if (!depthOk) return;
    // The free-space grids lie on their own, coarser grid (free_space_depth).
    int freeDepth = depth;
    if (auto i32 = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(
            (*f_.meta)[vdb_internal::kMetaFreeSpaceDepth])) {
      freeDepth = std::clamp(int(i32->value()), 0, depth);
    }
    std::string outside;
    uint64_t count = 0;
    for (const auto& g : *f_.grids) {
      if (!g || g->isType<openvdb::points::PointDataGrid>()) continue;
      const int res = 1 << (isVolumeGrid(g->getName()) ? freeDepth : depth);
      const openvdb::CoordBBox box = g->evalActiveVoxelBoundingBox();
      if (g->activeVoxelCount() == 0) continue;
      const openvdb::Coord lo = box.min(), hi = box.max();
      if (lo.x() < 0 || lo.y() < 0 || lo.z() < 0 || hi.x() >= res || hi.y() >= res ||
          hi.z() >= res) {
        ++count;
        if (outside.empty()) {
          outside = "grid '" + g->getName() + "' has voxels from " + coordText(lo) + " to " +
                    coordText(hi) + ", outside [0, " + std::to_string(res) + ")";
        }
      }
    }
    add("voxel_bounds", count == 0,
        count == 0 ? "every voxel within [0, " + std::to_string(1 << depth) + ") of depth " +
                         std::to_string(depth)
                   : std::to_string(count) + " grid(s) beyond it; first " + outside);
  }

  void checkSameActive() {
    const vdb_internal::GridsCheck c = vdb_internal::sameActiveVoxels(f_);
    add("same_active_voxels", c.passed, c.detail);
  }

  /// The values' meaning: the one validation every reader runs
  /// (checkLightGridValues), on the grid as the reader reads it. A file the
  /// reader refuses fails "readable" with the reader's message.
  void checkValues() {
    LoadedVdl loaded;
    try {
      loaded = vdb_internal::readVdlStructure(r_.path);
    } catch (const InputError& e) {
      add("readable", false, e.what());
      return;
    }
    add("readable", true, "render, convert and the sweep read it");
    for (const VdbCheck& c : checkLightGridValues(loaded.grid, loaded.halfFloat)) r_.checks.push_back(c);
    const std::vector<std::string>& absent = loaded.absentGrids;
    if (std::find(absent.begin(), absent.end(), "noise") == absent.end()) {
      r_.noise = summarizeNoise(loaded.grid);
    }
  }

  const OpenedFile& f_;
  VdbReport& r_;
};

}  // namespace
}  // namespace vdb_inspect_internal

VdbReport inspectVdb(const std::string& path) {
  using namespace vdb_inspect_internal;
  OpenedFile f = openAll(path);
  VdbReport r;
  r.path = path;
  std::error_code ec;
  r.fileBytes = uint64_t(fs::file_size(path, ec));
  r.metadata = metaList(*f.meta);
  for (const auto& g : *f.grids) {
    if (g) r.grids.push_back(summarize(*g));
  }
  bool hasIrradiance = false, hasPhotons = false;
  for (const auto& g : *f.grids) {
    if (!g) continue;
    hasIrradiance = hasIrradiance || g->getName() == vdb_internal::gridNameOf(&VdlGrid::irradiance);
    hasPhotons =
        hasPhotons || (g->getName() == "photons" && g->isType<openvdb::points::PointDataGrid>());
  }
  if (hasPhotons && !hasIrradiance) {
    r.kind = "photons";
    r.checks.push_back({"photons", true, "a lightoctree photon file (point grid 'photons')"});
    return r;
  }
  r.kind = hasIrradiance ? "vdl" : "other";
  VdlChecker(f, r).run();
  return r;
}

}  // namespace lo
