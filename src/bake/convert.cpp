// convertLightGrid: the method of a conversion chosen from what is asked and
// what is given (docs/convert.md), then run.

#include "bake/convert.h"

#include <cmath>

#include "cluster/resample.h"
#include "core/error.h"

namespace lo {

double lightGridEnergy(const LightGridVoxels& g) {
  double e = 0;
  for (size_t v = 0; v < g.size(); ++v) e += double(average(g.irradiance[v])) * g.areas[v];
  return e;
}

namespace {

/// A photon map of a `bake --bounds` holds photons inside its region only: a
/// grid reaching beyond it was re-gathered black there (80% of the light
/// lost without a word). Refused, not warned: no conversion wants those
/// voxels dark, and the grid of that region (or a photon map of the whole
/// scene) gives what was meant.
void checkPhotonRegion(const Bounds3& photons, const BakeMetadata& inMeta, const Scene& scene) {
  const Bounds3 grid = inMeta.region.empty() ? scene.bounds() : inMeta.region;
  if (photons.empty() || grid.empty()) return;
  // The regions pass through float metadata and a change of origin.
  const Vec3 slack = (photons.extent() + grid.extent()) * 1e-4f + Vec3(1e-6f);
  const Bounds3 held{photons.lower - slack, photons.upper + slack};
  if (min(grid.lower, held.lower) == held.lower && max(grid.upper, held.upper) == held.upper) {
    return;
  }
  throw InputError("--photon-map: its photons were stored inside " + photons.ToString() +
                   " only (their bake's --bounds), but the grid covers " + grid.ToString() +
                   (inMeta.region.empty() ? " (the whole scene)" : " (its bake's --bounds)") +
                   ": its voxels outside would gather no light. Give the photon map of a bake "
                   "that covers the grid, or convert the grid of that --bounds bake");
}

}  // namespace

std::string sparseRegatherWarning(const VdlGrid& input, const BakeMetadata& meta,
                                  const ConvertParams& params) {
  if (!params.photons || !params.scene) return "";
  const int depth = params.depth != 0 ? params.depth : input.frame.depth;
  if (depth < 1 || depth > kMaxGridDepth) return "";  // refused by the conversion
  GridFrame frame = input.frame;
  frame.depth = depth;
  frame.voxelSize = float(std::ldexp(double(input.frame.voxelSize), input.frame.depth - depth));
  return sparsePhotonsWarning(
      *params.scene, frame, meta.region, params.photons->size(),
      "the " + formatCount(params.photons->size()) + " photons of --photon-map",
      "a coarser --depth, or bake again with more --photons");
}

ConvertResult convertLightGrid(const VdlGrid& in, const BakeMetadata& inMeta,
                               const ConvertParams& params, ProgressSink* progress) {
  const int inDepth = in.frame.depth;
  const int depth = params.depth != 0 ? params.depth : inDepth;  // -1 is refused, not "the input's"
  checkDepth(depth);
  if (in.shTerms > 0) {
    throw InputError(std::string("convert works on VDL files; this one holds ") +
                     representationName(in.representation()) +
                     " spherical harmonics (bake --representation): bake it again with the "
                     "settings wanted");
  }
  if (depth > inDepth && !params.scene) {
    throw InputError("--depth " + std::to_string(depth) + " is finer than the input's depth " +
                     std::to_string(inDepth) +
                     ": converting to a finer grid needs --scene SCENE to know which voxels "
                     "hold geometry");
  }
  if (params.photons && !params.scene) {
    throw InputError(
        "--photon-map needs --scene SCENE: re-gathering voxelizes the scene at depth " +
        std::to_string(depth));
  }
  if (params.photons) checkPhotonRegion(params.photonRegion, inMeta, *params.scene);

  ClusterParams cluster;
  cluster.seed = params.seed;
  std::string vdls = params.vdls.empty() ? inMeta.vdls : params.vdls;
  if (vdls == "auto") {
    cluster.autoCount = true;
    cluster.vdls = params.vdls.empty() ? in.maxVdls : kMaxVdls;
  } else {
    cluster.vdls = params.vdls.empty() ? in.maxVdls : parseVdlCount(params.vdls).count;
    vdls = std::to_string(cluster.vdls);
  }

  ConvertResult r;
  r.vdls = vdls;
  r.metadata = inMeta;
  r.metadata.depth = depth;
  r.metadata.vdls = vdls;
  std::vector<StageReport>& rows = r.stages;

  if (params.scene && (depth != inDepth || params.photons)) {
    if (depth > inDepth) {
      // The finer grid's voxels against the memory, before voxelizing (as bake).
      GridFrame finer = in.frame;
      finer.depth = depth;
      finer.voxelSize = in.frame.voxelSize / float(1 << (depth - inDepth));
      const double photonBytes = params.photons ? double(params.photons->size()) * double(kBakeBytesPerPhoton) : 0.0;
      checkVoxelMemory(*params.scene, finer, inMeta.region, photonBytes);
    }
    StageTimer voxelize(rows, "voxelize scene");
    GridParams gridParams;
    gridParams.depth = depth;
    gridParams.region = inMeta.region;  // the bake's region of interest, if it had one
    SurfaceGrid grid = buildSurfaceGrid(*params.scene, gridParams, progress);
    // The bake voxelized the same scene with makeGridFrame, whose origin does
    // not depend on the depth: a different scene shows up here.
    checkNestedFrames(in.frame, grid.frame, "--scene");
    voxelize.finish(formatCount(grid.size()) + " voxels active at depth " + std::to_string(depth));
    if (params.photons) {
      StageTimer gatherTimer(rows, "re-gather");
      const std::vector<Photon>& photons = *params.photons;
      splatPhotons(grid, photons);
      GatherParams gather;
      gather.k = inMeta.knn > 0 ? inMeta.knn : GatherParams{}.k;
      gather.radius = 0;  // the default for the new depth: kDefaultRadiusVoxels voxels
      // The bake's defaults: surface layers and gather occlusion.
      const GatherOcclusion occlusion(*params.scene);
      gather.blocked = occlusion.test();
      gather.surfaceAt = occlusion.surfaceProbe();
      const LayerParams layers;
      r.grid = buildVdlGrid(grid, photons, gather, cluster, progress, nullptr, &layers);
      r.metadata.knn = gather.k;
      r.metadata.radius = resolveRadius(gather, grid.frame);
      r.metadata.photons = int64_t(photons.size());
      r.metadata.skyHash = params.photonSkyHash;
      if (params.photonIncludeDirect >= 0) r.metadata.includeDirect = params.photonIncludeDirect;
      r.method = "re-gathered " + formatCount(photons.size()) + " photons";
      gatherTimer.finish(r.method);
    } else if (depth > inDepth) {
      StageTimer refineTimer(rows, "interpolate");
      RefineStats stats;
      r.grid = refineVdlGrid(in, grid, cluster, &stats);
      r.withoutParent = stats.withoutParent;
      r.method = "trilinear interpolation of the parents";
      refineTimer.finish(stats.withoutParent
                             ? formatCount(stats.withoutParent) + " voxels without a parent (dark)"
                             : "");
    } else {
      StageTimer mergeTimer(rows, "merge");
      r.grid = coarsenVdlGrid(in, depth, cluster);
      r.method = "area-weighted merge of the children";
      mergeTimer.finish("");
    }
  } else if (depth < inDepth) {
    StageTimer mergeTimer(rows, "merge");
    r.grid = coarsenVdlGrid(in, depth, cluster);
    r.method = "area-weighted merge of the children";
    mergeTimer.finish("");
  } else if (cluster.vdls != in.maxVdls || cluster.autoCount != (inMeta.vdls == "auto") ||
             !params.vdls.empty()) {
    StageTimer clusterTimer(rows, "re-cluster");
    r.grid = reclusterVdlGrid(in, cluster);
    r.method = "re-clustered the VDLs";
    clusterTimer.finish("");
  } else {
    r.grid = in;
    r.method = "same grid";
  }
  // The contract: a voxel's irradiance is the sum of its VDLs. Values that
  // went through half floats before (convert --half, then another convert)
  // sum to their rounded totals only within half precision: the totals
  // follow the VDLs, so the sums hold to float rounding in any chain.
  if (r.method != "same grid") {
    VdlGrid& g = r.grid;
    for (size_t v = 0; v < g.size(); ++v) {
      if (g.vdlCount[v] == 0) continue;
      Vec3 sum{0, 0, 0};
      for (int i = 0; i < g.vdlCount[v]; ++i) sum += g.vdlsOf(v)[i].irradiance;
      g.irradiance[v] = sum;
    }
    for (size_t e = 0; e < g.layers.size(); ++e) {
      if (g.layers.vdlCount[e] == 0) continue;
      Vec3 sum{0, 0, 0};
      for (int i = 0; i < g.layers.vdlCount[e]; ++i) sum += g.layerVdlsOf(e)[i].irradiance;
      g.layers.irradiance[e] = sum;
    }
  }
  if (in.layers.size() > 0 && r.grid.layers.size() == 0) {
    r.method += " (the input's surface layers are not carried to another depth: bake again, "
                "or convert with --photon-map, for layers at depth " + std::to_string(depth) + ")";
  }
  // The free-space light has its own grid over the same cube (the frames of
  // one scene nest at every depth): it goes along while it is no finer than
  // the new surface grid.
  if (!in.volume.empty() && r.grid.volume.empty()) {
    if (in.volume.frame.depth <= depth) {
      r.grid.volume = in.volume;
    } else {
      r.method += " (the free-space light, " + std::to_string(in.volume.frame.depth) +
                  " levels deep, is left out of a grid of depth " + std::to_string(depth) +
                  ": bake again for it)";
    }
  }
  return r;
}

}  // namespace lo
