#include "sweep/sweep.h"

// The harness: references, then for each point a bake, the octree's
// irradiance and indirect image, their errors and timings (the cache and the
// report are sweep_cache.cpp and sweep_report.cpp).

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <memory>

#include "bake/bake.h"
#include "core/error.h"
#include "core/file.h"
#include "core/resources.h"
#include "core/threads.h"
#include "image/compare.h"
#include "image/image.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "reference/first_hit.h"
#include "reference/path_tracer.h"
#include "render/context.h"
#include "render/render_session.h"
#include "scene/scene.h"
#include "sweep/sweep_internal.h"
#include "vdb/vdb_io.h"

namespace fs = std::filesystem;

namespace lo {
namespace sweep_internal {
namespace {

/// What every error of the sweep compares: the pixels that see the scene
/// and no light fixture.
CompareParams sweepCompareParams(const RgbImage& emitterMask) {
  CompareParams p;
  p.ignoreBackground = true;
  p.mask = &emitterMask;
  return p;
}

/// Path-traced references, cached in cacheDir with the settings they were
/// rendered with; re-rendered when those differ.
References loadOrRenderReferences(const SweepParams& params, const Scene& scene,
                                  const PinholeCamera& camera, const SweepCache& cache,
                                  std::FILE* log) {
  References refs;
  if (cache.loadReferences(refs, camera)) {
    if (log) std::fprintf(log, "reference: cached in %s\n", cache.dir().c_str());
    return refs;
  }
  ReferenceParams rp;
  rp.width = params.width;
  rp.height = params.height;
  rp.samplesPerPixel = params.referenceSpp;
  rp.seed = params.seed;
  rp.part = ReferencePart::Irradiance;
  ReferenceImage irr = renderReference(scene, camera, rp, params.progress);
  refs.irradiance = irr.image;
  refs.emitterMask = irr.emitterMask;
  const CompareParams compared = sweepCompareParams(refs.emitterMask);
  refs.irradianceNoise = referenceNoise(irr.image, irr.stdError, compared);
  const RgbImage binnedMask = binMask(refs.emitterMask, kSweepBin);
  refs.irradianceBinnedNoise =
      referenceNoise(binImage(irr.image, kSweepBin), binStdError(irr.stdError, kSweepBin),
                     sweepCompareParams(binnedMask));
  refs.seconds = irr.seconds;
  if (params.frames > 0) {
    rp.part = ReferencePart::Indirect;
    ReferenceImage ind = renderReference(scene, camera, rp, params.progress);
    refs.indirect = ind.image;
    refs.indirectNoise = referenceNoise(ind.image, ind.stdError, compared);
    refs.seconds += ind.seconds;
  }
  cache.storeReferences(refs, camera);
  if (log) {
    std::fprintf(log,
                 "reference: %d x %d, %d spp, %.1f s; noise (rel. RMS std. error) "
                 "irradiance %.2f%% (%.2f%% over %dx%d bins), indirect %.2f%%\n",
                 params.width, params.height, params.referenceSpp, refs.seconds,
                 100 * refs.irradianceNoise, 100 * refs.irradianceBinnedNoise, kSweepBin,
                 kSweepBin, 100 * refs.indirectNoise);
  }
  return refs;
}

/// The bake parameters of a point; every default comes from the bake module.
BakeParams bakeParamsOf(const SweepPoint& point, const Scene& scene, uint64_t seed) {
  BakeParams b;
  b.depth = point.depth;
  b.photons = point.photons;
  b.targetError = point.targetError;
  b.knn = point.knn;
  b.vdls = parseVdlCount(point.vdls, "sweep point --vdls");
  b.seed = seed;
  b.layers = point.layers;
  b.occlusion = point.occlusion;
  b.edgeCorrection = point.edgeCorrection;
  b.smoothing = point.smoothing;
  if (!parseRepresentation(point.representation, &b.representation)) {
    throw InputError("sweep point representation '" + point.representation +
                     "': expected " + representationChoices());
  }
  // 0 lets the gather apply its own default (kDefaultRadiusVoxels voxels).
  if (point.radiusVoxels != kDefaultRadiusVoxels) {
    b.radius = point.radiusVoxels * makeGridFrame(scene.bounds(), point.depth).voxelSize;
  }
  return b;
}

/// Bakes in this process and writes the .vdb; memory is the peak resident
/// set during the bake above the resident set before it, the pages an
/// earlier point freed given back first: else a bake reused them unseen and
/// was reported at 0.0 MiB (H17-4-2).
BakeFigures bakeAndWrite(const Scene& scene, const BakeParams& b, const std::string& vdb) {
  returnFreeMemory();
  const size_t before = currentRssBytes();
  const bool reset = resetPeakRss();
  Stopwatch clock;
  BakeResult baked = bake(scene, b);
  recordSourceScene(baked.metadata, scene);
  writeVdlGrid(vdb, baked.grid, baked.metadata);
  BakeFigures f;
  f.bakeSeconds = clock.seconds();
  const size_t peak = reset ? peakRssSinceResetBytes() : peakRssBytes();
  f.peakRssBytes = double(peak > before ? peak - before : 0);
  const BakeStats& st = baked.stats;
  f.traceSeconds = st.traceSeconds;
  f.voxelizeSeconds = st.level.voxelizeSeconds;
  f.splatSeconds = st.level.splatSeconds;
  f.clusterSeconds = st.level.gatherClusterSeconds;
  f.vdbBytes = double(fs::file_size(vdb));
  f.activeVoxels = double(st.level.activeVoxels);
  f.denseVoxels = double(st.denseVoxels);
  f.storedPhotons = double(st.storedPhotons);
  f.noiseFigure = st.noise.recorded ? st.noise.quantile : -1.0;
  return f;
}

/// The render settings of a sweep point: the octree stage's lossless
/// texels (the point chooses half floats, the cosine correction and the
/// adaptive leaves), the point's interpolation, indirect light alone, one
/// sample per pixel.
RenderSettings renderSettingsOf(const SweepPoint& point, int width, int height) {
  RenderSettings s;
  s.frame.width = width;
  s.frame.height = height;
  s.frame.mode = RenderMode::Indirect;
  s.frame.interpolation = point.interpolation;
  s.frame.supersample = 1;  // the sweep's published figures: one sample per pixel
  s.octree = GpuOctreeParams{};
  s.octree.halfFloat = point.halfFloat;
  s.octree.cosineCorrection = point.cosineCorrection;
  s.octree.tolerance = point.tolerance;
  return s;
}

/// The GL render session of the indirect images: one context and one set of
/// scene resources for the whole sweep (made with the first point's grid,
/// each later point's light swapped in).
struct IndirectRenderer {
  std::unique_ptr<GlContext> context;
  std::unique_ptr<RenderSession> session;

  /// The octree of `grid` as the point's renderer draws it (within the
  /// context's limits, when frames are timed), for the CPU lookup too.
  GpuOctree octreeOf(Scene& scene, const VdlGrid& grid, const RenderSettings& settings) {
    if (!context) return buildRenderOctree(grid, settings);
    if (!session) {
      RenderSessionOptions options;
      options.freeTexels = false;  // the first-hit images read the textures
      options.keepOctree = true;
      session = std::make_unique<RenderSession>(scene, grid, *context, settings, options);
    } else {
      session->setGrid(grid, settings.octree);
    }
    return session->octree();
  }

  /// The indirect image of the octree octreeOf built last and its mean frame
  /// time over `frames`.
  RgbImage render(const PinholeCamera& camera, const RenderSettings& settings, int frames,
                  double& frameMs) {
    const RgbImage image = session->renderer().render(camera, settings.frame);
    frameMs = 1000.0 * session->renderer().timeFrames(camera, settings.frame, frames) / frames;
    return image;
  }
};

}  // namespace
}  // namespace sweep_internal

std::vector<SweepResult> runSweep(const SweepParams& params, std::FILE* log) {
  using namespace sweep_internal;
  if (!fs::is_directory(params.outDir))
    throw InputError("--out: folder '" + params.outDir + "' does not exist");
  const std::string cacheDir = params.outDir + "/cache";
  fs::create_directories(cacheDir);
  const SweepCache cache(params, cacheDir);
  // Bakes, images and logs stay out of version control; tables and plots are
  // the results.
  if (!fs::exists(params.outDir + "/.gitignore"))
    writeTextAtomically(params.outDir + "/.gitignore", "cache/\n");

  ThreadLimit threadLimit(params.threads);
  Scene scene = loadScene(params.scene);
  const PinholeCamera camera = PinholeCamera::ofScene(scene, kPi / 4);
  const References refs = loadOrRenderReferences(params, scene, camera, cache, log);
  const CompareParams compareParams = sweepCompareParams(refs.emitterMask);
  const RgbImage binnedMask = binMask(refs.emitterMask, kSweepBin);
  const RgbImage binnedReference = binImage(refs.irradiance, kSweepBin);
  const CompareParams binnedParams = sweepCompareParams(binnedMask);

  const std::vector<SweepPoint> points =
      params.points.empty() ? sweepPoints(params.scale) : params.points;
  IndirectRenderer indirectRenderer;
  // The GL context first, when frames are timed: each point's octree is then
  // built once, within its texture limits, for the CPU lookup and the GPU.
  if (params.frames > 0) indirectRenderer.context = createGlContext(GlContextParams{});
  std::vector<SweepResult> results;
  for (size_t pi = 0; pi < points.size(); ++pi) {
    const SweepPoint& point = points[pi];
    {
      SweepResult cached;
      if (cache.loadResult(point, cached)) {
        results.push_back(cached);
        if (log)
          std::fprintf(log, "[%zu/%zu] %s: cached\n", pi + 1, points.size(), point.label().c_str());
        continue;
      }
    }
    // Bake (shared by points that differ only in the lookup).
    const std::string vdb = cache.vdbPath(point);
    BakeFigures figures;
    if (!cache.loadBake(point, figures)) {
      figures = bakeAndWrite(scene, bakeParamsOf(point, scene, params.seed), vdb);
      cache.storeBake(point, figures);
    }
    SweepResult r;
    r.point = point;
    r.traceSeconds = figures.traceSeconds;
    r.voxelizeSeconds = figures.voxelizeSeconds;
    r.splatSeconds = figures.splatSeconds;
    r.clusterSeconds = figures.clusterSeconds;
    r.bakeSeconds = figures.bakeSeconds;
    r.peakRssBytes = figures.peakRssBytes;
    r.vdbBytes = figures.vdbBytes;
    r.activeVoxels = figures.activeVoxels;
    r.denseVoxels = figures.denseVoxels;
    r.storedPhotons = figures.storedPhotons;
    r.noiseFigure = figures.noiseFigure;
    // The octree's irradiance at the reference's first hits.
    const LoadedVdl baked = readVdlGrid(vdb);
    const RenderSettings settings = renderSettingsOf(point, params.width, params.height);
    const GpuOctree octree = indirectRenderer.octreeOf(scene, baked.grid, settings);
    r.gpuBytes = double(octree.poolBytes() + octree.vdlBytes());
    r.vdlTexels = double(octree.vdlCount);
    r.gpuLeaves = double(octree.leafCount);
    FirstHitParams hitParams;
    hitParams.width = params.width;
    hitParams.height = params.height;
    // Many rays per pixel: a pixel across an edge mixes its surfaces as
    // the reference's samples do (4 rays made up to a quarter of the jump).
    hitParams.samplesPerPixel = 64;
    hitParams.seed = params.seed;
    const RgbImage irradiance = renderOctreeIrradiance(scene, camera, octree, GpuOctree(),
                                                       shadeParamsOf(settings.frame), hitParams);
    writeExr(cache.imagePath(point, "irradiance"), irradiance);
    const CompareResult irrError = compareImages(irradiance, refs.irradiance, compareParams);
    r.irradianceRelRmse = irrError.luminance.relRmse;
    r.irradianceRelMae = irrError.luminance.relMae;
    r.irradianceBinnedRelRmse =
        compareImages(binImage(irradiance, kSweepBin), binnedReference, binnedParams)
            .luminance.relRmse;
    // The indirect image through the GL renderer, and its frame time.
    if (params.frames > 0) {
      const RgbImage indirect = indirectRenderer.render(camera, settings, params.frames, r.frameMs);
      writeExr(cache.imagePath(point, "indirect"), indirect);
      r.indirectRelRmse = compareImages(indirect, refs.indirect, compareParams).luminance.relRmse;
    }
    cache.storeResult(r);
    if (log) {
      std::fprintf(log, "[%zu/%zu] %s: bake %.2f s, GPU %s, irradiance rel. RMSE %.2f%%\n", pi + 1,
                   points.size(), point.label().c_str(), r.bakeSeconds,
                   formatBytes(size_t(r.gpuBytes)).c_str(), 100 * r.irradianceRelRmse);
      std::fflush(log);
    }
    results.push_back(r);
  }
  for (SweepResult& r : results) {
    r.referenceIrradianceNoise = refs.irradianceNoise;
    r.referenceIndirectNoise = refs.indirectNoise;
    r.referenceIrradianceBinnedNoise = refs.irradianceBinnedNoise;
  }
  markParetoFronts(results);

  writeSweepPictures(params, results, refs.irradiance, refs.emitterMask, cache);
  return results;
}

}  // namespace lo
