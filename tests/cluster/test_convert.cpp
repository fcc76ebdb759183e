// Converting VDL grids between depths and VDL counts (src/cluster/resample.h):
// energy conservation of the merge, the down-then-up round trip, merge vs a
// direct bake at the coarser depth, frame checks, determinism.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <set>
#include <vector>

#include "cluster/resample.h"
#include "cluster/vdl_cluster.h"
#include "core/error.h"
#include "grid/surface_grid.h"
#include "photon/photon_map.h"
#include "test_util.h"

namespace lo {
namespace {

// A closed room with a block and a point light under the ceiling: smooth
// indirect light on six walls, corners, and a block's faces.
Scene roomScene(float scale = 1.0f) {
  Scene scene;
  Material grey;
  grey.baseColor = Vec3(0.7f);
  scene.materials.push_back(grey);
  test::addClosedBox(scene, Vec3(0.0f), Vec3(scale), 0);
  test::addBlock(scene, Vec3(0.3f, 0.0f, 0.3f) * scale, Vec3(0.6f, 0.45f, 0.55f) * scale, 0);
  Light light;
  light.type = Light::Type::Point;
  light.position = Vec3(0.5f, 0.85f, 0.5f) * scale;
  light.intensity = 2.0f;
  scene.lights.push_back(light);
  return scene;
}

struct Baked {
  Scene scene;
  PhotonMap photons;
  SurfaceGrid grid6, grid5;
  VdlGrid bake6, bake5;
};

GatherParams gatherParams() {
  GatherParams g;
  g.k = 100;
  return g;
}

ClusterParams clusterParams(int k = 4) {
  ClusterParams c;
  c.vdls = k;
  c.seed = 3;
  return c;
}

// Built once: tracing and gathering are the slow part of this file.
const Baked& baked() {
  static const Baked b = [] {
    Baked out;
    out.scene = roomScene();
    PhotonParams p;
    p.storedPhotons = 150000;
    p.seed = 11;
    out.photons = tracePhotons(out.scene, p);
    for (int depth : {6, 5}) {
      GridParams gp;
      gp.depth = depth;
      SurfaceGrid grid = buildSurfaceGrid(out.scene, gp);
      splatPhotons(grid, out.photons.photons);
      VdlGrid vdl = buildVdlGrid(grid, out.photons.photons, gatherParams(), clusterParams());
      (depth == 6 ? out.grid6 : out.grid5) = std::move(grid);
      (depth == 6 ? out.bake6 : out.bake5) = std::move(vdl);
    }
    return out;
  }();
  return b;
}

double channelRelDiff(const Vec3& a, const Vec3& b) {
  const double scale = std::max({std::abs(b.x), std::abs(b.y), std::abs(b.z), 1e-30f});
  return std::max({std::abs(a.x - b.x), std::abs(a.y - b.y), std::abs(a.z - b.z)}) / scale;
}

Vec3 vdlSum(const VdlGrid& g, size_t v) {
  Vec3 s{};
  for (int i = 0; i < g.vdlCount[v]; ++i) s += g.vdlsOf(v)[i].irradiance;
  return s;
}

std::map<Coord, size_t> indexOf(const VdlGrid& g) {
  std::map<Coord, size_t> m;
  for (size_t v = 0; v < g.size(); ++v) m[g.coords[v]] = v;
  return m;
}

/// sqrt(Σ (a − b)² / Σ b²) over the channel means of the voxels present in
/// both grids (matched by coordinate).
double rmsRelative(const VdlGrid& a, const VdlGrid& b, size_t* matched = nullptr) {
  std::map<Coord, size_t> ib = indexOf(b);
  double num = 0, den = 0;
  size_t count = 0;
  for (size_t v = 0; v < a.size(); ++v) {
    auto it = ib.find(a.coords[v]);
    if (it == ib.end()) continue;
    const double x = average(a.irradiance[v]), y = average(b.irradiance[it->second]);
    num += (x - y) * (x - y);
    den += y * y;
    ++count;
  }
  if (matched) *matched = count;
  return den > 0 ? std::sqrt(num / den) : 0.0;
}

TEST(Coarsen, ConservesEnergyAndAveragesChildrenByArea) {
  const VdlGrid& fine = baked().bake6;
  ASSERT_GT(fine.size(), 1000u);
  for (int depth : {5, 4}) {
    SCOPED_TRACE("depth " + std::to_string(depth));
    const int levels = 6 - depth;
    VdlGrid coarse = coarsenVdlGrid(fine, depth, clusterParams());
    EXPECT_EQ(coarse.frame.depth, depth);
    EXPECT_EQ(coarse.frame.origin, fine.frame.origin);
    EXPECT_EQ(coarse.frame.voxelSize, std::ldexp(fine.frame.voxelSize, levels));

    // Reference, written independently: children grouped with a std::map.
    struct Acc {
      double area = 0, irr[3] = {0, 0, 0}, photons = 0;
    };
    std::map<Coord, Acc> ref;
    double fineEnergy[3] = {0, 0, 0};
    for (size_t v = 0; v < fine.size(); ++v) {
      const Coord& c = fine.coords[v];
      Acc& a = ref[Coord{c.x >> levels, c.y >> levels, c.z >> levels}];
      a.area += fine.areas[v];
      a.photons += fine.photonCount[v];
      for (int k = 0; k < 3; ++k) {
        a.irr[k] += double(fine.irradiance[v][k]) * fine.areas[v];
        fineEnergy[k] += double(fine.irradiance[v][k]) * fine.areas[v];
      }
    }
    ASSERT_EQ(coarse.size(), ref.size());
    double coarseEnergy[3] = {0, 0, 0};
    double worstMean = 0, worstSum = 0;
    for (size_t v = 0; v < coarse.size(); ++v) {
      auto it = ref.find(coarse.coords[v]);
      ASSERT_NE(it, ref.end()) << coarse.coords[v].ToString();
      const Acc& a = it->second;
      ASSERT_GT(a.area, 0) << "the room has no zero-area voxels";
      EXPECT_NEAR(coarse.areas[v], a.area, 1e-6 * a.area);
      EXPECT_EQ(coarse.photonCount[v], float(a.photons));
      const Vec3 mean(float(a.irr[0] / a.area), float(a.irr[1] / a.area), float(a.irr[2] / a.area));
      worstMean = std::max(worstMean, channelRelDiff(coarse.irradiance[v], mean));
      if (average(coarse.irradiance[v]) > 0) {
        worstSum = std::max(worstSum, channelRelDiff(vdlSum(coarse, v), coarse.irradiance[v]));
      }
      EXPECT_LE(coarse.vdlCount[v], 4);
      for (int k = 0; k < 3; ++k)
        coarseEnergy[k] += double(coarse.irradiance[v][k]) * coarse.areas[v];
    }
    EXPECT_LE(worstMean, 1e-6) << "coarse irradiance vs area-weighted mean of the children";
    EXPECT_LE(worstSum, 1e-4) << "VDLs must still sum to the irradiance";
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(coarseEnergy[k], fineEnergy[k], 1e-5 * fineEnergy[k]) << "channel " << k;
    }
    std::printf("[ coarsen 6->%d ] %zu -> %zu voxels, energy rel diff %.2e, worst mean %.2e\n",
                depth, fine.size(), coarse.size(),
                std::abs(coarseEnergy[1] - fineEnergy[1]) / fineEnergy[1], worstMean);
  }
}

TEST(Coarsen, ZeroAreaChildrenAverageEqually) {
  VdlGrid g;
  g.frame.depth = 3;
  g.frame.voxelSize = 0.5f;
  g.maxVdls = 2;
  g.coords = {Coord{0, 0, 0}, Coord{1, 0, 0}};
  g.normals = {Vec3(0, 1, 0), Vec3(1, 0, 0)};
  g.areas = {0.0f, 0.0f};
  g.irradiance = {Vec3(1, 2, 3), Vec3(3, 2, 1)};
  g.photonCount = {10, 20};
  g.radius = {0.1f, 0.3f};
  g.noise = {0.1f, 0.2f};
  g.reflectance = {{0.5f, 0.25f, 0.125f}, {0.75f, 0.5f, 0.25f}};
  g.angularError = {0, 0};
  g.vdlCount = {1, 1};
  g.vdls = {Vdl{Vec3(1, 2, 3), Vec3(0, 1, 0)}, Vdl{}, Vdl{Vec3(3, 2, 1), Vec3(1, 0, 0)}, Vdl{}};
  VdlGrid c = coarsenVdlGrid(g, 2, clusterParams(2));
  ASSERT_EQ(c.size(), 1u);
  EXPECT_EQ(c.irradiance[0], Vec3(2, 2, 2));
  EXPECT_EQ(c.areas[0], 0.0f);
  EXPECT_EQ(c.photonCount[0], 30.0f);
  EXPECT_NEAR(c.radius[0], 0.2f, 1e-7f);
  EXPECT_NEAR(length(c.normals[0]), 1.0f, 1e-6f);
  EXPECT_EQ(c.vdlCount[0], 2);
  EXPECT_LE(channelRelDiff(vdlSum(c, 0), c.irradiance[0]), 1e-6);
}

TEST(Coarsen, SameBytesForAnyThreadCount) {
  const VdlGrid& fine = baked().bake6;
  VdlGrid one;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    one = coarsenVdlGrid(fine, 5, clusterParams());
  }
  VdlGrid many = coarsenVdlGrid(fine, 5, clusterParams());
  ASSERT_EQ(one.size(), many.size());
  for (size_t v = 0; v < one.size(); ++v) {
    ASSERT_EQ(one.irradiance[v], many.irradiance[v]);
    ASSERT_EQ(one.angularError[v], many.angularError[v]);
  }
  for (size_t i = 0; i < one.vdls.size(); ++i) {
    ASSERT_EQ(one.vdls[i].irradiance, many.vdls[i].irradiance);
    ASSERT_EQ(one.vdls[i].direction, many.vdls[i].direction);
  }
}

TEST(Coarsen, BadDepthIsAnInputError) {
  const VdlGrid& fine = baked().bake6;
  EXPECT_THROW(coarsenVdlGrid(fine, 6, clusterParams()), InputError);
  EXPECT_THROW(coarsenVdlGrid(fine, 0, clusterParams()), InputError);
  EXPECT_THROW(coarsenVdlGrid(fine, 5, clusterParams(9)), InputError);
}

TEST(Refine, DownThenUpKeepsTheActiveSetAndIsClose) {
  const Baked& b = baked();
  VdlGrid coarse = coarsenVdlGrid(b.bake6, 5, clusterParams());
  RefineStats stats;
  VdlGrid back = refineVdlGrid(coarse, b.grid6, clusterParams(), &stats);
  ASSERT_EQ(back.coords, b.bake6.coords) << "active set from the depth-6 voxelization";
  EXPECT_EQ(stats.withoutParent, 0u);
  EXPECT_EQ(back.frame.voxelSize, b.bake6.frame.voxelSize);
  EXPECT_EQ(back.areas, b.bake6.areas);
  double worstSum = 0;
  for (size_t v = 0; v < back.size(); ++v) {
    if (average(back.irradiance[v]) > 0) {
      worstSum = std::max(worstSum, channelRelDiff(vdlSum(back, v), back.irradiance[v]));
    }
  }
  EXPECT_LE(worstSum, 1e-4);
  const double rms = rmsRelative(back, b.bake6);
  std::printf("[ round trip 6->5->6 ] %zu voxels, RMS relative irradiance difference %.4f\n",
              back.size(), rms);
  EXPECT_LT(rms, 0.25);
  EXPECT_GT(rms, 0.0) << "interpolation cannot reproduce the fine grid exactly";
}

TEST(Refine, MismatchedFrameIsAnInputError) {
  const Baked& b = baked();
  VdlGrid coarse = coarsenVdlGrid(b.bake6, 5, clusterParams());
  // Another scene (twice as large) voxelized at depth 6: not nested in coarse.
  GridParams gp;
  gp.depth = 6;
  SurfaceGrid other = buildSurfaceGrid(roomScene(2.0f), gp);
  try {
    refineVdlGrid(coarse, other, clusterParams());
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not nested"), std::string::npos) << e.what();
  }
  // Same depth as the input: not finer.
  EXPECT_THROW(refineVdlGrid(b.bake6, b.grid6, clusterParams()), InputError);
}

TEST(Convert, MergeToDepth5IsCloseToBakingDepth5) {
  const Baked& b = baked();
  VdlGrid merged = coarsenVdlGrid(b.bake6, 5, clusterParams());
  std::set<Coord> mergedSet(merged.coords.begin(), merged.coords.end());
  std::set<Coord> bakedSet(b.bake5.coords.begin(), b.bake5.coords.end());
  EXPECT_EQ(mergedSet, bakedSet) << "children's union = parent box: same active voxels";
  size_t matched = 0;
  const double rms = rmsRelative(merged, b.bake5, &matched);
  double e5 = 0, e56 = 0;
  for (size_t v = 0; v < merged.size(); ++v) e56 += average(merged.irradiance[v]) * merged.areas[v];
  for (size_t v = 0; v < b.bake5.size(); ++v)
    e5 += average(b.bake5.irradiance[v]) * b.bake5.areas[v];
  std::printf(
      "[ 6->5 vs direct 5 ] %zu voxels matched, RMS relative difference %.4f, "
      "total irradiance x area %.5g vs %.5g (%+.2f%%)\n",
      matched, rms, e56, e5, 100.0 * (e56 - e5) / e5);
  EXPECT_LT(rms, 0.3);
  EXPECT_NEAR(e56, e5, 0.1 * e5);
}

TEST(Recluster, FewerVdlsKeepTheIrradiance) {
  const VdlGrid& g = baked().bake6;
  VdlGrid two = reclusterVdlGrid(g, clusterParams(2));
  EXPECT_EQ(two.maxVdls, 2);
  ASSERT_EQ(two.coords, g.coords);
  EXPECT_EQ(two.irradiance, g.irradiance);
  double worstSum = 0;
  size_t grew = 0;
  for (size_t v = 0; v < g.size(); ++v) {
    EXPECT_LE(two.vdlCount[v], 2);
    if (average(g.irradiance[v]) > 0) {
      worstSum = std::max(worstSum, channelRelDiff(vdlSum(two, v), g.irradiance[v]));
    }
    grew += two.angularError[v] >= g.angularError[v];
  }
  EXPECT_LE(worstSum, 1e-4);
  EXPECT_EQ(grew, g.size()) << "merging VDLs never lowers the angular error";

  ClusterParams autoParams = clusterParams(8);
  autoParams.autoCount = true;
  VdlGrid autoGrid = reclusterVdlGrid(g, autoParams);
  EXPECT_EQ(autoGrid.maxVdls, 8);
  for (size_t v = 0; v < g.size(); ++v) EXPECT_LE(autoGrid.vdlCount[v], g.vdlCount[v]);
}

}  // namespace
}  // namespace lo
