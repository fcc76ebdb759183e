// Spherical harmonics beside VDLs (docs/accuracy.md, "Spherical harmonics"),
// against analytic answers: the projection of one direction is the known
// truncated series of the clamped cosine, with the order's known largest
// error; the scaling keeps the voxel's own irradiance; the octree and its
// C++ lookup return sum_i E_i Y_i(n) in float, half and compact texels; and
// an SH bake goes through the .vdb (with its surface layers) unchanged,
// passes inspect, and is refused by convert with a message.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <vector>

#include <octree_layout.h>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "bake/convert.h"
#include "cluster/vdl_cluster.h"
#include "core/error.h"
#include "core/math.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "test_util.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

/// E(n) = sum_i E_i Y_i(n) of `terms` coefficients.
Vec3 evaluate(const Vec3* sh, int terms, const Vec3& n) {
  Vec3 e{0, 0, 0};
  for (int i = 0; i < terms; ++i) e += sh[i] * layout::loShBasis(uint32_t(i), n.x, n.y, n.z);
  return e;
}

/// Unit directions spread over the sphere (a Fibonacci lattice), with the
/// poles and the equator of +z among them.
std::vector<Vec3> sphereDirections(int n) {
  std::vector<Vec3> out = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}};
  const float golden = kPi * (3.0f - std::sqrt(5.0f));
  for (int i = 0; i < n; ++i) {
    const float z = 1.0f - 2.0f * (float(i) + 0.5f) / float(n);
    const float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
    out.push_back({r * std::cos(golden * float(i)), r * std::sin(golden * float(i)), z});
  }
  return out;
}

// Ramamoorthi and Hanrahan (2001): a directional light of intensity I along d
// projected on SH up to band L and convolved with the clamped cosine gives
// E(n) = I sum_l A_l (2l + 1) / (4 pi) P_l(n . d): with c = n . d,
//   L1: I (1/4 + c/2)                      largest error against I max(0, c): I/4
//   L2: I (1/4 + c/2 + (15 c^2 - 5) / 32)  largest error: 3 I / 32 (at c = 0)
TEST(SphericalHarmonics, OneDirectionIsTheKnownTruncatedSeries) {
  const Vec3 d = normalize(Vec3{0.3f, -0.5f, 0.8f});
  const DirectionSample sample{d, {2.0f, 1.0f, 0.5f}};
  for (int terms : {4, 9}) {
    Vec3 sh[9];
    projectSh(&sample, 1, Vec3{0, 0, 0}, terms, sh);  // no normal: no division, no scaling
    double worst = 0;
    for (const Vec3& n : sphereDirections(2000)) {
      const float c = dot(n, d);
      const double series = terms == 4 ? 0.25 + 0.5 * c
                                       : 0.25 + 0.5 * c + (15.0 * c * c - 5.0) / 32.0;
      const Vec3 e = evaluate(sh, terms, n);
      for (int a = 0; a < 3; ++a) {
        EXPECT_NEAR(e[a], sample.value[a] * series, 2e-6 * sample.value[a]) << terms << " terms";
      }
      worst = std::max(worst, std::fabs(double(e.x) - 2.0 * std::max(0.0f, c)) / 2.0);
    }
    // The order's known largest error, reached on the lattice within 1e-3.
    const double known = terms == 4 ? 0.25 : 3.0 / 32.0;
    EXPECT_NEAR(worst, known, 1e-3) << terms << " terms";
  }
}

TEST(SphericalHarmonics, ScalingKeepsTheVoxelsOwnIrradiance) {
  // Photons from three directions of the upper hemisphere on a surface
  // facing +z, one grazing below kShMinCosine: E(n_v) is their sum exactly.
  const Vec3 up{0, 0, 1};
  const std::vector<DirectionSample> samples = {
      {normalize(Vec3{0.2f, 0.1f, 1.0f}), {1.0f, 0.5f, 0.25f}},
      {normalize(Vec3{-1.0f, 0.3f, 0.6f}), {0.3f, 0.6f, 0.9f}},
      {normalize(Vec3{0.0f, 1.0f, 0.1f}), {0.2f, 0.2f, 0.2f}}};
  Vec3 sum{0, 0, 0};
  for (const DirectionSample& s : samples) sum += s.value;
  for (int terms : {4, 9}) {
    Vec3 sh[9];
    projectSh(samples.data(), samples.size(), up, terms, sh);
    const Vec3 e = evaluate(sh, terms, up);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(e[a], sum[a], 1e-6f * sum[a]) << terms << " terms";
    // Brute force at other normals: the lights' intensities I_k = c_k /
    // max(cos_k, kShMinCosine) give E(n) = s sum_k I_k max(0, n . d_k), s
    // the scale that made E(n_v) exact, up to the order's error per light.
    double truthAtNormal = 0, intensity = 0;
    for (const DirectionSample& k : samples) {
      const double i = double(k.value.x) / std::max(double(k.direction.z), double(kShMinCosine));
      truthAtNormal += i * std::max(0.0, double(k.direction.z));
      intensity += i;
    }
    const double scale = sum.x / truthAtNormal;
    const double bound = (terms == 4 ? 0.25 : 3.0 / 32.0) * intensity * scale;
    for (const Vec3& n : sphereDirections(200)) {
      double truth = 0;
      for (const DirectionSample& k : samples) {
        truth += double(k.value.x) / std::max(double(k.direction.z), double(kShMinCosine)) *
                 std::max(0.0, double(dot(n, k.direction)));
      }
      EXPECT_LE(std::fabs(double(evaluate(sh, terms, n).x) - scale * truth), bound + 1e-5)
          << terms << " terms at " << n.ToString();
    }
  }
  // No samples: all terms zero.
  Vec3 sh[9];
  projectSh(nullptr, 0, up, 9, sh);
  for (const Vec3& t : sh) EXPECT_EQ(luminance(t), 0.0f);
}

// One photon from behind the layer's surface (a thin wall's dark layer may
// gather one whose own normal faced its way): the series is negative at the
// normal, so the channel is kept as a constant that still equals the
// estimate there, as the file's check (E(n) = irradiance) demands.
TEST(Sh, ASeriesNotPositiveAtTheNormalKeepsTheEstimateAsAConstant) {
  const Vec3 up{0, 0, 1};
  const DirectionSample grazing{normalize(Vec3{0.1f, 0, -1}), Vec3(0.5f)};
  // Order 1 from straight behind: E(n) ~ 1/4 - 1/2 of the light, negative.
  Vec3 sh[9];
  projectSh(&grazing, 1, up, 4, sh);
  EXPECT_NEAR(evaluate(sh, 4, up).x, 0.5f, 1e-6f);
  EXPECT_NEAR(evaluate(sh, 4, Vec3{1, 0, 0}).x, 0.5f, 1e-6f) << "a constant";
  EXPECT_NEAR(evaluate(sh, 4, Vec3{0, 0, -1}).x, 0.5f, 1e-6f) << "a constant";
  // Order 2 rings positive there: scaled as usual, the estimate kept.
  projectSh(&grazing, 1, up, 9, sh);
  EXPECT_NEAR(evaluate(sh, 9, up).x, 0.5f, 1e-5f);
}

/// A slab of depth-3 voxels at z = 0 whose SH hold one projected direction.
VdlGrid shSlab(int terms, float power) {
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = 0.25f;
  g.frame.depth = 3;
  g.shTerms = terms;
  const DirectionSample sample{normalize(Vec3{0.4f, 0.2f, 1.0f}), Vec3{3.0f, 2.0f, 1.0f} * power};
  Vec3 sh[9];
  projectSh(&sample, 1, {0, 0, 1}, terms, sh);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      g.coords.push_back({x, y, 0});
      g.normals.push_back({0, 0, 1});
      g.areas.push_back(0.0625f);
      g.irradiance.push_back(sample.value);
      g.photonCount.push_back(1);
      g.radius.push_back(0.3f);
      g.noise.push_back(0.05f);
      g.reflectance.push_back({0, 0, 0});  // nothing reflected: the terms alone
      g.angularError.push_back(0);
      g.vdlCount.push_back(0);
      for (int i = 0; i < g.maxVdls; ++i) g.vdls.push_back(Vdl{});
      g.sh.insert(g.sh.end(), sh, sh + terms);
    }
  }
  return g;
}

TEST(SphericalHarmonics, OctreeLookupEvaluatesTheTermsInEveryTexelFormat) {
  for (int terms : {4, 9}) {
    // 1e6: compact texels scale instead of clamping (halves stop at 65504).
    for (float power : {1.0f, 1e6f}) {
      const VdlGrid g = shSlab(terms, power);
      GpuOctreeParams half, compact;
      half.halfFloat = true;
      compact.compact = true;
      const GpuOctree octrees[3] = {buildGpuOctree(g), buildGpuOctree(g, half),
                                    buildGpuOctree(g, compact)};
      const float tolerance[3] = {1e-5f, 2e-3f, 2e-3f};
      EXPECT_EQ(octrees[0].vdlCount, 64u * size_t(terms));
      for (int k = 0; k < 3; ++k) {
        if (k == 1 && power > 1e4f) continue;  // half texels clamp there (documented)
        for (const Vec3& n : {Vec3{0, 0, 1}, normalize(Vec3{1, 0, 1}), normalize(Vec3{-1, 1, 2})}) {
          const Vec3 p = Vec3{3.5f, 4.5f, 0.5f} * 0.25f;
          Vec3 expected = evaluate(g.shOf(0), terms, n);
          for (int a = 0; a < 3; ++a) expected[a] = std::max(0.0f, expected[a]);
          const Vec3 e = octreeIrradiance(octrees[k], p, n);
          for (int a = 0; a < 3; ++a) {
            EXPECT_NEAR(e[a], expected[a], tolerance[k] * luminance(expected) + 1e-6f)
                << terms << " terms, texel format " << k << ", power " << power;
          }
          // The dominant direction sum has the irradiance's luminance as its length.
          const OctreeIrradianceSample s = octreeIrradianceSample(octrees[k], p, n);
          EXPECT_NEAR(length(s.directionSum), luminance(e), 1e-4f * luminance(e));
        }
      }
    }
  }
}

// A small SH bake with surface layers through the .vdb: the same grid comes
// back, inspect passes (E at each normal is its irradiance), the file says
// what it is (format version 3, representation), and convert refuses it.
TEST(SphericalHarmonics, BakeRoundTripsThroughTheVdbFile) {
  const std::string dir = test::outputDir("sh_vdb");
  const Scene scene = loadScene(test::dataDir() + "/cornell-box.gltf");
  BakeParams p = test::smallBake(4, 60000, 60);
  p.representation = LightRepresentation::Sh2;
  const BakeResult baked = bake(scene, p);
  ASSERT_EQ(baked.grid.shTerms, 9);
  ASSERT_GT(baked.grid.layers.size(), 0u);
  const std::string path = dir + "/sh2.vdb";
  writeVdlGrid(path, baked.grid, baked.metadata);
  const LoadedVdl read = readVdlGrid(path);
  EXPECT_EQ(read.meta.formatVersion, kVdlFormatVersion);
  EXPECT_EQ(read.meta.representation, "sh2");
  ASSERT_EQ(read.grid.shTerms, 9);
  ASSERT_EQ(read.grid.size(), baked.grid.size());
  ASSERT_EQ(read.grid.layers.size(), baked.grid.layers.size());
  for (size_t i = 0; i < baked.grid.sh.size(); ++i) {
    ASSERT_EQ(read.grid.sh[i], baked.grid.sh[i]) << "term " << i;
  }
  for (size_t i = 0; i < baked.grid.layers.sh.size(); ++i) {
    ASSERT_EQ(read.grid.layers.sh[i], baked.grid.layers.sh[i]) << "layer term " << i;
  }
  const VdbReport report = inspectVdb(path);
  for (const VdbCheck& c : report.checks) EXPECT_TRUE(c.passed) << c.name << ": " << c.detail;
  EXPECT_TRUE(std::any_of(report.checks.begin(), report.checks.end(),
                          [](const VdbCheck& c) { return c.name == "sh_sum"; }));
  // The octree of the file is the octree of the bake.
  const GpuOctree a = buildGpuOctree(baked.grid), b = buildGpuOctree(read.grid);
  EXPECT_EQ(a.vdlTexelsHalf, b.vdlTexelsHalf);
  EXPECT_EQ(a.pool, b.pool);
  try {
    convertLightGrid(read.grid, read.meta, ConvertParams{});
    ADD_FAILURE() << "convert accepted an SH file";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("convert works on VDL files"), std::string::npos)
        << e.what();
  }
  // A VDL bake stays format version 2: readers of version 2 still open it.
  BakeParams vp = p;
  vp.representation = LightRepresentation::Vdl;
  const BakeResult vdl = bake(scene, vp);
  writeVdlGrid(dir + "/vdl.vdb", vdl.grid, vdl.metadata);
  EXPECT_EQ(readVdlGrid(dir + "/vdl.vdb").meta.formatVersion, kVdlFormatVersionVdl);
}

}  // namespace
}  // namespace lo
