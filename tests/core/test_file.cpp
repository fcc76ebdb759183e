// Output files (core/file.h): a fresh, exclusively created temporary name for
// every write, nothing written through links or over what is not a regular
// file, no temporary left after a failure or a SIGINT, and commands that
// refuse an output that is one of their inputs.

#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <string>

#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

TEST(OutputFiles, TemporaryNamesAreFreshHiddenAndBesideTheTarget) {
  const std::string dir = test::outputDir("OutputFiles.Names");
  std::set<std::string> names;
  for (int i = 0; i < 100; ++i) {
    const std::string t = temporaryPathFor(dir + "/out.vdb");
    EXPECT_TRUE(names.insert(t).second) << t;
    EXPECT_EQ(fs::path(t).parent_path(), fs::path(dir));
    EXPECT_EQ(fs::path(t).filename().string().rfind(".out.vdb.", 0), 0u) << t;
    EXPECT_TRUE(isTemporaryPathFor(t, dir + "/out.vdb"));
  }
  EXPECT_FALSE(isTemporaryPathFor(dir + "/out.vdb.tmp", dir + "/out.vdb"));
}

TEST(OutputFiles, EveryNameTheFileSystemTakesHasATemporaryName) {
  // Names of 200-255 bytes are legal (NAME_MAX); their temporary names are
  // cut and end in a hash, so the write works and nothing is left behind.
  const std::string dir = test::outputDir("OutputFiles.LongNames");
  for (size_t length : {200u, 227u, 250u, 255u}) {
    const std::string path = dir + "/" + std::string(length - 4, 'n') + ".vdb";
    const std::string t = temporaryPathFor(path);
    EXPECT_LE(fs::path(t).filename().string().size(), 255u) << length;
    EXPECT_TRUE(isTemporaryPathFor(t, path)) << length;
    writeTextAtomically(path, "x");
    EXPECT_EQ(readFile(path), "x") << length;
    EXPECT_TRUE(leftoverTemporaries(path).empty()) << length;
    checkOutputName(path, "--output");
  }
  // Two long names that share their first 230 bytes keep distinct temporaries.
  const std::string a = dir + "/" + std::string(240, 'm') + "a", b = dir + "/" + std::string(240, 'm') + "b";
  EXPECT_FALSE(isTemporaryPathFor(temporaryPathFor(a), b));
  // One byte past the limit is refused before any work, naming the flag.
  try {
    checkOutputFolder(dir + "/" + std::string(256, 'n'), "--output");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--output: the file name"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("256 bytes"), std::string::npos) << e.what();
  }
}

TEST(OutputFiles, ReplacesARegularFileAndLeavesNothingBehind) {
  const std::string dir = test::outputDir("OutputFiles.Replace");
  const std::string path = dir + "/a.txt";
  writeTextAtomically(path, "old");
  writeTextAtomically(path, "new");
  EXPECT_EQ(readFile(path), "new");
  EXPECT_TRUE(leftoverTemporaries(path).empty());
  // A failing writer: the target keeps its old bytes, no temporary remains.
  EXPECT_THROW(writeAtomically(path, [](const std::string&) { throw std::runtime_error("boom"); }),
               IoError);
  EXPECT_EQ(readFile(path), "new");
  EXPECT_TRUE(leftoverTemporaries(path).empty());
}

TEST(OutputFiles, NeverWritesThroughALinkOrOverWhatIsNotARegularFile) {
  const std::string dir = test::outputDir("OutputFiles.Links");
  const std::string victim = dir + "/victim.txt", link = dir + "/link.txt";
  writeTextAtomically(victim, "precious");
  fs::remove(link);
  fs::create_symlink(victim, link);
  try {
    writeTextAtomically(link, "overwritten");
    FAIL() << "expected an IoError";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("symbolic link"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readFile(victim), "precious");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_THROW(checkOutputFolder(link, "--output"), InputError);
  const std::string folder = dir + "/a-folder";
  fs::create_directories(folder);
  EXPECT_THROW(writeTextAtomically(folder, "x"), IoError);
  EXPECT_TRUE(fs::is_directory(folder));
  EXPECT_THROW(checkOutputFolder("/dev/null", "--output"), InputError);
  EXPECT_THROW(checkOutputFolder(dir + "/no-such-folder/x.vdb", "--output"), InputError);
  EXPECT_TRUE(leftoverTemporaries(link).empty());
  // A folder that is a loop of links (a -> b -> a): refused naming the flag
  // and the folder, not in std::filesystem's words (eighth hostile list F6-21).
  fs::remove(dir + "/a");
  fs::remove(dir + "/b");
  fs::create_symlink("b", dir + "/a");
  fs::create_symlink("a", dir + "/b");
  test::expectRefusal([&] { checkOutputFolder(dir + "/a/o.vdb", "--output"); },
                      {"--output: folder '" + dir + "/a' cannot be reached", "a loop of links"});
}

// An output in /proc or /sys (which take no new file whatever their
// permission bits say, and root passes access()), or relative to a working
// folder deleted before the run, was found only when written, after the
// work: checkOutputFolder finds both, naming the flag, and leaves nothing.
TEST(OutputFiles, AFolderThatTakesNoFileOrADeletedWorkingFolderIsFoundFirst) {
  const std::string dir = test::outputDir("OutputFiles.NoNewFile");
  auto refusal = [](const std::string& path) -> std::string {
    try {
      checkOutputFolder(path, "--output");
    } catch (const InputError& e) {
      return e.what();
    }
    return "taken";
  };
  for (const char* folder : {"/proc", "/sys"}) {
    if (!fs::is_directory(folder)) continue;
    const std::string why = refusal(std::string(folder) + "/lightoctree-test.png");
    EXPECT_EQ(why.rfind(std::string("--output: folder '") + folder + "' ", 0), 0u) << why;
    EXPECT_TRUE(why.find("takes no new file") != std::string::npos ||
                why.find("is not writable") != std::string::npos)
        << why;
  }
  EXPECT_EQ(refusal(dir + "/fine.vdb"), "taken");
  EXPECT_TRUE(leftoverTemporaries(dir + "/fine.vdb").empty());
  // A working folder deleted under the process.
  const fs::path before = fs::current_path();
  const fs::path gone = fs::path(dir) / "gone";
  fs::create_directories(gone);
  fs::current_path(gone);
  fs::remove(gone);
  const std::string relative = refusal("out.vdb");
  const std::string absolute = refusal(dir + "/fine.vdb");
  fs::current_path(before);
  EXPECT_EQ(relative,
            "--output: 'out.vdb' is relative to the working folder, which was deleted: run from "
            "a folder that exists, or give an absolute path");
  EXPECT_EQ(absolute, "taken");
}

// A set of output files appears whole or not at all: a failure at its last
// file (a link planted at its name) leaves an earlier run's files as they
// were and no temporary; a committed set replaces them all.
TEST(OutputFiles, ASetAppearsWholeOrNotAtAll) {
  const std::string dir = test::outputDir("OutputFiles.Set");
  const std::string a = dir + "/a.gltf", b = dir + "/a.bin", c = dir + "/a-preview.glb";
  for (const std::string& f : {a, b, c}) std::filesystem::remove(f);
  writeTextAtomically(a, "old a");
  writeTextAtomically(b, "old b");
  std::filesystem::create_symlink(dir + "/elsewhere.txt", c);
  {
    AtomicFileSet set;
    set.addText(a, "new a");
    set.addText(b, "new b");
    EXPECT_THROW(set.addText(c, "new c"), IoError);
  }
  EXPECT_EQ(readFile(a), "old a");
  EXPECT_EQ(readFile(b), "old b");
  EXPECT_FALSE(std::filesystem::exists(dir + "/elsewhere.txt")) << "nothing through the link";
  for (const std::string& f : {a, b, c}) EXPECT_TRUE(leftoverTemporaries(f).empty()) << f;
  // Destroyed uncommitted: nothing changes either.
  {
    AtomicFileSet set;
    set.addText(a, "new a");
    EXPECT_THROW(set.addText(a, "twice"), IoError);
  }
  EXPECT_EQ(readFile(a), "old a");
  std::filesystem::remove(c);
  {
    AtomicFileSet set;
    set.addText(a, "new a");
    set.addText(b, "new b");
    set.add(c, [](const std::string& tmp) { std::ofstream(tmp) << "new c"; });
    EXPECT_EQ(readFile(a), "old a") << "nothing renamed before commit";
    // A link planted at a name after its write: commit refuses, renames nothing.
    std::filesystem::create_symlink(dir + "/elsewhere.txt", c);
    EXPECT_THROW(set.commit(), IoError);
    EXPECT_EQ(readFile(a), "old a");
    std::filesystem::remove(c);
    set.commit();
    EXPECT_EQ(set.paths(), (std::vector<std::string>{a, b, c}));
    EXPECT_EQ(set.bytesOf(b), 5u);
    EXPECT_EQ(set.bytesOf(dir + "/absent.txt"), 0u);
  }
  EXPECT_EQ(readFile(a), "new a");
  EXPECT_EQ(readFile(b), "new b");
  EXPECT_EQ(readFile(c), "new c");
  for (const std::string& f : {a, b, c}) EXPECT_TRUE(leftoverTemporaries(f).empty()) << f;
}

TEST(OutputFiles, AnOutputThatIsAnInputIsRefused) {
  const std::string dir = test::outputDir("OutputFiles.Inputs");
  writeTextAtomically(dir + "/scene.gltf", "{}");
  try {
    checkDistinctFiles({{"--output", dir + "/./scene.gltf"}}, {{"SCENE", dir + "/scene.gltf"}});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("--output"), std::string::npos) << msg;
    EXPECT_NE(msg.find("the input SCENE"), std::string::npos) << msg;
  }
  try {
    checkDistinctFiles({{"--output", dir + "/o.vdb"}, {"--stats-json", dir + "/o.vdb"}}, {});
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--output and --stats-json"), std::string::npos)
        << e.what();
  }
  EXPECT_NO_THROW(checkDistinctFiles({{"--output", dir + "/o.vdb"}, {"--stats-json", ""}},
                                     {{"SCENE", dir + "/scene.gltf"}}));
}

// SIGINT while a temporary file is being written: the process ends by the
// signal, the temporary file is gone and the target is untouched.
TEST(OutputFiles, SigintRemovesTheTemporaryFile) {
  const std::string dir = test::outputDir("OutputFiles.Sigint");
  const std::string path = dir + "/interrupted.txt";
  writeTextAtomically(path, "before");
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    writeAtomically(path, [](const std::string& tmp) {
      std::ofstream(tmp) << "half";
      ::raise(SIGINT);
    });
    ::_exit(0);  // not reached: SIGINT ends the child
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGINT) << status;
  EXPECT_EQ(readFile(path), "before");
  EXPECT_TRUE(leftoverTemporaries(path).empty());
}

}  // namespace
}  // namespace lo
