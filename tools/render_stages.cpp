#include "render_stages.h"

#include <cstdio>

#include "json_report.h"
#include "render_options.h"
#include "report.h"

namespace lo::tool {

Scene loadSceneStage(const SceneFlags& opt, std::vector<StageReport>& rows) {
  StageTimer loadTimer(rows, "load scene");
  Scene scene = loadSceneWith(opt);
  printSceneWarnings(scene);
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.textures.size()) + " textures");
  return scene;
}

LoadedVdl readLightsStage(const std::string& lights, const Scene& scene,
                          std::vector<StageReport>& rows) {
  StageTimer readTimer(rows, "read grid");
  LoadedVdl baked = readVdlGrid(lights, scene.origin);
  readTimer.finish(formatCount(baked.grid.size()) + " voxels");
  for (const std::string& warning : gridWarnings(baked.meta, scene)) {
    printWarning(lights + ": " + warning);
  }
  return baked;
}

std::unique_ptr<GlContext> openContextStage(const GlContextParams& params, const std::string& name,
                                            bool quiet, JsonReport& report,
                                            std::vector<StageReport>& rows) {
  StageTimer contextTimer(rows, "GL context");
  std::unique_ptr<GlContext> context = createGlContext(params);
  contextTimer.finish(name);
  if (!quiet) std::printf("%s: %s\n", name.c_str(), context->info().ToString().c_str());
  report.figures["gl"] = context->info().ToString();
  return context;
}

void reportSession(const RenderSession& session, bool showOctree, bool quiet, JsonReport& report,
                   std::vector<StageReport>& rows) {
  rows.insert(rows.end(), session.stages().begin(), session.stages().end());
  printWarnings(session.warnings());
  if (showOctree) {
    if (!quiet) std::printf("octree: %s\n", session.octreeSummary().c_str());
    report.figures["octree"] = session.octreeSummary();
  }
  if (!quiet && !session.atlasSummary().empty()) {
    std::printf("atlas: %s\n", session.atlasSummary().c_str());
  }
}

}  // namespace lo::tool
