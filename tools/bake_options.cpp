#include "bake_options.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "cli_checks.h"
#include "command_options.h"
#include "core/error.h"
#include "core/resources.h"

namespace lo::tool {

BakeParams BakeOptions::bakeParams(const Scene& scene) const {
  BakeParams params;
  params.depth = parseDepth(depth);
  setPhotonBudget(params, photons, targetError);
  if (params.targetError > 0) {
    params.maxPhotons = maxPhotons;
    params.maxSeconds = maxSeconds;
    params.targetSeenLight = targetLight == "seen";
  }
  params.knn = knn;
  params.radius = float(radius);
  params.vdls = parseVdlCount(vdls);
  params.seed = seed;
  params.includeDirect = includeDirect;
  params.layers = layers == "on";
  params.occlusion = occlusion == "on";
  params.edgeCorrection = edgeCorrection == "on";
  params.separateCaustics = separateCaustics == "on";
  params.smoothing = smoothing == "on";
  params.freeSpace = freeSpace == "on";
  params.freeSpaceLevels = freeSpaceLevels;
  params.freeSpaceOrder = freeSpaceOrder;
  params.autoCap = autoCap;
  params.autoThreshold = autoThreshold;
  parseRepresentation(representation, &params.representation);  // checked by the flag
  if (!bounds.empty()) {
    // Finite, of some extent, within the coordinates a scene may have: a NaN
    // would make an empty grid, 1e20 an Embree abort. Corners in any order.
    for (int a = 0; a < 3; ++a) {
      const double lo = bounds[size_t(a)], hi = bounds[size_t(a) + 3];
      if (!std::isfinite(lo) || !std::isfinite(hi) || !(lo != hi) ||
          std::max(std::fabs(lo), std::fabs(hi)) > double(kMaxCoordinate)) {
        char what[160];
        std::snprintf(what, sizeof what, "axis %c: %g, %g", char('x' + a), lo, hi);
        throw InputError("--bounds: each axis needs two different finite corners within " +
                         formatNumber(double(kMaxCoordinate)) + " scene units (" + what + ")");
      }
    }
    params.region.extend(scene.toLocal(Vec3d{bounds[0], bounds[1], bounds[2]}));
    params.region.extend(scene.toLocal(Vec3d{bounds[3], bounds[4], bounds[5]}));
  }
  const std::string sparse = sparsePhotonsWarning(scene, params);
  if (!sparse.empty()) std::fprintf(stderr, "warning: %s\n", sparse.c_str());
  params.keepPhotons = !photonMap.empty();
  return params;
}

void addBakeOptions(CLI::App* cmd, BakeOptions& opt) {
  cmd->description(
      "Trace a photon map and compress it into a sparse grid of virtual directional lights "
      "(VDLs), written as a .vdb file.");
  cmd->add_option("scene", opt.scene, "Scene to bake: .gltf, .glb or .obj")
      ->required()
      ->check(existingFile());
  cmd->add_option("-o,--output", opt.output, "Output .vdb file (written atomically)")->required();
  addSceneOptions(cmd, opt.sceneOptions);
  cmd->add_option("--depth", opt.depth,
                  "Octree depth: 2^depth voxels across the scene's bounding cube, 1 to " +
                      std::to_string(kMaxGridDepth) + "; auto: 6, or 7 where depth 6's voxels "
                      "would be wider than 1 scene unit (glTF: a metre; a scene over 64 m)")
      ->check(autoDepthValidator())
      ->capture_default_str();
  cmd->add_option("--photons", opt.photons,
                  "A fixed photon budget: store this many photons (the paper's 600000) instead "
                  "of tracing until --target-error is reached")
      ->check(numberIn(kPhotonsRange));
  cmd->add_option("--target-error", opt.targetError,
                  "Trace photons in passes until the bake's noise figure is at most this (default " +
                      formatNumber(kDefaultTargetError) +
                      "): the estimated relative standard error of the irradiance that 90% of the "
                      "lit area is below (docs/accuracy.md, \"How good is a bake\"). A deeper "
                      "grid gets the photons it needs")
      ->check(numberIn(kTargetErrorRange));
  cmd->add_option("--target-light", opt.targetLight,
                  "What --target-error measures the indirect light's noise against: 'seen', "
                  "the light a viewer sees (direct plus indirect: where direct light is bright, "
                  "as in a sunlit street, the indirect light needs fewer photons), or "
                  "'indirect', the indirect light alone (a lightmap or .vdb of indirect light)")
      ->check(CLI::IsMember({"seen", "indirect"}))
      ->capture_default_str();
  cmd->add_option("--max-photons", opt.maxPhotons,
                  "With --target-error: store at most this many photons (fewer when memory "
                  "holds fewer); the report says when the cap stopped the bake")
      ->check(numberIn(kPhotonsRange))
      ->capture_default_str();
  cmd->add_option("--max-seconds", opt.maxSeconds,
                  "With --target-error: start no new pass after this many seconds (0: no limit). "
                  "The one setting that makes the result depend on the machine's speed")
      ->check(numberIn({0, 1e7}))
      ->capture_default_str();
  cmd->add_option("--knn", opt.knn,
                  "Nearest photons gathered per voxel (paper: 300); a target bake raises it to "
                  "3/E^2 so that it does not hold the noise up")
      ->check(numberIn(kKnnRange))
      ->capture_default_str();
  cmd->add_option("--radius", opt.radius,
                  "Gathering radius in scene units (default: " + formatNumber(kDefaultRadiusVoxels) +
                      " voxel sizes; at least " + formatNumber(kMinRadiusVoxels) +
                      " of one, at most the grid's cube)")
      ->check(numberIn({1e-30, 1e30}));  // a float's range: 1e-300 would become 0, the default
  cmd->add_option("--vdls", opt.vdls,
                  "VDLs per voxel, 1-" + std::to_string(kMaxVdls) + ", or 'auto' for the fewest (up to --auto-cap) whose "
                  "angular error is under --auto-threshold")
      ->check(vdlCountValidator())
      ->capture_default_str();
  cmd->add_option("--representation", opt.representation,
                  "How each voxel stores its light: 'vdl' (virtual directional lights, the "
                  "paper's), or the irradiance as spherical harmonics of order 1 ('sh1', 4 terms) "
                  "or 2 ('sh2', 9 terms); docs/accuracy.md compares them")
      ->check(CLI::IsMember(representationNames()))
      ->capture_default_str();
  cmd->add_option("--auto-cap", opt.autoCap, "With --vdls auto: at most this many VDLs per voxel")
      ->check(wholeIn(1, kMaxVdls))
      ->capture_default_str();
  cmd->add_option("--auto-threshold", opt.autoThreshold,
                  "With --vdls auto: the fewest VDLs whose angular error (chord-length deviation, "
                  "0..2; 0.35 is about 20 degrees) is under this")
      ->check(numberIn({0, 2, true}))
      ->capture_default_str();
  cmd->add_option("--seed", opt.seed, "Random seed (same seed, same bytes)")
      ->check(seedValidator())->capture_default_str();
  addThreadsOption(cmd, opt.threads)->capture_default_str();
  cmd->add_flag("--include-direct", opt.includeDirect,
                "Also store direct-light photons (by default the GL renderer draws direct light)");
  cmd->add_option("--layers", opt.layers,
                  "Surface layers: a voxel whose photons land on surfaces facing clearly "
                  "different ways (an edge, the two sides of a thin wall) keeps one gather and "
                  "one set of VDLs per orientation (docs/accuracy.md)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--gather-occlusion", opt.occlusion,
                  "Leave out photons that lie behind geometry seen from the voxel: no light "
                  "gathered through thin walls (one shadow ray per neighbouring photon group)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--edge-correction", opt.edgeCorrection,
                  "Divide the gathered power by the part of the gather disc that lies on the "
                  "surface, not the whole disc: next to an edge the plain estimate is too dark")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--separate-caustics", opt.separateCaustics,
                  "Gather the photons that reached a surface through mirrors and glass alone (a "
                  "caustic) apart from the smooth light, within " +
                      formatNumber(kDefaultCausticRadiusVoxels) +
                      " voxels: a caustic stays sharp and does not blot the light around it")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--smoothing", opt.smoothing,
                  "Smooth each voxel's estimate with its neighbours on the same surface, where "
                  "they differ by no more than the photon noise explains (shadow edges kept)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--free-space", opt.freeSpace,
                  "Also bake the light in free space, on a grid --free-space-levels coarser: "
                  "what lights objects that were not baked (render/view --add)")
      ->check(CLI::IsMember({"on", "off"}))
      ->capture_default_str();
  cmd->add_option("--free-space-levels", opt.freeSpaceLevels,
                  "How many levels coarser than the surface grid the free-space grid is "
                  "(2: a free-space voxel is 4 surface voxels wide; never coarser than depth 1)")
      ->check(wholeIn(0, 11))
      ->capture_default_str();
  cmd->add_option("--free-space-order", opt.freeSpaceOrder,
                  "SH order of the free-space light: 2 (9 terms, 80 bytes a voxel on the GPU) or "
                  "1 (4 terms, 40 bytes; smoother across directions)")
      ->check(CLI::IsMember({1, 2}))
      ->capture_default_str();
  cmd->add_option("--bounds", opt.bounds,
                  "A region of interest, x0,y0,z0,x1,y1,z1 in scene units: the grid covers it "
                  "alone, photons are stored only inside it and suns shine on its footprint "
                  "(a room on a large ground plane)")
      ->expected(6)
      ->delimiter(',');
  cmd->add_option("--photon-map", opt.photonMap,
                  "Also write the photons as an OpenVDB point grid (a .vdb) for inspection");
  cmd->add_option("--stats-json,--json", opt.statsJson,
                  "Write the per-stage figures as JSON, a .json file (under mpirun, per rank too: time, "
                  "bytes sent, peak memory)");
  cmd->add_option("--tiles", opt.tiles,
                  "Under mpirun (mpirun -np N lightoctree bake ...): tiles per axis the grid is "
                  "cut into and shared among the ranks by estimated memory, a power of two with "
                  "tiles of at least 8^3 voxels, or 'auto' (32, fewer for shallow grids). The "
                  ".vdb bytes are the one-process bake's whatever the tiles and ranks "
                  "(docs/scale.md)")
      ->check(tilesValidator())
      ->capture_default_str();
  cmd->add_flag("-q,--quiet", opt.quiet, "No progress or summary, only errors");
}

}  // namespace lo::tool
