// Surface layers and gather occlusion through the whole bake (bake() ->
// VdlGrid -> GpuOctree -> octreeIrradiance), against answers known without
// the bake: two perpendicular black planes, each lit by its own distant light
// that grazes the other, hold exactly their own light's irradiance up to the
// edge where they meet; a floor split by a thin wall with the light on one
// side holds none on the other.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "core/error.h"
#include "lightgrid/grid_frame.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "test_util.h"

namespace lo {
namespace {

using test::sun;

Scene blackScene() {
  Scene scene;
  Material black;
  black.baseColor = {0, 0, 0};  // no bounce: every photon is a direct one
  scene.materials.push_back(black);
  return scene;
}

struct EdgeError {
  double floor = 0, wall = 0;  ///< mean relative error within one voxel of the edge
};

/// A floor (y = 0, facing up) and a wall (x = 0, facing +x) meeting along the
/// z axis; light A straight down lights only the floor (E_A = 2), light B
/// along -x only the wall (E_B = 1).
EdgeError edgeError(bool layers, LightRepresentation representation = LightRepresentation::Vdl) {
  Scene scene = blackScene();
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);
  test::addQuad(scene, {0, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 0);
  scene.lights.push_back(sun({0, -1, 0}, 2.0f));
  scene.lights.push_back(sun({-1, 0, 0}, 1.0f));
  BakeParams p = test::smallBake(4, 400000);
  p.includeDirect = true;
  p.layers = layers;
  p.representation = representation;
  const BakeResult baked = bake(scene, p);
  const GpuOctree octree = buildGpuOctree(baked.grid);
  const float voxel = baked.grid.frame.voxelSize;
  EdgeError e;
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      const float d = voxel * (0.05f + 0.9f * float(i) / 7.0f);  // within a voxel of the edge
      const float z = 0.25f + 0.5f * float(j) / 7.0f;
      const Vec3 floorE = octreeIrradiance(octree, {d, 0, z}, {0, 1, 0});
      const Vec3 wallE = octreeIrradiance(octree, {0, d, z}, {1, 0, 0});
      e.floor += std::fabs(floorE.x - 2.0) / 2.0;
      e.wall += std::fabs(wallE.x - 1.0) / 1.0;
      ++n;
    }
  }
  e.floor /= n;
  e.wall /= n;
  std::printf("edge, %s, layers %s: %zu voxels with 2+ layers; mean relative error within one voxel "
              "of the edge: floor %.3f, wall %.3f\n",
              representationName(representation), layers ? "on" : "off",
              baked.stats.level.layeredVoxels, e.floor, e.wall);
  return e;
}

TEST(SurfaceLayers, EachFaceOfAnEdgeKeepsItsOwnLight) {
  const EdgeError on = edgeError(true);
  const EdgeError off = edgeError(false);
  // Photon noise of a k = 300 estimate is ~6%; the edge voxels without
  // layers mix the two faces' photons. (Since the edge correction asks the
  // scene where its surfaces end, layers off measure 0.057 and 0.084 against
  // 0.029 and 0.042 on: half, where the grid's coverage left off at 2.5x.)
  EXPECT_LT(on.floor, 0.08);
  EXPECT_LT(on.wall, 0.08);
  EXPECT_GT(off.floor + off.wall, 1.5 * (on.floor + on.wall));
}

// The same edge with the SH representation: each layer's SH, scaled to its
// gathered estimate at its normal, gives each face its own light.
TEST(SurfaceLayers, EachFaceOfAnEdgeKeepsItsOwnLightAsSphericalHarmonics) {
  for (LightRepresentation r : {LightRepresentation::Sh1, LightRepresentation::Sh2}) {
    const EdgeError on = edgeError(true, r);
    EXPECT_LT(on.floor, 0.08) << representationName(r);
    EXPECT_LT(on.wall, 0.08) << representationName(r);
  }
}

/// A 1 x 1 floor split at x = 0.5 by a thin wall (both sides facing out,
/// up to y = 1), lit from above on the +x side only (a sun whose light
/// reaches x < 0.5 is blocked by a roof there).
Scene thinWallScene() {
  Scene scene = blackScene();
  Material white;
  white.baseColor = {0.8f, 0.8f, 0.8f};
  scene.materials.push_back(white);
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, 1);        // floor
  test::addQuad(scene, {0.5f, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 0}, 1);     // wall, +x side
  test::addQuad(scene, {0.5f, 0, 0}, {0, 0, 1}, {0, 1, 0}, {-1, 0, 0}, 1);    // wall, -x side
  test::addQuad(scene, {0, 1, 0}, {0, 0, 1}, {0.5f, 0, 0}, {0, 1, 0}, 0);     // black roof over x < 0.5
  test::addQuad(scene, {0, 1, 0}, {0.5f, 0, 0}, {0, 0, 1}, {0, -1, 0}, 0);
  scene.lights.push_back(sun({0, -1, 0}, 1.0f));
  return scene;
}

TEST(SurfaceLayers, NoLightThroughAThinWall) {
  const Scene scene = thinWallScene();
  for (int on = 0; on < 2; ++on) {
    BakeParams p = test::smallBake(5, 300000);
    p.layers = on;
    p.occlusion = on;
    const BakeResult baked = bake(scene, p);
    const GpuOctree octree = buildGpuOctree(baked.grid);
    double dark = 0, lit = 0;
    int n = 0;
    for (int i = 0; i < 16; ++i) {
      const float x = 0.5f - 0.004f - 0.06f * float(i % 4) / 3.0f;  // the dark side, near the wall
      const float z = 0.2f + 0.6f * float(i / 4) / 3.0f;
      dark += luminance(octreeIrradiance(octree, {x, 0, z}, {0, 1, 0}));
      lit += luminance(octreeIrradiance(octree, {1.0f - x, 0, z}, {0, 1, 0}));
      ++n;
    }
    std::printf("thin wall, layers and occlusion %s: floor near the wall, dark side %.4g, lit "
                "side (indirect) %.4g W/m^2\n",
                on ? "on" : "off", dark / n, lit / n);
    ASSERT_GT(lit, 0.0);
    if (on) {
      EXPECT_EQ(dark, 0.0) << "light through the wall";
    } else {
      EXPECT_GT(dark, 0.05 * lit) << "the test would not show a leak";
    }
  }
}

/// The joint of the same scene: the dark side's floor right at the wall
/// (closer than the layers' side tolerance) and the wall's dark face right
/// above the floor. The layer a fragment there takes must be its own
/// side's: a lit floor layer whose point lay on the wall served both sides,
/// and drew a bright line along the joint's dark side.
TEST(SurfaceLayers, NoBrightLineWhereAThinWallMeetsTheFloor) {
  const Scene scene = thinWallScene();
  BakeParams p = test::smallBake(5, 300000);
  const BakeResult baked = bake(scene, p);
  const GpuOctree octree = buildGpuOctree(baked.grid);
  double darkestLit = 1e30, brightestDark = 0;
  for (int i = 0; i < 40; ++i) {
    const float z = 0.1f + 0.8f * float(i) / 39.0f;
    for (float gap : {1e-4f, 5e-4f, 1e-3f, 2e-3f, 3e-3f}) {
      // The dark side's floor next to the wall, and the wall's dark face next to the floor.
      brightestDark = std::max(brightestDark, double(luminance(octreeIrradiance(
                                                  octree, {0.5f - gap, 0, z}, {0, 1, 0}))));
      brightestDark = std::max(brightestDark, double(luminance(octreeIrradiance(
                                                  octree, {0.5f, gap, z}, {-1, 0, 0}))));
      darkestLit = std::min(darkestLit, double(luminance(octreeIrradiance(
                                            octree, {0.5f + gap, 0, z}, {0, 1, 0}))));
    }
  }
  std::printf("thin wall joint: brightest dark-side point %.4g, darkest lit-side point %.4g W/m^2\n",
              brightestDark, darkestLit);
  EXPECT_GT(darkestLit, 0.0);
  EXPECT_EQ(brightestDark, 0.0) << "light across the joint";
}

/// A slab half a voxel thick whose two faces share their voxels: its top
/// (y = t, facing up) lit straight down by a sun of 2 W/m^2, its underside
/// (y = 0, facing down) straight up by one of 1 W/m^2, black, baked with
/// the direct light. The underside's layer gathered around the top's
/// centroid, half a voxel off its own surface along the normal (where the
/// gather's ellipsoid, four times thinner than wide, reaches 0.4 voxel):
/// it held no photon, and a game level's ledges were black underneath.
TEST(SurfaceLayers, EachFaceOfAThickSlabGathersOnItsOwnSurface) {
  Scene scene = blackScene();
  const float t = 0.016f;  // half a voxel at depth 5
  test::addQuad(scene, {0, t, 0}, {0, 0, 1}, {1, 0, 0}, {0, 1, 0}, 0);   // top
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 0, 1}, {0, -1, 0}, 0);  // underside
  // A post in a corner, so that the grid's rows do not split the two faces.
  test::addQuad(scene, {0, 0, 0}, {0.01f, 0, 0}, {0, 0.37f, 0}, {0, 0, -1}, 0);
  scene.lights.push_back(sun({0, -1, 0}, 2.0f));
  scene.lights.push_back(sun({0, 1, 0}, 1.0f));
  BakeParams p = test::smallBake(5, 300000);
  p.includeDirect = true;
  const BakeResult baked = bake(scene, p);
  const GpuOctree octree = buildGpuOctree(baked.grid);
  const GridFrame& frame = baked.grid.frame;
  ASSERT_GT(t, 0.4f * frame.voxelSize);
  ASSERT_EQ(frame.coordOf({0.5f, 0, 0.5f}).y, frame.coordOf({0.5f, t, 0.5f}).y)
      << "both faces must share their voxels";
  double top = 0, under = 0, worstUnder = 1e30;
  int n = 0;
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      const float x = 0.2f + 0.6f * float(i) / 7.0f, z = 0.2f + 0.6f * float(j) / 7.0f;
      top += luminance(octreeIrradiance(octree, {x, t, z}, {0, 1, 0}));
      const double e = luminance(octreeIrradiance(octree, {x, 0, z}, {0, -1, 0}));
      under += e;
      worstUnder = std::min(worstUnder, e);
      ++n;
    }
  }
  std::printf("thick slab: top %.4g W/m^2 (exact 2), underside %.4g (exact 1), darkest underside "
              "point %.4g\n", top / n, under / n, worstUnder);
  EXPECT_NEAR(top / n, 2.0, 0.15);
  EXPECT_NEAR(under / n, 1.0, 0.08);
  EXPECT_GT(worstUnder, 0.8);
}

/// A floor of two levels a sliver apart: y = 0 for x < 0.515 and y = -0.0015
/// beyond, joined by a riser facing +x (a twentieth of a voxel at depth 5),
/// black, lit straight down by a sun of 1 W/m^2 and baked with the direct
/// light: E = 1 on both levels. The riser's plane crossed its voxels as a
/// layer of its own, and the lower level's fragments there lay across it
/// from the floor layer's photons: no layer served them, and where every
/// voxel of the interpolation had the riser, neither did the interpolation
/// (a game level's steps and tiles: black patches on the floor).
TEST(SurfaceLayers, ASliverOfAStepDoesNotSplitTheFloor) {
  Scene scene = blackScene();
  const float step = 0.0015f, at = 0.515f;
  test::addQuad(scene, {0, 0, 0}, {at, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);                  // upper level
  test::addQuad(scene, {at, -step, 0}, {1 - at, 0, 0}, {0, 0, 1}, {0, 1, 0}, 0);        // lower level
  test::addQuad(scene, {at, -step, 0}, {0, step, 0}, {0, 0, 1}, {1, 0, 0}, 0);          // the riser
  // A post in a corner, so that the grid's rows do not split the two levels.
  test::addQuad(scene, {0, 0, 0}, {0.01f, 0, 0}, {0, 0.37f, 0}, {0, 0, -1}, 0);
  scene.lights.push_back(sun({0, -1, 0}, 1.0f));
  BakeParams p = test::smallBake(5, 300000);
  p.includeDirect = true;
  const BakeResult baked = bake(scene, p);
  const GpuOctree octree = buildGpuOctree(baked.grid);
  const GridFrame& frame = baked.grid.frame;
  const float voxel = frame.voxelSize;
  ASSERT_LT(step, 0.1f * voxel) << "the riser must be a sliver of its voxels";
  ASSERT_EQ(frame.coordOf({at, 0, 0.5f}).y, frame.coordOf({at, -step, 0.5f}).y)
      << "both levels must share their voxels";
  const float across = (at - frame.origin.x) / voxel - std::floor((at - frame.origin.x) / voxel);
  ASSERT_GT(across, 0.2f) << "the riser must cross its voxels, not lie on their faces";
  ASSERT_LT(across, 0.8f);
  double worst = 1e30;
  for (bool interpolation : {false, true}) {
    OctreeShadeParams shade;
    shade.interpolation = interpolation;
    for (int i = 0; i < 24; ++i) {
      for (int j = 0; j < 8; ++j) {
        // Both levels, within one and a half voxels of the step.
        const float d = voxel * (0.02f + 1.5f * float(i % 12) / 11.0f);
        const Vec3 point = i < 12 ? Vec3{at + d, -step, 0} : Vec3{at - d, 0, 0};
        const float z = 0.2f + 0.6f * float(j) / 7.0f;
        worst = std::min(worst, double(luminance(octreeIrradiance(
                                    octree, {point.x, point.y, z}, {0, 1, 0}, shade))));
      }
    }
  }
  std::printf("two-level floor: %zu voxels with 2+ layers, voxel %.4g; darkest point near the step %.4g W/m^2 (exact 1)\n",
              baked.stats.level.layeredVoxels, voxel, worst);
  EXPECT_GT(worst, 0.8);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// A scene so small that its voxels are below what a .vdb transform stores is
// refused before any work, naming --depth (it used to fail at the write,
// after the whole bake).
TEST(BakeLimits, VoxelsTooSmallForAVdbAreRefusedFirst) {
  Scene scene = test::pointLitRoom();
  for (Vec3& p : scene.positions) p = p * 1e-3f;
  for (Light& l : scene.lights) l.position = l.position * 1e-3f;
  BakeParams p;
  p.depth = 8;
  test::expectRefusal([&] { bake(scene, p); },
                      {"--depth 8", "smaller than a .vdb stores", "bake at a smaller --depth"});
  // At depth 1 no smaller depth helps (H10-4-241): only the scene's units.
  Scene tiny = scene;
  for (Vec3& q : tiny.positions) q = q * 1e-4f;
  for (Light& l : tiny.lights) l.position = l.position * 1e-4f;
  p.depth = 1;
  test::expectRefusal([&] { bake(tiny, p); },
                      {"--depth 1", "the scene is too small for a .vdb at any depth"});
  p.depth = 4;  // 16 voxels across a millimetre: storable
  p.photons = 2000;
  EXPECT_NO_THROW(bake(scene, p));
}

// A gathering radius far below the photons' spacing found no photon: every
// voxel dark and a noise figure of 0 (none gathered, no variance). Refused
// below a tenth of a voxel, naming the smallest it takes.
TEST(BakeLimits, ARadiusUnderATenthOfAVoxelIsRefused) {
  const Scene scene = test::pointLitRoom();
  BakeParams p = test::smallBake(4, 2000);
  const float voxel = makeGridFrame(scene.bounds(), 4).voxelSize;
  p.radius = 0.05f * voxel;
  test::expectRefusal([&] { bake(scene, p); }, {"--radius", "of a voxel", "at least"});
  p.radius = 1e-30f;
  test::expectRefusal([&] { bake(scene, p); }, {"--radius"});
  p.radius = 0.2f * voxel;  // small, but a radius the gather can use
  EXPECT_NO_THROW(bake(scene, p));
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

TEST(BakeRegion, BudgetWarningSaysWhatHappenedAndWhatHelps) {
  BakeParams p;
  p.photons = 1000;
  BakeStats st;
  st.storedPhotons = 1000;
  st.emittedPaths = 20000;
  st.emptyPaths = 19500;  // open ground: paths land and store nothing
  st.missedPaths = 100;
  EXPECT_EQ(photonBudgetWarning(p, st), "");
  st.storedPhotons = 400;  // ... and the cap is reached
  std::string w = photonBudgetWarning(p, st);
  EXPECT_NE(w.find("only 400 of 1,000 photons"), std::string::npos) << w;
  EXPECT_NE(w.find("--include-direct"), std::string::npos) << w;
  EXPECT_EQ(w.find("missed"), std::string::npos) << w;
  st.missedPaths = 15000;  // most light aimed past the surfaces
  w = photonBudgetWarning(p, st);
  EXPECT_NE(w.find("15,000 of 20,000 photon paths missed every surface"), std::string::npos) << w;
  EXPECT_NE(w.find("--bounds"), std::string::npos) << w;
  st.storedPhotons = 1000;
  EXPECT_NE(photonBudgetWarning(p, st).find("--bounds"), std::string::npos);
  // A target bake stores what its noise asks, fewer than BakeParams::photons
  // or more: short only when its passes ran out of paths.
  p.targetError = 0.07;
  st.missedPaths = 100;
  st.storedPhotons = 400;
  st.targetStop = "target reached";
  EXPECT_EQ(photonBudgetWarning(p, st), "");
  st.targetStop = "no more paths";
  w = photonBudgetWarning(p, st);
  EXPECT_NE(w.find("the noise target was not reached: 400 photons"), std::string::npos) << w;
  EXPECT_NE(w.find("--include-direct"), std::string::npos) << w;
}

// A small room on a 50 m ground plane under a sun: without a region of
// interest most photon paths store nothing (the grid spans the ground, the
// sun shines on all of it); with --bounds on the room, the grid covers the
// room alone, every stored photon lies in it, and far fewer paths are wasted.
TEST(BakeRegion, ARoomOnAGroundPlane) {
  Scene scene = blackScene();
  Material white;
  white.baseColor = {0.7f, 0.7f, 0.7f};
  scene.materials.push_back(white);
  test::addQuad(scene, {-25, 0, -25}, {50, 0, 0}, {0, 0, 50}, {0, 1, 0}, 1);  // ground
  // A room of 2 x 1 x 2 m open to the sky.
  test::addQuad(scene, {-1, 0, -1}, {2, 0, 0}, {0, 1, 0}, {0, 0, 1}, 1);
  test::addQuad(scene, {-1, 0, 1}, {2, 0, 0}, {0, 1, 0}, {0, 0, -1}, 1);
  test::addQuad(scene, {-1, 0, -1}, {0, 0, 2}, {0, 1, 0}, {1, 0, 0}, 1);
  test::addQuad(scene, {1, 0, -1}, {0, 0, 2}, {0, 1, 0}, {-1, 0, 0}, 1);
  scene.lights.push_back(sun({0.3f, -1.0f, 0.2f}, 1.0f));
  BakeParams p = test::smallBake(5, 20000, 50);
  const BakeResult whole = bake(scene, p, nullptr);
  Bounds3 room;
  room.extend(Vec3{-1.2f, -0.1f, -1.2f});
  room.extend(Vec3{1.2f, 1.2f, 1.2f});
  p.region = room;
  const BakeResult roi = bake(scene, p, nullptr);
  const double wasted = double(whole.stats.emptyPaths) / double(whole.stats.emittedPaths);
  const double wastedRoi = double(roi.stats.emptyPaths) / double(roi.stats.emittedPaths);
  std::printf("ground plane: %zu paths for %zu photons (%.0f%% stored nothing); with --bounds "
              "%zu paths (%.0f%%)\n",
              whole.stats.emittedPaths, whole.stats.storedPhotons, 100 * wasted,
              roi.stats.emittedPaths, 100 * wastedRoi);
  EXPECT_GT(wasted, 0.5);
  // Aimed at the scene's footprint, the sun's paths land (on the ground):
  // they store nothing because their first hit is direct light and the
  // ground reflects into the open.
  // Only the room's walls catch what the ground reflects, so the cap of
  // paths is reached: the warning says so, and that --bounds helps.
  EXPECT_LT(whole.stats.missedPaths, whole.stats.emittedPaths / 20);
  p.region = Bounds3{};
  const std::string warning = photonBudgetWarning(p, whole.stats);
  EXPECT_NE(warning.find("reached a surface but stored nothing"), std::string::npos) << warning;
  EXPECT_NE(warning.find("--bounds"), std::string::npos) << warning;
  EXPECT_EQ(roi.stats.storedPhotons, p.photons);
  EXPECT_LT(wastedRoi, wasted);
  EXPECT_LT(roi.stats.emittedPaths, whole.stats.emittedPaths / 4);
  // The grid spans the region, not the ground.
  EXPECT_LT(roi.grid.frame.voxelSize * float(roi.grid.frame.resolution()), 2.6f);
  EXPECT_GT(whole.grid.frame.voxelSize * float(whole.grid.frame.resolution()), 49.0f);
  for (const Coord& c : roi.grid.coords) {
    const Vec3 centre = roi.grid.frame.voxelCenter(c);
    ASSERT_TRUE(centre.x > -1.4f && centre.x < 1.4f && centre.z > -1.4f && centre.z < 1.4f)
        << centre.ToString();
  }
  EXPECT_EQ(roi.metadata.region.lower, room.lower);
  // The same region marked in the scene (a glTF marker node) when no
  // --bounds is given: the same bake.
  Scene marked = scene;
  marked.region = room;
  p.region = Bounds3{};
  const BakeResult fromScene = bake(marked, p, nullptr);
  EXPECT_EQ(fromScene.metadata.region.lower, room.lower);
  EXPECT_EQ(fromScene.grid.coords, roi.grid.coords);
  EXPECT_EQ(fromScene.stats.emittedPaths, roi.stats.emittedPaths);
  p.region = room;
  EXPECT_EQ(photonBudgetWarning(p, roi.stats), "");
}

}  // namespace
}  // namespace lo
