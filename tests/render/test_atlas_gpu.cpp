// Render to atlas on the GPU (render/atlas_gpu.h, paper §4.2.3) against the
// CPU path (lightmap/lightmap_atlas.h, itself tested against a polygon
// clipper and brute-force nearest points in tests/lightmap): the same texels
// covered, owned by the same triangles, holding the same irradiance and
// direction within float rounding; a plane under one constant VDL holds the
// cosine law at every texel; and on the Cornell box the whole bake (dilation
// and seams included) matches the CPU's.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "lightmap/atlas_test_scenes.h"
#include "lightmap/lightmap_atlas.h"
#include "lightmap/lightmap_bake.h"
#include "octree/octree_irradiance.h"
#include "render/atlas_gpu.h"
#include "render/context.h"
#include "render/render_fixture.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vdb/vdb_io.h"

namespace lo {
namespace {

using namespace atlas_test;

/// Texels whose coverage differs, and the largest irradiance and direction
/// differences over the texels both cover (relative to 1e-3 + |cpu|).
struct AtlasDifference {
  size_t coverageDiffers = 0, compared = 0;
  float irradiance = 0, direction = 0;
};

AtlasDifference difference(const LightmapAtlas& gpu, const LightmapAtlas& cpu,
                           uint8_t which = kAtlasCovered) {
  AtlasDifference d;
  EXPECT_EQ(gpu.pageCount, cpu.pageCount);
  EXPECT_EQ(gpu.width, cpu.width);
  EXPECT_EQ(gpu.height, cpu.height);
  for (int page = 0; page < std::min(gpu.pageCount, cpu.pageCount); ++page) {
    const size_t p = size_t(page);
    for (size_t i = 0; i < cpu.coverage[p].size(); ++i) {
      const bool a = gpu.coverage[p][i] == which, b = cpu.coverage[p][i] == which;
      if (a != b) ++d.coverageDiffers;
      if (!a || !b) continue;
      ++d.compared;
      const Vec3 eg = gpu.irradiance[p].at(i), ec = cpu.irradiance[p].at(i);
      for (int c = 0; c < 3; ++c) {
        d.irradiance =
            std::max(d.irradiance, std::fabs(eg[c] - ec[c]) / (1e-3f + std::fabs(ec[c])));
      }
      d.direction = std::max(d.direction, length(gpu.direction[p].at(i) - cpu.direction[p].at(i)));
    }
  }
  return d;
}

LightmapAtlas gpuBake(const Scene& scene, const LightmapUvs& uvs, const GpuOctree& octree,
                      AtlasBakeParams params) {
  GpuAtlasEvaluator evaluator;
  params.evaluator = &evaluator;
  return bakeLightmapAtlas(scene, uvs, octree, params);
}

/// A tilted plane (6 x 6 quads, facing its winding's way, or turned over)
/// under one constant VDL, its UVs on a 64-texel page, and bake settings
/// without dilation and stitching.
struct PlaneUnderOneVdl {
  Scene scene = emptyScene();
  Vec3 c{2.0f, 1.0f, 0.5f};
  GpuOctree octree;
  Vec3 decoded;  ///< the VDL's direction as the lookup decodes it
  LightmapUvs uvs;
  AtlasBakeParams params;

  explicit PlaneUnderOneVdl(bool turned) {
    const Vec3 eu{1.2f, 0.25f, 0.1f}, ev{-0.2f, 0.9f, 0.35f};
    addGrid(scene, 6, {0.35f, 0.3f, 0.55f}, turned ? ev : eu, turned ? eu : ev);
    const Vec3 d = normalize(Vec3{0.3f, -0.2f, 1.0f});
    octree = denseOctree([&](const Coord&) { return std::vector<Vdl>{vdl(c, d)}; });
    decoded = lookupOctree(octree, Vec3{1, 1, 1}).vdls[0].direction;
    LightmapUvParams up;
    up.atlasSize = 64;
    uvs = buildLightmapUvs(scene, up);
    params.dilation = 0;
    params.stitchSeams = false;
  }
};

TEST(AtlasGpu, PlaneUnderAConstantVdlIsTheCosineLawAtEveryTexel) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  PlaneUnderOneVdl plane(false);
  const Scene& scene = plane.scene;
  const GpuOctree& octree = plane.octree;
  const LightmapUvs& uvs = plane.uvs;
  AtlasBakeParams& params = plane.params;
  // The lookup decodes the packed direction: the cosine law with that one.
  const Vec3 decoded = plane.decoded;
  const Vec3 analytic = plane.c * std::max(0.0f, dot(scene.faceNormal(0), decoded));
  ASSERT_GT(analytic.x, 0.5f);
  for (bool interpolation : {true, false}) {
    SCOPED_TRACE(interpolation ? "interpolated" : "nearest voxel");
    params.shade.interpolation = interpolation;
    const LightmapAtlas atlas = gpuBake(scene, uvs, octree, params);
    ASSERT_EQ(atlas.pageCount, 1);
    EXPECT_GT(atlas.coveredTexels, size_t(atlas.width * atlas.height / 4));
    for (size_t i = 0; i < atlas.coverage[0].size(); ++i) {
      if (atlas.coverage[0][i] == kAtlasEmpty) continue;
      ASSERT_NEAR(length(atlas.irradiance[0].at(i) - analytic), 0.0f, 1e-5f) << i;
      ASSERT_NEAR(length(atlas.direction[0].at(i) - decoded), 0.0f, 1e-5f) << i;
    }
  }
}

// The plane turned over (winding and normals the other way), drawn from both
// sides: the GPU holds the side its light reaches, as the CPU does
// (atlasSurfaceSides), texel for texel; one-sided, the dark one.
TEST(AtlasGpu, ADoubleSidedSurfaceHoldsTheSideItsLightReaches) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  PlaneUnderOneVdl plane(true);
  const Vec3 lit = plane.c * std::max(0.0f, dot(-plane.scene.faceNormal(0), plane.decoded));
  ASSERT_GT(lit.x, 0.5f);
  for (bool doubleSided : {true, false}) {
    SCOPED_TRACE(doubleSided ? "doubleSided" : "one-sided");
    plane.scene.materials[0].doubleSided = doubleSided;
    const LightmapAtlas gpu = gpuBake(plane.scene, plane.uvs, plane.octree, plane.params);
    const LightmapAtlas cpu = bakeLightmapAtlas(plane.scene, plane.uvs, plane.octree, plane.params);
    const AtlasDifference diff = difference(gpu, cpu);
    EXPECT_EQ(diff.coverageDiffers, 0u);
    EXPECT_LT(diff.irradiance, 1e-4f);
    ASSERT_GT(gpu.coveredTexels, 0u);
    for (size_t i = 0; i < gpu.coverage[0].size(); ++i) {
      if (gpu.coverage[0][i] == kAtlasEmpty) continue;
      ASSERT_NEAR(length(gpu.irradiance[0].at(i) - (doubleSided ? lit : Vec3{0, 0, 0})), 0.0f, 1e-5f) << i;
    }
  }
}

// A cube under light that varies across voxels, with and without
// interpolation: texel for texel the CPU's values.
TEST(AtlasGpu, CubeMatchesTheCpuPathTexelForTexel) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  Scene scene = emptyScene();
  addCube(scene, Vec3(0.55f, 0.6f, 0.65f), 0.8f);
  const GpuOctree octree = denseOctree([](const Coord& v) {
    const float s = 1.0f + 0.3f * float(v.x) + 0.2f * float(v.y) + 0.1f * float(v.z);
    return std::vector<Vdl>{
        vdl(Vec3(1.0f, 0.8f, 0.6f) * s, {0.3f, 0.5f, 0.8f}),
        vdl(Vec3(0.2f, 0.3f, 0.5f) * (3.0f - 0.2f * float(v.y)), {-0.6f, -0.3f, -0.5f})};
  });
  LightmapUvParams up;
  up.atlasSize = 96;
  const LightmapUvs uvs = buildLightmapUvs(scene, up);
  AtlasBakeParams params;
  params.stitchSeams = false;
  for (bool interpolation : {true, false}) {
    SCOPED_TRACE(interpolation ? "interpolated" : "nearest voxel");
    params.shade.interpolation = interpolation;
    const LightmapAtlas cpu = bakeLightmapAtlas(scene, uvs, octree, params);
    const LightmapAtlas gpu = gpuBake(scene, uvs, octree, params);
    const AtlasDifference d = difference(gpu, cpu);
    std::printf("cube, %s: %zu texels compared, %zu differ in coverage, E within %.2g, d within %.2g\n",
                interpolation ? "interpolated" : "nearest", d.compared, d.coverageDiffers,
                d.irradiance, d.direction);
    EXPECT_EQ(gpu.coveredTexels, cpu.coveredTexels);
    EXPECT_EQ(d.coverageDiffers, 0u);
    EXPECT_GT(d.compared, size_t(uvs.width * uvs.height / 4));
    if (interpolation) {
      EXPECT_LT(d.irradiance, 1e-4f);
      EXPECT_LT(d.direction, 1e-4f);
    } else {
      // Without interpolation a point within rounding of a voxel face may
      // fall on either side (float here, double there): few texels, and
      // those jump by the step between neighbouring voxels.
      size_t jumps = 0;
      for (size_t i = 0; i < cpu.coverage[0].size(); ++i) {
        if (cpu.coverage[0][i] != kAtlasCovered) continue;
        const Vec3 a = gpu.irradiance[0].at(i), b = cpu.irradiance[0].at(i);
        if (length(a - b) > 1e-4f * (1.0f + length(b))) ++jumps;
      }
      EXPECT_LT(jumps, cpu.coveredTexels / 100) << jumps << " texels differ";
    }
    EXPECT_EQ(gpu.dilatedTexels, cpu.dilatedTexels);
  }
}

// The Cornell box's golden bake through the whole pipeline (automatic
// charts, dilation, seam stitching) on both paths.
TEST(AtlasGpu, CornellBoxMatchesTheCpuBake) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  const Scene scene = loadScene(test::dataDir() + "/cornell-box.gltf");
  const GpuOctree octree = test::goldenCornellOctree();
  LightmapParams lp;
  const LightmapBake cpu = bakeLightmap(scene, octree, lp);
  GpuAtlasEvaluator evaluator;
  lp.atlas.evaluator = &evaluator;
  const LightmapBake gpu = bakeLightmap(scene, octree, lp);
  const AtlasDifference covered = difference(gpu.atlas, cpu.atlas, kAtlasCovered);
  const AtlasDifference dilated = difference(gpu.atlas, cpu.atlas, kAtlasDilated);
  std::printf("cornell box: CPU %s\n  GPU %s\n", cpu.atlas.ToString().c_str(),
              gpu.atlas.ToString().c_str());
  std::printf("  covered: %zu compared, %zu differ in coverage, E within %.2g; dilated: %zu, E "
              "within %.2g\n",
              covered.compared, covered.coverageDiffers, covered.irradiance, dilated.compared,
              dilated.irradiance);
  EXPECT_EQ(covered.coverageDiffers, 0u);
  EXPECT_EQ(dilated.coverageDiffers, 0u);
  EXPECT_GT(covered.compared, size_t(cpu.atlas.width * cpu.atlas.height / 4));
  EXPECT_LT(covered.irradiance, 1e-3f);
  EXPECT_LT(dilated.irradiance, 1e-2f);
  EXPECT_LT(gpu.atlas.seamMismatchAfter, 0.01f * gpu.atlas.seamMismatchBefore);
}

// The same with an octree that has surface layers (a fresh bake of the
// Cornell box: its edges have them): the GLSL layer choice
// (octree_lookup.h's loLeafVdls) is the C++ one.
void expectLayeredBakeMatches(LightRepresentation representation, float tolerance = 0) {
  const Scene scene = loadScene(test::dataDir() + "/cornell-box.gltf");
  BakeParams bp = test::smallBake(5, 100000, 100);
  bp.representation = representation;
  const BakeResult baked = bake(scene, bp);
  ASSERT_GT(baked.grid.layers.size(), 0u);
  GpuOctreeParams op;
  op.compact = true;
  op.tolerance = tolerance;
  const GpuOctree octree = buildGpuOctree(baked.grid, op);
  if (tolerance > 0) {
    ASSERT_GT(octree.collapsedLeaves, 0u);
  }
  LightmapParams lp;
  lp.atlas.stitchSeams = false;
  const LightmapBake cpu = bakeLightmap(scene, octree, lp);
  GpuAtlasEvaluator evaluator;
  lp.atlas.evaluator = &evaluator;
  const LightmapBake gpu = bakeLightmap(scene, octree, lp);
  const AtlasDifference covered = difference(gpu.atlas, cpu.atlas, kAtlasCovered);
  std::printf("layered Cornell box, %s: %zu covered texels compared, %zu differ in coverage, E "
              "within %.2g\n",
              representationName(representation), covered.compared, covered.coverageDiffers,
              covered.irradiance);
  EXPECT_EQ(covered.coverageDiffers, 0u);
  // Float rounding of a position next to a layer's plane may flip the side
  // test: count the texels that differ, they must be rare.
  size_t differ = 0;
  for (size_t i = 0; i < cpu.atlas.coverage[0].size(); ++i) {
    if (cpu.atlas.coverage[0][i] != kAtlasCovered) continue;
    const Vec3 a = gpu.atlas.irradiance[0].at(i), b = cpu.atlas.irradiance[0].at(i);
    differ += length(a - b) > 1e-4f * (1e-3f + length(b));
  }
  EXPECT_LT(differ, cpu.atlas.coveredTexels / 1000) << differ << " texels differ";
}

TEST(AtlasGpu, LayeredOctreeMatchesTheCpuBake) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  expectLayeredBakeMatches(LightRepresentation::Vdl);
}

// The SH representation's GLSL (loShIrradiance, signed half texels times the
// scale) is the C++ one.
TEST(AtlasGpu, ShOctreeMatchesTheCpuBake) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  expectLayeredBakeMatches(LightRepresentation::Sh1);
  expectLayeredBakeMatches(LightRepresentation::Sh2);
}

// Adaptive leaves: the GLSL descent stops at leaves above the grid's depth
// as the C++ one does.
TEST(AtlasGpu, AdaptiveOctreeMatchesTheCpuBake) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  expectLayeredBakeMatches(LightRepresentation::Vdl, 0.1f);
  expectLayeredBakeMatches(LightRepresentation::Sh1, 0.1f);
}

}  // namespace
}  // namespace lo
