#pragma once
/// @file scene/emitter_sampler.h
/// @brief The power distribution over a scene's emissive triangles, built once
/// for every stage that picks emitters by power: the photon tracer (where a
/// photon path starts), the reference path tracer (next-event estimation) and
/// the renderer (virtual point lights). One rule for all three, so that they
/// agree on which triangles emit and how much.
///
/// A triangle emits when its material is emissive, its area is positive and
/// its mean emission (Scene::triangleEmission) is positive. Its power is that
/// of a Lambertian emitter of radiance L over area A: pi L A per emitting
/// side, glTF `doubleSided` emitting from both (W, per RGB channel).

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/discrete_distribution.h"
#include "core/math.h"
#include "scene/scene.h"

namespace lo {

struct EmitterSampler {
  /// Emissive triangles, ascending, into the Scene's triangles.
  std::vector<uint32_t> triangles;
  /// Per entry: emitted power pi L A * sides, W (RGB).
  std::vector<Vec3> power;
  /// Per entry: its mean radiance L (Scene::triangleEmission), W/(m^2 sr).
  std::vector<Vec3> emission;
  /// The entries by average(power), summed in double in triangle order.
  DiscreteDistribution distribution;

  bool empty() const { return triangles.empty(); }
  size_t size() const { return triangles.size(); }
  /// Sum of average(power) over every emitter, W.
  double total() const { return distribution.total(); }
  /// The entry whose stretch of the distribution holds u * total(), u in [0, 1).
  size_t pick(double u) const { return distribution.sample(u); }
  /// Probability that pick() returns entry k.
  double pickProbability(size_t k) const { return distribution.pmf(k); }
  /// Per triangle of the scene: pick probability / area (the area density
  /// of a point drawn uniformly on the picked triangle), 0 for triangles that
  /// do not emit. size() = the scene's triangle count.
  std::vector<float> areaPdfs(const Scene& scene) const;

  /// Emissive textures: where on a triangle its light comes from. The
  /// triangle is cut into kEmitterCells equal sub-triangles (8 x 8 along
  /// its edges), each weighted by the emission at 4 of the 256 points its
  /// mean (Scene::triangleEmission) averages; a point is drawn in a cell
  /// picked by that weight three times in four and evenly the fourth (no
  /// emitting texel is missed and no photon weighs more than 4 times its
  /// share), then uniformly in it. Per entry: -1 (no texture: uniform points), or
  /// where its kEmitterCells cumulative weights start in cellCdf.
  std::vector<int32_t> cellTable;
  std::vector<float> cellCdf;
  /// A point on entry k's triangle for u0, u1, u2 in [0, 1): barycentrics
  /// (b1, b2) of Scene::emission, and the factor (1 / area) / pdf of the
  /// point, by which a photon's power is multiplied (1 without a texture).
  void samplePoint(size_t k, float u0, float u1, float u2, float& b1, float& b2,
                   float& weight) const;
};

/// Sub-triangles per emitting triangle for EmitterSampler::samplePoint.
constexpr int kEmitterCells = 64;

/// @throws InputError naming the material and triangle when an emitter's
/// power is not finite (an emission so large that pi L A overflows).
EmitterSampler buildEmitterSampler(const Scene& scene);

}  // namespace lo
