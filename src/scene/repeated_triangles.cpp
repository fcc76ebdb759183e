// Triangles that repeat an earlier one (scene_internal.h,
// dropRepeatedTriangles): found by a hash of their vertices, sorted, then
// compared exactly within each run of equal hashes.
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/fnv.h"
#include "scene/scene_internal.h"

namespace lo::scene_internal {

namespace {

/// Triangle t's vertex indices from its lowest in winding order, so that
/// (a, b, c), (b, c, a) and (c, a, b) read alike and (a, c, b) does not.
std::array<uint32_t, 3> canonicalCorners(const Scene& scene, size_t t) {
  const uint32_t* v = &scene.indices[3 * t];
  const size_t first = v[0] <= v[1] && v[0] <= v[2] ? 0 : (v[1] <= v[2] ? 1 : 2);
  return {v[first], v[(first + 1) % 3], v[(first + 2) % 3]};
}

bool sameTriangle(const Scene& scene, size_t a, size_t b) {
  return canonicalCorners(scene, a) == canonicalCorners(scene, b);
}

}  // namespace

size_t dropRepeatedTriangles(Scene& scene) {
  const size_t n = scene.triangleCount();
  if (n < 2 || scene.triangleMaterial.size() != n) return 0;
  struct Key {
    uint64_t hash;
    uint32_t triangle;
  };
  std::vector<Key> keys;
  keys.reserve(n);  // one per triangle
  for (size_t t = 0; t < n; ++t) {
    const std::array<uint32_t, 3> p = canonicalCorners(scene, t);
    Fnv1a64 h;
    h.bytes(p.data(), sizeof(p));
    keys.push_back({h.value(), uint32_t(t)});
  }
  std::sort(keys.begin(), keys.end(), [](const Key& a, const Key& b) {
    return a.hash != b.hash ? a.hash < b.hash : a.triangle < b.triangle;
  });
  // Within a run of equal hashes each triangle is compared with the kept
  // ones before it (a run longer than one is a copy but for a collision).
  std::vector<uint8_t> repeated(n, 0);
  size_t dropped = 0, otherMaterial = 0;
  for (size_t i = 0; i < keys.size();) {
    size_t end = i + 1;
    while (end < keys.size() && keys[end].hash == keys[i].hash) ++end;
    for (size_t j = i + 1; j < end; ++j) {
      for (size_t k = i; k < j; ++k) {
        if (repeated[keys[k].triangle]) continue;
        if (sameTriangle(scene, keys[k].triangle, keys[j].triangle)) {
          repeated[keys[j].triangle] = 1;
          ++dropped;
          otherMaterial += scene.triangleMaterial[keys[k].triangle] !=
                           scene.triangleMaterial[keys[j].triangle];
          break;
        }
        // Distinct triangles of one hash are rare: the run is short then.
        if (k - i > 64) break;
      }
    }
    i = end;
  }
  if (dropped == 0) return 0;
  size_t kept = 0;
  for (size_t t = 0; t < n; ++t) {
    if (repeated[t]) continue;
    for (int c = 0; c < 3; ++c) scene.indices[3 * kept + size_t(c)] = scene.indices[3 * t + size_t(c)];
    scene.triangleMaterial[kept] = scene.triangleMaterial[t];
    ++kept;
  }
  scene.indices.resize(3 * kept);
  scene.indices.shrink_to_fit();
  scene.triangleMaterial.resize(kept);
  scene.triangleMaterial.shrink_to_fit();
  scene.warnings.push_back(
      (scene.sourcePath.empty() ? std::string("scene") : scene.sourcePath) + ": " +
      std::to_string(dropped) + " of " + std::to_string(n) +
      " triangles repeat an earlier one (the same vertices and winding" +
      (otherMaterial ? ", " + std::to_string(otherMaterial) +
                           " of them in another material, where which face a rasteriser" +
                           " shows is undefined"
                     : std::string()) +
      ") and were left out, the first kept: a copy draws nothing more, and every ray would "
      "test it");
  return dropped;
}

}  // namespace lo::scene_internal
