// ProgressiveBake (octree/progressive_bake.h): levels arrive coarse to fine,
// each equal to a one-off bake of the same photons at its depth; only the
// newest is handed out; failures reach the caller; cancel stops the thread.

#include <gtest/gtest.h>

#include <chrono>
#include <thread>
#include <vector>

#include "core/error.h"
#include "bake/progressive_bake.h"
#include "test_util.h"

namespace lo {
namespace {

ProgressiveParams smallParams() {
  ProgressiveParams p;
  p.photons.storedPhotons = 20000;
  p.photons.seed = 3;
  p.firstDepth = 2;
  p.targetDepth = 4;
  p.gather.k = 40;
  p.cluster.seed = 7;
  return p;
}

void expectSameOctree(const GpuOctree& a, const GpuOctree& b) {
  EXPECT_EQ(a.depth, b.depth);
  EXPECT_EQ(a.origin, b.origin);
  EXPECT_EQ(a.cubeSize, b.cubeSize);
  EXPECT_EQ(a.pool, b.pool);
  EXPECT_EQ(a.vdlWidth, b.vdlWidth);
  EXPECT_EQ(a.vdlHeight, b.vdlHeight);
  EXPECT_EQ(a.vdlTexels, b.vdlTexels);
  EXPECT_EQ(a.leafCount, b.leafCount);
}

TEST(ProgressiveBake, FinalLevelEqualsAOneOffBakeOfTheSamePhotons) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  PhotonMap photons = tracePhotons(scene, params.photons);
  std::vector<Photon> copy = photons.photons;
  ProgressiveBake bake(scene, std::move(photons), params);
  bake.wait();
  EXPECT_EQ(bake.status().phase, ProgressiveStatus::Phase::Done) << bake.status().ToString();
  EXPECT_TRUE(bake.finished());
  EXPECT_EQ(bake.storedPhotons(), copy.size());
  EXPECT_EQ(bake.traceSeconds(), 0.0);

  std::vector<ProgressiveBake::LevelTiming> timings = bake.timings();
  ASSERT_EQ(timings.size(), 3u);
  for (size_t i = 0; i < timings.size(); ++i) {
    EXPECT_EQ(timings[i].depth, params.firstDepth + int(i));
    EXPECT_GT(timings[i].stats.activeVoxels, 0u);
    if (i > 0) {
      EXPECT_GE(timings[i].secondsAfterPhotons, timings[i - 1].secondsAfterPhotons);
      EXPECT_GT(timings[i].stats.activeVoxels, timings[i - 1].stats.activeVoxels);
    }
  }

  // Nobody polled while it ran: only the newest (finest) level is handed out.
  std::optional<ProgressiveLevel> level = bake.takeNewest();
  ASSERT_TRUE(level);
  EXPECT_EQ(level->depth, params.targetDepth);
  EXPECT_FALSE(bake.takeNewest()) << "each level is handed out once";
  EXPECT_GE(level->secondsAfterPhotons(), 0.0);

  LevelParams one;
  one.grid.depth = params.targetDepth;
  one.gather = params.gather;
  one.cluster = params.cluster;
  GpuOctree expected = buildGpuOctree(bakeLevel(scene, copy, one), params.octree);
  expectSameOctree(level->octree, expected);
}

TEST(ProgressiveBake, PollingSeesIncreasingDepthsEndingAtTheTarget) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  ProgressiveBake bake(scene, params);  // traces its own photons
  std::vector<int> seen;
  for (;;) {
    bool finished = bake.finished();  // before the poll: a level finished after it is not lost
    while (std::optional<ProgressiveLevel> level = bake.takeNewest()) seen.push_back(level->depth);
    if (finished) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_FALSE(seen.empty());
  for (size_t i = 1; i < seen.size(); ++i) EXPECT_GT(seen[i], seen[i - 1]);
  EXPECT_EQ(seen.back(), params.targetDepth);
  EXPECT_EQ(bake.storedPhotons(), params.photons.storedPhotons);
  EXPECT_GT(bake.traceSeconds(), 0.0);
}

TEST(ProgressiveBake, ALevelTooLargeForTheTextureLimitsFailsOnce) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  params.octree.max3DTextureSize = 2;  // room for the root tile only
  ProgressiveBake bake(scene, params);
  bake.wait();
  ProgressiveStatus status = bake.status();
  EXPECT_EQ(status.phase, ProgressiveStatus::Phase::Failed);
  EXPECT_NE(status.error.find("3D texture size limit 2"), std::string::npos) << status.error;
  EXPECT_THROW(bake.takeNewest(), InputError);
  EXPECT_FALSE(bake.takeNewest()) << "the failure is reported once";
}

TEST(ProgressiveBake, CancelStopsTheThread) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  params.photons.storedPhotons = 5000000;  // seconds of tracing: cancel arrives well before
  params.targetDepth = 8;
  ProgressiveBake bake(scene, params);
  bake.cancel();
  bake.wait();
  EXPECT_EQ(bake.status().phase, ProgressiveStatus::Phase::Cancelled) << bake.status().ToString();
  EXPECT_TRUE(bake.timings().empty());
  EXPECT_FALSE(bake.takeNewest());
}

TEST(ProgressiveBake, CancelDuringALevelStopsBeforeTheTarget) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  params.targetDepth = 9;  // depth 9 alone takes seconds: cancel arrives before the end
  ProgressiveBake bake(scene, params);
  while (!bake.takeNewest()) {
    ASSERT_FALSE(bake.finished()) << bake.status().ToString();
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  bake.cancel();
  bake.wait();
  EXPECT_EQ(bake.status().phase, ProgressiveStatus::Phase::Cancelled) << bake.status().ToString();
  std::vector<ProgressiveBake::LevelTiming> timings = bake.timings();
  ASSERT_FALSE(timings.empty());
  EXPECT_LT(timings.back().depth, params.targetDepth);
}

TEST(ProgressiveBake, RefusesBadDepths) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  params.firstDepth = 5;
  params.targetDepth = 4;
  EXPECT_THROW(ProgressiveBake(scene, params), InputError);
  params.firstDepth = 0;
  EXPECT_THROW(ProgressiveBake(scene, params), InputError);
  params.firstDepth = 4;
  params.targetDepth = 13;
  EXPECT_THROW(ProgressiveBake(scene, params), InputError);
}

// view --progressive traced 2e8 photons for a minute, growing, where bake
// refuses them at once (eighth hostile list F4-74): the same check, before
// any photon, under a limit the photons do not fit.
TEST(ProgressiveBake, PhotonsBeyondTheMemoryAreRefusedBeforeTracing) {
  Scene scene = test::pointLitRoom();
  ProgressiveParams params = smallParams();
  params.photons.storedPhotons = 20000000;  // 2.4 GB at kBakeBytesPerPhoton
  const std::optional<std::string> message = test::messageUnderAddressSpaceLimit(
      size_t(256) << 20, [&] { ProgressiveBake bake(scene, params); });
  if (!message) GTEST_SKIP() << "a lower address-space limit is already in force";
  EXPECT_NE(message->find("with the photons need about"), std::string::npos) << *message;
  EXPECT_NE(message->find("of memory available"), std::string::npos) << *message;
}

}  // namespace
}  // namespace lo
