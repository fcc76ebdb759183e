// The meaning of a light grid's values: what a reader refuses outright
// (non-finite values, depth) and the checks `inspect` reports
// (checkLightGridValues). No OpenVDB: the values as VdlGrid holds them.

#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <type_traits>
#include <vector>

#include "core/error.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace vdb_internal {
namespace {

bool finiteValue(float v) { return std::isfinite(v); }
bool finiteValue(const Vec3& v) { return isFinite(v); }

/// The grid that holds value `slot` (and `component`) of `row` for the
/// voxels (layer 0) or surface layer `layer`.
template <typename T>
std::string gridNameFor(const LightGridField<T>& row, int layer, const VdlGrid& g, size_t slot,
                        const VdlComponent* component) {
  for (const FieldGrid& grid : fieldGrids(row, layer, g.maxVdls, g.shTerms)) {
    if (size_t(grid.slot) == slot && grid.component == component) return grid.name;
  }
  return row.member;
}

/// Throws for the first non-finite value of `row` at entry `index` (a voxel,
/// or with layer > 0 a surface layer entry) at voxel `c`. Unused VDL slots
/// are never read and not checked; counts are integers already.
template <typename T>
void checkFinite(const std::string& path, const VdlGrid& g, const LightGridField<T>& row,
                 int layer, size_t index, const Coord& c) {
  if (layer > 0 && !row.layers) return;
  const std::vector<T>& values = layer > 0 ? g.layers.*row.layers : g.*row.voxels;
  const size_t per = layer > 0 ? valuesPerLayer(g, row) : valuesPerVoxel(g, row);
  auto fail = [&](size_t slot, const VdlComponent* component) {
    throw InputError(path + ": " + gridNameFor(row, layer, g, slot, component) + " at voxel " +
                     c.ToString() + " is not finite (NaN or Inf): the file is damaged");
  };
  for (size_t i = 0; i < per; ++i) {
    const T& value = values[index * per + i];
    if constexpr (std::is_same_v<T, Vdl>) {
      const uint8_t count = layer > 0 ? g.layers.vdlCount[index] : g.vdlCount[index];
      if (i >= count) break;
      for (const VdlComponent& component : kVdlComponents) {
        if (!finiteValue(value.*component.member)) fail(i, &component);
      }
    } else if constexpr (!std::is_same_v<T, uint8_t>) {
      if (!finiteValue(value)) fail(i, nullptr);
    }
  }
}

}  // namespace

/// The free-space light's arrays and values (docs/vdb-contract.md): what a
/// renderer can draw, checked by the writer and the reader alike.
void checkVolume(const std::string& path, const VolumeLight& v, int depth) {
  if (v.empty()) return;
  const size_t n = v.size();
  if ((v.shTerms != 4 && v.shTerms != 9) || v.irradiance.size() != n ||
      v.sh.size() != n * size_t(v.shTerms) || v.segments.size() != n || v.litLower.size() != n ||
      v.litUpper.size() != n) {
    throw InputError(path + ": the free-space light's arrays disagree (" + std::to_string(n) +
                     " voxels, " + std::to_string(v.shTerms) + " SH terms)");
  }
  if (v.frame.depth < 1 || v.frame.depth > depth) {
    throw InputError(path + ": free-space depth " + std::to_string(v.frame.depth) +
                     " is outside [1, depth " + std::to_string(depth) + "]");
  }
  const int res = 1 << v.frame.depth;
  auto bad = [&](size_t k, const std::string& what) {
    throw InputError(path + ": free-space voxel " + v.coords[k].ToString() + " " + what);
  };
  auto inRange = [](const Vec3& x) {
    return isFinite(x) && std::fabs(x.x) <= kMaxStoredIrradiance &&
           std::fabs(x.y) <= kMaxStoredIrradiance && std::fabs(x.z) <= kMaxStoredIrradiance;
  };
  for (size_t k = 0; k < n; ++k) {
    const Coord& c = v.coords[k];
    if (c.x < 0 || c.y < 0 || c.z < 0 || c.x >= res || c.y >= res || c.z >= res) {
      bad(k, "lies outside [0, " + std::to_string(res) + ")^3");
    }
    if (!inRange(v.irradiance[k])) bad(k, "has irradiance " + v.irradiance[k].ToString());
    for (int i = 0; i < v.shTerms; ++i) {
      if (!inRange(v.shOf(k)[i])) bad(k, "has SH term " + v.shOf(k)[i].ToString());
    }
    if (!(v.segments[k] >= 0) || !std::isfinite(v.segments[k])) {
      bad(k, "counts " + std::to_string(v.segments[k]) + " rays");
    }
    for (int a = 0; a < 3; ++a) {
      if (!(v.litLower[k][a] >= 0 && v.litUpper[k][a] <= 1 && v.litLower[k][a] <= v.litUpper[k][a])) {
        bad(k, "has lit box " + v.litLower[k].ToString() + " .. " + v.litUpper[k].ToString() +
                   "; expected 0 <= lower <= upper <= 1");
      }
    }
  }
}

void checkDepthInRange(const std::string& path, int depth) {
  if (depth < 1 || depth > kMaxGridDepth) {
    throw InputError(path + ": depth " + std::to_string(depth) +
                     " in the file's metadata: a light grid's depth is 1 to " +
                     std::to_string(kMaxGridDepth));
  }
}

void checkReadableValues(const std::string& path, const VdlGrid& g) {
  checkDepthInRange(path, g.frame.depth);
  checkVolume(path, g.volume, g.frame.depth);
  for (size_t v = 0; v < g.size(); ++v) {
    forEachField([&](const auto& row) { checkFinite(path, g, row, 0, v, g.coords[v]); });
  }
  const std::vector<uint32_t>& voxel = g.layers.voxel;
  for (size_t e = 0; e < g.layers.size(); ++e) {
    const int layer = e > 0 && voxel[e - 1] == voxel[e] ? 2 : 1;
    forEachField([&](const auto& row) { checkFinite(path, g, row, layer, e, g.coords[voxel[e]]); });
  }
}

}  // namespace vdb_internal

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

}  // namespace lo
