#pragma once
/// @file core/discrete_distribution.h
/// @brief One rule for drawing an entry of a list in proportion to its weight,
/// shared by every stage that picks lights: the photon tracer's lights of
/// every kind (punctual, sun, sky, emissive triangles), the emissive
/// triangles by power (scene/emitter_sampler.h: the path tracer's next-event
/// estimation and the renderer's virtual point lights) and a sky image's
/// texels (scene/sky_sampler.h). pbrt-v4's PowerLightSampler and
/// PiecewiseConstant1D in one small class: Sample(u) -> entry, Pmf(entry).
///
/// The weights are summed in double in entry order, so that a list of
/// millions of emissive triangles keeps every entry's share and the same
/// list gives the same draws on every machine.

#include <algorithm>
#include <cstddef>
#include <vector>

namespace lo {

class DiscreteDistribution {
 public:
  DiscreteDistribution() = default;

  /// Appends an entry of weight w >= 0 (a negative or NaN weight counts as 0).
  void add(double w) {
    w = w > 0 ? w : 0.0;
    weights_.push_back(w);
    cdf_.push_back(total() + w);
  }
  void reserve(size_t n) {
    weights_.reserve(n);
    cdf_.reserve(n);
  }

  bool empty() const { return weights_.empty(); }
  size_t size() const { return weights_.size(); }
  /// The sum of the weights.
  double total() const { return cdf_.empty() ? 0.0 : cdf_.back(); }
  double weight(size_t k) const { return weights_[k]; }

  /// The entry whose stretch of [0, total) holds u * total, u in [0, 1)
  /// (53 random bits for long lists); `remapped`, when given, receives
  /// where in that stretch u fell, in [0, 1], for a second dimension.
  /// Entries of weight 0 are never drawn. Requires total() > 0.
  size_t sample(double u, double* remapped = nullptr) const {
    const double x = u * total();
    size_t k = size_t(std::upper_bound(cdf_.begin(), cdf_.end(), x) - cdf_.begin());
    k = std::min(k, cdf_.size() - 1);
    if (remapped) {
      const double before = k > 0 ? cdf_[k - 1] : 0.0;
      const double width = cdf_[k] - before;
      *remapped = width > 0 ? std::clamp((x - before) / width, 0.0, 1.0) : 0.0;
    }
    return k;
  }

  /// The probability that sample() returns entry k: weight(k) / total().
  double pmf(size_t k) const { return weights_[k] / total(); }

 private:
  std::vector<double> weights_;
  std::vector<double> cdf_;  ///< inclusive running sums; back() = total
};

/// One of `count` cells whose cumulative weights are `cdf` (cdf[count - 1] >
/// 0): evenly with probability `spread`, else by its weight, u in [0, 1)
/// rescaled for the choice within each branch. `weight` receives (1 / count)
/// / the cell's probability, the factor that keeps an estimate unbiased; no
/// cell weighs more than 1 / spread. The texture cells of an emissive
/// triangle (scene/emitter_sampler.h) and the direction cells of its light
/// (photon/emission_guide.h) are picked so.
inline int pickCellWithSpread(const float* cdf, int count, float spread, float u, float& weight) {
  const float total = cdf[count - 1];
  int cell = 0;
  if (u < spread) {
    cell = std::min(int(u / spread * float(count)), count - 1);
  } else {
    const float x = (u - spread) / (1.0f - spread) * total;
    cell = std::min(int(std::upper_bound(cdf, cdf + count, x) - cdf), count - 1);
  }
  const float w = cdf[cell] - (cell > 0 ? cdf[cell - 1] : 0.0f);
  const float p = spread / float(count) + (1.0f - spread) * w / total;
  weight = 1.0f / (float(count) * p);
  return cell;
}

}  // namespace lo
