#pragma once
/// @file lightgrid/grid_noise.h
/// @brief One figure for how noisy a bake is, from the per-voxel noise
/// (LightGridVoxels::noise): what `bake --target-error` aims at, the bake's
/// report and `inspect` print (docs/accuracy.md, "How good is a bake").

#include <cstddef>
#include <string>
#include <vector>

#include "lightgrid/vdl_grid.h"

namespace lo {

/// A voxel's noise as the statistic counts it: its standard deviation over
/// max(its irradiance, kNoiseFloorShare x the mean irradiance), luminance, so
/// that a nearly black corner does not demand photons for a relative error
/// nobody sees, and a voxel at a tenth of the mean counts in full.
constexpr double kNoiseFloorShare = 0.1;

/// The statistic: the kNoiseQuantile quantile over the lit surface, each
/// voxel (or surface layer) weighted by its area, so that 90% of the lit
/// area is below it.
constexpr double kNoiseQuantile = 0.9;

struct NoiseSummary {
  bool recorded = false;     ///< the grid holds noise values (false: a file without them)
  /// The noise is of the light seen: each voxel's indirect light's standard
  /// deviation over its direct plus indirect light (summarizeNoise with
  /// `direct`); false: over the indirect light alone.
  bool seen = false;
  size_t lit = 0;            ///< voxels and layers with light
  size_t unlit = 0;          ///< active voxels and layers without light
  double meanLuminance = 0;  ///< area-weighted, over the lit ones, W/m^2
  double litLight = 0;       ///< luminance of the indirect light over the lit surface, W (area x W/m^2)
  double median = 0;         ///< area-weighted median of the counted noise
  double quantile = 0;       ///< area-weighted kNoiseQuantile quantile: the bake's noise figure
  std::string ToString() const;  ///< "noise 4.1% (90% of the lit area below), median 2.3%"
};

/// Summarises `grid`'s noise over layer 0 of every voxel and its surface
/// layers (a layer weighs its voxel's area over the voxel's layer count).
/// With `direct` (luminance of the direct irradiance, W/m^2, per voxel then
/// per entry of grid.layers), the noise of the light seen: the indirect
/// light's standard deviation over direct plus indirect, the floor a tenth
/// of the mean of their sum; meanLuminance stays the indirect light's.
NoiseSummary summarizeNoise(const VdlGrid& grid, const std::vector<float>* direct = nullptr);

}  // namespace lo
