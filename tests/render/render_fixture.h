#pragma once
/// @file tests/render/render_fixture.h
/// @brief What the renderer's tests set up again and again: the skip where
/// there is no OSMesa context, octrees built by hand, the lit quad in front
/// of a camera, and the lights they put over it.

#include <gtest/gtest.h>

#include <functional>

#include "image/image.h"
#include "octree/gpu_octree.h"
#include "render/renderer.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"
#include "test_util.h"

/// For a test that also checks things without GL: skips from here on where
/// the binary has no OSMesa context.
#define REQUIRE_OSMESA()                                                       \
  do {                                                                         \
    if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available"; \
  } while (0)

namespace lo::test {

/// The fixture of a suite whose every test draws: skipped where the binary
/// has no OSMesa context (each file names its suites by this type, e.g.
/// `using RenderImage = test::GlTest;`).
class GlTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  }
};

/// The VDLs of the leaf voxel at `coord` (written to `out`, at most
/// kMaxVdls); returns how many, 0 for an empty voxel.
using VdlsOf = std::function<int(const Coord& coord, Vdl* out)>;

/// A light octree built by hand (independent of buildGpuOctree): depth
/// `depth` over the cube [origin, origin + cubeSize]^3; tiles laid out along x.
GpuOctree makeOctree(int depth, const Vec3& origin, float cubeSize, const VdlsOf& vdlsOf);

/// The depth-2 octree over QuadSetup's cube [-1.5, 1.5]^3 (voxel size 0.75).
GpuOctree quadOctree(const VdlsOf& vdlsOf);
/// quadOctree with no VDL anywhere: no indirect light.
GpuOctree emptyOctree();
/// quadOctree with one VDL in every voxel: irradiance 1, along +z.
GpuOctree constantOctree();

/// The project's Cornell box baked at depth 4 (tests/golden/cornell-box-d4.vdb,
/// the golden images' bake) as a GPU octree of the default texel form.
GpuOctree goldenCornellOctree();

/// A direction the 8+8-bit packing represents exactly (what the shader sees).
Vec3 latticeDirection(uint32_t thetaQ, uint32_t phiQ);

/// A 2x2 quad in the plane z = 0, normal +z, facing a camera on +z whose view
/// the quad fills; the octree cube [-1.5, 1.5]^3 has its voxel faces at z = 0
/// (depth 2: voxel size 0.75).
struct QuadSetup {
  Scene scene;
  Vec3 albedo{0.5f, 0.25f, 0.8f};
  PinholeCamera camera =
      PinholeCamera::lookAt({0.1f, -0.05f, 2.0f}, {0.1f, -0.05f, 0.0f}, 36.0f * kPi / 180.0f);
  QuadSetup();
  /// 64 x 48 pixels, indirect light only, no specular.
  static RenderParams params(bool interpolation);
  /// params(false) with direct light only: what the lights' tests draw.
  static RenderParams directParams();
  /// The scene drawn from `camera` by a fresh renderer of `octree`.
  RgbImage render(const GpuOctree& octree, const RenderParams& p) const;
  /// World units per pixel on a plane at `distance` from the camera.
  float worldPerPixel(const RenderParams& p, float distance) const;
};

/// Pixel column of world x on QuadSetup's quad plane z = `z` (the camera at
/// z = 2 looks down -z through x = 0.1).
int columnAt(const QuadSetup& s, const RenderParams& p, float x, float z);

}  // namespace lo::test
