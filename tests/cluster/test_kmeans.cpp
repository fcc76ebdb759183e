#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "cluster/kmeans_internal.h"
#include "cluster/vdl_cluster.h"
#include "core/error.h"
#include "core/rng.h"
#include "test_util.h"

namespace lo {
namespace {

// Direction within `jitter` (chord-ish) of `axis`.
Vec3 jittered(const Vec3& axis, float jitter, Rng& rng) {
  return normalize(axis + test::randomUnit(rng) * (jitter * rng.uniform()));
}

Vec3 sumValues(const std::vector<DirectionSample>& s) {
  double x = 0, y = 0, z = 0;
  for (const auto& d : s) {
    x += d.value.x;
    y += d.value.y;
    z += d.value.z;
  }
  return Vec3(float(x), float(y), float(z));
}

Vec3 sumVdls(const ClusterResult& r) {
  Vec3 s;
  for (int i = 0; i < r.count; ++i) s += r.vdls[i].irradiance;
  return s;
}

float angleDegrees(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(dot(normalize(a), normalize(b)), -1.0f, 1.0f)) * 180.0f / kPi;
}

void expectVec3Near(const Vec3& a, const Vec3& b, float tol) {
  EXPECT_NEAR(a.x, b.x, tol) << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.y, b.y, tol) << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.z, b.z, tol) << a.ToString() << " vs " << b.ToString();
}

ClusterResult cluster(const std::vector<DirectionSample>& s, int k, uint64_t stream = 0,
                      ClusterParams params = {}) {
  return clusterDirections(s.data(), s.size(), k, params, stream);
}

TEST(KMeans, RecoversPlantedDirectionsAndIrradianceSplit) {
  const Vec3 axes[3] = {{0, 0, 1}, {1, 0, 0}, normalize(Vec3(-1, -1, 0))};
  const Vec3 values[3] = {{0.01f, 0.01f, 0.01f}, {0.03f, 0.0f, 0.0f}, {0.0f, 0.002f, 0.004f}};
  Rng rng(7, 0);
  std::vector<DirectionSample> s;
  for (int i = 0; i < 300; ++i) {
    int g = i % 3;  // interleaved, so the result cannot depend on input grouping
    s.push_back({jittered(axes[g], 0.08f, rng), values[g]});
  }
  for (uint64_t stream = 0; stream < 20; ++stream) {
    ClusterResult r = cluster(s, 3, stream);
    ASSERT_EQ(r.count, 3);
    for (int g = 0; g < 3; ++g) {
      int best = 0;
      for (int i = 1; i < 3; ++i) {
        if (dot(r.vdls[i].direction, axes[g]) > dot(r.vdls[best].direction, axes[g])) best = i;
      }
      // 100 samples jittered by up to 0.08 rad: the mean is within ~1 degree.
      EXPECT_LT(angleDegrees(r.vdls[best].direction, axes[g]), 2.0f) << "group " << g;
      expectVec3Near(r.vdls[best].irradiance, values[g] * 100.0f, 1e-5f);
    }
    // Sorted by decreasing average irradiance: red group (1.0), white (1.0), blue (0.2).
    EXPECT_GE(average(r.vdls[0].irradiance), average(r.vdls[1].irradiance));
    EXPECT_GE(average(r.vdls[1].irradiance), average(r.vdls[2].irradiance));
    EXPECT_LT(r.angularError, 0.08f);
    EXPECT_GT(r.angularError, 0.0f);
  }
}

TEST(KMeans, VdlsSumToTotalForRandomInputs) {
  Rng rng(11, 0);
  for (int trial = 0; trial < 200; ++trial) {
    size_t n = 1 + rng.uniformInt(400);
    int k = 1 + int(rng.uniformInt(kMaxVdls));
    std::vector<DirectionSample> s(n);
    for (auto& d : s) {
      d.direction = test::randomUnit(rng);
      d.value = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 0.05f;
      if (rng.uniform() < 0.1f) d.value = Vec3{};  // some zero-weight samples
    }
    ClusterResult r = cluster(s, k, uint64_t(trial));
    Vec3 total = sumValues(s);
    Vec3 got = sumVdls(r);
    ASSERT_GE(r.count, 1);
    ASSERT_LE(r.count, k);
    // Each VDL is one float rounding of a double sum; adding <= 8 of them in
    // float costs a few ulps of the total.
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], total[c], 1e-6f * (1.0f + total[c]));
    for (int i = 0; i < r.count; ++i) EXPECT_NEAR(length(r.vdls[i].direction), 1.0f, 1e-5f);
    for (int i = r.count; i < kMaxVdls; ++i) {
      EXPECT_EQ(r.vdls[i].irradiance, Vec3{});
      EXPECT_EQ(r.vdls[i].direction, Vec3{});
    }
  }
}

// Brute-force check of the Lloyd fixed point: every sample's nearest VDL
// (by chord) is the VDL whose irradiance it was summed into, and each direction
// is the normalized weighted mean of those samples.
TEST(KMeans, ConvergedResultIsALloydFixedPoint) {
  Rng rng(5, 0);
  ClusterParams params;
  params.maxIterations = 200;
  for (int trial = 0; trial < 50; ++trial) {
    std::vector<DirectionSample> s(250);
    for (auto& d : s) {
      d.direction = test::randomUnit(rng);
      d.value = Vec3(rng.uniform() + 0.1f);
    }
    ClusterResult r = cluster(s, 4, uint64_t(trial), params);
    ASSERT_EQ(r.count, 4);
    Vec3 irr[kMaxVdls], mean[kMaxVdls];
    for (const auto& d : s) {
      int best = 0;
      for (int i = 1; i < r.count; ++i) {
        if (lengthSquared(d.direction - r.vdls[i].direction) <
            lengthSquared(d.direction - r.vdls[best].direction))
          best = i;
      }
      irr[best] += d.value;
      mean[best] += d.direction * average(d.value);
    }
    for (int i = 0; i < r.count; ++i) {
      expectVec3Near(r.vdls[i].irradiance, irr[i], 1e-3f);
      expectVec3Near(r.vdls[i].direction, normalize(mean[i]), 1e-4f);
    }
  }
}

TEST(KMeans, FewerDistinctSamplesThanClusters) {
  std::vector<DirectionSample> s = {
      {{0, 0, 1}, {1, 1, 1}}, {{1, 0, 0}, {2, 2, 2}}, {{0, -1, 0}, {3, 0, 0}}};
  ClusterResult r = cluster(s, 8);
  ASSERT_EQ(r.count, 3);
  EXPECT_EQ(r.angularError, 0.0f);
  // Sorted by average: (2,2,2) > (1,1,1) == (3,0,0) tie broken by direction x then y.
  EXPECT_EQ(r.vdls[0].direction, Vec3(1, 0, 0));
  EXPECT_EQ(r.vdls[0].irradiance, Vec3(2, 2, 2));
  EXPECT_EQ(r.vdls[1].direction, Vec3(0, -1, 0));
  EXPECT_EQ(r.vdls[2].direction, Vec3(0, 0, 1));
  EXPECT_EQ(r.vdls[2].irradiance, Vec3(1, 1, 1));
}

TEST(KMeans, IdenticalDirectionsGiveOneVdl) {
  const Vec3 d = normalize(Vec3(0.3f, -0.5f, 0.8f));
  std::vector<DirectionSample> s(64, DirectionSample{d, {0.25f, 0.5f, 0.125f}});
  ClusterResult r = cluster(s, 4);
  ASSERT_EQ(r.count, 1);
  EXPECT_EQ(r.vdls[0].irradiance, Vec3(16, 32, 8));  // exact: powers of two
  expectVec3Near(r.vdls[0].direction, d, 1e-6f);
  // The centre is the renormalized mean, which can move d by an ulp.
  EXPECT_NEAR(r.angularError, 0.0f, 1e-6f);
}

TEST(KMeans, EmptyClusterIsDroppedAndEnergyKept) {
  Rng rng(3, 0);
  std::vector<DirectionSample> s;
  for (int i = 0; i < 50; ++i) s.push_back({jittered({0, 0, 1}, 0.2f, rng), {0.1f, 0.2f, 0.3f}});
  // A weight-0 sample near the empty centre: its value (average 0) still
  // counts, so it must move to the surviving cluster rather than vanish.
  s.push_back({{0, 0, -1}, {0.5f, -0.5f, 0.0f}});
  const Vec3 centres[2] = {{0, 0, 1}, {0, 0, -1}};
  ClusterResult r = kmeans_internal::clusterFromCentres(s.data(), s.size(), centres, 2, 20);
  ASSERT_EQ(r.count, 1);
  expectVec3Near(r.vdls[0].irradiance, sumValues(s), 1e-5f);
  EXPECT_GT(r.vdls[0].direction.z, 0.95f);
  EXPECT_EQ(r.vdls[1].irradiance, Vec3{});
}

TEST(KMeans, ZeroPowerGivesNoVdl) {
  std::vector<DirectionSample> s(10, DirectionSample{{0, 1, 0}, {0, 0, 0}});
  ClusterResult r = cluster(s, 4);
  EXPECT_EQ(r.count, 0);
  EXPECT_EQ(r.angularError, 0.0f);
  EXPECT_EQ(r.vdls[0].direction, Vec3{});
  EXPECT_EQ(clusterDirections(nullptr, 0, 4, {}, 0).count, 0);
}

TEST(KMeans, ZeroWeightSamplesNeverSeedOrPull) {
  const Vec3 lit{0, 1, 0};
  std::vector<DirectionSample> s;
  for (int i = 0; i < 20; ++i) s.push_back({lit, {1, 1, 1}});
  Rng rng(9, 0);
  for (int i = 0; i < 20; ++i) s.push_back({test::randomUnit(rng), {0, 0, 0}});
  for (uint64_t stream = 0; stream < 10; ++stream) {
    ClusterResult r = cluster(s, 4, stream);
    ASSERT_EQ(r.count, 1);
    EXPECT_EQ(r.vdls[0].direction, lit);
    EXPECT_EQ(r.vdls[0].irradiance, Vec3(20, 20, 20));
    EXPECT_EQ(r.angularError, 0.0f);
  }
}

TEST(KMeans, AngularErrorMatchesAnalyticValues) {
  // Two equal-weight directions theta apart, one cluster: the centre is the
  // bisector, each sample is theta/2 from it, chord 2 sin(theta/4).
  for (float deg : {10.0f, 45.0f, 90.0f, 150.0f}) {
    float t = deg * kPi / 180.0f;
    std::vector<DirectionSample> s = {{{std::sin(t / 2), 0, std::cos(t / 2)}, {1, 1, 1}},
                                      {{-std::sin(t / 2), 0, std::cos(t / 2)}, {1, 1, 1}}};
    ClusterResult r = cluster(s, 1);
    ASSERT_EQ(r.count, 1);
    EXPECT_NEAR(r.angularError, 2.0f * std::sin(t / 4), 1e-5f) << deg << " degrees";
    expectVec3Near(r.vdls[0].direction, {0, 0, 1}, 1e-6f);
    EXPECT_NEAR(cluster(s, 2).angularError, 0.0f, 1e-6f);
  }
  // Antipodal, weights 1 and 3: the mean points along the heavier one, the
  // lighter is a chord of 2 away: sqrt(1 * 4 / 4) = 1.
  std::vector<DirectionSample> s = {{{1, 0, 0}, {1, 1, 1}}, {{-1, 0, 0}, {3, 3, 3}}};
  ClusterResult r = cluster(s, 1);
  EXPECT_NEAR(r.angularError, 1.0f, 1e-6f);
  EXPECT_EQ(r.vdls[0].direction, Vec3(-1, 0, 0));
  // Antipodal, equal weights: the weighted sum is zero, so the centre stays on
  // its seed (one of the two); the error is sqrt((0 + 4) / 2).
  s[1].value = {1, 1, 1};
  r = cluster(s, 1);
  EXPECT_NEAR(r.angularError, std::sqrt(2.0f), 1e-6f);
  EXPECT_EQ(std::abs(r.vdls[0].direction.x), 1.0f);
  EXPECT_EQ(r.vdls[0].irradiance, Vec3(2, 2, 2));
}

TEST(KMeans, AutoCountPicksFewestAcceptable) {
  ClusterParams params;
  params.autoCount = true;
  Rng rng(21, 0);
  std::vector<DirectionSample> one, two;
  for (int i = 0; i < 200; ++i) {
    one.push_back({jittered({0, 0, 1}, 0.05f, rng), {1, 1, 1}});
    two.push_back({jittered(i % 2 ? Vec3(0, 0, 1) : Vec3(1, 0, 0), 0.05f, rng), {1, 1, 1}});
  }
  EXPECT_EQ(cluster(one, 8, 0, params).count, 1);
  ClusterResult r2 = cluster(two, 8, 0, params);
  EXPECT_GE(r2.count, 2);
  EXPECT_LE(r2.angularError, params.autoThreshold);
  // The cap wins over the threshold.
  EXPECT_EQ(cluster(two, 1, 0, params).count, 1);
  // Uniform directions never reach a tiny threshold: the cap is used.
  params.autoThreshold = 1e-4f;
  std::vector<DirectionSample> uniform;
  for (int i = 0; i < 300; ++i) uniform.push_back({test::randomUnit(rng), {1, 1, 1}});
  EXPECT_EQ(cluster(uniform, 5, 0, params).count, 5);
}

TEST(KMeans, DeterministicPerStream) {
  Rng rng(13, 0);
  std::vector<DirectionSample> s;
  for (int i = 0; i < 300; ++i) s.push_back({test::randomUnit(rng), {rng.uniform(), 0.5f, 0.2f}});
  auto same = [](const ClusterResult& a, const ClusterResult& b) {
    if (a.count != b.count || a.angularError != b.angularError) return false;
    for (int i = 0; i < kMaxVdls; ++i) {
      if (a.vdls[i].irradiance != b.vdls[i].irradiance ||
          a.vdls[i].direction != b.vdls[i].direction)
        return false;
    }
    return true;
  };
  ClusterParams params;
  params.maxIterations = 3;  // unconverged results differ more visibly between seeds
  ClusterResult a = cluster(s, 4, 42, params);
  EXPECT_TRUE(same(a, cluster(s, 4, 42, params)));
  int differing = 0;
  for (uint64_t stream = 0; stream < 10; ++stream)
    differing += !same(a, cluster(s, 4, stream, params));
  EXPECT_GT(differing, 0);
  params.seed = 2;
  EXPECT_FALSE(same(a, cluster(s, 4, 42, params)));
}

TEST(KMeans, RejectsBadClusterCount) {
  std::vector<DirectionSample> s(3, DirectionSample{{0, 0, 1}, {1, 1, 1}});
  EXPECT_THROW(cluster(s, 0), InputError);
  EXPECT_THROW(cluster(s, kMaxVdls + 1), InputError);
}

}  // namespace
}  // namespace lo
