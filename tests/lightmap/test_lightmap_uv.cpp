// Lightmap UVs (paper §4.2.3): charts, LSCM and packing on meshes built in
// code, where the answer is known: a plane and a faceted cylinder unroll
// isometrically, a cube has six flat faces, and every chart must keep its
// orientation, its world texel density and its own texels.

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "lightmap/atlas_test_scenes.h"
#include "lightmap/lightmap_uv.h"
#include "test_util.h"

namespace lo {
namespace {

using namespace atlas_test;


void addTriangle(Scene& scene, const Vec3& a, const Vec3& b, const Vec3& c) {
  const uint32_t base = uint32_t(scene.positions.size());
  scene.positions.insert(scene.positions.end(), {a, b, c});
  scene.indices.insert(scene.indices.end(), {base, base + 1, base + 2});
  scene.triangleMaterial.push_back(0);
}

// Open cylinder about the y axis (no caps), outward facing; the seam column
// duplicates its vertices, as exporters do at a UV seam, so only welding by
// position closes the tube.
void addOpenCylinder(Scene& scene, int segments, int rings, float radius, float height) {
  const uint32_t base = uint32_t(scene.positions.size());
  for (int j = 0; j <= rings; ++j) {
    for (int i = 0; i <= segments; ++i) {
      const float phi = 2 * kPi * float(i % segments) / float(segments);
      scene.positions.push_back(
          {radius * std::cos(phi), height * float(j) / float(rings), -radius * std::sin(phi)});
    }
  }
  auto id = [&](int i, int j) { return base + uint32_t(j * (segments + 1) + i); };
  for (int j = 0; j < rings; ++j) {
    for (int i = 0; i < segments; ++i) {
      scene.indices.insert(scene.indices.end(), {id(i, j), id(i + 1, j), id(i + 1, j + 1)});
      scene.indices.insert(scene.indices.end(), {id(i, j), id(i + 1, j + 1), id(i, j + 1)});
      scene.triangleMaterial.insert(scene.triangleMaterial.end(), {0, 0});
    }
  }
}

// UV sphere, outward facing, triangle fans at the poles.
void addSphere(Scene& scene, const Vec3& centre, float radius, int rings, int segments) {
  auto point = [&](int j, int i) {
    const float theta = kPi * float(j) / float(rings);
    const float phi = 2 * kPi * float(i % segments) / float(segments);
    return centre + Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                         -std::sin(theta) * std::sin(phi)) *
                        radius;
  };
  for (int j = 0; j < rings; ++j) {
    for (int i = 0; i < segments; ++i) {
      const Vec3 a = point(j, i), b = point(j, i + 1), c = point(j + 1, i + 1), d = point(j + 1, i);
      if (j > 0) addTriangle(scene, a, d, b);
      if (j + 1 < rings) addTriangle(scene, b, d, c);
    }
  }
}

double uvArea(const LightmapUvs& uvs, size_t t) {
  const float* p = &uvs.uv[6 * t];
  return 0.5 * ((double(p[2]) - p[0]) * (double(p[5]) - p[1]) -
                (double(p[4]) - p[0]) * (double(p[3]) - p[1]));
}

void expectNoFlips(const Scene& scene, const LightmapUvs& uvs) {
  ASSERT_EQ(uvs.uv.size(), 6 * scene.triangleCount());
  int flipped = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (uvs.triangleChart[t] < 0) continue;
    if (!(uvArea(uvs, t) > 0)) {
      if (++flipped <= 5) ADD_FAILURE() << "triangle " << t << " has UV area " << uvArea(uvs, t);
    }
  }
  EXPECT_EQ(flipped, 0);
}

struct TexelRect {
  int page = 0;
  long x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // texels [x0, x1) x [y0, y1)
};

// Each chart's texel rectangle: the texels its UVs touch.
std::vector<TexelRect> chartRects(const LightmapUvs& uvs) {
  std::vector<double> lo(2 * size_t(uvs.chartCount), INFINITY),
      hi(2 * size_t(uvs.chartCount), -INFINITY);
  std::vector<int> page(size_t(uvs.chartCount), -1);
  for (size_t t = 0; t < uvs.triangleChart.size(); ++t) {
    const int c = uvs.triangleChart[t];
    if (c < 0) continue;
    EXPECT_TRUE(page[size_t(c)] < 0 || page[size_t(c)] == uvs.trianglePage[t])
        << "chart " << c << " spans pages";
    page[size_t(c)] = uvs.trianglePage[t];
    for (int k = 0; k < 3; ++k) {
      const double x = double(uvs.uv[6 * t + size_t(2 * k)]) * uvs.width;
      const double y = double(uvs.uv[6 * t + size_t(2 * k) + 1]) * uvs.height;
      lo[2 * size_t(c)] = std::min(lo[2 * size_t(c)], x);
      lo[2 * size_t(c) + 1] = std::min(lo[2 * size_t(c) + 1], y);
      hi[2 * size_t(c)] = std::max(hi[2 * size_t(c)], x);
      hi[2 * size_t(c) + 1] = std::max(hi[2 * size_t(c) + 1], y);
    }
  }
  std::vector<TexelRect> rects(size_t(uvs.chartCount));
  for (size_t c = 0; c < rects.size(); ++c) {
    rects[c] = {page[c], long(std::floor(lo[2 * c])), long(std::floor(lo[2 * c + 1])),
                long(std::ceil(hi[2 * c])), long(std::ceil(hi[2 * c + 1]))};
  }
  return rects;
}

// Every chart inside [gutter, size - gutter] of its page, and at least
// `gutter` empty texels between any two charts of a page.
void expectPacked(const LightmapUvs& uvs, int gutter) {
  const std::vector<TexelRect> rects = chartRects(uvs);
  for (size_t c = 0; c < rects.size(); ++c) {
    const TexelRect& r = rects[c];
    EXPECT_TRUE(r.page >= 0 && r.page < uvs.pageCount) << "chart " << c << " page " << r.page;
    EXPECT_TRUE(r.x0 >= gutter && r.y0 >= gutter && r.x1 <= uvs.width - gutter &&
                r.y1 <= uvs.height - gutter)
        << "chart " << c << " texels [" << r.x0 << ", " << r.x1 << ") x [" << r.y0 << ", " << r.y1
        << ")";
  }
  // Sweep along x: sort by x0, compare with the charts that start before x1 + gutter.
  std::vector<size_t> order(rects.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(),
            [&](size_t a, size_t b) { return rects[a].x0 < rects[b].x0; });
  int overlaps = 0;
  for (size_t i = 0; i < order.size(); ++i) {
    const TexelRect& a = rects[order[i]];
    for (size_t j = i + 1; j < order.size() && rects[order[j]].x0 < a.x1 + gutter; ++j) {
      const TexelRect& b = rects[order[j]];
      if (a.page != b.page) continue;
      const bool apart = a.x1 + gutter <= b.x0 || b.x1 + gutter <= a.x0 || a.y1 + gutter <= b.y0 ||
                         b.y1 + gutter <= a.y0;
      if (!apart && ++overlaps <= 5) {
        ADD_FAILURE() << "charts " << order[i] << " and " << order[j]
                      << " closer than the gutter: [" << a.x0 << "," << a.x1 << ")x[" << a.y0 << ","
                      << a.y1 << ") and [" << b.x0 << "," << b.x1 << ")x[" << b.y0 << "," << b.y1
                      << ")";
      }
    }
  }
  EXPECT_EQ(overlaps, 0);
}

// UV area of each chart, in world units at the reported texel size, against
// its 3D area: one texel density everywhere. Besides `tolerance`, each corner
// of a float UV may be rounded by half an ulp of [0.5, 1) (2^-25 of the page),
// which moves a triangle's area by at most that times its perimeter: tiny
// triangles of a scan are a few hundredths of a texel.
void expectTexelDensity(const Scene& scene, const LightmapUvs& uvs, double tolerance) {
  std::vector<double> area2(size_t(uvs.chartCount), 0), area3(size_t(uvs.chartCount), 0);
  std::vector<double> rounding(size_t(uvs.chartCount), 0);
  const double halfUlp = std::ldexp(1.0, -25);
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const int c = uvs.triangleChart[t];
    if (c < 0) continue;
    area2[size_t(c)] += uvArea(uvs, t);
    area3[size_t(c)] += scene.triangleArea(t);
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      const double du = double(uvs.uv[6 * t + size_t(2 * l)]) - uvs.uv[6 * t + size_t(2 * k)];
      const double dv =
          double(uvs.uv[6 * t + size_t(2 * l) + 1]) - uvs.uv[6 * t + size_t(2 * k) + 1];
      rounding[size_t(c)] += 2 * halfUlp * std::sqrt(du * du + dv * dv);
    }
  }
  const double scale = double(uvs.width) * uvs.height * double(uvs.texelSize) * uvs.texelSize;
  for (size_t c = 0; c < area2.size(); ++c) {
    EXPECT_NEAR(area2[c] * scale / area3[c], 1.0, tolerance + rounding[c] / area2[c])
        << "chart " << c;
  }
}

void expectValid(const Scene& scene, const LightmapUvs& uvs, const LightmapUvParams& params) {
  expectNoFlips(scene, uvs);
  expectPacked(uvs, params.gutter);
  expectTexelDensity(scene, uvs, 1e-3);
  EXPECT_LE(uvs.worstStretch, params.maxStretch);
  for (float u : uvs.uv) ASSERT_TRUE(u >= 0 && u <= 1) << u;
}

TEST(LightmapUv, PlanarGridIsIsometric) {
  Scene scene = emptyScene();
  // A tilted plane: orthogonal edges of lengths 2 and 1.5, normal along neither axis.
  const Vec3 eu = normalize(Vec3(1, 0.3f, -0.2f)) * 2.0f;
  const Vec3 ev = normalize(cross(Vec3(0.1f, 1, 0.4f), eu)) * 1.5f;
  addGrid(scene, 8, Vec3(0.5f, -1, 2), eu, ev);
  LightmapUvParams params;
  const LightmapUvs uvs = buildLightmapUvs(scene, params);
  EXPECT_EQ(uvs.chartCount, 1) << uvs.ToString();
  EXPECT_EQ(uvs.pageCount, 1);
  EXPECT_NEAR(uvs.worstStretch, 1.0, 1e-4);
  // Every UV edge is its 3D edge at the texel size: |duv| * size * texelSize.
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const int l = (k + 1) % 3;
      const double du =
          (double(uvs.uv[6 * t + size_t(2 * l)]) - uvs.uv[6 * t + size_t(2 * k)]) * uvs.width;
      const double dv =
          (double(uvs.uv[6 * t + size_t(2 * l) + 1]) - uvs.uv[6 * t + size_t(2 * k) + 1]) *
          uvs.height;
      const double world = length(scene.positions[scene.indices[3 * t + size_t(l)]] -
                                  scene.positions[scene.indices[3 * t + size_t(k)]]);
      EXPECT_NEAR(std::sqrt(du * du + dv * dv) * uvs.texelSize / world, 1.0, 1e-4)
          << "triangle " << t;
    }
  }
  expectValid(scene, uvs, params);
  // One square-ish chart (2 x 1.5) on a page: most of the page is used.
  EXPECT_GT(uvs.utilisation, 0.6f) << uvs.ToString();
}

TEST(LightmapUv, CubeGivesSixFlatCharts) {
  Scene scene = unitCube();
  LightmapUvParams params;
  params.chartConeDegrees = 45;
  const LightmapUvs uvs = buildLightmapUvs(scene, params);
  EXPECT_EQ(uvs.chartCount, 6) << uvs.ToString();
  EXPECT_NEAR(uvs.worstStretch, 1.0, 1e-4);
  // The two triangles of each face share a chart.
  for (size_t f = 0; f < 6; ++f) EXPECT_EQ(uvs.triangleChart[2 * f], uvs.triangleChart[2 * f + 1]);
  expectValid(scene, uvs, params);
  // Six equal squares, two rows of three: about 6 / 9 of the page.
  EXPECT_GT(uvs.utilisation, 0.6f) << uvs.ToString();
}

// The chart picture (lightmap --chart-image): each chart's interior one
// colour of its own, its border a darker shade, the rest black, and its
// area the charts' share of the page.
TEST(LightmapUv, ChartLayoutImageColoursEachChart) {
  Scene scene = unitCube();
  LightmapUvParams params;
  params.atlasSize = 96;
  const LightmapUvs uvs = buildLightmapUvs(scene, params);
  ASSERT_EQ(uvs.chartCount, 6);
  const RgbImage image = chartLayoutImage(uvs, 0);
  ASSERT_EQ(image.width, uvs.width);
  ASSERT_EQ(image.height, uvs.height);
  std::vector<Vec3> colours;  // interior colours (not beside another colour)
  size_t lit = 0;
  for (int y = 1; y + 1 < image.height; ++y) {
    for (int x = 1; x + 1 < image.width; ++x) {
      const Vec3 c = image.at(size_t(y) * size_t(image.width) + size_t(x));
      if (c.x + c.y + c.z == 0) continue;
      ++lit;
      bool interior = true;
      for (int d = 0; d < 4; ++d) {
        const int nx = x + (d == 0) - (d == 1), ny = y + (d == 2) - (d == 3);
        const Vec3 n = image.at(size_t(ny) * size_t(image.width) + size_t(nx));
        interior = interior && n.x == c.x && n.y == c.y && n.z == c.z;
      }
      if (!interior) continue;
      if (std::none_of(colours.begin(), colours.end(), [&](const Vec3& k) {
            return k.x == c.x && k.y == c.y && k.z == c.z;
          })) {
        colours.push_back(c);
      }
    }
  }
  EXPECT_EQ(colours.size(), 6u);
  EXPECT_NEAR(double(lit) / double(image.pixelCount()), uvs.utilisation, 0.05);
  EXPECT_THROW(chartLayoutImage(uvs, 1), InputError);
}

TEST(LightmapUv, OpenCylinderUnrolls) {
  // The faceted cylinder is developable: its charts unroll isometrically.
  Scene scene = emptyScene();
  addOpenCylinder(scene, 32, 4, 1.0f, 2.0f);
  for (float cone : {45.0f, 180.0f}) {
    SCOPED_TRACE("cone " + std::to_string(cone));
    LightmapUvParams params;
    params.chartConeDegrees = cone;
    const LightmapUvs uvs = buildLightmapUvs(scene, params);
    // A closed tube has no flat layout as one chart: the welded seam must be cut.
    EXPECT_GT(uvs.chartCount, 1) << uvs.ToString();
    EXPECT_LT(uvs.worstStretch, 1.01f) << uvs.ToString();
    expectValid(scene, uvs, params);
  }
}

TEST(LightmapUv, SphereHasNoFlips) {
  Scene scene = emptyScene();
  addSphere(scene, Vec3(0.0f), 1.0f, 16, 32);
  LightmapUvParams params;
  const LightmapUvs uvs = buildLightmapUvs(scene, params);
  EXPECT_GT(uvs.chartCount, 1);
  EXPECT_EQ(uvs.degenerateTriangles, 0);
  expectValid(scene, uvs, params);
  // A bound below the worst chart's stretch splits more, and still folds nothing.
  params.maxStretch = 1 + 0.5f * (uvs.worstStretch - 1);
  const LightmapUvs tight = buildLightmapUvs(scene, params);
  EXPECT_GT(tight.chartCount, uvs.chartCount);
  expectValid(scene, tight, params);
}

Scene mixedScene() {
  Scene scene = emptyScene();
  addCube(scene, Vec3(2, 0, 0), 0.5f);
  addOpenCylinder(scene, 32, 4, 0.5f, 1.0f);
  addSphere(scene, Vec3(0, 2, 0), 0.7f, 12, 24);
  addGrid(scene, 8, Vec3(-3, -1, -3), Vec3(6, 0, 0), Vec3(0, 0, 6));
  return scene;
}

TEST(LightmapUv, PacksWithGutterOnOnePageOrMany) {
  const Scene scene = mixedScene();
  LightmapUvParams params;
  params.atlasSize = 256;
  params.gutter = 3;
  const LightmapUvs one = buildLightmapUvs(scene, params);
  EXPECT_EQ(one.pageCount, 1) << one.ToString();
  expectValid(scene, one, params);

  // A texel size four times finer than the fitted one needs many pages (the
  // 6 x 6 floor alone is larger than a page: it is cut).
  params.texelSize = one.texelSize / 4;
  const LightmapUvs many = buildLightmapUvs(scene, params);
  EXPECT_GT(many.pageCount, 4) << many.ToString();
  EXPECT_FLOAT_EQ(many.texelSize, params.texelSize);
  expectValid(scene, many, params);
}

TEST(LightmapUv, Deterministic) {
  const Scene scene = mixedScene();
  LightmapUvParams params;
  const LightmapUvs a = buildLightmapUvs(scene, params);
  const LightmapUvs b = buildLightmapUvs(scene, params);
  EXPECT_EQ(a.uv, b.uv);
  EXPECT_EQ(a.triangleChart, b.triangleChart);
  EXPECT_EQ(a.trianglePage, b.trianglePage);
  EXPECT_EQ(a.texelSize, b.texelSize);
}

// Charts cut once and packed at many sizes (bakeLightmap's search for the
// smallest page) give buildLightmapUvs' bytes at every size; packing with
// another cone or stretch than the charts were cut with is refused.
TEST(LightmapUv, ChartsCutOncePackAsBuildLightmapUvsDoes) {
  const Scene scene = mixedScene();
  LightmapUvParams params;
  LightmapCharts charts(scene, params);
  for (int size : {64, 96, 256, 1024}) {
    for (float texel : {0.0f, 0.02f}) {
      params.atlasSize = size;
      params.texelSize = texel;
      const LightmapUvs a = charts.pack(params);
      const LightmapUvs b = buildLightmapUvs(scene, params);
      EXPECT_EQ(a.uv, b.uv) << size << " " << texel;
      EXPECT_EQ(a.trianglePage, b.trianglePage);
      EXPECT_EQ(a.triangleChart, b.triangleChart);
      EXPECT_EQ(a.pageCount, b.pageCount);
      EXPECT_EQ(a.texelSize, b.texelSize);
      // The search for one page passes over the sizes whose pages the
      // charts' area exceeds: they would have needed more.
      if (charts.exceedsOnePage(params)) {
        EXPECT_GT(a.pageCount, 1) << size << " " << texel;
      }
    }
  }
  params.atlasSize = 64;
  params.texelSize = 0.02f;
  EXPECT_TRUE(charts.exceedsOnePage(params));
  params.chartConeDegrees = 30;
  EXPECT_THROW(charts.pack(params), InputError);
}

TEST(LightmapUv, DegenerateTrianglesGetNoChart) {
  Scene scene = unitCube();
  addTriangle(scene, {0, 0, 0}, {1, 0, 0}, {2, 0, 0});  // collinear
  addTriangle(scene, {0, 1, 0}, {0, 1, 0}, {0, 2, 0});  // two corners alike
  const LightmapUvs uvs = buildLightmapUvs(scene, LightmapUvParams{});
  EXPECT_EQ(uvs.degenerateTriangles, 2);
  EXPECT_EQ(uvs.chartCount, 6);
  for (size_t t = 12; t < 14; ++t) {
    EXPECT_EQ(uvs.triangleChart[t], -1);
    for (int i = 0; i < 6; ++i) EXPECT_EQ(uvs.uv[6 * t + size_t(i)], 0.0f);
  }
}

TEST(LightmapUv, BadParametersNameTheField) {
  Scene scene = unitCube();
  auto expectError = [&](LightmapUvParams p, const std::string& field) {
    try {
      buildLightmapUvs(scene, p);
      ADD_FAILURE() << "no error for " << field;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(field), std::string::npos) << e.what();
    }
  };
  LightmapUvParams p;
  p.atlasSize = 4;
  expectError(p, "atlasSize");
  p = {};
  p.gutter = -1;
  expectError(p, "gutter");
  p = {};
  p.texelSize = -1;
  expectError(p, "texelSize");
  p = {};
  p.chartConeDegrees = 0;
  expectError(p, "chartConeDegrees");
  p = {};
  p.maxStretch = 0.5f;
  expectError(p, "maxStretch");
}

// A triangle larger than a page at the texel size: the command's flags are
// named (it named LightmapUvParams.texelSize), and each value the message
// advises holds every triangle.
TEST(LightmapUv, ATriangleBeyondAPageNamesTheFlagsAndValuesThatHold) {
  const Scene scene = unitCube();
  LightmapUvParams p;
  p.atlasSize = 64;
  p.texelSize = 0.001f;  // one triangle of the unit cube spans 1000 texels
  std::string what;
  try {
    buildLightmapUvs(scene, p);
    ADD_FAILURE() << "built";
  } catch (const InputError& e) {
    what = e.what();
  }
  EXPECT_NE(what.find("at a texel size of 0.001 scene units (--texel-size"), std::string::npos)
      << what;
  EXPECT_NE(what.find("more than a page of --atlas 64"), std::string::npos) << what;
  const size_t texelAt = what.find("use --texel-size "), atlasAt = what.find("or --atlas ");
  ASSERT_NE(texelAt, std::string::npos) << what;
  ASSERT_NE(atlasAt, std::string::npos) << what;
  LightmapUvParams texel = p;
  texel.texelSize = std::stof(what.substr(texelAt + 17));
  EXPECT_GE(buildLightmapUvs(scene, texel).pageCount, 1);
  LightmapUvParams atlas = p;
  atlas.atlasSize = std::stoi(what.substr(atlasAt + 11));
  EXPECT_GE(buildLightmapUvs(scene, atlas).pageCount, 1);
}

// ---------------------------------------------------------------------------
// TEXCOORD_1

// Two unit quads side by side, TEXCOORD_1 from `uvs` (2 per vertex, 8 vertices).
Scene twoQuadsWithUv(const std::vector<float>& uvs) {
  Scene scene = emptyScene();
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  test::addQuad(scene, {2, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  scene.texcoords1 = uvs;
  return scene;
}

std::string errorOf(const Scene& scene) {
  try {
    checkLightmapTexcoords(scene);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Quad 0 in [0.1, 0.4]^2, quad 1 in [0.5, 0.9] x [0.1, 0.4]: a valid layout.
const std::vector<float> kValidUv = {0.1f, 0.1f, 0.4f, 0.1f, 0.4f, 0.4f, 0.1f, 0.4f,
                                     0.5f, 0.1f, 0.9f, 0.1f, 0.9f, 0.4f, 0.5f, 0.4f};

TEST(LightmapTexcoords, AcceptsValidLayout) {
  const Scene scene = twoQuadsWithUv(kValidUv);
  EXPECT_EQ(errorOf(scene), "");
  const LightmapUvs uvs = lightmapUvsFromTexcoord1(scene, 512);
  EXPECT_EQ(uvs.chartCount, 2);
  EXPECT_EQ(uvs.pageCount, 1);
  EXPECT_EQ(uvs.width, 512);
  EXPECT_NEAR(uvs.utilisation, 0.3 * 0.3 + 0.4 * 0.3, 1e-6);
  // Mean texel: 2 world units^2 over 0.21 of the page.
  EXPECT_NEAR(uvs.texelSize, std::sqrt(2.0 / (0.21 * 512 * 512)), 1e-6);
  // Quad 0 is square in UV (stretch 1). Quad 1, 0.4 x 0.3, scaled to its
  // area 1, is sqrt(4/3) x sqrt(3/4): singular values sqrt(3/4) and sqrt(4/3)
  // of the map to 3D, L2 = sqrt((3/4 + 4/3) / 2).
  const double a2 = 4.0 / 3.0;
  EXPECT_NEAR(uvs.worstStretch, std::sqrt((a2 + 1 / a2) / 2), 1e-4);
  EXPECT_EQ(uvs.uv[0], 0.1f);
  EXPECT_EQ(uvs.triangleChart[0], uvs.triangleChart[1]);
  EXPECT_NE(uvs.triangleChart[1], uvs.triangleChart[2]);
}

TEST(LightmapTexcoords, TouchingChartsAreFine) {
  // Quad 1 shares quad 0's right edge in UV: touching, not overlapping.
  std::vector<float> uv = kValidUv;
  for (int i : {8, 14}) uv[size_t(i)] = 0.4f;
  EXPECT_EQ(errorOf(twoQuadsWithUv(uv)), "");
}

TEST(LightmapTexcoords, RejectsMissing) {
  EXPECT_NE(errorOf(twoQuadsWithUv({})).find("missing"), std::string::npos);
  EXPECT_THROW(lightmapUvsFromTexcoord1(twoQuadsWithUv({}), 512), InputError);
}

TEST(LightmapTexcoords, RejectsOutside) {
  std::vector<float> uv = kValidUv;
  uv[2 * 6] = 1.5f;  // vertex 6: corner 2 of triangle 2 (quad 1's first triangle)
  const std::string error = errorOf(twoQuadsWithUv(uv));
  EXPECT_NE(error.find("outside"), std::string::npos) << error;
  EXPECT_NE(error.find("1.5"), std::string::npos) << error;
  EXPECT_NE(error.find("triangle 2"), std::string::npos) << error;
}

TEST(LightmapTexcoords, RejectsOverlap) {
  // Quad 1 moved onto quad 0's corner: triangles of both overlap.
  std::vector<float> uv = kValidUv;
  const float quad1[8] = {0.3f, 0.3f, 0.6f, 0.3f, 0.6f, 0.6f, 0.3f, 0.6f};
  std::copy(quad1, quad1 + 8, uv.begin() + 8);
  const std::string error = errorOf(twoQuadsWithUv(uv));
  EXPECT_NE(error.find("overlap"), std::string::npos) << error;
  // Triangle 0 (below quad 0's diagonal) and triangle 2 (below quad 1's)
  // share the region 0.3 <= v <= u <= 0.4.
  EXPECT_NE(error.find("triangles 0 and 2"), std::string::npos) << error;

  // Mirrored islands count too: quad 1 flipped in u over quad 0.
  std::vector<float> mirrored = kValidUv;
  const float flipped[8] = {0.4f, 0.1f, 0.1f, 0.1f, 0.1f, 0.4f, 0.4f, 0.4f};
  std::copy(flipped, flipped + 8, mirrored.begin() + 8);
  EXPECT_NE(errorOf(twoQuadsWithUv(mirrored)).find("overlap"), std::string::npos);
}

// ---------------------------------------------------------------------------
// A real scan: the Stanford dragon in the Cornell box (about 200k triangles).

TEST(LightmapUv, CornellDragon) {
  const std::string path = test::sharedScenesDir() + "/composed/cornell-dragon.glb";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  const Scene scene = loadScene(path);
  LightmapUvParams params;
  const auto start = std::chrono::steady_clock::now();
  const LightmapUvs uvs = buildLightmapUvs(scene, params);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  // Printed for docs, not asserted: timings belong to benchmarks.
  std::printf("cornell-dragon: %zu triangles, %s, %.3f s\n", scene.triangleCount(),
              uvs.ToString().c_str(), seconds);
  EXPECT_EQ(uvs.pageCount, 1);
  EXPECT_LT(uvs.degenerateTriangles, int(scene.triangleCount() / 1000));
  expectValid(scene, uvs, params);
}

}  // namespace
}  // namespace lo
