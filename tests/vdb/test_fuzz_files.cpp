// Fuzzing the readers with damaged files, deterministically (seeded), in CI:
// every mutation of a real .vdb bake and of the bundled glTF scene must load
// or be refused with an InputError naming the file, never crash, hang or
// throw anything else (docs/robustness.md). The .vdb readers run each file
// through their child-process trial read (core/isolate.h) first.

#include <gtest/gtest.h>
#include <sys/inotify.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <vector>
#include <fstream>
#include <iterator>
#include <string>

#include "core/error.h"
#include "core/rng.h"
#include "scene/scene.h"
#include "test_util.h"
#include "core/file.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

void writeBytes(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), std::streamsize(bytes.size()));
}

/// One damage of `bytes`, chosen by `rng`: a flipped bit, a run of random
/// bytes, a run of 0xff (the sizes and counts a reader trusts, made huge), a
/// truncation, or a copied block (structure repeated out of place).
std::string mutate(const std::string& bytes, Rng& rng) {
  std::string out = bytes;
  const size_t n = out.size();
  const uint32_t kind = rng.uniformInt(5);
  const size_t at = size_t(rng.uniformInt(uint32_t(n)));
  switch (kind) {
    case 0:
      out[at] = char(out[at] ^ char(1u << rng.uniformInt(8)));
      break;
    case 1:
      for (size_t i = at; i < std::min(n, at + 1 + rng.uniformInt(8)); ++i) {
        out[i] = char(rng.uniformInt(256));
      }
      break;
    case 2:
      for (size_t i = at; i < std::min(n, at + 4 + rng.uniformInt(5)); ++i) out[i] = char(0xff);
      break;
    case 3:
      out.resize(at);
      break;
    default: {
      const size_t from = size_t(rng.uniformInt(uint32_t(n)));
      const size_t len = std::min({size_t(1 + rng.uniformInt(64)), n - from, n - at});
      out.replace(at, len, bytes.substr(from, len));
    }
  }
  return out;
}

struct Tally {
  int loaded = 0, refused = 0;
  int bounded = 0;  ///< refused by the child read's limits (core/isolate.h)
};

/// Runs `load` on `path`: loaded or an InputError naming the file; anything
/// else fails the test.
template <class Load>
void expectLoadsOrRefuses(const std::string& path, Load load, Tally& tally, const std::string& what) {
  try {
    load(path);
    ++tally.loaded;
  } catch (const InputError& e) {
    ++tally.refused;
    if (std::string(e.what()).find("damaged or not an OpenVDB file: reading it") != std::string::npos) {
      ++tally.bounded;
    }
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << what << ": " << e.what();
    EXPECT_LT(std::string(e.what()).size(), 3000u) << what << ": a message of "
                                                    << std::string(e.what()).size() << " bytes";
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": " << typeid(e).name() << ": " << e.what();
  }
}

TEST(Fuzz, DamagedVdbFilesAreReadOrRefusedCleanly) {
  const std::string dir = test::outputDir("Fuzz.Vdb");
  const std::string original = readFile(test::dataDir() + "/../tests/golden/cornell-box-d4.vdb");
  ASSERT_GT(original.size(), 1000u);
  Rng rng(2026, 12);
  Tally reader, inspector;
  constexpr int kMutations = 120;
  for (int i = 0; i < kMutations; ++i) {
    const std::string path = dir + "/m" + std::to_string(i) + ".vdb";
    writeBytes(path, mutate(original, rng));
    expectLoadsOrRefuses(path, [](const std::string& p) { readVdlGrid(p); }, reader,
                         "readVdlGrid, mutation " + std::to_string(i));
    expectLoadsOrRefuses(path, [](const std::string& p) { inspectVdb(p); }, inspector,
                         "inspectVdb, mutation " + std::to_string(i));
  }
  std::printf(".vdb mutations: reader %d loaded / %d refused (%d by the child read's limits: "
              "memory, time or a crash); inspect %d read / %d refused\n",
              reader.loaded, reader.refused, reader.bounded, inspector.loaded, inspector.refused);
  EXPECT_GT(reader.refused, kMutations / 4);  // the damage was real
  // Some of these files make OpenVDB allocate gigabytes or corrupt its heap:
  // the child read refused them instead of the process going down.
  EXPECT_GT(reader.bounded, 0);
}

TEST(Fuzz, DamagedGltfScenesAreLoadedOrRefusedCleanly) {
  const std::string dir = test::outputDir("Fuzz.Gltf");
  const std::string original = readFile(test::dataDir() + "/cornell-box.gltf");
  ASSERT_GT(original.size(), 1000u);
  Rng rng(2026, 13);
  Tally tally;
  constexpr int kMutations = 300;
  for (int i = 0; i < kMutations; ++i) {
    const std::string path = dir + "/m" + std::to_string(i) + ".gltf";
    writeBytes(path, mutate(original, rng));
    expectLoadsOrRefuses(path, [](const std::string& p) { loadScene(p); }, tally,
                         "loadScene, mutation " + std::to_string(i));
  }
  std::printf(".gltf mutations: %d loaded / %d refused\n", tally.loaded, tally.refused);
  EXPECT_GT(tally.refused, kMutations / 4);
}

// The parent process never reads an untrusted .vdb's own bytes: the child
// that reads it under limits hands the grids back through memory (written
// anew by OpenVDB's writer), so the file is opened by the child alone. An
// inotify watch counts the opens of the file, whichever process makes them.
TEST(Fuzz, OnlyTheChildReadsTheFileItself) {
  const std::string golden = test::dataDir() + "/../tests/golden/cornell-box-d4.vdb";
  const std::string path = test::outputDir("Fuzz.ChildReads") + "/grid.vdb";
  writeBytes(path, readFile(golden));
  const int watch = inotify_init1(IN_NONBLOCK | IN_CLOEXEC);
  ASSERT_GE(watch, 0);
  ASSERT_GE(inotify_add_watch(watch, path.c_str(), IN_OPEN), 0);
  const LoadedVdl loaded = readVdlGrid(path);
  int opens = 0;
  alignas(inotify_event) char buffer[4096];
  for (ssize_t n; (n = ::read(watch, buffer, sizeof buffer)) > 0;) {
    for (char* p = buffer; p < buffer + n;) {
      const auto* event = reinterpret_cast<const inotify_event*>(p);
      if (event->mask & IN_OPEN) ++opens;
      p += sizeof(inotify_event) + event->len;
    }
  }
  ::close(watch);
  EXPECT_EQ(opens, 1) << "opened by the child and by the parent";
  // The grids handed back are the file's: the same as a direct read.
  EXPECT_GT(loaded.grid.size(), 0u);
  EXPECT_EQ(loaded.grid.size(), readVdlGrid(golden).grid.size());
  EXPECT_EQ(loaded.grid.irradiance, readVdlGrid(golden).grid.irradiance);
}

// The libFuzzer targets' seed corpus (tests/fuzz/seeds/: minimal scenes and
// the reproducers of the hardening issues) as ordinary tests: each loads or
// is refused cleanly, and the reproducers are refused.
TEST(Fuzz, SeedsAreLoadedOrRefusedCleanly) {
  namespace fs = std::filesystem;
  const fs::path seeds = fs::path(test::dataDir()) / ".." / "tests" / "fuzz" / "seeds";
  Tally tally;
  std::vector<std::string> refused;
  for (const char* kind : {"gltf", "obj"}) {
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(seeds / kind)) {
      if (e.path().extension() != ".mtl") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    ASSERT_GE(files.size(), 2u) << kind;
    for (const fs::path& f : files) {
      const int before = tally.refused;
      expectLoadsOrRefuses(f.string(), [](const std::string& p) { loadScene(p); }, tally, f.string());
      if (tally.refused > before) refused.push_back(f.filename().string());
    }
  }
  std::string list;
  for (const std::string& r : refused) list += r + " ";
  std::printf("seeds: %d loaded, %d refused (%s)\n", tally.loaded, tally.refused, list.c_str());
  for (const char* reproducer : {"deep-extras.gltf", "index-beyond-int32.gltf",
                                 "huge-translation.gltf", "sparse-implicit-zeros.gltf",
                                 "no-bufferview-no-sparse.gltf",
                                 "index-out-of-range.obj"}) {
    EXPECT_NE(std::find(refused.begin(), refused.end(), reproducer), refused.end()) << reproducer;
  }
  for (const char* good : {"triangle.gltf", "triangle.glb", "quad.obj"}) {
    EXPECT_EQ(std::find(refused.begin(), refused.end(), good), refused.end()) << good;
  }
}

}  // namespace
}  // namespace lo
