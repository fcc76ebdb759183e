#include "lightmap/lightmap_uv.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <memory>
#include <numeric>
#include <sstream>
#include <tuple>

#include "core/error.h"
#include "core/resources.h"
#include "image/image.h"
#include "lightmap/atlas_pack.h"
#include "lightmap/chart_param.h"

namespace lo {

namespace {

using lightmap_internal::D3;
using lightmap_internal::FlatChart;
using lightmap_internal::RectPlacement;
using lightmap_internal::RectSize;

std::string sceneName(const Scene& scene) {
  return scene.sourcePath.empty() ? std::string("scene") : scene.sourcePath;
}

void checkParams(const LightmapUvParams& p) {
  auto fail = [](const std::string& field, const std::string& what) {
    throw InputError("LightmapUvParams." + field + ": " + what);
  };
  if (!(std::isfinite(p.texelSize) && p.texelSize >= 0)) {
    fail("texelSize", std::to_string(p.texelSize) + " is not a size >= 0 (0 = fit one page)");
  }
  if (p.gutter < 0) fail("gutter", std::to_string(p.gutter) + " is negative");
  if (p.atlasSize < 2 * p.gutter + 1 || p.atlasSize > (1 << 16)) {
    fail("atlasSize", std::to_string(p.atlasSize) + " is outside [2 * gutter + 1, 65536] (gutter " +
                          std::to_string(p.gutter) + ")");
  }
  if (!(p.chartConeDegrees > 0 && p.chartConeDegrees <= 180)) {
    fail("chartConeDegrees", std::to_string(p.chartConeDegrees) + " is outside (0, 180]");
  }
  if (!(p.maxStretch >= 1 && std::isfinite(p.maxStretch))) {
    fail("maxStretch", std::to_string(p.maxStretch) + " is below 1 (1 = isometric)");
  }
}

// Texels a chart of the given world extent occupies at texel size t: its
// extent plus a margin on both sides, so that float rounding of the UVs
// (2^-24 of the page) never pushes a corner into the next texel column.
// The margin of chartTexels for pages of `size` texels.
double uvMargin(int size) { return 1e-3 + double(size) * 1e-6; }

int chartTexels(double extent, double t, double margin) {
  // Saturated: a texel size of 1e-15 must not overflow the int (it did).
  return int(std::clamp(std::ceil(extent / t + 2 * margin), 1.0, double(1 << 30)));
}

// A chart's rectangle in texels: each carries the gutter on its right and
// top side; the page region starts one gutter in from the left and bottom
// border.
RectSize rectSize(const FlatChart& chart, double t, int gutter, double margin) {
  return {chartTexels(chart.width, t, margin) + gutter,
          chartTexels(chart.height, t, margin) + gutter};
}

std::vector<RectSize> rectSizes(const std::vector<const FlatChart*>& charts, double t, int gutter,
                                double margin) {
  std::vector<RectSize> sizes(charts.size());
  for (size_t c = 0; c < charts.size(); ++c) sizes[c] = rectSize(*charts[c], t, gutter, margin);
  return sizes;
}

// The texel size at which the charts fill about one page: the smallest that
// still packs into it, to within 0.5% (a geometric search from the size at
// which the rectangles' total area equals the page).
double fitOnePage(const std::vector<const FlatChart*>& charts, int usable, int gutter,
                  double margin) {
  // Rectangle area at texel size t, with ceil(x) <= x + 1:
  // sum (w x + o)(h x + o), x = 1 / t, o = 1 + 2 margin + gutter. Quadratic in x.
  const double o = 1 + 2 * margin + gutter;
  double a = 0, b = 0;
  for (const FlatChart* c : charts) {
    a += c->width * c->height;
    b += (c->width + c->height) * o;
  }
  const double s2 = double(usable) * double(usable);
  const double overhead = double(charts.size()) * o * o;
  if (overhead >= 0.5 * s2) {
    // The charts' minimal rectangles alone fill half a page: one page cannot
    // hold them at a useful density. Give the charts half a page of area and
    // let the packing spill onto more pages.
    return std::sqrt(a / (0.5 * s2));
  }
  const double x = (-b + std::sqrt(b * b + 4 * a * (s2 - overhead))) / (2 * a);
  auto fits = [&](double t) {
    std::vector<RectPlacement> placement;
    return lightmap_internal::packRects(rectSizes(charts, t, gutter, margin), usable, 1,
                                        placement) == 1;
  };
  constexpr double kStep = 1.05;
  double lo = 1 / x, hi = lo;
  if (fits(hi)) {
    // Denser while it fits (a few steps at most: the start is an area bound).
    for (int i = 0; i < 64 && fits(hi / kStep); ++i) hi /= kStep;
    lo = hi / kStep;
  } else {
    for (int i = 0; i < 512 && !fits(hi); ++i) {
      lo = hi;
      hi *= kStep;
    }
  }
  for (int i = 0; i < 4; ++i) {
    const double mid = std::sqrt(lo * hi);
    (fits(mid) ? hi : lo) = mid;
  }
  return hi;
}

/// The smallest value >= v with 3 significant digits: a size that, printed,
/// still does what the message says it does.
double roundUp3(double v) {
  const double unit = std::pow(10.0, std::floor(std::log10(v)) - 2);
  return std::ceil(v / unit * (1 - 1e-12)) * unit;
}

/// A triangle larger than a page at texel size t (chart of one triangle, so
/// cutting cannot help): the flags named, with values that hold every
/// triangle of the scene (a triangle's rectangle is no wider than its
/// longest edge).
InputError triangleBeyondAPage(const Scene& scene, const FlatChart& chart, double t, int size,
                               int gutter) {
  double extent = std::max(chart.width, chart.height);
  for (size_t i = 0; i < scene.triangleCount(); ++i) {
    const D3 p[3] = {D3(scene.positions[scene.indices[3 * i]]),
                     D3(scene.positions[scene.indices[3 * i + 1]]),
                     D3(scene.positions[scene.indices[3 * i + 2]])};
    for (int k = 0; k < 3; ++k) extent = std::max(extent, length(p[k] - p[(k + 1) % 3]));
  }
  // A page of `s` holds a rectangle of chartTexels + gutter <= s - gutter.
  auto fits = [&](double texel, int s) {
    return chartTexels(extent, texel, uvMargin(s)) + 2 * gutter <= s;
  };
  double texel = roundUp3(extent / (size - 2 * gutter - 2 * uvMargin(size)));
  while (!fits(texel, size)) texel = roundUp3(texel * 1.001);
  std::ostringstream os;
  os << "triangle " << chart.triangles[0] << " of " << sceneName(scene) << " alone spans "
     << std::ceil(std::max(chart.width, chart.height) / t) << " texels at a texel size of " << t
     << " scene units (--texel-size; the default is a quarter voxel), more than a page of --atlas "
     << size << " holds with its gutter of " << gutter << " texels: use --texel-size " << texel
     << " or larger";
  const double side = std::ceil(extent / t + 2 * uvMargin(size)) + 2 * gutter;
  if (side <= double(kMaxImageSide)) {  // --atlas takes up to the largest texture side
    int atlas = int(side);
    while (!fits(t, atlas)) ++atlas;
    os << ", or --atlas " << atlas << " or larger";
  }
  return InputError(os.str());
}

// Squared L2 stretch sum and areas of one triangle's UVs (scaled by `scale`).
double stretchTerm(const Scene& scene, size_t t, const float* uv, double scale, double area3) {
  const D3 q[3] = {D3(scene.positions[scene.indices[3 * t]]),
                   D3(scene.positions[scene.indices[3 * t + 1]]),
                   D3(scene.positions[scene.indices[3 * t + 2]])};
  double p[6];
  for (int i = 0; i < 6; ++i) p[i] = double(uv[i]) * scale;
  return lightmap_internal::triangleStretchSquared(q, p) * area3;
}

double uvSignedArea(const float* uv) {
  return 0.5 * ((double(uv[2]) - uv[0]) * (double(uv[5]) - uv[1]) -
                (double(uv[4]) - uv[0]) * (double(uv[3]) - uv[1]));
}

}  // namespace

std::string LightmapUvs::ToString() const {
  std::ostringstream os;
  os << "LightmapUvs{" << width << "x" << height << ", " << pageCount << " page(s), gutter "
     << gutter << ", " << chartCount << " charts, " << degenerateTriangles
     << " degenerate triangles, texelSize " << texelSize << ", utilisation " << utilisation
     << ", worstStretch " << worstStretch << "}";
  return os.str();
}

struct LightmapCharts::Impl {
  Impl(const Scene& s, const LightmapUvParams& params)
      : scene(s),
        topology(lightmap_internal::buildChartTopology(s)),
        flattener(s, topology, params.maxStretch),
        charts(flattener.run(params.chartConeDegrees)),
        coneDegrees(params.chartConeDegrees),
        maxStretch(params.maxStretch) {}
  const Scene& scene;
  const lightmap_internal::ChartTopology topology;
  lightmap_internal::ChartFlattener flattener;
  const std::vector<FlatChart> charts;
  const float coneDegrees, maxStretch;
};

namespace {

const LightmapUvParams& checkedCharts(const Scene& scene, const LightmapUvParams& params) {
  checkParams(params);
  checkSceneIndices(scene);
  return params;
}

}  // namespace

LightmapCharts::LightmapCharts(const Scene& scene, const LightmapUvParams& params)
    : impl_(std::make_unique<Impl>(scene, checkedCharts(scene, params))) {}

LightmapCharts::~LightmapCharts() = default;

LightmapUvs buildLightmapUvs(const Scene& scene, const LightmapUvParams& params) {
  return LightmapCharts(scene, params).pack(params);
}

bool LightmapCharts::exceedsOnePage(const LightmapUvParams& params) const {
  checkParams(params);
  const double t = params.texelSize;
  if (!(t > 0)) return false;  // fitted to one page
  const int gutter = params.gutter;
  const int usable = params.atlasSize - gutter;
  const double margin = uvMargin(params.atlasSize), page = double(usable) * double(usable);
  // Each chart's rectangle; a chart larger than a page is cut into pieces
  // whose rectangles hold at least its area, and two rectangles of a texel
  // and the gutter each.
  double area = 0;
  for (const FlatChart& c : impl_->charts) {
    const RectSize r = rectSize(c, t, gutter, margin);
    area += r.w <= usable && r.h <= usable
                ? double(r.w) * double(r.h)
                : std::max(c.area / (t * t), 2.0 * double(1 + gutter) * double(1 + gutter));
    if (area > page) return true;
  }
  return false;
}

LightmapUvs LightmapCharts::pack(const LightmapUvParams& params) {
  checkParams(params);
  if (params.chartConeDegrees != impl_->coneDegrees || params.maxStretch != impl_->maxStretch) {
    throw InputError("LightmapCharts::pack: the charts were cut with chartConeDegrees " +
                     std::to_string(impl_->coneDegrees) + " and maxStretch " +
                     std::to_string(impl_->maxStretch) + ", not " +
                     std::to_string(params.chartConeDegrees) + " and " +
                     std::to_string(params.maxStretch));
  }
  const Scene& scene = impl_->scene;
  lightmap_internal::ChartFlattener& flattener = impl_->flattener;
  const size_t nt = scene.triangleCount();
  const int size = params.atlasSize;
  const int gutter = params.gutter;
  const int usable = size - gutter;
  const double margin = uvMargin(size);
  // The charts as cut, and the pieces of those split here (a deque keeps
  // their addresses); no copy of the charts that need none.
  std::vector<const FlatChart*> charts;
  charts.reserve(impl_->charts.size());
  for (const FlatChart& c : impl_->charts) charts.push_back(&c);
  std::deque<FlatChart> pieces;

  LightmapUvs out;
  out.width = out.height = size;
  out.gutter = gutter;
  out.uv.assign(6 * nt, 0.0f);
  out.trianglePage.assign(nt, 0);
  out.triangleChart.assign(nt, -1);
  out.texelSize = params.texelSize;

  double t = params.texelSize;
  const Bounds3 bounds = scene.bounds();
  const double diagonal = bounds.empty() ? 0.0 : double(length(bounds.extent()));
  if (t > 0 && diagonal > 0 && t > diagonal) {
    // Every triangle would fall between texel centres: an all-black page.
    throw InputError("a texel size of " + formatNumber(t) + " scene units (--texel-size) exceeds " +
                     sceneName(scene) + " (its bounds' diagonal is " + formatNumber(diagonal) +
                     "): no texel would cover a triangle; leave it out (a quarter voxel) or give "
                     "a size well under the scene's");
  }
  if (t > 0) {
    // A given texel size: charts larger than a page are cut in halves until
    // every one fits.
    for (bool cut = true; cut;) {
      cut = false;
      std::vector<const FlatChart*> next;
      next.reserve(charts.size());
      for (const FlatChart* c : charts) {
        const RectSize r = rectSize(*c, t, gutter, margin);
        if (r.w <= usable && r.h <= usable) {
          next.push_back(c);
          continue;
        }
        if (c->triangles.size() < 2) throw triangleBeyondAPage(scene, *c, t, size, gutter);
        for (FlatChart& piece : flattener.splitInHalves(c->triangles, params.chartConeDegrees)) {
          pieces.push_back(std::move(piece));
          next.push_back(&pieces.back());
        }
        cut = true;
      }
      charts.swap(next);
    }
  } else if (!charts.empty()) {
    t = fitOnePage(charts, usable, gutter, margin);
  }

  std::vector<RectPlacement> placement;
  const std::vector<RectSize> rects = rectSizes(charts, t, gutter, margin);
  const int pages =
      charts.empty() ? 0 : lightmap_internal::packRects(rects, usable, 1 << 20, placement);
  LO_CHECK(pages >= 0);

  out.pageCount = pages;
  out.texelSize = float(t);
  double coveredTexels = 0;
  int32_t chartId = 0;
  for (size_t c = 0; c < charts.size(); ++c) {
    const FlatChart& chart = *charts[c];
    // Centred in its texel rectangle (which starts one gutter in from the page border).
    const double ox = gutter + placement[c].x + 0.5 * (rects[c].w - gutter - chart.width / t);
    const double oy = gutter + placement[c].y + 0.5 * (rects[c].h - gutter - chart.height / t);
    for (size_t i = 0; i < chart.triangles.size(); ++i) {
      const size_t tri = size_t(chart.triangles[i]);
      float* uv = &out.uv[6 * tri];
      for (int k = 0; k < 3; ++k) {
        uv[2 * k] = float((ox + chart.uv[6 * i + size_t(2 * k)] / t) / size);
        uv[2 * k + 1] = float((oy + chart.uv[6 * i + size_t(2 * k) + 1] / t) / size);
      }
      if (!(uvSignedArea(uv) > 0)) {
        // Positive in double, collapsed by the float rounding of the UVs: a
        // triangle thinner than float resolution at this texel size. It gets no
        // texel; say so rather than emit a flipped triangle.
        std::fill(uv, uv + 6, 0.0f);
        continue;
      }
      out.trianglePage[tri] = placement[c].page;
      out.triangleChart[tri] = chartId;
    }
    coveredTexels += chart.area / (t * t);
    out.worstStretch = std::max(out.worstStretch, float(chart.stretch));
    ++chartId;
  }
  out.chartCount = chartId;
  out.degenerateTriangles =
      int(std::count(out.triangleChart.begin(), out.triangleChart.end(), int32_t(-1)));
  out.utilisation = pages > 0 ? float(coveredTexels / (double(pages) * size * size)) : 0.0f;
  return out;
}

// ---------------------------------------------------------------------------
// TEXCOORD_1

namespace {

// Separating-axis test of two UV triangles: they overlap when no edge normal
// of either separates their projections by more than -eps (touching along an
// edge or at a corner, within eps, is not an overlap). Either winding.
bool uvTrianglesOverlap(const float* a, const float* b, double eps) {
  const float* tris[2] = {a, b};
  for (const float* t : tris) {
    for (int k = 0; k < 3; ++k) {
      const double ex = double(t[2 * ((k + 1) % 3)]) - t[2 * k];
      const double ey = double(t[2 * ((k + 1) % 3) + 1]) - t[2 * k + 1];
      const double len = std::sqrt(ex * ex + ey * ey);
      if (!(len > 0)) continue;
      const double nx = -ey / len, ny = ex / len;
      double minA = INFINITY, maxA = -INFINITY, minB = INFINITY, maxB = -INFINITY;
      for (int j = 0; j < 3; ++j) {
        const double pa = nx * a[2 * j] + ny * a[2 * j + 1];
        const double pb = nx * b[2 * j] + ny * b[2 * j + 1];
        minA = std::min(minA, pa);
        maxA = std::max(maxA, pa);
        minB = std::min(minB, pb);
        maxB = std::max(maxB, pb);
      }
      if (maxA <= minB + eps || maxB <= minA + eps) return false;
    }
  }
  return true;
}

std::vector<float> cornerTexcoords1(const Scene& scene) {
  const size_t nt = scene.triangleCount();
  std::vector<float> uv(6 * nt);
  for (size_t i = 0; i < 3 * nt; ++i) {
    uv[2 * i] = scene.texcoords1[2 * size_t(scene.indices[i])];
    uv[2 * i + 1] = scene.texcoords1[2 * size_t(scene.indices[i]) + 1];
  }
  return uv;
}

}  // namespace

void checkLightmapTexcoords(const Scene& scene) {
  const std::string where = sceneName(scene);
  if (scene.texcoords1.empty()) {
    throw InputError(
        where + ": TEXCOORD_1 is missing: the scene has no second UV set to use as lightmap UVs");
  }
  if (scene.texcoords1.size() != 2 * scene.positions.size()) {
    throw InputError(where + ": TEXCOORD_1 has " + std::to_string(scene.texcoords1.size()) +
                     " values for " + std::to_string(scene.positions.size()) +
                     " vertices (2 per vertex expected)");
  }
  checkSceneIndices(scene);
  const size_t nt = scene.triangleCount();
  const std::vector<float> uv = cornerTexcoords1(scene);
  for (size_t i = 0; i < 3 * nt; ++i) {
    const float u = uv[2 * i], v = uv[2 * i + 1];
    if (!(u >= 0 && u <= 1 && v >= 0 && v <= 1)) {
      std::ostringstream os;
      os << where << ": TEXCOORD_1 of triangle " << i / 3 << ", corner " << i % 3 << " (vertex "
         << scene.indices[i] << ") is (" << u << ", " << v << "), outside [0, 1]";
      throw InputError(os.str());
    }
  }

  // Overlaps between non-degenerate triangles: bin the UV bounding boxes in a
  // uniform grid of about one triangle per cell, test candidate pairs exactly.
  // Reports the pair (i, j), i < j, with the smallest i, then the smallest j.
  const lightmap_internal::TriangleGeometry geometry = lightmap_internal::triangleGeometry(scene);
  const int grid = std::clamp(int(std::sqrt(double(nt))), 1, 1024);
  auto cellOf = [grid](float x) { return std::clamp(int(double(x) * grid), 0, grid - 1); };
  struct Box {
    int x0, y0, x1, y1;
  };
  std::vector<Box> boxes(nt);
  std::vector<int32_t> cellStart(size_t(grid) * size_t(grid) + 1, 0);
  for (size_t t = 0; t < nt; ++t) {
    if (geometry.degenerate[t]) continue;
    const float* p = &uv[6 * t];
    boxes[t] = {cellOf(std::min({p[0], p[2], p[4]})), cellOf(std::min({p[1], p[3], p[5]})),
                cellOf(std::max({p[0], p[2], p[4]})), cellOf(std::max({p[1], p[3], p[5]}))};
    for (int y = boxes[t].y0; y <= boxes[t].y1; ++y) {
      for (int x = boxes[t].x0; x <= boxes[t].x1; ++x)
        ++cellStart[size_t(y) * size_t(grid) + size_t(x) + 1];
    }
  }
  std::partial_sum(cellStart.begin(), cellStart.end(), cellStart.begin());
  std::vector<int32_t> cells(size_t(cellStart.back()));
  std::vector<int32_t> fill(cellStart.begin(), cellStart.end() - 1);
  for (size_t t = 0; t < nt; ++t) {
    if (geometry.degenerate[t]) continue;
    for (int y = boxes[t].y0; y <= boxes[t].y1; ++y) {
      for (int x = boxes[t].x0; x <= boxes[t].x1; ++x) {
        cells[size_t(fill[size_t(y) * size_t(grid) + size_t(x)]++)] = int32_t(t);
      }
    }
  }
  // Float UVs of triangles that share an edge are the same numbers; eps only
  // absorbs the rounding of the projections (a few ulps of [0, 1]).
  constexpr double kTouch = 1e-6;
  std::vector<int32_t> seen(nt, -1);
  std::vector<int32_t> candidates;
  for (size_t i = 0; i < nt; ++i) {
    if (geometry.degenerate[i]) continue;
    candidates.clear();
    for (int y = boxes[i].y0; y <= boxes[i].y1; ++y) {
      for (int x = boxes[i].x0; x <= boxes[i].x1; ++x) {
        const size_t cell = size_t(y) * size_t(grid) + size_t(x);
        for (int32_t k = cellStart[cell]; k < cellStart[cell + 1]; ++k) {
          const int32_t j = cells[size_t(k)];
          if (j <= int32_t(i) || seen[size_t(j)] == int32_t(i)) continue;
          seen[size_t(j)] = int32_t(i);
          candidates.push_back(j);
        }
      }
    }
    std::sort(candidates.begin(), candidates.end());
    for (int32_t j : candidates) {
      if (uvTrianglesOverlap(&uv[6 * i], &uv[6 * size_t(j)], kTouch)) {
        throw InputError(where + ": TEXCOORD_1 triangles " + std::to_string(i) + " and " +
                         std::to_string(j) +
                         " overlap in UV space: lightmap texels must not be shared");
      }
    }
  }
}

LightmapUvs lightmapUvsFromTexcoord1(const Scene& scene, int atlasSize) {
  if (atlasSize < 1 || atlasSize > (1 << 16)) {
    throw InputError("lightmap atlas size " + std::to_string(atlasSize) + " is outside [1, 65536]");
  }
  checkLightmapTexcoords(scene);
  const size_t nt = scene.triangleCount();
  const lightmap_internal::TriangleGeometry geometry = lightmap_internal::triangleGeometry(scene);

  // UV islands: triangles that share an edge in position and in UV. Weld the
  // vertices by (position, uv), key the edges by welded end points.
  const size_t nv = scene.positions.size();
  std::vector<int32_t> order(nv);
  std::iota(order.begin(), order.end(), 0);
  auto key = [&](int32_t v) {
    const Vec3& p = scene.positions[size_t(v)];
    return std::make_tuple(p.x, p.y, p.z, scene.texcoords1[2 * size_t(v)],
                           scene.texcoords1[2 * size_t(v) + 1]);
  };
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    const auto ka = key(a), kb = key(b);
    return ka != kb ? ka < kb : a < b;
  });
  std::vector<uint32_t> weld(nv);
  uint32_t ids = 0;
  for (size_t i = 0; i < nv; ++i) {
    if (i > 0 && key(order[i]) != key(order[i - 1])) ++ids;
    weld[size_t(order[i])] = ids;
  }
  std::vector<std::pair<uint64_t, int32_t>> edges;
  for (size_t t = 0; t < nt; ++t) {
    if (geometry.degenerate[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = weld[scene.indices[3 * t + size_t(k)]];
      const uint32_t b = weld[scene.indices[3 * t + size_t((k + 1) % 3)]];
      edges.push_back({a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a), int32_t(t)});
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<int32_t> parent(nt);
  std::iota(parent.begin(), parent.end(), 0);
  auto find = [&](int32_t a) {
    while (parent[size_t(a)] != a) a = parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
    return a;
  };
  for (size_t i = 1; i < edges.size(); ++i) {
    if (edges[i].first != edges[i - 1].first) continue;
    int32_t a = find(edges[i].second), b = find(edges[i - 1].second);
    if (a == b) continue;
    if (a < b) std::swap(a, b);
    parent[size_t(a)] = b;
  }

  LightmapUvs out;
  out.width = out.height = atlasSize;
  out.pageCount = 1;
  out.uv = cornerTexcoords1(scene);
  out.trianglePage.assign(nt, 0);
  out.triangleChart.assign(nt, -1);
  std::vector<int32_t> chartOfRoot(nt, -1);
  std::vector<double> area3, area2;
  for (size_t t = 0; t < nt; ++t) {
    if (geometry.degenerate[t]) {
      std::fill(&out.uv[6 * t], &out.uv[6 * t] + 6, 0.0f);
      continue;
    }
    const size_t root = size_t(find(int32_t(t)));
    if (chartOfRoot[root] < 0) {
      chartOfRoot[root] = int32_t(area3.size());
      area3.push_back(0);
      area2.push_back(0);
    }
    const int32_t c = chartOfRoot[root];
    out.triangleChart[t] = c;
    area3[size_t(c)] += geometry.area[t];
    area2[size_t(c)] += std::abs(uvSignedArea(&out.uv[6 * t]));
  }
  out.chartCount = int(area3.size());
  out.degenerateTriangles =
      int(std::count(out.triangleChart.begin(), out.triangleChart.end(), int32_t(-1)));

  // Stretch per island, its UVs scaled to its 3D area; a triangle with zero
  // UV area has infinite stretch.
  std::vector<double> stretchSum(area3.size(), 0);
  for (size_t t = 0; t < nt; ++t) {
    const int32_t c = out.triangleChart[t];
    if (c < 0) continue;
    const double scale = area2[size_t(c)] > 0 ? std::sqrt(area3[size_t(c)] / area2[size_t(c)]) : 0;
    stretchSum[size_t(c)] += uvSignedArea(&out.uv[6 * t]) != 0
                                 ? stretchTerm(scene, t, &out.uv[6 * t], scale, geometry.area[t])
                                 : std::numeric_limits<double>::infinity();
  }
  const double total3 = std::accumulate(area3.begin(), area3.end(), 0.0);
  const double total2 = std::accumulate(area2.begin(), area2.end(), 0.0);
  for (size_t c = 0; c < area3.size(); ++c) {
    out.worstStretch = std::max(out.worstStretch, float(std::sqrt(stretchSum[c] / area3[c])));
  }
  out.utilisation = float(total2);
  out.texelSize = total2 > 0 ? float(std::sqrt(total3 / total2) / atlasSize) : 0.0f;
  return out;
}

RgbImage chartLayoutImage(const LightmapUvs& uvs, int page) {
  if (page < 0 || page >= uvs.pageCount) {
    throw InputError("chartLayoutImage: page " + std::to_string(page) + " of " +
                     std::to_string(uvs.pageCount));
  }
  const int w = uvs.width, h = uvs.height;
  std::vector<int32_t> chartOf(size_t(w) * size_t(h), -1);
  for (size_t t = 0; t < uvs.triangleChart.size(); ++t) {
    if (uvs.triangleChart[t] < 0 || uvs.trianglePage[t] != page) continue;
    double x[3], y[3];
    for (int k = 0; k < 3; ++k) {
      x[k] = double(uvs.uv[6 * t + size_t(2 * k)]) * w;
      y[k] = double(uvs.uv[6 * t + size_t(2 * k) + 1]) * h;
    }
    const double area = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    if (area == 0) continue;
    const int x0 = std::max(0, int(std::floor(std::min({x[0], x[1], x[2]}))));
    const int x1 = std::min(w - 1, int(std::ceil(std::max({x[0], x[1], x[2]}))));
    const int y0 = std::max(0, int(std::floor(std::min({y[0], y[1], y[2]}))));
    const int y1 = std::min(h - 1, int(std::ceil(std::max({y[0], y[1], y[2]}))));
    for (int py = y0; py <= y1; ++py) {
      for (int px = x0; px <= x1; ++px) {
        const double cx = px + 0.5, cy = py + 0.5;
        bool inside = true;
        for (int k = 0; k < 3 && inside; ++k) {
          const int j = (k + 1) % 3;
          const double e = (x[j] - x[k]) * (cy - y[k]) - (y[j] - y[k]) * (cx - x[k]);
          inside = area > 0 ? e >= 0 : e <= 0;
        }
        if (inside) chartOf[size_t(py) * size_t(w) + size_t(px)] = uvs.triangleChart[t];
      }
    }
  }
  RgbImage image(w, h);
  for (int py = 0; py < h; ++py) {
    for (int px = 0; px < w; ++px) {
      const size_t i = size_t(py) * size_t(w) + size_t(px);
      const int32_t c = chartOf[i];
      if (c < 0) continue;
      uint32_t k = uint32_t(c) * 2654435761u;
      k ^= k >> 15;
      k *= 2246822519u;
      k ^= k >> 13;
      Vec3 colour{0.25f + 0.7f * float(k & 255u) / 255.0f,
                  0.25f + 0.7f * float((k >> 8) & 255u) / 255.0f,
                  0.25f + 0.7f * float((k >> 16) & 255u) / 255.0f};
      // A texel beside another chart or an empty one: the border, darker.
      bool border = false;
      for (int d = 0; d < 4 && !border; ++d) {
        const int nx = px + (d == 0) - (d == 1), ny = py + (d == 2) - (d == 3);
        border = nx < 0 || ny < 0 || nx >= w || ny >= h ||
                 chartOf[size_t(ny) * size_t(w) + size_t(nx)] != c;
      }
      image.set(i, border ? colour * 0.45f : colour);
    }
  }
  return image;
}

}  // namespace lo
