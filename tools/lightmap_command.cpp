// `lightoctree lightmap`: parses, calls exportLightmap (src/export: scene +
// baked .vdb -> light octree -> lightmap UVs and atlas -> page images and a
// glTF 2.0 file other tools open, optionally an unlit preview) and reports.

#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli_checks.h"
#include "command_options.h"
#include "commands.h"
#include "core/file.h"
#include "export/lightmap_export.h"
#include "json_report.h"
#include "report.h"
#include "scene/scene.h"
#include "scene_options.h"

namespace lo::tool {
namespace {

struct LightmapOptions {
  std::string scene;
  SceneOptions sceneOptions;  // --sky
  std::string lights;
  std::string output;
  float texelSize = 0;  // 0 = a quarter voxel (defaultLightmapTexel)
  int atlas = 1024;
  std::string uv;  // "" = TEXCOORD_1 when the scene has it, else automatic charts
  std::string content = "indirect";
  int directSamples = 64;
  std::string image = "exr";
  bool previewUnlit = false;
  float exposure = 0;
  std::string atlasOn = "cpu";  // cpu | osmesa | egl
  bool chartImage = false;
  std::string directions;  // "": on, but for --content full
  std::string json;  // --json FILE: tools/json_report.h
  bool quiet = false;
};

/// The export's parameters from the flags, checked before any work against
/// the files the command reads, `inputs`.
LightmapExportParams exportParams(const LightmapOptions& opt, const NamedPaths& inputs) {
  checkOutputFolder(opt.output, "--output");
  checkLightmapExportPath(opt.output, "--output");
  checkLightmapOutputs(opt.output, opt.previewUnlit, inputs);
  if (!opt.json.empty()) {
    checkOutputFolder(opt.json, "--json");
    checkDistinctFiles({{"--output", opt.output}, {"--json", opt.json}}, inputs);
  }
  LightmapExportParams p;
  p.output = opt.output;
  p.content = parseAtlasContent(opt.content);
  p.directSamples = opt.directSamples;
  p.lightmap.uvSource = opt.uv.empty() ? UvSource::Default : parseUvSource(opt.uv);
  p.lightmap.uv.texelSize = opt.texelSize;
  p.lightmap.uv.atlasSize = opt.atlas;
  p.rgbm = opt.image == "png";
  p.preview = opt.previewUnlit;
  p.previewExposureEv = opt.exposure;
  p.chartImages = opt.chartImage;
  p.directionPages = directionPagesOf(opt.directions, p.content, "--directions");
  if (opt.atlasOn != "cpu") p.atlasGl = parseGlBackend(opt.atlasOn);
  return p;
}

/// The figures `lightmap --json` reports (README.md, "Scripting").
nlohmann::json lightmapFigures(const LightmapExportResult& r, const LightmapExportParams& params) {
  const LightmapUvs& uvs = r.lightmap.uvs;
  const LightmapAtlas& atlas = r.lightmap.atlas;
  return {
      {"uvs", r.lightmap.fromTexcoord1 ? "texcoord1" : "charts"},
      {"charts", uvs.chartCount},
      {"pages", atlas.pageCount},
      {"page_size", {atlas.width, atlas.height}},
      {"texel_size", uvs.texelSize},
      {"utilisation", uvs.utilisation},
      {"covered_texels", atlas.coveredTexels},
      {"dilated_texels", atlas.dilatedTexels},
      {"seam_mismatch", {{"before", atlas.seamMismatchBefore}, {"after", atlas.seamMismatchAfter}}},
      {"content", toString(params.content)},
      {"encoding", params.rgbm ? "rgbm-png" : "linear-exr"},
      {"rgbm_range", params.rgbm ? nlohmann::json(r.rgbmRange) : nlohmann::json(nullptr)},
      {"page_files", r.pagePaths},
      {"direction_files", r.directionPaths},
      {"gltf", r.output},
      {"preview", r.previewPath.empty() ? nlohmann::json(nullptr) : nlohmann::json(r.previewPath)},
      {"octree_bytes", r.octreePoolBytes + r.octreeVdlBytes}};
}

int runLightmap(const LightmapOptions& opt) {
  NamedPaths inputs = sceneInputs(opt.scene, opt.sceneOptions);
  inputs.push_back({"LIGHTS", opt.lights});
  LightmapExportParams params = exportParams(opt, inputs);
  std::vector<StageReport> rows;
  if (!opt.json.empty()) {
    // The report goes into the export's set: it appears with the files or not at all.
    params.beforeCommit = [&](const LightmapExportResult& r, AtomicFileSet& set) {
      std::vector<StageReport> all = rows;
      all.insert(all.end(), r.stages.begin(), r.stages.end());
      JsonReport report{"lightmap", inputs, lightmapFigures(r, params)};
      report.addTo(set, opt.json, all);
    };
  }
  StageTimer loadTimer(rows, "load scene");
  const Scene scene = loadSceneWith(opt.scene, opt.sceneOptions);
  printSceneWarnings(scene);
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.materials.size()) + " materials");

  params.warn = printWarning;
  const LightmapExportResult r = exportLightmap(scene, opt.lights, params);
  if (opt.quiet) return 0;
  if (params.atlasGl) std::printf("%s: %s\n", opt.atlasOn.c_str(), r.glInfo.c_str());
  rows.insert(rows.end(), r.stages.begin(), r.stages.end());
  printSummary(stdout, rows);
  std::printf("\n%s", lightmapExportSummary(r, params).c_str());
  return 0;
}

void addLightmapOptions(CLI::App* cmd, LightmapOptions& opt) {
  cmd->description(
      "Bake the light octree into lightmap atlases and export the scene as glTF 2.0 with "
      "lightmap UVs (TEXCOORD_1) and the atlas pages beside it, referenced from each material's "
      "extras.lightmap (docs/lightmap.md).");
  addSceneArgument(cmd, opt.scene);
  addSceneOptions(cmd, opt.sceneOptions);
  addLightsArgument(cmd, opt.lights)->required();
  cmd->add_option("-o,--output", opt.output,
                  "glTF to write: .glb (one file) or .gltf (+ OUT.bin); the atlas pages go beside "
                  "it as OUT-lightmapN.exr or .png")
      ->required();
  cmd->add_option("--texel-size", opt.texelSize,
                  "Scene units per lightmap texel (automatic charts only; default: a quarter of "
                  "the octree's voxel, which holds nothing finer)")
      ->check(numberIn(kPositiveNumber));
  cmd->add_option("--atlas", opt.atlas,
                  "Largest atlas page in texels (width = height): charts go on the smallest page "
                  "that holds them, up to this size, then on more pages")
      ->check(wholeIn(8, 16384))
      ->capture_default_str();
  cmd->add_option("--uv", opt.uv,
                  "Lightmap UVs: texcoord1 (the scene's TEXCOORD_1, which must lie in [0, 1] "
                  "without overlaps) or auto (automatic charts, LSCM, packed). Default: "
                  "TEXCOORD_1 when the scene has one (an invalid one is an error), else auto")
      ->check(CLI::IsMember({"auto", "texcoord1"}));
  cmd->add_option("--content", opt.content,
                  "What the atlas holds: indirect (the light octree) or full (the direct light "
                  "too, ray traced with soft shadows: one complete lightmap for engines)")
      ->check(CLI::IsMember({"indirect", "full"}))
      ->capture_default_str();
  cmd->add_option("--direct-samples", opt.directSamples,
                  "With --content full: emitter samples per texel (shadow rays; punctual lights "
                  "take one each)")
      ->check(wholeIn(1, 65536))
      ->capture_default_str();
  cmd->add_option("--image", opt.image,
                  "Page images: exr (linear 32-bit float irradiance, W/m^2) or png (RGBM in "
                  "8-bit RGBA, range recorded in extras.lightmap.rgbmRange)")
      ->check(CLI::IsMember({"exr", "png"}))
      ->capture_default_str();
  cmd->add_flag("--preview-unlit", opt.previewUnlit,
                "Also write OUT-preview.glb: every material KHR_materials_unlit with the baked "
                "radiance (albedo / pi * E + emission) as its base colour, for any glTF viewer");
  cmd->add_option("--exposure", opt.exposure,
                  "Exposure of the unlit preview in EV (radiance * 2^EV before the sRGB curve)")
      ->check(numberIn({-30, 30}))
      ->capture_default_str();
  cmd->add_option("--atlas-on", opt.atlasOn,
                  "Where the octree is rendered into the atlas: cpu (the C++ lookup; the same "
                  "bytes on every machine), osmesa (OpenGL in software) or egl (a GPU, "
                  "headless): the scene shader's lookup run per texel (paper 4.2.3)")
      ->check(CLI::IsMember({"cpu", "osmesa", "egl"}))
      ->capture_default_str();
  cmd->add_option(
         "--directions", opt.directions,
         "Also write OUT-directionN.png beside each page: the mean direction the light "
         "comes from per texel (world space, 8-bit unit vectors, extras.lightmap.direction), "
         "so viewers shade normal maps and gloss from the lightmap (on, the default) or not "
         "(off); never with --content full, whose E holds direct light from other directions")
      ->check(CLI::IsMember({"on", "off"}));
  cmd->add_flag("--chart-image", opt.chartImage,
                "Also write OUT-chartsN.png: each page's UV layout, one colour per chart, chart "
                "borders darker (v = 0 is the top row)");
  cmd->add_option("--json", opt.json,
                  "Also write a JSON report: the files read and written (pages, glTF, "
                  "preview), the RGBM range, page count and size, time and memory per stage "
                  "(README.md, \"Scripting\"); written with the other files, as one set");
  cmd->add_flag("-q,--quiet", opt.quiet, "Only errors");
}

}  // namespace

std::function<int()> addLightmapCommand(CLI::App& app) {
  return addCommand(app, "lightmap", addLightmapOptions, runLightmap);
}

}  // namespace lo::tool
