#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <functional>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>
#include <vector>

#include "core/file.h"
#include "test_util.h"
#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "bake/convert.h"
#include "core/error.h"
#include "core/rng.h"
#include "vdb/vdb_contract.h"
#include "vdb/vdb_internal.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

// The order readVdlGrid documents: 8^3 block first, then offset in the block.
bool canonicalLess(const Coord& a, const Coord& b) {
  Coord ba{a.x >> 3, a.y >> 3, a.z >> 3}, bb{b.x >> 3, b.y >> 3, b.z >> 3};
  if (ba != bb) return ba < bb;
  return Coord{a.x & 7, a.y & 7, a.z & 7} < Coord{b.x & 7, b.y & 7, b.z & 7};
}

VdlGrid makeGrid(size_t voxels, int maxVdls, uint64_t seed) {
  Rng rng(seed, 0);
  VdlGrid g;
  g.frame.origin = {-1.25f, 0.3f, 7.1f};
  g.frame.voxelSize = 0.0371f;  // not a power of two: the transform must still round-trip
  g.frame.depth = 6;
  g.maxVdls = maxVdls;
  std::set<Coord> unique;
  while (unique.size() < voxels) {
    // Negative coordinates too: block order must use floor division.
    unique.insert(
        Coord{int(rng.uniformInt(40)) - 20, int(rng.uniformInt(40)) - 8, int(rng.uniformInt(40))});
  }
  g.coords.assign(unique.begin(), unique.end());
  std::sort(g.coords.begin(), g.coords.end(), canonicalLess);
  auto vec = [&] { return Vec3(rng.uniform(), rng.uniform() - 0.5f, rng.uniform() * 3.0f); };
  // Random but meaningful values (the reader checks them, vdb_io.h's
  // checkLightGridValues): irradiance >= 0 and the sum of the VDLs.
  auto light = [&] { return Vec3(rng.uniform(), rng.uniform() * 0.5f, rng.uniform() * 3.0f); };
  for (size_t v = 0; v < voxels; ++v) {
    g.normals.push_back(normalize(vec()));
    g.areas.push_back(rng.uniform() * 0.01f);
    g.photonCount.push_back(float(rng.uniformInt(301)));
    g.radius.push_back(rng.uniform() * 0.1f);
    g.noise.push_back(rng.uniform() * 0.2f);
    g.reflectance.push_back(Vec3(rng.uniform(), rng.uniform(), rng.uniform()));
    g.angularError.push_back(rng.uniform() * 0.5f);
    uint8_t count = uint8_t(rng.uniformInt(uint32_t(maxVdls) + 1));
    g.vdlCount.push_back(count);
    Vec3 sum{0, 0, 0};
    for (int i = 0; i < maxVdls; ++i) {
      g.vdls.push_back(i < count ? Vdl{light(), normalize(vec())} : Vdl{});
      sum += g.vdls.back().irradiance;
    }
    g.irradiance.push_back(sum);
  }
  return g;
}

BakeMetadata makeMeta() {
  BakeMetadata m;
  m.sourceScene = "scenes/cornell.gltf";
  m.depth = 6;
  m.photons = 600000;
  m.emittedPaths = 1234567890123ll;
  m.knn = 300;
  m.radius = 0.125f;
  m.vdls = "auto";
  m.seed = -7;
  m.sceneBounds.extend({-1, 0, -1});
  m.sceneBounds.extend({1, 2, 1.5f});
  return m;
}

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream f(path, std::ios::binary);
  f.write(bytes.data(), std::streamsize(bytes.size()));
}

template <typename T>
void expectSameBits(const std::vector<T>& a, const std::vector<T>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (size_t i = 0; i < a.size(); ++i) ASSERT_TRUE(a[i] == b[i]) << what << " at " << i;
}

std::string expectInputError(const std::string& path) {
  try {
    readVdlGrid(path);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    return e.what();
  } catch (const std::exception& e) {
    ADD_FAILURE() << "expected InputError, got: " << e.what();
    return "";
  }
  ADD_FAILURE() << "expected InputError for " << path;
  return "";
}

TEST(VdbIo, RoundTripIsBitExact) {
  std::string dir = test::outputDir("VdbIo.RoundTrip");
  for (int maxVdls : {1, 3, kMaxVdls}) {
    VdlGrid g = makeGrid(300, maxVdls, uint64_t(maxVdls));
    BakeMetadata meta = makeMeta();
    std::string path = dir + "/grid" + std::to_string(maxVdls) + ".vdb";
    writeVdlGrid(path, g, meta);
    EXPECT_TRUE(leftoverTemporaries(path).empty());
    LoadedVdl back = readVdlGrid(path);
    const VdlGrid& r = back.grid;
    EXPECT_EQ(r.frame.origin, g.frame.origin);
    EXPECT_EQ(r.frame.voxelSize, g.frame.voxelSize);
    EXPECT_EQ(r.frame.depth, g.frame.depth);
    EXPECT_EQ(r.maxVdls, g.maxVdls);
    expectSameBits(r.coords, g.coords, "coords");
    expectSameBits(r.normals, g.normals, "normals");
    expectSameBits(r.areas, g.areas, "areas");
    expectSameBits(r.irradiance, g.irradiance, "irradiance");
    expectSameBits(r.photonCount, g.photonCount, "photonCount");
    expectSameBits(r.radius, g.radius, "radius");
    expectSameBits(r.angularError, g.angularError, "angularError");
    expectSameBits(r.vdlCount, g.vdlCount, "vdlCount");
    ASSERT_EQ(r.vdls.size(), g.vdls.size());
    for (size_t i = 0; i < g.vdls.size(); ++i) {
      ASSERT_EQ(r.vdls[i].irradiance, g.vdls[i].irradiance) << i;
      ASSERT_EQ(r.vdls[i].direction, g.vdls[i].direction) << i;
    }
    const BakeMetadata& m = back.meta;
    EXPECT_EQ(m.generator, meta.generator);
    EXPECT_EQ(m.version, meta.version);
    EXPECT_EQ(m.sourceScene, meta.sourceScene);
    EXPECT_EQ(m.depth, meta.depth);
    EXPECT_EQ(m.photons, meta.photons);
    EXPECT_EQ(m.emittedPaths, meta.emittedPaths);
    EXPECT_EQ(m.knn, meta.knn);
    EXPECT_EQ(m.radius, meta.radius);
    EXPECT_EQ(m.vdls, meta.vdls);
    EXPECT_EQ(m.seed, meta.seed);
    EXPECT_EQ(m.sceneBounds.lower, meta.sceneBounds.lower);
    EXPECT_EQ(m.sceneBounds.upper, meta.sceneBounds.upper);
    EXPECT_EQ(m.units, meta.units);
  }
}

TEST(VdbIo, AGridTheReadersWouldRefuseIsNotWritten) {
  // The readers' value checks run before the write: a negative or a NaN
  // irradiance (what a bad light once baked) leaves the old file as it was.
  const std::string path = test::outputDir("VdbIo.RefusedWrite") + "/grid.vdb";
  const VdlGrid good = makeGrid(50, 2, 3);
  writeVdlGrid(path, good, makeMeta());
  const std::string before = readFile(path);
  for (float bad : {-1.0f, std::nanf("")}) {
    VdlGrid g = good;
    g.irradiance[7].y = bad;
    try {
      writeVdlGrid(path, g, makeMeta());
      ADD_FAILURE() << "written with irradiance " << bad;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("not written"), std::string::npos) << e.what();
    }
    EXPECT_EQ(readFile(path), before) << "irradiance " << bad;
    EXPECT_TRUE(leftoverTemporaries(path).empty());
  }
}

TEST(VdbIo, EmptyGridRoundTrips) {
  std::string path = test::outputDir("VdbIo.Empty") + "/empty.vdb";
  VdlGrid g = makeGrid(0, 4, 1);
  writeVdlGrid(path, g, makeMeta());
  LoadedVdl back = readVdlGrid(path);
  EXPECT_EQ(back.grid.size(), 0u);
  EXPECT_EQ(back.grid.maxVdls, 4);
  EXPECT_EQ(back.grid.frame.voxelSize, g.frame.voxelSize);
}

TEST(VdbIo, SameInputGivesSameBytes) {
  std::string dir = test::outputDir("VdbIo.SameBytes");
  VdlGrid g = makeGrid(200, 4, 3);
  writeVdlGrid(dir + "/a.vdb", g, makeMeta());
  writeVdlGrid(dir + "/b.vdb", g, makeMeta());
  std::string a = readFile(dir + "/a.vdb");
  EXPECT_GT(a.size(), 1000u);
  EXPECT_TRUE(a == readFile(dir + "/b.vdb"));
  // A different grid gets a different (content-derived) file UUID.
  g.photonCount[0] += 1.0f;
  writeVdlGrid(dir + "/c.vdb", g, makeMeta());
  EXPECT_NE(a.substr(21, 36), readFile(dir + "/c.vdb").substr(21, 36));
}

TEST(VdbIo, VdbPrintListsTheContractGrids) {
  const char* vdbPrint = "/usr/bin/vdb_print";
  if (!fs::exists(vdbPrint)) GTEST_SKIP() << vdbPrint << " not installed";
  std::string dir = test::outputDir("VdbIo.VdbPrint");
  VdlGrid g = makeGrid(100, 2, 5);
  writeVdlGrid(dir + "/g.vdb", g, makeMeta());
  std::string out = test::runCommand(std::string(vdbPrint) + " -m " + dir + "/g.vdb 2>&1");
  for (const char* name :
       {"irradiance", "normal", "photon_count", "angular_error", "vdl_count", "radius", "area",
        "vdl0_irradiance", "vdl0_direction", "vdl1_irradiance", "vdl1_direction"}) {
    // One summary line per grid, starting with its name.
    EXPECT_NE(out.find("\n" + std::string(name) + " "), std::string::npos) << name << "\n" << out;
  }
  EXPECT_EQ(out.find("vdl2_"), std::string::npos) << out;
  EXPECT_NE(out.find("source_scene: scenes/cornell.gltf"), std::string::npos) << out;
  EXPECT_NE(out.find("file_compression: blosc"), std::string::npos) << out;

  std::vector<Photon> photons(50);
  for (size_t i = 0; i < photons.size(); ++i) photons[i].position = Vec3(float(i) * 0.01f);
  writePhotonPoints(dir + "/p.vdb", photons, 0.1f);
  out = test::runCommand(std::string(vdbPrint) + " " + dir + "/p.vdb 2>&1");
  EXPECT_EQ(out.rfind("photons ", 0), 0u) << out;
}

// The display grid `density` (viewers' default volume import shows it): the
// irradiance luminance over the brightest voxel's, on every voxel, in [0, 1];
// readers ignore it, `--drop density` leaves it out, and it is the only
// grid the contract does not name.
TEST(VdbIo, ADensityGridShowsTheLightToViewers) {
  std::string dir = test::outputDir("VdbIo.Density");
  VdlGrid g = makeGrid(100, 2, 5);
  writeVdlGrid(dir + "/g.vdb", g, makeMeta());
  const VdbReport report = inspectVdb(dir + "/g.vdb");
  const GridSummary* density = nullptr;
  for (const GridSummary& s : report.grids) {
    if (s.name == "density") density = &s;
  }
  ASSERT_NE(density, nullptr);
  EXPECT_EQ(density->activeVoxels, g.size());
  ASSERT_EQ(density->min.size(), 1u);
  EXPECT_GE(density->min[0], 0.0);
  EXPECT_DOUBLE_EQ(density->max[0], 1.0);  // the brightest voxel
  // Reading ignores it: the grid comes back as written.
  EXPECT_EQ(readVdlGrid(dir + "/g.vdb").grid.irradiance, g.irradiance);
  VdlWriteOptions drop;
  drop.drop = {"density"};
  writeVdlGrid(dir + "/nodensity.vdb", g, makeMeta(), drop);
  const VdbReport without = inspectVdb(dir + "/nodensity.vdb");
  for (const GridSummary& s : without.grids) EXPECT_NE(s.name, "density");
  // The grid changes no check's verdict (this grid's coordinates are not a
  // bake's, so voxel_bounds fails in both).
  ASSERT_EQ(without.checks.size(), report.checks.size());
  for (size_t i = 0; i < report.checks.size(); ++i) {
    EXPECT_EQ(report.checks[i].name, without.checks[i].name);
    EXPECT_EQ(report.checks[i].passed, without.checks[i].passed) << report.checks[i].name;
  }
  drop.drop = {"irradiance"};
  EXPECT_THROW(writeVdlGrid(dir + "/bad.vdb", g, makeMeta(), drop), InputError);
}

TEST(VdbIo, MissingGridIsAnInputError) {
  std::string dir = test::outputDir("VdbIo.MissingGrid");
  VdlGrid g = makeGrid(50, 2, 7);
  for (const char* omit : {"irradiance", "normal", "vdl_count", "vdl1_direction"}) {
    std::string path = dir + "/" + omit + ".vdb";
    vdb_internal::Damage damage;
    damage.omitGrid = omit;
    vdb_internal::writeVdlGridDamaged(path, g, makeMeta(), damage);
    std::string msg = expectInputError(path);
    EXPECT_NE(msg.find("missing grid '" + std::string(omit) + "'"), std::string::npos) << msg;
  }
}

TEST(VdbIo, MismatchedTransformsAreAnInputError) {
  std::string dir = test::outputDir("VdbIo.Transforms");
  VdlGrid g = makeGrid(50, 2, 8);
  vdb_internal::Damage shifted;
  shifted.shiftGrid = "vdl0_irradiance";
  vdb_internal::writeVdlGridDamaged(dir + "/shifted.vdb", g, makeMeta(), shifted);
  std::string msg = expectInputError(dir + "/shifted.vdb");
  EXPECT_NE(msg.find("mismatched transforms"), std::string::npos) << msg;

  vdb_internal::Damage rotated;
  rotated.rotateTransform = true;
  vdb_internal::writeVdlGridDamaged(dir + "/rotated.vdb", g, makeMeta(), rotated);
  msg = expectInputError(dir + "/rotated.vdb");
  EXPECT_NE(msg.find("transform"), std::string::npos) << msg;
}

TEST(VdbIo, DamagedFilesAreInputErrorsNotCrashes) {
  std::string dir = test::outputDir("VdbIo.Damaged");
  VdlGrid g = makeGrid(200, 2, 9);
  writeVdlGrid(dir + "/good.vdb", g, makeMeta());
  const std::string bytes = readFile(dir + "/good.vdb");
  ASSERT_GT(bytes.size(), 200u);
  // Truncated at the header, in the metadata, in the grid descriptors, in the
  // middle of the data and just before the end.
  for (size_t keep : {size_t(0), size_t(10), size_t(40), size_t(200), bytes.size() / 3,
                      bytes.size() / 2, bytes.size() - 8}) {
    std::string path = dir + "/truncated" + std::to_string(keep) + ".vdb";
    writeBytes(path, bytes.substr(0, keep));
    expectInputError(path);
  }
  std::string wrongMagic = bytes;
  wrongMagic[0] ^= 0x5a;
  writeBytes(dir + "/magic.vdb", wrongMagic);
  expectInputError(dir + "/magic.vdb");
  writeBytes(dir + "/text.vdb", "this is not a vdb file\n");
  expectInputError(dir + "/text.vdb");
}

TEST(VdbIo, NonexistentFileIsAnInputError) {
  std::string msg = expectInputError(test::outputDir("VdbIo.Nonexistent") + "/nope.vdb");
  EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
}

TEST(VdbIo, WritingIntoAMissingFolderFailsCleanly) {
  std::string dir = test::outputDir("VdbIo.MissingFolder") + "/no/such/folder";
  std::string path = dir + "/g.vdb";
  try {
    writeVdlGrid(path, makeGrid(10, 1, 1), makeMeta());
    ADD_FAILURE() << "expected IoError";
  } catch (const IoError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find(path), std::string::npos) << msg;
    EXPECT_NE(msg.find("does not exist"), std::string::npos) << msg;
  }
  EXPECT_THROW(writePhotonPoints(path, {}, 1.0f), IoError);
  EXPECT_FALSE(fs::exists(path));
  EXPECT_TRUE(leftoverTemporaries(path).empty());
}

TEST(VdbIo, OverwritesAnExistingFileAndLeavesNoTemporary) {
  std::string dir = test::outputDir("VdbIo.Overwrite");
  std::string path = dir + "/g.vdb";
  writeBytes(path, "old contents");
  writeVdlGrid(path, makeGrid(20, 1, 2), makeMeta());
  EXPECT_EQ(readVdlGrid(path).grid.size(), 20u);
  EXPECT_TRUE(leftoverTemporaries(path).empty());
  // A directory where the file should go: the write fails, nothing is left.
  fs::create_directories(dir + "/taken.vdb/inner");
  EXPECT_THROW(writeVdlGrid(dir + "/taken.vdb", makeGrid(5, 1, 2), makeMeta()), IoError);
  EXPECT_TRUE(leftoverTemporaries(dir + "/taken.vdb").empty());
}

std::vector<Photon> makePhotons(size_t n) {
  Rng rng(4, 0);
  std::vector<Photon> photons(n);
  for (auto& p : photons) {
    p.position = {rng.uniform() * 2 - 1, rng.uniform(), rng.uniform() * 3};
    p.direction = normalize(Vec3(rng.uniform(), 1, rng.uniform()));
    p.normal = {0, 1, 0};
    p.power = {rng.uniform() * 1e-3f, 2e-4f, 1e-4f};
    p.bounce = rng.uniformInt(4);
  }
  return photons;
}

TEST(VdbIo, PhotonPointsReadBack) {
  std::string dir = test::outputDir("VdbIo.Points");
  std::vector<Photon> photons = makePhotons(5000);
  std::string path = dir + "/photons.vdb";
  writePhotonPoints(path, photons, 0.05f);
  EXPECT_TRUE(leftoverTemporaries(path).empty());
  vdb_internal::PointFileInfo info = vdb_internal::inspectPointFile(path);
  EXPECT_EQ(info.gridNames, std::vector<std::string>{"photons"});
  EXPECT_EQ(info.pointCount, photons.size());
  EXPECT_EQ(info.attributes, (std::vector<std::string>{"P", "Cd", "direction", "N", "bounce", "reflectance"}));
  double cd[3] = {0, 0, 0};
  int64_t bounce = 0;
  Bounds3 bounds;
  for (const Photon& p : photons) {
    for (int k = 0; k < 3; ++k) cd[k] += p.power[k];
    bounce += p.bounce;
    bounds.extend(p.position);
  }
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(info.totalCd[k], cd[k], 1e-6 * cd[k]);
  EXPECT_EQ(info.totalBounce, bounce);
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(info.positionBounds.lower[k], bounds.lower[k], 1e-5f);
    EXPECT_NEAR(info.positionBounds.upper[k], bounds.upper[k], 1e-5f);
  }
  // Not a VDL file: the VDL reader says so instead of misreading it.
  expectInputError(path);
}

TEST(VdbIo, PhotonPointsAreDeterministicAndMayBeEmpty) {
  std::string dir = test::outputDir("VdbIo.PointsDeterministic");
  std::vector<Photon> photons = makePhotons(20000);
  writePhotonPoints(dir + "/a.vdb", photons, 0.05f);
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    writePhotonPoints(dir + "/b.vdb", photons, 0.05f);
  }
  EXPECT_TRUE(readFile(dir + "/a.vdb") == readFile(dir + "/b.vdb"));

  writePhotonPoints(dir + "/empty.vdb", {}, 0.05f);
  vdb_internal::PointFileInfo info = vdb_internal::inspectPointFile(dir + "/empty.vdb");
  EXPECT_EQ(info.pointCount, 0u);
  EXPECT_EQ(info.gridNames, std::vector<std::string>{"photons"});
  EXPECT_THROW(writePhotonPoints(dir + "/bad.vdb", photons, 0.0f), InputError);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

/// A small bake of a room (its edges have surface layers) for the tests below.
TEST(VdbIo, AGridOfARebasedSceneIsStoredInWorldCoordinates) {
  // A scene the loader rebased (Scene::origin 1e6 away): the grid's frame is
  // relative to it, the file's transform is in world coordinates, and
  // reading gives back the frame exactly, by default or for the scene's
  // origin; for another origin, the same world positions.
  const std::string folder = test::outputDir("VdbIo.Rebased");
  const std::string path = folder + "/far.vdb";
  VdlGrid g = makeGrid(200, 2, 7);
  g.frame.offset = Vec3d(1234567.25, -89.5, -7654321.0625);
  writeVdlGrid(path, g, makeMeta());
  for (const LoadedVdl& back : {readVdlGrid(path), readVdlGrid(path, g.frame.offset)}) {
    EXPECT_EQ(back.grid.frame.origin, g.frame.origin);
    EXPECT_EQ(back.grid.frame.voxelSize, g.frame.voxelSize);
    EXPECT_EQ(back.grid.frame.offset.x, g.frame.offset.x);
    EXPECT_EQ(back.grid.frame.offset.y, g.frame.offset.y);
    EXPECT_EQ(back.grid.frame.offset.z, g.frame.offset.z);
    EXPECT_EQ(back.meta.sceneOrigin.z, g.frame.offset.z);
  }
  const Vec3d near(1234560.0, -80.0, -7654320.0);
  const LoadedVdl moved = readVdlGrid(path, near);
  for (int a = 0; a < 3; ++a) {
    EXPECT_NEAR(double(moved.grid.frame.origin[a]) + near[a],
                double(g.frame.origin[a]) + g.frame.offset[a], 1e-5)
        << a;
  }
  // Photons likewise: world positions in the file, relative ones back.
  std::vector<Photon> photons = makePhotons(100);
  writePhotonPoints(folder + "/photons.vdb", photons, 0.05f, g.frame.offset);
  const std::vector<Photon> world = readPhotonPoints(folder + "/photons.vdb");
  const std::vector<Photon> local = readPhotonPoints(folder + "/photons.vdb", g.frame.offset);
  Bounds3 a, b, c;
  for (const Photon& p : photons) a.extend(p.position);
  for (const Photon& p : world) b.extend(p.position);
  for (const Photon& p : local) c.extend(p.position);
  EXPECT_NEAR(b.lower.z, a.lower.z + g.frame.offset.z, 1.0);  // float at 7.6e6: 0.5 apart
  for (int k = 0; k < 3; ++k) {
    EXPECT_NEAR(c.lower[k], a.lower[k], 1e-5f) << k;
    EXPECT_NEAR(c.upper[k], a.upper[k], 1e-5f) << k;
  }
}

TEST(VdbIo, AGridFarFromTheOriginWithinTheCoordinateLimitReadsBackAndPassesInspect) {
  // At 9.9e11 (within kMaxCoordinate, 1e12) a double keeps the translation to
  // 1.2e-4: a voxel size taken as the difference of two mapped points came
  // back 0.0356445 for 0.035649, and every reader refused the file the bake
  // had written. The size is the map's own scale.
  const std::string folder = test::outputDir("VdbIo.FarFromTheOrigin");
  const std::string path = folder + "/far.vdb";
  VdlGrid g = makeGrid(120, 2, 9);
  g.frame.voxelSize = 0.035649f;
  for (const Vec3d offset : {Vec3d(9.9e11, 0.2744, -0.2796), Vec3d(-9.99e11, 9.9e11, 3e11)}) {
    g.frame.offset = offset;
    writeVdlGrid(path, g, makeMeta());
    const LoadedVdl back = readVdlGrid(path, g.frame.offset);
    EXPECT_EQ(back.grid.frame.voxelSize, g.frame.voxelSize);
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(back.grid.frame.offset[a], g.frame.offset[a]) << a;
      EXPECT_NEAR(back.grid.frame.origin[a], g.frame.origin[a], 1e-3f) << a;
    }
    EXPECT_EQ(back.grid.coords, g.coords);
    // inspect's "readable" is the readers' verdict (makeGrid's voxels reach
    // below 0, which "voxel_bounds" fails whatever the origin).
    size_t seen = 0;
    for (const VdbCheck& c : inspectVdb(path).checks) {
      if (c.name != "readable" && c.name != "transform" && c.name != "same_transform") continue;
      ++seen;
      EXPECT_TRUE(c.passed) << c.name << ": " << c.detail;
    }
    EXPECT_EQ(seen, 3u);
  }
}

BakeResult smallRoomBake() {
  BakeParams p = test::smallBake(4, 60000, 60);
  return bake(test::pointLitRoom(), p);
}

// Surface layers round-trip through the .vdb: a bake of a room (its edges
// have layers) written and read back gives the same layers, points and VDLs,
// and the same octree bytes.
TEST(VdbLayers, RoundTrip) {
  const BakeResult baked = smallRoomBake();
  const VdlGrid& g = baked.grid;
  ASSERT_GT(g.layers.size(), 0u);
  const std::string path = test::outputDir("VdbLayers") + "/room.vdb";
  writeVdlGrid(path, g, baked.metadata);
  const LoadedVdl r = readVdlGrid(path);
  EXPECT_EQ(r.meta.formatVersion, kVdlFormatVersionVdl);
  const VdlLayers &a = g.layers, &b = r.grid.layers;
  ASSERT_EQ(b.size(), a.size());
  EXPECT_EQ(b.voxel, a.voxel);
  EXPECT_EQ(b.normals, a.normals);
  EXPECT_EQ(b.points, a.points);
  EXPECT_EQ(b.irradiance, a.irradiance);
  EXPECT_EQ(b.vdlCount, a.vdlCount);
  EXPECT_EQ(b.photonCount, a.photonCount);
  ASSERT_EQ(b.vdls.size(), a.vdls.size());
  for (size_t i = 0; i < a.vdls.size(); ++i) {
    EXPECT_EQ(b.vdls[i].irradiance, a.vdls[i].irradiance);
    EXPECT_EQ(b.vdls[i].direction, a.vdls[i].direction);
  }
  for (size_t e = 0; e < a.size(); ++e) EXPECT_EQ(r.grid.points[a.voxel[e]], g.points[a.voxel[e]]);
  const GpuOctree x = buildGpuOctree(g), y = buildGpuOctree(r.grid);
  EXPECT_EQ(x.pool, y.pool);
  EXPECT_EQ(x.vdlTexels, y.vdlTexels);
  // inspect checks the layers too.
  const VdbReport report = inspectVdb(path);
  bool layersChecked = false;
  for (const VdbCheck& c : report.checks) {
    EXPECT_TRUE(c.passed) << c.name << ": " << c.detail;
    layersChecked = layersChecked || c.name == "layers";
  }
  EXPECT_TRUE(layersChecked);
  // Same-depth re-clustering keeps them; a new depth drops them and says so.
  ConvertParams cp;
  cp.vdls = "2";
  const ConvertResult two = convertLightGrid(r.grid, r.meta, cp);
  EXPECT_EQ(two.grid.layers.voxel, a.voxel);
  EXPECT_LE(*std::max_element(two.grid.layers.vdlCount.begin(), two.grid.layers.vdlCount.end()), 2);
  cp.vdls = "";
  cp.depth = 3;
  const ConvertResult coarse = convertLightGrid(r.grid, r.meta, cp);
  EXPECT_EQ(coarse.grid.layers.size(), 0u);
  EXPECT_NE(coarse.method.find("surface layers are not carried"), std::string::npos)
      << coarse.method;
}

// A grid of a file with no active voxel where the others of its set have
// some (4 KB of a bake's file zeroed emptied 'layer1_normal'): inspect failed
// "same_active_voxels" while render, convert and Python read the layer as
// zeros. Every reader refuses it now, by the very check inspect runs.
TEST(VdbLayers, AGridWithoutTheVoxelsOfItsSetIsRefusedByTheReadersAsByInspect) {
  const BakeResult baked = smallRoomBake();
  ASSERT_GT(baked.grid.layers.size(), 0u);
  const std::string dir = test::outputDir("VdbLayers.EmptyGrid");
  for (const std::string& name :
       {std::string("layer1_normal"), std::string("layer1_angular_error"),
        std::string(vdb_internal::gridNameOf(&VdlGrid::points)), std::string("density")}) {
    vdb_internal::Damage d;
    d.emptyGrid = name;
    const std::string path = dir + "/" + name + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, baked.grid, baked.metadata, d);
    const VdbReport report = inspectVdb(path);
    bool failed = false;
    for (const VdbCheck& c : report.checks) {
      if (c.name == "same_active_voxels") failed = !c.passed;
    }
    EXPECT_TRUE(failed) << name;
    try {
      readVdlGrid(path);
      ADD_FAILURE() << name << ": read, where inspect fails it";
    } catch (const InputError& e) {
      const std::string msg = e.what();
      // The emptied grid is named, against another of its set or as the set's first.
      EXPECT_NE(msg.find("'" + name + "'"), std::string::npos) << msg;
      EXPECT_NE(msg.find("grids of one set of voxels differ"), std::string::npos) << msg;
    }
  }
  // Undamaged, both take it.
  vdb_internal::writeVdlGridDamaged(dir + "/good.vdb", baked.grid, baked.metadata, {});
  EXPECT_TRUE(inspectVdb(dir + "/good.vdb").ok());
  EXPECT_NO_THROW(readVdlGrid(dir + "/good.vdb"));
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// A file whose values are not finite (a damaged file, or one written by a
// buggy tool) is refused at reading, so render, convert and lightmap never
// draw or copy it; the message names the voxel.
TEST(VdbIo, NonFiniteValuesAreRefusedAtReading) {
  const std::string dir = test::outputDir("VdbIo.NonFinite");
  VdlGrid g = makeGrid(30, 2, 7);
  g.irradiance[11].y = std::nanf("");
  // Written past writeVdlGrid's own checks (which refuse it), as a damaged
  // or foreign file would arrive.
  vdb_internal::writeVdlGridDamaged(dir + "/nan.vdb", g, makeMeta(), vdb_internal::Damage{});
  try {
    readVdlGrid(dir + "/nan.vdb");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("irradiance at voxel " + g.coords[11].ToString()), std::string::npos) << msg;
    EXPECT_NE(msg.find("not finite"), std::string::npos) << msg;
  }
  g.irradiance[11].y = 0.5f;
  g.vdls[3].direction.x = INFINITY;
  vdb_internal::writeVdlGridDamaged(dir + "/inf.vdb", g, makeMeta(), vdb_internal::Damage{});
  EXPECT_THROW(readVdlGrid(dir + "/inf.vdb"), InputError);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// convert chains keep the contract: half floats, then fewer VDLs, then a
// coarser depth, each written and read back, pass inspect's checks (the
// VDL sums used to drift past the tolerance after a half-float step).
TEST(VdbIo, ConvertChainsKeepTheVdlSums) {
  const BakeResult baked = smallRoomBake();
  const std::string dir = test::outputDir("VdbIo.ConvertChain");
  VdlWriteOptions half;
  half.halfFloat = true;
  writeVdlGrid(dir + "/half.vdb", baked.grid, baked.metadata, half);
  LoadedVdl in = readVdlGrid(dir + "/half.vdb");
  for (const std::string step : {"vdls 2", "depth 3"}) {
    ConvertParams cp;
    if (step == "vdls 2") cp.vdls = "2";
    if (step == "depth 3") cp.depth = 3;
    const ConvertResult out = convertLightGrid(in.grid, in.meta, cp);
    const std::string path = dir + "/" + (step == "vdls 2" ? "v2" : "d3") + ".vdb";
    writeVdlGrid(path, out.grid, out.metadata);
    for (const VdbCheck& c : inspectVdb(path).checks) {
      EXPECT_TRUE(c.passed) << step << ": " << c.name << ": " << c.detail;
    }
    in = readVdlGrid(path);
  }
}

// Every conversion chain keeps the contract (issue "hardening, second
// list"): all sequences of up to three steps among half-float storage, 1
// and 8 VDLs, one depth coarser and one finer, from a small bake; after each
// step the file passes every check of `inspect` (and so the reader). Under
// the sanitizers, chains of up to two steps: every step from every kind of
// input (150 files took four minutes there).
TEST(VdbIo, EveryConversionChainOfUpToThreeStepsKeepsTheContract) {
#if defined(__SANITIZE_ADDRESS__)
  const int longest = 2;
  const size_t least = 20;
#else
  const int longest = 3;
  const size_t least = 120;
#endif
  const Scene scene = test::pointLitRoom();
  const BakeResult baked = smallRoomBake();
  const std::string dir = test::outputDir("VdbIo.ConvertChains");
  const std::vector<std::string> steps = {"half", "vdls 1", "vdls 8", "depth -1", "depth +1"};
  size_t files = 0;
  // Depth-first over the chains, each prefix converted once.
  std::function<void(const LoadedVdl&, const std::string&, int)> extend =
      [&](const LoadedVdl& in, const std::string& chain, int length) {
        if (length == longest) return;
        for (size_t k = 0; k < steps.size(); ++k) {
          const std::string& step = steps[k];
          const int depth = in.grid.frame.depth;
          if ((step == "depth -1" && depth <= 2) || (step == "depth +1" && depth >= 5)) continue;
          const std::string name = chain + (chain.empty() ? "" : "_") + std::to_string(k);
          const std::string path = dir + "/" + name + ".vdb";
          if (step == "half") {
            VdlWriteOptions half;
            half.halfFloat = true;
            writeVdlGrid(path, in.grid, in.meta, half);
          } else {
            ConvertParams cp;
            if (step.rfind("vdls", 0) == 0) cp.vdls = step.substr(5);
            if (step == "depth -1") cp.depth = depth - 1;
            if (step == "depth +1") {
              cp.depth = depth + 1;
              cp.scene = &scene;
            }
            const ConvertResult out = convertLightGrid(in.grid, in.meta, cp);
            // A half-float input stays half-float, as `convert` keeps the storage.
            VdlWriteOptions options;
            options.halfFloat = in.halfFloat;
            writeVdlGrid(path, out.grid, out.metadata, options);
          }
          ++files;
          for (const VdbCheck& c : inspectVdb(path).checks) {
            ASSERT_TRUE(c.passed) << "chain " << name << " (" << step << "): " << c.name << ": "
                                  << c.detail;
          }
          extend(readVdlGrid(path), name, length + 1);
        }
      };
  const std::string start = dir + "/start.vdb";
  writeVdlGrid(start, baked.grid, baked.metadata);
  extend(readVdlGrid(start), "", 0);
  std::printf("conversion chains: %zu files, every one passes inspect\n", files);
  EXPECT_GT(files, least);
}

// A photon map of a `bake --bounds` holds photons inside its region only:
// convert --photon-map re-gathered a grid of the whole scene from it, black
// outside the region (73% of the voxels; eighth hostile list F7-25). The
// region travels in the photon file; a grid reaching beyond it is refused.
TEST(VdbIo, APhotonMapIsRefusedForAGridBeyondItsRegion) {
  const Scene scene = test::pointLitRoom();
  BakeParams p = test::smallBake(3, 20000, 40);
  p.keepPhotons = true;
  p.region = Bounds3{{0, 0, 0}, {0.6f, 0.6f, 0.6f}};
  const BakeResult part = bake(scene, p);
  const std::string path = test::outputDir("VdbIo.PhotonRegion") + "/part.vdb";
  writePhotonPoints(path, part.photons.photons, part.grid.frame.voxelSize, scene.origin, nullptr,
                    photonMapInfo(part.metadata));
  PhotonMapInfo info;
  const std::vector<Photon> photons = readPhotonPoints(path, scene.origin, &info);
  ASSERT_FALSE(photons.empty());
  EXPECT_EQ(info.region.lower, p.region.lower);
  EXPECT_EQ(info.region.upper, p.region.upper);
  for (const Photon& ph : photons) {  // what the check relies on
    ASSERT_EQ(min(max(ph.position, p.region.lower), p.region.upper), ph.position);
  }
  ConvertParams cp;
  cp.scene = &scene;
  cp.photons = &photons;
  cp.photonRegion = info.region;
  BakeParams wholeParams = test::smallBake(3, 20000, 40);
  const BakeResult whole = bake(scene, wholeParams);
  test::expectRefusal([&] { convertLightGrid(whole.grid, whole.metadata, cp); },
                      {"--photon-map: its photons were stored inside", "(the whole scene)",
                       "would gather no light"});
  // The region's own grid is re-gathered from them, with light; it records
  // the photons' sky (here another than the input's), whose light it holds.
  cp.photonSkyHash = "0123456789abcdef";
  const ConvertResult regathered = convertLightGrid(part.grid, part.metadata, cp);
  EXPECT_GT(lightGridEnergy(regathered.grid), 0.5 * lightGridEnergy(part.grid));
  EXPECT_EQ(regathered.metadata.skyHash, "0123456789abcdef");
  EXPECT_EQ(part.metadata.skyHash, "none");
  // A photon map that records no region (before this check) is taken.
  cp.photonRegion = Bounds3();
  EXPECT_NO_THROW(convertLightGrid(whole.grid, whole.metadata, cp));
}

// A .vdb or a photon map cut short was refused in OpenVDB's words: "Grid
// type  is not registered", "Expected to decompress 360000 bytes, got
// 18446744073709551615 bytes" (eighth hostile list F7-37, F7-38). A file
// that starts as a .vdb is said to be damaged or truncated.
TEST(VdbIo, AFileCutShortIsCalledDamagedOrTruncated) {
  BakeParams p = test::smallBake(3, 20000, 40);
  p.keepPhotons = true;
  const BakeResult baked = bake(test::pointLitRoom(), p);
  const std::string dir = test::outputDir("VdbIo.Cut");
  writeVdlGrid(dir + "/grid.vdb", baked.grid, baked.metadata);
  writePhotonPoints(dir + "/photons.vdb", baked.photons.photons, baked.grid.frame.voxelSize);
  for (const char* name : {"/grid.vdb", "/photons.vdb"}) {
    const std::string whole = readFile(dir + name), cut = dir + "/cut" + (name + 1);
    std::ofstream(cut, std::ios::binary) << whole.substr(0, whole.size() / 2);
    test::expectRefusal(
        [&] {
          if (std::string(name) == "/grid.vdb") readVdlGrid(cut);
          else readPhotonPoints(cut);
        },
        {cut + ": cannot read as an OpenVDB file: damaged or truncated"});
  }
  // Another format is not called damaged.
  std::ofstream(dir + "/text.vdb") << "not a vdb at all, but long enough to be read";
  try {
    readVdlGrid(dir + "/text.vdb");
    ADD_FAILURE() << "a text file was read";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).find("truncated"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace lo
