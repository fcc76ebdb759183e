#include "lightgrid/grid_noise.h"

#include <algorithm>
#include <cstdio>
#include <utility>
#include <vector>

namespace lo {

std::string NoiseSummary::ToString() const {
  if (!recorded) return "noise not recorded";
  char text[160];
  std::snprintf(text, sizeof text,
                seen ? "noise %.1f%% of the light seen (%.0f%% of the lit area below), median %.1f%%"
                     : "noise %.1f%% (%.0f%% of the lit area below), median %.1f%%",
                100.0 * quantile, 100.0 * kNoiseQuantile, 100.0 * median);
  return text;
}

NoiseSummary summarizeNoise(const VdlGrid& g, const std::vector<float>* direct) {
  NoiseSummary s;
  const size_t n = g.size();
  if (g.noise.size() != n || n == 0) return s;
  if (direct && direct->size() != n + g.layers.size()) direct = nullptr;
  s.seen = direct != nullptr;
  // Layer count per voxel (1 + its entries in g.layers).
  std::vector<uint8_t> layers(n, 1);
  for (uint32_t v : g.layers.voxel) ++layers[v];
  struct Entry {
    double y, sigma, area, seen;  // seen: y plus the direct light
  };
  std::vector<Entry> entries;
  entries.reserve(n + g.layers.size());
  auto add = [&](const Vec3& irradiance, float noise, size_t voxel, size_t entry) {
    const double y = double(luminance(irradiance));
    if (!(y > 0)) {
      ++s.unlit;
      return;
    }
    const double area = g.areas.size() == n && g.areas[voxel] > 0 ? double(g.areas[voxel]) : 1.0;
    const double d = direct ? std::max(0.0, double((*direct)[entry])) : 0.0;
    entries.push_back({y, double(noise) * y, area / double(layers[voxel]), y + d});
  };
  for (size_t v = 0; v < n; ++v) add(g.irradiance[v], g.noise[v], v, v);
  if (g.layers.noise.size() == g.layers.size()) {
    for (size_t e = 0; e < g.layers.size(); ++e) {
      add(g.layers.irradiance[e], g.layers.noise[e], g.layers.voxel[e], n + e);
    }
  }
  s.recorded = true;
  s.lit = entries.size();
  if (entries.empty()) return s;
  double area = 0, weighted = 0, weightedSeen = 0;
  for (const Entry& e : entries) {
    area += e.area;
    weighted += e.area * e.y;
    weightedSeen += e.area * e.seen;
  }
  s.meanLuminance = weighted / area;
  s.litLight = weighted;
  const double floor = kNoiseFloorShare * weightedSeen / area;
  std::vector<std::pair<double, double>> counted;  // (noise, area)
  counted.reserve(entries.size());
  for (const Entry& e : entries) counted.push_back({e.sigma / std::max(e.seen, floor), e.area});
  std::sort(counted.begin(), counted.end());
  auto quantile = [&](double q) {
    double below = 0;
    for (const auto& [noise, a] : counted) {
      below += a;
      if (below >= q * area) return noise;
    }
    return counted.back().first;
  };
  s.median = quantile(0.5);
  s.quantile = quantile(kNoiseQuantile);
  return s;
}

}  // namespace lo
