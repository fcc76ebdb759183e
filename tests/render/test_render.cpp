// Renderer tests under OSMesa (software GL, no display): shaders compile, the
// C++ and GLSL builds of the octree layout agree, limits, image files, the
// supersampled image. The images by feature are in test_render_*.cpp.

#include <gtest/gtest.h>
#include <octree_layout.h>
#include <sys/resource.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/file.h"
#include "core/resources.h"
#include "image/compare.h"
#include "image/image.h"
#include "render/context.h"
#include "render/layout_probe.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

using RenderLayout = test::GlTest;
using RenderLimits = test::GlTest;
using RenderImage = test::GlTest;
using test::QuadSetup;

TEST(Render, EveryShaderCompilesAndLinks) {
  REQUIRE_OSMESA();
  EXPECT_NO_THROW(compileAllShaders());
}

TEST(Render, ContextReportsTextureLimits) {
  REQUIRE_OSMESA();
  const GlInfo& info = test::osmesaContext()->info();
  EXPECT_GE(info.major * 10 + info.minor, 33) << info.ToString();
  EXPECT_GE(info.max3DTextureSize, 256) << info.ToString();
  EXPECT_GE(info.max2DTextureSize, 4096) << info.ToString();
}

// Under an address-space limit (ulimit -v) libOSMesa cannot be mapped: the
// message advised installing libosmesa6, which was installed. It says memory
// and names the limit, and a context is made once the limit is lifted (the
// failure is not kept). Not under AddressSanitizer, whose shadow memory is
// terabytes of address space already mapped.
TEST(Render, ContextUnderAnAddressSpaceLimitSaysMemory) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer";
#endif
  // 1 MiB more than is mapped now.
  const std::optional<std::string> limited =
      test::messageUnderAddressSpaceLimit(size_t(1) << 20, [] { createGlContext(); });
  if (!limited) GTEST_SKIP() << "the address space is limited already";
  const std::string& message = *limited;
  if (message.find("cannot open shared object file") != std::string::npos) {
    GTEST_SKIP() << "libOSMesa is not installed: " << message;
  }
  EXPECT_NE(message.find("osmesa: out of memory: "), std::string::npos) << message;
  EXPECT_NE(message.find("(ulimit -v)"), std::string::npos) << message;
  EXPECT_EQ(message.find("install"), std::string::npos) << message;
  EXPECT_NO_THROW(createGlContext()) << "the failure under the limit was kept";
  // Room for less than llvmpipe maps as it draws is refused before the
  // context (Mesa failed at random there: a segmentation fault, GL errors,
  // H15-2-1); room for it makes one, and draws.
  const std::optional<std::string> short_ =
      test::messageUnderAddressSpaceLimit(size_t(500) << 20, [] { createGlContext(); });
  ASSERT_TRUE(short_.has_value());
  EXPECT_NE(short_->find("osmesa: out of memory: the GL driver (llvmpipe, in software) maps about"),
            std::string::npos)
      << *short_;
  // The same before an EGL or a window's context (`view` crashed under such
  // limits, H16-2-1): the check comes before the driver is loaded.
  for (const GlBackend backend : {GlBackend::Egl, GlBackend::Glfw}) {
    GlContextParams params;
    params.backend = backend;
    const std::optional<std::string> other = test::messageUnderAddressSpaceLimit(
        size_t(500) << 20, [&params] { createGlContext(params); });
    ASSERT_TRUE(other.has_value());
    EXPECT_NE(other->find(toString(backend) + ": out of memory: the GL driver"), std::string::npos)
        << *other;
  }
  const std::optional<std::string> room =
      test::messageUnderAddressSpaceLimit(size_t(1) << 30, [] { createGlContext(); });
  ASSERT_TRUE(room.has_value());
  EXPECT_EQ(*room, "no error");
}

TEST(Render, BackendAndModeNamesRoundTrip) {
  for (const char* name : {"osmesa", "egl", "glfw"})
    EXPECT_EQ(toString(parseGlBackend(name)), name);
  for (const char* name : {"full", "direct", "indirect", "voxels"}) {
    EXPECT_EQ(toString(parseRenderMode(name)), name);
  }
  EXPECT_THROW(parseGlBackend("vulkan"), InputError);
  EXPECT_THROW(parseRenderMode("pretty"), InputError);
}

TEST_F(RenderLayout, GlslPackDirectionMatchesCpp) {
  namespace L = layout;
  std::vector<std::array<float, 4>> in;
  // Lattice directions pack back to their own code in any correct build, so
  // the two builds must agree exactly; plus the axes and a few off-lattice ones.
  for (uint32_t t = 0; t <= 255; t += 17) {
    for (uint32_t p = 0; p < 256; p += 29) {
      Vec3 d = test::latticeDirection(t, p);
      in.push_back({d.x, d.y, d.z, float(t * 256 + p)});
    }
  }
  for (Vec3 d : {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1),
                 Vec3(0, 0, -1), normalize(Vec3(0.3f, -0.5f, 0.8f))}) {
    in.push_back({d.x, d.y, d.z, 0.0f});
  }
  auto out = runLayoutProbe(LayoutProbe::PackDirection, in);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    SCOPED_TRACE("input " + std::to_string(i) + ": " +
                 Vec3(in[i][0], in[i][1], in[i][2]).ToString());
    EXPECT_EQ(out[i][0], L::loPackDirection(in[i][0], in[i][1], in[i][2]));
    EXPECT_EQ(out[i][1], L::loPackedTheta(in[i][3]));
    EXPECT_EQ(out[i][2], L::loPackedPhi(in[i][3]));
  }
}

TEST_F(RenderLayout, GlslUnpackDirectionMatchesCpp) {
  namespace L = layout;
  std::vector<std::array<float, 4>> in;
  for (uint32_t t = 0; t <= 255; t += 5) {
    for (uint32_t p = 0; p < 256; p += 7) in.push_back({float(t * 256 + p), 0, 0, 0});
  }
  auto out = runLayoutProbe(LayoutProbe::UnpackDirection, in);
  ASSERT_EQ(out.size(), in.size());
  // sin/cos are not correctly rounded in either build: the decoded directions
  // agree to a few ulps, and re-packing them gives the same code exactly.
  for (size_t i = 0; i < in.size(); ++i) {
    float packed = in[i][0];
    SCOPED_TRACE("packed " + std::to_string(int(packed)));
    EXPECT_NEAR(out[i][0], L::loUnpackDirectionX(packed), 2e-6f);
    EXPECT_NEAR(out[i][1], L::loUnpackDirectionY(packed), 2e-6f);
    EXPECT_NEAR(out[i][2], L::loUnpackDirectionZ(packed), 2e-6f);
    uint32_t code = uint32_t(packed);
    bool pole = code / 256 == 0 || code / 256 == 255;  // phi is arbitrary at the poles
    if (!pole) {
      EXPECT_EQ(out[i][3], packed);
    }
  }
}

TEST_F(RenderLayout, GlslAddressesMatchCpp) {
  namespace L = layout;
  std::vector<std::array<float, 4>> in;
  uint32_t x = 12345;
  for (int i = 0; i < 200; ++i) {
    x = x * 1664525u + 1013904223u;
    uint32_t address = i == 0 ? L::LO_MAX_ADDRESS : (i == 1 ? 0u : (x >> 8));
    in.push_back({float(L::loPackAddressR(address)), float(L::loPackAddressG(address)),
                  float(L::loPackAddressB(address)), float(address)});
  }
  auto out = runLayoutProbe(LayoutProbe::Address, in);
  ASSERT_EQ(out.size(), in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    uint32_t address = uint32_t(in[i][3]);
    SCOPED_TRACE("address " + std::to_string(address));
    EXPECT_EQ(out[i][0], float(L::loUnpackAddress(uint32_t(in[i][0]), uint32_t(in[i][1]),
                                                  uint32_t(in[i][2]))));
    EXPECT_EQ(out[i][0], float(address));
    EXPECT_EQ(out[i][1], float(L::loPackAddressR(address) + 256u * L::loPackAddressG(address)));
    EXPECT_EQ(out[i][2], float(L::loVdlTexelX(address)));
    EXPECT_EQ(out[i][3], float(L::loVdlTexelY(address)));
  }
}

TEST_F(RenderLimits, OctreeTooLargeForTheContextFailsNamingTheLimit) {
  QuadSetup s;
  const GpuOctree octree = test::constantOctree();
  // Each limit alone: the renderer refuses, naming it and its value.
  RendererParams tiny;
  tiny.max3DTextureSize = 4;  // the pool is 18 x 2 x 2 texels
  test::expectRefusal([&] { Renderer r(s.scene, octree, tiny); }, {"GL_MAX_3D_TEXTURE_SIZE = 4"});
  RendererParams tiny2D;
  tiny2D.max2DTextureSize = 16;  // 64 VDLs in one row
  test::expectRefusal([&] { Renderer r(s.scene, octree, tiny2D); }, {"GL_MAX_TEXTURE_SIZE = 16"});
}

TEST(RenderImageIo, WritesPngAndExrAtomicallyAndRejectsOtherExtensions) {
  RgbImage image(3, 2);
  image.rgb.assign(18, 0.5f);
  std::string dir = test::outputDir("render_image_io");
  writeImage(dir + "/a.png", image, 0.0f);
  writeImage(dir + "/a.exr", image);
  EXPECT_TRUE(std::filesystem::exists(dir + "/a.png"));
  EXPECT_TRUE(std::filesystem::exists(dir + "/a.exr"));
  EXPECT_TRUE(leftoverTemporaries(dir + "/a.png").empty());
  EXPECT_THROW(writeImage(dir + "/a.jpg", image), InputError);
  EXPECT_EQ(encodeSrgb8(0.0f), 0);
  EXPECT_EQ(encodeSrgb8(1.0f), 255);
  EXPECT_EQ(encodeSrgb8(0.5f), 188);  // 0.7354 * 255
}

// Supersampling: an image drawn with supersample s is the s x s box filter of
// the same image drawn s times larger (a brute-force cross-check), and it
// anti-aliases: a quad's edge crossing a pixel gives it a fractional value.
// The supersampling tests' view of the quad under a point light: 40 x 30,
// its right edge (x = 1) 0.1 right of the view's centre, at pixel 20 + 20
// (0.1 / (1.5 tan 20 deg 4/3)) = 22.747 from the left.
RenderParams edgeParams() {
  RenderParams p = QuadSetup::directParams();
  p.width = 40;
  p.height = 30;
  return p;
}
PinholeCamera edgeCamera() {
  return PinholeCamera::lookAt({0.9f, -0.05f, 1.5f}, {0.9f, -0.05f, 0.0f}, 40.0f * kPi / 180.0f);
}

TEST_F(RenderImage, SupersamplingIsTheBoxFilterOfTheLargerImage) {
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));
  Renderer renderer(s.scene, test::constantOctree());
  RenderParams p = edgeParams();
  const PinholeCamera camera = edgeCamera();
  p.supersample = 3;
  const RgbImage small = renderer.render(camera, p);
  RenderParams big = p;
  big.supersample = 1;
  big.width = 120;
  big.height = 90;
  const RgbImage filtered = binImage(renderer.render(camera, big), 3);
  ASSERT_EQ(small.rgb.size(), filtered.rgb.size());
  for (size_t i = 0; i < small.rgb.size(); ++i) ASSERT_NEAR(small.rgb[i], filtered.rgb[i], 1e-5f) << i;
  int fractional = 0;
  const float lit = small.pixel(5, 15)[0];
  for (int x = 0; x < p.width; ++x) {
    const float v = small.pixel(x, 15)[0];
    if (v > 0.05f * lit && v < 0.95f * lit) ++fractional;
  }
  EXPECT_GE(fractional, 1) << "the edge pixel is partly covered";
  EXPECT_THROW(
      {
        RenderParams bad = p;
        bad.supersample = 0;
        renderer.render(camera, bad);
      },
      InputError);
}

// A glTF camera's znear of 1e30 (beyond the whole scene), or a zfar of
// 1e30, put the near plane past everything: a black image where the tracers
// draw the scene (eighth hostile list F4-55, F4-56). The planes follow the
// scene's box: the same image as the camera's usual planes.
TEST_F(RenderImage, ACameraNearOrFarPlaneBeyondTheSceneDrawsItAsTheUsualPlanes) {
  QuadSetup s;
  const RenderParams p = QuadSetup::params(false);
  const RgbImage usual = s.render(test::constantOctree(), p);
  ASSERT_GT(usual.pixel(p.width / 2, p.height / 2)[0], 0.0f);
  for (const auto& [znear, zfar] : {std::pair{1e30f, 0.0f}, std::pair{1e-30f, 1e30f}}) {
    QuadSetup odd;
    odd.camera.znear = znear;
    odd.camera.zfar = zfar;
    const RgbImage image = odd.render(test::constantOctree(), p);
    ASSERT_EQ(image.rgb.size(), usual.rgb.size());
    for (size_t i = 0; i < image.rgb.size(); ++i) {
      ASSERT_NEAR(image.rgb[i], usual.rgb[i], 1e-5f) << "znear " << znear << ", zfar " << zfar;
    }
  }
}

// Two by two samples lie on a rotated grid (x offsets -3/8, -1/8, 1/8, 3/8
// of a pixel, one per row as well): a vertical edge 0.247 px right of a
// pixel's centre leaves 3 of its 4 samples on the quad, where an ordered
// 2 x 2 grid (offsets -1/4 and 1/4) would leave half.
TEST_F(RenderImage, TwoBySupersamplingSamplesARotatedGrid) {
  QuadSetup s;
  s.scene.lights.push_back(test::pointLight({0.1f, -0.05f, 1.0f}, 2.0f));
  Renderer renderer(s.scene, test::constantOctree());
  RenderParams p = edgeParams();
  p.supersample = 2;
  const RgbImage image = renderer.render(edgeCamera(), p);
  const float v20 = image.pixel(20, 15)[0], v21 = image.pixel(21, 15)[0];
  ASSERT_GT(v21, 0.0f);
  EXPECT_EQ(image.pixel(23, 15)[0], 0.0f);  // wholly right of the edge
  // The lit light where the three covered samples are (their mean offset
  // -1/8: 0.875 px right of pixel 21's centre), extrapolated.
  const float lit = v21 + 0.875f * (v21 - v20);
  EXPECT_NEAR(image.pixel(22, 15)[0] / lit, 0.75f, 0.02f);
}

}  // namespace
}  // namespace lo
