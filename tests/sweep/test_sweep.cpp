// The sweep's logic (sweep/sweep.h): the point list, the Pareto front against
// a brute-force definition, the CSV rows.

#include <gtest/gtest.h>

#include <set>
#include <sstream>

#include "core/rng.h"
#include "octree/gpu_octree.h"
#include "sweep/sweep.h"

namespace lo {
namespace {

/// Parameters in which two points differ.
std::set<std::string> differences(const SweepPoint& a, const SweepPoint& b) {
  std::set<std::string> d;
  if (a.depth != b.depth) d.insert("depth");
  if (a.photons != b.photons) d.insert("photons");
  if (a.knn != b.knn) d.insert("knn");
  if (a.radiusVoxels != b.radiusVoxels) d.insert("radius");
  if (a.vdls != b.vdls) d.insert("vdls");
  if (a.interpolation != b.interpolation) d.insert("interpolation");
  if (a.halfFloat != b.halfFloat) d.insert("texels");
  if (a.cosineCorrection != b.cosineCorrection) d.insert("cosine");
  if (a.layers != b.layers || a.occlusion != b.occlusion || a.edgeCorrection != b.edgeCorrection ||
      a.smoothing != b.smoothing) {
    d.insert("accuracy");
  }
  if (a.representation != b.representation) d.insert("representation");
  if (a.tolerance != b.tolerance) d.insert("tolerance");
  return d;
}

/// A target point differs from the paper in its budget (a target, not a
/// count) and, for some, its depth: the "target" group.
std::set<std::string> targetDifferences(const SweepPoint& a, const SweepPoint& b) {
  std::set<std::string> d = differences(a, b);
  d.erase("depth");
  if (a.targetError != b.targetError) d.insert("target");
  return d;
}

TEST(SweepPoints, OneParameterAtATimeAroundThePaper) {
  for (SweepScale scale : {SweepScale::Full, SweepScale::Quick}) {
    const std::vector<SweepPoint> points = sweepPoints(scale);
    ASSERT_FALSE(points.empty());
    const SweepPoint paper = paperPoint();
    EXPECT_EQ(points.front().key(), paper.key());
    EXPECT_EQ(paper.depth, 6);
    EXPECT_EQ(paper.photons, 600000u);
    EXPECT_EQ(paper.knn, 300);
    EXPECT_EQ(paper.vdls, "4");
    std::set<std::string> keys, groups;
    for (const SweepPoint& p : points) {
      EXPECT_TRUE(keys.insert(p.key()).second) << "duplicate " << p.label();
      groups.insert(p.group);
      const std::set<std::string> d = differences(p, paper);
      if (p.group == "paper") {
        EXPECT_TRUE(d.empty());
      } else if (p.group == "target") {
        EXPECT_GT(p.targetError, 0.0) << p.label();
        EXPECT_EQ(targetDifferences(p, paper), std::set<std::string>{"target"}) << p.label();
      } else if (p.group == "combined" || (p.group == "tolerance" && p.representation != "vdl")) {
        EXPECT_GE(d.size(), 2u) << p.label();
      } else {
        EXPECT_EQ(d, std::set<std::string>{p.group}) << p.label();
      }
    }
    for (const char* g :
         {"depth", "photons", "knn", "vdls", "interpolation", "texels", "cosine", "accuracy",
          "representation", "tolerance", "target"})
      EXPECT_TRUE(groups.count(g)) << g;
  }
  // The full sweep covers the ranges.
  const std::vector<SweepPoint> full = sweepPoints(SweepScale::Full);
  std::set<int> depths, knns;
  std::set<size_t> photons;
  std::set<std::string> vdls;
  for (const SweepPoint& p : full) {
    depths.insert(p.depth);
    knns.insert(p.knn);
    photons.insert(p.photons);
    vdls.insert(p.vdls);
  }
  EXPECT_EQ(*depths.begin(), 3);
  EXPECT_EQ(*depths.rbegin(), 8);
  EXPECT_EQ(*photons.begin(), 50000u);
  EXPECT_EQ(*photons.rbegin(), 5000000u);
  EXPECT_EQ(*knns.begin(), 10);
  EXPECT_EQ(*knns.rbegin(), 1000);
  EXPECT_EQ(vdls, (std::set<std::string>{"1", "2", "4", "8", "auto"}));
}

TEST(SweepPoints, ThePaperPointIsTheBakeDefault) {
  // The sweep must label and bake its reference point with the settings
  // `lightoctree bake` uses without flags (it once hard-coded an old radius).
  const SweepPoint p = paperPoint();
  const BakeParams b;
  // The bake's depth is auto, which takes 6 on the sweep's scenes (boxes
  // of under 2 m): the sweep names the depth it takes.
  EXPECT_EQ(b.depth, kAutoDepth);
  EXPECT_EQ(p.depth, kAutoDepthMin);
  EXPECT_EQ(p.photons, b.photons);
  EXPECT_EQ(p.knn, b.knn);
  EXPECT_EQ(p.vdls, b.vdls.ToString());
  EXPECT_EQ(p.radiusVoxels, kDefaultRadiusVoxels);
  EXPECT_TRUE(p.cosineCorrection == GpuOctreeParams{}.cosineCorrection);
}

TEST(SweepPoints, KeysSeparateBakeFromLookup) {
  SweepPoint a = paperPoint(), b = paperPoint();
  b.interpolation = false;
  EXPECT_EQ(a.bakeKey(), b.bakeKey());
  EXPECT_NE(a.key(), b.key());
  b = paperPoint();
  b.radiusVoxels = 3.0f;
  EXPECT_NE(a.bakeKey(), b.bakeKey());
  EXPECT_EQ(a.label(), "d6 600k k300 r1.5 v4");
  b.photons = 2500000;
  b.halfFloat = true;
  EXPECT_EQ(b.label(), "d6 2.5M k300 r3 v4 half");
}

TEST(Pareto, MatchesTheDefinitionOnRandomSets) {
  EXPECT_EQ(paretoFront({1, 2, 3}, {3, 2, 1}), (std::vector<bool>{true, true, true}));
  EXPECT_EQ(paretoFront({1, 2, 3}, {1, 2, 3}), (std::vector<bool>{true, false, false}));
  EXPECT_EQ(paretoFront({1, 1}, {2, 2}), (std::vector<bool>{true, true}));  // ties both stay
  EXPECT_EQ(paretoFront({1, 1}, {2, 3}), (std::vector<bool>{true, false}));
  Rng rng(7, 0);
  for (int trial = 0; trial < 50; ++trial) {
    const size_t n = 1 + rng.uniformInt(30);
    std::vector<double> cost, error;
    for (size_t i = 0; i < n; ++i) {
      cost.push_back(double(rng.uniformInt(10)));
      error.push_back(double(rng.uniformInt(10)));
    }
    const std::vector<bool> front = paretoFront(cost, error);
    // Every point off the front is dominated by one on it; no point on the
    // front is dominated by any point.
    for (size_t i = 0; i < n; ++i) {
      bool dominatedByFront = false, dominated = false;
      for (size_t j = 0; j < n; ++j) {
        const bool dom = cost[j] <= cost[i] && error[j] <= error[i] &&
                         (cost[j] < cost[i] || error[j] < error[i]);
        dominated |= dom;
        dominatedByFront |= dom && front[j];
      }
      EXPECT_EQ(front[i], !dominated);
      if (!front[i]) {
        EXPECT_TRUE(dominatedByFront);
      }
    }
  }
}

TEST(SweepCsv, OneRowPerResultWithTheFlags) {
  std::vector<SweepResult> results(3);
  results[0].point = paperPoint();
  results[0].bakeSeconds = 2, results[0].gpuBytes = 1000, results[0].irradianceBinnedRelRmse = 0.1;
  results[1].point = paperPoint();
  results[1].point.depth = 5;
  results[1].bakeSeconds = 1, results[1].gpuBytes = 2000, results[1].irradianceBinnedRelRmse = 0.2;
  results[2].point = paperPoint();
  results[2].point.depth = 7;
  results[2].bakeSeconds = 3, results[2].gpuBytes = 3000, results[2].irradianceBinnedRelRmse = 0.3;
  // The fronts weigh the binned error: a per-pixel error that says otherwise is not read.
  results[2].irradianceRelRmse = 0.01;
  markParetoFronts(results);
  EXPECT_TRUE(results[0].paretoTime && results[1].paretoTime && !results[2].paretoTime);
  EXPECT_TRUE(results[0].paretoMemory && !results[1].paretoMemory && !results[2].paretoMemory);
  std::istringstream csv(sweepCsv(results));
  std::string line;
  std::vector<std::string> lines;
  while (std::getline(csv, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0].rfind("label,group,depth", 0), 0u);
  EXPECT_NE(lines[1].find("\"d6 600k k300 r1.5 v4\""), std::string::npos);
  EXPECT_EQ(lines[1].substr(lines[1].size() - 6), ",1,1,1");  // fronts and paper
  EXPECT_EQ(lines[3].substr(lines[3].size() - 6), ",0,0,0");
}

}  // namespace
}  // namespace lo
