#pragma once
/// @file reference/light_tree.h
/// @brief Punctual lights drawn at a shading point in O(log n): a binary
/// tree over the point and spot lights' positions (a light BVH, Conty Estevez
/// & Kulla 2018; pbrt-v4's BVHLightSampler without orientation cones), each
/// node choosing a child by a bound on what the child's lights can bring to
/// the point, and the directional lights as one more group. What lets the
/// path tracer's next-event estimation (path_tracer.cpp) cost the same per
/// sample with ten lights or a hundred thousand (issue 43, family 5).
///
/// Importance (W/m^2: the irradiance a light would give without shadows, by
/// its brightest channel): a light's own is exact, I * max(colour) * spot
/// falloff * range window / d^2 * max(0, cos), cos between the direction to
/// it and the normal n (E * max(colour) * max(0, cos) for a directional
/// light); a node's bounds it from above: its lights'
/// summed intensity over the squared distance to its box's centre (at least
/// the box's half diagonal squared), times the largest cosine any direction
/// into the box's bounding sphere makes with n (0 when the sphere lies wholly
/// below the surface's horizon). Light from below the horizon is never
/// drawn, so the tree serves surfaces that only reflect (the path tracer's
/// smooth lobes, material/bsdf.h evalBsdf): there a light it never draws
/// contributes nothing, and every draw is unbiased with its pmf.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/discrete_distribution.h"
#include "core/math.h"
#include "scene/scene.h"

namespace lo {

/// What punctual light `light` sends to point p without shadows: its
/// irradiance perpendicular to the direction (W/m^2, RGB: intensity times
/// the spot falloff and the range window over d^2, KHR_lights_punctual), the
/// unit direction towards it `wi` and its distance `dist` (infinite for a
/// directional light). Zero at its own position and outside its cone or
/// range. The path tracer's shading and the tree's importance both read it.
Vec3 punctualIrradiance(const Light& light, const Vec3& p, Vec3& wi, float& dist);

class LightTree {
 public:
  LightTree() = default;
  /// The lights of `lights` whose power is positive (intensity > 0 and a
  /// colour above 0); indices refer to `lights`, which must outlive the tree.
  explicit LightTree(const std::vector<Light>& lights);

  /// Lights the tree draws from.
  size_t size() const { return count_; }
  bool empty() const { return count_ == 0; }

  /// One light for the surface point `p` with unit normal `n`, u in [0, 1):
  /// its index into the lights and the probability of drawing it (> 0).
  /// False when the walk finds no light that can reach p from above its
  /// horizon (a node whose bound is positive over lights that are all dark
  /// at p): such a draw counts as no light, and the estimate stays unbiased,
  /// as every light that can light p has its probability.
  bool sample(const Vec3& p, const Vec3& n, double u, uint32_t& light, float& pmf) const;

  /// The probability that sample(p, n, .) returns `light` (0 when never, or
  /// for a light not in the tree). For tests: the pmfs at a point sum to at
  /// most 1, the rest being the draws that find no light.
  float pmf(const Vec3& p, const Vec3& n, uint32_t light) const;

  /// A light's exact importance at (p, n): its irradiance there without
  /// shadows, W/m^2, by its brightest channel.
  static float importance(const Light& light, const Vec3& p, const Vec3& n);

 private:
  struct Node {
    Vec3 lower, upper;    ///< bounds of the positions of the node's lights
    float power = 0;      ///< sum of intensity * max(colour), W/sr
    int32_t second = -1;  ///< interior: the second child (the first is the next node); leaf: -1
    uint32_t light = 0;   ///< leaf: the light's index
  };
  int32_t build(std::vector<uint32_t>& order, size_t begin, size_t end, int32_t parent);
  float nodeImportance(int32_t node, const Vec3& p, const Vec3& n) const;
  /// The probability of drawing from the tree of point and spot lights
  /// rather than from the directional group, at (p, n).
  double treeShare(const Vec3& p, const Vec3& n) const;

  const std::vector<Light>* lights_ = nullptr;
  size_t count_ = 0;
  std::vector<Node> nodes_;               ///< point and spot lights, depth first; empty without any
  std::vector<int32_t> parent_;           ///< per node; -1 at the root
  std::vector<int32_t> leafOf_;           ///< per light: its leaf, or -1
  std::vector<uint32_t> directional_;     ///< directional lights with positive power
  DiscreteDistribution directionalPick_;  ///< those by E * max(colour)
  double directionalTotal_ = 0;           ///< their summed E * max(colour), W/m^2
};

}  // namespace lo
