// The octree's irradiance (octree/octree_irradiance.h) against analytic
// answers: a block of voxels with one constant VDL gives c * max(0, n.d)
// everywhere on it, through the lookup, the interpolation (empty neighbours
// left out) and the half-float texels; and, through reference/first_hit.h, the
// same value at every pixel of a camera looking at a lit plane.

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "core/math.h"
#include "core/rng.h"
#include <octree_layout.h>

#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "reference/first_hit.h"
#include "test_util.h"

namespace lo {
namespace {

constexpr float kVoxel = 0.25f;

/// A slab of voxels [0, res) x [0, res) x {z0..z1} of a depth-`depth` grid at
/// the origin, every voxel with the same VDLs.
VdlGrid constantGrid(int depth, int z0, int z1, const std::vector<Vdl>& vdls) {
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = kVoxel;
  g.frame.depth = depth;
  g.maxVdls = kMaxVdls;
  const int res = 1 << depth;
  for (int z = z0; z <= z1; ++z)
    for (int y = 0; y < res; ++y)
      for (int x = 0; x < res; ++x) {
        g.coords.push_back({x, y, z});
        g.normals.push_back({0, 0, 1});
        g.vdlCount.push_back(uint8_t(vdls.size()));
        for (int i = 0; i < kMaxVdls; ++i) g.vdls.push_back(i < int(vdls.size()) ? vdls[i] : Vdl{});
      }
  return g;
}

Vdl vdl(const Vec3& irradiance, const Vec3& direction) {
  Vdl v;
  v.irradiance = irradiance;
  v.direction = normalize(direction);
  return v;
}

/// The decoded direction (8+8-bit packing) of the octree's first VDL, so that
/// the expected value uses what the shader sees.
Vec3 decodedDirection(const GpuOctree& o, int k) {
  OctreeSample s = lookupOctree(o, Vec3{1.5f, 1.5f, 0.5f} * kVoxel);
  EXPECT_TRUE(s.found);
  return s.vdls[k].direction;
}

/// Unit direction d as a texel's packed direction decodes it.
Vec3 unpacked(const Vec3& d) {
  const float code = layout::loPackDirection(d.x, d.y, d.z);
  return {layout::loUnpackDirectionX(code), layout::loUnpackDirectionY(code),
          layout::loUnpackDirectionZ(code)};
}

/// The x of the decoded direction of the first VDL of the voxel at p.
Vec3 decodedDirectionAt(const GpuOctree& o, const Vec3& p) {
  OctreeSample s = lookupOctree(o, p);
  EXPECT_TRUE(s.found);
  return s.vdls[0].direction;
}

TEST(OctreeIrradiance, ConstantVdlGivesTheCosineLawEverywhereOnTheSlab) {
  const Vec3 c{2.0f, 1.0f, 0.5f};
  const Vec3 d = normalize(Vec3{0.3f, -0.2f, 1.0f});
  const GpuOctree o = buildGpuOctree(constantGrid(3, 0, 1, {vdl(c, d)}), test::paperCosine());
  const Vec3 dq = decodedDirection(o, 0);
  EXPECT_NEAR(dot(dq, d), 1.0f, 1e-3f);
  const Vec3 normals[] = {{0, 0, 1}, normalize(Vec3{1, 0, 1}), normalize(Vec3{0.2f, 0.9f, 0.1f})};
  for (bool interpolation : {true, false}) {
    OctreeShadeParams p;
    p.interpolation = interpolation;
    // Points inside the slab (z < 2 voxels), including its edges and corners
    // where most interpolation neighbours are empty.
    for (const Vec3& q : {Vec3{1.3f, 4.7f, 1.0f}, Vec3{0.01f, 0.01f, 0.2f}, Vec3{7.99f, 3.5f, 1.9f},
                          Vec3{4.0f, 4.0f, 1.0f}}) {
      for (const Vec3& n : normals) {
        const Vec3 e = octreeIrradiance(o, q * kVoxel, n, p);
        const Vec3 expected = c * std::max(0.0f, dot(n, dq));
        for (int ch = 0; ch < 3; ++ch)
          EXPECT_NEAR(e[ch], expected[ch], 1e-5f * (1 + expected[ch]))
              << "interpolation " << interpolation << " at " << q.ToString() << " n "
              << n.ToString();
      }
    }
    // A normal facing away from the VDL receives nothing.
    EXPECT_EQ(octreeIrradiance(o, Vec3{2, 2, 1} * kVoxel, -d, p), Vec3(0, 0, 0));
    // Empty space and outside the cube: nothing.
    EXPECT_EQ(octreeIrradiance(o, Vec3{2, 2, 5} * kVoxel, {0, 0, 1}, p), Vec3(0, 0, 0));
    EXPECT_EQ(octreeIrradiance(o, Vec3{-3, 2, 1} * kVoxel, {0, 0, 1}, p), Vec3(0, 0, 0));
  }
}

// A surface facing across the voxels' own (a step's riser in the floor's
// voxels) sees that surface below its own horizon over (1 - n.m) / 2 of its
// cosine-weighted hemisphere: it receives the floor's irradiance E(m) times
// the floor's reflectance from there, on top of the VDLs' cosine law; one
// turned against it, (1 - |n.m|) / 2, nothing at n = -m (the far side of a
// thin wall); without recorded reflectance, nothing more.
TEST(OctreeIrradiance, ASurfaceFacingBelowTheVoxelsSurfaceGetsTheLightThatSurfaceReflects) {
  const Vec3 c{2.0f, 1.0f, 0.5f};
  const Vec3 rho{0.5f, 0.25f, 0.8f};
  VdlGrid g = constantGrid(3, 0, 1, {vdl(c, {0, 0, 1})});
  g.reflectance.assign(g.size(), rho);
  for (int format = 0; format < 3; ++format) {
    SCOPED_TRACE(format == 0 ? "float" : format == 1 ? "half" : "compact");
    GpuOctreeParams params;
    params.halfFloat = format > 0;
    params.compact = format == 2;
    const GpuOctree o = buildGpuOctree(g, params);
    ASSERT_TRUE(o.surfaceTexels);
    const float tol = format == 0 ? 1e-5f : 4e-3f;
    for (bool interpolation : {true, false}) {
      OctreeShadeParams p;
      p.interpolation = interpolation;
      for (const Vec3& n : {Vec3{0, 0, 1}, Vec3{1, 0, 0}, normalize(Vec3{0.3f, 1, -0.2f}),
                            Vec3{0, 0, -1}, normalize(Vec3{1, 1, 1})}) {
        const Vec3 expected = c * std::max(0.0f, n.z) + rho * c * (0.5f * (1.0f - std::fabs(n.z)));
        const Vec3 e = octreeIrradiance(o, Vec3{4.3f, 2.6f, 1.0f} * kVoxel, n, p);
        EXPECT_NEAR(length(e - expected), 0.0f, tol * length(expected)) << n.ToString();
      }
    }
  }
  g.reflectance.assign(g.size(), Vec3{});
  const GpuOctree dark = buildGpuOctree(g);
  EXPECT_FALSE(dark.surfaceTexels);
  EXPECT_EQ(octreeIrradiance(dark, Vec3{4.3f, 2.6f, 1.0f} * kVoxel, {1, 0, 0}), Vec3(0.0f));
}

TEST(OctreeIrradiance, InterpolationBlendsNeighboursTrilinearly) {
  // Two slabs of different irradiance, z = 0 and z = 1: between their centres
  // (z = 0.5 .. 1.5 voxels) the value is linear in z.
  VdlGrid g = constantGrid(3, 0, 1, {vdl({1, 1, 1}, {0, 0, 1})});
  for (size_t v = 0; v < g.size(); ++v)
    if (g.coords[v].z == 1) g.vdls[v * kMaxVdls].irradiance = {3, 3, 3};
  const GpuOctree o = buildGpuOctree(g, test::paperCosine());
  OctreeShadeParams p;
  p.normalOffset = 0;
  for (float z : {0.5f, 0.75f, 1.0f, 1.25f, 1.5f}) {
    const float expected = 1.0f + 2.0f * (z - 0.5f);
    EXPECT_NEAR(octreeIrradiance(o, Vec3{3.5f, 3.5f, z} * kVoxel, {0, 0, 1}, p).x, expected, 1e-4f)
        << z;
  }
  p.interpolation = false;
  EXPECT_NEAR(octreeIrradiance(o, Vec3{3.5f, 3.5f, 0.75f} * kVoxel, {0, 0, 1}, p).x, 1.0f, 1e-6f);
  EXPECT_NEAR(octreeIrradiance(o, Vec3{3.5f, 3.5f, 1.25f} * kVoxel, {0, 0, 1}, p).x, 3.0f, 1e-6f);
}

TEST(OctreeIrradiance, ANeighbourLitOnlyFromBehindLendsNoDarkness) {
  // A wall thinner than a voxel: the voxels x = 2 hold its inside face, lit
  // from +x (irradiance 2); the voxels x = 1 its outside face, lit from -x
  // only (5). A point of the inside face (normal +x) between the two columns'
  // centres interpolates over both; the outside column's light all arrives
  // from behind it, so it is left out: 2, not 2 x 0.6 (its weight counted as
  // darkness), and never any of the outside's 5.
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = kVoxel;
  g.frame.depth = 3;
  g.maxVdls = kMaxVdls;
  for (int x = 1; x <= 2; ++x)
    for (int y = 0; y < 8; ++y)
      for (int z = 0; z < 8; ++z) {
        g.coords.push_back({x, y, z});
        g.normals.push_back({x == 2 ? 1.0f : -1.0f, 0, 0});
        g.vdlCount.push_back(1);
        g.vdls.push_back(x == 2 ? vdl({2, 2, 2}, {1, 0, 0}) : vdl({5, 5, 5}, {-1, 0, 0}));
        for (int i = 1; i < kMaxVdls; ++i) g.vdls.push_back(Vdl{});
      }
  const GpuOctree o = buildGpuOctree(g, test::paperCosine());
  OctreeShadeParams p;
  p.normalOffset = 0;
  const float c = decodedDirectionAt(o, Vec3{2.5f, 3.5f, 3.5f} * kVoxel).x;
  for (float x : {2.1f, 2.3f, 2.5f}) {
    const Vec3 e = octreeIrradiance(o, Vec3{x, 3.5f, 3.5f} * kVoxel, {1, 0, 0}, p);
    EXPECT_NEAR(e.x, 2.0f * c, 1e-4f) << "x = " << x;
  }
  // The outside face likewise sees only the outside's light.
  const Vec3 out = octreeIrradiance(o, Vec3{1.9f, 3.5f, 3.5f} * kVoxel, {-1, 0, 0}, p);
  EXPECT_NEAR(out.x, 5.0f * c, 1e-4f);
}

TEST(OctreeIrradiance, MaxVdlsAndHalfFloatTexels) {
  const GpuOctree full =
      buildGpuOctree(constantGrid(3, 0, 0, {vdl({4, 4, 4}, {0, 0, 1}), vdl({1, 2, 3}, {1, 0, 1})}),
                     test::paperCosine());
  GpuOctreeParams hp;
  hp.cosineCorrection = false;  // the paper's texels: what these checks compare
  hp.halfFloat = true;
  const GpuOctree half = buildGpuOctree(
      constantGrid(3, 0, 0, {vdl({4, 4, 4}, {0, 0, 1}), vdl({1, 2, 3}, {1, 0, 1})}), hp);
  const Vec3 p = Vec3{2.5f, 2.5f, 0.5f} * kVoxel, n{0, 0, 1};
  const float c1 = std::max(0.0f, decodedDirection(full, 1).z);
  OctreeShadeParams one;
  one.maxVdls = 1;
  EXPECT_NEAR(octreeIrradiance(full, p, n, one).y, 4.0f * decodedDirection(full, 0).z, 1e-5f);
  const Vec3 both = octreeIrradiance(full, p, n);
  EXPECT_NEAR(both.z, 4.0f * decodedDirection(full, 0).z + 3.0f * c1, 1e-5f);
  // Half floats: 11 significant bits.
  const Vec3 h = octreeIrradiance(half, p, n);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(h[ch], both[ch], 1e-3f * both[ch]);
}

TEST(OctreeIrradiance, CosineCorrectionReturnsTheBakedEstimateOnTheBakedSurface) {
  // The bake's VDLs sum to the irradiance on the voxel's surface (normal +z):
  // c1 + c2. The paper's form returns c1 cos1 + c2 cos2; corrected, the sum.
  const Vdl a = vdl({1.0f, 2.0f, 3.0f}, {std::sin(kPi / 3), 0, std::cos(kPi / 3)});
  const Vdl b = vdl({0.5f, 0.5f, 0.5f}, {0, 0.2f, 1});
  const Vdl grazing = vdl({2, 2, 2}, {std::cos(0.1f), 0, std::sin(0.1f)});  // ~84 degrees
  VdlGrid g = constantGrid(3, 0, 0, {a, b, grazing});
  GpuOctreeParams on;
  on.cosineCorrection = true;
  const GpuOctree paper = buildGpuOctree(g, test::paperCosine()), corrected = buildGpuOctree(g, on);
  const Vec3 p = Vec3{3.5f, 3.5f, 0.5f} * kVoxel, up{0, 0, 1};
  const float cosGrazing = decodedDirection(paper, 2).z;
  ASSERT_LT(cosGrazing, kMinCorrectionCosine);
  const Vec3 expected =
      a.irradiance + b.irradiance + grazing.irradiance * (cosGrazing / kMinCorrectionCosine);
  const Vec3 e = octreeIrradiance(corrected, p, up);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(e[ch], expected[ch], 1e-5f * expected[ch]);
  const Vec3 ePaper = octreeIrradiance(paper, p, up);
  EXPECT_LT(ePaper.x, 0.8f * e.x);
  // Another normal: each VDL scaled by cos(n, d) / cos(n_v, d).
  const Vec3 n = normalize(Vec3{1, 0, 1});
  Vec3 other{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const Vec3 d = decodedDirection(paper, k);
    other += g.vdls[size_t(k)].irradiance *
             (std::max(0.0f, dot(n, d)) / std::max(std::fabs(d.z), kMinCorrectionCosine));
  }
  const Vec3 eOther = octreeIrradiance(corrected, p, n);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(eOther[ch], other[ch], 1e-5f * other[ch]);
  // A voxel without a normal (opposite faces cancelled) keeps the baked values.
  for (Vec3& normal : g.normals) normal = {0, 0, 0};
  const Vec3 eNoNormal = octreeIrradiance(buildGpuOctree(g, on), p, up);
  for (int ch = 0; ch < 3; ++ch) EXPECT_NEAR(eNoNormal[ch], ePaper[ch], 1e-6f);
}

TEST(OctreeIrradiance, FirstHitImageOfALitPlaneIsTheAnalyticValueAtEveryPixel) {
  // A plane z = 0.3 (inside the first voxel layer) seen from above; every
  // voxel holds one VDL of irradiance c from 60 degrees off the normal.
  Scene scene;
  Material m;
  scene.materials.push_back(m);
  test::addQuad(scene, {0, 0, 0.3f * kVoxel}, {8 * kVoxel, 0, 0}, {0, 8 * kVoxel, 0}, {0, 0, 1}, 0);
  const Vec3 c{0.8f, 0.5f, 0.2f};
  const Vec3 d{std::sin(kPi / 3), 0, std::cos(kPi / 3)};
  const GpuOctree o = buildGpuOctree(constantGrid(3, 0, 0, {vdl(c, d)}), test::paperCosine());
  const Vec3 expected = c * dot(Vec3{0, 0, 1}, decodedDirection(o, 0));
  EXPECT_NEAR(expected.x, 0.4f, 0.01f);
  // Camera above the middle of the plane, looking down at part of it.
  const PinholeCamera camera =
      PinholeCamera::lookAt(Vec3{1, 1, 3}, Vec3{1, 1, 0}, 20.0f * kPi / 180.0f);
  FirstHitParams params;
  params.width = 24;
  params.height = 16;
  params.samplesPerPixel = 2;
  const RgbImage image = renderFirstHits(scene, camera, params, [&](const FirstHit& h) {
    EXPECT_NEAR(h.position.z, 0.3f * kVoxel, 1e-5f);
    EXPECT_GT(h.normal.z, 0.999f);  // turned to the camera's side
    return octreeIrradiance(o, h.position, h.normal);
  });
  for (size_t i = 0; i < image.pixelCount(); ++i)
    for (int ch = 0; ch < 3; ++ch) ASSERT_NEAR(image.at(i)[ch], expected[ch], 1e-5f) << i;

  // The same plane turned over (normal -z), of a material never culled (an
  // OBJ face; a glTF single-sided one the camera would not see from
  // behind): the camera still sees the side facing it, and the VDL from
  // above lights it.
  Scene flipped;
  m.backFaceCulling = false;
  flipped.materials.push_back(m);
  test::addQuad(flipped, {0, 0, 0.3f * kVoxel}, {0, 8 * kVoxel, 0}, {8 * kVoxel, 0, 0}, {0, 0, -1},
                0);
  const RgbImage image2 = renderFirstHits(flipped, camera, params, [&](const FirstHit& h) {
    return octreeIrradiance(o, h.position, h.normal);
  });
  EXPECT_NEAR(image2.at(5).x, expected.x, 1e-5f);
}

// octreeIrradianceSample is a C++ twin of the shader's loOctreeIndirect that
// also sums the VDL directions: its E must be octreeIrradiance's, and its
// direction sum the luminance-weighted one of the VDLs the lookup reads.
TEST(OctreeIrradiance, SampleGivesTheLookupsIrradianceAndItsDirection) {
  // A slab of random VDLs, a few voxels empty (so interpolation renormalizes
  // and the nearest-leaf fallback runs).
  VdlGrid g = constantGrid(3, 0, 2, {});
  Rng rng(7, 0);
  for (size_t v = 0; v < g.size(); ++v) {
    const int count = rng.uniform() < 0.1f ? 0 : 1 + int(rng.uniformInt(4));
    g.vdlCount[v] = uint8_t(count);
    for (int i = 0; i < count; ++i)
      g.vdls[v * kMaxVdls + size_t(i)] =
          vdl(Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 3.0f, test::randomUnit(rng));
  }
  GpuOctreeParams half = test::paperCosine();
  half.halfFloat = true;
  for (const GpuOctree& o : {buildGpuOctree(g, test::paperCosine()), buildGpuOctree(g, half)}) {
    for (int trial = 0; trial < 400; ++trial) {
      OctreeShadeParams p;
      p.interpolation = trial % 2 == 0;
      p.maxVdls = 1 + trial % 4;
      const Vec3 q{0.2f + 7.6f * rng.uniform(), 0.2f + 7.6f * rng.uniform(),
                   0.05f + 2.9f * rng.uniform()};
      const Vec3 pos = q * kVoxel, n = test::randomUnit(rng);
      const OctreeIrradianceSample s = octreeIrradianceSample(o, pos, n, p);
      const Vec3 e = octreeIrradiance(o, pos, n, p);
      for (int c = 0; c < 3; ++c) ASSERT_NEAR(s.irradiance[c], e[c], 1e-6f * (1 + e[c])) << trial;
      ASSERT_LE(length(s.directionSum), luminance(e) * (1 + 1e-5f) + 1e-7f) << trial;
      if (p.interpolation) continue;
      // One leaf: the voxel in front of the point, else the one behind.
      OctreeSample leaf = lookupOctree(o, (q + n * p.normalOffset) * kVoxel);
      if (!leaf.found) leaf = lookupOctree(o, (q - n * p.normalOffset) * kVoxel);
      Vec3 expected{0, 0, 0};
      for (int i = 0; i < std::min(leaf.vdlCount, p.maxVdls); ++i) {
        const Vdl& v = leaf.vdls[i];
        expected += v.direction * (luminance(v.irradiance) * std::max(0.0f, dot(n, v.direction)));
      }
      ASSERT_NEAR(length(s.directionSum - expected), 0.0f, 1e-5f * (1 + length(expected))) << trial;
    }
  }
  // VDLs of one direction: the sum points along it, |sum| = Y(E).
  const Vec3 d = normalize(Vec3{0.3f, -0.5f, 0.8f});
  VdlGrid one = constantGrid(3, 0, 1, {vdl({1, 2, 3}, d)});
  for (size_t v = 0; v < one.size(); ++v)
    one.vdls[v * kMaxVdls].irradiance *= 1.0f + 0.1f * float(v % 7);
  const GpuOctree o = buildGpuOctree(one, test::paperCosine());
  const Vec3 dq = decodedDirection(o, 0);
  const OctreeIrradianceSample s =
      octreeIrradianceSample(o, Vec3{3.3f, 4.6f, 1.2f} * kVoxel, {0, 0, 1});
  EXPECT_GT(luminance(s.irradiance), 0.5f);
  EXPECT_NEAR(length(s.directionSum - dq * luminance(s.irradiance)), 0.0f, 1e-5f);
}

TEST(FirstHit, MissesCountZeroAndBadParamsAreRefused) {
  Scene scene = test::oneMaterialScene();
  // A quad covering the left half of the view only.
  test::addQuad(scene, {-10, -10, 0}, {10, 0, 0}, {0, 20, 0}, {0, 0, 1}, 0);
  const PinholeCamera camera = PinholeCamera::lookAt({0, 0, 5}, {0, 0, 0}, 0.5f);
  FirstHitParams params;
  params.width = 8;
  params.height = 4;
  params.samplesPerPixel = 1;
  const RgbImage image = renderFirstHits(scene, camera, params, [](const FirstHit&) {
    return Vec3{1, 1, 1};
  });
  for (int y = 0; y < 4; ++y) {
    EXPECT_EQ(image.at(size_t(y) * 8 + 0).x, 1.0f);
    EXPECT_EQ(image.at(size_t(y) * 8 + 7).x, 0.0f);
  }
  params.samplesPerPixel = 0;
  EXPECT_THROW(renderFirstHits(scene, camera, params, [](const FirstHit&) { return Vec3{}; }),
               InputError);
}

// The edge mask (reference/first_hit.h): a floor seen from above with a wall
// standing on it at x = 0.5. A floor hit is in the mask exactly when it lies
// within the distance of the wall's foot; the same jittered rays (same seed)
// give each pixel's hit point, so every pixel is checked against geometry.
TEST(FirstHit, EdgeMaskMarksTheHitsNearAnEdge) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {-3, -3, 0}, {6, 0, 0}, {0, 6, 0}, {0, 0, 1}, 0);              // floor
  test::addQuad(scene, {0.5f, -3, 0}, {0, 6, 0}, {0, 0, 1}, {-1, 0, 0}, 0);           // wall
  const PinholeCamera camera =
      PinholeCamera::lookAt({0, 0, 10}, {0, 0, 0}, 2.0f * std::atan(0.15f));
  FirstHitParams params;
  params.width = 60;
  params.height = 40;
  params.samplesPerPixel = 1;
  const float distance = 0.2f;
  const RgbImage mask = renderEdgeMask(scene, camera, params, distance);
  const RgbImage where = renderFirstHits(scene, camera, params, [](const FirstHit& h) {
    return Vec3{h.position.x, h.position.z, 1.0f};
  });
  int near = 0, far = 0;
  for (size_t i = 0; i < mask.pixelCount(); ++i) {
    const Vec3 w = where.at(i);
    ASSERT_EQ(w.z, 1.0f) << "pixel " << i << " missed the scene";
    if (w.y > 1e-4f || w.x >= 0.5f) continue;  // the wall, or beyond it
    const float gap = 0.5f - w.x;
    if (gap < distance - 1e-3f) {
      EXPECT_EQ(mask.at(i).x, 1.0f) << "floor hit " << gap << " from the wall";
      ++near;
    } else if (gap > distance + 1e-3f) {
      EXPECT_EQ(mask.at(i).x, 0.0f) << "floor hit " << gap << " from the wall";
      ++far;
    }
  }
  EXPECT_GT(near, 40);
  EXPECT_GT(far, 800);
  EXPECT_THROW(renderEdgeMask(scene, camera, params, 0.0f), InputError);
  // Beyond the scene's size every hit is near an edge: all ones, where 1e19
  // scene units made probes Embree aborted on.
  const RgbImage all = renderEdgeMask(scene, camera, params, 1e19f);
  for (size_t i = 0; i < all.pixelCount(); ++i) ASSERT_EQ(all.at(i).x, 1.0f) << "pixel " << i;
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// Surface layers in the octree (octree_layout.h's layer blocks): one voxel
// holding a floor (normal +y, lit by VDL A from above) and a wall standing on
// it (normal +x, at x = 0.5 voxel, lit by VDL B from +x). A point of the floor
// takes layer A, a point of the wall layer B; a floor point behind the wall
// (x < 0.5 voxel) is served by neither (the floor layer's surface lies on the
// other side of the wall's plane), and a point facing -z by neither. Float and
// half-float texels; without cosine correction, so the values are the VDLs'.
TEST(OctreeLayers, EachSurfaceOfAVoxelGetsItsOwnLayer) {
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = kVoxel;
  g.frame.depth = 2;
  g.maxVdls = 2;
  g.coords.push_back({1, 1, 1});
  g.normals.push_back({0, 1, 0});
  g.vdlCount.push_back(1);
  const Vdl a = vdl({2.0f, 1.5f, 1.0f}, {0, 1, 0}), b = vdl({0.5f, 0.25f, 1.0f}, {1, 0, 0});
  g.vdls = {a, Vdl{}};
  const Vec3 corner = Vec3{1, 1, 1} * kVoxel;
  g.points = {corner + Vec3{0.75f, 0.1f, 0.5f} * kVoxel};  // on the floor, +x of the wall
  g.layers.voxel = {0};
  g.layers.normals = {{1, 0, 0}};
  g.layers.points = {corner + Vec3{0.5f, 0.5f, 0.5f} * kVoxel};
  g.layers.irradiance = {b.irradiance};
  g.layers.photonCount = {10};
  g.layers.radius = {0.1f};
  g.layers.noise = {0.1f};
  g.layers.angularError = {0};
  g.layers.vdlCount = {1};
  g.layers.vdls = {b, Vdl{}};
  // Each layer's surface texel follows its VDLs: the lookup steps over it
  // to the next layer and reads the one of the layer it chose.
  const Vec3 floorRho{0.2f, 0.4f, 0.6f}, wallRho{0.7f, 0.5f, 0.3f};
  for (bool reflects : {false, true}) {
  SCOPED_TRACE(reflects ? "with reflectance" : "without");
  g.reflectance = {reflects ? floorRho : Vec3{}};
  g.layers.reflectance = {reflects ? wallRho : Vec3{}};
  for (int format = 0; format < 3; ++format) {
    const bool half = format > 0;
    SCOPED_TRACE(format == 0 ? "float" : format == 1 ? "half" : "compact");
    GpuOctreeParams params;
    params.halfFloat = half;
    params.compact = format == 2;
    params.cosineCorrection = false;
    const GpuOctree o = buildGpuOctree(g, params);
    EXPECT_EQ(o.leafCount, 1u);
    EXPECT_EQ(o.surfaceTexels, reflects);
    EXPECT_EQ(o.vdlCount, 1u + 2u * (reflects ? 3u : 2u))
        << "block header + per layer header, one VDL and the surface texel";
    const OctreeSample s = lookupOctree(o, corner + Vec3(0.6f) * kVoxel);
    EXPECT_EQ(s.layerCount, 2);
    EXPECT_EQ(s.vdlCount, 1);
    const float tol = half ? 2e-3f : 1e-4f;  // the 8+8-bit direction: cos within 2e-5
    OctreeShadeParams shade;
    for (bool interpolation : {true, false}) {
      shade.interpolation = interpolation;
      const Vec3 floorPoint = corner + Vec3{0.8f, 0.1f, 0.5f} * kVoxel;
      const Vec3 floorE = octreeIrradiance(o, floorPoint, {0, 1, 0}, shade);
      EXPECT_NEAR(length(floorE - a.irradiance), 0.0f, tol * length(a.irradiance));
      const Vec3 wallPoint = corner + Vec3{0.5f, 0.6f, 0.5f} * kVoxel;
      const Vec3 wallE = octreeIrradiance(o, wallPoint, {1, 0, 0}, shade);
      EXPECT_NEAR(length(wallE - b.irradiance), 0.0f, tol * length(b.irradiance));
      // Behind the wall the floor layer's surface lies on the wall's other
      // side: no voxel serves the point strictly, and rather than black the
      // lookup takes the layer closest in normal (the relaxed pass; below,
      // the same point beside a lit voxel of the wall's other side takes
      // that voxel's light alone).
      const Vec3 behind = corner + Vec3{0.2f, 0.1f, 0.5f} * kVoxel;
      const Vec3 behindE = octreeIrradiance(o, behind, {0, 1, 0}, shade);
      EXPECT_NEAR(length(behindE - a.irradiance), 0.0f, tol * length(a.irradiance));
      // A surface facing neither layer's way.
      EXPECT_EQ(octreeIrradiance(o, floorPoint, {0, 0, -1}, shade), Vec3(0.0f));
      // Tilted off the wall (the wall layer serves it): the wall's VDL, and
      // what the wall reflects of it from below the wall's plane.
      // The wall's normal and its VDL's direction as the texels pack them.
      const Vec3 n = normalize(Vec3{1, 0, 0.6f});
      const Vec3 m = unpacked(g.layers.normals[0]), d = unpacked(b.direction);
      const Vec3 tilted = octreeIrradiance(o, wallPoint, n, shade);
      const Vec3 expected =
          b.irradiance * dot(n, d) +
          (reflects ? wallRho * b.irradiance * (dot(m, d) * 0.5f * (1 - dot(n, m))) : Vec3{});
      EXPECT_NEAR(length(tilted - expected), 0.0f, tol * length(expected));
    }
  }
  }
  // The wall's other side holds a voxel of its own (-x of the wall's), its
  // floor lit by VDL c: it serves the floor behind the wall strictly, and the
  // floor layer's light stays on its side of the wall: the interpolation
  // takes c's light alone; the nearest voxel's lookup, which reads only the
  // point's own voxel and the one behind it, none.
  const Vdl c = vdl({0.1f, 0.2f, 0.3f}, {0, 1, 0});
  VdlGrid other = g;
  other.coords.push_back({0, 1, 1});
  other.normals.push_back({0, 1, 0});
  other.vdlCount.push_back(1);
  other.vdls.push_back(c);
  other.vdls.push_back(Vdl{});
  other.points.push_back(Vec3{0.5f, 1.1f, 1.5f} * kVoxel);
  other.reflectance.push_back(Vec3{});
  GpuOctreeParams params;
  params.cosineCorrection = false;
  const GpuOctree o = buildGpuOctree(other, params);
  ASSERT_EQ(o.leafCount, 2u);
  const Vec3 behind = corner + Vec3{0.2f, 0.1f, 0.5f} * kVoxel;
  for (bool interpolation : {true, false}) {
    SCOPED_TRACE(interpolation ? "interpolated" : "nearest");
    OctreeShadeParams shade;
    shade.interpolation = interpolation;
    const Vec3 behindE = octreeIrradiance(o, behind, {0, 1, 0}, shade);
    const Vec3 expected = interpolation ? c.irradiance : Vec3(0.0f);
    EXPECT_NEAR(length(behindE - expected), 0.0f, 1e-4f * length(c.irradiance));
  }
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// Compact texels (RGB9E5 times a scale per octree): the cosine law within
// RGB9E5's rounding (9-bit mantissas: 2^-9 of the largest channel), and a
// light a million times brighter gives a million times the irradiance,
// where half floats clamp at 65504.
TEST(CompactTexels, RoundTripAndNoClampingAtAnyPower) {
  for (float power : {1.0f, 1e6f, 1e-6f}) {
    SCOPED_TRACE(power);
    const Vec3 c = Vec3{2.0f, 1.0f, 0.5f} * power;
    const VdlGrid g = constantGrid(3, 2, 3, {vdl(c, {0.3f, 0.5f, 0.8f}), vdl(c * 0.25f, {-0.6f, 0.2f, 0.7f})});
    GpuOctreeParams fp;
    fp.cosineCorrection = false;
    GpuOctreeParams cp = fp;
    cp.compact = true;
    const GpuOctree f = buildGpuOctree(g, fp), k = buildGpuOctree(g, cp);
    EXPECT_TRUE(k.compact);
    EXPECT_EQ(k.vdlBytes() * 2, f.vdlBytes());
    // A power of two.
    EXPECT_EQ(std::exp2(std::round(std::log2(k.irradianceScale))), k.irradianceScale);
    for (const Vec3& n : {Vec3{0, 0, 1}, normalize(Vec3{0.2f, 0.3f, 1.0f})}) {
      const Vec3 p = Vec3{1.3f, 2.2f, 2.5f} * kVoxel;
      const Vec3 ef = octreeIrradiance(f, p, n), ek = octreeIrradiance(k, p, n);
      for (int a = 0; a < 3; ++a) EXPECT_NEAR(ek[a], ef[a], 4e-3f * ef[a]) << a;
    }
  }
  // Half floats clamp a million-fold light; compact texels do not.
  const Vec3 c = Vec3{2.0f, 1.0f, 0.5f} * 1e6f;
  const VdlGrid g = constantGrid(3, 2, 3, {vdl(c, {0, 0, 1})});
  GpuOctreeParams hp, cp;
  hp.halfFloat = true;
  hp.cosineCorrection = cp.cosineCorrection = false;
  cp.compact = true;
  const Vec3 p = Vec3{1.3f, 2.2f, 2.5f} * kVoxel;
  EXPECT_LT(octreeIrradiance(buildGpuOctree(g, hp), p, {0, 0, 1}).x, 1e5f);
  EXPECT_NEAR(octreeIrradiance(buildGpuOctree(g, cp), p, {0, 0, 1}).x, c.x, 4e-3f * c.x);
}

TEST(CompactTexels, EncodingMatchesTheGlSpec) {
  // Exact values: 1 = 256 * 2^-8 (exponent 16), 0.5 and 0.25 share it.
  const uint32_t one = encodeRgb9e5({1.0f, 0.5f, 0.25f});
  EXPECT_EQ(one >> 27, 16u);
  EXPECT_EQ(one & 511u, 256u);
  EXPECT_EQ((one >> 9) & 511u, 128u);
  EXPECT_EQ((one >> 18) & 511u, 64u);
  EXPECT_EQ(encodeRgb9e5({0, 0, 0}), 0u);
  EXPECT_EQ(encodeRgb9e5({-1.0f, std::nanf(""), 0}), 0u);  // negative and NaN: 0
  const uint32_t big = encodeRgb9e5({1e9f, 0, 0});         // clamps to 65408
  EXPECT_EQ(big >> 27, 31u);
  EXPECT_EQ(big & 511u, 511u);
  // Decoding (octree_layout.h) inverts it for representable values.
  for (float v : {1.0f, 3.0f, 0.125f, 1000.0f, 6.5e-5f}) {
    const uint32_t bits = encodeRgb9e5({v, 0, 0});
    EXPECT_NEAR(layout::loRgb9e5Channel(bits, 0u), v, v / 256.0f) << v;
  }
}

}  // namespace
}  // namespace lo
