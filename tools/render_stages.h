#pragma once
/// @file tools/render_stages.h
/// @brief The stages `render` and `view` run alike before their first frame
/// (the scene, the baked grid, the GL context, the render session), each
/// timed as a row of the stage table and reported the same way: on stdout
/// unless quiet, warnings on stderr, the figures in the --json report.

#include <memory>
#include <string>
#include <vector>

#include "bake/bake.h"
#include "core/resources.h"
#include "render/context.h"
#include "render/render_session.h"
#include "scene/scene.h"
#include "scene_options.h"
#include "vdb/vdb_io.h"

namespace lo::tool {

struct JsonReport;

/// The "load scene" row: the scene with the --sky flags and the --add
/// objects placed, its warnings printed. @throws as loadSceneWith.
Scene loadSceneStage(const SceneFlags& opt, std::vector<StageReport>& rows);

/// The "read grid" row: the baked grid `lights` in the scene's coordinates,
/// with a "warning: LIGHTS: ..." for a bake of another version of the scene
/// or under another sky (gridWarnings). @throws as readVdlGrid.
LoadedVdl readLightsStage(const std::string& lights, const Scene& scene,
                          std::vector<StageReport>& rows);

/// The "GL context" row (its result `name`): the context, "name: GL info" on
/// stdout unless `quiet`, the info as the report's figure "gl".
std::unique_ptr<GlContext> openContextStage(const GlContextParams& params, const std::string& name,
                                            bool quiet, JsonReport& report,
                                            std::vector<StageReport>& rows);

/// After a RenderSession's set-up: its rows, its warnings, and unless
/// `quiet` its octree (with `showOctree`, also the report's figure "octree")
/// and atlas summaries on stdout.
void reportSession(const RenderSession& session, bool showOctree, bool quiet, JsonReport& report,
                   std::vector<StageReport>& rows);

}  // namespace lo::tool
