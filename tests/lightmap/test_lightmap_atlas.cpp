// The light octree baked into lightmap atlases (paper §4.2.3, render to
// atlas), against answers known without the bake's own code: a plane lit by
// one constant VDL has E = c max(0, n.d) at every covered texel; the covered
// texels are the ones a polygon clipper finds overlapping a triangle, each
// holding octreeIrradiance at the point a brute-force search picks; dilation
// fills exactly the rings it is asked for; and after stitching, the bilinear
// lookups on the two sides of every seam agree.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "core/error.h"
#include "lightmap/lightmap_atlas.h"
#include "lightmap/atlas_test_scenes.h"
#include "octree/octree_irradiance.h"
#include "test_util.h"

namespace lo {
namespace {

using namespace atlas_test;

/// The decoded direction of VDL k (8+8-bit packing): what the lookup uses.
Vec3 decodedDirection(const GpuOctree& o, int k) {
  const OctreeSample s = lookupOctree(o, Vec3{1, 1, 1});
  EXPECT_TRUE(s.found);
  return s.vdls[k].direction;
}

// ---------------------------------------------------------------------------
// Brute-force references, written without the bake's code.

struct P2 {
  double x = 0, y = 0;
};

std::array<P2, 3> texelCorners(const LightmapUvs& uvs, size_t t) {
  std::array<P2, 3> c;
  for (int k = 0; k < 3; ++k)
    c[size_t(k)] = {double(uvs.uv[6 * t + size_t(2 * k)]) * uvs.width,
                    double(uvs.uv[6 * t + size_t(2 * k) + 1]) * uvs.height};
  return c;
}

/// Area of triangle ∩ texel square [x, x + 1] x [y, y + 1] (Sutherland-Hodgman).
double overlapArea(const std::array<P2, 3>& tri, int x, int y) {
  std::vector<P2> poly(tri.begin(), tri.end());
  auto clip = [&poly](auto inside, auto cut) {
    std::vector<P2> out;
    for (size_t i = 0; i < poly.size(); ++i) {
      const P2 a = poly[i], b = poly[(i + 1) % poly.size()];
      if (inside(a)) out.push_back(a);
      if (inside(a) != inside(b)) out.push_back(cut(a, b));
    }
    poly = out;
  };
  auto atX = [](double X) {
    return [X](P2 a, P2 b) { return P2{X, a.y + (b.y - a.y) * (X - a.x) / (b.x - a.x)}; };
  };
  auto atY = [](double Y) {
    return [Y](P2 a, P2 b) { return P2{a.x + (b.x - a.x) * (Y - a.y) / (b.y - a.y), Y}; };
  };
  clip([x](P2 p) { return p.x >= x; }, atX(x));
  clip([x](P2 p) { return p.x <= x + 1; }, atX(x + 1));
  clip([y](P2 p) { return p.y >= y; }, atY(y));
  clip([y](P2 p) { return p.y <= y + 1; }, atY(y + 1));
  double area = 0;
  for (size_t i = 0; i < poly.size(); ++i) {
    const P2 a = poly[i], b = poly[(i + 1) % poly.size()];
    area += a.x * b.y - b.x * a.y;
  }
  return std::fabs(area) / 2;
}

/// Barycentrics of p in tri (area ratios; p need not be inside).
std::array<double, 3> barycentrics(const std::array<P2, 3>& c, P2 p) {
  auto cross = [](P2 a, P2 b, P2 q) {
    return (b.x - a.x) * (q.y - a.y) - (q.x - a.x) * (b.y - a.y);
  };
  const double area = cross(c[0], c[1], c[2]);
  return {cross(c[1], c[2], p) / area, cross(c[2], c[0], p) / area, cross(c[0], c[1], p) / area};
}

/// The point of tri nearest to p: p itself when inside, else the nearest
/// point of the three edges.
P2 nearestPoint(const std::array<P2, 3>& c, P2 p) {
  const std::array<double, 3> b = barycentrics(c, p);
  if (b[0] >= 0 && b[1] >= 0 && b[2] >= 0) return p;
  P2 best;
  double bestD = INFINITY;
  for (int k = 0; k < 3; ++k) {
    const P2 a = c[size_t(k)], e = c[size_t((k + 1) % 3)];
    const double dx = e.x - a.x, dy = e.y - a.y;
    const double s =
        std::clamp(((p.x - a.x) * dx + (p.y - a.y) * dy) / (dx * dx + dy * dy), 0.0, 1.0);
    const P2 q{a.x + s * dx, a.y + s * dy};
    const double d = (q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y);
    if (d < bestD) {
      bestD = d;
      best = q;
    }
  }
  return best;
}

/// What the texel should hold by the rules of lightmap_atlas.h, found by
/// brute force over all triangles of the page.
struct ReferenceTexel {
  bool covered = false;
  bool ambiguous = false;  ///< a touching-only overlap or a near tie: not checked
  size_t triangle = 0;
  Vec3 position, normal;
};

ReferenceTexel referenceTexel(const Scene& scene, const LightmapUvs& uvs, int page, int x, int y) {
  ReferenceTexel r;
  const P2 centre{x + 0.5, y + 0.5};
  double bestD = INFINITY, secondD = INFINITY;
  P2 bestPoint;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (uvs.triangleChart[t] < 0 || uvs.trianglePage[t] != page) continue;
    const std::array<P2, 3> c = texelCorners(uvs, t);
    const double area = overlapArea(c, x, y);
    if (area <= 0) continue;
    if (area < 1e-9) r.ambiguous = true;
    const P2 q = nearestPoint(c, centre);
    const double d = std::hypot(q.x - centre.x, q.y - centre.y);
    if (d < bestD) {
      secondD = bestD;
      bestD = d;
      bestPoint = q;
      r.triangle = t;
    } else {
      secondD = std::min(secondD, d);
    }
    r.covered = true;
  }
  // Two triangles at (almost) the same distance, not both containing the
  // centre: either may win by rounding.
  if (r.covered && secondD - bestD < 1e-9 && bestD > 1e-9) r.ambiguous = true;
  if (!r.covered) return r;
  const std::array<double, 3> b = barycentrics(texelCorners(uvs, r.triangle), bestPoint);
  Vec3 p{0, 0, 0}, n{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const uint32_t v = scene.indices[3 * r.triangle + size_t(k)];
    p += scene.positions[v] * float(b[size_t(k)]);
    if (!scene.normals.empty()) n += scene.normals[v] * float(b[size_t(k)]);
  }
  r.position = p;
  r.normal = scene.normals.empty() ? scene.faceNormal(r.triangle) : normalize(n);
  return r;
}

/// Checks coverage against the clipper and every covered texel against
/// `expected` (given the reference texel); returns the number checked.
size_t expectCoveredTexels(const Scene& scene, const LightmapUvs& uvs, const LightmapAtlas& atlas,
                           const std::function<Vec3(const ReferenceTexel&)>& expected,
                           float relTolerance,
                           const std::function<bool(const ReferenceTexel&)>& skip = {}) {
  size_t checked = 0;
  int failures = 0;
  for (int page = 0; page < atlas.pageCount; ++page) {
    for (int y = 0; y < atlas.height; ++y) {
      for (int x = 0; x < atlas.width; ++x) {
        const ReferenceTexel r = referenceTexel(scene, uvs, page, x, y);
        if (r.ambiguous) continue;
        const size_t i = size_t(y) * size_t(atlas.width) + size_t(x);
        const uint8_t cov = atlas.coverage[size_t(page)][i];
        if (r.covered != (cov == kAtlasCovered)) {
          if (++failures <= 5)
            ADD_FAILURE() << "page " << page << " texel (" << x << ", " << y << "): coverage "
                          << int(cov) << ", the clipper says " << (r.covered ? "covered" : "not");
          continue;
        }
        if (!r.covered || (skip && skip(r))) continue;
        const Vec3 e = expected(r), got = atlas.irradiance[size_t(page)].at(i);
        for (int c = 0; c < 3; ++c) {
          if (std::fabs(got[c] - e[c]) > relTolerance * (1e-3f + std::fabs(e[c]))) {
            if (++failures <= 5)
              ADD_FAILURE() << "page " << page << " texel (" << x << ", " << y << ") triangle "
                            << r.triangle << ": " << got.ToString() << ", expected " << e.ToString()
                            << " at " << r.position.ToString();
            break;
          }
        }
        ++checked;
      }
    }
  }
  EXPECT_EQ(failures, 0);
  return checked;
}

/// Bilinear lookup as GL_LINEAR does it (texel centres at i + 0.5), p in texel units.
Vec3 bilinear(const RgbImage& image, P2 p) {
  const double fx = p.x - 0.5, fy = p.y - 0.5;
  const int x0 = int(std::floor(fx)), y0 = int(std::floor(fy));
  const float tx = float(fx - x0), ty = float(fy - y0);
  auto at = [&](int x, int y) {
    x = std::clamp(x, 0, image.width - 1);
    y = std::clamp(y, 0, image.height - 1);
    return image.at(size_t(y) * size_t(image.width) + size_t(x));
  };
  return (at(x0, y0) * (1 - tx) + at(x0 + 1, y0) * tx) * (1 - ty) +
         (at(x0, y0 + 1) * (1 - tx) + at(x0 + 1, y0 + 1) * tx) * ty;
}

/// An edge two triangles share in 3D (same end points, opposite directions)
/// that has different UVs or pages on its two sides.
struct Seam {
  int pageA = 0, pageB = 0;
  P2 a0, a1, b0, b1;  ///< texel units; a0 and b0 are the same 3D point
};

std::vector<Seam> seamsOf(const Scene& scene, const LightmapUvs& uvs) {
  std::vector<Seam> seams;
  const size_t nt = scene.triangleCount();
  auto pos = [&](size_t t, int k) { return scene.positions[scene.indices[3 * t + size_t(k % 3)]]; };
  for (size_t t = 0; t < nt; ++t) {
    for (size_t u = t + 1; u < nt; ++u) {
      if (uvs.triangleChart[t] < 0 || uvs.triangleChart[u] < 0) continue;
      for (int k = 0; k < 3; ++k) {
        for (int j = 0; j < 3; ++j) {
          if (!(pos(t, k) == pos(u, j + 1) && pos(t, k + 1) == pos(u, j))) continue;
          const std::array<P2, 3> ct = texelCorners(uvs, t), cu = texelCorners(uvs, u);
          Seam s{uvs.trianglePage[t],     uvs.trianglePage[u],     ct[size_t(k)],
                 ct[size_t((k + 1) % 3)], cu[size_t((j + 1) % 3)], cu[size_t(j)]};
          const bool same = s.pageA == s.pageB && s.a0.x == s.b0.x && s.a0.y == s.b0.y &&
                            s.a1.x == s.b1.x && s.a1.y == s.b1.y;
          if (!same) seams.push_back(s);
        }
      }
    }
  }
  return seams;
}

/// Largest relative difference between the bilinear lookups of the two
/// sides of every seam, at `perTexel` points per texel of the longer side
/// (centres of equal parts; 2 is the bake's own stitching pattern).
/// Relative to the larger side, at least 1e-3 of the atlas's brightest texel.
double seamMismatch(const LightmapAtlas& atlas, const std::vector<Seam>& seams, double perTexel) {
  float brightest = 0;
  for (const RgbImage& page : atlas.irradiance)
    for (float v : page.rgb) brightest = std::max(brightest, v);
  double worst = 0;
  for (const Seam& s : seams) {
    const double len = std::max(std::hypot(s.a1.x - s.a0.x, s.a1.y - s.a0.y),
                                std::hypot(s.b1.x - s.b0.x, s.b1.y - s.b0.y));
    const int n = std::max(1, int(std::ceil(perTexel * len)));
    for (int i = 0; i < n; ++i) {
      const double f = (i + 0.5) / n;
      const Vec3 a = bilinear(atlas.irradiance[size_t(s.pageA)],
                              {s.a0.x + f * (s.a1.x - s.a0.x), s.a0.y + f * (s.a1.y - s.a0.y)});
      const Vec3 b = bilinear(atlas.irradiance[size_t(s.pageB)],
                              {s.b0.x + f * (s.b1.x - s.b0.x), s.b0.y + f * (s.b1.y - s.b0.y)});
      for (int c = 0; c < 3; ++c) {
        const double scale =
            std::max({double(std::fabs(a[c])), double(std::fabs(b[c])), 1e-3 * brightest});
        worst = std::max(worst, std::fabs(double(a[c]) - b[c]) / scale);
      }
    }
  }
  return worst;
}

/// The atlas of `octree` baked without seam stitching and with it, and the
/// seams' mismatch (2 points per texel) in each.
struct StitchingBakes {
  LightmapAtlas raw, stitched;
  double before = 0, after = 0;
};

StitchingBakes bakeUnstitchedAndStitched(const Scene& scene, const LightmapUvs& uvs,
                                         const GpuOctree& octree, const std::vector<Seam>& seams) {
  AtlasBakeParams params;
  params.stitchSeams = false;
  StitchingBakes b;
  b.raw = bakeLightmapAtlas(scene, uvs, octree, params);
  params.stitchSeams = true;
  b.stitched = bakeLightmapAtlas(scene, uvs, octree, params);
  b.before = seamMismatch(b.raw, seams, 2);
  b.after = seamMismatch(b.stitched, seams, 2);
  return b;
}

/// Chebyshev distance (texels) from each texel to the nearest covered one;
/// large where none is near.
std::vector<int> ringOf(const LightmapAtlas& atlas, int page) {
  const int w = atlas.width, h = atlas.height;
  std::vector<int> ring(size_t(w) * size_t(h), 1 << 20);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      if (atlas.coverage[size_t(page)][size_t(y) * size_t(w) + size_t(x)] != kAtlasCovered)
        continue;
      for (int yy = std::max(0, y - 8); yy <= std::min(h - 1, y + 8); ++yy)
        for (int xx = std::max(0, x - 8); xx <= std::min(w - 1, x + 8); ++xx) {
          int& r = ring[size_t(yy) * size_t(w) + size_t(xx)];
          r = std::min(r, std::max(std::abs(xx - x), std::abs(yy - y)));
        }
    }
  return ring;
}

// ---------------------------------------------------------------------------
// A tilted plane under one constant VDL: the analytic answer everywhere.

struct PlaneCase {
  Scene scene;
  Vec3 normal;
};

PlaneCase tiltedPlane() {
  PlaneCase p{emptyScene(), {}};
  const Vec3 eu = Vec3(1.2f, 0.25f, 0.1f), ev = Vec3(-0.2f, 0.9f, 0.35f);
  addGrid(p.scene, 4, Vec3(0.35f, 0.3f, 0.55f), eu, ev);
  p.normal = normalize(cross(eu, ev));
  return p;
}

TEST(LightmapAtlas, PlaneUnderAConstantVdlIsTheCosineLawAtEveryTexel) {
  PlaneCase plane = tiltedPlane();
  const Vec3 c{2.0f, 1.0f, 0.5f};
  const GpuOctree octree = denseOctree([&](const Coord&) {
    return std::vector<Vdl>{vdl(c, {0.3f, -0.2f, 1.0f})};
  });
  const Vec3 d = decodedDirection(octree, 0);
  LightmapUvParams up;
  up.atlasSize = 64;
  const LightmapUvs uvs = buildLightmapUvs(plane.scene, up);
  ASSERT_EQ(uvs.chartCount, 1);

  // Face normals, then vertex normals that differ from them: the texels
  // follow the vertex normals.
  const Vec3 tilted = normalize(plane.normal + Vec3(0.3f, 0, 0));
  for (const Vec3& n : {plane.normal, tilted}) {
    SCOPED_TRACE("normal " + n.ToString());
    if (n != plane.normal) plane.scene.normals.assign(plane.scene.positions.size(), n);
    const LightmapAtlas atlas = bakeLightmapAtlas(plane.scene, uvs, octree);
    const Vec3 analytic = c * std::max(0.0f, dot(n, d));
    ASSERT_GT(analytic.x, 0.5f);
    const size_t checked = expectCoveredTexels(
        plane.scene, uvs, atlas, [&](const ReferenceTexel&) { return analytic; }, 1e-5f);
    EXPECT_GT(checked, size_t(0.9 * double(atlas.coveredTexels))) << atlas.ToString();
    // The direction is the VDL's; dilated texels carry both on.
    const std::vector<uint8_t>& cov = atlas.coverage[0];
    for (size_t i = 0; i < cov.size(); ++i) {
      if (cov[i] == kAtlasEmpty) continue;
      ASSERT_NEAR(length(atlas.direction[0].at(i) - d), 0.0f, 1e-5f) << i;
      ASSERT_NEAR(length(atlas.irradiance[0].at(i) - analytic), 0.0f, 1e-5f) << i;
    }
    EXPECT_EQ(atlas.seamEdges, 0u);
  }
}

// A surface drawn from both sides holds the side its light reaches, whatever
// way its normals face: the tilted plane turned over (winding and normals
// the other way) under the same VDL is the cosine law at every texel when
// it is doubleSided (an OBJ's faces, drawn from both sides, alike), and dark
// when it is one-sided glTF, whose back is not drawn. A room modelled with
// outward normals had a lightmap three quarters black where the renderer
// shows it lit.
TEST(LightmapAtlas, ADoubleSidedSurfaceHoldsTheSideItsLightReaches) {
  const PlaneCase plane = tiltedPlane();
  const Vec3 c{2.0f, 1.0f, 0.5f};
  const GpuOctree octree = denseOctree([&](const Coord&) {
    return std::vector<Vdl>{vdl(c, {0.3f, -0.2f, 1.0f})};
  });
  const Vec3 d = decodedDirection(octree, 0);
  const Vec3 analytic = c * std::max(0.0f, dot(plane.normal, d));
  ASSERT_GT(analytic.x, 0.5f);
  Scene turned = plane.scene;
  for (size_t t = 0; t < turned.triangleCount(); ++t) std::swap(turned.indices[3 * t + 1], turned.indices[3 * t + 2]);
  turned.normals.assign(turned.positions.size(), -plane.normal);
  LightmapUvParams up;
  up.atlasSize = 64;
  const LightmapUvs uvs = buildLightmapUvs(turned, up);
  struct Case {
    const char* what;
    bool doubleSided, backFaceCulling;
    Vec3 expected;
  };
  for (const Case& k : {Case{"doubleSided", true, true, analytic}, Case{"OBJ", false, false, analytic},
                        Case{"one-sided", false, true, Vec3{0, 0, 0}}}) {
    SCOPED_TRACE(k.what);
    turned.materials[0].doubleSided = k.doubleSided;
    turned.materials[0].backFaceCulling = k.backFaceCulling;
    const std::vector<int8_t> sides = atlasSurfaceSides(turned, octree, OctreeShadeParams{});
    for (int8_t side : sides) ASSERT_EQ(side, k.expected.x > 0 ? -1 : 1);
    const LightmapAtlas atlas = bakeLightmapAtlas(turned, uvs, octree);
    ASSERT_GT(atlas.coveredTexels, 0u);
    const std::vector<uint8_t>& cov = atlas.coverage[0];
    for (size_t i = 0; i < cov.size(); ++i) {
      if (cov[i] == kAtlasEmpty) continue;
      ASSERT_NEAR(length(atlas.irradiance[0].at(i) - k.expected), 0.0f, 1e-5f) << i;
    }
  }
}

// --content full: the direct light function's value is added to every
// covered texel's E, at the texel's own surface point and normal (here a
// function of the position, so a mix-up of texels shows).
TEST(LightmapAtlas, DirectLightIsAddedAtEachCoveredTexel) {
  PlaneCase plane = tiltedPlane();
  const Vec3 c{2.0f, 1.0f, 0.5f};
  const GpuOctree octree = denseOctree([&](const Coord&) {
    return std::vector<Vdl>{vdl(c, {0.3f, -0.2f, 1.0f})};
  });
  LightmapUvParams up;
  up.atlasSize = 64;
  const LightmapUvs uvs = buildLightmapUvs(plane.scene, up);
  AtlasBakeParams indirectOnly;
  indirectOnly.dilation = 0;
  indirectOnly.stitchSeams = false;
  const LightmapAtlas without = bakeLightmapAtlas(plane.scene, uvs, octree, indirectOnly);
  AtlasBakeParams full = indirectOnly;
  size_t calls = 0;
  full.directLight = [&](const std::vector<AtlasSurfacePoint>& points, int page,
                         const std::function<void()>& alive) {
    alive();  // a heartbeat of the bake's progress, harmless without a sink
    EXPECT_EQ(page, 0);
    ++calls;
    std::vector<Vec3> out;
    for (const AtlasSurfacePoint& p : points) {
      EXPECT_NEAR(length(p.normal), 1.0f, 1e-5f);
      out.push_back(Vec3{1.0f + p.position.x, 2.0f, 3.0f});
    }
    return out;
  };
  const LightmapAtlas with = bakeLightmapAtlas(plane.scene, uvs, octree, full);
  EXPECT_EQ(calls, 1u);
  size_t covered = 0;
  for (size_t i = 0; i < with.coverage[0].size(); ++i) {
    if (with.coverage[0][i] != kAtlasCovered) continue;
    const Vec3 added = with.irradiance[0].at(i) - without.irradiance[0].at(i);
    EXPECT_NEAR(added.y, 2.0f, 1e-5f);
    EXPECT_NEAR(added.z, 3.0f, 1e-5f);
    EXPECT_GT(added.x, 0.0f);
    ++covered;
  }
  EXPECT_EQ(covered, with.coveredTexels);
  EXPECT_GT(covered, 0u);
}

// The radiance pages (AtlasBakeParams::radiance): on a textured, emissive
// plane under one constant VDL, every covered texel holds albedo / pi * E +
// emission with the albedo of the texture texel under its surface point,
// found here from the point's position (not from the bake's barycentrics).
TEST(LightmapAtlas, RadianceIsAlbedoOverPiTimesIrradiancePlusEmission) {
  PlaneCase plane = tiltedPlane();
  const Vec3 origin(0.35f, 0.3f, 0.55f), eu(1.2f, 0.25f, 0.1f), ev(-0.2f, 0.9f, 0.35f);
  constexpr int kGrid = 4, kTex = 4;
  for (int j = 0; j <= kGrid; ++j)
    for (int i = 0; i <= kGrid; ++i) {
      plane.scene.texcoords0.push_back(float(i) / kGrid);
      plane.scene.texcoords0.push_back(float(j) / kGrid);
    }
  std::vector<Vec3> ramps;
  for (int y = 0; y < kTex; ++y)
    for (int x = 0; x < kTex; ++x) ramps.push_back({0.1f + 0.2f * float(x), 0.9f - 0.2f * float(y), 0.5f});
  Texture tex = Texture::fromLinear(kTex, kTex, ramps);
  tex.sampler.magFilter = TextureSampler::kNearest;  // the expected albedo below is per texel
  plane.scene.textures.push_back(tex);
  Material& m = plane.scene.materials[0];
  m.baseColor = {0.9f, 0.8f, 0.7f};
  m.baseColorTexture = 0;
  m.emission = {0.05f, 0.1f, 0.0f};

  const Vec3 c{2.0f, 1.0f, 0.5f};
  const GpuOctree octree = denseOctree([&](const Coord&) {
    return std::vector<Vdl>{vdl(c, {0.3f, -0.2f, 1.0f})};
  });
  const Vec3 analytic = c * std::max(0.0f, dot(plane.normal, decodedDirection(octree, 0)));
  LightmapUvParams up;
  up.atlasSize = 64;
  const LightmapUvs uvs = buildLightmapUvs(plane.scene, up);
  AtlasBakeParams params;
  EXPECT_TRUE(bakeLightmapAtlas(plane.scene, uvs, octree, params).radiance.empty());
  params.radiance = true;
  const LightmapAtlas atlas = bakeLightmapAtlas(plane.scene, uvs, octree, params);
  ASSERT_EQ(atlas.radiance.size(), 1u);

  // (u, v) of a point of the plane: solve p - origin = u eu + v ev.
  const double a11 = dot(eu, eu), a12 = dot(eu, ev), a22 = dot(ev, ev);
  auto planeUv = [&](const Vec3& p, double& u, double& v) {
    const Vec3 q = p - origin;
    const double b1 = dot(eu, q), b2 = dot(ev, q), det = a11 * a22 - a12 * a12;
    u = (b1 * a22 - b2 * a12) / det;
    v = (a11 * b2 - a12 * b1) / det;
  };
  size_t checked = 0;
  std::vector<Vec3> seen;
  Vec3 lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (int y = 0; y < atlas.height; ++y) {
    for (int x = 0; x < atlas.width; ++x) {
      const size_t i = size_t(y) * size_t(atlas.width) + size_t(x);
      if (atlas.coverage[0][i] != kAtlasCovered) continue;
      const Vec3 l = atlas.radiance[0].at(i);
      lo = min(lo, l);
      hi = max(hi, l);
      const ReferenceTexel r = referenceTexel(plane.scene, uvs, 0, x, y);
      if (r.ambiguous || !r.covered) continue;
      double u, v;
      planeUv(r.position, u, v);
      // Points within 1e-3 texture texels of a texel border: either texel.
      const double tu = u * kTex, tv = v * kTex;
      if (std::fabs(tu - std::round(tu)) < 1e-3 || std::fabs(tv - std::round(tv)) < 1e-3) continue;
      const int tx = std::clamp(int(std::floor(tu)), 0, kTex - 1);
      const int ty = std::clamp(int(std::floor(tv)), 0, kTex - 1);
      const Vec3 albedo = m.baseColor * tex.texel(tx, ty);
      const Vec3 e = atlas.irradiance[0].at(i);
      const Vec3 expected = albedo * e / kPi + m.emission;
      const Vec3 fromAnalytic = albedo * analytic / kPi + m.emission;
      for (int k = 0; k < 3; ++k) {
        ASSERT_NEAR(l[k], expected[k], 1e-6f * (1 + expected[k])) << x << ", " << y;
        ASSERT_NEAR(l[k], fromAnalytic[k], 1e-5f * (1 + expected[k])) << x << ", " << y;
      }
      if (std::find(seen.begin(), seen.end(), albedo) == seen.end()) seen.push_back(albedo);
      ++checked;
    }
  }
  EXPECT_GT(checked, size_t(0.8 * double(atlas.coveredTexels))) << atlas.ToString();
  EXPECT_EQ(seen.size(), size_t(kTex * kTex));  // the texture shows, not one colour
  // Dilated texels: the mean of their neighbours' albedo under the same E,
  // so inside the covered texels' range; empty texels stay black.
  for (size_t i = 0; i < atlas.coverage[0].size(); ++i) {
    const Vec3 l = atlas.radiance[0].at(i);
    if (atlas.coverage[0][i] == kAtlasEmpty) {
      ASSERT_EQ(l, Vec3(0, 0, 0)) << i;
    } else if (atlas.coverage[0][i] == kAtlasDilated) {
      for (int k = 0; k < 3; ++k) {
        ASSERT_GE(l[k], lo[k] - 1e-6f) << i;
        ASSERT_LE(l[k], hi[k] + 1e-6f) << i;
      }
    }
  }
}

TEST(LightmapAtlas, DilationFillsTheRingsAskedForAndNothingElse) {
  const PlaneCase plane = tiltedPlane();
  // Irradiance varying across voxels, so that a dilated texel's mean of its
  // neighbours is a real check.
  const GpuOctree octree = denseOctree([](const Coord& v) {
    return std::vector<Vdl>{
        vdl(Vec3(1.0f + 0.5f * float(v.x), 2.0f, 1.0f + 0.3f * float(v.y)), {0.1f, 0.2f, 1.0f})};
  });
  LightmapUvParams up;
  up.atlasSize = 64;
  up.gutter = 3;
  const LightmapUvs uvs = buildLightmapUvs(plane.scene, up);
  ASSERT_EQ(uvs.gutter, 3);
  for (int dilation : {-1, 0, 1, 2}) {
    SCOPED_TRACE("dilation " + std::to_string(dilation));
    AtlasBakeParams params;
    params.dilation = dilation;
    const LightmapAtlas atlas = bakeLightmapAtlas(plane.scene, uvs, octree, params);
    const int rings = dilation < 0 ? uvs.gutter : dilation;
    EXPECT_EQ(atlas.dilation, rings);
    const std::vector<int> ring = ringOf(atlas, 0);
    const std::vector<uint8_t>& cov = atlas.coverage[0];
    size_t dilated = 0;
    for (size_t i = 0; i < cov.size(); ++i) {
      if (ring[i] == 0) continue;
      const bool filled = ring[i] <= rings;
      ASSERT_EQ(cov[i], filled ? kAtlasDilated : kAtlasEmpty)
          << "texel " << i << " ring " << ring[i];
      if (!filled) {
        ASSERT_EQ(atlas.irradiance[0].at(i), Vec3(0, 0, 0)) << i;
        continue;
      }
      ++dilated;
      // The mean of the 8-neighbours one ring further in.
      const int x = int(i % size_t(atlas.width)), y = int(i / size_t(atlas.width));
      Vec3 sum{0, 0, 0};
      int count = 0;
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          if (x + dx < 0 || y + dy < 0 || x + dx >= atlas.width || y + dy >= atlas.height) continue;
          const size_t j = size_t(y + dy) * size_t(atlas.width) + size_t(x + dx);
          if (ring[j] < ring[i]) {
            sum += atlas.irradiance[0].at(j);
            ++count;
          }
        }
      ASSERT_GT(count, 0);
      ASSERT_NEAR(length(atlas.irradiance[0].at(i) - sum / float(count)), 0.0f, 1e-5f) << i;
    }
    EXPECT_EQ(dilated, atlas.dilatedTexels);
    if (rings > 0) {
      EXPECT_GT(dilated, size_t(0));
    }
  }
  // UVs of unknown gutter (TEXCOORD_1): one ring, what bilinear lookups need.
  LightmapUvs unknown = uvs;
  unknown.gutter = 0;
  EXPECT_EQ(bakeLightmapAtlas(plane.scene, unknown, octree).dilation, 1);
}

// ---------------------------------------------------------------------------
// A cube: six charts, twelve seams.

Scene cubeScene() {
  Scene scene = emptyScene();
  addCube(scene, Vec3(0.55f, 0.6f, 0.65f), 0.8f);
  return scene;
}

/// Two VDLs whose irradiance varies across voxels: every face lit, each differently.
GpuOctree varyingOctree() {
  return denseOctree([](const Coord& v) {
    const float s = 1.0f + 0.3f * float(v.x) + 0.2f * float(v.y) + 0.1f * float(v.z);
    return std::vector<Vdl>{
        vdl(Vec3(1.0f, 0.8f, 0.6f) * s, {0.3f, 0.5f, 0.8f}),
        vdl(Vec3(0.2f, 0.3f, 0.5f) * (3.0f - 0.2f * float(v.y)), {-0.6f, -0.3f, -0.5f})};
  });
}

LightmapUvs cubeUvs(const Scene& scene) {
  LightmapUvParams up;
  up.atlasSize = 96;
  const LightmapUvs uvs = buildLightmapUvs(scene, up);
  EXPECT_EQ(uvs.chartCount, 6);
  return uvs;
}

TEST(LightmapAtlas, CoveredTexelsHoldTheLookupAtTheirSurfacePoint) {
  const Scene scene = cubeScene();
  const LightmapUvs uvs = cubeUvs(scene);
  const GpuOctree octree = varyingOctree();
  AtlasBakeParams params;
  params.stitchSeams = false;  // stitching moves texels next to seams on purpose
  for (bool interpolation : {true, false}) {
    SCOPED_TRACE(interpolation ? "interpolated" : "nearest voxel");
    params.shade.interpolation = interpolation;
    const LightmapAtlas atlas = bakeLightmapAtlas(scene, uvs, octree, params);
    const size_t checked = expectCoveredTexels(
        scene, uvs, atlas,
        [&](const ReferenceTexel& r) {
          return octreeIrradiance(octree, r.position, r.normal, params.shade);
        },
        1e-4f,
        [&](const ReferenceTexel& r) {
          // Without interpolation the lookup jumps at voxel faces: a point
          // within rounding of one may fall on either side.
          if (interpolation) return false;
          const Vec3 q = r.position / kVoxel + r.normal * params.shade.normalOffset;
          for (int c = 0; c < 3; ++c)
            if (std::fabs(q[c] - std::round(q[c])) < 1e-4f) return true;
          return false;
        });
    EXPECT_GT(checked, size_t(0.9 * double(atlas.coveredTexels))) << atlas.ToString();
    EXPECT_EQ(atlas.seamEdges, 12u);
  }
}

TEST(LightmapAtlas, CubeUnderAConstantVdlShowsNoSeamAfterStitching) {
  const Scene scene = cubeScene();
  const LightmapUvs uvs = cubeUvs(scene);
  // Lights +x, +y, +z faces differently and the others not at all.
  const GpuOctree octree = denseOctree([](const Coord&) {
    return std::vector<Vdl>{vdl({1.5f, 1.0f, 0.5f}, {0.3f, 0.5f, 0.8f})};
  });
  const std::vector<Seam> seams = seamsOf(scene, uvs);
  ASSERT_EQ(seams.size(), 12u);
  const auto [raw, stitched, before, after] =
      bakeUnstitchedAndStitched(scene, uvs, octree, seams);
  std::printf(
      "cube, constant VDL: seam mismatch %.3g unstitched, %.3g stitched (%.3g at 16 points per "
      "texel)\n",
      before, after, seamMismatch(stitched, seams, 16));
  // The gutter takes the change: covered texels move by a few percent of the
  // jump across the seam (kCoveredWeight / kDilatedWeight).
  float covered = 0, lowestDilated = 0;
  for (size_t i = 0; i < stitched.coverage[0].size(); ++i) {
    const Vec3 v = stitched.irradiance[0].at(i);
    if (stitched.coverage[0][i] == kAtlasCovered) {
      covered = std::max(covered, length(v - raw.irradiance[0].at(i)));
      ASSERT_GE(std::min({v.x, v.y, v.z}), 0.0f) << i;
    } else {
      lowestDilated = std::min({lowestDilated, v.x, v.y, v.z});
    }
  }
  std::printf(
      "  covered texels moved by at most %.3g W/m^2, dilated ones went down to %.3g "
      "(seam jump %.3g W/m^2)\n",
      covered, lowestDilated, raw.seamMismatchBefore);
  EXPECT_LT(covered, 0.05f * raw.seamMismatchBefore);
  EXPECT_GT(before, 0.3);  // faces of different cosines meet at every edge
  EXPECT_LE(after, 1e-4) << stitched.ToString();
  EXPECT_EQ(stitched.seamEdges, 12u);
  EXPECT_GT(stitched.stitchedTexels, 0u);
  EXPECT_LE(stitched.seamMismatchAfter, 1e-4f * stitched.seamMismatchBefore);
}

TEST(LightmapAtlas, StitchingJoinsSeamsUnderVaryingLightAndMovesOnlyTexelsItReads) {
  const Scene scene = cubeScene();
  const LightmapUvs uvs = cubeUvs(scene);
  const GpuOctree octree = varyingOctree();
  const std::vector<Seam> seams = seamsOf(scene, uvs);
  const auto [raw, stitched, before, after] =
      bakeUnstitchedAndStitched(scene, uvs, octree, seams);
  std::printf("cube, varying VDLs: seam mismatch %.3g unstitched, %.3g stitched\n", before, after);
  EXPECT_LE(after, 1e-4);
  EXPECT_GT(before, 100 * std::max(after, 1e-6));

  // Texels that changed lie in the bilinear footprint of a seam point (any
  // point of the seam: the footprints of a line two texels wide).
  std::vector<uint8_t> read(raw.coverage[0].size(), 0);
  for (const Seam& s : seams) {
    for (int side = 0; side < 2; ++side) {
      const P2 p0 = side ? s.b0 : s.a0, p1 = side ? s.b1 : s.a1;
      for (int i = 0; i <= 1000; ++i) {
        const double f = i / 1000.0;
        const double fx = p0.x + f * (p1.x - p0.x) - 0.5, fy = p0.y + f * (p1.y - p0.y) - 0.5;
        for (int k = 0; k < 4; ++k) {
          const int x = int(std::floor(fx)) + (k & 1), y = int(std::floor(fy)) + (k >> 1);
          read[size_t(y) * size_t(raw.width) + size_t(x)] = 1;
        }
      }
    }
  }
  size_t changed = 0;
  for (size_t i = 0; i < read.size(); ++i) {
    if (raw.irradiance[0].at(i) == stitched.irradiance[0].at(i)) continue;
    ++changed;
    ASSERT_TRUE(read[i]) << "texel " << i << " changed but no seam lookup reads it";
    ASSERT_NE(raw.coverage[0][i], kAtlasEmpty);
  }
  EXPECT_GT(changed, 0u);
  EXPECT_LE(changed, stitched.stitchedTexels);
  EXPECT_EQ(raw.coverage, stitched.coverage);
}

TEST(LightmapAtlas, StitchingJoinsTwoIslandsOfOnePlane) {
  // One plane (z = 1.1, normal +z) of two quads sharing the edge x = 1, laid
  // out as two TEXCOORD_1 islands, the second turned by 90 degrees and off
  // the first's texel grid: the two sides of the seam see the same light at
  // different texel centres, so they differ only by discretisation.
  Scene scene = emptyScene();
  const float z = 1.1f;
  test::addQuad(scene, {0.4f, 0.5f, z}, {0.6f, 0, 0}, {0, 0.9f, 0}, {0, 0, 1}, 0);
  test::addQuad(scene, {1.0f, 0.5f, z}, {0.7f, 0, 0}, {0, 0.9f, 0}, {0, 0, 1}, 0);
  // Vertices: corner, +u, +u+v, +v per quad. Island 1 in [0.05, 0.35] x [0.05, 0.5];
  // island 2 turned: world x runs along v, world y along -u.
  scene.texcoords1 = {0.05f,   0.05f,   0.35f,   0.05f,   0.35f,   0.5f,    0.05f,   0.5f,
                      0.9137f, 0.5213f, 0.9137f, 0.8713f, 0.4637f, 0.8713f, 0.4637f, 0.5213f};
  const LightmapUvs uvs = lightmapUvsFromTexcoord1(scene, 64);
  ASSERT_EQ(uvs.chartCount, 2);
  const GpuOctree octree = denseOctree([](const Coord& v) {
    return std::vector<Vdl>{
        vdl(Vec3(1.0f, 1.0f, 1.0f) * (1.0f + 2.0f * float(v.x) + 1.5f * float(v.y)),
            {0.2f, 0.1f, 1.0f})};
  });
  const std::vector<Seam> seams = seamsOf(scene, uvs);
  ASSERT_EQ(seams.size(), 1u);
  const auto [raw, stitched, before, after] =
      bakeUnstitchedAndStitched(scene, uvs, octree, seams);
  const double beforeDense = seamMismatch(raw, seams, 16),
               afterDense = seamMismatch(stitched, seams, 16);
  std::printf(
      "plane in two islands: seam mismatch %.3g unstitched, %.3g stitched; at 16 points "
      "per texel %.3g and %.3g\n",
      before, after, beforeDense, afterDense);
  EXPECT_GT(before, 1e-3);
  EXPECT_LE(after, 1e-4);
  EXPECT_GT(before, 20 * after);
  // Between the stitched points the two sides' bilinear pieces still part a little.
  EXPECT_LT(afterDense, 0.5 * beforeDense);
}

TEST(LightmapAtlas, Deterministic) {
  const Scene scene = cubeScene();
  const LightmapUvs uvs = cubeUvs(scene);
  const GpuOctree octree = varyingOctree();
  const LightmapAtlas a = bakeLightmapAtlas(scene, uvs, octree);
  const LightmapAtlas b = bakeLightmapAtlas(scene, uvs, octree);
  ASSERT_EQ(a.pageCount, b.pageCount);
  for (int p = 0; p < a.pageCount; ++p) {
    EXPECT_EQ(a.irradiance[size_t(p)].rgb, b.irradiance[size_t(p)].rgb);
    EXPECT_EQ(a.direction[size_t(p)].rgb, b.direction[size_t(p)].rgb);
  }
  EXPECT_EQ(a.coverage, b.coverage);
}

TEST(LightmapAtlas, BadInputsNameTheField) {
  const Scene scene = cubeScene();
  const LightmapUvs uvs = cubeUvs(scene);
  const GpuOctree octree = varyingOctree();
  auto errorOf = [&](const Scene& s, const LightmapUvs& u, const AtlasBakeParams& p) {
    try {
      bakeLightmapAtlas(s, u, octree, p);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  AtlasBakeParams p;
  p.dilation = -2;
  EXPECT_NE(errorOf(scene, uvs, p).find("AtlasBakeParams.dilation"), std::string::npos);
  p = {};
  p.shade.maxVdls = 0;
  EXPECT_NE(errorOf(scene, uvs, p).find("maxVdls"), std::string::npos);
  Scene bigger = scene;
  addCube(bigger, Vec3(0.1f, 0.1f, 0.1f), 0.2f);
  EXPECT_NE(errorOf(bigger, uvs, {}).find("LightmapUvs.uv"), std::string::npos);
  LightmapUvs badPage = uvs;
  badPage.trianglePage[3] = 5;
  EXPECT_NE(errorOf(scene, badPage, {}).find("trianglePage: triangle 3"), std::string::npos);
}

// ---------------------------------------------------------------------------
// The Cornell dragon at 1 cm texels: a timing printed for the docs, not asserted.

TEST(LightmapAtlas, CornellDragon) {
  const std::string path = test::sharedScenesDir() + "/composed/cornell-dragon.glb";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  const Scene scene = loadScene(path);
  BakeParams bp;
  bp.photons = 100000;
  bp.knn = 50;
  const GpuOctree octree = buildGpuOctree(bake(scene, bp).grid);
  using Clock = std::chrono::steady_clock;
  auto start = Clock::now();
  LightmapUvParams up;
  up.texelSize = 0.01f;
  up.atlasSize = 1024;
  const LightmapUvs uvs = buildLightmapUvs(scene, up);
  const double uvSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  start = Clock::now();
  const LightmapAtlas atlas = bakeLightmapAtlas(scene, uvs, octree);
  const double atlasSeconds = std::chrono::duration<double>(Clock::now() - start).count();
  std::printf("cornell-dragon: %zu triangles, %s\n  %s\n  UVs %.3f s, atlas %.3f s, total %.3f s\n",
              scene.triangleCount(), uvs.ToString().c_str(), atlas.ToString().c_str(), uvSeconds,
              atlasSeconds, uvSeconds + atlasSeconds);
  double sum = 0;
  for (int page = 0; page < atlas.pageCount; ++page)
    for (size_t i = 0; i < atlas.coverage[size_t(page)].size(); ++i)
      if (atlas.coverage[size_t(page)][i] == kAtlasCovered)
        sum += luminance(atlas.irradiance[size_t(page)].at(i));
  std::printf("  mean covered texel: %.3g W/m^2 (luminance)\n", sum / double(atlas.coveredTexels));
  EXPECT_GT(atlas.coveredTexels, size_t(100000));
  // Stitching takes the largest seam mismatch down by a factor of 50 or
  // more (measured: 0.306 -> 0.0056 W/m^2 since the photons scatter about
  // the dragon's vertex normals; 0.32 -> 0.0011 about its face normals).
  EXPECT_LT(atlas.seamMismatchAfter, 0.02f * atlas.seamMismatchBefore);
}

}  // namespace
}  // namespace lo
