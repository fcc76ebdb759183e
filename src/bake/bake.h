#pragma once
/// @file bake/bake.h
/// @brief The one entry point of the bake (paper §3.1, Fig. 4): scene ->
/// photon map -> surface grid -> photon bins -> KNN gather + K-means VDLs ->
/// VdlGrid. Commands, benchmarks, the sweep and the progressive preview all
/// bake through this header (or bake/progressive_bake.h, which uses it), so
/// the stages are chained, timed and defaulted in one place.

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "cluster/vdl_cluster.h"
#include "cluster/volume_light.h"
#include "core/number_range.h"
#include "core/progress.h"
#include "core/resources.h"
#include "gather/gather.h"
#include "lightgrid/grid_noise.h"
#include "grid/surface_grid.h"
#include "lightgrid/vdl_grid.h"
#include "photon/photon_map.h"
#include "scene/scene.h"

namespace lo {

/// VDLs per voxel: a fixed count 1..kMaxVdls, or "auto" (the fewest, up to
/// kMaxVdls, whose angular error is under ClusterParams::autoThreshold).
struct VdlCount {
  int count = 4;           ///< paper §5.3.2: 4
  bool automatic = false;  ///< "auto"
  std::string ToString() const;  ///< "4" or "auto": the text of `--vdls` and of the file metadata
};

/// Parses "1".."8" or "auto". @throws InputError naming `flag` and the text.
VdlCount parseVdlCount(const std::string& text, const char* flag = "--vdls");
/// The same check for a CLI validator: "" when valid, else the message.
std::string vdlCountError(const std::string& text);

/// @throws InputError "<what>: must be a whole number from 1 to 12, got N"
/// unless kDepthRange holds `depth`: the one depth check of the bake module.
void checkDepth(int depth, const std::string& what = "--depth");

/// BakeParams::depth "auto", the default: autoDepth picks it for the scene.
constexpr int kAutoDepth = 0;
/// The widest voxel an automatic depth leaves where it can, in scene units
/// (glTF's metres): a room's light changes over a metre; a 78 m game level
/// at depth 6 has 1.2 m voxels, and its picture is 11.7% off the path
/// tracer's where depth 7's is 7.7% (docs/accuracy.md).
constexpr double kAutoVoxelSize = 1.0;
/// The depths an automatic depth takes: the paper's 6, and 7 at most (4x
/// the voxels and about 3x the bake's time and memory of depth 6).
constexpr int kAutoDepthMin = 6;
constexpr int kAutoDepthMax = 7;
/// The depth of `--depth auto` for a grid over `region`: the smallest of
/// kAutoDepthMin..kAutoDepthMax whose voxels are at most kAutoVoxelSize
/// wide, else kAutoDepthMax. (checkedBakeParams then takes a coarser one
/// where the voxels would be finer than a .vdb stores, or 6 where 7's
/// memory is not there.)
int autoDepth(const Bounds3& region);
/// "auto" (kAutoDepth) or a whole number in kDepthRange. @throws InputError
/// naming `flag`.
int parseDepth(const std::string& text, const char* flag = "--depth");
/// The same check for a CLI validator: "" when valid, else the message.
std::string depthError(const std::string& text);

/// Memory a bake needs per stored photon (the map, its bins and the gather's
/// copy), bytes: checked against the memory available before tracing.
constexpr size_t kBakeBytesPerPhoton = 120;

/// Peak memory a bake needs per active voxel (the surface grid, the photon
/// bins, the VDL grid and its layers), bytes: measured on the Cornell box at
/// depths 7 to 9 (peak RSS / active voxels, 1.04 KB; docs/robustness.md).
constexpr size_t kBakeBytesPerVoxel = 1000;

/// Smallest voxel a .vdb transform stores, scene units: OpenVDB refuses
/// scales whose cube is below 3e-15 (with a margin).
constexpr double kMinStorableVoxel = 1.5e-5;

struct LevelParams;

/// `lightoctree bake`'s default noise target (`--target-error`): the bake's
/// noise figure (NoiseSummary::quantile) it traces photons until it reaches.
/// Measured on the Cornell box (docs/accuracy.md, "How good is a bake"):
/// 960k photons at depth 6, 1.8 s, irradiance 2.9% (4x4 bins, emitters
/// masked) against the paper's 600k at 1.0 s and 3.4%; 0.05 reaches 2.7%
/// at 3.3 s, which real textured scenes pay 5-9x for.
constexpr double kDefaultTargetError = 0.07;
/// The noise targets a bake takes (`--target-error`, Python's target_error):
/// 0.1% to 100%. The photons needed grow as 1/E^2: below 0.1% a bake of any
/// scene runs for hours.
constexpr NumberRange kTargetErrorRange{1e-3, 1.0};
/// The photons a bake stores (`--photons`, `--max-photons`, Python's
/// photons): up to 200 million, 24 GB (kBakeBytesPerPhoton each).
constexpr NumberRange kPhotonsRange{1, 2e8, false, true};
/// The nearest photons a voxel gathers (`--knn`, Python's knn).
constexpr NumberRange kKnnRange{1, 1e5, false, true};
/// The grid depths a bake takes (`--depth`, Python's depth; checkDepth).
constexpr NumberRange kDepthRange{1, kMaxGridDepth, false, true};
/// A target bake stores at most this many photons unless told otherwise
/// (`--max-photons`), nor more than the memory available holds.
constexpr size_t kDefaultMaxPhotons = 20000000;
/// A target bake's first pass stores this many photons per active voxel
/// (at least kMinPilotPhotons): enough for the noise figure to say how many
/// the target needs. One, not the eight it was: where direct light is bright
/// (an emissive object alone, a sunlit street) the figure of the light seen
/// was 15-200 times below the target after eight, which open scenes paid for
/// with hundreds of paths per photon (docs/results/bake-cost.md).
constexpr size_t kPilotPhotonsPerVoxel = 1;
constexpr size_t kMinPilotPhotons = 20000;
/// A target bake stops at its target only once the light over the lit
/// surface has settled: its pass found at most this share more indirect light
/// there (NoiseSummary::litLight) than the pass before. A small pilot leaves
/// voxels its few photons missed unlit, which the figure does not count: a
/// pass whose photons still light surface that holds light has not yet
/// measured all of it. (The voxels lit at the far edge of an emissive
/// object's reach hold little light: counting them, the lit voxels of the
/// emissive helmet grew by more than 2% in every pass.)
constexpr double kLitSettledGrowth = 0.05;
/// Passes of a target bake at most (the pilot included).
constexpr int kMaxTargetPasses = 6;

/// The smallest gathering radius a bake takes, in voxel sizes: below it the
/// gather finds no photon in most voxels (a dark bake whose noise figure, of
/// no photons, reads 0).
constexpr float kMinRadiusVoxels = 0.1f;

/// Every setting of a bake, with the defaults of `lightoctree bake`.
struct BakeParams {
  /// 2^depth voxels across the padded bounding cube (paper's delta);
  /// kAutoDepth: autoDepth's for the scene (checkedBakeParams sets it).
  int depth = kAutoDepth;
  /// Photons stored in the photon map (paper: 600k), when targetError is 0.
  size_t photons = 600000;
  /// > 0: trace photons in passes until the bake's noise figure
  /// (NoiseSummary::quantile of the smoothed grid) is at most this, or
  /// maxPhotons or maxSeconds stops it (BakeStats::targetStop says which).
  /// The gather then reads photons within its radius up to k =
  /// max(knn, targetKnn(targetError)), so that k does not hold the noise up.
  double targetError = 0;
  /// Target bakes: what the noise figure weighs each voxel's indirect
  /// noise against. true (the default): the light a viewer sees there,
  /// direct plus indirect (the direct part counted from the paths' first
  /// hits, which the bake does not store): a sunlit street's indirect light
  /// need not be as smooth as a closed room's, where it is all there is.
  /// false: the indirect light alone, for what shows it alone (a lightmap
  /// of indirect light, the .vdb in Houdini).
  bool targetSeenLight = true;
  size_t maxPhotons = kDefaultMaxPhotons;  ///< target bakes: photon cap
  /// Target bakes: no new pass starts after this many seconds, nor one whose
  /// photons, at the last pass's time per photon, would not end within them
  /// (cut to what fits, or none under half again the photons: 0: no limit).
  /// The only setting whose result depends on the machine's speed.
  double maxSeconds = 0;
  int knn = 300;            ///< nearest photons gathered per voxel (paper: 300)
  /// Gathering radius, world units; 0 = kDefaultRadiusVoxels voxel sizes;
  /// else at least kMinRadiusVoxels voxel sizes.
  float radius = 0.0f;
  VdlCount vdls;
  /// `--vdls auto`: at most this many VDLs per voxel (`--auto-cap`), the
  /// fewest whose angular error (chord-length deviation) is under
  /// autoThreshold (`--auto-threshold`; the paper's 0.35 ~ 20 degrees keeps
  /// almost every voxel at the cap; 0.5 gives 3.1 VDLs per voxel on the test
  /// scenes at the irradiance error of 4, docs/octree.md).
  int autoCap = 4;
  float autoThreshold = 0.5f;
  /// VDLs (the paper's), or SH of order 1 or 2 (`--representation`,
  /// docs/accuracy.md "Spherical harmonics"): ClusterParams::representation.
  LightRepresentation representation = LightRepresentation::Vdl;
  uint64_t seed = 1;           ///< same inputs and seed, same bytes, whatever the thread count
  bool includeDirect = false;  ///< also store bounce-0 photons (the renderer draws direct light)
  bool keepPhotons = false;    ///< return the photon map in BakeResult::photons
  /// Surface layers (`--layers`): a voxel whose photons face clearly
  /// different ways keeps one gather and VDL set per orientation.
  bool layers = true;
  /// Gather occlusion (`--gather-occlusion`): photons behind geometry, seen
  /// from the voxel, are not gathered (no light through thin walls).
  bool occlusion = true;
  /// Edge correction (`--edge-correction`): GatherParams::edgeCorrection.
  bool edgeCorrection = true;
  /// Caustics apart (`--separate-caustics`): GatherParams::separateCaustics.
  bool separateCaustics = true;
  /// Layer-aware smoothing of the estimates (`--smoothing`): smoothVdlGrid.
  bool smoothing = true;
  /// Free-space light (`--free-space`): the light in every voxel of a grid
  /// freeSpaceLevels coarser than the surface grid (at least 1 level deep), surfaces or not, from the
  /// photon paths' track lengths (cluster/volume_light.h), for objects that
  /// were not baked (VdlGrid::volume). A distributed bake makes it on rank 0
  /// from every rank's segments: the same bytes.
  bool freeSpace = true;
  int freeSpaceLevels = 2;
  /// SH order of the free-space light: 1 (4 terms, the default: as close to the
  /// path tracer on the moving-sphere test as 2, at half the GPU bytes) or 2 (9).
  int freeSpaceOrder = 1;
  /// At most this many rays make it (PhotonParams::maxSegments): the whole
  /// paths from the first on.
  size_t freeSpaceRays = kDefaultMaxSegments;
  /// A region of interest (`--bounds`; empty = the whole scene): the grid
  /// covers it alone, photons are stored only inside it, and directional
  /// lights emit over its footprint (PhotonParams::region).
  Bounds3 region;

  PhotonParams photonParams() const;
  /// The gather's k: knn, raised for a target bake (targetKnn).
  int effectiveKnn() const;
  LevelParams levelParams() const;  ///< the grid, gather and cluster settings together
  GridParams gridParams() const;
  GatherParams gatherParams() const;
  VolumeLightParams volumeParams() const;  ///< the free-space light's settings
  ClusterParams clusterParams() const;
  std::string ToString() const;
};

class RayTracer;

/// The bake's gather occlusion (GatherParams::blocked): segments tested
/// against the scene's triangles with a ray tracer built here, in a frame
/// centred on the scene. Keep it alive while the gather runs.
class GatherOcclusion {
 public:
  explicit GatherOcclusion(const Scene& scene);
  ~GatherOcclusion();
  GatherOcclusion(const GatherOcclusion&) = delete;
  GatherOcclusion& operator=(const GatherOcclusion&) = delete;
  SegmentBlocked test() const;
  /// GatherParams::surfaceAt through the same ray tracer.
  SurfaceProbe surfaceProbe() const;

 private:
  std::unique_ptr<RayTracer> tracer_;
  Vec3 origin_{0, 0, 0};
};

/// One octree level from a traced photon map (what the progressive preview
/// bakes once per depth): voxelize, splat, gather + cluster.
struct LevelParams {
  GridParams grid;        ///< depth (paper's delta) and padding of the bounding cube
  GatherParams gather;    ///< KNN k, radius (0 = kDefaultRadiusVoxels voxels at this depth)
  ClusterParams cluster;  ///< VDLs per voxel, seed
  bool layers = true;     ///< BakeParams::layers
  bool occlusion = true;  ///< BakeParams::occlusion: gather.blocked by the scene's ray tracer
  bool smoothing = true;  ///< BakeParams::smoothing
};

/// What bakeLevel did, for reports and benchmarks. Seconds are wall time.
struct LevelStats {
  size_t activeVoxels = 0;    ///< voxels that touch geometry
  size_t droppedPhotons = 0;  ///< photons outside every active voxel's neighbourhood
  float radius = 0;           ///< gathering radius used, world units
  size_t layeredVoxels = 0;   ///< voxels with more than one surface layer
  size_t extraLayers = 0;     ///< their layers beyond the first (VdlGrid::layers)
  double voxelizeSeconds = 0, splatSeconds = 0, gatherClusterSeconds = 0;
  BakeTimings threadSeconds;  ///< gather / K-means split, summed over threads
  double seconds() const { return voxelizeSeconds + splatSeconds + gatherClusterSeconds; }
};

/// The first two stages of bakeLevel: the surface grid at `params.depth` with
/// `photons` splatted into its bins, i.e. what the gather reads (benchmarks
/// of the gather start here). Fills the voxelize / splat fields of `stats`.
SurfaceGrid voxelizeAndSplat(const Scene& scene, const std::vector<Photon>& photons,
                             const GridParams& params, ProgressSink* progress = nullptr,
                             LevelStats* stats = nullptr,
                             std::vector<StageReport>* stages = nullptr);

/// Voxelizes `scene` (buildSurfaceGrid), splats `photons` (splatPhotons) and
/// gathers + clusters every active voxel (buildVdlGrid). Deterministic: the
/// same inputs give the same grid whatever the thread count. `progress` gets
/// the voxelize and gather + cluster tasks; a sink may throw to abandon the
/// bake (the exception propagates, nothing is left behind). `stages`, when
/// given, receives one row per stage.
VdlGrid bakeLevel(const Scene& scene, const std::vector<Photon>& photons, const LevelParams& params,
                  ProgressSink* progress = nullptr, LevelStats* stats = nullptr,
                  std::vector<StageReport>* stages = nullptr);

/// bakeLevel on a grid already voxelized (buildSurfaceGrid at
/// params.grid): splats `photons` into its bins (replacing earlier ones),
/// gathers, clusters and smooths. Fills the splat and gather fields of `stats`.
VdlGrid gatherLevel(const Scene& scene, SurfaceGrid& grid, const std::vector<Photon>& photons,
                    const LevelParams& params, ProgressSink* progress = nullptr,
                    LevelStats* stats = nullptr, std::vector<StageReport>* stages = nullptr);

/// The k a target bake gathers with: 3 / E^2 photons. A disc holding k
/// photons whose powers vary with a coefficient of variation c is at noise
/// sqrt((1 + c^2) / k) before smoothing, what more photons no longer lower
/// once k of them fit within the radius: this k reaches E with c up to
/// sqrt(2) (an emissive texture's paths weighted by their texel; measured on
/// the DamagedHelmet lit by its emissive map, where 2 / E^2 held the noise
/// figure near E and took five passes to pass it).
int targetKnn(double targetError);

/// One pass of a target bake.
struct TargetPass {
  size_t photons = 0, paths = 0;
  NoiseSummary noise;
  double seconds = 0;  ///< the pass's tracing and gathering, wall
};

/// Figures of a whole bake.
struct BakeStats {
  size_t triangles = 0;
  size_t storedPhotons = 0, emittedPaths = 0;
  size_t emptyPaths = 0;   ///< traced paths that stored no photon
  /// Of those, paths whose first ray hit no surface (the light aimed past
  /// the scene; not counted by the distributed bake: 0 there).
  size_t missedPaths = 0;
  size_t denseVoxels = 0;  ///< 8^depth
  double traceSeconds = 0;
  LevelStats level;        ///< voxelize / splat / gather + cluster (the last pass)
  NoiseSummary noise;      ///< the grid's noise figure (summarizeNoise)
  /// Target bakes: every pass, and why the last one was the last:
  /// "target reached", "photon cap", "time cap", "pass cap", "no more paths".
  std::vector<TargetPass> passes;
  std::string targetStop;
  /// Tracing stopped before the most paths a bake traces: the rate so far
  /// said that they would store under 1% of the photons (photonBatchPaths).
  bool reachStop = false;
  /// The lights whose paths stored nothing (PhotonMap::darkLights), named
  /// with where they are and their paths.
  std::vector<std::string> darkLights;
  /// One row per stage ("trace photons", "voxelize", "splat photons",
  /// "gather + cluster"), with the process's memory after each.
  std::vector<StageReport> stages;
  double seconds() const { return traceSeconds + level.seconds(); }
};

struct BakeResult {
  VdlGrid grid;
  /// Everything the file metadata records (the source scene is left to the caller:
  /// recordSourceScene).
  BakeMetadata metadata;
  BakeStats stats;
  PhotonMap photons;  ///< filled when BakeParams::keepPhotons
};

/// The free-space light of a bake from its rays (PhotonMap::segments,
/// scaled), timed as the stage "free-space light" in `stages`; the one-process
/// and the distributed bakes both call it.
VolumeLight bakeFreeSpaceLight(const std::vector<PhotonSegment>& segments, const GridFrame& frame,
                               const BakeParams& params, ProgressSink* progress,
                               std::vector<StageReport>& stages);

/// "" when the photon tracing stored what was asked without aiming most
/// paths past the scene; else a sentence saying which of the two happened
/// and what helps. Paths that hit a surface and store nothing are not a
/// fault: the first hit is direct light, left to the renderer, and in an
/// open scene most reflected light leaves it (a room corner, a truck on
/// open ground: nine paths in ten). When that keeps the bake from storing
/// the photons asked for, the advice is --include-direct; when most paths
/// miss every surface, --bounds.
/// Also names the lights that stored nothing (darkLightsWarning).
std::string photonBudgetWarning(const BakeParams& params, const BakeStats& stats);
/// The lights whose paths stored nothing, named with where they are; "" when none.
std::string darkLightsWarning(const BakeStats& stats);

/// @throws InputError saying why, when the photon tracing stored no photon
/// at all (a bake of nothing but zeros is never what was asked for).
void checkPhotonsStored(const BakeParams& params, const BakeStats& stats);

/// Active voxels a bake at `frame` will have, from the area of the scene's
/// surfaces (inside `region` when it is set): area / h^2, what a surface
/// lying along the grid crosses (1.04x that was measured on the Cornell box;
/// slanted surfaces cross up to sqrt(3)x more, so this rather underestimates),
/// and never more than the grid's resolution^3 voxels (coincident surfaces).
double estimateActiveVoxels(const Scene& scene, const GridFrame& frame, const Bounds3& region);

/// The photon budget from the two ways of asking for one: `photons` > 0 a
/// fixed budget, else photons until the noise figure reaches `targetError`
/// (0: kDefaultTargetError). The command line and the Python module both ask
/// through it. @throws InputError when both are given, or a target error
/// other than 0 is outside kTargetErrorRange (NaN, a negative one: never
/// taken as "not given").
void setPhotonBudget(BakeParams& params, size_t photons, double targetError);

/// Refuses, before any work, a grid at `frame` whose voxels
/// (estimateActiveVoxels x kBakeBytesPerVoxel) and `otherBytes` need more
/// memory than is available, naming --depth and the figures (bake, convert
/// to a finer depth). @throws InputError.
void checkVoxelMemory(const Scene& scene, const GridFrame& frame, const Bounds3& region,
                      double otherBytes, int processes = 1);

/// A warning for a fixed photon budget spread thinner than a photon per ten
/// surface voxels over a million or more of them (--depth 10 with 100,000
/// photons: 6.5 M voxels, 78 s and 6.2 GB for light gathered from far
/// beyond each voxel, H14-5-3); empty otherwise, and for --depth auto or a
/// target error, which fit the depth or the photons to each other.
std::string sparsePhotonsWarning(const Scene& scene, const BakeParams& params);
/// The same for `photons` photons gathered over `frame` (a bake's, or
/// `convert --photon-map` to a finer depth), `what` naming them and `advice`
/// ending the message.
std::string sparsePhotonsWarning(const Scene& scene, const GridFrame& frame, const Bounds3& region,
                                 size_t photons, const std::string& what,
                                 const std::string& advice);

/// Refuses, before any work, a bake whose voxels (estimateActiveVoxels x
/// kBakeBytesPerVoxel) and photons (kBakeBytesPerPhoton) need more memory
/// than is available (availableMemoryBytes), naming --depth and the figures.
/// `processes` > 1: a distributed bake, each process holding about its share.
void checkBakeMemory(const Scene& scene, const BakeParams& params, int processes = 1);

/// What bake() does before any work, shared with the distributed bake
/// (src/distributed): the scene's marked region (Scene::region) when
/// `requested` has none, then every check (parameter ranges, a voxel the
/// .vdb can store, the memory: checkBakeMemory). Returns the parameters the
/// bake runs with. @throws InputError naming the flag.
BakeParams checkedBakeParams(const Scene& scene, const BakeParams& requested, int processes = 1);

/// The file metadata of a bake of `scene` with `params` (the source scene
/// left to the caller: recordSourceScene) that stored `photons` from `emittedPaths` paths and gathered
/// within `radius` (world units).
BakeMetadata bakeMetadata(const Scene& scene, const BakeParams& params, int64_t photons,
                          int64_t emittedPaths, float radius);

/// Records the scene file a bake read, `scene.sourcePath`, in `meta`: its
/// name, its absolute path and the content hash of its files as they were
/// read (Scene::contentHash; for a scene made in code with a sourcePath, the
/// files' hash now).
void recordSourceScene(BakeMetadata& meta, const Scene& scene);

/// "" when `meta` records no content hash or `scenePath`'s files still have
/// it; else a sentence for a warning: the grid was baked from a scene whose
/// files have changed since (its light may no longer fit the scene). Control
/// characters of the file's metadata escaped (core/printable.h).
std::string staleBakeWarning(const BakeMetadata& meta, const std::string& scenePath);

/// "" when `meta` records no sky (older files) or the sky it records is
/// `sky` (Sky::fingerprint); else a sentence for a warning: the grid's light
/// was baked under another sky, which the surfaces keep (render --sky, or the
/// scene's sky changed, changes only the background and the reflections).
std::string skyMismatchWarning(const BakeMetadata& meta, const Sky& sky);

/// The warnings of a grid drawn with `scene`, each a sentence, for every
/// reader alike (render, lightmap, the Python module): staleBakeWarning
/// against the scene's files as it read them (Scene::contentHash; its
/// sourcePath's files now for a scene made in code; none without either)
/// and skyMismatchWarning.
std::vector<std::string> gridWarnings(const BakeMetadata& meta, const Scene& scene);

/// "" unless `meta` records a bake with --include-direct; else a sentence for
/// a warning: the VDLs hold the direct light, which `drawnAgain` ("mode
/// full", "--content full") adds again, counted twice; `advice` ends it.
std::string directTwiceWarning(const BakeMetadata& meta, const std::string& drawnAgain,
                               const std::string& advice);

/// "" when either hash is not recorded or they agree; else a sentence for a
/// warning: the photon map `what` was traced under another sky than the grid
/// `gridWhat` was baked under (recorded as `gridSkyHash`), so the grid
/// re-gathered from it holds the photons' sky's light and records that sky.
/// "" unless a photon map's include_direct (`photonIncludeDirect`, -1 = not
/// recorded) differs from the grid's it is re-gathered into: the output holds
/// the photons' light, with or without the direct light, and records it.
std::string photonDirectMismatchWarning(const std::string& what, int photonIncludeDirect,
                                        const std::string& gridWhat, int gridIncludeDirect);
std::string photonSkyMismatchWarning(const std::string& what, const std::string& photonSkyHash,
                                     const std::string& gridWhat, const std::string& gridSkyHash);

/// The same rule for any input made from a scene (a photon map, a `.vdb`
/// given to `convert --scene`): "" when `recordedHash` is empty (not
/// recorded) or equals `sceneHash` (sceneContentHash of the scene given
/// with it); else a warning naming `what` and both hashes: the input was
/// made from another scene, or from this one before it changed.
std::string sceneMismatchWarning(const std::string& what, const std::string& recordedHash,
                                 const std::string& scenePath, const std::string& sceneHash);


/// @brief Bakes `scene` with `params` (paper §3.1). Deterministic. Without
/// params.region, the scene's marked region (Scene::region) is the region.
/// @throws InputError for out-of-range parameters (naming them) and the
/// stages' errors (a scene without light, a grid too deep).
BakeResult bake(const Scene& scene, const BakeParams& params, ProgressSink* progress = nullptr);

}  // namespace lo
