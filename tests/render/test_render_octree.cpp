// The renderer's octree lookup under OSMesa: a Lambertian quad lit only by
// VDLs built by hand is albedo / pi times their cosine-weighted irradiance,
// in every texel format, from a voxel on either side of the surface; the
// voxel view shows the leaves.

#include <gtest/gtest.h>
#include <octree_layout.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include "image/image.h"
#include "render/render_fixture.h"
#include "render/renderer.h"
#include "test_util.h"

namespace lo {
namespace {

using RenderImage = test::GlTest;
using test::QuadSetup;

struct Comparison {
  float maxAbsDiff = 0;
  double failingFraction = 0;
};

/// Compares RGB of every pixel; on failure writes rendered/expected/diff EXRs.
Comparison compareImages(const RgbImage& rendered, const RgbImage& expected, float tolerance,
                         const std::string& name) {
  Comparison c;
  RgbImage diff = expected;
  size_t failing = 0, pixels = size_t(rendered.width) * rendered.height;
  for (size_t i = 0; i < pixels; ++i) {
    float worst = 0;
    for (int k = 0; k < 3; ++k) {
      float d = std::fabs(rendered.rgb[i * 3 + k] - expected.rgb[i * 3 + k]);
      if (!std::isfinite(d)) d = INFINITY;
      diff.rgb[i * 3 + k] = d;
      worst = std::max(worst, d);
    }
    c.maxAbsDiff = std::max(c.maxAbsDiff, worst);
    if (worst > tolerance && failing++ == 0) {
      std::ostringstream os;
      os << "first failing pixel (" << i % size_t(rendered.width) << ", "
         << i / size_t(rendered.width) << "): rendered " << rendered.rgb[i * 3] << " "
         << rendered.rgb[i * 3 + 1] << " " << rendered.rgb[i * 3 + 2] << ", expected "
         << expected.rgb[i * 3] << " " << expected.rgb[i * 3 + 1] << " "
         << expected.rgb[i * 3 + 2];
      ADD_FAILURE() << name << ": " << os.str();
    }
  }
  c.failingFraction = double(failing) / double(pixels);
  if (failing > 0) {
    std::string dir = test::outputDir(name);
    writeImage(dir + "/rendered.exr", rendered);
    writeImage(dir + "/expected.exr", expected);
    writeImage(dir + "/diff.exr", diff);
    ADD_FAILURE() << name << ": images written to " << dir;
  }
  return c;
}

/// Expected radiance of the Lambertian quad lit by `vdls`: albedo/pi * sum E_i max(0, n.d_i).
RgbImage expectedQuad(const QuadSetup& s, const RenderParams& p, const std::vector<Vdl>& vdls) {
  Vec3 radiance{0, 0, 0};
  for (const Vdl& v : vdls) {
    Vec3 d = normalize(v.direction);
    float packed = layout::loPackDirection(d.x, d.y, d.z);
    float cosine = std::max(0.0f, layout::loUnpackDirectionZ(packed));
    radiance += s.albedo * kInvPi * v.irradiance * cosine;
  }
  RgbImage e(p.width, p.height);
  for (size_t i = 0; i < e.pixelCount(); ++i) e.set(i, radiance);
  return e;
}

void checkQuad(const GpuOctree& octree, const std::vector<Vdl>& vdls, bool interpolation,
               const std::string& name) {
  QuadSetup s;
  RenderParams p = QuadSetup::params(interpolation);
  RgbImage image = s.render(octree, p);
  Comparison c = compareImages(image, expectedQuad(s, p, vdls), 1e-3f, name);
  EXPECT_LE(c.maxAbsDiff, 1e-3f) << name;
  EXPECT_EQ(c.failingFraction, 0.0) << name;
}

TEST_F(RenderImage, ConstantVdlAlongNormalGivesAlbedoOverPiTimesE) {
  Vdl v;
  v.irradiance = {2.0f, 1.0f, 0.5f};
  v.direction = {0, 0, 1};
  GpuOctree octree = test::quadOctree([&](const Coord&, Vdl* out) {
    out[0] = v;
    return 1;
  });
  checkQuad(octree, {v}, false, "render_constant_vdl_nearest");
  checkQuad(octree, {v}, true, "render_constant_vdl_trilinear");
  // Half precision (RGBA16UI: half bits + packed direction); 2, 1, 0.5 are exact halves.
  GpuOctree half = octree;
  half.halfFloat = true;
  half.vdlTexelsHalf.resize(half.vdlTexels.size());
  for (size_t i = 0; i < half.vdlTexels.size(); ++i) {
    half.vdlTexelsHalf[i] =
        i % 4 == 3 ? uint16_t(half.vdlTexels[i]) : floatToHalf(half.vdlTexels[i]);
  }
  half.vdlTexels.clear();
  checkQuad(half, {v}, true, "render_constant_vdl_half");
  // Compact texels (RGB9E5 x a power-of-two scale); 2, 1, 0.5 are exact.
  GpuOctree compact = half;
  compact.compact = true;
  compact.irradianceScale = 4.0f;
  for (size_t i = 0; i < compact.vdlTexelsHalf.size(); i += 4) {
    const uint32_t bits = encodeRgb9e5(Vec3{halfToFloat(half.vdlTexelsHalf[i]),
                                            halfToFloat(half.vdlTexelsHalf[i + 1]),
                                            halfToFloat(half.vdlTexelsHalf[i + 2])} /
                                       4.0f);
    compact.vdlTexelsHalf[i] = uint16_t(bits & 0xffffu);
    compact.vdlTexelsHalf[i + 1] = uint16_t(bits >> 16);
    compact.vdlTexelsHalf[i + 2] = 0;
  }
  checkQuad(compact, {v}, true, "render_constant_vdl_compact");
}

TEST_F(RenderImage, SeveralVdlsAddWithTheirCosines) {
  std::vector<Vdl> vdls(3);
  vdls[0] = {{1.0f, 0.5f, 0.25f}, {0, 0, 1}};
  vdls[1] = {{0.5f, 2.0f, 1.0f}, test::latticeDirection(60, 40)};   // oblique, facing the quad
  vdls[2] = {{3.0f, 3.0f, 3.0f}, test::latticeDirection(200, 10)};  // from below: no light
  GpuOctree octree = test::quadOctree([&](const Coord&, Vdl* out) {
    std::copy(vdls.begin(), vdls.end(), out);
    return 3;
  });
  checkQuad(octree, vdls, true, "render_three_vdls");
}

TEST_F(RenderImage, SurfaceOnAVoxelFaceFindsTheVoxelOnEitherSide) {
  // Only one layer of voxels is lit: the one in front of the quad (z in
  // [0, 0.75], coordinate 2) or the one behind it (coordinate 1).
  Vdl v{{1.0f, 1.0f, 1.0f}, {0, 0, 1}};
  for (int layer : {1, 2}) {
    GpuOctree octree = test::quadOctree([&](const Coord& c, Vdl* out) {
      if (c.z != layer) return 0;
      out[0] = v;
      return 1;
    });
    for (bool interpolation : {false, true}) {
      checkQuad(octree, {v}, interpolation,
                "render_voxel_face_layer" + std::to_string(layer) +
                    (interpolation ? "_trilinear" : "_nearest"));
    }
  }
}

TEST_F(RenderImage, VoxelModeColoursLeavesAndLeavesEmptySpaceBlack) {
  QuadSetup s;
  // Only voxels with x coordinate 2 (x in [0, 0.75]) exist.
  GpuOctree octree = test::quadOctree([](const Coord& c, Vdl* out) {
    if (c.x != 2) return 0;
    out[0] = {{1, 1, 1}, {0, 0, 1}};
    return 1;
  });
  RenderParams p = QuadSetup::params(false);
  p.mode = RenderMode::Voxels;
  RgbImage image = s.render(octree, p);
  // Camera x centre 0.1; half width at distance 2 ~ 0.97: x = 0 is left of
  // centre by ~0.1/0.97 of the half width.
  const float* left = image.pixel(2, p.height / 2);
  const float* right = image.pixel(p.width / 2 + 4, p.height / 2);
  EXPECT_EQ(left[0] + left[1] + left[2], 0.0f);
  EXPECT_GT(right[0] + right[1] + right[2], 0.1f);
}

}  // namespace
}  // namespace lo
