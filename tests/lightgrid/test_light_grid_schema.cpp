// The light grid's field table drives every place that handles all of a
// grid's arrays: a grid whose every field (and surface layer) holds distinct
// values, made by walking the table, must come back bit for bit through the
// .vdb writer and reader, the distributed split and merge and the resampling
// copies, and resizing must satisfy the array checks. A row added to
// kLightGridFields is tested here without a change.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <type_traits>
#include <vector>

#include "cluster/resample.h"
#include "core/error.h"
#include "distributed/vdl_grid_parts.h"
#include "lightgrid/light_grid_schema.h"
#include "test_util.h"
#include "vdb/vdb_internal.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

/// A value of type T that differs with the row, the entry and the slot:
/// unit vectors (they may be VDL directions), positive floats, counts.
template <typename T>
T fieldValue(int row, size_t entry, size_t slot, const VdlGrid& g) {
  const float a = float(row) * 0.173f + float(entry % 97) * 0.011f + float(slot) * 0.0371f;
  if constexpr (std::is_same_v<T, Vec3>) {
    return normalize(Vec3(1.0f + a, 2.0f - a * 0.5f, 0.5f + a * 0.25f));
  } else if constexpr (std::is_same_v<T, float>) {
    return 0.25f + a;
  } else if constexpr (std::is_same_v<T, uint8_t>) {
    // SH grids hold no VDLs (the reader refuses counts there).
    return g.shTerms > 0 ? 0 : uint8_t((entry + size_t(row)) % size_t(g.maxVdls + 1));
  } else {
    static_assert(std::is_same_v<T, Vdl>, "a value type the test does not know");
    return Vdl{fieldValue<Vec3>(row, entry, slot + 1, g), fieldValue<Vec3>(row + 1, entry, slot, g)};
  }
}

/// `voxels` voxels of which every third has a second layer and every ninth
/// a third; every field of the table filled by fieldValue.
VdlGrid makeFullGrid(size_t voxels, int maxVdls, int shTerms) {
  VdlGrid g;
  g.frame.origin = {-0.5f, 0.25f, 1.5f};
  g.frame.voxelSize = 0.0625f;
  g.frame.depth = 5;
  g.maxVdls = maxVdls;
  g.shTerms = shTerms;
  std::set<uint64_t> keys;
  for (size_t v = 0; keys.size() < voxels; ++v) {
    const Coord c{int(v * 7 % 32), int(v * 13 % 29), int(v * 5 % 31)};
    if (keys.insert(canonicalVoxelKey(c)).second) g.coords.push_back(c);
  }
  std::sort(g.coords.begin(), g.coords.end(), [](const Coord& a, const Coord& b) {
    return canonicalVoxelKey(a) < canonicalVoxelKey(b);
  });
  std::vector<uint32_t> layerVoxel;
  for (size_t v = 0; v < voxels; v += 3) {
    layerVoxel.push_back(uint32_t(v));
    if (v % 9 == 0) layerVoxel.push_back(uint32_t(v));
  }
  resizeVoxelArrays(g);
  resizeLayerArrays(g, layerVoxel.size());
  g.layers.voxel = layerVoxel;
  int rowIndex = 0;
  // Counts first: the VDL slots a count leaves unused are zero (they are
  // not stored).
  for (int pass = 0; pass < 2; ++pass) {
    rowIndex = 0;
    forEachField([&](const auto& row) {
      using T = typename std::decay_t<decltype(row)>::Value;
      const int r = rowIndex++;
      if ((pass == 0) != std::is_same_v<T, uint8_t>) return;
      auto fill = [&](std::vector<T>& values, size_t per, const std::vector<uint8_t>& count,
                      size_t offset) {
        for (size_t i = 0; i < values.size(); ++i) {
          const size_t entry = per ? i / per : 0, slot = per ? i % per : 0;
          if constexpr (std::is_same_v<T, Vdl>) {
            if (slot >= count[entry]) continue;
          }
          values[i] = fieldValue<T>(r, entry + offset, slot, g);
        }
      };
      fill(g.*row.voxels, valuesPerVoxel(g, row), g.vdlCount, 0);
      if (row.layers) fill(g.layers.*row.layers, valuesPerLayer(g, row), g.layers.vdlCount, 1000);
    });
  }
  checkLightGridArrays(g);
  return g;
}

BakeMetadata metaFor(const VdlGrid& g) {
  BakeMetadata m;
  m.sourceScene = "table";
  m.depth = g.frame.depth;
  m.vdls = std::to_string(g.maxVdls);
  m.representation = representationName(g.representation());
  return m;
}

template <typename T>
const T& zero() {
  static const T value{};
  return value;
}

template <typename T>
std::string firstDifference(const std::vector<T>& a, const std::vector<T>& b) {
  if (a.size() != b.size()) {
    return "sizes " + std::to_string(a.size()) + " and " + std::to_string(b.size());
  }
  for (size_t i = 0; i < a.size(); ++i) {
    if (std::memcmp(&a[i], &b[i], sizeof(T)) != 0) return "value " + std::to_string(i);
  }
  return "";
}

/// Every array of the table (the voxels' OneOrNone arrays only where the
/// voxel has layers: elsewhere nothing is stored) compared bit for bit.
void expectSameFields(const VdlGrid& a, const VdlGrid& b, const std::string& what) {
  ASSERT_EQ(firstDifference(a.coords, b.coords), "") << what << ": coords";
  ASSERT_EQ(firstDifference(a.layers.voxel, b.layers.voxel), "") << what << ": layers.voxel";
  EXPECT_EQ(a.maxVdls, b.maxVdls) << what;
  EXPECT_EQ(a.shTerms, b.shTerms) << what;
  forEachField([&](const auto& row) {
    if (row.arity == FieldArity::OneOrNone) {
      ASSERT_EQ((a.*row.voxels).empty(), (b.*row.voxels).empty()) << what << ": " << row.member;
      for (uint32_t v : a.layers.voxel) {
        EXPECT_EQ(std::memcmp(&(a.*row.voxels)[v], &(b.*row.voxels)[v], sizeof((a.*row.voxels)[v])),
                  0)
            << what << ": " << row.member << " of voxel " << v;
      }
    } else {
      EXPECT_EQ(firstDifference(a.*row.voxels, b.*row.voxels), "") << what << ": " << row.member;
    }
    if (row.layers) {
      EXPECT_EQ(firstDifference(a.layers.*row.layers, b.layers.*row.layers), "")
          << what << ": layers." << row.member;
    }
  });
}

struct Shape {
  int maxVdls, shTerms;
};
const Shape kShapes[] = {{3, 0}, {1, 0}, {kMaxVdls, 0}, {2, 4}, {1, 9}};

TEST(LightgridSchema, TheTableIsConsistent) {
  std::set<std::string> names, members;
  forEachField([&](const auto& row) {
    EXPECT_TRUE(names.insert(row.gridName).second) << row.gridName;
    EXPECT_TRUE(members.insert(row.member).second) << row.member;
    EXPECT_EQ(row.layers == nullptr, row.layerGridName == nullptr) << row.member;
    // What only some voxels have is not optional: its absence means no layers.
    if (row.arity == FieldArity::OneOrNone) {
      EXPECT_FALSE(row.optional) << row.member;
      EXPECT_TRUE(row.layers != nullptr) << row.member;
    }
  });
  EXPECT_EQ(optionalVdlGridNames(),
            (std::vector<std::string>{"reflectance", "photon_count", "noise", "angular_error", "radius",
                                      "area"}));
}

TEST(LightgridSchema, ResizingSatisfiesTheArrayChecks) {
  for (const Shape& s : kShapes) {
    VdlGrid g;
    g.maxVdls = s.maxVdls;
    g.shTerms = s.shTerms;
    g.coords.resize(17);
    resizeVoxelArrays(g);
    EXPECT_NO_THROW(checkLightGridArrays(g));
    EXPECT_TRUE(g.points.empty());  // not recorded without layers
    resizeLayerArrays(g, 5);
    for (size_t e = 0; e < 5; ++e) g.layers.voxel[e] = uint32_t(e * 3);
    EXPECT_NO_THROW(checkLightGridArrays(g));
    EXPECT_EQ(g.points.size(), 17u);
    // Every array is checked: one value too many in any of them fails.
    forEachField([&](const auto& row) {
      VdlGrid broken = g;
      (broken.*row.voxels).emplace_back();
      EXPECT_THROW(checkLightGridArrays(broken), InternalError) << row.member;
      if (row.layers) {
        broken = g;
        (broken.layers.*row.layers).emplace_back();
        EXPECT_THROW(checkLightGridArrays(broken), InternalError) << "layers." << row.member;
      }
    });
  }
}

TEST(LightgridSchema, EveryFieldRoundTripsThroughVdbFiles) {
  const std::string dir = test::outputDir("LightgridSchema.RoundTrip");
  // The grids hold random values in every field, not light: written past
  // writeVdlGrid's value checks, read back by the structure reader.
  auto write = [](const std::string& path, const VdlGrid& g, const BakeMetadata& meta,
                  const VdlWriteOptions& options = {}) {
    vdb_internal::Damage none;
    none.options = options;
    vdb_internal::writeVdlGridDamaged(path, g, meta, none);
  };
  for (const Shape& s : kShapes) {
    const VdlGrid g = makeFullGrid(120, s.maxVdls, s.shTerms);
    const std::string what = "max_vdls " + std::to_string(s.maxVdls) + ", SH terms " +
                             std::to_string(s.shTerms);
    const std::string path = dir + "/full.vdb";
    write(path, g, metaFor(g));
    const LoadedVdl r = vdb_internal::readVdlStructure(path);
    EXPECT_TRUE(r.absentGrids.empty()) << what;
    expectSameFields(g, r.grid, what);

    // Each optional grid left out reads as zeros, the rest unchanged (for
    // one VDL and one SH grid: each file read is a child process).
    forEachField([&](const auto& row) {
      if (!row.optional || (s.maxVdls != 3 && s.shTerms != 4)) return;
      VdlWriteOptions options;
      options.drop = {row.gridName};
      write(path, g, metaFor(g), options);
      const LoadedVdl d = vdb_internal::readVdlStructure(path);
      EXPECT_EQ(d.absentGrids, std::vector<std::string>{row.gridName});
      VdlGrid expected = g;
      using T = typename std::decay_t<decltype(row)>::Value;
      std::fill((expected.*row.voxels).begin(), (expected.*row.voxels).end(), T{});
      expectSameFields(expected, d.grid, what + ", without " + row.gridName);
    });

    // Half floats: the rows that allow them lose precision, the others keep
    // every bit.
    VdlWriteOptions half;
    half.halfFloat = true;
    write(path, g, metaFor(g), half);
    const LoadedVdl h = vdb_internal::readVdlStructure(path);
    EXPECT_TRUE(h.halfFloat);
    forEachField([&](const auto& row) {
      using T = typename std::decay_t<decltype(row)>::Value;
      const auto& a = g.*row.voxels;
      const auto& b = h.grid.*row.voxels;
      ASSERT_EQ(a.size(), b.size()) << row.member;
      if (!row.halfFloat || row.arity == FieldArity::OneOrNone) {
        if (row.arity != FieldArity::OneOrNone) {
          EXPECT_EQ(firstDifference(a, b), "") << what << ": " << row.member << " (full floats)";
        }
        return;
      }
      bool rounded = false, nonZero = false;
      for (size_t i = 0; i < a.size(); ++i) {
        nonZero = nonZero || std::memcmp(&a[i], &zero<T>(), sizeof(T)) != 0;
        if constexpr (std::is_same_v<T, float>) {
          EXPECT_NEAR(b[i], a[i], 1e-3 * std::fabs(a[i])) << row.member;
          rounded = rounded || b[i] != a[i];
        } else if constexpr (std::is_same_v<T, Vec3>) {
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(b[i][k], a[i][k], 1e-3) << row.member;
          rounded = rounded || !(b[i] == a[i]);
        } else if constexpr (std::is_same_v<T, Vdl>) {
          for (int k = 0; k < 3; ++k) EXPECT_NEAR(b[i].direction[k], a[i].direction[k], 1e-3);
          rounded = rounded || !(b[i].direction == a[i].direction);
        }
      }
      // (SH grids hold no VDLs: nothing to round.)
      if (nonZero) {
        EXPECT_TRUE(rounded) << what << ": " << row.member << " kept full floats";
      }
    });
  }
}

TEST(LightgridSchema, EveryFieldSurvivesTheDistributedSplitAndMerge) {
  for (const Shape& s : kShapes) {
    const VdlGrid g = makeFullGrid(90, s.maxVdls, s.shTerms);
    std::vector<VdlGrid> parts;
    for (uint32_t part = 0; part < 3; ++part) {
      std::vector<uint32_t> voxels;
      for (uint32_t v = part; v < g.size(); v += 3) voxels.push_back(v);
      parts.push_back(deserializeVdlGrid(serializeVdlGrid(selectVoxels(g, voxels))));
      checkLightGridArrays(parts.back());
    }
    // Merged in another order than split: the merge sorts by voxel.
    std::swap(parts[0], parts[2]);
    expectSameFields(g, mergeVdlGrids(std::move(parts)),
                     "split and merge, max_vdls " + std::to_string(s.maxVdls));
  }
}

TEST(LightgridSchema, ReclusteringCopiesTheSurfaceAndGatherFields) {
  const VdlGrid g = makeFullGrid(60, 3, 0);
  ClusterParams params;
  params.vdls = 2;
  const VdlGrid out = reclusterVdlGrid(g, params);
  checkLightGridArrays(out);
  EXPECT_EQ(out.maxVdls, 2);
  EXPECT_EQ(firstDifference(out.layers.voxel, g.layers.voxel), "");
  forEachField([&](const auto& row) {
    if (row.role == FieldRole::Light) return;
    EXPECT_EQ(firstDifference(out.*row.voxels, g.*row.voxels), "") << row.member;
    if (row.layers) {
      EXPECT_EQ(firstDifference(out.layers.*row.layers, g.layers.*row.layers), "")
          << "layers." << row.member;
    }
  });
}

}  // namespace
}  // namespace lo
