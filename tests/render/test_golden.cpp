// Golden images of the bundled Cornell box under OSMesa: the committed bake
// tests/golden/cornell-box-d4.vdb rendered at 128x128 from the scene camera in
// modes full, indirect and direct, compared with tests/golden/cornell-box-<mode>.png.
//
// Compared in the PNGs' own 8-bit sRGB values (what a person sees): a pixel
// fails when a channel differs by more than kPixelTolerance; the test fails
// when more than kMaxFailingFraction of the pixels fail or any pixel differs
// by more than kMaxAbsDiff. On failure the rendered image, the reference and
// an amplified difference are written to the test's output folder and their
// paths printed.
//
// Regenerate the references (after an intended change of the renderer, and
// look at them):  LO_UPDATE_GOLDEN=1 build/tests/lightoctree_tests --gtest_filter='Golden*'
// Regenerate the bake itself (after a change of the VDL file format):
//   lightoctree bake data/cornell-box.gltf -o tests/golden/cornell-box-d4.vdb --depth 4
//     --photons 50000 --knn 50 --seed 1

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "image/image.h"
#include "octree/gpu_octree.h"
#include "render/context.h"
#include "render/renderer.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

constexpr int kSize = 128;
constexpr float kPixelTolerance = 8.0f / 255.0f;  // per channel, 8-bit sRGB
constexpr double kMaxFailingFraction = 0.005;     // 82 of 16384 pixels
constexpr float kMaxAbsDiff = 64.0f / 255.0f;     // no pixel may be grossly wrong

std::string goldenDir() { return test::dataDir() + "/../tests/golden"; }

bool updating() {
  const char* v = std::getenv("LO_UPDATE_GOLDEN");
  return v && std::string(v) == "1";
}

struct GoldenScene {
  Scene scene;
  GpuOctree octree;
  PinholeCamera camera;
  GoldenScene() {
    scene = loadScene(test::dataDir() + "/cornell-box.gltf");
    LoadedVdl baked = readVdlGrid(goldenDir() + "/cornell-box-d4.vdb");
    octree = buildGpuOctree(baked.grid, test::paperCosine());
    camera = PinholeCamera::fromScene(scene.cameras.at(0));
  }
  /// The same scene, octree and camera moved by `offset`, in float as a file
  /// placing the scene there holds them (vertices round to the float grid
  /// at that distance: 2^-7 units at 1e5).
  GoldenScene translated(const Vec3& offset) const {
    GoldenScene t = *this;
    t.scene = scene.translated(offset);
    t.octree.origin = octree.origin + offset;
    t.camera.eye = camera.eye + offset;
    return t;
  }
};

const GoldenScene& setup() {
  static const GoldenScene s;
  return s;
}

/// Exposure per mode so that every reference uses the 8-bit range.
float exposureOf(RenderMode mode) { return mode == RenderMode::Indirect ? 1.0f : 0.0f; }

/// The rendered frame as the PNG would store it: 8-bit sRGB, read back as v/255.
RgbImage asPng(const RgbImage& image, float exposure, const std::string& path) {
  writeImage(path, image, exposure);
  return readImage(path, true);
}

struct Mismatch {
  float maxAbsDiff = 0;
  double failingFraction = 0;
  bool failed() const { return failingFraction > kMaxFailingFraction || maxAbsDiff > kMaxAbsDiff; }
};

Mismatch compare(const RgbImage& a, const RgbImage& b, RgbImage* diff) {
  Mismatch m;
  size_t failing = 0;
  if (diff) *diff = RgbImage(a.width, a.height);
  for (size_t i = 0; i < a.pixelCount(); ++i) {
    float worst = 0;
    for (int k = 0; k < 3; ++k) {
      const float d = std::fabs(a.rgb[3 * i + k] - b.rgb[3 * i + k]);
      worst = std::max(worst, d);
      if (diff) diff->rgb[3 * i + k] = std::min(1.0f, 8.0f * d);  // amplified to be seen
    }
    m.maxAbsDiff = std::max(m.maxAbsDiff, worst);
    failing += worst > kPixelTolerance;
  }
  m.failingFraction = double(failing) / double(std::max<size_t>(a.pixelCount(), 1));
  return m;
}

/// Renders `mode`; compares with (or, when updating, writes) the golden PNG.
Mismatch renderAndCompare(const GoldenScene& s, RenderMode mode, bool interpolation,
                          const std::string& reference, const std::string& name) {
  Renderer renderer(s.scene, s.octree);
  RenderParams p;
  p.width = p.height = kSize;
  p.mode = mode;
  p.interpolation = interpolation;
  RgbImage frame = renderer.render(s.camera, p);
  const std::string dir = test::outputDir(name);
  const std::string rendered = dir + "/rendered.png";
  RgbImage got = asPng(frame, exposureOf(mode), rendered);
  if (updating()) {
    writeImage(reference, frame, exposureOf(mode));
    std::printf("wrote %s\n", reference.c_str());
    return {};
  }
  RgbImage expected = readImage(reference, true);
  EXPECT_EQ(got.width, expected.width);
  EXPECT_EQ(got.height, expected.height);
  if (got.width != expected.width || got.height != expected.height) return {1.0f, 1.0};
  RgbImage diff;
  Mismatch m = compare(got, expected, &diff);
  if (m.failed()) {
    std::filesystem::copy_file(reference, dir + "/reference.png",
                               std::filesystem::copy_options::overwrite_existing);
    writePng(dir + "/difference.png", diff);
    std::printf(
        "[ golden %s ] rendered %s\n[ golden %s ] reference %s\n[ golden %s ] difference "
        "(x8) %s\n",
        name.c_str(), rendered.c_str(), name.c_str(), (dir + "/reference.png").c_str(),
        name.c_str(), (dir + "/difference.png").c_str());
  }
  return m;
}

void checkGolden(RenderMode mode) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const std::string name = "golden_cornell_" + toString(mode);
  const std::string reference = goldenDir() + "/cornell-box-" + toString(mode) + ".png";
  Mismatch m = renderAndCompare(setup(), mode, true, reference, name);
  if (updating()) return;
  EXPECT_LE(m.failingFraction, kMaxFailingFraction)
      << name << ": fraction of pixels off by more than 8/255 (max abs diff " << m.maxAbsDiff
      << ")";
  EXPECT_LE(m.maxAbsDiff, kMaxAbsDiff) << name;
}

TEST(Golden, CornellBoxFull) { checkGolden(RenderMode::Full); }
TEST(Golden, CornellBoxIndirect) { checkGolden(RenderMode::Indirect); }
TEST(Golden, CornellBoxDirect) { checkGolden(RenderMode::Direct); }

// The tolerances must catch a real change: the indirect image without
// interpolation (blocky voxels) must fail against the interpolated reference.
TEST(Golden, ToleranceDetectsInterpolationOff) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  if (updating()) GTEST_SKIP() << "updating the references";
  Mismatch m =
      renderAndCompare(setup(), RenderMode::Indirect, false,
                       goldenDir() + "/cornell-box-indirect.png",
                       "golden_cornell_indirect_nearest");
  EXPECT_TRUE(m.failed()) << "failing fraction " << m.failingFraction << ", max abs diff "
                          << m.maxAbsDiff;
}

// Anywhere in space: the renderer works in render space (world minus the
// scene's centre, in double), so the Cornell box placed far from the origin
// draws the picture it draws at the origin. The moved scene holds its vertices
// in float, rounded to the float grid at that distance (2^-7 units at 1e5),
// so the picture at the origin is of that same rounded scene moved back
// (exactly: the differences are representable): only the renderer's
// precision is under test, with the golden tolerances.
TEST(Golden, CornellBoxFarFromTheOriginIsTheSamePicture) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  if (updating()) GTEST_SKIP() << "updating the references";
  for (const Vec3& offset : {Vec3(1e4f, -1e4f, 1e4f), Vec3(1e5f, 1e5f, -1e5f)}) {
    const auto far = setup().translated(offset);
    const auto near = far.translated(-offset);
    for (RenderMode mode : {RenderMode::Full, RenderMode::Indirect}) {
      const std::string name = "golden_cornell_far_" + std::to_string(int(offset.x)) + "_" +
                               toString(mode);
      const std::string dir = test::outputDir(name);
      RenderParams p;
      p.width = p.height = kSize;
      p.mode = mode;
      Renderer atOrigin(near.scene, near.octree), moved(far.scene, far.octree);
      const RgbImage expected =
          asPng(atOrigin.render(near.camera, p), exposureOf(mode), dir + "/at-origin.png");
      const RgbImage got = asPng(moved.render(far.camera, p), exposureOf(mode), dir + "/far.png");
      RgbImage diff;
      const Mismatch m = compare(got, expected, &diff);
      if (m.failed()) writePng(dir + "/difference.png", diff);
      EXPECT_LE(m.failingFraction, kMaxFailingFraction)
          << name << " (max abs diff " << m.maxAbsDiff << "); images in " << dir;
      EXPECT_LE(m.maxAbsDiff, kMaxAbsDiff) << name << "; images in " << dir;
    }
  }
}

/// data/cornell-box.gltf with its nodes under one node at `t` (glTF JSON
/// numbers: exact in double), as a scene in projected coordinates holds them.
std::string cornellBoxUnderNode(const std::string& t, const std::string& path) {
  std::ifstream in(test::dataDir() + "/cornell-box.gltf");
  std::stringstream text;
  text << in.rdbuf();
  std::string g = text.str();
  const size_t scenes = g.find("\"scenes\"");
  const size_t list = g.find('[', g.find("\"nodes\"", scenes));
  g.replace(list, g.find(']', list) - list + 1, "[0]");
  const std::string top = "\n \"nodes\": [";
  std::string root = "\n  {\"name\": \"projected\", \"translation\": [" + t + "], \"children\": [";
  for (int i = 1; i <= 9; ++i) root += std::to_string(i) + (i < 9 ? ", " : "]},");
  g.insert(g.find(top) + top.size(), root);
  std::ofstream(path) << g;
  return path;
}

// A scene in projected coordinates, millions of metres from the origin
// (float spacing 0.25-0.5 m there): the loader keeps it relative to its
// centre in double (Scene::origin), the light grid is read in the same
// coordinates, the bake writes its frame there, and the picture is the one
// at the origin.
TEST(Golden, CornellBoxInProjectedCoordinatesIsTheSamePicture) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  if (updating()) GTEST_SKIP() << "updating the references";
  const std::string dir = test::outputDir("golden_cornell_projected");
  GoldenScene far = setup();
  far.scene = loadScene(cornellBoxUnderNode("2500000.5, 300, -5400000.25", dir + "/far.gltf"));
  ASSERT_TRUE(far.scene.rebased());
  // The golden bake (of the box at the origin), read relative to where the
  // far scene keeps its own centre: the box's centre at the origin.
  const Vec3d centre = far.scene.origin - Vec3d(2500000.5, 300, -5400000.25);
  far.octree = buildGpuOctree(readVdlGrid(goldenDir() + "/cornell-box-d4.vdb", centre).grid,
                              test::paperCosine());
  far.camera = PinholeCamera::fromScene(far.scene.cameras.at(0));
  for (RenderMode mode : {RenderMode::Full, RenderMode::Indirect}) {
    RenderParams p;
    p.width = p.height = kSize;
    p.mode = mode;
    Renderer atOrigin(setup().scene, setup().octree), moved(far.scene, far.octree);
    const std::string name = toString(mode);
    const RgbImage expected = asPng(atOrigin.render(setup().camera, p), exposureOf(mode),
                                    dir + "/at-origin-" + name + ".png");
    const RgbImage got =
        asPng(moved.render(far.camera, p), exposureOf(mode), dir + "/far-" + name + ".png");
    RgbImage diff;
    const Mismatch m = compare(got, expected, &diff);
    if (m.failed()) writePng(dir + "/difference-" + name + ".png", diff);
    EXPECT_LE(m.failingFraction, kMaxFailingFraction)
        << name << " (max abs diff " << m.maxAbsDiff << "); images in " << dir;
    EXPECT_LE(m.maxAbsDiff, kMaxAbsDiff) << name << "; images in " << dir;
  }
  // A bake of the far scene stores its frame in the scene's coordinates.
  BakeParams params = test::smallBake(3, 2000);
  const BakeResult baked = bake(far.scene, params);
  EXPECT_EQ(baked.grid.frame.offset.x, far.scene.origin.x);
  EXPECT_EQ(baked.grid.frame.offset.z, far.scene.origin.z);
  EXPECT_LT(std::fabs(baked.grid.frame.origin.x), 1.0f);
}

}  // namespace
}  // namespace lo
