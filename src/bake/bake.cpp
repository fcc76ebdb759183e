// bake(): the stages of paper §3.1 in order, timed, with the defaults of
// `lightoctree bake`.

#include "bake/bake.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "cluster/volume_light.h"
#include "core/error.h"
#include "core/printable.h"
#include "scene/scene_files.h"
#include "raytrace/ray_tracer.h"

namespace lo {

std::string VdlCount::ToString() const { return automatic ? "auto" : std::to_string(count); }

std::string vdlCountError(const std::string& text) {
  if (text == "auto") return {};
  try {
    size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size() && v >= 1 && v <= kMaxVdls) return {};
  } catch (const std::exception&) {
  }
  return "must be an integer from 1 to " + std::to_string(kMaxVdls) + " or 'auto', got '" + text +
         "'";
}

VdlCount parseVdlCount(const std::string& text, const char* flag) {
  const std::string error = vdlCountError(text);
  if (!error.empty()) throw InputError(std::string(flag) + ": " + error);
  VdlCount c;
  if (text == "auto") {
    c.automatic = true;
    c.count = kMaxVdls;
  } else {
    c.count = std::stoi(text);
  }
  return c;
}

PhotonParams BakeParams::photonParams() const {
  PhotonParams p;
  p.storedPhotons = photons;
  p.includeDirect = includeDirect;
  p.seed = seed;
  p.region = region;
  p.segments = freeSpace;
  p.maxSegments = freeSpaceRays;
  return p;
}

VolumeLightParams BakeParams::volumeParams() const {
  VolumeLightParams p;
  p.levels = freeSpaceLevels;
  p.shTerms = freeSpaceOrder == 1 ? 4 : 9;
  return p;
}

GridParams BakeParams::gridParams() const {
  GridParams p;
  p.depth = depth;
  p.region = region;
  return p;
}

int targetKnn(double targetError) {
  if (!(targetError > 0)) return 0;
  return int(std::min(1e5, std::ceil(3.0 / (targetError * targetError))));
}

int BakeParams::effectiveKnn() const {
  return targetError > 0 ? std::max(knn, targetKnn(targetError)) : knn;
}

GatherParams BakeParams::gatherParams() const {
  GatherParams p;
  p.k = effectiveKnn();
  p.radius = radius;
  p.edgeCorrection = edgeCorrection;
  p.separateCaustics = separateCaustics;
  return p;
}

ClusterParams BakeParams::clusterParams() const {
  ClusterParams p;
  p.seed = seed;
  p.vdls = vdls.automatic ? autoCap : vdls.count;
  p.autoCount = vdls.automatic;
  p.autoThreshold = autoThreshold;
  p.representation = representation;
  return p;
}

std::string BakeParams::ToString() const {
  const std::string budget =
      targetError > 0 ? "target error " + std::to_string(targetError) + ", max photons " +
                            std::to_string(maxPhotons)
                      : "photons " + std::to_string(photons);
  return "BakeParams{depth " + std::to_string(depth) + ", " + budget +
         ", knn " + std::to_string(effectiveKnn()) + ", radius " + std::to_string(radius) + ", vdls " +
         vdls.ToString() + ", representation " + representationName(representation) +
         ", seed " + std::to_string(seed) +
         (includeDirect ? ", include direct" : "") + (layers ? "" : ", no layers") +
         (occlusion ? "" : ", no occlusion") + (edgeCorrection ? "" : ", no edge correction") +
         (separateCaustics ? "" : ", caustics merged") +
         (smoothing ? ", smoothing" : "") +
         (freeSpace ? ", free space " + std::to_string(freeSpaceLevels) + " levels up, SH order " +
                          std::to_string(freeSpaceOrder)
                    : "") +
         "}";
}

// Segments are tested in a frame centred on the scene: its floats are finest
// there, as the photon tracer's are.
GatherOcclusion::GatherOcclusion(const Scene& scene) : origin_(scene.tracingOrigin()) {
  tracer_ = std::make_unique<RayTracer>(origin_ == Vec3{0, 0, 0} ? scene
                                                                 : scene.translated(-origin_));
}

GatherOcclusion::~GatherOcclusion() = default;

SurfaceProbe GatherOcclusion::surfaceProbe() const {
  const RayTracer* tracer = tracer_.get();
  const Vec3 origin = origin_;
  return [tracer, origin](const Vec3& p, const Vec3& n, float h) {
    // Down the segment from p + n h, past surfaces that face another way
    // (a few at most: the first facing one answers).
    const Vec3 down = -n;
    const Vec3 from = p + n * h - origin;
    float tmin = 0;
    for (int crossed = 0; crossed < 8; ++crossed) {
      Hit hit;
      if (!tracer->intersectBetween(from, down, hit, tmin, 2.0f * h)) return false;
      if (std::fabs(dot(hit.geometricNormal, n)) > 0.5f) return true;
      tmin = std::nextafter(hit.t, std::numeric_limits<float>::infinity());
    }
    return false;
  };
}

SegmentBlocked GatherOcclusion::test() const {
  const RayTracer* tracer = tracer_.get();
  const Vec3 origin = origin_;
  return [tracer, origin](const Vec3& from, const Vec3& to) {
    return tracer->occluded(from - origin, to - from, 1.0f - 1e-4f);
  };
}

namespace {

SurfaceGrid voxelize(const Scene& scene, const GridParams& params, ProgressSink* progress,
                     LevelStats& s, std::vector<StageReport>& rows) {
  StageTimer voxelize(rows, "voxelize");
  SurfaceGrid grid = buildSurfaceGrid(scene, params, progress);
  s.activeVoxels = grid.size();
  const size_t dense = size_t(1) << (3 * params.depth);
  s.voxelizeSeconds =
      voxelize.finish(formatCount(grid.size()) + " of " + formatCount(dense) + " voxels active at depth " +
                      std::to_string(params.depth));
  return grid;
}

void splat(SurfaceGrid& grid, const std::vector<Photon>& photons, LevelStats& s,
           std::vector<StageReport>& rows) {
  StageTimer splat(rows, "splat photons");
  s.droppedPhotons = splatPhotons(grid, photons);
  s.splatSeconds =
      splat.finish(s.droppedPhotons ? formatCount(s.droppedPhotons) + " photons outside the grid"
                                    : "");
}

}  // namespace

SurfaceGrid voxelizeAndSplat(const Scene& scene, const std::vector<Photon>& photons,
                             const GridParams& params, ProgressSink* progress, LevelStats* stats,
                             std::vector<StageReport>* stages) {
  std::vector<StageReport> ignored;
  std::vector<StageReport>& rows = stages ? *stages : ignored;
  LevelStats s;
  SurfaceGrid grid = voxelize(scene, params, progress, s, rows);
  splat(grid, photons, s, rows);
  if (stats) *stats = s;
  return grid;
}

namespace {

/// gatherLevel after its splat: the gather and clustering of every voxel.
VdlGrid gatherSplatted(const Scene& scene, SurfaceGrid& grid, const std::vector<Photon>& photons,
                       const LevelParams& params, ProgressSink* progress, LevelStats& s,
                       std::vector<StageReport>& rows) {
  StageTimer cluster(rows, "gather + cluster");
  GatherParams gather = params.gather;
  std::unique_ptr<GatherOcclusion> occlusion;
  if (params.occlusion && !gather.blocked && scene.triangleCount() > 0) {
    occlusion = std::make_unique<GatherOcclusion>(scene);
    gather.blocked = occlusion->test();
    if (gather.edgeCorrection) gather.surfaceAt = occlusion->surfaceProbe();
  }
  const LayerParams layerParams;
  VdlGrid vdls = buildVdlGrid(grid, photons, gather, params.cluster, progress, &s.threadSeconds,
                              params.layers ? &layerParams : nullptr);
  if (params.smoothing) smoothVdlGrid(grid, vdls);
  size_t layered = 0;
  for (size_t e = 0; e < vdls.layers.size(); ++e) {
    if (e == 0 || vdls.layers.voxel[e] != vdls.layers.voxel[e - 1]) ++layered;
  }
  s.layeredVoxels = layered;
  s.extraLayers = vdls.layers.size();
  char split[160];
  std::snprintf(split, sizeof split, "%s voxels with 2+ layers; thread-seconds: gather %.3f, K-means %.3f",
                formatCount(layered).c_str(), s.threadSeconds.gatherSeconds, s.threadSeconds.clusterSeconds);
  s.gatherClusterSeconds = cluster.finish(split);
  s.radius = resolveRadius(params.gather, grid.frame);
  return vdls;
}

}  // namespace

VdlGrid gatherLevel(const Scene& scene, SurfaceGrid& grid, const std::vector<Photon>& photons,
                    const LevelParams& params, ProgressSink* progress, LevelStats* stats,
                    std::vector<StageReport>* stages) {
  std::vector<StageReport> ignored;
  std::vector<StageReport>& rows = stages ? *stages : ignored;
  LevelStats s;
  if (stats) s = *stats;  // keeps the voxelize figures
  s.activeVoxels = grid.size();
  splat(grid, photons, s, rows);
  VdlGrid vdls = gatherSplatted(scene, grid, photons, params, progress, s, rows);
  if (stats) *stats = s;
  return vdls;
}

VdlGrid bakeLevel(const Scene& scene, const std::vector<Photon>& photons, const LevelParams& params,
                  ProgressSink* progress, LevelStats* stats, std::vector<StageReport>* stages) {
  std::vector<StageReport> ignored;
  std::vector<StageReport>& rows = stages ? *stages : ignored;
  LevelStats s;
  SurfaceGrid grid = voxelize(scene, params.grid, progress, s, rows);
  VdlGrid vdls = gatherLevel(scene, grid, photons, params, progress, &s, &rows);
  if (stats) *stats = s;
  return vdls;
}

void checkDepth(int depth, const std::string& what) { checkNumber(depth, kDepthRange, what); }

int autoDepth(const Bounds3& region) {
  for (int depth = kAutoDepthMin; depth < kAutoDepthMax; ++depth) {
    if (makeGridFrame(region, depth).voxelSize <= kAutoVoxelSize) return depth;
  }
  return kAutoDepthMax;
}

std::string depthError(const std::string& text) {
  if (text == "auto") return {};
  try {
    size_t used = 0;
    const int v = std::stoi(text, &used);
    if (used == text.size() && kDepthRange.contains(double(v))) return {};
  } catch (const std::exception&) {
  }
  return "must be 'auto' or " + kDepthRange.ToString() + ", got '" + printable(text) + "'";
}

int parseDepth(const std::string& text, const char* flag) {
  const std::string error = depthError(text);
  if (!error.empty()) throw InputError(std::string(flag) + ": " + error);
  return text == "auto" ? kAutoDepth : std::stoi(text);
}

namespace {

void checkParams(const BakeParams& p, int processes) {
  checkDepth(p.depth);
  checkNumber(double(p.photons), kPhotonsRange, "--photons");
  if (!(p.targetError >= 0) || !(p.targetError <= 1)) {
    throw InputError("--target-error " + formatNumber(p.targetError) +
                     " is outside (0, 1] (a relative error: 0.05 is 5%)");
  }
  if (p.targetError > 0 && p.maxPhotons < 1) throw InputError("--max-photons must be at least 1");
  if (!(p.maxSeconds >= 0) || !std::isfinite(p.maxSeconds)) {
    throw InputError("--max-seconds " + formatNumber(p.maxSeconds) + " must be a finite time >= 0");
  }
  if (!p.region.empty() &&
      (!isFinite(p.region.lower) || !isFinite(p.region.upper) ||
       !(maxComponent(p.region.extent()) > 0))) {
    throw InputError("--bounds " + p.region.ToString() + " is not a finite box");
  }
  // The photon map and its bins cost about kBakeBytesPerPhoton each (measured
  // at depths 6 to 8, docs/scale.md): refuse before tracing what cannot fit.
  const size_t available = availableMemoryBytes();
  const double needed = double(p.photons) * double(kBakeBytesPerPhoton) / double(processes);
  if (p.targetError == 0 && available > 0 && needed > double(available)) {
    throw InputError("--photons " + std::to_string(p.photons) + " needs about " +
                     formatBytes(size_t(needed)) + " (" + std::to_string(kBakeBytesPerPhoton) +
                     " bytes per stored photon), more than the " + formatBytes(available) +
                     " of memory available: store fewer photons");
  }
  checkNumber(p.knn, kKnnRange, "--knn");
  if (!(p.radius >= 0.0f) || !std::isfinite(p.radius)) {
    throw InputError("--radius " + std::to_string(p.radius) + " must be a finite positive length");
  }
  if (p.vdls.automatic && (p.autoCap < 1 || p.autoCap > kMaxVdls)) {
    throw InputError("--auto-cap " + std::to_string(p.autoCap) + " is outside [1, " +
                     std::to_string(kMaxVdls) + "]");
  }
  if (p.vdls.automatic && !(p.autoThreshold > 0 && p.autoThreshold <= 2)) {
    throw InputError("--auto-threshold " + formatNumber(p.autoThreshold) +
                     " is outside (0, 2] (a chord length)");
  }
  if (!p.vdls.automatic && (p.vdls.count < 1 || p.vdls.count > kMaxVdls)) {
    throw InputError("--vdls " + std::to_string(p.vdls.count) + " is outside [1, " +
                     std::to_string(kMaxVdls) + "]");
  }
}

}  // namespace

double estimateActiveVoxels(const Scene& scene, const GridFrame& frame, const Bounds3& region) {
  double area = 0;
  for (size_t t = 0; t < scene.triangleCount(); ++t) {
    if (!region.empty()) {
      Bounds3 b;
      for (int k = 0; k < 3; ++k) b.extend(scene.positions[scene.indices[3 * t + size_t(k)]]);
      if (b.lower.x > region.upper.x || b.upper.x < region.lower.x || b.lower.y > region.upper.y ||
          b.upper.y < region.lower.y || b.lower.z > region.upper.z || b.upper.z < region.lower.z) {
        continue;
      }
    }
    area += double(scene.triangleArea(t));
  }
  const double h = double(frame.voxelSize);
  // Coincident surfaces (instances at one place, shared-buffer primitives)
  // add area but no voxels: the grid has resolution^3 at most.
  const double cells = std::pow(double(frame.resolution()), 3.0);
  return h > 0 ? std::min(area / (h * h), cells) : 0.0;
}

void setPhotonBudget(BakeParams& params, size_t photons, double targetError) {
  // 0 is "not given"; anything else is a target, checked (NaN is not 0).
  if (targetError != 0) checkNumber(targetError, kTargetErrorRange, "--target-error");
  if (photons > 0 && targetError != 0) {
    throw InputError("give photons (a fixed budget, --photons) or a target error (photons until "
                     "the noise reaches it, --target-error), not both");
  }
  if (photons > 0) {
    params.photons = photons;
    params.targetError = 0;
  } else {
    params.targetError = targetError != 0 ? targetError : kDefaultTargetError;
  }
}

void checkVoxelMemory(const Scene& scene, const GridFrame& frame, const Bounds3& region,
                      double otherBytes, int processes) {
  const size_t available = availableMemoryBytes();
  if (available == 0 || scene.triangleCount() == 0) return;
  const double voxels = estimateActiveVoxels(scene, frame, region);
  const double needed =
      (voxels * double(kBakeBytesPerVoxel) + otherBytes) / double(std::max(processes, 1));
  if (needed > double(available)) {
    throw InputError("--depth " + std::to_string(frame.depth) + ": the scene's surfaces cross " +
                     "about " + formatCount(size_t(voxels)) + " voxels of " +
                     formatNumber(frame.voxelSize) + " scene units, which " +
                     (otherBytes > 0 ? "with the photons " : "") + "need about " +
                     formatBytes(size_t(needed)) + " (" + std::to_string(kBakeBytesPerVoxel) +
                     " bytes per voxel), more than the " + formatBytes(available) +
                     " of memory available: use a smaller --depth, or only the part "
                     "that matters (bake --bounds)");
  }
}

std::string sparsePhotonsWarning(const Scene& scene, const BakeParams& params) {
  if (params.photons == 0 || params.targetError > 0 || params.depth == kAutoDepth) return "";
  const GridFrame frame =
      makeGridFrame(params.region.empty() ? scene.bounds() : params.region, params.depth);
  return sparsePhotonsWarning(scene, frame, params.region, params.photons,
                              "--photons " + formatCount(params.photons),
                              "--depth auto picks the depth the photons resolve, or give more "
                              "--photons");
}

std::string sparsePhotonsWarning(const Scene& scene, const GridFrame& frame, const Bounds3& region,
                                 size_t photons, const std::string& what,
                                 const std::string& advice) {
  constexpr double kManyVoxels = 1e6, kPhotonsPerVoxel = 0.1;
  if (scene.triangleCount() == 0) return "";
  const double voxels = estimateActiveVoxels(scene, frame, region);
  const double perVoxel = double(photons) / std::max(voxels, 1.0);
  if (voxels < kManyVoxels || perVoxel >= kPhotonsPerVoxel) return "";
  char share[32];
  std::snprintf(share, sizeof share, "%.2g", perVoxel);
  return "--depth " + std::to_string(frame.depth) + ": the surfaces cross about " +
         formatCount(size_t(voxels)) + " voxels, and " + what + " are " + share +
         " a voxel: each voxel's light is gathered from photons far beyond "
         "it, and the work takes the time and memory of every voxel (about " +
         formatBytes(size_t(voxels * double(kBakeBytesPerVoxel))) + "): " + advice;
}

void checkBakeMemory(const Scene& scene, const BakeParams& params, int processes) {
  const GridFrame frame =
      makeGridFrame(params.region.empty() ? scene.bounds() : params.region, params.depth);
  // A target bake fits its photons to what memory is left (targetPhotonCap).
  const double photons = params.targetError > 0 ? double(kMinPilotPhotons) : double(params.photons);
  checkVoxelMemory(scene, frame, params.region, photons * double(kBakeBytesPerPhoton), processes);
}

std::string photonBudgetWarning(const BakeParams& params, const BakeStats& st) {
  if (st.emittedPaths == 0) return "";
  const bool mostlyMissed = 2 * st.missedPaths > st.emittedPaths;
  const std::string missed = formatCount(st.missedPaths) + " of " +
                             formatCount(st.emittedPaths) +
                             " photon paths missed every surface" +
                             (params.region.empty() ? "" : " in --bounds") +
                             ": bake the part that matters with --bounds";
  // A fixed budget falls short when fewer photons than asked were stored; a
  // target bake when its passes ran out of paths (its other stops are
  // reported by the bake's own summary).
  const bool target = params.targetError > 0;
  const std::string dark = darkLightsWarning(st);
  const std::string traced =
      st.reachStop ? " paths (stopped early: at this rate the most a bake traces would store "
                     "under 1% of them); "
                   : " paths (the most a bake traces); ";
  if (target ? st.targetStop == "no more paths" : st.storedPhotons < params.photons) {
    const std::string head =
        target ? "the noise target was not reached: " + formatCount(st.storedPhotons) +
                     " photons were stored from " + formatCount(st.emittedPaths) + traced
               : "only " + formatCount(st.storedPhotons) + " of " + formatCount(params.photons) +
                     " photons were stored from " + formatCount(st.emittedPaths) + traced;
    if (!dark.empty()) return head + dark;
    if (mostlyMissed) return head + missed;
    return head + formatCount(st.emptyPaths) +
           " paths reached a surface but stored nothing (their first hit is direct light, "
           "left to the renderer, and the light they reflect leaves the scene or is "
           "absorbed): --include-direct stores the first hits too, or --bounds bakes only the "
           "part that matters";
  }
  if (!dark.empty()) return dark;
  return mostlyMissed ? missed : "";
}

std::string darkLightsWarning(const BakeStats& st) {
  if (st.darkLights.empty()) return "";
  std::string names;
  for (const std::string& name : st.darkLights) names += (names.empty() ? "" : "; ") + name;
  return "no photon was stored from " + names +
         ": its light reaches no surface of the grid (under or behind geometry, aimed away, "
         "outside --bounds), or only as direct light (which the renderer draws) that bounces "
         "nowhere the grid holds";
}

void checkPhotonsStored(const BakeParams& params, const BakeStats& st) {
  if (st.storedPhotons > 0) return;
  std::string lights;
  for (const std::string& name : st.darkLights) lights += (lights.empty() ? "" : "; ") + name;
  throw InputError(
      "no photon was stored: " + formatCount(st.emittedPaths) + " photon paths were traced" +
      (lights.empty() ? std::string() : " (from " + lights + ")") + " and " +
      "none left light on a surface after a bounce" +
      (params.region.empty() ? std::string() : std::string(" inside --bounds")) +
      " (the light's first hit is direct light, which the renderer draws and the bake stores "
      "only with --include-direct): check that the lights reach the geometry" +
      (params.region.empty() ? std::string() : std::string(" and that --bounds holds lit surfaces")));
}

BakeParams checkedBakeParams(const Scene& scene, const BakeParams& requested, int processes) {
  // The scene's own region of interest (a glTF marker node) when none is given.
  BakeParams params = requested;
  if (params.region.empty()) params.region = scene.region;
  if (params.depth == kAutoDepth && scene.triangleCount() > 0) {
    // The finer depth only where its memory is there; else the paper's; and
    // no finer than a .vdb stores (a scene of a millimetre: depth 5).
    const Bounds3 region = params.region.empty() ? scene.bounds() : params.region;
    params.depth = autoDepth(region);
    while (params.depth > 1 &&
           !(double(makeGridFrame(region, params.depth).voxelSize) >= kMinStorableVoxel)) {
      --params.depth;
    }
    if (params.depth > kAutoDepthMin) {
      try {
        checkBakeMemory(scene, params, processes);
      } catch (const InputError&) {
        params.depth = kAutoDepthMin;
      }
    }
  }
  if (params.depth == kAutoDepth) params.depth = kAutoDepthMin;
  checkParams(params, processes);
  // A scene of unlit surfaces only (KHR_materials_unlit) holds no light to
  // bake: said at once, where the photons found nothing to store after the
  // whole path budget.
  const bool allUnlit =
      scene.triangleCount() > 0 &&
      std::all_of(scene.triangleMaterial.begin(), scene.triangleMaterial.end(), [&](int32_t m) {
        return m >= 0 && size_t(m) < scene.materials.size() && scene.materials[size_t(m)].unlit;
      });
  if (allUnlit) {
    throw InputError("every surface of the scene is unlit (KHR_materials_unlit): none receives "
                     "or reflects light, so there is no light to bake");
  }
  if (params.freeSpaceOrder != 1 && params.freeSpaceOrder != 2) {
    throw InputError("--free-space-order " + std::to_string(params.freeSpaceOrder) +
                     ": the free-space light's SH are of order 1 or 2");
  }
  if (params.freeSpaceLevels < 0) {
    throw InputError("--free-space-levels " + std::to_string(params.freeSpaceLevels) +
                     ": the free-space grid is 0 or more levels coarser than the surface grid");
  }
  // What the .vdb can store, checked before any work: OpenVDB refuses a
  // transform whose scale cubed is below 3e-15 (math::ScaleMap).
  if (scene.triangleCount() > 0) {
    const GridFrame frame =
        makeGridFrame(params.region.empty() ? scene.bounds() : params.region, params.depth);
    const double h = frame.voxelSize;
    if (!(h * h * h >= kMinStorableVoxel * kMinStorableVoxel * kMinStorableVoxel)) {
      // At depth 1 no smaller depth helps (H10-4-241): the scene's units do.
      throw InputError("--depth " + std::to_string(params.depth) + ": voxels of " +
                       formatNumber(float(h)) + " scene units are smaller than a .vdb stores (" +
                       formatNumber(float(kMinStorableVoxel)) + "): " +
                       (params.depth > 1 ? "bake at a smaller --depth, or the scene in smaller "
                                           "units (a node scale)"
                                         : "the scene is too small for a .vdb at any depth: "
                                           "give it in smaller units (a node scale)"));
    }
    // A radius far below the photons' spacing gathers none: every voxel
    // dark, and a noise figure of 0 (no photon, no variance) that would call
    // the dark bake converged.
    if (params.radius > 0 && !(params.radius >= kMinRadiusVoxels * float(h))) {
      throw InputError("--radius " + formatNumber(params.radius) + " is under " +
                       formatNumber(kMinRadiusVoxels) + " of a voxel (" + formatNumber(float(h)) +
                       " scene units at --depth " + std::to_string(params.depth) +
                       "): the gather would find no photon and the bake would be dark; leave "
                       "it out (" + formatNumber(kDefaultRadiusVoxels) + " voxels) or give at least " +
                       formatNumber(kMinRadiusVoxels * float(h)));
    }
    // A radius beyond the grid's cube gathers every photon for every voxel
    // (and 1e19 scene units made rays Embree aborts on).
    const double cube = double(h) * double(1 << params.depth);
    if (params.radius > 0 && !(double(params.radius) <= cube)) {
      throw InputError("--radius " + formatNumber(params.radius) + " exceeds the grid's cube (" +
                       formatNumber(float(cube)) + " scene units at --depth " +
                       std::to_string(params.depth) +
                       "): the gather would read every photon for every voxel; leave it out (" +
                       formatNumber(kDefaultRadiusVoxels) + " voxels) or give at most " +
                       formatNumber(float(cube)));
    }
  }
  checkBakeMemory(scene, params, processes);
  return params;
}

BakeMetadata bakeMetadata(const Scene& scene, const BakeParams& params, int64_t photons,
                          int64_t emittedPaths, float radius) {
  BakeMetadata meta;
  meta.depth = params.depth;
  meta.photons = photons;
  meta.emittedPaths = emittedPaths;
  meta.knn = params.effectiveKnn();
  meta.radius = radius;
  meta.vdls = params.vdls.ToString();
  meta.representation = representationName(params.representation);
  meta.seed = int64_t(params.seed);
  meta.sceneBounds = scene.bounds();
  meta.skyHash = scene.sky.fingerprint();
  meta.surfaceLayers = params.layers ? 1 : 0;
  meta.gatherOcclusion = params.occlusion ? 1 : 0;
  meta.edgeCorrection = params.edgeCorrection ? 1 : 0;
  meta.includeDirect = params.includeDirect ? 1 : 0;
  meta.region = params.region;
  return meta;
}

namespace {

/// The content hash of `scene`'s files: as loadScene read them, else (a
/// scene made in code with a sourcePath) as they are now; "" without either.
std::string contentHashOf(const Scene& scene) {
  if (!scene.contentHash.empty()) return scene.contentHash;
  return scene.sourcePath.empty() ? std::string() : sceneContentHash(scene.sourcePath);
}

}  // namespace

void recordSourceScene(BakeMetadata& meta, const Scene& scene) {
  const std::string& scenePath = scene.sourcePath;
  if (scenePath.empty()) return;
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(scenePath, ec);
  meta.sourceScene = std::filesystem::path(scenePath).filename().string();
  meta.sourceScenePath = ec ? scenePath : absolute.lexically_normal().string();
  meta.sourceSceneHash = contentHashOf(scene);
}

VolumeLight bakeFreeSpaceLight(const std::vector<PhotonSegment>& segments, const GridFrame& frame,
                               const BakeParams& params, ProgressSink* progress,
                               std::vector<StageReport>& stages) {
  StageTimer timer(stages, "free-space light");
  VolumeLight volume = buildVolumeLight(segments, frame, params.volumeParams(), progress);
  timer.finish(formatCount(volume.size()) + " voxels from " + formatCount(segments.size()) +
               " light rays");
  return volume;
}

namespace {

/// staleBakeWarning of the scene at `scenePath` whose files hash to `now`.
std::string staleWarning(const BakeMetadata& meta, const std::string& scenePath,
                         const std::string& now) {
  if (meta.sourceSceneHash.empty() || now == meta.sourceSceneHash) return "";
  // The path and hash are the file's metadata, whatever another tool wrote.
  return printable("the light was baked from " +
                   (meta.sourceScenePath.empty() ? meta.sourceScene : meta.sourceScenePath) +
                   " (" + meta.sourceSceneHash + "); '" + scenePath +
                   "' and the files it reads differ (" + now +
                   "): bake again if the scene changed");
}

}  // namespace

std::string staleBakeWarning(const BakeMetadata& meta, const std::string& scenePath) {
  if (meta.sourceSceneHash.empty()) return "";
  return staleWarning(meta, scenePath, sceneContentHash(scenePath));
}

std::vector<std::string> gridWarnings(const BakeMetadata& meta, const Scene& scene) {
  std::vector<std::string> warnings;
  const std::string hash = meta.sourceSceneHash.empty() ? std::string() : contentHashOf(scene);
  const std::string stale =
      hash.empty() ? std::string() : staleWarning(meta, scene.sourcePath, hash);
  for (const std::string& w : {stale, skyMismatchWarning(meta, scene.sky)}) {
    if (!w.empty()) warnings.push_back(w);
  }
  return warnings;
}

std::string directTwiceWarning(const BakeMetadata& meta, const std::string& drawnAgain,
                               const std::string& advice) {
  if (meta.includeDirect != 1) return "";
  return "baked with --include-direct: its VDLs hold the direct light, which " + drawnAgain +
         " adds again (counted twice); " + advice;
}

std::string skyMismatchWarning(const BakeMetadata& meta, const Sky& sky) {
  if (meta.skyHash.empty() || meta.skyHash == sky.fingerprint()) return "";
  return "the light was baked under another sky than the one given (" +
         (sky.present() ? std::string("a sky ") + sky.fingerprint() : std::string("no sky")) +
         ", baked: " + printable(meta.skyHash) +
         "): the surfaces keep the baked sky's light, only what is drawn of the sky itself "
         "follows the one given; bake again with it to light them by it";
}

std::string photonDirectMismatchWarning(const std::string& what, int photonIncludeDirect,
                                        const std::string& gridWhat, int gridIncludeDirect) {
  if (photonIncludeDirect < 0 || gridIncludeDirect < 0 || photonIncludeDirect == gridIncludeDirect) {
    return "";
  }
  auto holds = [](int direct) {
    return direct ? std::string("with --include-direct (the direct light in it)")
                  : std::string("without --include-direct (the indirect light alone)");
  };
  return printable(what + " was traced " + holds(photonIncludeDirect) + ", " + gridWhat +
                   " was baked " + holds(gridIncludeDirect) +
                   ": the output holds the photons' light and records it, so that render "
                   "adds the direct light " +
                   (photonIncludeDirect ? "no more" : "itself"));
}

std::string photonSkyMismatchWarning(const std::string& what, const std::string& photonSkyHash,
                                     const std::string& gridWhat, const std::string& gridSkyHash) {
  if (photonSkyHash.empty() || gridSkyHash.empty() || photonSkyHash == gridSkyHash) return "";
  auto sky = [](const std::string& hash) {
    return hash == "none" ? std::string("no sky") : "the sky " + hash;
  };
  return printable(what + " was traced under another sky (" + sky(photonSkyHash) + ") than " +
                   gridWhat + " was baked under (" + sky(gridSkyHash) +
                   "): the output holds the photons' light and records their sky; render it "
                   "under that sky, or bake the photon map again under this one");
}

std::string sceneMismatchWarning(const std::string& what, const std::string& recordedHash,
                                 const std::string& scenePath, const std::string& sceneHash) {
  if (recordedHash.empty() || recordedHash == sceneHash) return "";
  return printable(what + " was made from a scene with content hash " + recordedHash + "; '" +
                   scenePath + "' and the files it reads have " + sceneHash +
                   ": it belongs to another scene, or to this one before it changed (its light "
                   "may not fit; bake again with this scene)");
}

LevelParams BakeParams::levelParams() const {
  LevelParams level;
  level.grid = gridParams();
  level.gather = gatherParams();
  level.cluster = clusterParams();
  level.layers = layers;
  level.occlusion = occlusion;
  level.smoothing = smoothing;
  return level;
}

namespace bake_internal {

/// The photons a target bake may store: maxPhotons, or fewer when the
/// memory left beside the voxels (kBakeBytesPerVoxel) does not hold them at
/// kBakeBytesPerPhoton plus the raw power the passes keep apart.
size_t targetPhotonCap(const BakeParams& params, size_t activeVoxels) {
  size_t cap = params.maxPhotons;
  const size_t available = availableMemoryBytes();
  if (available > 0) {
    const double left = double(available) - double(activeVoxels) * double(kBakeBytesPerVoxel);
    const double fits = left / double(kBakeBytesPerPhoton + sizeof(Vec3));
    cap = size_t(std::clamp(fits, 0.0, double(cap)));
  }
  return std::max<size_t>(cap, 1);
}

/// Photons the next pass stores: the noise falls as 1/sqrt(photons) while
/// the gather reads every photon within its radius, so the count that
/// reaches `target` from `noise` with `photons`, with a 10% margin, at
/// least 1.5x and at most 16x the current count, and within `cap`.
size_t nextPassPhotons(size_t photons, double noise, double target, size_t cap) {
  const double ratio = noise / target;
  const double grow = std::clamp(ratio * ratio * 1.1, 1.5, 16.0);
  return std::min(cap, size_t(std::ceil(double(photons) * grow)));
}

/// The luminance of the direct irradiance (W/m^2) of each entry of `baked`
/// (its voxels, then its surface layers), from the first hits' power summed
/// per voxel side of `grid` over `paths` paths: a side's light over the
/// voxel's area shared by its layers, as summarizeNoise weighs them.
std::vector<float> directIrradiance(const SurfaceGrid& grid, const VdlGrid& baked,
                                    const std::vector<double>& front,
                                    const std::vector<double>& back, size_t paths) {
  const size_t n = baked.size();
  std::vector<uint8_t> layers(n, 1);
  for (uint32_t v : baked.layers.voxel) ++layers[v];
  std::vector<float> out(n + baked.layers.size(), 0.0f);
  auto entry = [&](size_t voxel, const Vec3& normal) {
    const int64_t g = grid.find(baked.coords[voxel]);
    if (g < 0 || paths == 0) return 0.0f;
    const size_t i = size_t(g);
    const double power = dot(normal, grid.normals[i]) >= 0 ? front[i] : back[i];
    const double area = double(grid.areas[i]) / double(layers[voxel]);
    return area > 0 ? float(power / double(paths) / area) : 0.0f;
  };
  for (size_t v = 0; v < n; ++v) out[v] = entry(v, baked.normals[v]);
  for (size_t e = 0; e < baked.layers.size(); ++e) {
    out[n + e] = entry(baked.layers.voxel[e], baked.layers.normals[e]);
  }
  return out;
}

/// bake() with params.targetError > 0: passes of more photons over one
/// voxelization until the noise figure reaches the target.
BakeResult targetBake(const Scene& scene, const BakeParams& params, ProgressSink* progress) {
  using Clock = std::chrono::steady_clock;
  const Clock::time_point start = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - start).count(); };
  BakeResult r;
  BakeStats& s = r.stats;
  s.triangles = scene.triangleCount();
  s.denseVoxels = size_t(1) << (3 * params.depth);

  const LevelParams level = params.levelParams();
  SurfaceGrid grid = voxelize(scene, level.grid, progress, s.level, s.stages);
  const size_t cap = targetPhotonCap(params, grid.size());
  PhotonParams photonParams = params.photonParams();
  photonParams.storedPhotons = cap;
  photonParams.countDirect = params.targetSeenLight && !params.includeDirect;
  PhotonTracer tracer(scene, photonParams);
  // The direct light of each voxel's two sides (along its normal and
  // against it), luminance of the first hits' unscaled power: what the
  // noise figure weighs the indirect light against (targetSeenLight).
  std::vector<double> directFront, directBack;
  if (photonParams.countDirect) {
    directFront.assign(grid.size(), 0.0);
    directBack.assign(grid.size(), 0.0);
  }
  const PhotonTracer::DirectSink countDirect = [&](const Photon* hits, uint32_t n) {
    for (uint32_t i = 0; i < n; ++i) {
      const int64_t v = grid.find(grid.frame.coordOf(hits[i].position));
      if (v < 0) continue;
      const double y = double(luminance(hits[i].power));
      (dot(hits[i].normal, grid.normals[size_t(v)]) >= 0 ? directFront : directBack)[size_t(v)] += y;
    }
  };
  const size_t maxEmitted = maxEmittedPaths(photonParams);
  const double target = params.targetError;

  // Photons of paths 0 .. emitted-1, powers not yet scaled (during a
  // gather, and after the last, scaled: see below).
  std::vector<Photon> raw;
  SegmentCollector rawSegments(photonParams.maxSegments);  // their rays (BakeParams::freeSpace)
  size_t emitted = 0, empty = 0, missed = 0;
  LightReach reach;  // paths and photons per light
  uint64_t firstPath = 0;  // the path index `emitted` counts from
  size_t goal = std::min(cap, std::max(kMinPilotPhotons, kPilotPhotonsPerVoxel * grid.size()));
  double previousLit = 0;  // the light over the lit surface of the pass before (kLitSettledGrowth)
  for (int pass = 1;; ++pass) {
    const double passStart = elapsed();
    StageTimer trace(s.stages, "trace photons");
    {
      // The pass's photons, where growing by doubling would hold up to
      // twice them; a path stores at most maxBounces + 1 past the goal.
      raw.reserve(goal + size_t(photonParams.maxBounces) + 1);
      Progress bar(progress, "Tracing photons, pass " + std::to_string(pass), goal);
      bar.advance(std::min(raw.size(), goal));
      const PhotonTracer::PathSink take = [&](const Photon* photons, uint32_t n, uint32_t,
                                              bool pathMissed, uint32_t light) {
        raw.insert(raw.end(), photons, photons + n);
        reach.add(light, n);
        ++emitted;
        empty += n == 0;
        missed += pathMissed;
        return raw.size() < goal;
      };
      const PhotonTracer::SegmentSink keepSegments = [&](const PhotonSegment* p, uint32_t n) {
        rawSegments.addPath(p, n);
      };
      while (tracer.canStore() && raw.size() < goal) {
        const size_t batch = photonBatchPaths(goal, raw.size(), emitted, maxEmitted);
        if (batch == 0) break;
        const size_t before = raw.size();
        tracer.trace(firstPath + uint64_t(emitted), batch, take,
                     params.freeSpace && !rawSegments.full() ? keepSegments
                                                             : PhotonTracer::SegmentSink(),
                     countDirect);
        bar.advance(std::min(raw.size(), goal) - std::min(before, goal));
      }
    }
    s.storedPhotons = raw.size();
    s.emittedPaths = emitted;
    s.emptyPaths = empty;
    s.missedPaths = missed;
    s.darkLights = reach.dark(tracer.lightNames());
    s.reachStop = raw.size() < goal && emitted < maxEmitted;
    checkPhotonsStored(params, s);
    s.traceSeconds += trace.finish(formatCount(raw.size()) + " photons from " +
                                   formatCount(emitted) + " paths (pass " +
                                   std::to_string(pass) + ")");

    // The photons in the order of the grid's bins, so that the gather reads
    // them in place rather than a copy (gather.h, sortPhotonsByBin). The
    // gather reads powers scaled by the paths traced: the photons are scaled
    // in place, their raw powers kept apart (12 B a photon, where a scaled
    // copy took 52) and put back if another pass follows.
    s.level.activeVoxels = grid.size();
    splat(grid, raw, s.level, s.stages);
    sortPhotonsByBin(grid, raw);
    std::vector<Vec3> rawPower(raw.size());
    for (size_t i = 0; i < raw.size(); ++i) rawPower[i] = raw[i].power;
    scalePhotonPower(raw, emitted);
    r.grid = gatherSplatted(scene, grid, raw, level, progress, s.level, s.stages);
    if (photonParams.countDirect) {
      const std::vector<float> direct =
          directIrradiance(grid, r.grid, directFront, directBack, emitted);
      s.noise = summarizeNoise(r.grid, &direct);
    } else {
      s.noise = summarizeNoise(r.grid);
    }
    s.passes.push_back({raw.size(), emitted, s.noise, elapsed() - passStart});
    const bool litSettled =
        previousLit > 0 && s.noise.litLight <= (1.0 + kLitSettledGrowth) * previousLit;
    previousLit = s.noise.litLight;
    if (s.noise.quantile <= target && litSettled) {
      s.targetStop = "target reached";
    } else if (raw.size() >= cap) {
      s.targetStop = "photon cap";
    } else if (emitted >= maxEmitted || raw.size() < goal) {
      s.targetStop = "no more paths";
    } else if (params.maxSeconds > 0 && elapsed() >= params.maxSeconds) {
      s.targetStop = "time cap";
    } else if (pass >= kMaxTargetPasses) {
      s.targetStop = "pass cap";
    }
    if (!s.targetStop.empty()) break;
    goal = nextPassPhotons(raw.size(), s.noise.quantile, target, cap);
    if (params.maxSeconds > 0) {
      // The next pass's time, from this one's per photon (its tracing and
      // its gather grow with the photons): cut to what the time left holds,
      // or none where that is not half again this pass's photons. A pass 16
      // times the last, started just inside the limit, ran it over seven
      // times (3 s asked, 20 s taken).
      const double perPhoton = s.passes.back().seconds / double(std::max<size_t>(raw.size(), 1));
      const double left = params.maxSeconds - elapsed();
      const double fits = perPhoton > 0 ? left / perPhoton : double(goal);
      if (fits < double(goal)) {
        if (fits < 1.5 * double(raw.size())) {
          s.targetStop = "time cap";
          break;
        }
        goal = size_t(fits);
      }
    }
    // Lights whose paths stored nothing take no share of the next passes,
    // which start afresh: the pilot's photons, drawn while the dark lights
    // took their share, would weigh more than the passes' own and hold the
    // noise where the pilot left it.
    if (pass == 1 && !s.darkLights.empty()) {
      tracer.leaveOut(reach.darkLights());
      firstPath += uint64_t(emitted);
      raw.clear();
      rawPower.clear();
      rawSegments = SegmentCollector(photonParams.maxSegments);
      emitted = empty = missed = 0;
      previousLit = 0;
      std::fill(directFront.begin(), directFront.end(), 0.0);
      std::fill(directBack.begin(), directBack.end(), 0.0);
    }
    for (size_t i = 0; i < raw.size(); ++i) raw[i].power = rawPower[i];
  }
  r.metadata = bakeMetadata(scene, params, int64_t(raw.size()), int64_t(emitted), s.level.radius);
  if (!params.keepPhotons) raw = std::vector<Photon>();
  if (params.freeSpace) {
    r.grid.volume = bakeFreeSpaceLight(rawSegments.take(), r.grid.frame, params, progress, s.stages);
  }
  if (params.keepPhotons) {
    r.photons.photons = std::move(raw);  // scaled
    r.photons.emittedPaths = emitted;
    r.photons.emptyPaths = empty;
    r.photons.missedPaths = missed;
    r.photons.emittedPower = tracer.emittedPower();
  }
  return r;
}

}  // namespace bake_internal

BakeResult bake(const Scene& scene, const BakeParams& requested, ProgressSink* progress) {
  const BakeParams params = checkedBakeParams(scene, requested);
  if (params.targetError > 0) return bake_internal::targetBake(scene, params, progress);
  BakeResult r;
  BakeStats& s = r.stats;
  s.triangles = scene.triangleCount();
  s.denseVoxels = size_t(1) << (3 * params.depth);

  StageTimer trace(s.stages, "trace photons");
  PhotonMap photons = tracePhotons(scene, params.photonParams(), progress);
  s.storedPhotons = photons.photons.size();
  s.emittedPaths = photons.emittedPaths;
  s.emptyPaths = photons.emptyPaths;
  s.missedPaths = photons.missedPaths;
  s.darkLights = photons.darkLights;
  s.reachStop = photons.photons.size() < params.photons &&
                photons.emittedPaths < maxEmittedPaths(params.photonParams());
  checkPhotonsStored(params, s);
  s.traceSeconds = trace.finish(formatCount(photons.photons.size()) + " photons from " +
                                formatCount(photons.emittedPaths) + " paths");

  // bakeLevel, with the photons put in the order of the grid's bins between
  // its splat and its gather, which then reads them in place (gather.h,
  // sortPhotonsByBin) rather than a copy.
  const LevelParams level = params.levelParams();
  SurfaceGrid grid = voxelize(scene, level.grid, progress, s.level, s.stages);
  s.level.activeVoxels = grid.size();
  splat(grid, photons.photons, s.level, s.stages);
  sortPhotonsByBin(grid, photons.photons);
  r.grid = gatherSplatted(scene, grid, photons.photons, level, progress, s.level, s.stages);
  s.noise = summarizeNoise(r.grid);
  if (params.freeSpace) {
    r.grid.volume = bakeFreeSpaceLight(photons.segments, r.grid.frame, params, progress, s.stages);
  }
  photons.segments = std::vector<PhotonSegment>();
  r.metadata = bakeMetadata(scene, params, int64_t(photons.photons.size()),
                            int64_t(photons.emittedPaths), s.level.radius);
  if (params.keepPhotons) r.photons = std::move(photons);
  return r;
}

}  // namespace lo
