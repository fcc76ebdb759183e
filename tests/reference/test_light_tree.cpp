// The light tree (reference/light_tree.h): its probabilities cover exactly
// the lights that can light a point (the rest of the unit is draws that
// find none: a node whose bound is positive over lights that all turn out
// dark there), its draws follow them, and importance over probability
// estimates the lights' summed irradiance without bias.

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/rng.h"
#include "reference/light_tree.h"

namespace lo {
namespace {

/// `count` point and spot lights over the box [-5, 5] x [0.1, 3] x [-5, 5]
/// (some of them below the test points' horizon, some spots turned away,
/// some with a range), two of them at one place, and two directional lights.
std::vector<Light> mixedLights(int count) {
  std::vector<Light> lights;
  Rng rng(7, 0);
  for (int i = 0; i < count; ++i) {
    Light l;
    l.type = i % 5 == 0 ? Light::Type::Spot : Light::Type::Point;
    l.position = {rng.uniform() * 10 - 5, rng.uniform() * 2.9f + 0.1f, rng.uniform() * 10 - 5};
    if (i == 1) l.position = lights[0].position;
    l.direction = normalize(Vec3{rng.uniform() - 0.5f, -1.0f, rng.uniform() - 0.5f});
    if (i % 15 == 0) l.direction = -l.direction;  // a spot lighting the ceiling only
    l.intensity = 0.1f + rng.uniform() * 4;
    l.color = {1.0f, rng.uniform(), rng.uniform()};
    l.range = i % 7 == 0 ? 2.0f : 0.0f;
    lights.push_back(l);
  }
  Light off;  // no power: never drawn
  off.intensity = 0;
  lights.push_back(off);
  for (const Vec3& d : {Vec3{0.3f, -1, 0.2f}, Vec3{0, 1, 0}}) {  // the second shines upwards
    Light sun;
    sun.type = Light::Type::Directional;
    sun.direction = normalize(d);
    sun.intensity = 2.0f;
    lights.push_back(sun);
  }
  return lights;
}

struct Point {
  Vec3 p, n;
};

std::vector<Point> testPoints() {
  return {{{0, 0, 0}, {0, 1, 0}},
          {{3, 1, -2}, normalize(Vec3{-1, 0.2f, 0.5f})},
          {{-4.5f, 2.5f, 4}, normalize(Vec3{1, -1, 0})},
          {{0.5f, 1.5f, 0.5f}, {0, -1, 0}}};
}

TEST(LightTree, ProbabilitiesCoverExactlyTheLightsThatCanLightThePoint) {
  const std::vector<Light> lights = mixedLights(300);
  const LightTree tree(lights);
  EXPECT_EQ(tree.size(), 302u);  // the light without power is not in it
  for (const Point& q : testPoints()) {
    double sum = 0;
    int lit = 0;
    for (uint32_t i = 0; i < lights.size(); ++i) {
      const float pmf = tree.pmf(q.p, q.n, i);
      const float importance = LightTree::importance(lights[i], q.p, q.n);
      // Every light that can light the point can be drawn; no point or spot
      // light that cannot (importance 0: behind the surface, outside its cone
      // or range). A directional light is drawn by its power alone.
      if (importance > 0) {
        EXPECT_GT(pmf, 0.0f) << "light " << i << " at " << q.p.ToString();
      } else if (lights[i].type != Light::Type::Directional) {
        EXPECT_EQ(pmf, 0.0f) << "light " << i << " at " << q.p.ToString();
      }
      lit += importance > 0;
      sum += pmf;
    }
    EXPECT_GT(lit, 10);
    EXPECT_LE(sum, 1.0 + 1e-5) << "at " << q.p.ToString();
    EXPECT_GT(sum, 0.5) << "at " << q.p.ToString();  // 0.82 to 0.97 measured
  }
}

TEST(LightTree, DrawsFollowTheProbabilitiesAndEstimateTheIrradianceWithoutBias) {
  const std::vector<Light> lights = mixedLights(300);
  const LightTree tree(lights);
  constexpr int kDraws = 200000;
  for (const Point& q : testPoints()) {
    std::vector<int> drawn(lights.size(), 0);
    double estimate = 0, exact = 0, covered = 0;
    int none = 0;
    for (int k = 0; k < kDraws; ++k) {
      uint32_t light = 0;
      float pmf = 0;
      if (!tree.sample(q.p, q.n, (k + 0.5) / kDraws, light, pmf)) {
        ++none;  // counts as 0
        continue;
      }
      ASSERT_LT(light, lights.size());
      EXPECT_FLOAT_EQ(pmf, tree.pmf(q.p, q.n, light));
      ++drawn[light];
      estimate += LightTree::importance(lights[light], q.p, q.n) / pmf;
    }
    for (uint32_t i = 0; i < lights.size(); ++i) {
      exact += LightTree::importance(lights[i], q.p, q.n);
      covered += tree.pmf(q.p, q.n, i);
      // Stratified u: each light's count is its probability's share to
      // within the strata a leaf's interval can cut, a few draws.
      EXPECT_NEAR(drawn[i], double(tree.pmf(q.p, q.n, i)) * kDraws, 2.0 + 1e-3 * kDraws)
          << "light " << i;
    }
    EXPECT_NEAR(none, (1.0 - covered) * kDraws, 2.0 + 1e-3 * kDraws);
    EXPECT_NEAR(estimate / kDraws, exact, 5e-3 * exact) << "at " << q.p.ToString();
  }
}

TEST(LightTree, APointThatNoLightReachesDrawsNone) {
  std::vector<Light> lights;
  for (int i = 0; i < 20; ++i) {
    Light l;
    l.position = {float(i), 2.0f, 0};
    lights.push_back(l);
  }
  const LightTree tree(lights);
  uint32_t light = 0;
  float pmf = 0;
  // Facing down under lights that are all above it.
  EXPECT_FALSE(tree.sample({3, 0, 0}, {0, -1, 0}, 0.5, light, pmf));
  EXPECT_TRUE(tree.sample({3, 0, 0}, {0, 1, 0}, 0.5, light, pmf));
  EXPECT_TRUE(LightTree().empty());
}

}  // namespace
}  // namespace lo
