// The lightmap export (export/lightmap_export.h): every file it names is
// written and nothing else, the direction pages holding the atlas's
// directions; the RGBM range is the power of two above the
// brightest texel; the glTF reads back with its lightmap UVs; a file that
// cannot be written takes the others with it; --content full adds the
// path tracer's direct light; a bad output name is refused before any work.

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <string>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "core/error.h"
#include "export/lightmap_export.h"
#include "image/image.h"
#include "lightgrid/vdl_grid.h"
#include "scene/scene.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

/// Every voxel of a depth-3 grid over [0, 2]^3 active, one VDL lighting
/// surfaces that face up: enough light for the unit room to have pages.
VdlGrid uniformGrid() {
  VdlGrid g;
  g.frame.origin = {0, 0, 0};
  g.frame.voxelSize = 0.25f;
  g.frame.depth = 3;
  g.maxVdls = kMaxVdls;
  for (int z = 0; z < 8; ++z)
    for (int y = 0; y < 8; ++y)
      for (int x = 0; x < 8; ++x) {
        g.coords.push_back({x, y, z});
        g.normals.push_back({0, 1, 0});
        g.vdlCount.push_back(1);
        for (int i = 0; i < kMaxVdls; ++i) {
          Vdl v;
          if (i == 0) {
            v.irradiance = {0.3f, 0.2f, 0.1f + 0.01f * float(x)};
            v.direction = {0, -1, 0};
          }
          g.vdls.push_back(v);
        }
      }
  return g;
}

std::set<std::string> filesIn(const std::string& dir) {
  std::set<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.insert(e.path().filename().string());
  return names;
}

double sumOfPages(const LightmapAtlas& atlas) {
  double sum = 0;
  for (const RgbImage& page : atlas.irradiance)
    for (float v : page.rgb) sum += double(v);
  return sum;
}

TEST(LightmapExport, WritesEveryFileItNamesAndNothingElse) {
  const std::string dir = test::outputDir("lightmap_export_files");
  const Scene scene = test::pointLitRoom();
  LightmapExportParams p;
  p.output = dir + "/room.gltf";
  p.rgbm = true;
  p.preview = true;
  p.chartImages = true;
  p.lightmap.uv.texelSize = 0.02f;  // 50 texels along a wall
  p.lightmap.uv.atlasSize = 64;     // and small pages: more than one
  const LightmapExportResult r = exportLightmap(scene, uniformGrid(), p);

  const int pages = r.lightmap.atlas.pageCount;
  ASSERT_GT(pages, 1);
  std::set<std::string> expected = {"room.gltf", "room.bin", "room-preview.glb"};
  for (int i = 0; i < pages; ++i) {
    expected.insert("room-lightmap" + std::to_string(i) + ".png");
    expected.insert("room-charts" + std::to_string(i) + ".png");
    expected.insert("room-direction" + std::to_string(i) + ".png");
  }
  EXPECT_EQ(filesIn(dir), expected);
  ASSERT_EQ(r.directionPaths.size(), size_t(pages));
  EXPECT_EQ(r.directionPaths[1], lightmapDirectionPath(p.output, 1));
  // The direction pages hold the atlas's directions (to 0.5 / 127), and the
  // glTF names them.
  for (int i = 0; i < pages; ++i) {
    const RgbImage& want = r.lightmap.atlas.direction[size_t(i)];
    std::ifstream file(r.directionPaths[size_t(i)], std::ios::binary);
    const std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(file)), {});
    const RgbImage got = decodeUnitVectors(decodeImageBytes(bytes.data(), bytes.size()));
    ASSERT_EQ(got.rgb.size(), want.rgb.size());
    for (size_t k = 0; k < got.rgb.size(); ++k) {
      ASSERT_NEAR(got.rgb[k], std::clamp(want.rgb[k], -1.0f, 1.0f), 0.5f / 127 + 1e-6f) << i << " " << k;
    }
  }
  {
    std::ifstream in(p.output);
    const nlohmann::json gltf = nlohmann::json::parse(in);
    const nlohmann::json& direction = gltf["materials"][0]["extras"]["lightmap"]["direction"];
    EXPECT_EQ(direction["encoding"], "unit-vector-png");
    EXPECT_EQ(direction["space"], "world");
    EXPECT_EQ(direction["uri"].get<std::string>().rfind("room-direction", 0), 0u);
  }
  ASSERT_EQ(r.pagePaths.size(), size_t(pages));
  EXPECT_EQ(r.pagePaths[1], lightmapPagePath(p.output, 1, true));
  EXPECT_EQ(r.chartPaths.size(), size_t(pages));
  EXPECT_EQ(r.previewPath, dir + "/room-preview.glb");
  EXPECT_EQ(r.outputBytes, size_t(fs::file_size(dir + "/room.gltf") + fs::file_size(dir + "/room.bin")));
  EXPECT_EQ(r.previewBytes, size_t(fs::file_size(r.previewPath)));
  size_t pageBytes = 0;
  for (const std::string& page : r.pagePaths) pageBytes += size_t(fs::file_size(page));
  for (const std::string& page : r.directionPaths) pageBytes += size_t(fs::file_size(page));
  EXPECT_EQ(r.pageFileBytes, pageBytes);
  EXPECT_GT(r.octreeLeaves, 0u);
  EXPECT_TRUE(r.glInfo.empty());
  // Rows: octree, UVs, four atlas steps, encode, write.
  ASSERT_EQ(r.stages.size(), 8u);
  EXPECT_EQ(r.stages.front().name, "octree");
  EXPECT_EQ(r.stages.back().name, "write");

  float brightest = 0;
  for (const RgbImage& page : r.lightmap.atlas.irradiance)
    for (float v : page.rgb) brightest = std::max(brightest, v);
  ASSERT_GT(brightest, 0.0f);
  EXPECT_GE(r.rgbmRange, brightest);
  EXPECT_LT(r.rgbmRange, 2 * brightest);
  EXPECT_EQ(r.rgbmRange, std::exp2(std::round(std::log2(r.rgbmRange)))) << "a power of two";

  const Scene back = loadScene(p.output);
  EXPECT_EQ(back.triangleCount(), scene.triangleCount());
  EXPECT_FALSE(back.texcoords1.empty()) << "the lightmap UVs as TEXCOORD_1";
}

TEST(LightmapExport, AFileThatCannotBeWrittenTakesTheOthersWithIt) {
  const std::string dir = test::outputDir("lightmap_export_rollback");
  // The preview is written after the pages and the lit glTF; a folder of
  // its name makes it fail.
  fs::create_directory(dir + "/room-preview.glb");
  LightmapExportParams p;
  p.output = dir + "/room.glb";
  p.preview = true;
  EXPECT_THROW(exportLightmap(test::pointLitRoom(), uniformGrid(), p), IoError);
  EXPECT_EQ(filesIn(dir), std::set<std::string>{"room-preview.glb"})
      << "pages and the lit .glb removed again, no temporary files";
}

TEST(LightmapExport, FullContentAddsTheDirectLight) {
  const Scene scene = test::pointLitRoom();
  LightmapExportParams p;
  p.output = test::outputDir("lightmap_export_full") + "/room.glb";
  p.lightmap.uv.atlasSize = 64;
  const double indirect = sumOfPages(exportLightmap(scene, uniformGrid(), p).lightmap.atlas);
  p.content = AtlasContent::Full;
  p.directSamples = 1;  // a point light takes one shadow ray whatever the count
  const double full = sumOfPages(exportLightmap(scene, uniformGrid(), p).lightmap.atlas);
  EXPECT_GT(full, indirect * 1.05) << "the point light's direct irradiance on the room";
}

TEST(LightmapExport, ABadOutputNameIsRefusedBeforeAnyWork) {
  const std::string dir = test::outputDir("lightmap_export_bad_name");
  test::expectRefusal([&] { checkLightmapExportPath(dir + "/room.png"); }, {"--output: '"});
  LightmapExportParams p;
  p.output = dir + "/room.png";
  EXPECT_THROW(exportLightmap(test::pointLitRoom(), uniformGrid(), p), InputError);
  EXPECT_TRUE(filesIn(dir).empty());
  EXPECT_EQ(parseAtlasContent("full"), AtlasContent::Full);
  EXPECT_STREQ(toString(AtlasContent::Indirect), "indirect");
  EXPECT_THROW(parseAtlasContent("direct"), InputError);
}


// The stitch's least-squares fit leaves negative values in gutter texels of
// the Cornell box's atlas; the written pages hold none.
TEST(LightmapExport, PagesHoldNoNegativeIrradiance) {
  const Scene scene = loadScene(test::sharedScenesDir() + "/composed/cornell-box.glb");
  const VdlGrid grid = bake(scene, test::smallBake(5, 100000)).grid;
  LightmapExportParams p;
  p.output = test::outputDir("lightmap_export_non_negative") + "/box.gltf";
  const LightmapExportResult r = exportLightmap(scene, grid, p);
  size_t negativeInAtlas = 0;
  for (const RgbImage& page : r.lightmap.atlas.irradiance)
    for (float v : page.rgb) negativeInAtlas += v < 0;
  EXPECT_GT(negativeInAtlas, 0u) << "the atlas should show what the files must not hold";
  ASSERT_FALSE(r.pagePaths.empty());
  for (const std::string& path : r.pagePaths) {
    const RgbImage page = readImage(path);
    EXPECT_GE(*std::min_element(page.rgb.begin(), page.rgb.end()), 0.0f) << path;
  }
}

}  // namespace
}  // namespace lo
