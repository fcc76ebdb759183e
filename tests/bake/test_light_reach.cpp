// Lights that reach nothing (a lamp under the floor, a spot aimed away): the
// bake says so within a second and names them, and a target bake leaves
// them out of its passes without changing the light of the others.

#include <gtest/gtest.h>

#include <string>

#include "bake/bake.h"
#include "bake/bake_fixture.h"
#include "core/error.h"
#include "lightgrid/vdl_grid.h"
#include "photon/photon_map.h"
#include "test_util.h"

namespace lo {
namespace {

/// A spot under the scene's floor (y = 0 in the Cornell box), aimed down.
Light spotUnderTheFloor() {
  Light l;
  l.type = Light::Type::Spot;
  l.name = "cellar";
  l.position = {0.25f, -0.5f, 0.25f};
  l.direction = {0, -1, 0};
  l.intensity = 100.0f;
  l.outerConeAngle = 0.5f;
  l.innerConeAngle = 0.4f;
  return l;
}

const Scene& cornellBox() {
  static const Scene scene = loadScene(test::sharedScenesDir() + "/composed/cornell-box.glb");
  return scene;
}

double meanIrradiance(const VdlGrid& grid) {
  double sum = 0;
  for (size_t v = 0; v < grid.size(); ++v) sum += luminance(grid.irradiance[v]);
  return grid.size() > 0 ? sum / double(grid.size()) : 0.0;
}

TEST(PhotonBatchPaths, StopsWhenTheLightsReachAlmostNothing) {
  const size_t target = 1000000, maxEmitted = 64 * target;
  // After the probe's paths, a rate that would store under 1% of the
  // target by the last path stops; 1% or more goes on.
  EXPECT_EQ(photonBatchPaths(target, 100, kReachProbePaths, maxEmitted), 0u);
  EXPECT_GT(photonBatchPaths(target, 200, kReachProbePaths, maxEmitted), 0u);
  // Before the probe's paths, only a judgement beyond doubt: nothing from
  // 2^19 paths, where even 3 photons (the bound of none) would store 0.04%
  // by the last path, stops; 300 photons (4% at the bound) go on,
  // and so does nothing from a few paths.
  EXPECT_EQ(photonBatchPaths(target, 0, kReachProbePaths / 2, maxEmitted), 0u);
  EXPECT_GT(photonBatchPaths(target, 300, kReachProbePaths / 2, maxEmitted), 0u);
  EXPECT_GT(photonBatchPaths(target, 0, 8192, maxEmitted), 0u);
  // A target bake's pilot: 20,000 photons with the whole bake's paths
  // (1.28 billion) to draw on. Nothing from 100,000 paths stops (judged by
  // 64 paths per photon of the pilot); 5 photons go on.
  const size_t pilot = 20000, bakePaths = size_t(1280) * 1000000;
  EXPECT_EQ(photonBatchPaths(pilot, 0, 100000, bakePaths), 0u);
  EXPECT_GT(photonBatchPaths(pilot, 5, 100000, bakePaths), 0u);
}

TEST(LightReach, ALightThatReachesNothingStopsTheBakeAtOnceNamingIt) {
  Scene scene = cornellBox();
  for (Material& m : scene.materials) m.emission = Vec3{0, 0, 0};
  scene.lights = {spotUnderTheFloor()};
  PhotonParams pp;
  pp.storedPhotons = 100000;
  const PhotonMap map = tracePhotons(scene, pp);
  EXPECT_TRUE(map.photons.empty());
  // Stopped by the rate, long before the 6.4M paths the budget allows.
  EXPECT_LT(map.emittedPaths, 2 * kReachProbePaths);
  ASSERT_EQ(map.darkLights.size(), 1u);
  EXPECT_NE(map.darkLights[0].find("spot light 'cellar' at (0.25, -0.5, 0.25)"),
            std::string::npos)
      << map.darkLights[0];
  try {
    bake(scene, test::smallBake(4, 100000));
    FAIL() << "a bake whose one light reaches nothing must fail";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("spot light 'cellar'"), std::string::npos) << e.what();
  }
}

TEST(LightReach, ATargetBakeLeavesADarkLightOutAndKeepsTheOthersLight) {
  BakeParams p;
  p.depth = 4;
  p.targetError = 0.1;
  const BakeResult plain = bake(cornellBox(), p);
  Scene scene = cornellBox();
  scene.lights.push_back(spotUnderTheFloor());
  const BakeResult withSpot = bake(scene, p);
  ASSERT_EQ(withSpot.stats.darkLights.size(), 1u);
  EXPECT_NE(withSpot.stats.darkLights[0].find("'cellar'"), std::string::npos);
  EXPECT_NE(photonBudgetWarning(p, withSpot.stats).find("'cellar'"), std::string::npos);
  EXPECT_TRUE(plain.stats.darkLights.empty());
  EXPECT_EQ(withSpot.stats.targetStop, "target reached");
  // The spot carries most of the power (its paths were most of the
  // pilot's); left out, the passes after the pilot trace as many paths as
  // the box alone needs, and the light is the box's.
  EXPECT_LT(withSpot.stats.emittedPaths, 2 * plain.stats.emittedPaths);
  const double a = meanIrradiance(plain.grid), b = meanIrradiance(withSpot.grid);
  EXPECT_NEAR(b / a, 1.0, 0.03) << "box alone " << a << ", with the dark spot " << b;
}

}  // namespace
}  // namespace lo
