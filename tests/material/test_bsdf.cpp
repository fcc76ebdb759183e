// The tracers' material (material/bsdf.h): what sampleBsdf draws agrees with
// what evalBsdf and pdfBsdf say, and the smooth lobes are the GL renderer's
// glTF BRDF (material/gltf_brdf.h, the C++ build of shaders/material_brdf.h).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/rng.h"
#include "material/bsdf.h"
#include "material/gltf_brdf.h"
#include "test_util.h"

namespace lo {
namespace {

Vec3 viewAt(float thetaDegrees) {
  const float t = thetaDegrees * kPi / 180.0f;
  return {std::sin(t), 0.0f, std::cos(t)};
}

BsdfLobes lobesOf(float metallic, float roughness, float ior = 1.5f, float specular = 1.0f) {
  Material m;
  m.metallic = metallic;
  m.roughness = roughness;
  m.ior = ior;
  m.specular = specular;
  return bsdfLobes(m);
}

/// Integral of evalBsdf over the hemisphere around +z (the directional
/// albedo seen from wo), and of pdfBsdf (how much of the sampling density
/// the smooth lobes hold). Midpoint rule in (cos^2 theta, phi), fine enough
/// for lobes from roughness 0.3 on.
void integrate(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, Vec3& f, double& pdf) {
  const Vec3 n(0, 0, 1);
  const int steps = 768;
  Vec3d sum(0, 0, 0);
  double pdfSum = 0;
  // d(omega) = d(u1) d(phi) / (2 z): the cosine grid's solid angle.
  test::forCosineGrid(steps, [&](const Vec3& wi, float z) {
    sum = sum + Vec3d(evalBsdf(lobes, albedo, wo, wi, n) / z);
    pdfSum += pdfBsdf(lobes, albedo, wo, wi, n) / z;
  });
  const double scale = kPi / double(steps) / double(steps);
  f = {float(sum.x * scale), float(sum.y * scale), float(sum.z * scale)};
  pdf = pdfSum * scale;
}

/// The mean of sampleBsdf's weight over `count` samples (lost samples
/// count as zero): an unbiased estimate of the directional albedo; `kept`
/// the share of samples not lost.
Vec3 sampledAlbedo(const BsdfLobes& lobes, const Vec3& albedo, const Vec3& wo, int count,
                   double& kept) {
  const Vec3 n(0, 0, 1);
  Rng rng(7, 11);
  Vec3d sum(0, 0, 0);
  int success = 0;
  for (int i = 0; i < count; ++i) {
    BsdfSample s;
    if (sampleBsdf(lobes, albedo, wo, n, true, rng, s)) {
      sum = sum + Vec3d(s.weight);
      ++success;
    }
  }
  kept = double(success) / count;
  return {float(sum.x / count), float(sum.y / count), float(sum.z / count)};
}

TEST(Bsdf, HandBuiltLobesAreLambertExactly) {
  // DirectIrradiance's probe: no specular layer, every sample weighs the albedo.
  BsdfLobes lambert;
  const Vec3 albedo(0.7f, 0.5f, 0.2f);
  Rng rng(3, 4);
  for (int i = 0; i < 100; ++i) {
    BsdfSample s;
    ASSERT_TRUE(sampleBsdf(lambert, albedo, viewAt(40), Vec3(0, 0, 1), true, rng, s));
    EXPECT_EQ(s.weight.x, albedo.x);
    EXPECT_EQ(s.weight.z, albedo.z);
    const Vec3 wi = normalize(s.wi);
    EXPECT_NEAR(evalBsdf(lambert, albedo, viewAt(40), wi, Vec3(0, 0, 1)).x,
                albedo.x * wi.z / kPi, 1e-6f);
  }
}

// What a surface reflects of the light falling on it: a Lambert base alone
// its albedo; with the specular layer, more towards white; a metal its
// Schlick mean; no lobe more than all of the light.
TEST(Bsdf, HemisphericalReflectanceOfEachLobe) {
  const Vec3 albedo{0.7f, 0.3f, 0.05f};
  BsdfLobes lambert;  // hand-built: a Lambert base without a specular layer
  EXPECT_EQ(hemisphericalReflectance(lambert, albedo), albedo);
  Material m;
  m.baseColor = albedo;
  m.roughness = 0.5f;
  const Vec3 layered = hemisphericalReflectance(bsdfLobes(m), albedo);
  const float f = 0.04f + 0.96f / 21.0f;  // the Schlick mean of F0 = 0.04
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(layered[c], albedo[c] * (1 - f) + f, 1e-5f);
  m.metallic = 1;
  const Vec3 metal = hemisphericalReflectance(bsdfLobes(m), albedo);
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(metal[c], albedo[c] + (1 - albedo[c]) / 21.0f, 1e-5f);
  m.baseColor = Vec3(1.0f);
  m.metallic = 0;
  for (float transmission : {0.0f, 0.5f, 1.0f}) {
    m.transmission = transmission;
    const Vec3 r = hemisphericalReflectance(bsdfLobes(m), m.baseColor);
    EXPECT_LE(maxComponent(r), 1.0f + 1e-6f);
    EXPECT_GT(std::min({r.x, r.y, r.z}), 0.0f);
  }
}

TEST(Bsdf, SmoothLobesAreTheRenderersGltfBrdf) {
  // f cos of the tracers = the GL BRDF's f cos, lobe by lobe, on random
  // directions: the dielectric at metallic 0, the metal at metallic 1, and
  // the specification's mix in between.
  Rng rng(5, 6);
  for (int i = 0; i < 2000; ++i) {
    const float metallic = i % 3 == 0 ? 0.0f : i % 3 == 1 ? 1.0f : rng.uniform();
    const float roughness = 0.05f + 0.95f * rng.uniform();
    // KHR_materials_ior and KHR_materials_specular: the layer's F0 and weight.
    const float ior = 1.0f + 2.0f * rng.uniform(), specular = i % 5 == 0 ? 0.0f : rng.uniform();
    const float f0 = (ior - 1) * (ior - 1) / ((ior + 1) * (ior + 1));
    const Vec3 albedo(rng.uniform(), rng.uniform(), rng.uniform());
    const Vec3 n(0, 0, 1);
    Vec3 wo = normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() + 0.05f));
    Vec3 wi = normalize(Vec3(rng.uniform() - 0.5f, rng.uniform() - 0.5f, rng.uniform() + 0.05f));
    const Vec3 tracer = evalBsdf(lobesOf(metallic, roughness, ior, specular), albedo, wo, wi, n);
    const Vec3 gl = gltfBrdfCos({albedo, metallic, roughness, 0.0f, f0, specular}, n, wo, wi);
    SCOPED_TRACE("metallic " + std::to_string(metallic) + ", roughness " +
                 std::to_string(roughness));
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(tracer[c], gl[c], 1e-5f + 1e-4f * std::fabs(gl[c]));
  }
}

TEST(Bsdf, SamplingAgreesWithEvaluation) {
  // The mean sample weight (what a path's throughput gains) equals the
  // integral of f cos (white furnace per lobe), and the density the smooth
  // lobes report integrates to the share of samples not lost below the
  // surface (GGX): sampleBsdf, evalBsdf and pdfBsdf describe one
  // distribution. 400,000 samples: 3-sigma below 1%.
  const Vec3 albedo(0.9f, 0.6f, 0.3f);
  for (float metallic : {0.0f, 1.0f, 0.5f}) {
    for (float roughness : {0.3f, 0.6f, 1.0f}) {
      for (float theta : {0.0f, 45.0f, 75.0f}) {
        SCOPED_TRACE("metallic " + std::to_string(metallic) + ", roughness " +
                     std::to_string(roughness) + ", view " + std::to_string(theta));
        // A glass-like ior and half the layer's weight where the metal is half.
        const BsdfLobes lobes = metallic == 0.5f ? lobesOf(metallic, roughness, 2.2f, 0.5f)
                                                 : lobesOf(metallic, roughness);
        Vec3 integral;
        double pdf = 0;
        integrate(lobes, albedo, viewAt(theta), integral, pdf);
        double kept = 0;
        const Vec3 sampled = sampledAlbedo(lobes, albedo, viewAt(theta), 400000, kept);
        for (int c = 0; c < 3; ++c) EXPECT_NEAR(sampled[c], integral[c], 0.01f * integral[c] + 2e-3f);
        // The midpoint rule misses up to 1% near the horizon, where the
        // rough lobes' density is steep in cos^2 theta.
        EXPECT_NEAR(pdf, kept, 0.012);
        EXPECT_LE(pdf, 1.0 + 2e-3);
      }
    }
  }
}

TEST(Bsdf, DielectricLayerReflectsMoreTowardsGrazingViews) {
  // The specular layer's Fresnel weight: a black dielectric reflects about
  // F0 = 0.04 head-on and several times more at a grazing view; without
  // the layer it reflects nothing.
  const Vec3 black(0, 0, 0);
  Vec3 headOn, grazing;
  double pdf = 0;
  integrate(lobesOf(0, 0.5f), black, viewAt(0), headOn, pdf);
  integrate(lobesOf(0, 0.5f), black, viewAt(80), grazing, pdf);
  EXPECT_NEAR(headOn.x, 0.04f, 0.01f);
  EXPECT_GT(grazing.x, 3 * headOn.x);
  BsdfLobes lambert;
  integrate(lambert, black, viewAt(80), grazing, pdf);
  EXPECT_EQ(grazing.x, 0.0f);
  // KHR_materials_specular 0: no layer either; a higher ior: a brighter one.
  integrate(lobesOf(0, 0.5f, 1.5f, 0.0f), black, viewAt(80), grazing, pdf);
  EXPECT_EQ(grazing.x, 0.0f);
  Vec3 dense;
  integrate(lobesOf(0, 0.5f, 2.5f), black, viewAt(0), dense, pdf);
  EXPECT_NEAR(dense.x, 0.18f, 0.03f);  // F0 = (1.5 / 3.5)^2 = 0.184
}

}  // namespace
}  // namespace lo
