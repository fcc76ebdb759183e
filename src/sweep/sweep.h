#pragma once
/// @file sweep/sweep.h
/// @brief `lightoctree sweep`: the speed/accuracy trade of the bake, measured.
/// Each point bakes the scene in this process through the bake module
/// (bake/bake.h; its peak memory measured from a reset of the kernel's peak
/// resident set), evaluates the octree's indirect irradiance at the
/// reference's first hits (octree/octree_irradiance.h), renders the indirect
/// image and its frame time with the GL renderer, and compares both with
/// path-traced references rendered once per scene and cached. Points vary one parameter at a time around the paper's settings
/// (depth 6, 600k photons, KNN 300, 4 VDLs), plus a few combined points.
/// Results, tables and gnuplot plots go to one folder; see docs/accuracy.md.

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "core/progress.h"

namespace lo {

/// One setting of the bake and of the lookup. Every default is the bake
/// module's (BakeParams, kDefaultRadiusVoxels), so the paper's point is what
/// `lightoctree bake` does without flags.
struct SweepPoint {
  std::string group = "paper";  ///< the parameter this point varies ("paper", "depth", ...)
  int depth = kAutoDepthMin;  ///< the paper's 6 (a sweep names its depths)
  size_t photons = BakeParams{}.photons;
  int knn = BakeParams{}.knn;
  float radiusVoxels = kDefaultRadiusVoxels;  ///< gather radius in voxel sizes at this depth
  std::string vdls = BakeParams{}.vdls.ToString();  ///< "1".."8" or "auto"
  bool interpolation = true;     ///< trilinear lookup over 8 voxels
  bool halfFloat = false;        ///< RGBA16UI half-float VDL texels instead of RGBA32F
  bool cosineCorrection = true;  ///< GpuOctreeParams::cosineCorrection (off: the paper's form)
  bool layers = true;            ///< BakeParams::layers (surface layers)
  bool occlusion = true;         ///< BakeParams::occlusion (gather occlusion)
  bool edgeCorrection = true;    ///< BakeParams::edgeCorrection
  bool smoothing = BakeParams{}.smoothing;  ///< BakeParams::smoothing
  std::string representation = "vdl";     ///< BakeParams::representation: "vdl", "sh1", "sh2"
  float tolerance = 0.0f;  ///< GpuOctreeParams::tolerance (adaptive leaves; 0 = uniform tree)
  /// BakeParams::targetError: > 0 bakes to this noise figure (photons and
  /// knn then follow from it; `photons` is ignored).
  double targetError = 0;

  /// Short human label, e.g. "d6 600k k300 r1.5 v4" (+ " no-interp", " half",
  /// " paper-cosine", " no-layers", " no-occlusion", " no-edge", " smooth",
  /// " sh1", " sh2", " tol0.1").
  std::string label() const;
  /// File-name-safe key of the bake parameters only (points that differ only
  /// in interpolation or texel format share one bake).
  std::string bakeKey() const;
  /// File-name-safe key of the whole point.
  std::string key() const;
  bool sameSettings(const SweepPoint& other) const { return key() == other.key(); }
};

/// The paper's settings (§5: depth 6, 600k photons, KNN 300, 4 VDLs).
SweepPoint paperPoint();

enum class SweepScale {
  Full,   ///< every issue range: depth 3-8, photons 50k-5M, k 10-1000, radius, VDLs, lookup
  Quick,  ///< a reduced set around the paper's point (a few minutes on 2 cores)
  Tiny,   ///< three cheap points and tiny images: a smoke test of the machinery
};

/// One point per setting, the paper's point first, duplicates removed.
std::vector<SweepPoint> sweepPoints(SweepScale scale);

/// What one point costs and how wrong it is.
struct SweepResult {
  SweepPoint point;
  // Bake, wall-clock seconds.
  double traceSeconds = 0, voxelizeSeconds = 0, splatSeconds = 0, clusterSeconds = 0;
  double bakeSeconds = 0;   ///< every stage, load and write included
  /// Peak resident memory the bake added: the kernel's peak resident set
  /// during the bake (reset before it) above the resident set before it.
  double peakRssBytes = 0;
  double vdbBytes = 0;      ///< the .vdb file
  double gpuBytes = 0;      ///< octree pool + VDL texture as uploaded
  double activeVoxels = 0, denseVoxels = 0;
  double storedPhotons = 0;  ///< photons the bake stored (a target bake's last pass)
  double noiseFigure = -1;   ///< the bake's noise figure (NoiseSummary::quantile); < 0: none
  double vdlTexels = 0;  ///< VDLs stored in the GPU texture
  double gpuLeaves = -1;  ///< leaves of the GPU octree (< 0: not recorded)
  double frameMs = -1;   ///< OSMesa frame time, indirect mode; < 0: not measured
  // Errors against the references (luminance; relative RMSE and MAE).
  double irradianceRelRmse = 0, irradianceRelMae = 0;
  /// The same over kSweepBin x kSweepBin bins (the fronts' error).
  double irradianceBinnedRelRmse = 0;
  double indirectRelRmse = -1;  ///< < 0: not measured
  /// The references' own noise (relative RMS standard error of luminance):
  /// the floor under the two errors above.
  double referenceIrradianceNoise = 0, referenceIndirectNoise = 0;
  double referenceIrradianceBinnedNoise = 0;  ///< over the bins
  bool paretoTime = false;    ///< on the front of irradiance error vs bake time
  bool paretoMemory = false;  ///< on the front of irradiance error vs GPU bytes
};

/// Flags of the non-dominated points when minimising both cost and error
/// (ties in both count as non-dominated). Sizes must match.
std::vector<bool> paretoFront(const std::vector<double>& cost, const std::vector<double>& error);

/// Sets paretoTime / paretoMemory of every result.
void markParetoFronts(std::vector<SweepResult>& results);

struct SweepParams {
  std::string scene;       ///< .gltf, .glb or .obj
  std::string outDir;      ///< results; bulky files go to outDir/cache
  SweepScale scale = SweepScale::Full;
  std::vector<SweepPoint> points;  ///< empty = sweepPoints(scale)
  int width = 160, height = 120;   ///< images compared (scene camera, else framed)
  /// Path-traced samples per pixel of each reference. Irradiance is smooth, so
  /// small images with many samples: the reference's own noise (relative RMS
  /// standard error, printed and stored in cache/reference.json) is the floor
  /// of every error measured against it.
  int referenceSpp = 8192;
  int frames = 5;   ///< frames timed per point (0: no indirect render)
  int threads = 0;  ///< bake / reference threads (0 = all cores)
  uint64_t seed = 1;
  ProgressSink* progress = nullptr;  ///< the references' progress (may be null)
};

/// Standard parameters for a scale (image size, reference samples, frames).
SweepParams sweepDefaults(SweepScale scale);

/// Runs every point (reusing outDir/cache results of an earlier run with the
/// same settings and program version, so an interrupted sweep resumes),
/// prints one line per point to `log` (may be null). @throws InputError /
/// IoError naming the file, or the stage's error.
std::vector<SweepResult> runSweep(const SweepParams& params, std::FILE* log);

/// Writes outDir/sweep.csv, outDir/sweep.md and, if gnuplot is found,
/// outDir/error-vs-bake-time.png and outDir/error-vs-memory.png (with the
/// data and script beside them so that the plots can be redrawn).
void writeSweepReport(const SweepParams& params, const std::vector<SweepResult>& results,
                      std::FILE* log);

/// The CSV text of the results (header line first).
std::string sweepCsv(const std::vector<SweepResult>& results);

}  // namespace lo
