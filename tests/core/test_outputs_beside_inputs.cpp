// No output replaces an input (core/file.h): outputs named by a rule
// (numbered pages, saved frames, a results folder) are checked against the
// inputs in their folder however either is named (bare, with "..", through a
// link), and a path with a NUL byte, which the system would cut short and
// take for another file, is neither read nor written.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <string>

#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

/// "page N" for the names out-N.png, as a lightmap names its pages.
std::string pageKind(const std::string& name) {
  return name.rfind("out-", 0) == 0 && hasExtension(name, ".png") ? "page '" + name + "'" : "";
}

/// Runs `run` with the working folder `dir`, and goes back.
void inFolder(const std::string& dir, const std::function<void()>& run) {
  const fs::path before = fs::current_path();
  fs::current_path(dir);
  try {
    run();
  } catch (...) {
    fs::current_path(before);
    throw;
  }
  fs::current_path(before);
}

TEST(OutputsBesideInputs, AnInputNamedLikeAnOutputIsFoundByAnyName) {
  const std::string dir = test::outputDir("OutputsBesideInputs.Names");
  fs::create_directories(dir + "/sub");
  std::ofstream(dir + "/out-3.png") << "the scene's texture";
  const NamedPaths inputs{{"SCENE", dir + "/scene.gltf"},
                          {"SCENE's file 'out-3.png'", dir + "/out-3.png"}};
  test::expectRefusal([&] { checkFolderOutputs(dir, pageKind, "--output", inputs); },
                      {"--output: the page 'out-3.png' would replace the input SCENE's file "
                       "'out-3.png'"});
  EXPECT_THROW(checkFolderOutputs(dir + "/sub/..", pageKind, "--output", inputs), InputError);
  EXPECT_NO_THROW(checkFolderOutputs(dir + "/sub", pageKind, "--output", inputs));
  EXPECT_NO_THROW(checkFolderOutputs(dir, pageKind, "--output", {inputs[0]}));
  // Bare names in the scene's folder: the output's folder is "", the input's
  // path relative (before, "" compared unequal to every folder).
  inFolder(dir, [&] {
    EXPECT_THROW(
        checkFolderOutputs("", pageKind, "--output", {{"SCENE's file 'out-3.png'", "out-3.png"}}),
        InputError);
    EXPECT_THROW(checkFolderOutputs(".", pageKind, "--output", inputs), InputError);
    EXPECT_THROW(checkDistinctFiles({{"--output", "out-3.png"}}, inputs), InputError);
    EXPECT_THROW(
        checkDistinctFiles({{"--output", "sub/../out-3.png"}}, {{"SCENE's file", "out-3.png"}}),
        InputError);
  });
}

TEST(OutputsBesideInputs, ALinkLeadsToTheFolderItNames) {
  const std::string dir = test::outputDir("OutputsBesideInputs.Links");
  fs::create_directories(dir + "/real");
  std::ofstream(dir + "/real/out-0.png") << "texture";
  std::error_code ec;
  fs::remove(dir + "/alias", ec);
  fs::create_directory_symlink("real", dir + "/alias");
  // Output folder through the link, input by its real name, and the reverse.
  EXPECT_THROW(checkFolderOutputs(dir + "/alias", pageKind, "--save-frames",
                                  {{"SCENE's file", dir + "/real/out-0.png"}}),
               InputError);
  EXPECT_THROW(checkFolderOutputs(dir + "/real", pageKind, "--save-frames",
                                  {{"SCENE's file", dir + "/alias/out-0.png"}}),
               InputError);
  // A missing input (named by the scene, not there yet) is protected too.
  EXPECT_THROW(checkFolderOutputs(dir + "/alias", pageKind, "--output",
                                  {{"SCENE's file", dir + "/real/out-9.png"}}),
               InputError);
}

// The check before the work compares names; an output folder replaced
// during the work by a link to the inputs' folder (H16-6-1) is caught at the
// write, for a file alone and for a set at its commit, the input untouched.
// Once the call's InputsWatch ends, its inputs are files like any other.
TEST(OutputsBesideInputs, AnOutputFolderSwappedForTheInputsFolderIsNotWrittenThrough) {
  const std::string dir = test::outputDir("OutputsBesideInputs.Swapped");
  fs::create_directories(dir + "/in");
  fs::create_directories(dir + "/out");
  const std::string input = dir + "/in/scene.gltf";
  std::ofstream(input) << "the scene";
  auto content = [&] {
    std::ifstream in(input);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  auto swap = [&] {
    fs::remove_all(dir + "/out");
    fs::create_directory_symlink("in", dir + "/out");
  };
  {
    const InputsWatch call;
    checkDistinctFiles({{"--output", dir + "/out/scene.gltf"}}, {{"SCENE", input}});
    swap();
    try {
      writeTextAtomically(dir + "/out/scene.gltf", "output");
      ADD_FAILURE() << "written through the swapped folder";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("will not write: it is now the input SCENE"),
                std::string::npos)
          << e.what();
    }
    EXPECT_EQ(content(), "the scene");

    // A set whose file was written before the swap: its commit refuses.
    fs::remove(dir + "/out");
    fs::create_directories(dir + "/out");
    AtomicFileSet set;
    set.addText(dir + "/out/scene.gltf", "output");
    swap();
    EXPECT_THROW(set.commit(), IoError);
    EXPECT_EQ(content(), "the scene");
    EXPECT_TRUE(leftoverTemporaries(input).empty());
  }
  // The watch ended: the same write is the user's to make.
  writeTextAtomically(dir + "/out/scene.gltf", "output");
  EXPECT_EQ(content(), "output");
}

TEST(OutputsBesideInputs, APathWithANulByteIsNeitherReadNorWritten) {
  const std::string dir = test::outputDir("OutputsBesideInputs.Nul");
  const std::string real = dir + "/grid.vdb";
  fs::remove(real);
  const std::string cut = real + std::string(1, '\0') + ".png";
  ASSERT_EQ(cut.size(), real.size() + 5);
  test::expectRefusal([&] { checkPathText(cut, "path"); },
                      {"path: the path '", "grid.vdb\\0.png' holds a NUL byte"});
  EXPECT_NO_THROW(checkPathText(real, "path"));
  EXPECT_THROW(checkOutputFolder(cut, "--output"), InputError);
  EXPECT_THROW(writeTextAtomically(cut, "bytes"), InputError);
  EXPECT_FALSE(fs::exists(real)) << "the write went to the path cut at its NUL";
  EXPECT_TRUE(leftoverTemporaries(real).empty());
  std::ofstream(real) << "bytes";
  EXPECT_THROW(readFile(cut), InputError);
  EXPECT_THROW(requireRegularFile(cut, "the grid"), InputError);
  EXPECT_EQ(readFile(real), "bytes");
}

}  // namespace
}  // namespace lo
