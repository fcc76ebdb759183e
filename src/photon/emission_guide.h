#pragma once
/// @file photon/emission_guide.h
/// @brief Where emissive triangles send their photons. A triangle's light
/// leaves cosine-weighted over its hemisphere, from two random numbers
/// (u1, u2) (cosineHemisphere); most of it leaves an object alone in the
/// open at once (the emissive helmet: 86% of its paths met nothing), and a
/// path that meets nothing stores nothing. The guide cuts the (u1, u2)
/// square of each emissive triangle's side into kRings x kSectors cells and
/// weighs each cell by the share of probe rays from the triangle's centre
/// through it that meet the scene; a path picks its cell by that weight
/// half the time and evenly the other half (every direction stays
/// possible, no photon weighs more than twice its share), then a point
/// uniform in the cell, and its power is multiplied by (1 / cells) / the
/// cell's probability: the expected power in every direction is unchanged
/// (PhotonGuide.* against the analytic form factor). A side whose probes all
/// meet the scene (a light inside a room) or none of them is not guided:
/// its paths draw the same numbers as without a guide. Which triangle a path
/// starts from is weighed by the same probes (pickFactor).

#include <cstdint>
#include <vector>

#include "core/math.h"
#include "scene/emitter_sampler.h"
#include "scene/scene.h"

namespace lo {

class RayTracer;

class EmissionGuide {
 public:
  static constexpr int kRings = 4;    ///< cells along u1 (sin^2 of the angle from the normal)
  static constexpr int kSectors = 8;  ///< cells along u2 (the azimuth)
  static constexpr int kCells = kRings * kSectors;
  static constexpr int kProbesPerCell = 2;
  /// Probe rays at most over all triangles: the most powerful triangles are
  /// guided first, the rest of a scene of very many emissive triangles is not.
  static constexpr size_t kMaxProbeRays = size_t(1) << 21;
  /// The share of a side's paths drawn evenly over its cells, and of a
  /// triangle's pick weight kept whatever its probes met: every direction
  /// and triangle stays possible, no photon weighs more than 1 / kSpread
  /// times its share (as EmitterSampler::samplePoint's texture cells).
  static constexpr float kSpread = 0.5f;

  EmissionGuide() = default;
  /// Probes each side that emits of each entry of `emitters` (a
  /// double-sided material's two sides) with `tracer`, from the triangle's
  /// centre moved `epsilon` off it, up to `reach` (beyond the scene).
  EmissionGuide(const Scene& scene, const EmitterSampler& emitters, const RayTracer& tracer,
                float epsilon, float reach);

  /// True when entry `entry`'s side (`back`: against the winding normal) is
  /// guided; then sample() maps three numbers to the two of cosineHemisphere.
  bool guided(uint32_t entry, bool back) const {
    const size_t i = 2 * size_t(entry) + (back ? 1 : 0);
    return i < table_.size() && table_[i] >= 0;
  }
  /// (u0, u1, u2) in [0, 1)^3 to (u1, u2) of a guided side's direction, and
  /// the factor of the photon's power ((1 / kCells) / the cell's probability).
  void sample(uint32_t entry, bool back, float u0, float& u1, float& u2, float& weight) const;

  /// How much more often than by its power entry `entry` starts a path:
  /// kSpread, plus the rest times the share of its probes that met the
  /// scene (1 when it was not probed). A triangle whose every probe leaves
  /// into the open (the outside of a lone glowing object) starts half the
  /// paths its power would give it, each carrying twice the power.
  float pickFactor(uint32_t entry) const {
    return size_t(entry) < pick_.size() ? pick_[entry] : 1.0f;
  }

 private:
  std::vector<int32_t> table_;  ///< per entry and side: where its kCells cumulative weights start, or -1
  std::vector<float> cdf_;
  std::vector<float> pick_;  ///< per entry: pickFactor
};

}  // namespace lo
