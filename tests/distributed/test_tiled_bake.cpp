// The distributed bake (src/distributed) on thread ranks: the same grid,
// value for value and .vdb byte for byte, as the one-process bake, for 1 to
// 4 ranks; its parts (tile plan, halo lookup, grid parts, communicator)
// against brute force.

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <iterator>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <random>
#include <set>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "core/error.h"
#include "distributed/communicator.h"
#include "distributed/rank_agreement.h"
#include "distributed/tiled_bake.h"
#include "distributed/vdl_grid_parts.h"
#include "scene/scene.h"
#include "test_util.h"
#include "core/file.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

/// The first voxel where two grids differ, or "" when they are equal value
/// for value (every array, the layers included).
std::string firstDifference(const VdlGrid& a, const VdlGrid& b) {
  if (serializeVdlGrid(a) == serializeVdlGrid(b)) return "";
  if (a.size() != b.size()) {
    return "voxels " + std::to_string(a.size()) + " vs " + std::to_string(b.size());
  }
  if (a.layers.size() != b.layers.size()) {
    return "layers " + std::to_string(a.layers.size()) + " vs " + std::to_string(b.layers.size());
  }
  for (size_t v = 0; v < a.size(); ++v) {
    const VdlGrid one = selectVoxels(a, {uint32_t(v)}), two = selectVoxels(b, {uint32_t(v)});
    if (serializeVdlGrid(one) != serializeVdlGrid(two)) {
      return "voxel " + std::to_string(v) + " at " + a.coords[v].ToString() + ": irradiance " +
             a.irradiance[v].ToString() + " vs " + b.irradiance[v].ToString() + ", photons " +
             std::to_string(a.photonCount[v]) + " vs " + std::to_string(b.photonCount[v]);
    }
  }
  return "the frames or payloads differ";
}

struct RankRun {
  BakeResult result;
  DistributedStats stats;
};

RankRun bakeOnThreadRanks(const Scene& scene, const BakeParams& params, int ranks, int tiles,
                          const std::vector<int32_t>& owner = {}, double assumedMargin = 0.25) {
  RankRun run;
  std::mutex mutex;
  TileParams tileParams;
  tileParams.assumedMarginVoxels = assumedMargin;
  tileParams.tilesPerAxis = tiles;
  tileParams.owner = owner;
  runThreadRanks(ranks, [&](Communicator& comm) {
    DistributedStats stats;
    BakeResult r = distributedBake(scene, params, tileParams, comm, nullptr, &stats);
    if (comm.rank() == 0) {
      std::lock_guard<std::mutex> lock(mutex);
      run.result = std::move(r);
      run.stats = std::move(stats);
    } else {
      EXPECT_EQ(r.grid.size(), 0u) << "rank " << comm.rank() << " returns no grid";
    }
  });
  return run;
}

/// Bakes `scene` on one process and on 1..4 thread ranks; every grid and
/// its .vdb bytes must be the same.
void expectSameAsOneProcess(const Scene& scene, const BakeParams& params, int tiles,
                            const std::string& name) {
  const BakeResult single = bake(scene, params);
  ASSERT_GT(single.grid.size(), 100u);
  const std::string dir = test::outputDir(name);
  writeVdlGrid(dir + "/single.vdb", single.grid, single.metadata);
  const std::string expected = readFile(dir + "/single.vdb");
  for (int ranks = 1; ranks <= 4; ++ranks) {
    const RankRun run = bakeOnThreadRanks(scene, params, ranks, tiles);
    EXPECT_EQ(firstDifference(single.grid, run.result.grid), "") << ranks << " ranks";
    const std::string path = dir + "/ranks" + std::to_string(ranks) + ".vdb";
    writeVdlGrid(path, run.result.grid, run.result.metadata);
    EXPECT_TRUE(readFile(path) == expected) << ranks << " ranks: " << path << " differs";
    EXPECT_EQ(run.result.stats.storedPhotons, single.stats.storedPhotons);
    EXPECT_EQ(run.result.stats.emittedPaths, single.stats.emittedPaths);
    EXPECT_EQ(run.result.stats.emptyPaths, single.stats.emptyPaths);
    EXPECT_EQ(run.result.stats.level.activeVoxels, single.stats.level.activeVoxels);
    EXPECT_EQ(run.result.stats.level.droppedPhotons, single.stats.level.droppedPhotons);
    // Each rank held and owned a part: the work was split.
    ASSERT_EQ(run.stats.ranks.size(), size_t(ranks));
    uint64_t owned = 0, traced = 0;
    for (const RankStats& s : run.stats.ranks) {
      EXPECT_GT(s.voxelsOwned, 0u) << "rank " << s.rank << " of " << ranks;
      if (ranks > 1) {
        EXPECT_LT(s.photonsHeld, single.stats.storedPhotons) << "rank " << s.rank;
      }
      owned += s.voxelsOwned;
      traced += s.photonsTraced;
    }
    EXPECT_EQ(owned, single.grid.size());
    EXPECT_EQ(traced, single.stats.storedPhotons);
  }
}

TEST(TiledBake, CornellBoxIsTheOneProcessBakeFor1To4Ranks) {
  const Scene scene = loadScene(test::sharedScenesDir() + "/composed/cornell-box.glb");
  BakeParams params = test::smallBake(5, 60000, 80);
  expectSameAsOneProcess(scene, params, 4, "TiledBake.Cornell");
}

TEST(TiledBake, DragonWithShIsTheOneProcessBakeFor1To4Ranks) {
  const Scene scene = loadScene(test::sharedScenesDir() + "/composed/cornell-dragon.glb");
  BakeParams params = test::smallBake(5, 40000, 60);
  params.representation = LightRepresentation::Sh1;
  params.includeDirect = true;
  // Fewer free-space rays than the paths make: rank 0 takes the same whole
  // paths as one process.
  params.freeSpaceRays = 30000;
  expectSameAsOneProcess(scene, params, 4, "TiledBake.Dragon");
}

TEST(TiledBake, AutoVdlsAndAWideRadiusAreTheOneProcessBake) {
  // A radius of 3 voxels widens the halo; --vdls auto and no smoothing.
  Scene scene = test::pointLitRoom();
  BakeParams params = test::smallBake(5, 30000, 40);
  params.radius = 3.0f / 32.0f;
  params.vdls = parseVdlCount("auto");
  params.smoothing = false;
  expectSameAsOneProcess(scene, params, 2, "TiledBake.Room");
}

TEST(TiledBake, ATileBoundaryThroughAWallJointChangesNothing) {
  // A floor with a wall standing on it at x = 0, lit from both sides: the
  // grid's cube is centred on x = 0, so with 2 tiles per axis, rank 0 owning
  // x < 0 and rank 1 x >= 0, the ranks' boundary is the plane of the wall,
  // through its joint with the floor.
  Scene scene;
  Material grey;
  grey.baseColor = Vec3(0.7f);
  grey.doubleSided = true;
  scene.materials.push_back(grey);
  test::addQuad(scene, Vec3(-1, 0, -1), Vec3(2, 0, 0), Vec3(0, 0, 2), Vec3(0, 1, 0), 0);
  test::addQuad(scene, Vec3(0, 0, -1), Vec3(0, 0, 2), Vec3(0, 1, 0), Vec3(1, 0, 0), 0);
  for (float x : {-0.5f, 0.5f}) {
    Light light;
    light.position = Vec3(x, 0.6f, 0.2f * x);
    light.intensity = 1.0f;
    scene.lights.push_back(light);
  }
  BakeParams params = test::smallBake(5, 40000, 60);
  params.includeDirect = true;
  const BakeResult single = bake(scene, params);
  const RankRun run = bakeOnThreadRanks(scene, params, 2, 2, {0, 0, 0, 0, 1, 1, 1, 1});
  EXPECT_EQ(firstDifference(single.grid, run.result.grid), "");

  // The boundary is where it was meant to be: the wall lies on voxel
  // x = 16's lower face, and both sides of the joint hold lit voxels.
  ASSERT_EQ(run.stats.tileOwner, std::vector<int32_t>({0, 0, 0, 0, 1, 1, 1, 1}));
  const Coord wall = single.grid.frame.coordOf(Vec3(0, 0, 0));
  ASSERT_EQ(wall.x, 16);
  int joint[2] = {0, 0};
  for (size_t v = 0; v < single.grid.size(); ++v) {
    const Coord c = single.grid.coords[v];
    if (c.y == wall.y && (c.x == 15 || c.x == 16) && single.grid.lit(v)) ++joint[c.x == 16];
  }
  EXPECT_GT(joint[0], 10);
  EXPECT_GT(joint[1], 10);
}

TEST(TiledBake, ABinMarginBeyondTheAssumedOneStartsAgainWithTheBound) {
  // An assumed margin below zero is always exceeded: the second attempt,
  // with the bound's wider halo, must give the same grid.
  const Scene scene = test::pointLitRoom();
  BakeParams params = test::smallBake(5, 20000, 40);
  const BakeResult single = bake(scene, params);
  const RankRun first = bakeOnThreadRanks(scene, params, 3, 2);
  const RankRun again = bakeOnThreadRanks(scene, params, 3, 2, {}, -1.0);
  EXPECT_EQ(first.stats.attempts, 1);
  EXPECT_EQ(again.stats.attempts, 2);
  EXPECT_GT(again.stats.photonHalo, first.stats.photonHalo);
  EXPECT_EQ(firstDifference(single.grid, again.result.grid), "");
  EXPECT_EQ(again.result.stats.storedPhotons, single.stats.storedPhotons);
}

TEST(TiledBake, RanksWithoutTilesHoldNothingAndChangeNothing) {
  // One tile for three ranks: two own nothing, trace their paths and send
  // every photon away.
  const Scene scene = test::pointLitRoom();
  BakeParams params = test::smallBake(4, 10000, 30);
  const BakeResult single = bake(scene, params);
  const RankRun run = bakeOnThreadRanks(scene, params, 3, 1);
  EXPECT_EQ(firstDifference(single.grid, run.result.grid), "");
  ASSERT_EQ(run.stats.ranks.size(), 3u);
  int owners = 0;
  uint64_t traced = 0;
  for (const RankStats& r : run.stats.ranks) {
    traced += r.photonsTraced;
    if (r.voxelsOwned == 0) {
      EXPECT_EQ(r.photonsHeld, 0u) << "rank " << r.rank;
      continue;
    }
    ++owners;
    EXPECT_EQ(r.voxelsOwned, single.grid.size());
    EXPECT_EQ(r.photonsHeld, single.stats.storedPhotons);
  }
  EXPECT_EQ(owners, 1);
  EXPECT_EQ(traced, single.stats.storedPhotons);
}

TEST(TiledBake, RefusesAPhotonMapAndBadTileCounts) {
  const Scene scene = test::pointLitRoom();
  BakeParams params = test::smallBake(4, 2000);
  params.keepPhotons = true;
  EXPECT_THROW(bakeOnThreadRanks(scene, params, 2, 0), InputError);
  params.keepPhotons = false;
  for (int tiles : {3, 4, -1}) {  // depth 4: at most 2 per axis
    try {
      bakeOnThreadRanks(scene, params, 2, tiles);
      ADD_FAILURE() << tiles << " tiles were accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--tiles"), std::string::npos) << e.what();
    }
  }
}

// Ranks that were started with different settings, or read different
// copies of the scene, refuse before any work, every one with the same
// message naming what differs and which ranks (they hung in a collective of
// unequal sizes, or baked a grid mixed from both scenes).
TEST(TiledBake, RanksThatDisagreeRefuseTogether) {
  const Scene scene = test::pointLitRoom();
  Scene moved = scene;
  moved.positions[0].x += 0.01f;
  const BakeParams params = test::smallBake(4, 2000);
  BakeParams other = params;
  other.photons = 3000;
  struct Case {
    const char* what;
    bool otherSettings, otherScene, otherOutput;
  };
  // An output name is what rank 0 alone writes: a rank given another saw
  // rank 0's written without a word.
  for (const Case& c : {Case{"settings", true, false, false}, Case{"scene", false, true, false},
                        Case{"settings and scene", true, true, false},
                        Case{"output", false, false, true}}) {
    SCOPED_TRACE(c.what);
    std::vector<std::string> messages(3);
    std::mutex mutex;
    EXPECT_THROW(runThreadRanks(3,
                                [&](Communicator& comm) {
                                  const bool odd = comm.rank() == 2;
                                  try {
                                    distributedBake(odd && c.otherScene ? moved : scene,
                                                    odd && c.otherSettings ? other : params,
                                                    TileParams{}, comm, nullptr, nullptr,
                                                    odd && c.otherOutput ? "b.vdb" : "a.vdb");
                                  } catch (const InputError& e) {
                                    std::lock_guard<std::mutex> lock(mutex);
                                    messages[size_t(comm.rank())] = e.what();
                                    throw;
                                  }
                                }),
                 InputError);
    // Every rank that refused said the same (under threads, a rank whose
    // peer threw first may end with the communicator's own error instead;
    // under MPI each refuses on its own).
    std::string said;
    for (const std::string& m : messages) {
      if (m.empty()) continue;
      if (said.empty()) said = m;
      EXPECT_EQ(m, said);
    }
    EXPECT_NE(said.find("rank(s) 2"), std::string::npos) << said;
    EXPECT_EQ(said.find("settings") != std::string::npos, c.otherSettings) << said;
    EXPECT_EQ(said.find("scene read") != std::string::npos, c.otherScene) << said;
    EXPECT_EQ(said.find("output files") != std::string::npos, c.otherOutput) << said;
  }
  // Agreeing ranks bake.
  EXPECT_GT(bakeOnThreadRanks(scene, params, 3, 0).result.grid.size(), 0u);
}

// What a rank reads of its scene is all in the fingerprint: a texel, a
// shading normal, a UV, a material's alpha mode, the sky image.
TEST(RankAgreement, TheSceneFingerprintSeesEveryInputOfTheBake) {
  Scene base = test::pointLitRoom();
  Texture t;
  t.width = t.height = 2;
  t.channels = 3;
  t.format = TexelFormat::Unorm8;
  t.unorm8.assign(12, 100);
  base.textures.push_back(t);
  base.materials[0].baseColorTexture = 0;
  base.texcoords0.assign(2 * base.positions.size(), 0.5f);
  base.normals.assign(base.positions.size(), Vec3(0, 1, 0));
  const uint64_t h = sceneFingerprint(base);
  EXPECT_EQ(sceneFingerprint(base), h);
  std::vector<std::function<void(Scene&)>> changes = {
      [](Scene& s) { s.textures[0].unorm8[7] = 101; },
      [](Scene& s) { s.normals[3] = Vec3(0, 0, 1); },
      [](Scene& s) { s.texcoords0[5] = 0.25f; },
      [](Scene& s) { s.materials[0].alphaMode = AlphaMode::Mask; },
      [](Scene& s) { s.positions[2].y += 1e-3f; },
      [](Scene& s) { s.lights[0].intensity *= 2; },
      [t](Scene& s) { s.sky.image = std::make_shared<const Texture>(t); },
  };
  for (size_t i = 0; i < changes.size(); ++i) {
    Scene changed = base;
    changes[i](changed);
    EXPECT_NE(sceneFingerprint(changed), h) << "change " << i;
  }
  BakeParams a = test::smallBake(4, 2000), b = a;
  b.seed = 2;
  EXPECT_NE(bakeSettingsFingerprint(a, TileParams{}), bakeSettingsFingerprint(b, TileParams{}));
  EXPECT_EQ(bakeSettingsFingerprint(a, TileParams{}), bakeSettingsFingerprint(a, TileParams{}));
}

TEST(TilePlan, SplitsTheWorkEvenlyAlongTheCurve) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  const int T = 8;
  std::vector<double> work(size_t(T * T * T));
  for (double& w : work) w = u(rng) < 3.0 ? 0.0 : u(rng);
  double total = 0, largest = 0;
  for (double w : work) {
    total += w;
    largest = std::max(largest, w);
  }
  for (int ranks = 1; ranks <= 5; ++ranks) {
    const TilePlan plan = planTiles(6, T, work, ranks, 4);
    std::vector<double> share(size_t(ranks), 0.0);
    for (size_t t = 0; t < work.size(); ++t) {
      ASSERT_GE(plan.owner[t], 0);
      ASSERT_LT(plan.owner[t], ranks);
      share[size_t(plan.owner[t])] += work[t];
    }
    // Each share is within one tile's work of the mean.
    for (int r = 0; r < ranks; ++r) {
      EXPECT_NEAR(share[size_t(r)], total / ranks, largest) << r << " of " << ranks;
    }
  }
}

TEST(TilePlan, OwnersNearAVoxelAreThoseABruteForceFinds) {
  std::mt19937 rng(3);
  const int T = 4, depth = 5, res = 32;
  std::vector<double> work(size_t(T * T * T));
  for (double& w : work) w = double(rng() % 100);
  const TilePlan plan = planTiles(depth, T, work, 3, 3);
  for (int i = 0; i < 2000; ++i) {
    const Coord c{int(rng() % 44) - 6, int(rng() % 44) - 6, int(rng() % 44) - 6};
    const int halo = int(rng() % 10);
    std::set<int> expected;
    for (int x = c.x - halo; x <= c.x + halo; ++x)
      for (int y = c.y - halo; y <= c.y + halo; ++y)
        for (int z = c.z - halo; z <= c.z + halo; ++z)
          if (x >= 0 && y >= 0 && z >= 0 && x < res && y < res && z < res)
            expected.insert(plan.ownerOf({x, y, z}));
    std::multiset<int> found;
    plan.forOwnersNear(c, halo, [&](int r) { found.insert(r); });
    EXPECT_EQ(std::set<int>(found.begin(), found.end()), expected) << c.ToString() << " " << halo;
    EXPECT_EQ(found.size(), expected.size()) << "each owner once";
  }
}

TEST(VdlGridParts, AGridSplitAnyWayMergesBackToItself) {
  Scene scene = test::pointLitRoom();
  BakeParams params = test::smallBake(5, 20000, 40);
  const VdlGrid grid = bake(scene, params).grid;
  ASSERT_GT(grid.layers.size(), 0u) << "the room's edges have layers";
  std::mt19937 rng(11);
  for (int parts : {1, 2, 5}) {
    std::vector<std::vector<uint32_t>> split(static_cast<size_t>(parts));
    for (uint32_t v = 0; v < grid.size(); ++v) split[rng() % uint32_t(parts)].push_back(v);
    std::vector<VdlGrid> pieces;
    for (const auto& voxels : split) {
      pieces.push_back(deserializeVdlGrid(serializeVdlGrid(selectVoxels(grid, voxels))));
    }
    std::shuffle(pieces.begin(), pieces.end(), rng);
    EXPECT_EQ(firstDifference(grid, mergeVdlGrids(std::move(pieces))), "") << parts << " parts";
  }
  // A voxel in two parts, and damaged bytes, are refused.
  EXPECT_THROW(mergeVdlGrids({selectVoxels(grid, {0, 1}), selectVoxels(grid, {1, 2})}), IoError);
  std::vector<char> bytes = serializeVdlGrid(selectVoxels(grid, {0, 1, 2}));
  bytes.resize(bytes.size() - 3);
  EXPECT_THROW(deserializeVdlGrid(bytes), IoError);
}

TEST(ThreadRanks, CollectivesGiveWhatEachRankSent) {
  for (int ranks = 1; ranks <= 4; ++ranks) {
    runThreadRanks(ranks, [&](Communicator& comm) {
      const int me = comm.rank(), n = comm.size();
      uint64_t sum[2] = {uint64_t(me), 1};
      comm.allreduceSum(sum, 2);
      EXPECT_EQ(sum[0], uint64_t(n * (n - 1) / 2));
      EXPECT_EQ(sum[1], uint64_t(n));
      double m = double(me) * 1.5;
      comm.allreduceMax(&m, 1);
      EXPECT_EQ(m, 1.5 * (n - 1));
      const std::vector<uint64_t> all = comm.allgather(uint64_t(10 * me));
      for (int r = 0; r < n; ++r) EXPECT_EQ(all[size_t(r)], uint64_t(10 * r));
      // Rank s sends (s + 1) * (d + 1) items of value 100 s + d to rank d.
      std::vector<uint64_t> begin(size_t(n) + 1, 0);
      std::vector<int> items;
      for (int d = 0; d < n; ++d) {
        for (int i = 0; i < (me + 1) * (d + 1); ++i) items.push_back(100 * me + d);
        begin[size_t(d) + 1] = items.size();
      }
      std::vector<int> got = {-1};
      exchangeItems(comm, items, begin, got);
      std::vector<int> expected = {-1};
      for (int s = 0; s < n; ++s)
        expected.insert(expected.end(), size_t((s + 1) * (me + 1)), 100 * s + me);
      EXPECT_EQ(got, expected);
      const auto gathered = comm.gatherBytes(std::vector<char>(size_t(me), char(me)), n - 1);
      if (me == n - 1) {
        ASSERT_EQ(gathered.size(), size_t(n));
        for (int r = 0; r < n; ++r)
          EXPECT_EQ(gathered[size_t(r)], std::vector<char>(size_t(r), char(r)));
      } else {
        EXPECT_TRUE(gathered.empty());
      }
    });
  }
}

// A step each rank runs on its own (loading its copy of the scene): one
// rank that fails makes every rank refuse at once, rank 0 with the failing
// rank's words (under mpirun that rank aborted the job before it said why).
TEST(RankAgreement, ARankWhoseOwnStepFailedMakesEveryRankRefuseWithItsWords) {
  for (int failing : {1, 2, 0}) {
    SCOPED_TRACE(failing);
    std::vector<std::string> messages(3);
    std::vector<int> refused(3, 0);
    std::mutex mutex;
    runThreadRanks(3, [&](Communicator& comm) {
      const bool mine = comm.rank() == failing;
      try {
        checkRanksSucceeded(comm, mine ? "scene.gltf: invalid glTF" : "");
      } catch (const RanksRefuseError& e) {
        std::lock_guard<std::mutex> lock(mutex);
        messages[size_t(comm.rank())] = e.what();
        refused[size_t(comm.rank())] = 1;
      }
    });
    EXPECT_EQ(refused, (std::vector<int>{1, 1, 1}));
    EXPECT_EQ(messages[0], failing == 0 ? "scene.gltf: invalid glTF"
                                        : "rank " + std::to_string(failing) + ": scene.gltf: invalid glTF");
  }
  // When every rank succeeded, none refuses.
  std::atomic<int> passed{0};
  runThreadRanks(3, [&](Communicator& comm) {
    checkRanksSucceeded(comm, "");
    ++passed;
  });
  EXPECT_EQ(passed.load(), 3);
}

TEST(ThreadRanks, ARankThatFailsEndsTheOthersWaits) {
  std::atomic<int> reached{0};
  try {
    runThreadRanks(3, [&](Communicator& comm) {
      if (comm.rank() == 1) throw InputError("rank 1 fails");
      uint64_t x = 1;
      comm.allreduceSum(&x, 1);  // would wait forever for rank 1
      ++reached;
    });
    ADD_FAILURE() << "no exception";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "rank 1 fails");
  }
  EXPECT_EQ(reached.load(), 0);
}

}  // namespace
}  // namespace lo
