#include "lightmap/lightmap_atlas.h"

#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include "core/error.h"
#include "lightmap/chart_param.h"

namespace lo {

namespace atlas_internal {

using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A point in a page, texel units (u * width, v * height).
struct Uv {
  double x = 0, y = 0;
};
inline Uv operator-(const Uv& a, const Uv& b) { return {a.x - b.x, a.y - b.y}; }
inline double dot(const Uv& a, const Uv& b) { return a.x * b.x + a.y * b.y; }

/// Stitching weights (least squares, see solveSeams): how firmly a texel
/// keeps its own value against the seam equations, whose weight is 1. Small,
/// so that the sides agree to about 1e-4 of their difference (the cube tests);
/// covered texels ten times firmer than dilated ones, so that the gutter,
/// which a renderer reads only through the bilinear lookups next to a chart's
/// border, takes most of the change and the covered texels keep the octree's
/// values (on a cube under one VDL they move by under 3% of the jump across
/// the seam). The price: a dilated texel may go below zero.
constexpr double kCoveredWeight = 1e-2;
constexpr double kDilatedWeight = 1e-3;

void checkInputs(const Scene& scene, const LightmapUvs& uvs, const AtlasBakeParams& params) {
  auto fail = [](const std::string& what) { throw InputError(what); };
  if (params.dilation < -1) {
    fail("AtlasBakeParams.dilation: " + std::to_string(params.dilation) +
         " is below -1 (-1 = the UVs' gutter, 0 = none)");
  }
  if (params.shade.maxVdls < 1 || params.shade.maxVdls > kMaxVdls) {
    fail("AtlasBakeParams.shade.maxVdls: " + std::to_string(params.shade.maxVdls) +
         " is outside [1, " + std::to_string(kMaxVdls) + "]");
  }
  if (!std::isfinite(params.shade.normalOffset)) {
    fail("AtlasBakeParams.shade.normalOffset: " + std::to_string(params.shade.normalOffset) +
         " is not finite");
  }
  checkSceneIndices(scene);
  const size_t nt = scene.triangleCount();
  auto sizeError = [&](const char* array, size_t size, size_t expected) {
    fail("LightmapUvs." + std::string(array) + " has " + std::to_string(size) + " values for " +
         std::to_string(nt) + " triangles (" + std::to_string(expected) +
         " expected): the UVs were made for another scene");
  };
  if (uvs.uv.size() != 6 * nt) sizeError("uv", uvs.uv.size(), 6 * nt);
  if (uvs.trianglePage.size() != nt) sizeError("trianglePage", uvs.trianglePage.size(), nt);
  if (uvs.triangleChart.size() != nt) sizeError("triangleChart", uvs.triangleChart.size(), nt);
  if (uvs.pageCount < 0 || (uvs.pageCount > 0 && (uvs.width < 1 || uvs.height < 1))) {
    fail("LightmapUvs: " + std::to_string(uvs.pageCount) + " page(s) of " +
         std::to_string(uvs.width) + " x " + std::to_string(uvs.height) + " texels");
  }
  for (size_t t = 0; t < nt; ++t) {
    if (uvs.triangleChart[t] < 0) continue;
    if (uvs.trianglePage[t] < 0 || uvs.trianglePage[t] >= uvs.pageCount) {
      fail("LightmapUvs.trianglePage: triangle " + std::to_string(t) + " is on page " +
           std::to_string(uvs.trianglePage[t]) + " of " + std::to_string(uvs.pageCount));
    }
    for (int i = 0; i < 6; ++i) {
      const float u = uvs.uv[6 * t + size_t(i)];
      if (!(u >= 0 && u <= 1)) {
        fail("LightmapUvs.uv: triangle " + std::to_string(t) + " has " + std::to_string(u) +
             ", outside [0, 1]");
      }
    }
  }
  if (!scene.normals.empty() && scene.normals.size() != scene.positions.size()) {
    fail("scene normals: " + std::to_string(scene.normals.size()) + " for " +
         std::to_string(scene.positions.size()) + " vertices");
  }
}

/// Corner k of triangle t in texel units of its page.
Uv corner(const LightmapUvs& uvs, size_t t, int k) {
  return {double(uvs.uv[6 * t + size_t(2 * k)]) * uvs.width,
          double(uvs.uv[6 * t + size_t(2 * k) + 1]) * uvs.height};
}

/// Barycentrics of the point of triangle abc nearest to p (Ericson,
/// Real-Time Collision Detection, §5.1.5): Voronoi regions of the corners and
/// edges by dot products only, so either winding works. abc must have area.
void closestPointBarycentrics(const Uv& p, const Uv& a, const Uv& b, const Uv& c, double bary[3]) {
  auto set = [bary](double u, double v, double w) {
    bary[0] = u;
    bary[1] = v;
    bary[2] = w;
  };
  const Uv ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return set(1, 0, 0);
  const Uv bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return set(0, 1, 0);
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) {
    const double v = d1 / (d1 - d3);
    return set(1 - v, v, 0);
  }
  const Uv cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return set(0, 0, 1);
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) {
    const double w = d2 / (d2 - d6);
    return set(1 - w, 0, w);
  }
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && d4 - d3 >= 0 && d5 - d6 >= 0) {
    const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return set(0, 1 - w, w);
  }
  const double denom = 1 / (va + vb + vc);
  const double v = vb * denom, w = vc * denom;
  set(1 - v - w, v, w);
}

/// Which triangle owns each texel of one page, and how far its footprint is
/// from the texel centre (squared, texel units; 0 = contains it).
struct PageRaster {
  std::vector<int32_t> triangle;
  std::vector<float> distance2;
};

/// Conservative rasterisation of one triangle (UV area != 0) into `raster`.
/// A texel square and the triangle overlap unless an axis separates them:
/// the two texel axes (the bounding-box range below) or a triangle edge's
/// outward normal, along which the square's nearest corner lies on or beyond
/// the edge's line. Touching (a shared boundary of no area) is not overlap.
void rasterTriangle(const LightmapUvs& uvs, size_t t, PageRaster& raster) {
  const Uv c[3] = {corner(uvs, t, 0), corner(uvs, t, 1), corner(uvs, t, 2)};
  const double area2 =
      (c[1].x - c[0].x) * (c[2].y - c[0].y) - (c[2].x - c[0].x) * (c[1].y - c[0].y);
  const double s = area2 > 0 ? 1 : -1;
  double nx[3], ny[3], offset[3], half[3];
  for (int k = 0; k < 3; ++k) {
    const Uv e = c[(k + 1) % 3] - c[k];
    nx[k] = s * e.y;  // outward: right of the edge for a counter-clockwise triangle
    ny[k] = -s * e.x;
    offset[k] = nx[k] * c[k].x + ny[k] * c[k].y;
    half[k] = 0.5 * (std::fabs(nx[k]) + std::fabs(ny[k]));
  }
  const double minX = std::min({c[0].x, c[1].x, c[2].x}), maxX = std::max({c[0].x, c[1].x, c[2].x});
  const double minY = std::min({c[0].y, c[1].y, c[2].y}), maxY = std::max({c[0].y, c[1].y, c[2].y});
  const int x0 = std::max(0, int(std::floor(minX)));
  const int x1 = std::min(uvs.width - 1, int(std::ceil(maxX)) - 1);
  const int y0 = std::max(0, int(std::floor(minY)));
  const int y1 = std::min(uvs.height - 1, int(std::ceil(maxY)) - 1);
  for (int y = y0; y <= y1; ++y) {
    for (int x = x0; x <= x1; ++x) {
      const Uv centre{x + 0.5, y + 0.5};
      bool inside = true, separated = false;
      for (int k = 0; k < 3 && !separated; ++k) {
        const double f = nx[k] * centre.x + ny[k] * centre.y - offset[k];
        separated = f - half[k] >= 0;
        inside = inside && f <= 0;
      }
      if (separated) continue;
      float d2 = 0;
      if (!inside) {
        double b[3];
        closestPointBarycentrics(centre, c[0], c[1], c[2], b);
        const double px = b[0] * c[0].x + b[1] * c[1].x + b[2] * c[2].x - centre.x;
        const double py = b[0] * c[0].y + b[1] * c[1].y + b[2] * c[2].y - centre.y;
        d2 = float(px * px + py * py);
      }
      const size_t i = size_t(y) * size_t(uvs.width) + size_t(x);
      // Triangles come in index order: an equal distance keeps the lower index.
      if (d2 < raster.distance2[i]) {
        raster.distance2[i] = d2;
        raster.triangle[i] = int32_t(t);
      }
    }
  }
}

/// The surface point and shading normal of texel `i` owned by triangle t,
/// and the point's barycentrics b.
void texelSurface(const Scene& scene, const LightmapUvs& uvs, size_t t, size_t i, Vec3& position,
                  Vec3& normal, double b[3]) {
  const Uv centre{double(i % size_t(uvs.width)) + 0.5, double(i / size_t(uvs.width)) + 0.5};
  closestPointBarycentrics(centre, corner(uvs, t, 0), corner(uvs, t, 1), corner(uvs, t, 2), b);
  const uint32_t* v = &scene.indices[3 * t];
  double p[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const Vec3& q = scene.positions[v[k]];
    p[0] += b[k] * double(q.x);
    p[1] += b[k] * double(q.y);
    p[2] += b[k] * double(q.z);
  }
  position = {float(p[0]), float(p[1]), float(p[2])};
  normal = {0, 0, 0};
  if (!scene.normals.empty()) {
    for (int k = 0; k < 3; ++k) normal += scene.normals[v[k]] * float(b[k]);
    normal = normalize(normal);
  }
  // No vertex normals, or ones that cancel (a folded sheet): the winding's.
  if (!(lengthSquared(normal) > 0.5f)) normal = scene.faceNormal(t);
}

/// Rec. 709 luminance.
float luminance(const Vec3& c) { return 0.2126f * c.x + 0.7152f * c.y + 0.0722f * c.z; }

Vec3 unitOrZero(const Vec3& v) {
  const float l = length(v);
  return l > 0 && std::isfinite(l) ? v / l : Vec3{0, 0, 0};
}

/// Fills `rings` rings of empty texels: each ring, every empty texel with a
/// filled 8-neighbour gets the mean of its filled neighbours (all of a ring
/// computed before any is written, so the order does not matter). `extra`
/// images (albedo, emission), when given, are averaged the same way.
void dilatePage(int width, int height, int rings, std::vector<uint8_t>& coverage, RgbImage& e,
                RgbImage& d, size_t& dilated, const std::vector<RgbImage*>& extra = {}) {
  constexpr uint8_t kPending = 255;
  std::vector<size_t> frontier, next;
  for (size_t i = 0; i < coverage.size(); ++i)
    if (coverage[i] == kAtlasCovered) frontier.push_back(i);
  std::vector<Vec3> eNext, dNext, xNext;
  for (int ring = 0; ring < rings && !frontier.empty(); ++ring) {
    next.clear();
    for (size_t i : frontier) {
      const int x = int(i % size_t(width)), y = int(i / size_t(width));
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const size_t j = size_t(ny) * size_t(width) + size_t(nx);
          if (coverage[j] != kAtlasEmpty) continue;
          coverage[j] = kPending;
          next.push_back(j);
        }
      }
    }
    std::sort(next.begin(), next.end());
    eNext.assign(next.size(), Vec3{0, 0, 0});
    dNext.assign(next.size(), Vec3{0, 0, 0});
    xNext.assign(next.size() * extra.size(), Vec3{0, 0, 0});
    for (size_t k = 0; k < next.size(); ++k) {
      const int x = int(next[k] % size_t(width)), y = int(next[k] / size_t(width));
      Vec3 es{0, 0, 0}, ds{0, 0, 0};
      Vec3* xs = xNext.data() + k * extra.size();
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= width || ny >= height) continue;
          const size_t j = size_t(ny) * size_t(width) + size_t(nx);
          if (coverage[j] != kAtlasCovered && coverage[j] != kAtlasDilated) continue;
          es += e.at(j);
          ds += d.at(j);
          for (size_t m = 0; m < extra.size(); ++m) xs[m] += extra[m]->at(j);
          ++count;
        }
      }
      eNext[k] = es / float(count);
      dNext[k] = unitOrZero(ds);
      for (size_t m = 0; m < extra.size(); ++m) xs[m] = xs[m] / float(count);
    }
    for (size_t k = 0; k < next.size(); ++k) {
      coverage[next[k]] = kAtlasDilated;
      e.set(next[k], eNext[k]);
      d.set(next[k], dNext[k]);
      for (size_t m = 0; m < extra.size(); ++m) extra[m]->set(next[k], xNext[k * extra.size() + m]);
    }
    dilated += next.size();
    frontier.swap(next);
  }
}

/// One seam equation: the bilinear lookup of side a minus that of side b at
/// one point of a seam edge, over the texels it reads that are not empty
/// (empty texels read as the constant 0 they hold).
struct SeamRow {
  int32_t first = 0, count = 0;  ///< its entries in SeamSystem::column / weight
};

struct SeamSystem {
  std::vector<SeamRow> rows;
  std::vector<int32_t> column;                ///< unknown index
  std::vector<double> weight;                 ///< + bilinear weight on side a, - on side b
  std::vector<size_t> texelPage, texelIndex;  ///< per unknown
  size_t edges = 0;
};

/// Adds the bilinear footprint of point p (texel units) of `page` to the
/// current row with sign `sign`.
void addFootprint(const LightmapAtlas& atlas, int page, const Uv& p, double sign,
                  std::unordered_map<uint64_t, int32_t>& unknownOf, SeamSystem& system) {
  const double fx = p.x - 0.5, fy = p.y - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const double tx = fx - x0, ty = fy - y0;
  for (int k = 0; k < 4; ++k) {
    const int x = x0 + (k & 1), y = y0 + (k >> 1);
    const double w = ((k & 1) ? tx : 1 - tx) * ((k >> 1) ? ty : 1 - ty);
    if (w <= 0 || x < 0 || y < 0 || x >= atlas.width || y >= atlas.height) continue;
    const size_t i = size_t(y) * size_t(atlas.width) + size_t(x);
    if (atlas.coverage[size_t(page)][i] == kAtlasEmpty) continue;
    const uint64_t key = uint64_t(page) * uint64_t(atlas.width) * uint64_t(atlas.height) + i;
    auto [it, added] = unknownOf.try_emplace(key, int32_t(system.texelPage.size()));
    if (added) {
      system.texelPage.push_back(size_t(page));
      system.texelIndex.push_back(i);
    }
    system.column.push_back(it->second);
    system.weight.push_back(sign * w);
    ++system.rows.back().count;
  }
}

/// The seam equations: for each edge two consistently oriented triangles
/// share in 3D (ChartTopology's neighbours, welded by exact position) whose
/// UVs or pages differ, points at the centres of n equal parts, n about two
/// per texel of the longer side.
SeamSystem seamSystem(const Scene& scene, const LightmapUvs& uvs, const LightmapAtlas& atlas) {
  SeamSystem system;
  const lightmap_internal::ChartTopology topo = lightmap_internal::buildChartTopology(scene);
  std::unordered_map<uint64_t, int32_t> unknownOf;
  auto weldOf = [&](size_t t, int k) { return topo.weld[scene.indices[3 * t + size_t(k)]]; };
  auto sameUv = [&](size_t t, int k, size_t u, int j) {
    return uvs.uv[6 * t + size_t(2 * k)] == uvs.uv[6 * u + size_t(2 * j)] &&
           uvs.uv[6 * t + size_t(2 * k) + 1] == uvs.uv[6 * u + size_t(2 * j) + 1];
  };
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (uvs.triangleChart[t] < 0) continue;
    for (int k = 0; k < 3; ++k) {
      const int32_t other = topo.neighbour[3 * t + size_t(k)];
      if (other < int32_t(t) || uvs.triangleChart[size_t(other)] < 0) continue;
      const size_t u = size_t(other);
      const int32_t wa = weldOf(t, k), wb = weldOf(t, (k + 1) % 3);
      int j = 0;
      while (j < 3 && !(weldOf(u, j) == wb && weldOf(u, (j + 1) % 3) == wa)) ++j;
      LO_CHECK_LT(j, 3);
      const int ka = k, kb = (k + 1) % 3;  // t's corners at the end points a, b
      const int ja = (j + 1) % 3, jb = j;  // u's corners at a, b
      const int pt = uvs.trianglePage[t], pu = uvs.trianglePage[u];
      if (pt == pu && sameUv(t, ka, u, ja) && sameUv(t, kb, u, jb)) continue;
      ++system.edges;
      const Uv a0 = corner(uvs, t, ka), a1 = corner(uvs, t, kb);
      const Uv b0 = corner(uvs, u, ja), b1 = corner(uvs, u, jb);
      const Uv da = a1 - a0, db = b1 - b0;
      const double texels = std::sqrt(std::max(dot(da, da), dot(db, db)));
      const int n = std::max(1, int(std::ceil(2 * texels)));
      for (int i = 0; i < n; ++i) {
        const double s = (i + 0.5) / n;
        system.rows.push_back({int32_t(system.column.size()), 0});
        addFootprint(atlas, pt, {a0.x + s * da.x, a0.y + s * da.y}, 1, unknownOf, system);
        addFootprint(atlas, pu, {b0.x + s * db.x, b0.y + s * db.y}, -1, unknownOf, system);
      }
    }
  }
  return system;
}

/// Largest |row . x| over the seam equations, any of the three channels.
float seamMismatch(const SeamSystem& system, const LightmapAtlas& atlas) {
  double worst = 0;
  for (const SeamRow& row : system.rows) {
    double sum[3] = {0, 0, 0};
    for (int32_t e = row.first; e < row.first + row.count; ++e) {
      const size_t k = size_t(system.column[size_t(e)]);
      const Vec3 v = atlas.irradiance[system.texelPage[k]].at(system.texelIndex[k]);
      for (int c = 0; c < 3; ++c) sum[c] += system.weight[size_t(e)] * double(v[c]);
    }
    for (int c = 0; c < 3; ++c) worst = std::max(worst, std::fabs(sum[c]));
  }
  return float(worst);
}

/// Least squares over the texels the seam equations read (x, one channel at
/// a time): minimise sum_rows (row . x)^2 + sum_k w_k^2 (x_k - x0_k)^2, w_k
/// kCoveredWeight or kDilatedWeight. The normal equations (A^T A + W^2) x =
/// W^2 x0 are symmetric positive definite; one LDL^T factorisation serves the
/// channels. Irradiance must not go below zero where it is seen: covered
/// texels that the solve pushes below zero are pinned (kPinnedWeight) at
/// their clamped values and the solve repeated once, so that the texels
/// around them make up for it (any still below zero are clamped). The
/// directions are then solved with the final weights and renormalised.
/// Dilated texels may stay below zero: they only ever reach a picture
/// blended with the covered texels next to them.
void solveSeamPart(const SeamSystem& system, LightmapAtlas& atlas) {
  constexpr double kPinnedWeight = 1e2;
  const int unknowns = int(system.texelPage.size());
  if (unknowns == 0) return;
  std::vector<Eigen::Triplet<double>> triplets;
  triplets.reserve(system.column.size());
  for (size_t r = 0; r < system.rows.size(); ++r) {
    const SeamRow& row = system.rows[r];
    for (int32_t e = row.first; e < row.first + row.count; ++e) {
      triplets.emplace_back(int(r), system.column[size_t(e)], system.weight[size_t(e)]);
    }
  }
  Eigen::SparseMatrix<double> a(int(system.rows.size()), unknowns);
  a.setFromTriplets(triplets.begin(), triplets.end());
  const Eigen::SparseMatrix<double> ata = a.transpose() * a;
  Eigen::VectorXd w2(unknowns);
  std::vector<uint8_t> covered(static_cast<size_t>(unknowns), 0);
  for (int k = 0; k < unknowns; ++k) {
    covered[size_t(k)] =
        atlas.coverage[system.texelPage[size_t(k)]][system.texelIndex[size_t(k)]] == kAtlasCovered;
    const double w = covered[size_t(k)] ? kCoveredWeight : kDilatedWeight;
    w2[k] = w * w;
  }
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  auto factorize = [&] {
    Eigen::SparseMatrix<double> normal = ata;
    for (int k = 0; k < unknowns; ++k) normal.coeffRef(k, k) += w2[k];
    solver.compute(normal);
    LO_CHECK(solver.info() == Eigen::Success);
  };
  auto values = [&](const std::vector<RgbImage>& pages) {
    Eigen::MatrixXd v(unknowns, 3);
    for (int k = 0; k < unknowns; ++k) {
      const Vec3 t = pages[system.texelPage[size_t(k)]].at(system.texelIndex[size_t(k)]);
      for (int c = 0; c < 3; ++c) v(k, c) = double(t[c]);
    }
    return v;
  };
  auto solve = [&](Eigen::MatrixXd target) {
    for (int k = 0; k < unknowns; ++k) target.row(k) *= w2[k];
    Eigen::MatrixXd x = solver.solve(target);
    LO_CHECK(solver.info() == Eigen::Success);
    return x;
  };

  factorize();
  Eigen::MatrixXd target = values(atlas.irradiance);
  Eigen::MatrixXd e = solve(target);
  bool pinned = false;
  for (int k = 0; k < unknowns; ++k) {
    if (!covered[size_t(k)] || e.row(k).minCoeff() >= 0) continue;
    target.row(k) = e.row(k).cwiseMax(0.0);
    w2[k] = kPinnedWeight * kPinnedWeight;
    pinned = true;
  }
  if (pinned) {
    factorize();
    e = solve(target);
  }
  const Eigen::MatrixXd d = solve(values(atlas.direction));
  for (int k = 0; k < unknowns; ++k) {
    const size_t page = system.texelPage[size_t(k)], i = system.texelIndex[size_t(k)];
    Vec3 v{float(e(k, 0)), float(e(k, 1)), float(e(k, 2))};
    atlas.irradiance[page].set(i, covered[size_t(k)] ? max(v, Vec3{0, 0, 0}) : v);
    atlas.direction[page].set(i, unitOrZero(Vec3{float(d(k, 0)), float(d(k, 1)), float(d(k, 2))}));
  }
}

/// solveSeamPart over each set of texels the seam equations join (the
/// system is block-diagonal, one block a set): the same least squares, the
/// memory of the largest set at a time. One set for the whole: the system
/// as it is. 10,000 triangles in 15,000 charts stitched 914,645 texels in
/// one system of 1.3 GiB (H14-5-4); each instance of a model is a set.
void solveSeams(const SeamSystem& system, LightmapAtlas& atlas) {
  const size_t unknowns = system.texelPage.size();
  std::vector<int32_t> parent(unknowns);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&parent](int32_t k) {
    while (parent[size_t(k)] != k) k = parent[size_t(k)] = parent[size_t(parent[size_t(k)])];
    return k;
  };
  for (const SeamRow& row : system.rows) {
    if (row.count == 0) continue;
    int32_t first = root(system.column[size_t(row.first)]);
    for (int32_t e = row.first + 1; e < row.first + row.count; ++e) {
      const int32_t other = root(system.column[size_t(e)]);
      if (other == first) continue;
      // The smaller root stays: `first` is always the row's root.
      if (other < first) {
        parent[size_t(first)] = other;
        first = other;
      } else {
        parent[size_t(other)] = first;
      }
    }
  }
  // Sets in the order of their first texel; each one's rows in order.
  std::vector<int32_t> setOf(unknowns, -1);
  std::vector<int32_t> setOfRoot(unknowns, -1);
  int32_t sets = 0;
  for (size_t k = 0; k < unknowns; ++k) {
    const int32_t r = root(int32_t(k));
    if (setOfRoot[size_t(r)] < 0) setOfRoot[size_t(r)] = sets++;
    setOf[k] = setOfRoot[size_t(r)];
  }
  if (sets <= 1) {
    solveSeamPart(system, atlas);
    return;
  }
  std::vector<std::vector<int32_t>> rowsOf(static_cast<size_t>(sets));
  std::vector<std::vector<int32_t>> texelsOf(static_cast<size_t>(sets));
  for (size_t r = 0; r < system.rows.size(); ++r) {
    const SeamRow& row = system.rows[r];
    if (row.count == 0) continue;
    rowsOf[size_t(setOf[size_t(system.column[size_t(row.first)])])].push_back(int32_t(r));
  }
  for (size_t k = 0; k < unknowns; ++k) texelsOf[size_t(setOf[k])].push_back(int32_t(k));
  std::vector<int32_t> local(unknowns, -1);
  for (int32_t set = 0; set < sets; ++set) {
    if (rowsOf[size_t(set)].empty()) continue;  // no equation: the texels keep their values
    SeamSystem part;
    for (const int32_t k : texelsOf[size_t(set)]) {
      local[size_t(k)] = int32_t(part.texelPage.size());
      part.texelPage.push_back(system.texelPage[size_t(k)]);
      part.texelIndex.push_back(system.texelIndex[size_t(k)]);
    }
    for (const int32_t r : rowsOf[size_t(set)]) {
      const SeamRow& row = system.rows[size_t(r)];
      part.rows.push_back({int32_t(part.column.size()), row.count});
      for (int32_t e = row.first; e < row.first + row.count; ++e) {
        LO_CHECK(setOf[size_t(system.column[size_t(e)])] == set);
        part.column.push_back(local[size_t(system.column[size_t(e)])]);
        part.weight.push_back(system.weight[size_t(e)]);
      }
    }
    solveSeamPart(part, atlas);
  }
}

}  // namespace atlas_internal

std::string LightmapAtlas::ToString() const {
  std::ostringstream os;
  os << "LightmapAtlas{" << pageCount << " page(s) of " << width << "x" << height << ", "
     << coveredTexels << " covered + " << dilatedTexels << " dilated texels (" << dilation
     << " rings), " << skippedTriangles << " triangles without area, " << seamEdges
     << " seam edges, " << seamSamples << " samples, " << stitchedTexels
     << " texels stitched, seam mismatch " << seamMismatchBefore << " -> " << seamMismatchAfter
     << " W/m^2; raster " << rasterSeconds << " s, evaluate " << evaluateSeconds << " s, dilate "
     << dilateSeconds << " s, stitch " << stitchSeconds << " s}";
  return os.str();
}

std::vector<int8_t> atlasSurfaceSides(const Scene& scene, const GpuOctree& octree,
                                      const OctreeShadeParams& shade) {
  const size_t nt = scene.triangleCount();
  std::vector<int8_t> sides(nt, 1);
  if (octree.depth <= 0) return sides;
  // Each point's own voxel alone: the trilinear lookup lends a side that no
  // light reaches (the inside of a box) its neighbours' light.
  OctreeShadeParams own = shade;
  own.interpolation = false;
  for (size_t t = 0; t < nt; ++t) {
    {
      const int32_t m = scene.triangleMaterial[t];
      if (m < 0 || size_t(m) >= scene.materials.size()) continue;
      const Material& material = scene.materials[size_t(m)];
      if (material.backFaceCulling && !material.doubleSided) continue;  // one side drawn
      const uint32_t* v = &scene.indices[3 * t];
      const Vec3 a = scene.positions[v[0]], b = scene.positions[v[1]], c = scene.positions[v[2]];
      Vec3 n{0, 0, 0};
      if (!scene.normals.empty()) {
        n = normalize(scene.normals[v[0]] + scene.normals[v[1]] + scene.normals[v[2]]);
      }
      if (!(lengthSquared(n) > 0.5f)) n = scene.faceNormal(t);  // as texelSurface
      // Seven points spread over the triangle (its centroid, the midpoints of
      // its edges, its corners a tenth of the way in): a large floor
      // triangle's centroid may lie under a box, in the dark on both sides.
      const Vec3 centroid = (a + b + c) * (1.0f / 3.0f);
      const Vec3 points[7] = {centroid,           (a + b) * 0.5f,
                              (b + c) * 0.5f,     (c + a) * 0.5f,
                              a + (centroid - a) * 0.1f, b + (centroid - b) * 0.1f,
                              c + (centroid - c) * 0.1f};
      double front = 0, back = 0;
      for (const Vec3& p : points) {
        front += luminance(octreeIrradianceSample(octree, p, n, own).irradiance);
        back += luminance(octreeIrradianceSample(octree, p, -n, own).irradiance);
      }
      if (back > front) sides[t] = -1;
    }
  }
  return sides;
}

LightmapAtlas bakeLightmapAtlas(const Scene& scene, const LightmapUvs& uvs, const GpuOctree& octree,
                                const AtlasBakeParams& params) {
  using namespace atlas_internal;
  checkInputs(scene, uvs, params);
  LightmapAtlas atlas;
  atlas.width = uvs.width;
  atlas.height = uvs.height;
  atlas.pageCount = uvs.pageCount;
  atlas.dilation = params.dilation >= 0 ? params.dilation : std::max(1, uvs.gutter);
  const size_t texels = size_t(uvs.width) * size_t(uvs.height);
  const size_t nt = scene.triangleCount();

  // Triangles by page, in index order (a counting sort).
  std::vector<size_t> pageStart(size_t(uvs.pageCount) + 1, 0);
  for (size_t t = 0; t < nt; ++t)
    if (uvs.triangleChart[t] >= 0) ++pageStart[size_t(uvs.trianglePage[t]) + 1];
  for (size_t p = 1; p < pageStart.size(); ++p) pageStart[p] += pageStart[p - 1];
  std::vector<int32_t> byPage(pageStart.back());
  {
    std::vector<size_t> fill(pageStart.begin(), pageStart.end() - 1);
    for (size_t t = 0; t < nt; ++t)
      if (uvs.triangleChart[t] >= 0) byPage[fill[size_t(uvs.trianglePage[t])]++] = int32_t(t);
  }

  const bool direct = bool(params.directLight);
  PageRaster raster;
  // Per page, with params.radiance: the albedo and emission at each texel's
  // surface point (dilated like E), combined with the stitched E at the end.
  std::vector<RgbImage> albedo, emission;
  AtlasPageEvaluator* const evaluator = params.evaluator;
  if (evaluator) evaluator->begin(scene, uvs, octree, params.shade);
  // The side each texel holds (the evaluator finds the same).
  const std::vector<int8_t> sides = atlasSurfaceSides(scene, octree, params.shade);
  Progress progress(params.progress, "lightmap: atlas",
                    size_t(uvs.pageCount) * (size_t(uvs.height) + 1) + 1);
  std::vector<int32_t> pageTriangles;
  for (int page = 0; page < uvs.pageCount; ++page) {
    auto start = Clock::now();
    pageTriangles.clear();
    for (size_t k = pageStart[size_t(page)]; k < pageStart[size_t(page) + 1]; ++k) {
      const size_t t = size_t(byPage[k]);
      const float* p = &uvs.uv[6 * t];
      const double area2 = (double(p[2]) - p[0]) * (double(p[5]) - p[1]) -
                           (double(p[4]) - p[0]) * (double(p[3]) - p[1]);
      if (area2 == 0) {
        ++atlas.skippedTriangles;
        continue;
      }
      pageTriangles.push_back(int32_t(t));
    }
    RgbImage e(uvs.width, uvs.height), d(uvs.width, uvs.height);
    if (evaluator) {
      AtlasPageTexels done = evaluator->evaluatePage(page, pageTriangles);
      progress.advance(size_t(uvs.height));  // the page's rows, at once
      if (done.triangle.size() != texels || done.irradiance.width != uvs.width ||
          done.irradiance.height != uvs.height || done.direction.width != uvs.width ||
          done.direction.height != uvs.height) {
        throw InternalError("atlas: the page evaluator returned a page of another size");
      }
      raster.triangle = std::move(done.triangle);
      e = std::move(done.irradiance);
      d = std::move(done.direction);
      atlas.evaluateSeconds += secondsSince(start);
    } else {
      raster.triangle.assign(texels, -1);
      raster.distance2.assign(texels, std::numeric_limits<float>::infinity());
      for (int32_t t : pageTriangles) rasterTriangle(uvs, size_t(t), raster);
      atlas.rasterSeconds += secondsSince(start);
    }
    std::vector<uint8_t> coverage(texels, kAtlasEmpty);

    start = Clock::now();
    std::vector<AtlasSurfacePoint> directPoints;
    if (params.radiance) {
      albedo.push_back(RgbImage(uvs.width, uvs.height));
      emission.push_back(RgbImage(uvs.width, uvs.height));
    }
    // The surface points themselves are needed only to evaluate the octree
    // here, for the direct light and for the radiance.
    const bool needSurface = !evaluator || direct || params.radiance;
    for (size_t i = 0; i < texels; ++i) {
      if (!evaluator && (i + 1) % size_t(uvs.width) == 0) progress.advance();  // a row
      if (raster.triangle[i] < 0) continue;
      const size_t t = size_t(raster.triangle[i]);
      if (t >= nt) {
        throw InternalError("atlas: the page evaluator named triangle " + std::to_string(t));
      }
      Vec3 position{0, 0, 0}, normal{0, 0, 1};
      double b[3] = {1, 0, 0};
      if (needSurface) {
        texelSurface(scene, uvs, t, i, position, normal, b);
        if (sides[t] < 0) normal = -normal;
      }
      if (!evaluator) {
        const OctreeIrradianceSample s =
            octreeIrradianceSample(octree, position, normal, params.shade);
        e.set(i, s.irradiance);
        d.set(i, unitOrZero(s.directionSum));
      }
      if (params.radiance) {
        albedo.back().set(i, scene.albedo(t, float(b[1]), float(b[2])));
        emission.back().set(i, scene.emission(t, float(b[1]), float(b[2])));
      }
      coverage[i] = kAtlasCovered;
      ++atlas.coveredTexels;
      if (direct) directPoints.push_back({position, uint32_t(t), normal});
    }
    if (direct) {
      // The direct light of the covered texels in parallel, in texel order.
      // A page's direct light took 80 s without a report (H12-5-31).
      const std::vector<Vec3> light =
          params.directLight(directPoints, page, [&progress] { progress.heartbeat(); });
      if (light.size() != directPoints.size()) {
        throw InternalError("atlas: the direct light gave " + std::to_string(light.size()) +
                            " values for " + std::to_string(directPoints.size()) + " texels");
      }
      size_t k = 0;
      for (size_t i = 0; i < texels; ++i) {
        if (coverage[i] == kAtlasCovered) e.set(i, e.at(i) + light[k++]);
      }
      directPoints.clear();
    }
    atlas.evaluateSeconds += secondsSince(start);

    start = Clock::now();
    std::vector<RgbImage*> extra;
    if (params.radiance) extra = {&albedo.back(), &emission.back()};
    dilatePage(uvs.width, uvs.height, atlas.dilation, coverage, e, d, atlas.dilatedTexels, extra);
    atlas.dilateSeconds += secondsSince(start);
    progress.advance();
    atlas.irradiance.push_back(std::move(e));
    atlas.direction.push_back(std::move(d));
    atlas.coverage.push_back(std::move(coverage));
  }

  // Seams join pages: stitched once all pages are evaluated and dilated (the
  // bilinear lookups at a chart's border read the first dilated ring).
  const auto start = Clock::now();
  const SeamSystem system = seamSystem(scene, uvs, atlas);
  atlas.seamEdges = system.edges;
  atlas.seamSamples = system.rows.size();
  atlas.seamMismatchBefore = atlas.seamMismatchAfter = seamMismatch(system, atlas);
  if (params.stitchSeams) {
    solveSeams(system, atlas);
    atlas.stitchedTexels = system.texelPage.size();
    atlas.seamMismatchAfter = seamMismatch(system, atlas);
  }
  atlas.stitchSeconds = secondsSince(start);
  progress.advance();

  if (params.radiance) {
    // L = albedo / pi * E + emission from the final E: a seam joined in E is
    // joined in L wherever the albedo agrees (LightmapAtlas::radiance).
    const auto radianceStart = Clock::now();
    for (int page = 0; page < atlas.pageCount; ++page) {
      const size_t p = size_t(page);
      RgbImage l(atlas.width, atlas.height);
      for (size_t i = 0; i < texels; ++i) {
        if (atlas.coverage[p][i] == kAtlasEmpty) continue;
        l.set(i, albedo[p].at(i) * atlas.irradiance[p].at(i) * (1.0f / kPi) + emission[p].at(i));
      }
      atlas.radiance.push_back(std::move(l));
    }
    atlas.evaluateSeconds += secondsSince(radianceStart);
  }
  return atlas;
}

}  // namespace lo
