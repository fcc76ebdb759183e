// The C++ build of the renderer's BRDF (shaders/material_brdf.h): energy
// checks over the hemisphere (white furnace). The GLSL build is compared with
// this one in tests/render/test_shader_twins.cpp.

#include <gtest/gtest.h>

#include <cmath>

#include "material/gltf_brdf.h"
#include "test_util.h"

namespace lo {
namespace {

/// Integral of gltfBrdfCos(v, l) over the hemisphere of l around +z:
/// the directional albedo for the view direction `v`. Midpoint rule on a
/// cosine-weighted grid (l = (r cos phi, r sin phi, sqrt(1 - r^2)), r^2
/// uniform): the integral is pi times the mean of f = brdfCos / cos.
Vec3 albedo(const GltfBrdfMaterial& m, const Vec3& v, bool specular, int steps) {
  const Vec3 n(0, 0, 1);
  Vec3d sum(0, 0, 0);
  test::forCosineGrid(steps, [&](const Vec3& l, float z) {
    sum = sum + Vec3d(gltfBrdfCos(m, n, v, l, specular) / z);
  });
  const double scale = kPi / double(steps) / double(steps);
  return {float(sum.x * scale), float(sum.y * scale), float(sum.z * scale)};
}

Vec3 viewAt(float thetaDegrees) {
  const float t = thetaDegrees * kPi / 180.0f;
  return {std::sin(t), 0.0f, std::cos(t)};
}

TEST(GltfBrdf, DiffuseLobeAloneIntegratesToItsAlbedo) {
  // Specular off: baseColor (1 - metallic)(1 - transmission) / pi (n.l),
  // whose hemisphere integral is baseColor (1 - metallic)(1 - transmission).
  for (float metallic : {0.0f, 0.3f, 1.0f}) {
    for (float transmission : {0.0f, 0.5f}) {
      GltfBrdfMaterial m;
      m.baseColor = Vec3(0.9f, 0.5f, 0.1f);
      m.metallic = metallic;
      m.roughness = 0.4f;
      m.transmission = transmission;
      const Vec3 a = albedo(m, viewAt(30), false, 64);
      const Vec3 expected = m.baseColor * ((1 - metallic) * (1 - transmission));
      SCOPED_TRACE("metallic " + std::to_string(metallic) + ", transmission " +
                   std::to_string(transmission));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(a[c], expected[c], 1e-5f);
    }
  }
}

/// White base colour, the most the BRDF can reflect, at view angle theta.
float whiteAlbedo(float metallic, float roughness, float theta) {
  GltfBrdfMaterial m;
  m.baseColor = Vec3(1, 1, 1);
  m.metallic = metallic;
  m.roughness = roughness;
  // 512^2 directions resolve lobes from roughness 0.3 (alpha 0.09) to
  // better than 0.5%.
  return albedo(m, viewAt(theta), true, 512).x;
}

TEST(GltfBrdf, MetalAlbedoNeverExceedsOne) {
  // Single-scattering GGX loses energy with roughness and at grazing angles.
  float largest = 0;
  for (float roughness : {0.3f, 0.5f, 0.8f, 1.0f}) {
    for (float theta : {0.0f, 45.0f, 75.0f, 88.0f}) {
      SCOPED_TRACE("roughness " + std::to_string(roughness) + ", view " + std::to_string(theta) +
                   " deg");
      const float a = whiteAlbedo(1, roughness, theta);
      EXPECT_LE(a, 1.0f);
      EXPECT_GT(a, 0.3f);
      largest = std::max(largest, a);
    }
  }
  EXPECT_GT(largest, 0.9f);  // a smooth white metal reflects nearly everything
}

TEST(GltfBrdf, DielectricAlbedoExceedsOneOnlyTowardsGrazingViews) {
  // glTF's dielectric mix weights the diffuse lobe by 1 - F(v.h) per light
  // direction, not by what the specular lobe leaves for the view direction:
  // up to 30 degrees from the normal a white dielectric reflects at most
  // what it receives; further out the specular lobe's Fresnel rise is added
  // to a nearly whole diffuse lobe and the albedo exceeds 1 (measured for
  // roughness 0.3: 1.001 at 45 degrees, 1.025 at 60, 1.15 at 75, 1.32 at
  // 88; for roughness 0.8: 1.03 at 88). A limit of the renderer's BRDF
  // (docs/render.md), pinned here so that a change of the mix shows.
  for (float roughness : {0.3f, 0.5f, 0.8f, 1.0f}) {
    for (float theta : {0.0f, 15.0f, 30.0f}) {
      SCOPED_TRACE("roughness " + std::to_string(roughness) + ", view " + std::to_string(theta) +
                   " deg");
      const float a = whiteAlbedo(0, roughness, theta);
      EXPECT_LE(a, 1.0f);
      EXPECT_GT(a, 0.9f);  // the diffuse lobe takes nearly all the rest
    }
  }
  const float grazing = whiteAlbedo(0, 0.3f, 88.0f);
  EXPECT_GT(grazing, 1.2f);
  EXPECT_LT(grazing, 1.4f);
}

TEST(GltfBrdf, LobesCosineAndValueAgree) {
  // The functions are one BRDF: f = diffuse + specular, brdfCos = f (n.l),
  // zero below the surface; the specular weight scales the GGX lobe alone.
  GltfBrdfMaterial m;
  m.baseColor = Vec3(0.2f, 0.6f, 0.9f);
  m.metallic = 0.4f;
  m.roughness = 0.35f;
  m.transmission = 0.25f;
  const Vec3 n(0, 0, 1);
  const Vec3 v = normalize(Vec3(0.3f, -0.2f, 0.9f));
  const Vec3 l = normalize(Vec3(-0.5f, 0.1f, 0.7f));
  const GltfBrdfLobes lobes = gltfBrdfLobes(m, n, v, l);
  const Vec3 f = gltfBrdf(m, n, v, l);
  const Vec3 weighted = gltfBrdfCos(m, n, v, l, true, 0.25f);
  for (int c = 0; c < 3; ++c) {
    EXPECT_FLOAT_EQ(f[c], lobes.diffuse[c] + lobes.specular[c]);
    EXPECT_FLOAT_EQ(gltfBrdfCos(m, n, v, l)[c], f[c] * l.z);
    EXPECT_FLOAT_EQ(weighted[c], (lobes.diffuse[c] + 0.25f * lobes.specular[c]) * l.z);
    EXPECT_GT(lobes.specular[c], 0.0f);
  }
  const Vec3 below(l.x, l.y, -l.z);
  EXPECT_EQ(gltfBrdf(m, n, v, below).x, 0.0f);
  EXPECT_EQ(gltfBrdfCos(m, n, v, below).x, 0.0f);
}

}  // namespace
}  // namespace lo
