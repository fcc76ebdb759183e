// bakeLevel: voxelize + splat + gather + cluster at one depth.

#include "cluster/bake_level.h"

#include "core/resources.h"

namespace lo {

VdlGrid bakeLevel(const Scene& scene, const std::vector<Photon>& photons, const LevelParams& params,
                  ProgressSink* progress, LevelStats* stats) {
  LevelStats s;
  Stopwatch clock;
  SurfaceGrid grid = buildSurfaceGrid(scene, params.grid, progress);
  s.voxelizeSeconds = clock.seconds();
  s.activeVoxels = grid.size();

  clock.reset();
  s.droppedPhotons = splatPhotons(grid, photons);
  s.splatSeconds = clock.seconds();

  clock.reset();
  VdlGrid vdls =
      buildVdlGrid(grid, photons, params.gather, params.cluster, progress, &s.threadSeconds);
  s.gatherClusterSeconds = clock.seconds();
  s.radius = resolveRadius(params.gather, grid.frame);
  if (stats) *stats = s;
  return vdls;
}

}  // namespace lo
