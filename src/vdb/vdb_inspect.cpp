// `lightoctree inspect`: a generic report of an OpenVDB file and the checks of
// the VDL contract. Own translation unit so that vdb_io.cpp and this file
// compile in parallel; both include OpenVDB, nothing outside src/vdb does.

#include "vdb/vdb_inspect.h"

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointDataGrid.h>
#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>

#include "lightgrid/vdl_grid.h"
#include "core/error.h"
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

std::string num(double v) {
  std::ostringstream os;
  os.precision(4);
  os << v;
  return os.str();
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
    checkValues(maxVdls);
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
  /// files without the key), 4 for sh1, 9 for sh2, -1 for anything else.
  int readShTerms() const {
    auto typed = openvdb::DynamicPtrCast<const openvdb::StringMetadata>((*f_.meta)["representation"]);
    if (!typed) return (*f_.meta)["representation"] ? -1 : 0;
    const std::string& r = typed->value();
    return r == "vdl" ? 0 : r == "sh1" ? 4 : r == "sh2" ? 9 : -1;
  }

  /// Sum of the SH terms at voxel c (grids `prefix` + "sh<i>") evaluated at
  /// the normal n: E(n), and in `scale` the largest |term| seen.
  double shAt(const std::vector<Vec3SGrid::ConstAccessor>& sh, const openvdb::Coord& c,
              const openvdb::Vec3s& n, int k, double& scale) const {
    double e = 0;
    for (size_t i = 0; i < sh.size(); ++i) {
      const double t = double(sh[i].getValue(c)[k]);
      e += t * double(layout::loShBasis(uint32_t(i), n[0], n[1], n[2]));
      scale = std::max(scale, std::abs(t));
    }
    return e;
  }

  int readMaxVdls() const {
    auto m = (*f_.meta)["max_vdls"];
    auto typed = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(m);
    return typed ? typed->value() : -1;
  }

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
    if (maxVdls < 1 || maxVdls > kMaxVdls) {
      problems = "file metadata max_vdls is " +
                 (maxVdls < 0 ? std::string("missing or not int32") : std::to_string(maxVdls)) +
                 ", expected 1.." + std::to_string(kMaxVdls);
    } else {
      for (int i = 0; i < maxVdls; ++i) {
        need("vdl" + std::to_string(i) + "_irradiance", "vec3s", true);
        need("vdl" + std::to_string(i) + "_direction", "vec3s", true);
      }
    }
    need("irradiance", "vec3s", true);
    need("normal", "vec3s", true);
    need("vdl_count", "float", true);
    const int shTerms = readShTerms();
    if (shTerms < 0) {
      problems += std::string(problems.empty() ? "" : "; ") +
                  "file metadata representation is not 'vdl', 'sh1' or 'sh2'";
    }
    for (int i = 0; i < shTerms; ++i) need("sh" + std::to_string(i), "vec3s", true);
    std::string absent;
    for (const std::string& name : optionalVdlGridNames()) {
      need(name, "float", false);
      if (!find(name)) absent += (absent.empty() ? "" : ", ") + name;
    }
    add("contract", problems.empty(),
        problems.empty()
            ? "all required grids present with their types" +
                  (absent.empty() ? std::string() : "; optional grids absent: " + absent)
            : problems);
    return problems.empty();
  }

  void checkFormatVersion() {
    auto m = (*f_.meta)["format_version"];
    if (!m) {
      add("format_version", true, "absent: a file written before format_version 1 (read as 1)");
      return;
    }
    auto typed = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(m);
    if (!typed) {
      add("format_version", false, "has type " + m->typeName() + ", expected int32");
      return;
    }
    const int v = typed->value();
    add("format_version", v >= 1 && v <= kVdlFormatVersion,
        std::to_string(v) + " (this lightoctree reads 1.." + std::to_string(kVdlFormatVersion) +
            ")");
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

  void checkSameTransform() {
    const openvdb::GridBase* ref = nullptr;
    for (const auto& g : *f_.grids) {
      if (!g) continue;
      if (!ref) {
        ref = g.get();
      } else if (!(g->transform() == ref->transform())) {
        add("same_transform", false,
            "grid '" + g->getName() + "' differs from '" + ref->getName() + "'");
        return;
      }
    }
    add("same_transform", true, "every grid on one transform");
  }

  /// Which active set a grid shares: the voxels' (0), or surface layer l's
  /// (layer_point goes with layer 1: the voxels that have layers).
  static int layerGroup(const std::string& name) {
    if (name == "layer_point") return 1;
    if (name.rfind("layer", 0) == 0 && name.size() > 6 && name[6] == '_' && name[5] >= '1' &&
        name[5] <= '9') {
      return name[5] - '0';
    }
    return 0;
  }

  /// What the reader (readVdlGrid) and the GPU octree refuse, checked the
  /// same way here so that inspect never passes a file render refuses: the
  /// depth metadata within [1, kMaxGridDepth], a transform of uniform scale
  /// and translation only, and every voxel within [0, 2^depth) on each axis.
  void checkDepthAndBounds() {
    auto m = (*f_.meta)["depth"];
    int depth = -1;
    if (auto i32 = openvdb::DynamicPtrCast<const openvdb::Int32Metadata>(m)) depth = i32->value();
    if (auto i64 = openvdb::DynamicPtrCast<const openvdb::Int64Metadata>(m)) {
      depth = i64->value() >= 0 && i64->value() <= 64 ? int(i64->value()) : -1;
    }
    const bool depthOk = depth >= 1 && depth <= kMaxGridDepth;
    add("depth", depthOk,
        depthOk ? std::to_string(depth) + " (2^" + std::to_string(depth) + " voxels per axis)"
                : "file metadata depth is " + (m ? m->str() : std::string("missing")) +
                      ", expected an int32 in [1, " + std::to_string(kMaxGridDepth) + "]");
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
    const int res = 1 << depth;
    std::string outside;
    uint64_t count = 0;
    for (const auto& g : *f_.grids) {
      if (!g || g->isType<openvdb::points::PointDataGrid>()) continue;
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
        count == 0 ? "every voxel within [0, " + std::to_string(res) + ") of depth " +
                         std::to_string(depth)
                   : std::to_string(count) + " grid(s) beyond it; first " + outside);
  }

  /// The VDL grids of one slot ("vdl2", "layer1_vdl0"): active where the
  /// voxel (or layer) has that VDL (sparse since format version 2).
  static std::string vdlSlot(const std::string& name) {
    const size_t at = name.find("vdl");
    if (at == std::string::npos || (at != 0 && at != 7)) return "";
    const size_t under = name.find('_', at);
    if (under == std::string::npos || under == at + 3) return "";
    const std::string tail = name.substr(under);
    if (tail != "_irradiance" && tail != "_direction") return "";
    return name.substr(0, under);
  }

  void checkSameActive() {
    std::map<std::string, const openvdb::GridBase*> ref;
    std::string counts;
    for (const auto& g : *f_.grids) {
      if (!g) continue;
      const std::string slot = vdlSlot(g->getName());
      const int group = layerGroup(g->getName());
      const std::string key = !slot.empty() ? slot : "layer" + std::to_string(group);
      const openvdb::GridBase*& r = ref[key];
      if (!r) {
        r = g.get();
        if (slot.empty()) {
          counts += (counts.empty() ? "" : ", ") + std::to_string(g->activeVoxelCount()) +
                    (group == 0 ? " in every voxel grid"
                                : " in every layer" + std::to_string(group) + " grid");
        }
      } else if (g->activeVoxelCount() != r->activeVoxelCount() ||
                 g->evalActiveVoxelBoundingBox() != r->evalActiveVoxelBoundingBox()) {
        add("same_active_voxels", false,
            "grid '" + g->getName() + "' has " + std::to_string(g->activeVoxelCount()) +
                " active voxels, '" + r->getName() + "' " + std::to_string(r->activeVoxelCount()));
        return;
      }
    }
    add("same_active_voxels", true, counts.empty() ? "no grids" : counts);
  }

  /// Surface layers (format version 2): each layer's voxels are voxels of the
  /// file (layer 2's among layer 1's), counts integers within max_vdls, the
  /// VDLs of each layer sum to its irradiance.
  void checkLayers(int maxVdls, double sumTol) {
    auto count1 = openvdb::gridPtrCast<FloatGrid>(find("layer1_vdl_count"));
    bool anyLayerGrid = false;
    for (const auto& g : *f_.grids) anyLayerGrid = anyLayerGrid || (g && layerGroup(g->getName()) > 0);
    if (!anyLayerGrid) return;
    auto voxels = openvdb::gridPtrCast<FloatGrid>(find("vdl_count"));
    std::string problem;
    uint64_t layers = 0;
    double worstSum = 0;
    for (int layer = 1; layer < kMaxLayers && problem.empty(); ++layer) {
      const std::string prefix = "layer" + std::to_string(layer) + "_";
      auto count = openvdb::gridPtrCast<FloatGrid>(find(prefix + "vdl_count"));
      auto irr = openvdb::gridPtrCast<Vec3SGrid>(find(prefix + "irradiance"));
      auto normal = openvdb::gridPtrCast<Vec3SGrid>(find(prefix + "normal"));
      auto point = openvdb::gridPtrCast<Vec3SGrid>(find(prefix + "point"));
      if (!count) {
        if (layer == 1) problem = "layer grids without 'layer1_vdl_count'";
        break;
      }
      const int shTerms = std::max(0, readShTerms());
      std::vector<Vec3SGrid::ConstAccessor> sha;
      for (int i = 0; i < shTerms; ++i) {
        auto g = openvdb::gridPtrCast<Vec3SGrid>(find(prefix + "sh" + std::to_string(i)));
        if (!g) {
          problem = "missing or mistyped '" + prefix + "sh" + std::to_string(i) + "'";
          break;
        }
        sha.push_back(g->getConstAccessor());
      }
      std::vector<Vec3SGrid::Ptr> vi;
      for (int i = 0; i < maxVdls; ++i) {
        vi.push_back(openvdb::gridPtrCast<Vec3SGrid>(
            find(prefix + "vdl" + std::to_string(i) + "_irradiance")));
        if (!vi.back() || !openvdb::gridPtrCast<Vec3SGrid>(
                              find(prefix + "vdl" + std::to_string(i) + "_direction"))) {
          problem = "missing or mistyped '" + prefix + "vdl" + std::to_string(i) + "_*'";
        }
      }
      if (!irr || !normal || !point || !find("layer_point")) {
        problem = "missing or mistyped grids of layer " + std::to_string(layer);
      }
      if (!problem.empty()) break;
      auto irrAcc = irr->getConstAccessor();
      auto normalAcc = normal->getConstAccessor();
      std::vector<Vec3SGrid::ConstAccessor> via;
      for (const Vec3SGrid::Ptr& g : vi) via.push_back(g->getConstAccessor());
      for (auto it = count->cbeginValueOn(); it && problem.empty(); ++it) {
        ++layers;
        const openvdb::Coord c = it.getCoord();
        if (!voxels || !voxels->tree().isValueOn(c)) {
          problem = prefix + "vdl_count is active at " + coordText(c) + ", not a voxel of the file";
        } else if (layer > 1 && !(count1 && count1->tree().isValueOn(c))) {
          problem = "layer " + std::to_string(layer) + " at " + coordText(c) + " without layer 1";
        }
        const float n = *it;
        if (problem.empty() && (!(n >= 0 && n <= float(maxVdls)) || n != std::floor(n))) {
          problem = prefix + "vdl_count at " + coordText(c) + " holds " + num(n);
        }
        if (!problem.empty()) break;
        const openvdb::Vec3s e = irrAcc.getValue(c);
        double sum[3] = {0, 0, 0}, scale = std::max({double(e[0]), double(e[1]), double(e[2])});
        for (int i = 0; i < maxVdls; ++i) {
          const openvdb::Vec3s v = via[size_t(i)].getValue(c);
          for (int k = 0; k < 3; ++k) {
            sum[k] += v[k];
            scale = std::max(scale, double(std::abs(v[k])));
          }
        }
        if (shTerms > 0) {
          const openvdb::Vec3s nl = normalAcc.getValue(c);
          for (int k = 0; k < 3; ++k) sum[k] = shAt(sha, c, nl, k, scale);
        }
        double diff = 0;
        for (int k = 0; k < 3; ++k) diff = std::max(diff, std::abs(sum[k] - double(e[k])));
        const double rel = scale > 0 ? diff / scale : (diff > 0 ? 1e30 : 0.0);
        worstSum = std::max(worstSum, std::isfinite(rel) ? rel : 1e30);
        if (!(rel <= sumTol)) {
          problem = prefix + (shTerms > 0 ? "SH at the normal" : "vdl sum") + " at " + coordText(c) + " differs by " + num(rel) +
                    " of the irradiance (allowed " + num(sumTol) + ")";
        }
      }
    }
    add("layers", problem.empty(),
        problem.empty() ? std::to_string(layers) + " extra surface layers on voxels of the file; "
                                                    "their light sums to their irradiance (largest "
                                                    "relative difference " +
                              num(worstSum) + ")"
                        : problem);
  }

  void checkValues(int maxVdls) {
    auto irr = openvdb::gridPtrCast<Vec3SGrid>(find("irradiance"));
    auto count = openvdb::gridPtrCast<FloatGrid>(find("vdl_count"));
    std::vector<Vec3SGrid::Ptr> vi, vd;
    for (int i = 0; i < maxVdls; ++i) {
      vi.push_back(
          openvdb::gridPtrCast<Vec3SGrid>(find("vdl" + std::to_string(i) + "_irradiance")));
      vd.push_back(openvdb::gridPtrCast<Vec3SGrid>(find("vdl" + std::to_string(i) + "_direction")));
    }
    const bool half = irr->saveFloatAsHalf() || vi[0]->saveFloatAsHalf();
    const double sumTol = half ? kVdlSumToleranceHalf : kVdlSumTolerance;
    // SH files: E(n) at the voxel's normal is its irradiance, in place of the VDL sum.
    const int shTerms = readShTerms();
    std::vector<Vec3SGrid::ConstAccessor> sha;
    for (int i = 0; i < shTerms; ++i) {
      sha.push_back(openvdb::gridPtrCast<Vec3SGrid>(find("sh" + std::to_string(i)))->getConstAccessor());
    }
    auto normalAcc = openvdb::gridPtrCast<Vec3SGrid>(find("normal"))->getConstAccessor();

    uint64_t badCount = 0, negative = 0, notUnit = 0, badSum = 0, voxels = 0;
    std::string firstCount, firstNegative, firstNotUnit, firstSum;
    double worstUnit = 0, worstSum = 0;
    auto irrAcc = irr->getConstAccessor();
    std::vector<Vec3SGrid::ConstAccessor> ia, da;
    for (int i = 0; i < maxVdls; ++i) {
      ia.push_back(vi[size_t(i)]->getConstAccessor());
      da.push_back(vd[size_t(i)]->getConstAccessor());
    }
    auto negativeIn = [](const openvdb::Vec3s& v) { return v[0] < 0 || v[1] < 0 || v[2] < 0; };
    // Voxels in vdl_count's active order: deterministic "first offending voxel".
    for (auto it = count->cbeginValueOn(); it; ++it) {
      ++voxels;
      const openvdb::Coord c = it.getCoord();
      const float n = *it;
      if (!(n >= 0 && n <= float(maxVdls)) || n != std::floor(n)) {
        if (badCount++ == 0) firstCount = coordText(c) + " holds " + num(n);
        continue;
      }
      const openvdb::Vec3s e = irrAcc.getValue(c);
      bool neg = negativeIn(e);
      double sum[3] = {0, 0, 0};
      double scale = std::max({double(e[0]), double(e[1]), double(e[2])});
      for (int i = 0; i < maxVdls; ++i) {
        const openvdb::Vec3s vIrr = ia[size_t(i)].getValue(c);
        neg = neg || negativeIn(vIrr);
        for (int k = 0; k < 3; ++k) {
          sum[k] += vIrr[k];
          scale = std::max(scale, double(std::abs(vIrr[k])));
        }
        if (i < int(n)) {
          const double len = da[size_t(i)].getValue(c).length();
          const double dev = std::abs(len - 1.0);
          worstUnit = std::max(worstUnit, std::isfinite(dev) ? dev : 1e30);
          if (!(dev < kUnitDirectionTolerance) && notUnit++ == 0) {
            firstNotUnit = "vdl" + std::to_string(i) + "_direction at " + coordText(c) +
                           " has length " + num(len);
          }
        }
      }
      if (neg && negative++ == 0) firstNegative = coordText(c);
      if (shTerms > 0) {
        const openvdb::Vec3s nv = normalAcc.getValue(c);
        for (int k = 0; k < 3; ++k) sum[k] = shAt(sha, c, nv, k, scale);
      }
      double diff = 0;
      for (int k = 0; k < 3; ++k) diff = std::max(diff, std::abs(sum[k] - double(e[k])));
      const double rel = scale > 0 ? diff / scale : (diff > 0 ? 1e30 : 0.0);
      if (std::isfinite(rel)) worstSum = std::max(worstSum, rel);
      if (!(rel <= sumTol) && badSum++ == 0) {
        firstSum = coordText(c) + (shTerms > 0 ? ": SH at the normal" : ": sum of VDLs") +
                   " differs by " + num(rel) + " of the irradiance";
      }
    }
    const std::string of = " of " + std::to_string(voxels) + " voxels";
    add("vdl_count", badCount == 0,
        badCount ? std::to_string(badCount) + of + " not an integer in [0, " +
                       std::to_string(maxVdls) + "]; first " + firstCount
                 : "integers in [0, " + std::to_string(maxVdls) + "]");
    add("irradiance_non_negative", negative == 0,
        negative
            ? std::to_string(negative) + of + " with a negative channel; first " + firstNegative
            : "irradiance and VDL irradiance >= 0");
    add("unit_directions", notUnit == 0,
        (notUnit ? std::to_string(notUnit) + " used VDL slots not unit; first " + firstNotUnit
                 : std::string("used VDL slots unit")) +
            " (largest |length - 1| " + num(worstUnit) + ", allowed " +
            num(kUnitDirectionTolerance) + ")");
    add(shTerms > 0 ? "sh_sum" : "vdl_sum", badSum == 0,
        (badSum ? std::to_string(badSum) + of + " off; first " + firstSum
                : std::string(shTerms > 0 ? "SH irradiance at each voxel's normal is its irradiance"
                                          : "VDLs sum to the irradiance")) +
            " (largest relative difference " + num(worstSum) + ", allowed " + num(sumTol) +
            (half ? ", half floats)" : ")"));
    checkLayers(maxVdls, sumTol);
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
    hasIrradiance = hasIrradiance || g->getName() == "irradiance";
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
