// Photon tracing: analytic energy balances, determinism, light sampling.
//
// Tolerances are derived from the number of emitted paths: the per-path
// contribution of a bounce (or of the whole path) is a known discrete random
// variable, so its mean over N paths has a computable standard error; the
// checks allow 4 standard errors plus float slack and the at-most-one-path
// bias of truncating the last path.

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <vector>

#include "test_util.h"
#include "core/error.h"
#include "photon/light_footprint.h"
#include "photon/photon_map.h"

namespace lo {
namespace {

using test::addClosedBox;
using test::addQuad;
using test::pointLight;

struct Dvec3 {
  double v[3] = {0, 0, 0};
  void add(const Vec3& p) {
    v[0] += p.x;
    v[1] += p.y;
    v[2] += p.z;
  }
};

int addMaterial(Scene& scene, const Vec3& baseColor) {
  Material m;
  m.baseColor = baseColor;
  m.specular = 0;  // Lambert: the answers below are analytic for it
  m.name = "m" + std::to_string(scene.materials.size());
  scene.materials.push_back(m);
  return int(scene.materials.size()) - 1;
}

/// Closed cube [-1, 1]^3 facing in, of material 0: albedo `albedo`.
Scene closedBox(const Vec3& albedo) {
  Scene scene;
  int m = addMaterial(scene, albedo);
  addClosedBox(scene, {-1, -1, -1}, {1, 1, 1}, m);
  return scene;
}

/// closedBox with a point light in the centre.
Scene litBox(const Vec3& albedo, const Vec3& lightColor, float intensity) {
  Scene scene = closedBox(albedo);
  scene.lights.push_back(pointLight({0, 0, 0}, intensity, lightColor));
  return scene;
}

/// The 2 x 2 black floor (y = 0, facing up) of the sky and sun tests: every
/// photon stored where it lands.
Scene blackFloor() {
  Scene scene;
  int floor = addMaterial(scene, {0, 0, 0});
  addQuad(scene, {-1, 0, -1}, {2, 0, 0}, {0, 0, 2}, {0, 1, 0}, floor);
  return scene;
}

/// A clear, thin-walled glass material (KHR_materials_transmission); its index.
int addGlass(Scene& scene) {
  int glass = addMaterial(scene, {1, 1, 1});
  scene.materials[size_t(glass)].transmission = 1.0f;
  return glass;
}

/// Parameters storing `stored` photons, direct hits included.
PhotonParams withDirect(size_t stored) {
  PhotonParams params;
  params.storedPhotons = stored;
  params.includeDirect = true;
  return params;
}

/// Six outward-facing quads: a closed solid [lo, hi]^3.
void addSolidBox(Scene& scene, const Vec3& lo, const Vec3& hi, int material) {
  Vec3 d = hi - lo;
  Vec3 ex{d.x, 0, 0}, ey{0, d.y, 0}, ez{0, 0, d.z};
  addQuad(scene, lo, ex, ez, {0, -1, 0}, material);
  addQuad(scene, lo + ey, ex, ez, {0, 1, 0}, material);
  addQuad(scene, lo, ey, ez, {-1, 0, 0}, material);
  addQuad(scene, lo + ex, ey, ez, {1, 0, 0}, material);
  addQuad(scene, lo, ex, ey, {0, 0, -1}, material);
  addQuad(scene, lo + ez, ex, ey, {0, 0, 1}, material);
}

std::vector<Dvec3> powerPerBounce(const PhotonMap& map, int maxBounces) {
  std::vector<Dvec3> sums(size_t(maxBounces) + 1);
  for (const Photon& p : map.photons) {
    EXPECT_LE(p.bounce, uint32_t(maxBounces));
    if (p.bounce <= uint32_t(maxBounces)) sums[p.bounce].add(p.power);
  }
  return sums;
}

/// Per path, the stored power in one channel is phi * r^n at each of L hits,
/// n = 0..L-1, with r = a / q, survival q = min(1, max albedo), P(L > l) = q^l,
/// L <= K + 1. Returns the mean and the standard error over `paths` paths.
void pathTotalStats(double phi, double a, double q, int maxBounces, size_t paths, double& mean,
                    double& stdErr) {
  double r = a / q, e1 = 0, e2 = 0;
  for (int l = 1; l <= maxBounces + 1; ++l) {
    double pL = std::pow(q, l - 1) * (l <= maxBounces ? 1.0 - q : 1.0);
    double total = 0;
    for (int n = 0; n < l; ++n) total += phi * std::pow(r, n);
    e1 += pL * total;
    e2 += pL * total * total;
  }
  mean = e1;
  stdErr = std::sqrt(std::max(0.0, e2 - e1 * e1) / double(paths));
}

void checkClosedBoxEnergy(const Vec3& albedo) {
  const float intensity = 2.0f;
  const Vec3 color{1.0f, 0.7f, 0.4f};
  Scene scene = litBox(albedo, color, intensity);
  PhotonParams params = withDirect(200000);
  params.maxBounces = 16;
  params.seed = 7;
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  const size_t n = map.emittedPaths;
  const int k = params.maxBounces;
  std::vector<Dvec3> sums = powerPerBounce(map, k);
  const double q = std::min(1.0f, maxComponent(albedo));
  Dvec3 total;
  for (const Photon& p : map.photons) total.add(p.power);
  for (int c = 0; c < 3; ++c) {
    const double phi = 4.0 * M_PI * intensity * color[c];
    EXPECT_NEAR(map.emittedPower[c], phi, 1e-4 * phi);
    // Truncating the last path drops at most (K + 1) photons of <= phi / N each.
    const double slack = (k + 1) * phi / double(n) + 1e-4 * phi;
    const double a = albedo[c], r = a / q;
    for (int b = 0; b <= k; ++b) {
      double expected = phi * std::pow(a, b);
      double pb = std::pow(q, b);
      double stdErr = phi * std::pow(r, b) * std::sqrt(pb * (1.0 - pb) / double(n));
      EXPECT_NEAR(sums[size_t(b)].v[c], expected, 4.0 * stdErr + slack)
          << "channel " << c << " bounce " << b << " albedo " << albedo.ToString();
    }
    double mean = 0, stdErr = 0;
    pathTotalStats(phi, a, q, k, n, mean, stdErr);
    // The closed form phi (1 - a^(K+1)) / (1 - a) is what the test means by
    // "phi / (1 - a)" with the path length cap applied.
    ASSERT_NEAR(mean, phi * (1.0 - std::pow(a, k + 1)) / (1.0 - a), 1e-9 * phi);
    EXPECT_NEAR(total.v[c], mean, 4.0 * stdErr + slack)
        << "channel " << c << " albedo " << albedo.ToString();
  }
}

TEST(Photons, ClosedBoxEnergyGrey) { checkClosedBoxEnergy({0.5f, 0.5f, 0.5f}); }

TEST(Photons, ClosedBoxEnergyColoured) { checkClosedBoxEnergy({0.8f, 0.5f, 0.2f}); }

TEST(Photons, EmissiveQuadEmitsPiLA) {
  Scene scene = closedBox({0.5f, 0.5f, 0.5f});
  int lamp = addMaterial(scene, {0.5f, 0.5f, 0.5f});
  const Vec3 radiance{1.0f, 2.0f, 3.0f};
  scene.materials[size_t(lamp)].emission = radiance;
  // 0.5 x 0.4 quad below the ceiling, emitting downwards only.
  addQuad(scene, {-0.25f, 0.9f, -0.2f}, {0.5f, 0, 0}, {0, 0, 0.4f}, {0, -1, 0}, lamp);
  const double area = 0.5 * 0.4;

  PhotonParams params = withDirect(50000);
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  std::vector<Dvec3> sums = powerPerBounce(map, params.maxBounces);
  for (int c = 0; c < 3; ++c) {
    double phi = M_PI * radiance[c] * area;
    EXPECT_NEAR(map.emittedPower[c], phi, 1e-4 * phi);
    // Every path hits the box with the same power: only truncation and float error.
    double slack = (params.maxBounces + 1) * phi / double(map.emittedPaths) + 1e-4 * phi;
    EXPECT_NEAR(sums[0].v[c], phi, slack) << "channel " << c;
  }
  for (const Photon& p : map.photons) {
    if (p.bounce != 0) continue;
    ASSERT_LT(p.position.y, 0.9f) << "a one-sided emitter lit its back side";
  }
}

TEST(Photons, MixedLightsAreUnbiasedPerChannel) {
  // Two emitters with different spectra: selection by average power must still
  // give each channel's total emitted power.
  Scene scene = closedBox({0.3f, 0.3f, 0.3f});
  int lamp = addMaterial(scene, {0.3f, 0.3f, 0.3f});
  scene.materials[size_t(lamp)].emission = {0.2f, 0.5f, 4.0f};
  addQuad(scene, {-0.3f, 0.95f, -0.3f}, {0.6f, 0, 0}, {0, 0, 0.6f}, {0, -1, 0}, lamp);
  scene.lights.push_back(pointLight({0.2f, -0.3f, 0.1f}, 0.4f, {1.0f, 0.3f, 0.05f}));

  PhotonParams params = withDirect(100000);
  params.seed = 3;
  PhotonMap map = tracePhotons(scene, params);
  std::vector<Dvec3> sums = powerPerBounce(map, params.maxBounces);
  const size_t n = map.emittedPaths;
  Vec3 phiQuad = scene.materials[size_t(lamp)].emission * float(M_PI * 0.36);
  Vec3 phiPoint = scene.lights[0].color * float(4.0 * M_PI * 0.4);
  double wq = average(phiQuad), wp = average(phiPoint);
  double pq = wq / (wq + wp), pp = wp / (wq + wp);
  for (int c = 0; c < 3; ++c) {
    double expected = phiQuad[c] + phiPoint[c];
    double xq = phiQuad[c] / pq, xp = phiPoint[c] / pp;
    double var = pq * xq * xq + pp * xp * xp - expected * expected;
    double stdErr = std::sqrt(std::max(0.0, var) / double(n));
    double slack = std::max(xq, xp) / double(n) + 1e-4 * expected;
    EXPECT_NEAR(sums[0].v[c], expected, 4.0 * stdErr + slack) << "channel " << c;
  }
}

/// A scene with every lobe: diffuse, rough metal, mirror, glass.
Scene mixedScene() {
  Scene scene = closedBox({0.7f, 0.6f, 0.5f});
  int metal = addMaterial(scene, {0.9f, 0.7f, 0.3f});
  scene.materials[size_t(metal)].metallic = 1.0f;
  scene.materials[size_t(metal)].roughness = 0.4f;
  addSolidBox(scene, {-0.8f, -1.0f, -0.8f}, {-0.3f, -0.4f, -0.3f}, metal);
  int mirror = addMaterial(scene, {0.95f, 0.95f, 0.95f});
  scene.materials[size_t(mirror)].metallic = 1.0f;
  scene.materials[size_t(mirror)].roughness = 0.0f;
  addQuad(scene, {0.99f, -0.5f, -0.5f}, {0, 1, 0}, {0, 0, 1}, {-1, 0, 0}, mirror);
  int glass = addGlass(scene);
  addSolidBox(scene, {0.2f, -1.0f, 0.2f}, {0.7f, -0.2f, 0.7f}, glass);
  // A single-sided panel lit directly on its front and indirectly on its back.
  int panel = addMaterial(scene, {0.6f, 0.6f, 0.6f});
  addQuad(scene, {-0.2f, 0.0f, -0.5f}, {0, 0.6f, 0}, {0, 0, 1}, {1, 0, 0}, panel);
  scene.lights.push_back(pointLight({0, 0.8f, 0}, 1.0f));
  return scene;
}

PhotonMap traceWithThreads(const Scene& scene, const PhotonParams& params, int threads) {
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
  return tracePhotons(scene, params);
}

TEST(Photons, DeterministicAcrossThreadCounts) {
  Scene scene = mixedScene();
  PhotonParams params;
  params.storedPhotons = 150000;  // several batches
  params.seed = 11;
  PhotonMap ref = traceWithThreads(scene, params, 1);
  ASSERT_EQ(ref.photons.size(), params.storedPhotons);
  for (int threads : {2, 4}) {
    PhotonMap map = traceWithThreads(scene, params, threads);
    EXPECT_EQ(map.emittedPaths, ref.emittedPaths) << threads << " threads";
    EXPECT_EQ(map.raysTraced, ref.raysTraced) << threads << " threads";
    ASSERT_EQ(map.photons.size(), ref.photons.size()) << threads << " threads";
    EXPECT_EQ(
        std::memcmp(map.photons.data(), ref.photons.data(), ref.photons.size() * sizeof(Photon)), 0)
        << threads << " threads";
  }
  params.seed = 12;
  PhotonMap other = traceWithThreads(scene, params, 2);
  ASSERT_EQ(other.photons.size(), ref.photons.size());
  EXPECT_NE(
      std::memcmp(other.photons.data(), ref.photons.data(), ref.photons.size() * sizeof(Photon)),
      0);
}

TEST(Photons, PathRangesTracedInAnyPartsGiveTheMap) {
  // The map is the photons of paths 0, 1, 2, ... cut at the count: traced
  // as one range or as uneven parts (a distributed bake's ranks), the same.
  Scene scene = mixedScene();
  PhotonParams params;
  params.storedPhotons = 20000;
  params.seed = 5;
  const PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  PhotonTracer tracer(scene, params);
  for (const std::vector<size_t>& parts :
       {std::vector<size_t>{map.emittedPaths}, std::vector<size_t>{1, 999, 4000, 7, 50000}}) {
    std::vector<Photon> photons;
    std::vector<uint32_t> pathPhotons;
    uint64_t first = 0;
    for (size_t count : parts) {
      tracer.trace(first, count, photons, pathPhotons);
      first += count;
    }
    ASSERT_GE(pathPhotons.size(), map.emittedPaths);
    // Cut where the one-process map was cut: after path emittedPaths - 1.
    size_t kept = 0;
    for (size_t i = 0; i < map.emittedPaths; ++i) kept += pathPhotons[i];
    ASSERT_GE(kept, map.photons.size());
    ASSERT_LT(kept - pathPhotons[map.emittedPaths - 1], map.photons.size()) << "the last path cut";
    photons.resize(map.photons.size());
    scalePhotonPower(photons, map.emittedPaths);
    EXPECT_EQ(std::memcmp(photons.data(), map.photons.data(), photons.size() * sizeof(Photon)), 0)
        << parts.size() << " parts";
  }
}

TEST(Photons, StoresExactCount) {
  Scene scene = mixedScene();
  for (size_t count : {size_t(1), size_t(777), size_t(12345)}) {
    PhotonParams params;
    params.storedPhotons = count;
    PhotonMap map = tracePhotons(scene, params);
    EXPECT_EQ(map.photons.size(), count);
    EXPECT_GT(map.emittedPaths, 0u);
    EXPECT_GE(map.raysTraced, map.emittedPaths);
  }
}

TEST(Photons, MaxEmittedCapsPathsWhenLightMissesGeometry) {
  // A small floor far from a point light: most paths leave the scene. A
  // second small quad as far above keeps the light inside the scene's
  // bounding sphere, where it is not aimed at the scene (PhotonAim).
  Scene scene;
  int floor = addMaterial(scene, {0.5f, 0.5f, 0.5f});
  addQuad(scene, {-0.1f, 0, -0.1f}, {0.2f, 0, 0}, {0, 0, 0.2f}, {0, 1, 0}, floor);
  addQuad(scene, {-0.1f, 20, -0.1f}, {0.2f, 0, 0}, {0, 0, 0.2f}, {0, 1, 0}, floor);
  scene.lights.push_back(pointLight({0, 10, 0}, 1));
  PhotonParams params = withDirect(1000);
  params.maxEmitted = 5000;
  PhotonMap map = tracePhotons(scene, params);
  EXPECT_EQ(map.emittedPaths, params.maxEmitted);
  EXPECT_LT(map.photons.size(), params.storedPhotons);
  EXPECT_EQ(map.raysTraced, map.emittedPaths);  // one ray per path, nothing to bounce to
}

TEST(Photons, ExcludesDirectByDefault) {
  Scene scene = mixedScene();
  PhotonParams params;
  params.storedPhotons = 20000;
  ASSERT_FALSE(params.includeDirect);
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  size_t direct = 0;
  for (const Photon& p : map.photons) direct += p.bounce == 0;
  EXPECT_EQ(direct, 0u);

  params.includeDirect = true;
  map = tracePhotons(scene, params);
  direct = 0;
  for (const Photon& p : map.photons) direct += p.bounce == 0;
  EXPECT_GT(direct, 0u);  // the check above can fail
}

TEST(Photons, NormalFacesDirectionAndDirectionIsUnit) {
  Scene scene = mixedScene();
  PhotonParams params = withDirect(30000);
  PhotonMap map = tracePhotons(scene, params);
  size_t backOfPanel = 0;
  for (const Photon& p : map.photons) {
    ASSERT_NEAR(length(p.direction), 1.0f, 1e-4f);
    ASSERT_NEAR(length(p.normal), 1.0f, 1e-4f);
    ASSERT_GT(dot(p.normal, p.direction), 0.0f)
        << "normal " << p.normal.ToString() << " direction " << p.direction.ToString();
    ASSERT_TRUE(isFinite(p.power) && isFinite(p.position));
    ASSERT_GE(std::min({p.power.x, p.power.y, p.power.z}), 0.0f);
    backOfPanel += std::fabs(p.position.x + 0.2f) < 1e-4f && p.normal.x < 0;
  }
  EXPECT_GT(backOfPanel, 0u);  // the normal check above met a back face
}

TEST(Photons, StoresOnRoughButNotOnMirrorSurfaces) {
  Scene scene = mixedScene();
  PhotonParams params = withDirect(50000);
  PhotonMap map = tracePhotons(scene, params);
  size_t onMirror = 0, onRoughMetal = 0;
  for (const Photon& p : map.photons) {
    onMirror += std::fabs(p.position.x - 0.99f) < 1e-4f && p.normal.x < 0;
    // Top face of the rough metal box (roughness 0.4 > 0.2 stores photons).
    onRoughMetal += std::fabs(p.position.y + 0.4f) < 1e-4f && p.position.x < -0.3f &&
                    p.position.z < -0.3f && p.normal.y > 0;
  }
  EXPECT_EQ(onMirror, 0u);
  EXPECT_GT(onRoughMetal, 0u);
}

TEST(Photons, GlassStoresNothingAndConservesEnergy) {
  // Grey closed box with a glass slab below the light: glass only redirects,
  // so the stored total is the same as without it, phi (1 - a^(K+1)) / (1 - a).
  const float a = 0.5f;
  Scene scene = litBox({a, a, a}, {1, 1, 1}, 1.0f);
  int glass = addGlass(scene);
  scene.materials[size_t(glass)].ior = 1.5f;
  scene.materials[size_t(glass)].thickness = 0.2f;  // a solid slab (KHR_materials_volume)
  const Vec3 slabLo{-0.8f, -0.4f, -0.8f}, slabHi{0.8f, -0.2f, 0.8f};
  addSolidBox(scene, slabLo, slabHi, glass);

  PhotonParams params = withDirect(200000);
  params.maxBounces = 64;
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  double total = 0, floorThroughGlass = 0;
  for (const Photon& p : map.photons) {
    bool onSlab = p.position.x > slabLo.x - 1e-3f && p.position.x < slabHi.x + 1e-3f &&
                  p.position.y > slabLo.y - 1e-3f && p.position.y < slabHi.y + 1e-3f &&
                  p.position.z > slabLo.z - 1e-3f && p.position.z < slabHi.z + 1e-3f;
    ASSERT_FALSE(onSlab) << "photon stored on glass at " << p.position.ToString();
    total += p.power.x;
    // Refracted in and out: reached the floor under the slab through it.
    if (p.bounce == 2 && p.position.y < -0.99f && std::fabs(p.position.x) < 0.5f &&
        std::fabs(p.position.z) < 0.5f)
      floorThroughGlass += p.power.x;
  }
  const double phi = 4.0 * M_PI;
  double mean = 0, stdErr = 0;
  pathTotalStats(phi, a, a, params.maxBounces, map.emittedPaths, mean, stdErr);
  double slack = (params.maxBounces + 1) * phi / double(map.emittedPaths) + 1e-4 * phi;
  EXPECT_NEAR(total, mean, 4.0 * stdErr + slack);
  // The floor patch under the slab subtends a solid angle fraction
  // 1/4 * (1 - 1/sqrt(1 + 2 * ...)) > 2%; most of it passes (T ~ 0.92^2).
  EXPECT_GT(floorThroughGlass, 0.02 * phi);
}

TEST(Photons, NoLightThrows) {
  Scene scene = closedBox({0.5f, 0.5f, 0.5f});
  PhotonParams params;
  params.storedPhotons = 100;
  EXPECT_THROW(tracePhotons(scene, params), InputError);
  scene.lights.push_back(pointLight({0, 0, 0}, 0.0f));  // zero power
  EXPECT_THROW(tracePhotons(scene, params), InputError);
  scene.lights[0].intensity = 1.0f;
  EXPECT_NO_THROW(tracePhotons(scene, params));
}

TEST(Photons, SpotPhotonsStayInsideConeWithFalloffPower) {
  Scene scene = closedBox({0.5f, 0.5f, 0.5f});
  Light spot;
  spot.type = Light::Type::Spot;
  spot.position = {0.1f, 0.9f, -0.2f};
  spot.direction = normalize(Vec3{0.3f, -1.0f, 0.2f});
  spot.intensity = 3.0f;
  spot.innerConeAngle = 0.15f;
  spot.outerConeAngle = 0.4f;
  scene.lights.push_back(spot);

  PhotonParams params = withDirect(60000);
  PhotonMap map = tracePhotons(scene, params);
  double direct = 0;
  size_t count = 0;
  for (const Photon& p : map.photons) {
    if (p.bounce != 0) continue;
    ++count;
    direct += p.power.x;
    float cosAngle = dot(normalize(p.position - spot.position), spot.direction);
    ASSERT_GE(cosAngle, std::cos(spot.outerConeAngle) - 1e-4f) << p.position.ToString();
  }
  ASSERT_GT(count, 1000u);
  // glTF falloff ((cos - cosO) / (cosI - cosO))^2 integrated over the cone.
  double cosO = std::cos(spot.outerConeAngle), cosI = std::cos(spot.innerConeAngle);
  double expected = 2.0 * M_PI * spot.intensity * ((1.0 - cosI) + (cosI - cosO) / 3.0);
  double full = 2.0 * M_PI * spot.intensity * (1.0 - cosO);  // per accepted path
  double accept = expected / full;
  double stdErr = full * std::sqrt(accept * (1.0 - accept) / double(map.emittedPaths));
  EXPECT_NEAR(direct, expected, 4.0 * stdErr + full * 17.0 / double(map.emittedPaths));
  EXPECT_NEAR(map.emittedPower.x, expected, 1e-4 * expected);
}

TEST(Photons, DirectionalLightFluxThroughFloor) {
  // A black floor facing a directional light: irradiance E over area A.
  Scene scene = blackFloor();
  const Light sun = test::sun({0, -1, 0}, 2.5f);  // W/m^2
  scene.lights.push_back(sun);

  PhotonParams params = withDirect(40000);
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  double sum = 0;
  for (const Photon& p : map.photons) {
    ASSERT_EQ(p.bounce, 0u);
    ASSERT_NEAR(p.direction.y, 1.0f, 1e-6f);
    sum += p.power.x;
  }
  double radius = 0.5 * std::sqrt(8.0);  // bounding sphere of the 2 x 2 floor
  double full = sun.intensity * M_PI * radius * radius;
  double hit = 4.0 / (M_PI * radius * radius);
  double stdErr = full * std::sqrt(hit * (1.0 - hit) / double(map.emittedPaths));
  EXPECT_NEAR(sum, sun.intensity * 4.0, 4.0 * stdErr + full / double(map.emittedPaths));
}

TEST(Photons, ManySunsOfOneDirectionLightTheFloorAsTheirSum) {
  // 2,000 suns of one direction (H10-5-5: 10,000 baked at 2.6 GB, a
  // footprint each) share one footprint: the flux is their summed
  // irradiance over the floor, as for one sun.
  Scene scene = blackFloor();
  for (int i = 0; i < 2000; ++i) scene.lights.push_back(test::sun({0, -1, 0}, 2.5f / 2000.0f));
  PhotonParams params = withDirect(40000);
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  double sum = 0;
  for (const Photon& p : map.photons) sum += p.power.x;
  EXPECT_NEAR(sum, 2.5 * 4.0, 0.01 * 2.5 * 4.0);
}

TEST(LightFootprint, ASquareSeenAlongItsNormalIsSampledUniformlyOverItsCells) {
  // A 2 x 2 floor seen from above: the covered cells are the square (the
  // grid spans it), its area 4, and a bit per cell with a count per 64:
  // at most 12 KiB and change, where a list of cells took 256 KiB.
  Scene scene = blackFloor();
  const LightFootprint footprint(scene, {0, -1, 0}, Bounds3{}, 0.01f);
  ASSERT_FALSE(footprint.empty());
  EXPECT_NEAR(footprint.area(), 4.0, 0.04);
  EXPECT_LT(footprint.bytes(), size_t(13 * 1024));
  // Starts above the floor, inside it, a quarter in each quadrant (the
  // k-th covered cell for u0 = k / covered, walked in index order).
  int quadrant[4] = {0, 0, 0, 0};
  const int n = 4096;
  for (int i = 0; i < n; ++i) {
    const Vec3 p = footprint.sample((float(i) + 0.5f) / float(n), 0.5f, 0.5f);
    ASSERT_GT(p.y, 0.0f);
    ASSERT_LE(std::fabs(p.x), 1.0f);
    ASSERT_LE(std::fabs(p.z), 1.0f);
    ++quadrant[(p.x > 0 ? 1 : 0) + (p.z > 0 ? 2 : 0)];
  }
  for (int q = 0; q < 4; ++q) EXPECT_EQ(quadrant[q], n / 4) << "quadrant " << q;
}

TEST(Photons, SkyImageLightsAnOpenFloorWithItsCosineIntegral) {
  // An 8 x 8 sky image: radiance 4 within 45 degrees of the zenith (rows 0
  // and 1), 1 down to the horizon (rows 2 and 3), a colour below (unused).
  // An open floor receives E = 4 pi sin^2(45) + pi cos^2(45) = 2.5 pi, over
  // its 4 m^2.
  Scene scene = blackFloor();
  scene.sky.image = test::twoBandSkyImage();
  scene.sky.radiance = {1.0f, 0.5f, 0.25f};  // scales the image
  PhotonParams params;
  params.storedPhotons = 60000;
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  EXPECT_EQ(map.emptyPaths, 0u);
  Dvec3 sum;
  for (const Photon& p : map.photons) sum.add(p.power);
  for (int c = 0; c < 3; ++c) {
    const double expected = 2.5 * kPi * 4.0 * scene.sky.radiance[c];
    EXPECT_NEAR(sum.v[c], expected, 0.02 * expected) << "channel " << c;
  }
}

TEST(Photons, TiltedSunOverATallBoxSpendsNoPathBesideTheScene) {
  // A 2 x 2 black floor with a 1 x 1 x 8 black tower on it, the sun 40
  // degrees above the horizon: the covered box is tall, and photons started
  // over its silhouette would pass beside the floor. Aimed at the scene's
  // footprint, every path but those starting in a footprint cell's
  // uncovered corner lands, and the flux is the analytic E cos A over the
  // floor and the tower's lit faces.
  Scene scene;
  const int black = addMaterial(scene, {0, 0, 0});
  addQuad(scene, {-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, {0, 1, 0}, black);
  test::addBlock(scene, {-0.5f, 0, -0.5f}, {0.5f, 8, 0.5f}, black);
  const float elevation = 40.0f * kPi / 180.0f;
  const Light sun = test::sun({std::cos(elevation), -std::sin(elevation), 0.0f}, 2.0f);
  scene.lights.push_back(sun);

  PhotonParams params = withDirect(40000);
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  EXPECT_LT(double(map.emptyPaths), 0.05 * double(map.emittedPaths));
  double sum = 0;
  for (const Photon& p : map.photons) sum += p.power.x;
  // Lit: the floor outside the tower's base (1 m^2) and its shadow (the
  // 0.5 m^2 of floor behind it, x from 0.5 to 1), cos = sin 40; the tower's
  // top (1 m^2, sin 40) and its face towards the sun (8 m^2, cos 40).
  const double expected = sun.intensity * ((4.0 - 1.0 - 0.5 + 1.0) * std::sin(elevation) +
                                           8.0 * std::cos(elevation));
  // Each path carries E A_footprint / N, A_footprint >= the true outline.
  const double perPath = expected / (1.0 - double(map.emptyPaths) / double(map.emittedPaths));
  EXPECT_NEAR(sum, expected, 4.0 * perPath / std::sqrt(double(map.emittedPaths)) + 1e-3 * expected);
}

TEST(Photons, SkyLightsAnOpenFloorWithPiL) {
  // A black floor under a uniform sky of radiance L: irradiance pi L over
  // area A, every photon stored at its first hit (the sky's light lives in
  // the octree whole, even without --include-direct), and no path wasted:
  // the sky's photons enter through the floor's silhouette.
  Scene scene = blackFloor();
  scene.sky.radiance = {0.5f, 1.0f, 2.0f};  // W/(m^2 sr)

  PhotonParams params;
  params.storedPhotons = 40000;
  PhotonMap map = tracePhotons(scene, params);
  ASSERT_EQ(map.photons.size(), params.storedPhotons);
  EXPECT_EQ(map.emittedPaths, params.storedPhotons);
  Dvec3 sum;
  for (const Photon& p : map.photons) {
    ASSERT_EQ(p.bounce, 0u);
    ASSERT_GT(p.direction.y, 0.0f);
    sum.add(p.power);
  }
  // Each photon carries 4 A(d) / S of the sky's power pi L S / 2: here
  // A(d) = |d.y| A and S = 2 A, so the power varies with the direction
  // (standard deviation about 0.58 of the mean).
  for (int c = 0; c < 3; ++c) {
    const double expected = kPi * scene.sky.radiance[c] * 4.0;
    EXPECT_NEAR(sum.v[c], expected, 4.0 * 0.58 * expected / std::sqrt(double(map.emittedPaths)));
  }
}

/// The power stored on a wall at x = 1 (bounce 1 and later) from light a
/// floor reflects, the floor's shading normal tilted 35 degrees towards the
/// wall: by its vertex normals (`tilt` 1), by a constant normal map (2), or
/// not at all (0).
double wallPowerFromATiltedFloor(int tilt) {
  Scene scene;
  const int floor = addMaterial(scene, {0.8f, 0.8f, 0.8f});
  const int wall = addMaterial(scene, {0, 0, 0});
  addQuad(scene, {-1, 0, -1}, {0, 0, 2}, {2, 0, 0}, {0, 1, 0}, floor);
  addQuad(scene, {1, 0, -1}, {0, 2, 0}, {0, 0, 2}, {-1, 0, 0}, wall);
  const float angle = 35.0f * kPi / 180.0f;
  const Vec3 tilted{std::sin(angle), std::cos(angle), 0.0f};
  scene.normals.assign(scene.positions.size(), Vec3{0, 0, 0});
  for (size_t v = 0; v < 4; ++v) scene.normals[v] = tilt == 1 ? tilted : Vec3{0, 1, 0};
  for (size_t v = 4; v < 8; ++v) scene.normals[v] = Vec3{-1, 0, 0};
  if (tilt == 2) {
    // u along +x: tangent +x, bitangent cross(+y, +x) = -z; the map's
    // tangent-space normal (sin, 0, cos) is the same tilt towards +x.
    scene.texcoords0.assign(2 * scene.positions.size(), 0.0f);
    for (size_t v = 0; v < 4; ++v) {
      scene.texcoords0[2 * v] = 0.5f * (scene.positions[v].x + 1.0f);
      scene.texcoords0[2 * v + 1] = 0.5f * (scene.positions[v].z + 1.0f);
    }
    Texture map = Texture::fromLinear(
        1, 1, {Vec3{0.5f * (std::sin(angle) + 1.0f), 0.5f, 0.5f * (std::cos(angle) + 1.0f)}});
    scene.textures.push_back(map);
    scene.materials[size_t(floor)].normalTexture = 0;
  }
  scene.lights.push_back(pointLight({-0.5f, 1.0f, 0.0f}, 5.0f));
  PhotonParams params;
  params.storedPhotons = 200000;
  PhotonMap map = tracePhotons(scene, params);
  double power = 0;
  for (const Photon& p : map.photons) {
    if (p.position.x > 0.999f && p.bounce >= 1) power += p.power.x;
  }
  return power;
}

TEST(Photons, NormalMapTiltsTheScatteringAsVertexNormalsDo) {
  // The photon tracer scatters about the shading normal, as the path tracer
  // and the renderer shade: a floor whose normal map tilts it towards a
  // wall sends the wall what the same tilt in its vertex normals sends, and
  // clearly more than the untilted floor.
  const double byVertexNormals = wallPowerFromATiltedFloor(1);
  const double byNormalMap = wallPowerFromATiltedFloor(2);
  const double untilted = wallPowerFromATiltedFloor(0);
  std::printf("wall power: normal map %.4f, vertex normals %.4f, untilted %.4f\n", byNormalMap,
              byVertexNormals, untilted);
  EXPECT_NEAR(byNormalMap, byVertexNormals, 0.03 * byVertexNormals);
  EXPECT_GT(byVertexNormals, 1.15 * untilted)
      << "tilted " << byVertexNormals << ", untilted " << untilted;
}

struct RecordingSink : ProgressSink {
  size_t total = 0, last = 0, updates = 0;
  bool monotonic = true, ended = false;
  void begin(const std::string&, size_t t) override { total = t; }
  void update(size_t done, size_t) override {
    monotonic = monotonic && done >= last;
    last = done;
    ++updates;
  }
  void end() override { ended = true; }
};

TEST(Photons, ReportsProgressInStoredPhotons) {
  Scene scene = mixedScene();
  PhotonParams params;
  params.storedPhotons = 30000;
  RecordingSink sink;
  tracePhotons(scene, params, &sink);
  EXPECT_EQ(sink.total, params.storedPhotons);
  EXPECT_EQ(sink.last, params.storedPhotons);
  EXPECT_GT(sink.updates, 0u);
  EXPECT_TRUE(sink.monotonic);
  EXPECT_TRUE(sink.ended);
}

TEST(Photons, RejectsNegativeMaxBounces) {
  Scene scene = litBox({0.5f, 0.5f, 0.5f}, {1, 1, 1}, 1.0f);
  PhotonParams params;
  params.maxBounces = -1;
  EXPECT_THROW(tracePhotons(scene, params), InputError);
}

// An emissive texture: the quad's emitted power is pi A times the mean
// radiance over it, and photons start only where the texture emits.
TEST(Photons, EmissiveTextureWeightsThePhotons) {
  Scene scene = closedBox({0.5f, 0.5f, 0.5f});
  int lamp = addMaterial(scene, {0.5f, 0.5f, 0.5f});
  scene.materials[size_t(lamp)].emission = {2, 2, 2};
  // x < 0 emits, x > 0 is dark
  Texture half = Texture::fromLinear(2, 1, {Vec3{1, 1, 1}, Vec3{0, 0, 0}});
  half.sampler.magFilter = TextureSampler::kNearest;  // two halves, not a ramp
  scene.textures.push_back(half);
  scene.materials[size_t(lamp)].emissiveTexture = 0;
  const size_t firstVertex = scene.positions.size();
  // 0.1 above the floor, facing it: direct photons land near where they start.
  addQuad(scene, {-0.5f, -0.9f, -0.5f}, {1.0f, 0, 0}, {0, 0, 1.0f}, {0, -1, 0}, lamp);
  scene.texcoords0.assign(2 * scene.positions.size(), 0.0f);
  for (size_t v = firstVertex; v < scene.positions.size(); ++v) {
    scene.texcoords0[2 * v] = scene.positions[v].x + 0.5f;  // u = x + 0.5 over the quad
    scene.texcoords0[2 * v + 1] = scene.positions[v].z + 0.5f;
  }
  PhotonParams params = withDirect(40000);
  PhotonMap map = tracePhotons(scene, params);
  // Mean radiance 2 x (share of the quad with x < 0: 1/2), stratified 64
  // samples per triangle: each triangle's mean is within a sample's share.
  const double phi = M_PI * 1.0 * 1.0;
  EXPECT_NEAR(map.emittedPower[0], phi, 0.05 * phi);
  std::vector<Dvec3> sums = powerPerBounce(map, params.maxBounces);
  EXPECT_NEAR(sums[0].v[0], map.emittedPower[0], 0.03 * map.emittedPower[0]);
  // Direct photons land right below where they start: under the emitting
  // half (x < 0), not under the dark one.
  double left = 0, right = 0;
  for (const Photon& p : map.photons) {
    if (p.bounce != 0 || p.position.y > -0.99f) continue;
    if (p.position.x > -0.45f && p.position.x < -0.05f) left += p.power[0];
    if (p.position.x > 0.05f && p.position.x < 0.45f) right += p.power[0];
  }
  EXPECT_GT(left, 5.0 * right) << "left " << left << " right " << right;
}


// The photon tracer reads a metallic-roughness map as the renderer does: a
// mirror by its factors (metallic 1, roughness 0.05) whose map says
// metallic 0 (B = 0) scatters diffusely and stores photons; without the map
// it stores none.
TEST(Photons, MetallicRoughnessMapMakesAMirrorDiffuse) {
  auto floorPhotons = [](bool withMap) {
    Scene scene;
    int wall = addMaterial(scene, {0.5f, 0.5f, 0.5f});
    int mirror = addMaterial(scene, {0.9f, 0.9f, 0.9f});
    scene.materials[size_t(mirror)].metallic = 1.0f;
    scene.materials[size_t(mirror)].roughness = 0.05f;
    if (withMap) {
      Texture map = Texture::fromLinear(1, 1, {Vec3{0, 1, 0}});  // G roughness x1, B metallic x0
      scene.textures.push_back(map);
      scene.materials[size_t(mirror)].metallicRoughnessTexture = 0;
    }
    addClosedBox(scene, {-1, -1, -1}, {1, 1, 1}, wall);
    addQuad(scene, {-0.5f, -0.9f, -0.5f}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, mirror);
    scene.texcoords0.assign(2 * scene.positions.size(), 0.5f);
    scene.lights.push_back(pointLight({0, 0.5f, 0}, 5.0f));
    PhotonParams params = withDirect(20000);
    PhotonMap map = tracePhotons(scene, params);
    size_t onFloor = 0;
    for (const Photon& p : map.photons) {
      onFloor += std::fabs(p.position.y + 0.9f) < 1e-4f && std::fabs(p.position.x) < 0.5f &&
                 std::fabs(p.position.z) < 0.5f && p.normal.y > 0;
    }
    return onFloor;
  };
  EXPECT_EQ(floorPhotons(false), 0u);
  EXPECT_GT(floorPhotons(true), 300u);
}


// A thin-walled pane (no volume): light passes straight through it, as
// direct light: photons that crossed it keep bounce 0 (the renderer draws
// that light, the pane casts no shadow), and without --include-direct none
// of them is stored on the floor under it.
TEST(Photons, ThinWalledGlassPassesLightAsDirect) {
  const float a = 0.5f;
  Scene scene = litBox({a, a, a}, {1, 1, 1}, 1.0f);
  int glass = addGlass(scene);
  addQuad(scene, {-0.8f, -0.3f, -0.8f}, {1.6f, 0, 0}, {0, 0, 1.6f}, {0, 1, 0}, glass);
  PhotonParams params = withDirect(50000);
  PhotonMap map = tracePhotons(scene, params);
  double direct = 0;
  for (const Photon& p : map.photons) {
    if (p.position.y < -0.99f && std::fabs(p.position.x) < 0.5f && std::fabs(p.position.z) < 0.5f &&
        p.bounce == 0)
      direct += p.power.x;
  }
  EXPECT_GT(direct, 0.0) << "light through the pane arrives as bounce 0";
}

}  // namespace
}  // namespace lo


namespace lo {
namespace {

// Caustic photons (Photon::caustic) are the ones that reached a diffuse
// surface through specular events alone: in a box whose +x wall is a
// mirror, a point light's photons reflected by the mirror straight onto a
// wall; never a direct hit, never after a diffuse bounce; and none at all
// without the mirror.
TEST(Photons, CausticPhotonsCameThroughTheMirrorAlone) {
  Scene scene = litBox({0.7f, 0.7f, 0.7f}, {1, 1, 1}, 10.0f);
  PhotonParams params = withDirect(40000);
  const PhotonMap plain = tracePhotons(scene, params);
  for (const Photon& p : plain.photons) ASSERT_EQ(p.caustic, 0u);

  Material mirror;
  mirror.baseColor = {1, 1, 1};
  mirror.metallic = 1;
  mirror.roughness = 0;
  scene.materials.push_back(mirror);
  const int32_t m = int32_t(scene.materials.size()) - 1;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    bool onMirror = true;
    for (int k = 0; k < 3; ++k) {
      onMirror = onMirror && scene.positions[scene.indices[3 * t + size_t(k)]].x > 0.999f;
    }
    if (onMirror) scene.triangleMaterial[t] = m;
  }
  const PhotonMap map = tracePhotons(scene, params);
  size_t caustic = 0, firstAfterMirror = 0;
  for (const Photon& p : map.photons) {
    ASSERT_FALSE(p.position.x > 0.999f && p.normal.x < -0.9f) << "the mirror stores no photon";
    if (!p.caustic) continue;
    ++caustic;
    ASSERT_GE(p.bounce, 1u) << "a direct hit is no caustic";
    // One bounce: it arrived from the mirror, so it looks back towards +x.
    if (p.bounce == 1) {
      ++firstAfterMirror;
      ASSERT_GT(p.direction.x, 0.0f);
    }
  }
  std::printf("[ caustics ] %zu of %zu photons, %zu straight from the mirror\n", caustic,
              map.photons.size(), firstAfterMirror);
  // The mirror takes a sixth of the light's first hits (stored here with
  // the bounces after them): about 5% of the map.
  EXPECT_GT(firstAfterMirror, map.photons.size() / 40);
  EXPECT_EQ(caustic, firstAfterMirror) << "a caustic chain here has one mirror bounce, or two "
                                          "only through the mirror again (impossible: flat)";
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

TEST(SegmentCollector, TakesWholePathsAndScalesByThePathsTaken) {
  const PhotonSegment s{{0, 0, 0}, {1, 0, 0}, {6, 6, 6}};
  const std::vector<PhotonSegment> path(3, s);
  SegmentCollector c(7);
  EXPECT_TRUE(c.addPath(path.data(), 3));
  EXPECT_TRUE(c.addPath(path.data(), 0));  // a path without rays counts
  EXPECT_TRUE(c.addPath(path.data(), 3));
  EXPECT_FALSE(c.addPath(path.data(), 3));  // would pass 7: full, none of it
  EXPECT_FALSE(c.addPath(path.data(), 1));
  EXPECT_TRUE(c.full());
  EXPECT_EQ(c.paths(), 3u);
  const std::vector<PhotonSegment> taken = c.take();
  ASSERT_EQ(taken.size(), 6u);
  EXPECT_EQ(taken[0].power, Vec3(2.0f));  // 6 / 3 paths
}

TEST(SegmentCollector, TracePhotonsKeepsAtMostTheCap) {
  PhotonParams params;
  params.storedPhotons = 5000;
  params.segments = true;
  params.maxSegments = 1000;
  const PhotonMap map = tracePhotons(test::pointLitRoom(), params);
  EXPECT_LE(map.segments.size(), 1000u);
  EXPECT_GT(map.segments.size(), 900u);
  params.maxSegments = kDefaultMaxSegments;
  const PhotonMap all = tracePhotons(test::pointLitRoom(), params);
  EXPECT_GT(all.segments.size(), map.segments.size());
  // The first paths' rays are the same rays, scaled by fewer paths.
  ASSERT_FALSE(map.segments.empty());
  EXPECT_EQ(map.segments[0].from, all.segments[0].from);
  EXPECT_GT(map.segments[0].power.x, all.segments[0].power.x);
}


// A point light and a spot 10 units above a 0.2 x 0.2 floor, outside the
// scene's bounding sphere, are aimed at it: every path is drawn in the cone
// the sphere subtends and carries the intensity times that cone's solid
// angle. The direct flux on the floor must stay I x (the floor's solid angle
// seen from the light; for the spot, inside its inner cone, the same), now
// with a photon from almost every path where the whole sphere gave one in
// 30,000.
TEST(PhotonAim, ALightFarFromASmallSceneIsAimedAtItWithTheSameFlux) {
  const float half = 0.1f, height = 10.0f;
  // The solid angle of a rectangle of half-sides a, b at distance d on its
  // axis: 4 asin(a b / sqrt((a^2 + d^2)(b^2 + d^2))).
  const double omega = 4.0 * std::asin(double(half * half) / (double(half * half) + height * height));
  for (Light::Type type : {Light::Type::Point, Light::Type::Spot}) {
    SCOPED_TRACE(type == Light::Type::Point ? "point" : "spot");
    Scene scene;
    int floor = addMaterial(scene, {0.5f, 0.5f, 0.5f});
    addQuad(scene, {-half, 0, -half}, {2 * half, 0, 0}, {0, 0, 2 * half}, {0, 1, 0}, floor);
    Light light = pointLight({0, height, 0}, 2.0f);
    if (type == Light::Type::Spot) {
      light.type = Light::Type::Spot;
      light.direction = {0, -1, 0};
      light.innerConeAngle = 0.05f;  // the floor spans 0.01 rad: inside it
      light.outerConeAngle = 0.5f;
    }
    scene.lights.push_back(light);
    PhotonParams params = withDirect(20000);
    const PhotonMap map = tracePhotons(scene, params);
    ASSERT_EQ(map.photons.size(), params.storedPhotons);
    // The sphere round the square subtends pi/2 times its solid angle.
    EXPECT_LT(double(map.emittedPaths), 1.7 * double(map.photons.size()));
    double direct = 0;
    for (const Photon& p : map.photons) direct += p.bounce == 0 ? double(p.power.x) : 0.0;
    const double expected = double(light.intensity) * omega;
    // Each direct photon carries I x (the aimed cone's solid angle) / paths;
    // the hits are binomial over the paths.
    const double cone = 2.0 * M_PI * (1.0 - std::sqrt(1.0 - std::pow(0.5 * std::sqrt(2.0) * 0.2 * 1.01 / height, 2.0)));
    const double perPhoton = double(light.intensity) * cone / double(map.emittedPaths);
    const double hit = expected / (perPhoton * double(map.emittedPaths));
    const double stdErr = perPhoton * std::sqrt(double(map.emittedPaths) * hit * (1.0 - hit));
    EXPECT_NEAR(direct, expected, 4.0 * stdErr + 0.01 * expected);
  }
}

/// The form factor between two parallel, directly opposed a x b rectangles
/// a distance c apart (Hottel; Howell's catalogue, C-11).
double parallelRectanglesFormFactor(double a, double b, double c) {
  const double x = a / c, y = b / c, x2 = x * x, y2 = y * y;
  return 2.0 / (M_PI * x * y) *
         (0.5 * std::log((1 + x2) * (1 + y2) / (1 + x2 + y2)) +
          x * std::sqrt(1 + y2) * std::atan(x / std::sqrt(1 + y2)) +
          y * std::sqrt(1 + x2) * std::atan(y / std::sqrt(1 + x2)) - x * std::atan(x) -
          y * std::atan(y));
}

// An emissive square facing a grey one 2 m away across open space: the light
// the grey square receives is pi L F (F the form factor, 0.0685), with the
// emission guide (photon/emission_guide.h) and without; with it, most paths
// land where without it 93% left into the open.
TEST(PhotonGuide, AnEmitterInTheOpenSendsItsFormFactorsLightWithFewerPaths) {
  Scene scene;
  const int grey = addMaterial(scene, {0.5f, 0.5f, 0.5f});
  const int lamp = addMaterial(scene, {0.5f, 0.5f, 0.5f});
  const float radiance = 2.0f;
  scene.materials[size_t(lamp)].emission = Vec3(radiance);
  addQuad(scene, {-0.5f, 2, -0.5f}, {1, 0, 0}, {0, 0, 1}, {0, -1, 0}, lamp);  // facing down
  addQuad(scene, {-0.5f, 0, -0.5f}, {1, 0, 0}, {0, 0, 1}, {0, 1, 0}, grey);   // facing up
  const double expected = M_PI * radiance * parallelRectanglesFormFactor(1, 1, 2);
  double landed[2] = {0, 0};
  for (bool guide : {false, true}) {
    SCOPED_TRACE(guide ? "guided" : "not guided");
    PhotonParams params = withDirect(40000);
    params.maxBounces = 0;  // the first hits alone: one photon per path at most
    params.guideEmission = guide;
    const PhotonMap map = tracePhotons(scene, params);
    ASSERT_EQ(map.photons.size(), params.storedPhotons);
    double sum = 0, squares = 0;
    for (const Photon& p : map.photons) {
      EXPECT_LT(p.position.y, 1.0f) << "a photon on the lamp";
      sum += double(p.power.x);
      squares += double(p.power.x) * double(p.power.x);
    }
    // Each path adds its photon's (scaled) power or nothing: the sum's
    // standard error from the photons themselves.
    const double stdErr =
        std::sqrt(std::max(0.0, squares - sum * sum / double(map.emittedPaths)));
    EXPECT_NEAR(sum, expected, 4.0 * stdErr + 1e-3 * expected);
    landed[guide ? 1 : 0] = double(map.photons.size()) / double(map.emittedPaths);
  }
  std::printf("[ guide ] paths that land: %.1f%% without the guide, %.1f%% with it\n",
              100 * landed[0], 100 * landed[1]);
  EXPECT_NEAR(landed[0], parallelRectanglesFormFactor(1, 1, 2), 0.005);
  EXPECT_GT(landed[1], 3.0 * landed[0]);
}

}  // namespace
}  // namespace lo
