// What the scene shader shares with C++ agrees in both builds: the BRDF
// (shaders/material_brdf.h, material/gltf_brdf.h), the light block's std140
// layout (shaders/render_lights.h); and the renderer's VPLs carry the power
// of the tracers' emitter sampler.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <random>
#include <string>

#include "material/gltf_brdf.h"
#include "render/light_list.h"
#include "render/shader_probes.h"
#include "scene/emitter_sampler.h"
#include "test_util.h"

namespace lo {
namespace {

#define REQUIRE_OSMESA()                                                       \
  do {                                                                         \
    if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available"; \
  } while (0)

Vec3 randomUnit(std::mt19937& rng) {
  std::normal_distribution<float> g;
  for (;;) {
    const Vec3 d(g(rng), g(rng), g(rng));
    if (length(d) > 1e-3f) return normalize(d);
  }
}

/// Random BRDF inputs: v in n's hemisphere, l anywhere (a quarter below the
/// surface: the zero branch), materials over their whole ranges, with some
/// exact 0 and 1 values (mirrors, metals, glass).
std::vector<BrdfProbeInput> randomInputs(int count) {
  std::mt19937 rng(23);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<BrdfProbeInput> inputs;
  for (int i = 0; i < count; ++i) {
    BrdfProbeInput in;
    in.n = randomUnit(rng);
    in.v = randomUnit(rng);
    if (dot(in.v, in.n) < 0) in.v = -in.v;
    in.l = randomUnit(rng);
    if (i % 4 != 0 && dot(in.l, in.n) < 0) in.l = -in.l;
    in.baseColor = Vec3(u(rng), u(rng), u(rng));
    auto value = [&](int k) { return i % 7 == k ? 0.0f : (i % 11 == k ? 1.0f : u(rng)); };
    in.metallic = value(1);
    in.roughness = value(2);
    in.transmission = value(3);
    in.specularWeight = value(4);
    // The dielectric layer: F0 of an ior from 1 to 3 (0.04 at 1.5), weight
    // over [0, 1] with exact 0 and 1.
    const float ior = i % 5 == 0 ? 1.5f : 1.0f + 2.0f * u(rng);
    in.dielectricF0 = (ior - 1) * (ior - 1) / ((ior + 1) * (ior + 1));
    in.specular = value(5);
    inputs.push_back(in);
  }
  return inputs;
}

/// |a - b| within `relative` of the larger magnitude, or below `absolute`.
::testing::AssertionResult close(const char* what, size_t i, const Vec3& glsl, const Vec3& cpp,
                                 float relative, float absolute) {
  for (int c = 0; c < 3; ++c) {
    const float scale = std::max(std::fabs(glsl[c]), std::fabs(cpp[c]));
    if (!(std::fabs(glsl[c] - cpp[c]) <= std::max(relative * scale, absolute))) {
      return ::testing::AssertionFailure() << what << " of input " << i << ": GLSL "
                                           << glsl.ToString() << ", C++ " << cpp.ToString();
    }
  }
  return ::testing::AssertionSuccess();
}

TEST(RenderBrdf, GlslMatchesCpp) {
  REQUIRE_OSMESA();
  const std::vector<BrdfProbeInput> inputs = randomInputs(4000);
  const std::vector<BrdfProbeOutput> out = runBrdfProbe(inputs);
  ASSERT_EQ(out.size(), inputs.size());
  // The two builds run the same operations in float; they differ by the
  // rounding of pow, exp2, sqrt and normalize and by fused multiply-adds:
  // up to 7e-6 relative on llvmpipe. GGX's D = a^2 / (pi dd^2), dd =
  // 1 + nh^2 (a^2 - 1), turns an ulp of nh^2 into 2 ulp / dd of D: near the
  // peak of a sharp lobe dd is ~1e-4 and the specular lobe's tolerance
  // grows by that condition number (seen: 1.3e-4 at dd = 6e-3, 5.7e-4 at
  // dd = 9e-5, each within half of this bound).
  const float relative = 1e-5f, absolute = 1e-7f;
  auto specularRelative = [&](const BrdfProbeInput& in) {
    const float a = std::max(in.roughness * in.roughness, 2e-3f);
    const float nh = std::max(dot(in.n, normalize(in.l + in.v)), 0.0f);
    const float dd = nh * nh * (a * a - 1.0f) + 1.0f;
    return relative + 2e-6f / std::max(dd, 1e-12f);
  };
  int checked = 0;
  for (size_t i = 0; i < inputs.size(); ++i) {
    const BrdfProbeInput& in = inputs[i];
    GltfBrdfMaterial m;
    m.baseColor = in.baseColor;
    m.metallic = in.metallic;
    m.roughness = in.roughness;
    m.transmission = in.transmission;
    m.dielectricF0 = in.dielectricF0;
    m.specular = in.specular;
    const GltfBrdfLobes lobes = gltfBrdfLobes(m, in.n, in.v, in.l);
    const float withSpecular = specularRelative(in);
    EXPECT_TRUE(close("brdfCosWeighted", i, out[i].cosWeighted,
                      gltfBrdfCos(m, in.n, in.v, in.l, true, in.specularWeight), withSpecular,
                      absolute));
    EXPECT_TRUE(close("diffuse lobe", i, out[i].diffuse, lobes.diffuse, relative, absolute));
    EXPECT_TRUE(close("specular lobe", i, out[i].specular, lobes.specular, withSpecular, absolute));
    EXPECT_TRUE(close("environment BRDF", i, out[i].environment,
                      gltfEnvironmentBrdf(m, std::clamp(dot(in.n, in.v), 0.0f, 1.0f)), relative,
                      absolute));
    EXPECT_TRUE(
        close("brdf", i, out[i].brdf, gltfBrdf(m, in.n, in.v, in.l), withSpecular, absolute));
    EXPECT_TRUE(close("diffuse only", i, out[i].diffuseCos, gltfBrdfCos(m, in.n, in.v, in.l, false),
                      relative, absolute));
    EXPECT_FLOAT_EQ(out[i].alpha, std::max(in.roughness * in.roughness, 2e-3f));
    if (dot(in.n, in.l) > 0 && maxComponent(out[i].cosWeighted) > 0) ++checked;
    if (HasFailure()) break;  // one input's report is enough
  }
  EXPECT_GT(checked, 2000);  // most inputs are lit: the comparison is not of zeros
}

TEST(RenderLightBlock, GlLayoutMatchesCpp) {
  REQUIRE_OSMESA();
  using shader::GpuLight;
  using shader::LightBlock;
  EXPECT_EQ(lightBlockSize(), int(sizeof(LightBlock)));
  struct Member {
    std::string name;
    size_t offset;
  };
  std::vector<Member> members;
  for (int i : {0, 1, shader::LO_MAX_LIGHTS - 1}) {
    const size_t base = offsetof(LightBlock, uLights) + size_t(i) * sizeof(GpuLight);
    const std::string light = "uLights[" + std::to_string(i) + "].";
    members.push_back({light + "positionType", base + offsetof(GpuLight, positionType)});
    members.push_back({light + "directionRange", base + offsetof(GpuLight, directionRange)});
    members.push_back({light + "colorFar", base + offsetof(GpuLight, colorFar)});
    members.push_back({light + "params", base + offsetof(GpuLight, params)});
    members.push_back({light + "corner0", base + offsetof(GpuLight, corner0)});
    members.push_back({light + "corner1", base + offsetof(GpuLight, corner1)});
    members.push_back({light + "corner2", base + offsetof(GpuLight, corner2)});
  }
  members.push_back({"uShadowMatrices[0]", offsetof(LightBlock, uShadowMatrices)});
  members.push_back({"uLightCount", offsetof(LightBlock, uLightCount)});
  members.push_back({"uShadowParams", offsetof(LightBlock, uShadowParams)});
  members.push_back({"uAreaTriangles[0]", offsetof(LightBlock, uAreaTriangles)});
  std::vector<std::string> names;
  for (const Member& m : members) names.push_back(m.name);
  const std::vector<UniformLayout> layout = lightBlockLayout(names);
  ASSERT_EQ(layout.size(), members.size());
  for (size_t i = 0; i < members.size(); ++i) {
    SCOPED_TRACE(members[i].name);
    EXPECT_EQ(layout[i].offset, int(members[i].offset));
  }
  const UniformLayout& matrices = layout[layout.size() - 4];
  EXPECT_EQ(layout.back().arrayStride, 16);
  EXPECT_EQ(matrices.arrayStride, int(sizeof(glm::mat4)));
  EXPECT_EQ(matrices.matrixStride, 16);
}

/// A scene of emissive triangles: single-sided ones and double-sided ones
/// of other colours and sizes, plus a dark triangle.
Scene emitterScene() {
  Scene scene;
  auto addMaterial = [&](const Vec3& emission, bool doubleSided) {
    Material m;
    m.baseColor = Vec3(0.5f, 0.5f, 0.5f);
    m.emission = emission;
    m.doubleSided = doubleSided;
    scene.materials.push_back(m);
    return int(scene.materials.size()) - 1;
  };
  auto addTriangle = [&](const Vec3& a, const Vec3& b, const Vec3& c, int material) {
    const uint32_t first = uint32_t(scene.positions.size());
    for (const Vec3& p : {a, b, c}) scene.positions.push_back(p);
    for (uint32_t k = 0; k < 3; ++k) scene.indices.push_back(first + k);
    scene.triangleMaterial.push_back(material);
  };
  const int single = addMaterial(Vec3(4, 2, 1), false);
  const int twoSided = addMaterial(Vec3(1, 3, 5), true);
  const int dark = addMaterial(Vec3(0, 0, 0), false);
  for (int i = 0; i < 6; ++i) {
    const float x = float(i);
    addTriangle(Vec3(x, 0, 0), Vec3(x + 0.5f, 0, 0), Vec3(x, 0.5f + 0.1f * x, 0), single);
    addTriangle(Vec3(x, 2, 1), Vec3(x, 2.8f, 1), Vec3(x + 0.3f + 0.2f * x, 2, 1.5f), twoSided);
  }
  addTriangle(Vec3(0, 5, 0), Vec3(1, 5, 0), Vec3(0, 6, 0), dark);
  return scene;
}

TEST(RenderLights, VplPowerIsTheEmitterSamplersPower) {
  const Scene scene = emitterScene();
  const EmitterSampler sampler = buildEmitterSampler(scene);
  // The sampler's power, from the scene by hand: pi L A per emitting side
  // (L the mean of the emission's channels).
  double expected = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const Material& m = scene.materials[size_t(scene.triangleMaterial[t])];
    expected +=
        kPi * double(average(m.emission)) * scene.triangleArea(t) * (m.doubleSided ? 2.0 : 1.0);
  }
  ASSERT_NEAR(sampler.total(), expected, 1e-5 * expected);

  render_internal::RenderSpace space;
  space.origin = scene.bounds().center();
  space.sceneSize = length(scene.bounds().extent());
  for (int count : {1, 7, 16, 64}) {
    const std::vector<render_internal::GpuLight> vpls =
        render_internal::emitterVpls(scene, sampler, space, count);
    ASSERT_EQ(vpls.size(), size_t(count));
    // Each VPL is a one-sided Lambertian patch of intensity colorFar cos:
    // power pi colorFar.
    double power = 0;
    int front = 0, back = 0;
    for (const render_internal::GpuLight& l : vpls) {
      EXPECT_EQ(int(l.positionType.w), shader::LO_LIGHT_EMITTER);
      power += kPi * (double(l.colorFar.x) + l.colorFar.y + l.colorFar.z) / 3.0;
      // The double-sided emitters lie at z = 1..1.5, their normals along +x
      // (the front) or -x (the back).
      if (l.positionType.z + space.origin.z > 0.5f) {
        (l.directionRange.x > 0 ? front : back) += 1;
      }
    }
    SCOPED_TRACE(std::to_string(count) + " VPLs");
    EXPECT_NEAR(power, sampler.total(), 1e-5 * sampler.total());
    if (count >= 16) {
      EXPECT_GT(front, 0);
      EXPECT_GT(back, 0);
    }
  }
}

}  // namespace
}  // namespace lo
