#pragma once
/// @file scene/sky_sampler.h
/// @brief Directions towards a scene's sky (Scene::sky) drawn in proportion to
/// its light, for the stages that sample it: the photon tracer (where a sky
/// photon comes from) and the reference path tracer (next-event estimation,
/// weighted by multiple importance against BSDF sampling). One rule for both,
/// so that they agree on the density of every direction.
///
/// A sky image's texels above the horizon are picked in proportion to their
/// mean radiance times their solid angle times `weight(d)` at the texel's
/// centre (the photon tracer's covered-box silhouette; 1 by default), then a
/// direction uniform in the texel's solid angle; a uniform sky's directions
/// are uniform over the upper hemisphere.

#include <functional>
#include <vector>

#include "core/discrete_distribution.h"
#include "core/math.h"
#include "scene/scene.h"

namespace lo {

class SkySampler {
 public:
  SkySampler() = default;
  /// `sky` must outlive the sampler (its image is shared, not copied).
  explicit SkySampler(const Sky& sky, const std::function<float(const Vec3&)>& weight = {});

  /// No sky, or an image with no light above the horizon.
  bool empty() const { return sky_ == nullptr; }
  /// A direction towards the sky (unit, y > 0) and its solid-angle density,
  /// from u0 (53 random bits: the texel) and u1, u2; false when the draw is
  /// degenerate (the horizon itself).
  bool sample(double u0, float u1, float u2, Vec3& towards, float& pdf) const;
  /// The density sample() draws `towards` with; 0 below the horizon.
  float pdf(const Vec3& towards) const;

 private:
  const Sky* sky_ = nullptr;
  int width_ = 0, height_ = 0;  ///< the image's; 0 for a uniform sky
  /// Over the texels above the horizon, index y * width + x.
  DiscreteDistribution texels_;
};

}  // namespace lo
