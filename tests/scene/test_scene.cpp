// Tests of src/scene on real scenes: the project's Cornell box (a measured
// room) and the shared scenes, glTF and OBJ. The loader's features are
// tested on files written in code in test_scene_*.cpp.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "scene/scene.h"
#include "scene/scene_fixture.h"
#include "test_util.h"

namespace lo {
namespace {

namespace fs = std::filesystem;

using namespace test;  // scene_fixture.h

/// The scene's emissive materials (a Cornell box has one: the light's).
std::vector<const Material*> emissiveMaterials(const Scene& s) {
  std::vector<const Material*> out;
  for (const Material& m : s.materials) {
    if (m.isEmissive()) out.push_back(&m);
  }
  return out;
}

TEST(SceneCornellBox, LoadsMeasuredRoom) {
  Scene s = loadScene(test::dataDir() + "/cornell-box.gltf");
  SCOPED_TRACE(s.ToString());
  EXPECT_EQ(s.triangleCount(), 32u);

  const std::vector<const Material*> emissive = emissiveMaterials(s);
  EXPECT_EQ(emissive.size(), 1u);
  for (const Material* m : emissive) {
    expectNear(m->emission, {17, 12, 4}, 1e-4f, "light radiance");
    expectNear(m->baseColor, {0.78f, 0.78f, 0.78f}, 1e-6f, "light albedo");
  }

  ASSERT_EQ(s.cameras.size(), 1u);
  const Camera& cam = s.cameras[0];
  EXPECT_EQ(cam.name, "cornell_camera");
  EXPECT_NEAR(cam.yfov, 2.0f * std::atan(12.5f / 35.0f), 1e-6f);
  EXPECT_NEAR(cam.aspectRatio, 1.0f, 1e-6f);
  expectNear(cam.position, {0, 0.273f, 0.8f}, 1e-6f, "camera position");
  expectNear(cam.forward, {0, 0, -1}, 1e-6f, "camera forward");
  expectNear(cam.up, {0, 1, 0}, 1e-6f, "camera up");

  Bounds3 b = s.bounds();
  expectNear(b.extent(), {0.556f, 0.5488f, 0.5592f}, 1e-5f, "room size");
  EXPECT_NEAR(b.center().x, 0.0f, 1e-5f);
  EXPECT_NEAR(b.lower.y, 0.0f, 1e-6f);
  EXPECT_NEAR(b.upper.z, 0.0f, 1e-6f);  // the open side at z = 0, facing the camera

  ASSERT_EQ(s.normals.size(), s.positions.size());
  const Vec3 room = b.center();
  int floor = 0, ceiling = 0, red = 0, green = 0, back = 0, light = 0, blocks = 0;
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    Vec3 n = s.faceNormal(t);
    const Vec3& p0 = s.positions[s.indices[3 * t]];
    const Vec3& p1 = s.positions[s.indices[3 * t + 1]];
    const Vec3& p2 = s.positions[s.indices[3 * t + 2]];
    Vec3 c = (p0 + p1 + p2) / 3.0f;
    for (int k = 0; k < 3; ++k) {
      EXPECT_GT(dot(s.normals[s.indices[3 * t + size_t(k)]], n), 0.9999f) << "triangle " << t;
    }
    const Material& m = s.materials[size_t(s.triangleMaterial[t])];
    float ymax = std::max({p0.y, p1.y, p2.y}), ymin = std::min({p0.y, p1.y, p2.y});
    if (m.isEmissive()) {
      ++light;
      EXPECT_LT(dot(n, {0, 1, 0}), -0.99f) << "light must face down";
      EXPECT_NEAR(c.y, 0.5483f, 1e-6f);
    } else if (m.name == "red") {
      ++red;
      EXPECT_GT(dot(n, {1, 0, 0}), 0.99f) << "red wall faces +x (inside)";
      EXPECT_LT(c.x, -0.27f) << "red wall is on the left of the camera";
    } else if (m.name == "green") {
      ++green;
      EXPECT_GT(dot(n, {-1, 0, 0}), 0.99f);
      EXPECT_GT(c.x, 0.27f);
    } else if (ymax < 1e-6f) {
      ++floor;
      EXPECT_GT(dot(n, {0, 1, 0}), 0.99f) << "floor faces up";
    } else if (ymin > 0.5487f) {
      ++ceiling;
      EXPECT_GT(dot(n, {0, -1, 0}), 0.99f) << "ceiling faces down";
    } else if (c.z < -0.559f) {
      ++back;
      EXPECT_GT(dot(n, {0, 0, 1}), 0.99f) << "back wall faces the camera";
    } else {
      ++blocks;
      // Block faces point away from the block's vertical axis (or up for the top).
      bool tall = ymax > 0.2f;
      Vec3 axis = tall ? Vec3{-0.0905f, 0, -0.3512f} : Vec3{0.0925f, 0, -0.169f};
      Vec3 away = c - Vec3{axis.x, c.y, axis.z};
      if (ymin == ymax) {
        EXPECT_GT(n.y, 0.99f) << "block top faces up";
      } else {
        EXPECT_GT(dot(n, normalize(away)), 0.5f) << "block side faces out, triangle " << t;
      }
      EXPECT_GT(dot(n, room - c), -1.0f);  // (finite)
    }
  }
  EXPECT_EQ(floor, 2);
  EXPECT_EQ(ceiling, 2);
  EXPECT_EQ(back, 2);
  EXPECT_EQ(red, 2);
  EXPECT_EQ(green, 2);
  EXPECT_EQ(light, 2);
  EXPECT_EQ(blocks, 20);
}

TEST(SceneShared, ComposedCornellBoxGlb) {
  std::string path = test::sharedScenesDir() + "/composed/cornell-box.glb";
  if (!fs::exists(path)) GTEST_SKIP() << "missing " << path;
  Scene s = loadScene(path);
  EXPECT_EQ(s.triangleCount(), 32u);
  const std::vector<const Material*> emissive = emissiveMaterials(s);
  EXPECT_EQ(emissive.size(), 1u);
  for (const Material* m : emissive) {
    // emissiveFactor (1, 12/17, 4/17) x KHR_materials_emissive_strength 17.
    expectNear(m->emission, {17.0f, 12.0f, 4.0f}, 1e-4f, "emissive strength 17");
  }
  ASSERT_FALSE(s.cameras.empty());
  expectNear(s.cameras[0].position, {0, 1, 3.9f}, 1e-5f, "camera");
  Bounds3 b = s.bounds();
  EXPECT_NEAR(b.lower.x, -1.0f, 0.05f);
  EXPECT_NEAR(b.upper.y, 1.99f, 0.01f);
}

TEST(SceneShared, CornellBoxObj) {
  std::string path = test::sharedScenesDir() + "/cornell-box/CornellBox-Original.obj";
  if (!fs::exists(path)) GTEST_SKIP() << "missing " << path;
  Scene s = loadScene(path);
  SCOPED_TRACE(s.ToString());
  EXPECT_GE(s.triangleCount(), 30u);
  const std::vector<const Material*> emissive = emissiveMaterials(s);
  EXPECT_EQ(emissive.size(), 1u);
  for (const Material* m : emissive) {
    EXPECT_EQ(m->name, "light");
    expectNear(m->emission, {17, 12, 4}, 1e-5f, "Ke");
    expectNear(m->baseColor, {0.78f, 0.78f, 0.78f}, 1e-6f, "Kd");
  }
  for (const Material& m : s.materials) {
    if (m.name == "leftWall") {
      expectNear(m.baseColor, {0.63f, 0.065f, 0.05f}, 1e-6f, "Kd");
      EXPECT_FLOAT_EQ(m.roughness, 1.0f);  // Ks 0 0 0: diffuse
      EXPECT_FLOAT_EQ(m.specular, 0.0f);   // and no specular layer
      EXPECT_FLOAT_EQ(m.ior, 1.5f);        // Ni 1.5
      EXPECT_FLOAT_EQ(m.transmission, 0.0f);
    }
  }
  // Faces are grouped by material.
  for (size_t t = 1; t < s.triangleCount(); ++t)
    EXPECT_GE(s.triangleMaterial[t], s.triangleMaterial[t - 1]);
  // The floor (y = 0) faces up: the OBJ's winding is kept.
  for (size_t t = 0; t < s.triangleCount(); ++t) {
    const Vec3& a = s.positions[s.indices[3 * t]];
    const Vec3& b = s.positions[s.indices[3 * t + 1]];
    const Vec3& c = s.positions[s.indices[3 * t + 2]];
    if (std::max({a.y, b.y, c.y}) < 1e-6f) {
      EXPECT_GT(s.faceNormal(t).y, 0.99f);
    }
  }
}

TEST(SceneShared, CornellBoxGltfMatchesObj) {
  std::string dir = test::sharedScenesDir() + "/cornell-box/";
  if (!fs::exists(dir + "CornellBox-Original.gltf")) GTEST_SKIP();
  Scene g = loadScene(dir + "CornellBox-Original.gltf");
  Scene o = loadScene(dir + "CornellBox-Original.obj");
  expectNear(g.bounds().lower, o.bounds().lower, 1e-5f, "lower");
  expectNear(g.bounds().upper, o.bounds().upper, 1e-5f, "upper");
  // (Areas differ: the OBJ holds two duplicated quads, see MANIFEST.md.)
  EXPECT_EQ(emissiveMaterials(g).size(), 1u);
}

}  // namespace
}  // namespace lo
