// The chart step's cost grows with its input near-linearly (issue 43,
// family 5: 10^6 small triangles took minutes), checked by the work each
// part counts, not by time: the packing offers each rectangle about once
// whatever the page count, the minimal rectangle projects each hull point a
// few times, the edge topology does not scan a vertex's triangles per edge.
// And each still gives what the quadratic form gave.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "core/rng.h"
#include "lightmap/atlas_pack.h"
#include "lightmap/chart_param.h"
#include "test_util.h"

namespace lo {
namespace {

using lightmap_internal::RectPlacement;
using lightmap_internal::RectSize;

TEST(ChartGrowth, EachRectangleIsOfferedToAboutOnePageWhateverThePageCount) {
  // 100,000 rectangles of 3 to 5 texels a side on pages of 64^2: ~400 pages.
  // Offering each page every rectangle that remained was 2 * 10^7 offers.
  std::vector<RectSize> rects;
  Rng rng(3, 0);
  for (int i = 0; i < 100000; ++i)
    rects.push_back({3 + int(rng.uniform() * 3), 3 + int(rng.uniform() * 3)});
  const int size = 64;
  std::vector<RectPlacement> placement;
  size_t offered = 0;
  const int pages = lightmap_internal::packRects(rects, size, 1 << 20, placement, &offered);
  ASSERT_GT(pages, 200);
  EXPECT_LE(offered, 3 * rects.size()) << pages << " pages";
  // Every rectangle placed, inside its page, none overlapping another.
  std::vector<uint8_t> used(size_t(pages) * size * size, 0);
  double area = 0;
  for (size_t i = 0; i < rects.size(); ++i) {
    const RectPlacement& p = placement[i];
    ASSERT_TRUE(p.page >= 0 && p.page < pages) << "rectangle " << i;
    ASSERT_TRUE(p.x >= 0 && p.y >= 0 && p.x + rects[i].w <= size && p.y + rects[i].h <= size);
    for (int y = p.y; y < p.y + rects[i].h; ++y)
      for (int x = p.x; x < p.x + rects[i].w; ++x) {
        uint8_t& texel = used[(size_t(p.page) * size + size_t(y)) * size + size_t(x)];
        ASSERT_EQ(texel, 0) << "rectangle " << i << " overlaps at page " << p.page;
        texel = 1;
      }
    area += double(rects[i].w) * rects[i].h;
  }
  // The pages are still well used (about 0.85 with every page offered all).
  EXPECT_GT(area / (double(pages) * size * size), 0.8);

  // Within kPackOfferPages pages of area every page is offered everything:
  // a single page either holds them all or reports that it cannot.
  std::vector<RectSize> few(rects.begin(), rects.begin() + 300);
  offered = 0;
  EXPECT_EQ(lightmap_internal::packRects(few, size, 1, placement, &offered), -1);
  EXPECT_EQ(offered, few.size());
}

/// The least area of a rectangle around the points with a side along the
/// direction of some pair of them (the minimal one has a side along a hull
/// edge): n^3, for a check.
double bruteMinimalArea(const std::vector<double>& xy) {
  const size_t n = xy.size() / 2;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < n; ++i)
    for (size_t j = 0; j < n; ++j) {
      double dx = xy[2 * j] - xy[2 * i], dy = xy[2 * j + 1] - xy[2 * i + 1];
      const double len = std::sqrt(dx * dx + dy * dy);
      if (!(len > 0)) continue;
      dx /= len;
      dy /= len;
      double lo[2] = {INFINITY, INFINITY}, hi[2] = {-INFINITY, -INFINITY};
      for (size_t k = 0; k < n; ++k) {
        const double u = dx * xy[2 * k] + dy * xy[2 * k + 1];
        const double v = -dy * xy[2 * k] + dx * xy[2 * k + 1];
        lo[0] = std::min(lo[0], u);
        hi[0] = std::max(hi[0], u);
        lo[1] = std::min(lo[1], v);
        hi[1] = std::max(hi[1], v);
      }
      best = std::min(best, (hi[0] - lo[0]) * (hi[1] - lo[1]));
    }
  return best;
}

TEST(ChartGrowth, TheMinimalRectangleProjectsEachHullPointAFewTimes) {
  // A chart outlined by 20,000 vertices (a disc): every hull point for every
  // hull edge was 4 * 10^8 projections.
  const size_t h = 20000;
  std::vector<double> disc;
  for (size_t i = 0; i < h; ++i) {
    const double a = 2 * 3.14159265358979323846 * double(i) / double(h) + 0.1;
    disc.insert(disc.end(), {3 + std::cos(a), -2 + 0.5 * std::sin(a)});  // an ellipse 2 x 1
  }
  size_t projections = 0;
  double width = 0, height = 0;
  lightmap_internal::orientChart(disc, width, height, &projections);
  EXPECT_LE(projections, 32 * h);  // 23 h measured
  EXPECT_NEAR(width, 2.0, 1e-6);
  EXPECT_NEAR(height, 1.0, 1e-6);
  for (size_t i = 0; i < h; ++i) {
    ASSERT_TRUE(disc[2 * i] >= -1e-9 && disc[2 * i] <= width + 1e-9 && disc[2 * i + 1] >= -1e-9 &&
                disc[2 * i + 1] <= height + 1e-9)
        << "point " << i << " outside the rectangle";
  }

  // Random point sets: the same area as the brute force's.
  Rng rng(11, 0);
  for (int trial = 0; trial < 40; ++trial) {
    std::vector<double> xy;
    const int n = 3 + trial;
    for (int i = 0; i < n; ++i) {
      const double x = rng.uniform() * 4, y = rng.uniform() * (trial % 3 == 0 ? 0.3 : 2);
      xy.insert(xy.end(), {x, y});
    }
    const double expected = bruteMinimalArea(xy);
    std::vector<double> turned = xy;
    lightmap_internal::orientChart(turned, width, height);
    EXPECT_NEAR(width * height, expected, 1e-9 * expected) << "trial " << trial;
    EXPECT_GE(width, height);
  }
}

TEST(ChartGrowth, EdgesAroundAVertexOfTensOfThousandsOfTrianglesFindTheirNeighbours) {
  // A disc as one fan of 30,000 triangles around its centre (the neighbours
  // were found by scanning the centre's triangles per edge: 30,000^2).
  Scene scene = test::oneMaterialScene();
  const int k = 30000;
  scene.positions.push_back({0, 0, 0});
  for (int i = 0; i < k; ++i) {
    const float a = 2 * kPi * float(i) / float(k);
    scene.positions.push_back({std::cos(a), 0, -std::sin(a)});
  }
  for (int i = 0; i < k; ++i) {
    scene.indices.insert(scene.indices.end(), {0, uint32_t(1 + i), uint32_t(1 + (i + 1) % k)});
    scene.triangleMaterial.push_back(0);
  }
  // Three triangles on one edge (not manifold) and two that run an edge the
  // same way (not consistently oriented): seams.
  const uint32_t b = uint32_t(scene.positions.size());
  scene.positions.insert(scene.positions.end(), {{5, 0, 0},
                                                 {6, 0, 0},
                                                 {5.5f, 0, 1},
                                                 {5.5f, 0, -1},
                                                 {5.5f, 1, 0},
                                                 {8, 0, 0},
                                                 {9, 0, 0},
                                                 {8.5f, 0, 1},
                                                 {8.5f, 0, -1}});
  scene.indices.insert(scene.indices.end(), {b, b + 1, b + 2, b + 1, b, b + 3, b + 1, b, b + 4,
                                             b + 5, b + 6, b + 7, b + 5, b + 6, b + 8});
  scene.triangleMaterial.insert(scene.triangleMaterial.end(), {0, 0, 0, 0, 0});
  const lightmap_internal::ChartTopology topo = lightmap_internal::buildChartTopology(scene);
  for (int i = 0; i < k; ++i) {
    // Corner 0 -> 1 runs centre -> rim i (shared with the previous triangle),
    // 1 -> 2 the rim, 2 -> 0 rim i + 1 -> centre (shared with the next).
    ASSERT_EQ(topo.neighbour[3 * size_t(i)], (i + k - 1) % k) << "triangle " << i;
    ASSERT_EQ(topo.neighbour[3 * size_t(i) + 1], -1) << "triangle " << i;
    ASSERT_EQ(topo.neighbour[3 * size_t(i) + 2], (i + 1) % k) << "triangle " << i;
  }
  for (size_t t = size_t(k); t < scene.triangleCount(); ++t)
    for (int c = 0; c < 3; ++c) EXPECT_EQ(topo.neighbour[3 * t + size_t(c)], -1) << t << " " << c;
}

}  // namespace
}  // namespace lo
