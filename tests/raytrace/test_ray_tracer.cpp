// The ray tracer: alpha modes of the material seen by closest-hit and
// shadow rays alike.

#include "raytrace/ray_tracer.h"

#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <string>

#include "core/error.h"
#include "core/resources.h"

#include "test_util.h"

namespace lo {
namespace {

/// A unit quad in z = 0 (normal +z) whose UVs run u = x, v = y over [0, 1]^2,
/// with one material; the scene's only geometry.
Scene alphaQuad(const Material& material, const Texture* texture) {
  Scene scene;
  scene.materials.push_back(material);
  if (texture) {
    scene.textures.push_back(*texture);
    scene.materials[0].baseColorTexture = 0;
  }
  test::addQuad(scene, {0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, 0);
  for (const Vec3& p : scene.positions) {
    scene.texcoords0.push_back(p.x);
    scene.texcoords0.push_back(p.y);
  }
  return scene;
}

// Alpha MASK in the tracer: a ray through the cut-out half passes, one
// through the opaque half hits; the same for shadow rays.
TEST(RayTracerAlpha, MaskCutsRaysThroughTransparentTexels) {
  Texture half = Texture::fromLinear(2, 1, {Vec3{1, 1, 1}, Vec3{1, 1, 1}},
                                     {0.0f, 1.0f});  // u < 0.5 cut out
  Material m;
  m.alphaMode = AlphaMode::Mask;
  const Scene scene = alphaQuad(m, &half);
  RayTracer tracer(scene);
  Hit hit;
  EXPECT_FALSE(tracer.intersect({0.25f, 0.5f, 1}, {0, 0, -1}, hit));
  EXPECT_FALSE(tracer.occluded({0.25f, 0.5f, 1}, {0, 0, -1}, 2));
  ASSERT_TRUE(tracer.intersect({0.75f, 0.5f, 1}, {0, 0, -1}, hit));
  EXPECT_NEAR(hit.t, 1.0f, 1e-5f);
  EXPECT_TRUE(tracer.occluded({0.75f, 0.5f, 1}, {0, 0, -1}, 2));
  // Opaque mode ignores the alpha.
  Scene opaque = scene;
  opaque.materials[0].alphaMode = AlphaMode::Opaque;
  EXPECT_TRUE(RayTracer(opaque).intersect({0.25f, 0.5f, 1}, {0, 0, -1}, hit));
}

// Alpha BLEND in the tracer: a share alpha of the rays hits, decided per
// ray (the same ray always decides the same way).
TEST(RayTracerAlpha, BlendStopsAlphaOfTheRays) {
  Material m;
  m.alphaMode = AlphaMode::Blend;
  m.baseAlpha = 0.3f;
  const Scene scene = alphaQuad(m, nullptr);
  RayTracer tracer(scene);
  const int n = 20000;
  int hits = 0, occluded = 0;
  for (int i = 0; i < n; ++i) {
    const float x = (float(i % 200) + 0.5f) / 200.0f, y = (float(i / 200) + 0.5f) / 100.0f;
    Hit hit;
    const bool h = tracer.intersect({x, y, 1}, {0.01f, 0, -1}, hit);
    hits += h ? 1 : 0;
    occluded += tracer.occluded({x, y, 1}, {0.01f, 0, -1}, 2) ? 1 : 0;
    ASSERT_EQ(h, tracer.intersect({x, y, 1}, {0.01f, 0, -1}, hit)) << "ray " << i;
  }
  const double sigma = std::sqrt(0.3 * 0.7 / n);
  EXPECT_NEAR(double(hits) / n, 0.3, 4 * sigma);
  EXPECT_EQ(hits, occluded) << "closest-hit and shadow rays agree ray by ray";
}

// Rays Embree cannot take (a coordinate of the origin or the direction
// beyond its +-1.8e18, or not finite) meet nothing; they aborted the process
// inside Embree (a gather radius of 1e19). A ray within them still hits.
TEST(RayTracer, RaysBeyondWhatEmbreeTakesMeetNothing) {
  Scene scene = test::oneMaterialScene();
  test::addQuad(scene, {-1, -1, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 1}, 0);
  const RayTracer tracer(scene);
  Hit hit;
  ASSERT_TRUE(tracer.intersect({0, 0, 1}, {0, 0, -1}, hit, 10.0f));
  ASSERT_TRUE(tracer.occluded({0, 0, 1}, {0, 0, -1}, 10.0f));
  const float huge = 1e19f, nan = std::nanf("");
  for (const Vec3& org : {Vec3{0, 0, huge}, Vec3{nan, 0, 1}, Vec3{0, 0, INFINITY}}) {
    EXPECT_FALSE(tracer.intersect(org, {0, 0, -1}, hit, INFINITY));
    EXPECT_FALSE(tracer.occluded(org, {0, 0, -1}, INFINITY));
  }
  EXPECT_FALSE(tracer.intersect({0, 0, 1}, {0, 0, -huge}, hit, INFINITY));
  EXPECT_FALSE(tracer.occluded({0, 0, 1}, {0, 0, -huge}, INFINITY));
  EXPECT_FALSE(tracer.occluded({0, 0, 1}, {nan, 0, -1}, 10.0f));
}

// Under an address-space limit (ulimit -v) Embree's failure said only
// "rtcNewDevice failed (error 4)", a broken invariant: it is memory, and the
// message says so and names the limit. (Not under AddressSanitizer, whose
// shadow memory is terabytes of address space already mapped.)
TEST(RayTracer, OutOfMemoryUnderAnAddressSpaceLimitIsSaid) {
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer";
#endif
  Material m;
  const Scene scene = alphaQuad(m, nullptr);
  // 1 MiB more than is mapped now.
  const std::optional<std::string> limited =
      test::messageUnderAddressSpaceLimit(size_t(1) << 20, [&] { RayTracer tracer(scene); });
  if (!limited) GTEST_SKIP() << "the address space is limited already";
  const std::string& message = *limited;
  EXPECT_NE(message.find("out of memory: the ray tracer (Embree) could not"), std::string::npos)
      << message;
  EXPECT_NE(message.find("(ulimit -v)"), std::string::npos) << message;
}

}  // namespace
}  // namespace lo
