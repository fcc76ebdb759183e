// File-level checks of conversion: format_version, optional and dropped grids,
// half-float storage, photon read-back, `inspect` on good, damaged and
// corrupted files, vdb_print on a converted file.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "cluster/resample.h"
#include "core/error.h"
#include "core/file.h"
#include "core/printable.h"
#include "core/rng.h"
#include "octree/gpu_octree.h"
#include "scene/scene_files.h"
#include "test_util.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_internal.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

// A small consistent grid: an 8x8 floor at y = 0 in one depth-4 frame, each
// voxel with `maxVdls` VDLs that sum to its irradiance.
VdlGrid floorGrid(int maxVdls = 3) {
  VdlGrid g;
  g.frame.origin = {-0.5f, -0.25f, 0.125f};
  g.frame.voxelSize = 0.0625f;
  g.frame.depth = 4;
  g.maxVdls = maxVdls;
  Rng rng(5, 0);
  for (int x = 0; x < 8; ++x) {
    for (int z = 0; z < 8; ++z) {
      g.coords.push_back({x, 0, z});
      g.normals.push_back({0, 1, 0});
      g.areas.push_back(0.0625f * 0.0625f * (0.5f + rng.uniform()));
      g.photonCount.push_back(float(100 + rng.uniformInt(200)));
      g.radius.push_back(0.2f);
      g.noise.push_back(0.04f);
      g.reflectance.push_back({0.6f, 0.5f, 0.4f});
      g.angularError.push_back(0.2f * rng.uniform());
      const uint8_t count = uint8_t(1 + rng.uniformInt(uint32_t(maxVdls)));
      g.vdlCount.push_back(count);
      Vec3 total{};
      for (int i = 0; i < maxVdls; ++i) {
        Vdl vdl;
        if (i < count) {
          vdl.irradiance = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 3.0f;
          vdl.direction = normalize(Vec3(rng.uniform() - 0.5f, 1.0f, rng.uniform() - 0.5f));
          total += vdl.irradiance;
        }
        g.vdls.push_back(vdl);
      }
      g.irradiance.push_back(total);
    }
  }
  return g;
}

BakeMetadata meta() {
  BakeMetadata m;
  m.sourceScene = "floor.gltf";
  m.depth = 4;
  m.knn = 100;
  m.vdls = "3";
  return m;
}

const VdbCheck* findCheck(const VdbReport& r, const std::string& name) {
  for (const VdbCheck& c : r.checks) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

void expectCheck(const VdbReport& r, const std::string& name, bool passed) {
  const VdbCheck* c = findCheck(r, name);
  ASSERT_NE(c, nullptr) << "no check " << name;
  EXPECT_EQ(c->passed, passed) << name << ": " << c->detail;
}

std::string readError(const std::string& path) {
  try {
    readVdlGrid(path);
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected InputError for " << path;
  return "";
}

TEST(FormatVersion, WrittenReadAndNewerRefused) {
  std::string dir = test::outputDir("Convert.FormatVersion");
  VdlGrid g = floorGrid();
  writeVdlGrid(dir + "/v1.vdb", g, meta());
  LoadedVdl v1 = readVdlGrid(dir + "/v1.vdb");
  EXPECT_EQ(v1.meta.formatVersion, kVdlFormatVersionVdl);
  EXPECT_TRUE(v1.notes.empty());
  VdbReport r = inspectVdb(dir + "/v1.vdb");
  auto it = std::find_if(r.metadata.begin(), r.metadata.end(),
                         [](const auto& kv) { return kv.first == "format_version"; });
  ASSERT_NE(it, r.metadata.end());
  EXPECT_EQ(it->second, std::to_string(kVdlFormatVersionVdl));

  // A file written by a future lightoctree.
  vdb_internal::Damage newer;
  newer.formatVersion = kVdlFormatVersion + 1;
  vdb_internal::writeVdlGridDamaged(dir + "/vnext.vdb", g, meta(), newer);
  std::string msg = readError(dir + "/vnext.vdb");
  EXPECT_NE(msg.find("format_version " + std::to_string(kVdlFormatVersion + 1) +
                     " is not supported"),
            std::string::npos)
      << msg;
  EXPECT_NE(msg.find("newer lightoctree"), std::string::npos) << msg;
  expectCheck(inspectVdb(dir + "/vnext.vdb"), "format_version", false);

  // A file written before the key existed: read as version 1, with a note.
  vdb_internal::Damage older;
  older.formatVersion = std::nullopt;
  vdb_internal::writeVdlGridDamaged(dir + "/v0.vdb", g, meta(), older);
  LoadedVdl v0 = readVdlGrid(dir + "/v0.vdb");
  EXPECT_EQ(v0.meta.formatVersion, 1);
  ASSERT_EQ(v0.notes.size(), 1u);
  EXPECT_NE(v0.notes[0].find("format version 1"), std::string::npos) << v0.notes[0];
  EXPECT_EQ(v0.grid.irradiance, g.irradiance);
  expectCheck(inspectVdb(dir + "/v0.vdb"), "format_version", true);
}

// A format_version stored as 0 (or below) is no version at all: render read
// it as version 1, as if the key were missing, while inspect failed it. Both
// now refuse it by one rule, and pass the same files.
TEST(FormatVersion, ZeroOrNegativeIsRefusedByTheReaderAsByInspect) {
  std::string dir = test::outputDir("Convert.FormatVersionZero");
  VdlGrid g = floorGrid();
  for (int stored : {0, -1}) {
    vdb_internal::Damage d;
    d.formatVersion = stored;
    const std::string path = dir + "/v" + std::to_string(stored) + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, g, meta(), d);
    const std::string msg = readError(path);
    EXPECT_NE(msg.find("format_version " + std::to_string(stored) + " is not supported"),
              std::string::npos)
        << msg;
    EXPECT_EQ(msg.find("newer lightoctree"), std::string::npos) << msg;
    VdbReport r = inspectVdb(path);
    expectCheck(r, "format_version", false);
    const VdbCheck* c = findCheck(r, "format_version");
    ASSERT_NE(c, nullptr);
    EXPECT_NE(msg.find(c->detail), std::string::npos) << "reader: " << msg << "\ninspect: "
                                                      << c->detail;
  }
  // Every version this lightoctree writes, stored as an int64 as pyopenvdb
  // writes it: both read it.
  for (int stored = 1; stored <= kVdlFormatVersionVdl; ++stored) {
    vdb_internal::Damage d;
    d.formatVersion = stored;
    d.wideIntegers = true;
    const std::string path = dir + "/ok" + std::to_string(stored) + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, g, meta(), d);
    EXPECT_EQ(readVdlGrid(path).meta.formatVersion, stored);
    expectCheck(inspectVdb(path), "format_version", true);
  }
}

TEST(OptionalGrids, DroppedGridsReadAsZero) {
  std::string dir = test::outputDir("Convert.Drop");
  VdlGrid g = floorGrid();
  VdlWriteOptions opt;
  opt.drop = {"angular_error", "photon_count", "noise", "radius", "area"};
  writeVdlGrid(dir + "/d.vdb", g, meta(), opt);
  LoadedVdl d = readVdlGrid(dir + "/d.vdb");
  EXPECT_EQ(d.absentGrids.size(), 5u);
  EXPECT_EQ(d.grid.irradiance, g.irradiance);
  EXPECT_EQ(d.grid.coords, g.coords);
  for (size_t v = 0; v < g.size(); ++v) {
    ASSERT_EQ(d.grid.areas[v], 0.0f);
    ASSERT_EQ(d.grid.photonCount[v], 0.0f);
  }
  VdbReport r = inspectVdb(dir + "/d.vdb");
  EXPECT_TRUE(r.ok());
  // irradiance, reflectance, normal, vdl_count; two grids per VDL slot; density.
  EXPECT_EQ(r.grids.size(), 4u + 2u * 3u + 1u);

  for (const char* bad : {"irradiance", "vdl0_direction", "vdl_count", "bogus"}) {
    VdlWriteOptions o;
    o.drop = {bad};
    EXPECT_THROW(writeVdlGrid(dir + "/bad.vdb", g, meta(), o), InputError) << bad;
  }
  EXPECT_FALSE(fs::exists(dir + "/bad.vdb"));
  EXPECT_TRUE(leftoverTemporaries(dir + "/bad.vdb").empty());
}

TEST(HalfFloat, ReadsBackWithinHalfPrecisionAndPassesInspect) {
  std::string dir = test::outputDir("Convert.Half");
  VdlGrid g = floorGrid(4);
  writeVdlGrid(dir + "/full.vdb", g, meta());
  VdlWriteOptions opt;
  opt.halfFloat = true;
  writeVdlGrid(dir + "/half.vdb", g, meta(), opt);
  LoadedVdl h = readVdlGrid(dir + "/half.vdb");
  EXPECT_TRUE(h.halfFloat);
  EXPECT_FALSE(readVdlGrid(dir + "/full.vdb").halfFloat);
  double worst = 0;
  for (size_t v = 0; v < g.size(); ++v) {
    for (int k = 0; k < 3; ++k) {
      worst = std::max(worst, std::abs(double(h.grid.irradiance[v][k]) - g.irradiance[v][k]) /
                                  g.irradiance[v][k]);
    }
    // Counts and areas stay 32-bit.
    ASSERT_EQ(h.grid.photonCount[v], g.photonCount[v]);
    ASSERT_EQ(h.grid.areas[v], g.areas[v]);
    ASSERT_EQ(h.grid.vdlCount[v], g.vdlCount[v]);
  }
  std::printf("[ half ] largest relative irradiance error %.3g (2^-11 = %.3g); %ju vs %ju bytes\n",
              worst, std::ldexp(1.0, -11), uintmax_t(fs::file_size(dir + "/half.vdb")),
              uintmax_t(fs::file_size(dir + "/full.vdb")));
  EXPECT_GT(worst, 0.0) << "half storage must round";
  EXPECT_LE(worst, std::ldexp(1.0, -11));
  EXPECT_LT(fs::file_size(dir + "/half.vdb"), fs::file_size(dir + "/full.vdb"));
  VdbReport r = inspectVdb(dir + "/half.vdb");
  EXPECT_TRUE(r.ok());
  for (const GridSummary& s : r.grids) {
    const bool full = s.name == "vdl_count" || s.name == "photon_count" || s.name == "area";
    EXPECT_EQ(s.halfFloat, !full) << s.name;
  }
}

TEST(Inspect, GoodFileReportsGridsAndPasses) {
  std::string dir = test::outputDir("Inspect.Good");
  VdlGrid g = floorGrid(2);
  writeVdlGrid(dir + "/g.vdb", g, meta());
  VdbReport r = inspectVdb(dir + "/g.vdb");
  EXPECT_EQ(r.kind, "vdl");
  EXPECT_TRUE(r.ok());
  ASSERT_EQ(r.grids.size(), 9u + 2u * 2u + 1u);  // + the display grid density
  // VDL grids are active where the voxel has that VDL (sparse).
  size_t withTwo = 0;
  for (size_t v = 0; v < g.size(); ++v) withTwo += g.vdlCount[v] > 1;
  for (const GridSummary& s : r.grids) {
    const bool second = s.name.rfind("vdl1_", 0) == 0;
    const bool first = s.name.rfind("vdl0_", 0) == 0;
    size_t withOne = 0;
    for (size_t v = 0; v < g.size(); ++v) withOne += g.vdlCount[v] > 0;
    EXPECT_EQ(s.activeVoxels, second ? withTwo : first ? withOne : g.size()) << s.name;
    EXPECT_GT(s.memoryBytes, 0u) << s.name;
    EXPECT_NEAR(s.voxelSize[0], g.frame.voxelSize, 1e-9) << s.name;
  }
  auto irr = std::find_if(r.grids.begin(), r.grids.end(),
                          [](const GridSummary& s) { return s.name == "irradiance"; });
  ASSERT_NE(irr, r.grids.end());
  ASSERT_EQ(irr->min.size(), 3u);
  float lo = INFINITY, hi = -INFINITY;
  for (const Vec3& e : g.irradiance) lo = std::min(lo, e.x), hi = std::max(hi, e.x);
  EXPECT_EQ(irr->min[0], lo);
  EXPECT_EQ(irr->max[0], hi);
  for (const char* name :
       {"contract", "format_version", "finite", "same_transform", "same_active_voxels", "vdl_count",
        "irradiance_non_negative", "unit_directions", "vdl_sum"}) {
    expectCheck(r, name, true);
  }
}

TEST(Inspect, DamagedFilesFailTheirCheck) {
  std::string dir = test::outputDir("Inspect.Damaged");
  {
    vdb_internal::Damage d;
    d.omitGrid = "vdl1_irradiance";
    vdb_internal::writeVdlGridDamaged(dir + "/omit.vdb", floorGrid(), meta(), d);
    VdbReport r = inspectVdb(dir + "/omit.vdb");
    expectCheck(r, "contract", false);
    EXPECT_FALSE(r.ok());
    EXPECT_NE(readError(dir + "/omit.vdb").find("missing grid 'vdl1_irradiance'"),
              std::string::npos);
  }
  {
    vdb_internal::Damage d;
    d.shiftGrid = "normal";
    vdb_internal::writeVdlGridDamaged(dir + "/shift.vdb", floorGrid(), meta(), d);
    expectCheck(inspectVdb(dir + "/shift.vdb"), "same_transform", false);
    EXPECT_NE(readError(dir + "/shift.vdb").find("mismatched transforms"), std::string::npos);
  }
  auto damaged = [&](const char* name, auto edit) {
    VdlGrid g = floorGrid();
    edit(g);
    // Past writeVdlGrid's own checks, which would refuse it.
    vdb_internal::writeVdlGridDamaged(dir + "/" + name + ".vdb", g, meta(), vdb_internal::Damage{});
    return inspectVdb(dir + "/" + name + ".vdb");
  };
  expectCheck(damaged("short", [](VdlGrid& g) { g.vdls[0].direction *= 0.5f; }), "unit_directions",
              false);
  // An unused slot (>= vdl_count) may hold anything: zeros are the rule.
  expectCheck(damaged("unused", [](VdlGrid& g) { g.vdlCount[0] = 0; }), "unit_directions", true);
  expectCheck(damaged("sum", [](VdlGrid& g) { g.irradiance[5] *= 1.01f; }), "vdl_sum", false);
  expectCheck(damaged("negative", [](VdlGrid& g) { g.vdls[3].irradiance.y = -0.1f; }),
              "irradiance_non_negative", false);
  expectCheck(damaged("nan", [](VdlGrid& g) { g.radius[7] = NAN; }), "finite", false);
  // A VDL of 3e38 (finite, but the shader's cosine correction and sums would
  // overflow): irradiance_range.
  expectCheck(damaged("huge", [](VdlGrid& g) {
                g.vdls[0].irradiance.x = 3e38f;
                g.irradiance[0].x = 3e38f;
              }),
              "irradiance_range", false);
  // The reader every command uses refuses what inspect fails, naming the check.
  for (const char* name : {"short", "sum", "negative", "huge"}) {
    const std::string msg = readError(dir + "/" + name + ".vdb");
    EXPECT_NE(msg.find("check "), std::string::npos) << name << ": " << msg;
  }
  EXPECT_NE(readError(dir + "/negative.vdb").find("irradiance_non_negative"), std::string::npos);
  EXPECT_NE(readError(dir + "/huge.vdb").find("irradiance_range"), std::string::npos);
}

TEST(Inspect, CorruptedFilesAreInputErrors) {
  std::string dir = test::outputDir("Inspect.Corrupted");
  writeVdlGrid(dir + "/g.vdb", floorGrid(), meta());
  std::ifstream in(dir + "/g.vdb", std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), {});
  auto write = [&](const std::string& name, const std::string& content) {
    std::ofstream f(dir + "/" + name, std::ios::binary);
    f.write(content.data(), std::streamsize(content.size()));
    return dir + "/" + name;
  };
  std::string magic = bytes;
  magic[0] ^= 0x55;
  for (const std::string& path :
       {write("truncated.vdb", bytes.substr(0, bytes.size() / 2)),
        write("header-only.vdb", bytes.substr(0, 40)), write("magic.vdb", magic),
        write("text.vdb", "not a vdb file\n"), dir + "/missing.vdb"}) {
    try {
      inspectVdb(path);
      ADD_FAILURE() << "expected InputError for " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(PhotonPoints, ReadBackEqualsWritten) {
  std::string dir = test::outputDir("Convert.Photons");
  std::vector<Photon> photons(2000);
  Rng rng(9, 0);
  for (Photon& p : photons) {
    p.position = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 2.0f - Vec3(1.0f);
    p.direction = normalize(Vec3(rng.uniform() - 0.5f, rng.uniform(), rng.uniform() - 0.5f));
    p.normal = Vec3(0, 1, 0);
    p.power = Vec3(rng.uniform(), rng.uniform(), rng.uniform()) * 1e-4f;
    p.bounce = rng.uniformInt(4);
    for (uint8_t& r : p.reflectance) r = uint8_t(rng.uniformInt(256));
  }
  writePhotonPoints(dir + "/p.vdb", photons, 0.05f);
  std::vector<Photon> back = readPhotonPoints(dir + "/p.vdb");
  ASSERT_EQ(back.size(), photons.size());
  auto key = [](const Photon& p) {
    return std::make_tuple(p.position.x, p.position.y, p.position.z);
  };
  auto byPos = [&](const Photon& a, const Photon& b) { return key(a) < key(b); };
  std::sort(photons.begin(), photons.end(), byPos);
  std::sort(back.begin(), back.end(), byPos);
  double worstPos = 0;
  for (size_t i = 0; i < photons.size(); ++i) {
    worstPos = std::max(worstPos, double(length(back[i].position - photons[i].position)));
    ASSERT_EQ(back[i].power, photons[i].power);
    ASSERT_EQ(back[i].direction, photons[i].direction);
    ASSERT_EQ(back[i].bounce, photons[i].bounce);
    for (int c = 0; c < 3; ++c) ASSERT_EQ(back[i].reflectance[c], photons[i].reflectance[c]);
  }
  EXPECT_LE(worstPos, 1e-6);
  EXPECT_THROW(readPhotonPoints(dir + "/missing.vdb"), InputError);
  writeVdlGrid(dir + "/vdl.vdb", floorGrid(), meta());
  EXPECT_THROW(readPhotonPoints(dir + "/vdl.vdb"), InputError);
  EXPECT_EQ(inspectVdb(dir + "/p.vdb").kind, "photons");
}

TEST(Convert, VdbPrintListsTheGridsOfAConvertedFile) {
  const char* vdbPrint = "/usr/bin/vdb_print";
  if (!fs::exists(vdbPrint)) GTEST_SKIP() << vdbPrint << " not installed";
  std::string dir = test::outputDir("Convert.VdbPrint");
  ClusterParams params;
  params.vdls = 2;
  VdlGrid coarse = coarsenVdlGrid(floorGrid(), 3, params);
  VdlWriteOptions opt;
  opt.halfFloat = true;
  opt.drop = {"angular_error"};
  BakeMetadata m = meta();
  m.depth = coarse.frame.depth;
  writeVdlGrid(dir + "/c.vdb", coarse, m, opt);
  std::string out = test::runCommand(std::string(vdbPrint) + " -l -m " + dir + "/c.vdb 2>&1");
  for (const char* name : {"irradiance", "normal", "photon_count", "vdl_count", "radius", "area",
                           "vdl0_irradiance", "vdl0_direction", "vdl1_direction"}) {
    EXPECT_NE(out.find("\nName: " + std::string(name) + "\n"), std::string::npos) << name << "\n"
                                                                                  << out;
  }
  EXPECT_EQ(out.find("angular_error"), std::string::npos) << out;
  EXPECT_NE(out.find("is_saved_as_half_float: true"), std::string::npos) << out;
  EXPECT_NE(out.find("format_version: " + std::to_string(kVdlFormatVersionVdl)), std::string::npos)
      << out;
  EXPECT_TRUE(readVdlGrid(dir + "/c.vdb").grid.size() == coarse.size());
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// inspect and the readers agree (issue: a checker and a reader that
// disagree): a file the reader or the GPU octree refuses fails a check.
TEST(Inspect, FailsWhatTheReadersRefuse) {
  const std::string dir = test::outputDir("Inspect.Agree");
  // A rotated transform: readVdlGrid refuses, inspect's "transform" fails.
  vdb_internal::Damage rotated;
  rotated.rotateTransform = true;
  vdb_internal::writeVdlGridDamaged(dir + "/rotated.vdb", floorGrid(), meta(), rotated);
  EXPECT_THROW(readVdlGrid(dir + "/rotated.vdb"), InputError);
  expectCheck(inspectVdb(dir + "/rotated.vdb"), "transform", false);
  // Voxels outside [0, 2^depth): the GPU octree refuses, "voxel_bounds" fails.
  VdlGrid g = floorGrid();
  for (Coord& c : g.coords) c.x -= 100;
  writeVdlGrid(dir + "/outside.vdb", g, meta());
  EXPECT_THROW(buildGpuOctree(readVdlGrid(dir + "/outside.vdb").grid), InputError);
  expectCheck(inspectVdb(dir + "/outside.vdb"), "voxel_bounds", false);
  // A good file passes both.
  writeVdlGrid(dir + "/good.vdb", floorGrid(), meta());
  expectCheck(inspectVdb(dir + "/good.vdb"), "voxel_bounds", true);
  expectCheck(inspectVdb(dir + "/good.vdb"), "transform", true);
  expectCheck(inspectVdb(dir + "/good.vdb"), "depth", true);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

/// floorGrid with a free-space light over its cube, 2 levels coarser.
VdlGrid floorWithVolume() {
  VdlGrid g = floorGrid();
  VolumeLight& v = g.volume;
  v.frame = g.frame;
  v.frame.depth = 2;
  v.frame.voxelSize = g.frame.voxelSize * 4;
  v.shTerms = 4;
  for (int x = 0; x < 4; ++x) {
    v.coords.push_back({x, 1, 2});
    v.irradiance.push_back(Vec3(0.5f));
    for (int i = 0; i < 4; ++i) v.sh.push_back(i == 0 ? Vec3(1.7f) : Vec3(0.1f * float(x)));
    v.segments.push_back(10);
    v.litLower.push_back(Vec3(0.0f));
    v.litUpper.push_back(Vec3(x == 0 ? 0.5f : 1.0f));
  }
  return g;
}

TEST(Inspect, FreeSpaceGridsRoundTripAndTheirDamageIsRefused) {
  const std::string dir = test::outputDir("Inspect.FreeSpace");
  const VdlGrid g = floorWithVolume();
  writeVdlGrid(dir + "/ok.vdb", g, meta());
  const VdbReport ok = inspectVdb(dir + "/ok.vdb");
  EXPECT_TRUE(ok.ok());
  const LoadedVdl back = readVdlGrid(dir + "/ok.vdb");
  EXPECT_EQ(back.grid.volume.coords, g.volume.coords);
  EXPECT_EQ(back.grid.volume.sh, g.volume.sh);
  EXPECT_EQ(back.grid.volume.litUpper, g.volume.litUpper);
  EXPECT_EQ(back.grid.volume.frame.depth, 2);

  // A voxel beyond the free-space grid, a box upside down, a NaN: the writer
  // refuses them; written past it, inspect and the reader do.
  auto damaged = [&](const char* name, auto edit) {
    VdlGrid bad = floorWithVolume();
    edit(bad.volume);
    EXPECT_THROW(writeVdlGrid(dir + "/" + name + ".vdb", bad, meta()), InputError) << name;
    vdb_internal::writeVdlGridDamaged(dir + "/" + name + ".vdb", bad, meta(), vdb_internal::Damage{});
    return dir + "/" + name + ".vdb";
  };
  const std::string outside = damaged("outside", [](VolumeLight& v) { v.coords[3].x = 4; });
  expectCheck(inspectVdb(outside), "voxel_bounds", false);
  EXPECT_NE(readError(outside).find("active voxels, some outside"), std::string::npos)
      << readError(outside);
  const std::string box = damaged("box", [](VolumeLight& v) { v.litLower[1].y = 0.9f; v.litUpper[1].y = 0.2f; });
  EXPECT_NE(readError(box).find("lit box"), std::string::npos) << readError(box);
  const std::string nan = damaged("nan", [](VolumeLight& v) { v.sh[5].x = std::nanf(""); });
  EXPECT_FALSE(inspectVdb(nan).ok());
  EXPECT_NE(readError(nan).find("volume_sh1"), std::string::npos) << readError(nan);
}

}  // namespace
}  // namespace lo

// Issue 43, family 7: mismatched inputs.
namespace lo {
namespace {

/// meta() with the scene bounds the floor grid's cube was made from (depth 4,
/// voxels of 0.0625: a cube of 1 = the bounds' extent and 1% each side).
BakeMetadata metaWithBounds() {
  BakeMetadata m = meta();
  const float extent = 1.0f / 1.02f;
  m.sceneBounds.lower = Vec3(-0.49f, -0.24f, 0.135f);
  m.sceneBounds.upper = m.sceneBounds.lower + Vec3(extent, 0.1f, extent);
  return m;
}

// A transform of negative (or no) size passed `inspect` and was refused by
// `render` (the GPU octree); every reader now refuses it, with one message,
// the one inspect's "readable" check shows.
TEST(Inspect, AVoxelSizeTheReadersRefuseFailsInspectWithTheirMessage) {
  const std::string dir = test::outputDir("Inspect.VoxelSize");
  vdb_internal::Damage mirrored;
  mirrored.scale = -0.0625;
  vdb_internal::writeVdlGridDamaged(dir + "/negative.vdb", floorGrid(), meta(), mirrored);
  const std::string refused = readError(dir + "/negative.vdb");
  EXPECT_NE(refused.find("transform has voxel size -0.0625"), std::string::npos) << refused;
  const VdbReport report = inspectVdb(dir + "/negative.vdb");
  const VdbCheck* readable = findCheck(report, "readable");
  ASSERT_NE(readable, nullptr);
  EXPECT_FALSE(readable->passed);
  EXPECT_EQ(readable->detail, refused);
  EXPECT_FALSE(report.ok());
}

// Metadata claiming depth 6 over depth-4 voxels passed `inspect`, and
// `convert` wrote a grid 4x too large. The voxels' size against the cube the
// recorded bounds make tells: refused by every reader, named by inspect.
TEST(Inspect, ADepthTheVoxelsDoNotHaveIsRefusedByEveryReader) {
  const std::string dir = test::outputDir("Inspect.DepthLie");
  // The honest file, with its bounds, passes: the check has no false alarm.
  writeVdlGrid(dir + "/good.vdb", floorGrid(), metaWithBounds());
  EXPECT_NO_THROW(readVdlGrid(dir + "/good.vdb"));
  EXPECT_TRUE(inspectVdb(dir + "/good.vdb").ok());
  for (int claimed : {6, 3}) {
    vdb_internal::Damage lie;
    lie.metadataDepth = claimed;
    const std::string path = dir + "/depth" + std::to_string(claimed) + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, floorGrid(), metaWithBounds(), lie);
    const std::string refused = readError(path);
    EXPECT_NE(refused.find("file metadata depth = " + std::to_string(claimed)), std::string::npos)
        << refused;
    EXPECT_NE(refused.find("the voxels are of depth 4"), std::string::npos) << refused;
    const VdbReport report = inspectVdb(path);
    const VdbCheck* readable = findCheck(report, "readable");
    ASSERT_NE(readable, nullptr);
    EXPECT_FALSE(readable->passed);
    EXPECT_EQ(readable->detail, refused);
    EXPECT_FALSE(report.ok());
  }
}

// Depth -1 or 13 in a file's metadata was refused late, by a check that
// blamed something else; now by every reader first, with what is allowed,
// and by inspect's depth check in the same words.
TEST(Inspect, ADepthOutOfRangeIsNamedWithWhatIsAllowed) {
  const std::string dir = test::outputDir("Inspect.DepthRange");
  // Also with free-space grids, whose own depth was checked against it first.
  for (const auto& [claimed, volume] :
       {std::pair{-1, false}, std::pair{13, false}, std::pair{31, false}, std::pair{-1, true},
        std::pair{13, true}}) {
    vdb_internal::Damage out;
    out.metadataDepth = claimed;
    const std::string path =
        dir + "/depth" + std::to_string(claimed) + (volume ? "-volume" : "") + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, volume ? floorWithVolume() : floorGrid(),
                                      metaWithBounds(), out);
    const std::string expected = path + ": depth " + std::to_string(claimed) +
                                 " in the file's metadata: a light grid's depth is 1 to 12";
    EXPECT_EQ(readError(path), expected);
    const VdbReport report = inspectVdb(path);
    EXPECT_FALSE(report.ok());
    const VdbCheck* depth = findCheck(report, "depth");
    ASSERT_NE(depth, nullptr);
    EXPECT_FALSE(depth->passed);
    EXPECT_EQ(depth->detail, "depth " + std::to_string(claimed) +
                                 " in the file's metadata: a light grid's depth is 1 to 12");
    const VdbCheck* readable = findCheck(report, "readable");
    ASSERT_NE(readable, nullptr);
    EXPECT_EQ(readable->detail, expected);
  }
}

// A photon map given where a light grid is read (convert IN, render, Python
// read) said "missing file metadata 'depth'": now what it is and where it goes.
TEST(VdbIo, APhotonMapWhereALightGridIsReadIsNamed) {
  const std::string dir = test::outputDir("VdbIo.PhotonMapAsGrid");
  std::vector<Photon> photons(3);
  for (size_t i = 0; i < photons.size(); ++i) {
    photons[i].position = Vec3(float(i), 0, 0);
    photons[i].power = Vec3(1.0f);
    photons[i].direction = photons[i].normal = Vec3(0, 1, 0);
  }
  writePhotonPoints(dir + "/photons.vdb", photons, 0.05f);
  const std::string refused = readError(dir + "/photons.vdb");
  EXPECT_EQ(refused.rfind(dir + "/photons.vdb: this is a photon map (a .vdb of photons", 0), 0u)
      << refused;
  EXPECT_NE(refused.find("not a light grid"), std::string::npos) << refused;
  EXPECT_NE(refused.find("`convert --photon-map`"), std::string::npos) << refused;
  // inspect still tells it for what it is.
  EXPECT_EQ(inspectVdb(dir + "/photons.vdb").kind, "photons");
}

// A light .vdb read and written back unchanged by pyopenvdb holds doubles
// (and vec3d) where the bake wrote floats (and vec3s): it was refused.
TEST(VdbIo, FloatMetadataOfEitherWidthIsRead) {
  const std::string dir = test::outputDir("VdbIo.DoubleMetadata");
  BakeMetadata m = metaWithBounds();
  m.radius = 0.15f;
  m.region = m.sceneBounds;
  vdb_internal::Damage python;
  python.doubleMetadata = true;
  vdb_internal::writeVdlGridDamaged(dir + "/python.vdb", floorGrid(), m, python);
  LoadedVdl back;
  ASSERT_NO_THROW(back = readVdlGrid(dir + "/python.vdb"));
  EXPECT_EQ(back.meta.radius, 0.15f);
  EXPECT_EQ(back.meta.sceneBounds.lower.x, m.sceneBounds.lower.x);
  EXPECT_EQ(back.meta.region.upper.z, m.region.upper.z);
  EXPECT_TRUE(inspectVdb(dir + "/python.vdb").ok());
}

// pyopenvdb writes every Python int as an int64: such a file is read by
// every reader and passes inspect (inspect failed it, "expected int32",
// while render and convert took it).
TEST(VdbIo, IntegerMetadataOfEitherWidthPassesInspect) {
  const std::string dir = test::outputDir("VdbIo.WideIntegers");
  vdb_internal::Damage python;
  python.wideIntegers = true;
  vdb_internal::writeVdlGridDamaged(dir + "/python.vdb", floorGrid(), metaWithBounds(), python);
  LoadedVdl back;
  ASSERT_NO_THROW(back = readVdlGrid(dir + "/python.vdb"));
  EXPECT_EQ(back.grid.maxVdls, floorGrid().maxVdls);
  const VdbReport report = inspectVdb(dir + "/python.vdb");
  for (const VdbCheck& c : report.checks) EXPECT_TRUE(c.passed) << c.name << ": " << c.detail;
}

// Metadata another tool left out of range are refused by every reader and
// failed by inspect, naming the key: a NaN bound let a depth the voxels do
// not have through (convert then wrote a grid of the wrong size), a NaN or
// negative radius was copied on by convert.
TEST(Inspect, MetadataOutOfRangeAreRefusedNamingTheKey) {
  const std::string dir = test::outputDir("Inspect.MetadataRange");
  struct Case {
    const char* name;
    const char* key;
    void (*edit)(BakeMetadata&);
  };
  const Case cases[] = {
      {"radius-nan", "'radius'", [](BakeMetadata& m) { m.radius = std::nanf(""); }},
      {"radius-negative", "'radius'", [](BakeMetadata& m) { m.radius = -1.0f; }},
      {"bounds-nan", "'scene_bounds_min'",
       [](BakeMetadata& m) { m.sceneBounds.upper = Vec3(std::nanf("")); }},
      {"bounds-reversed", "'scene_bounds_min'",
       [](BakeMetadata& m) { std::swap(m.sceneBounds.lower, m.sceneBounds.upper); }},
      {"photons-negative", "'photons'", [](BakeMetadata& m) { m.photons = -5; }},
      // A switch other than 0 or 1 read as off (render did not warn that the
      // direct light of include_direct = 7 is counted twice).
      {"include-direct-7", "'include_direct' = 7", [](BakeMetadata& m) { m.includeDirect = 7; }},
      {"layers-2", "'surface_layers' = 2", [](BakeMetadata& m) { m.surfaceLayers = 2; }},
  };
  for (const Case& c : cases) {
    BakeMetadata m = metaWithBounds();
    c.edit(m);
    const std::string path = dir + "/" + c.name + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, floorGrid(), m, {});
    const std::string refused = readError(path);
    EXPECT_NE(refused.find(c.key), std::string::npos) << c.name << ": " << refused;
    EXPECT_FALSE(inspectVdb(path).ok()) << c.name;
  }
}

// A gather of no neighbours, or of a radius of 0, is not one a bake makes:
// `knn` <= 0 and a `radius` of 0, negative or not finite passed inspect.
// Refused by every reader and failed by inspect, naming the key; a file
// without them (a grid made in code) is read.
TEST(Inspect, ImpossibleKnnAndRadiusAreRefusedNamingTheKey) {
  const std::string dir = test::outputDir("Inspect.KnnRadius");
  struct Case {
    const char* name;
    const char* key;
    vdb_internal::Damage damage;
  };
  auto knn = [](int32_t k) {
    vdb_internal::Damage d;
    d.intMetadata = {{"knn", k}};
    return d;
  };
  auto radius = [](float r) {
    vdb_internal::Damage d;
    d.floatMetadata = {{"radius", r}};
    return d;
  };
  const Case cases[] = {
      {"knn-0", "'knn' = 0", knn(0)},
      {"knn-negative", "'knn' = -7", knn(-7)},
      {"radius-0", "'radius' = 0", radius(0.0f)},
      {"radius-negative", "'radius' = -0.5", radius(-0.5f)},
      {"radius-infinite", "'radius' = inf", radius(INFINITY)},
      {"radius-nan", "'radius' = nan", radius(std::nanf(""))},
  };
  for (const Case& c : cases) {
    const std::string path = dir + "/" + c.name + ".vdb";
    vdb_internal::writeVdlGridDamaged(path, floorGrid(), metaWithBounds(), c.damage);
    const std::string refused = readError(path);
    EXPECT_NE(refused.find(c.key), std::string::npos) << c.name << ": " << refused;
    const VdbReport report = inspectVdb(path);
    EXPECT_FALSE(report.ok()) << c.name;
    bool named = false;
    for (const VdbCheck& check : report.checks) {
      named = named || (!check.passed && check.detail.find(c.key) != std::string::npos);
    }
    EXPECT_TRUE(named) << c.name << ": inspect does not name " << c.key;
  }
  // Recorded and possible, or not recorded: read.
  BakeMetadata recorded = metaWithBounds();
  recorded.radius = 0.05f;
  writeVdlGrid(dir + "/recorded.vdb", floorGrid(), recorded);
  EXPECT_EQ(readVdlGrid(dir + "/recorded.vdb").meta.knn, 100);
  EXPECT_TRUE(inspectVdb(dir + "/recorded.vdb").ok());
  BakeMetadata none = metaWithBounds();
  none.knn = 0;
  writeVdlGrid(dir + "/none.vdb", floorGrid(), none);
  EXPECT_EQ(readVdlGrid(dir + "/none.vdb").meta.knn, 0);
  EXPECT_TRUE(inspectVdb(dir + "/none.vdb").ok());
}

// Under `ulimit -n` a reader that could open no more files said "cannot read
// as an OpenVDB file: IoError: could not open file x.vdb" (OpenVDB's words),
// hiding EMFILE: it says "Too many open files" and the limit. With no file
// left (the handover file is not made, the read is in this process) and
// with one (the handover takes it, the reading child has none).
TEST(VdbIo, TooManyOpenFilesIsSaidNotHidden) {
#if defined(__SANITIZE_ADDRESS__)
  // The sanitizers' runtime needs descriptors of its own: without them
  // UBSan reports every virtual call as an "invalid vptr".
  GTEST_SKIP() << "a sanitizer build: its runtime needs descriptors of its own";
#endif
  const std::string dir = test::outputDir("VdbIo.TooManyOpenFiles");
  const std::string path = dir + "/fine.vdb";
  writeVdlGrid(path, floorGrid(), metaWithBounds());
  for (int spare : {0, 1}) {
    // The limit in a child, not in the tests' process.
    const std::string text = test::textFromChild([&] {
      const int lowest = ::open("/dev/null", O_RDONLY);  // the lowest free descriptor
      if (lowest < 0) std::_Exit(2);
      ::close(lowest);
      const rlimit files{rlim_t(lowest + spare), rlim_t(lowest + spare)};
      if (setrlimit(RLIMIT_NOFILE, &files) != 0) std::_Exit(2);
      std::string said = "read";
      try {
        readVdlGrid(path);
      } catch (const std::exception& e) {
        said = e.what();
      }
      return said;
    });
    EXPECT_EQ(text.rfind("cannot open '" + path + "': Too many open files (this process may hold ",
                         0),
              0u)
        << "spare " << spare << ": " << text;
    EXPECT_NE(text.find(" at once: ulimit -n)"), std::string::npos) << text;
  }
  EXPECT_EQ(readVdlGrid(path).grid.size(), floorGrid().size());
}

// A photon map carries the hash of the scene it was traced in; a reader
// given another scene is told (convert --photon-map --scene).
TEST(PhotonPoints, CarryTheirScenesHash) {
  const std::string dir = test::outputDir("PhotonPoints.SceneHash");
  std::vector<Photon> photons(3);
  for (size_t i = 0; i < photons.size(); ++i) {
    photons[i].position = Vec3(float(i), 0, 0);
    photons[i].power = Vec3(1.0f);
    photons[i].direction = photons[i].normal = Vec3(0, 1, 0);
  }
  writePhotonPoints(dir + "/hashed.vdb", photons, 0.05f, Vec3d(), nullptr,
                    {"0123456789abcdef", Bounds3(), ""});
  writePhotonPoints(dir + "/plain.vdb", photons, 0.05f);
  PhotonMapInfo info{"x", Bounds3(), ""};
  EXPECT_EQ(readPhotonPoints(dir + "/hashed.vdb", Vec3d(), &info).size(), 3u);
  EXPECT_EQ(info.sourceSceneHash, "0123456789abcdef");
  readPhotonPoints(dir + "/plain.vdb", Vec3d(), &info);
  EXPECT_EQ(info.sourceSceneHash, "");
  // The warning: none when the hashes agree or none was recorded.
  EXPECT_EQ(sceneMismatchWarning("--photon-map 'p.vdb'", "", "s.gltf", "1"), "");
  EXPECT_EQ(sceneMismatchWarning("--photon-map 'p.vdb'", "1", "s.gltf", "1"), "");
  const std::string warning = sceneMismatchWarning("--photon-map 'p.vdb'", "1", "s.gltf", "2");
  EXPECT_NE(warning.find("--photon-map 'p.vdb' was made from a scene with content hash 1"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("'s.gltf' and the files it reads have 2"), std::string::npos) << warning;
}

// A photon map records the sky it was traced under, as the grid does
// (ninth hostile list H9-7-38: photons of `--sky 3,3,3` re-gathered into a
// grid baked without a sky gave no warning, and the 24 times brighter output
// still recorded sky_hash "none", misleading render's sky check).
TEST(PhotonPoints, CarryTheSkyTheyWereTracedUnder) {
  const std::string dir = test::outputDir("PhotonPoints.SkyHash");
  std::vector<Photon> photons(3);
  for (size_t i = 0; i < photons.size(); ++i) {
    photons[i].position = Vec3(float(i), 0, 0);
    photons[i].power = Vec3(1.0f);
    photons[i].direction = photons[i].normal = Vec3(0, 1, 0);
  }
  Sky sky;
  sky.radiance = {3, 3, 3};
  BakeMetadata m = meta();
  m.skyHash = sky.fingerprint();
  writePhotonPoints(dir + "/sky.vdb", photons, 0.05f, Vec3d(), nullptr, photonMapInfo(m));
  writePhotonPoints(dir + "/plain.vdb", photons, 0.05f);
  PhotonMapInfo info;
  readPhotonPoints(dir + "/sky.vdb", Vec3d(), &info);
  EXPECT_EQ(info.skyHash, sky.fingerprint());
  readPhotonPoints(dir + "/plain.vdb", Vec3d(), &info);
  EXPECT_EQ(info.skyHash, "");
  // The warning: only when both are recorded and differ.
  EXPECT_EQ(photonSkyMismatchWarning("p", "", "g", "none"), "");
  EXPECT_EQ(photonSkyMismatchWarning("p", "none", "g", ""), "");
  EXPECT_EQ(photonSkyMismatchWarning("p", sky.fingerprint(), "g", sky.fingerprint()), "");
  const std::string warning =
      photonSkyMismatchWarning("--photon-map 'p.vdb'", sky.fingerprint(), "IN 'g.vdb'", "none");
  EXPECT_NE(warning.find("--photon-map 'p.vdb' was traced under another sky (the sky " +
                         sky.fingerprint() + ") than IN 'g.vdb' was baked under (no sky)"),
            std::string::npos)
      << warning;
}

// A photon map records whether it holds the direct light (tenth hostile list
// H10-7-81: photons of `--include-direct` re-gathered into a grid baked
// without it doubled the direct light, and the output recorded
// include_direct 0, so render added it once more without a word).
TEST(PhotonPoints, RecordWhetherTheyHoldTheDirectLight) {
  const std::string dir = test::outputDir("PhotonPoints.IncludeDirect");
  std::vector<Photon> photons(2);
  for (size_t i = 0; i < photons.size(); ++i) {
    photons[i].position = Vec3(float(i), 0, 0);
    photons[i].power = Vec3(1.0f);
    photons[i].direction = photons[i].normal = Vec3(0, 1, 0);
  }
  PhotonMapInfo info;
  for (int direct : {1, 0}) {
    BakeMetadata m = meta();
    m.includeDirect = direct;
    writePhotonPoints(dir + "/p.vdb", photons, 0.05f, Vec3d(), nullptr, photonMapInfo(m));
    readPhotonPoints(dir + "/p.vdb", Vec3d(), &info);
    EXPECT_EQ(info.includeDirect, direct);
  }
  writePhotonPoints(dir + "/plain.vdb", photons, 0.05f);
  readPhotonPoints(dir + "/plain.vdb", Vec3d(), &info);
  EXPECT_EQ(info.includeDirect, -1);
  EXPECT_EQ(photonDirectMismatchWarning("p", -1, "g", 0), "");
  EXPECT_EQ(photonDirectMismatchWarning("p", 1, "g", -1), "");
  EXPECT_EQ(photonDirectMismatchWarning("p", 1, "g", 1), "");
  const std::string warning = photonDirectMismatchWarning("--photon-map 'p.vdb'", 1, "IN 'g.vdb'", 0);
  EXPECT_NE(warning.find("--photon-map 'p.vdb' was traced with --include-direct (the direct "
                         "light in it), IN 'g.vdb' was baked without --include-direct"),
            std::string::npos)
      << warning;
}

// A grid records the sky it was baked under (eighth hostile list F7-42:
// `render --sky 5,5,5` on a grid baked under the scene's own sky drew the
// same surfaces as `--sky 0,0,0`, without a word). The same sky, read back
// from the file, warns of nothing; another radiance, another image texel or
// no sky does; a file that records none (older) warns of nothing.
TEST(Inspect, AGridBakedUnderAnotherSkySaysSo) {
  const std::string dir = test::outputDir("Inspect.SkyHash");
  Sky baked;
  baked.radiance = {1, 1, 1};
  baked.image = std::make_shared<const Texture>(
      Texture::fromLinear(2, 2, {{1, 2, 3}, {4, 5, 6}, {0, 0, 0}, {0, 0, 0}}));
  BakeMetadata m = meta();
  m.skyHash = baked.fingerprint();
  writeVdlGrid(dir + "/sky.vdb", floorGrid(), m);
  const LoadedVdl read = readVdlGrid(dir + "/sky.vdb");
  EXPECT_EQ(read.meta.skyHash, baked.fingerprint());
  EXPECT_EQ(skyMismatchWarning(read.meta, baked), "");
  Sky brighter = baked;
  brighter.radiance = {5, 5, 5};
  Sky otherTexel = baked;
  otherTexel.image = std::make_shared<const Texture>(
      Texture::fromLinear(2, 2, {{1, 2, 3}, {4, 5, 7}, {0, 0, 0}, {0, 0, 0}}));
  for (const Sky& given : {brighter, otherTexel, Sky{}}) {
    const std::string warning = skyMismatchWarning(read.meta, given);
    EXPECT_NE(warning.find("baked under another sky"), std::string::npos) << warning;
    EXPECT_NE(given.fingerprint(), baked.fingerprint());
  }
  EXPECT_EQ(Sky{}.fingerprint(), "none");
  EXPECT_EQ(skyMismatchWarning(meta(), brighter), "");  // not recorded
}

// A .vdb's string metadata is whatever wrote it: a source_scene_path with
// terminal escapes (a window title, a cleared screen, a recoloured line) was
// printed raw by the stale-scene warning of render, view, lightmap and
// Python. The warning shows them escaped, and the reader's refusal of a
// representation it does not know quotes it escaped too.
TEST(Inspect, ControlCharactersOfTheMetadataArePrintedEscaped) {
  const std::string dir = test::outputDir("Inspect.ControlCharacters");
  BakeMetadata m = meta();
  m.sourceScenePath = "/scenes/\x1b]0;owned\x07\x1b[2Jroom\xc2\x9b" "31m.gltf";
  m.sourceSceneHash = "fnv1a64:\x1b[31m0000000000000000";
  writeVdlGrid(dir + "/escapes.vdb", floorGrid(), m);
  const LoadedVdl read = readVdlGrid(dir + "/escapes.vdb");
  EXPECT_EQ(read.meta.sourceScenePath, m.sourceScenePath);  // the value itself is kept
  const std::string warning =
      staleBakeWarning(read.meta, test::dataDir() + "/cornell-box.gltf");
  ASSERT_FALSE(warning.empty());
  for (const char control : {'\x1b', '\x07'}) {
    EXPECT_EQ(warning.find(control), std::string::npos) << warning;
  }
  EXPECT_EQ(warning.find("\xc2\x9b"), std::string::npos) << warning;
  EXPECT_NE(warning.find("/scenes/\\x1b]0;owned\\x07\\x1b[2Jroom\\u009b31m.gltf"),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("fnv1a64:\\x1b[31m0"), std::string::npos) << warning;

  vdb_internal::Damage representation;
  representation.stringMetadata = {{"representation", "sh9\x1b[8m"}};
  vdb_internal::writeVdlGridDamaged(dir + "/representation.vdb", floorGrid(), meta(),
                                    representation);
  const std::string refused = readError(dir + "/representation.vdb");
  EXPECT_EQ(refused.find('\x1b'), std::string::npos) << refused;
  EXPECT_NE(refused.find("'sh9\\x1b[8m'"), std::string::npos) << refused;
}

// A bake records the scene as it was read, not as it is when the bake ends:
// a scene edited during its bake (H16-7-4) is then called stale, not
// recorded with the edited file's hash.
TEST(Inspect, TheBakeRecordsTheSceneAsItWasRead) {
  const std::string dir = test::outputDir("Inspect.RecordedAsRead");
  const std::string path = dir + "/room.gltf";
  fs::copy_file(test::dataDir() + "/cornell-box.gltf", path, fs::copy_options::overwrite_existing);
  const Scene scene = loadScene(path);
  const std::string asRead = sceneContentHash(path);
  EXPECT_EQ(scene.contentHash, asRead);
  std::ofstream(path, std::ios::app) << "\n";  // edited while the bake runs
  BakeMetadata m = meta();
  recordSourceScene(m, scene);
  EXPECT_EQ(m.sourceSceneHash, asRead);
  EXPECT_NE(sceneContentHash(path), asRead);
  EXPECT_FALSE(staleBakeWarning(m, path).empty());
}

}  // namespace
}  // namespace lo
