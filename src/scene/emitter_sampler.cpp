#include "scene/emitter_sampler.h"

#include <algorithm>
#include <string>

#include "core/error.h"

namespace lo {

EmitterSampler buildEmitterSampler(const Scene& scene) {
  EmitterSampler s;
  double total = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    const Material& m = scene.materials[size_t(scene.triangleMaterial[t])];
    if (!m.isEmissive()) continue;
    const float area = scene.triangleArea(t);
    if (!(area > 0)) continue;
    const float sides = m.doubleSided ? 2.0f : 1.0f;
    const Vec3 power = scene.triangleEmission(t) * (sides * kPi * area);
    if (!isFinite(power))
      throw InputError("material '" + m.name + "' of triangle " + std::to_string(t) +
                       " emits non-finite power " + power.ToString());
    if (!(average(power) > 0)) continue;
    total += double(average(power));
    s.triangles.push_back(uint32_t(t));
    s.power.push_back(power);
    s.cdf.push_back(total);
  }
  return s;
}

size_t EmitterSampler::pick(double u) const {
  const double x = u * total();
  size_t k = size_t(std::upper_bound(cdf.begin(), cdf.end(), x) - cdf.begin());
  return std::min(k, triangles.size() - 1);
}

double EmitterSampler::pickProbability(size_t k) const {
  return double(average(power[k])) / total();
}

std::vector<float> EmitterSampler::areaPdfs(const Scene& scene) const {
  std::vector<float> pdf(scene.triangleCount(), 0.0f);
  for (size_t k = 0; k < triangles.size(); ++k)
    pdf[triangles[k]] = float(double(average(power[k])) / total()) / scene.triangleArea(triangles[k]);
  return pdf;
}

}  // namespace lo
