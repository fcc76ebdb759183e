// sceneFiles: every file loading a scene reads, so that no command's output
// replaces one of them (an output that is an input).

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>

#include "core/error.h"
#include "core/file.h"
#include "export/lightmap_export.h"
#include "scene/scene_files.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> names(const std::vector<std::string>& files) {
  std::vector<std::string> out;
  for (const std::string& f : files) out.push_back(fs::path(f).filename().string());
  return out;
}

TEST(SceneFiles, AGltfListsItsBuffersAndImages) {
  const std::string truck = test::sharedScenesDir() + "/real/milk-truck-spots/truck-under-spots.gltf";
  const std::vector<std::string> files = sceneFiles(truck);
  EXPECT_EQ(names(files), (std::vector<std::string>{"truck-under-spots.gltf",
                                                    "CesiumMilkTruck0.bin", "CesiumMilkTruck.png"}));
  for (const std::string& f : files) EXPECT_TRUE(fs::is_regular_file(f)) << f;
}

TEST(SceneFiles, AGlbListsItselfAndAnObjItsLibrariesAndTextures) {
  EXPECT_EQ(names(sceneFiles(test::sharedScenesDir() + "/composed/cornell-box.glb")),
            std::vector<std::string>{"cornell-box.glb"});
  const std::vector<std::string> files =
      sceneFiles(test::sharedScenesDir() + "/real/viking-room/viking_room_lit.obj");
  EXPECT_EQ(names(files), (std::vector<std::string>{"viking_room_lit.obj", "viking_room_lit.mtl",
                                                    "viking_room.png"}));
}

TEST(SceneFiles, WhatCannotBeReadListsTheSceneAlone) {
  const std::string dir = test::outputDir("SceneFiles.Bad");
  {
    std::ofstream(dir + "/broken.gltf") << "{ not json";
  }
  EXPECT_EQ(sceneFiles(dir + "/broken.gltf"), std::vector<std::string>{dir + "/broken.gltf"});
  EXPECT_EQ(sceneFiles(dir + "/missing.gltf"), std::vector<std::string>{dir + "/missing.gltf"});
  {
    // A uri outside the folder is the loader's to refuse, not listed.
    std::ofstream(dir + "/outside.gltf")
        << R"({"asset":{"version":"2.0"},"images":[{"uri":"../x.png"}],)"
        << R"("buffers":[{"uri":"a%20b.bin","byteLength":4}]})";
  }
  EXPECT_EQ(names(sceneFiles(dir + "/outside.gltf")),
            (std::vector<std::string>{"outside.gltf", "a b.bin"}));
}

// A lightmap export refuses outputs that would replace the scene's files:
// its glTF, its .bin, its preview, and any numbered page, direction page or
// chart image (what it writes, or removes when an earlier export left it).
TEST(SceneFiles, ALightmapExportWouldNotReplaceTheScenesFiles) {
  const std::string dir = test::outputDir("SceneFiles.Lightmap");
  const NamedPaths inputs{{"SCENE", dir + "/room.gltf"},
                          {"SCENE's file 'room.bin'", dir + "/room.bin"},
                          {"SCENE's file 'out-lightmap3.exr'", dir + "/out-lightmap3.exr"},
                          {"SCENE's file 'out-charts0.png'", dir + "/out-charts0.png"},
                          {"SCENE's file 'y-preview.glb'", dir + "/y-preview.glb"}};
  EXPECT_NO_THROW(checkLightmapOutputs(dir + "/lit.gltf", true, inputs));
  EXPECT_THROW(checkLightmapOutputs(dir + "/room.gltf", false, inputs), InputError);
  EXPECT_NO_THROW(checkLightmapOutputs(dir + "/room.glb", false, {inputs[1]}))
      << "no .bin beside a .glb: only a .gltf output writes room.bin";
  EXPECT_THROW(checkLightmapOutputs(dir + "/out.glb", false, {inputs[2]}), InputError)
      << "an EXR page name, even for PNG pages: an earlier export's page is removed";
  EXPECT_THROW(checkLightmapOutputs(dir + "/out.glb", false, {inputs[3]}), InputError)
      << "a chart image name, even without --chart-image";
  EXPECT_THROW(checkLightmapOutputs(dir + "/room.glb", false,
                                    {{"SCENE's file 'room-direction2.png'", dir + "/room-direction2.png"}}),
               InputError);
  EXPECT_NO_THROW(checkLightmapOutputs(dir + "/out.glb", false, {inputs[4]}));
  EXPECT_THROW(checkLightmapOutputs(dir + "/y.glb", true, inputs), InputError);
  // lit.gltf writes lit.bin.
  test::expectRefusal(
      [&] {
        checkLightmapOutputs(dir + "/lit.gltf", false,
                             {{"SCENE's file 'lit.bin'", dir + "/lit.bin"}});
      },
      {"SCENE's file 'lit.bin'"});
}

// The content hash: the same bytes give the same hash wherever they lie and
// whatever the scene file is called; a byte changed in a file it reads (an
// image) changes it.
TEST(SceneFiles, TheContentHashFollowsTheBytesNotTheNames) {
  const std::string dir = test::outputDir("SceneFiles.Hash");
  fs::create_directories(dir + "/a");
  fs::create_directories(dir + "/b");
  const std::string gltf =
      R"({"asset":{"version":"2.0"},"images":[{"uri":"t.png"}]})";
  for (const char* sub : {"/a/", "/b/"}) {
    std::ofstream(dir + sub + (sub[1] == 'a' ? "scene.gltf" : "renamed.gltf")) << gltf;
    std::ofstream(dir + sub + "t.png") << "not really a png";
  }
  const std::string a = sceneContentHash(dir + "/a/scene.gltf");
  EXPECT_EQ(a.rfind("fnv1a64:", 0), 0u) << a;
  EXPECT_EQ(a.size(), 8u + 16u);
  EXPECT_EQ(a, sceneContentHash(dir + "/b/renamed.gltf"));
  std::ofstream(dir + "/b/t.png") << "not really a pnG";
  EXPECT_NE(a, sceneContentHash(dir + "/b/renamed.gltf"));
  fs::remove(dir + "/b/t.png");  // a missing image counts too
  EXPECT_NE(a, sceneContentHash(dir + "/b/renamed.gltf"));
}

// The stamp the load compares before and after reading changes when a file
// of the scene is written, and only then.
TEST(SceneFiles, TheStampChangesWhenAFileIsWritten) {
  const std::string dir = test::outputDir("SceneFiles.Stamp");
  std::ofstream(dir + "/scene.gltf") << R"({"asset":{"version":"2.0"},"images":[{"uri":"t.png"}]})";
  std::ofstream(dir + "/t.png") << "texture";
  // Times in the past, so that the write below is seen on any clock.
  const auto past = fs::file_time_type::clock::now() - std::chrono::hours(1);
  fs::last_write_time(dir + "/t.png", past);
  const std::vector<std::string> files = sceneFiles(dir + "/scene.gltf");
  ASSERT_EQ(files.size(), 2u);
  const std::string stamp = sceneFilesStamp(files);
  EXPECT_EQ(stamp, sceneFilesStamp(files));
  std::ofstream(dir + "/t.png") << "texturE";  // the same size
  EXPECT_NE(stamp, sceneFilesStamp(files));
}

}  // namespace
}  // namespace lo
