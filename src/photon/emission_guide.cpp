/// @file photon/emission_guide.cpp
/// @brief EmissionGuide: probe rays per cell of each emissive triangle's
/// (u1, u2) square, and the cell picked by what they met.

#include "photon/emission_guide.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <numeric>

#include "core/discrete_distribution.h"
#include "material/bsdf.h"
#include "raytrace/ray_tracer.h"

namespace lo {

EmissionGuide::EmissionGuide(const Scene& scene, const EmitterSampler& emitters,
                             const RayTracer& tracer, float epsilon, float reach) {
  const size_t n = emitters.size();
  table_.assign(2 * n, -1);
  // The sides that emit, the most powerful first, while the probe budget lasts.
  std::vector<uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  std::stable_sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
    return average(emitters.power[a]) > average(emitters.power[b]);
  });
  constexpr size_t kSideRays = size_t(kCells) * size_t(kProbesPerCell);
  std::vector<uint32_t> sides;  // entry * 2 + back
  for (uint32_t k : order) {
    const uint32_t tri = emitters.triangles[k];
    const bool both = scene.materials[size_t(scene.triangleMaterial[tri])].doubleSided;
    const size_t count = both ? 2 : 1;
    if ((sides.size() + count) * kSideRays > kMaxProbeRays) break;
    for (size_t side = 0; side < count; ++side) sides.push_back(2 * k + uint32_t(side));
  }
  std::sort(sides.begin(), sides.end());

  // Hits per cell of each probed side, in parallel (each side its own row).
  std::vector<uint8_t> hits(sides.size() * size_t(kCells), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, sides.size(), 64),
                    [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const uint32_t k = sides[i] / 2;
      const size_t tri = emitters.triangles[k];
      const Vec3& p0 = scene.positions[scene.indices[3 * tri]];
      const Vec3& p1 = scene.positions[scene.indices[3 * tri + 1]];
      const Vec3& p2 = scene.positions[scene.indices[3 * tri + 2]];
      const Vec3 n = (sides[i] & 1) ? -scene.faceNormal(tri) : scene.faceNormal(tri);
      const Vec3 origin = (p0 + p1 + p2) * (1.0f / 3.0f) + n * epsilon;
      Vec3 t, b;
      orthonormalBasis(n, t, b);
      for (int c = 0; c < kCells; ++c) {
        const int ring = c / kSectors, sector = c % kSectors;
        for (int j = 0; j < kProbesPerCell; ++j) {
          const float s = (float(j) + 0.5f) / float(kProbesPerCell);
          const float u1 = (float(ring) + s) / float(kRings);
          const float u2 = (float(sector) + 1.0f - s) / float(kSectors);
          const Vec3 d = normalize(fromLocal(cosineHemisphere(u1, u2), t, b, n));
          if (tracer.occluded(origin, d, reach)) ++hits[i * size_t(kCells) + size_t(c)];
        }
      }
    }
  });

  pick_.assign(n, 1.0f);
  std::vector<int> probed(n, 0), met(n, 0);
  for (size_t i = 0; i < sides.size(); ++i) {
    const uint8_t* h = hits.data() + i * size_t(kCells);
    int total = 0;
    for (int c = 0; c < kCells; ++c) total += h[c];
    probed[sides[i] / 2] += kCells * kProbesPerCell;
    met[sides[i] / 2] += total;
    // Every probe met the scene (nothing to gain) or none did (nothing to
    // aim at): the side keeps the plain cosine distribution.
    if (total == 0 || total == kCells * kProbesPerCell) continue;
    table_[sides[i]] = int32_t(cdf_.size());
    float sum = 0;
    for (int c = 0; c < kCells; ++c) {
      sum += float(h[c]);
      cdf_.push_back(sum);
    }
  }
  for (size_t k = 0; k < n; ++k) {
    if (probed[k] > 0) pick_[k] = kSpread + (1.0f - kSpread) * float(met[k]) / float(probed[k]);
  }
}

void EmissionGuide::sample(uint32_t entry, bool back, float u0, float& u1, float& u2,
                           float& weight) const {
  const float* cdf = cdf_.data() + table_[2 * size_t(entry) + (back ? 1 : 0)];
  // The cell: evenly with probability kSpread, else by its hits.
  const int cell = pickCellWithSpread(cdf, kCells, kSpread, u0, weight);
  const int ring = cell / kSectors, sector = cell % kSectors;
  u1 = std::min((float(ring) + u1) / float(kRings), 1.0f - 1e-7f);
  u2 = std::min((float(sector) + u2) / float(kSectors), 1.0f - 1e-7f);
}

}  // namespace lo
