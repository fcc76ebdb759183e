// `lightoctree lightmap`: scene + baked .vdb -> light octree -> lightmap UVs
// and atlas (src/lightmap on the CPU, or render/atlas_gpu.h in GL) -> page images and a glTF 2.0 file that other
// tools open (src/scene gltf_export.h), optionally with an unlit preview.

#include <CLI/CLI.hpp>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>

#include "commands.h"
#include "core/error.h"
#include "core/file.h"
#include "image/image.h"
#include "lightmap/lightmap_bake.h"
#include "octree/gpu_octree.h"
#include "reference/path_tracer.h"
#include "render/atlas_gpu.h"
#include "render/context.h"
#include "report.h"
#include "scene/gltf_export.h"
#include "scene/scene.h"
#include "vdb/vdb_io.h"

namespace lo::tool {
namespace {

namespace fs = std::filesystem;

/// What the atlas holds.
enum class AtlasContent {
  Indirect,  ///< the light octree alone (what `bake` stores by default)
  Full,      ///< direct light too: needs the GL renderer's render-to-atlas pass
};

AtlasContent parseContent(const std::string& name) {
  if (name == "indirect") return AtlasContent::Indirect;
  if (name == "full") return AtlasContent::Full;
  throw InputError("--content: '" + name + "' (expected indirect or full)");
}
const char* contentName(AtlasContent c) { return c == AtlasContent::Full ? "full" : "indirect"; }

struct LightmapOptions {
  std::string scene;
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
  bool quiet = false;
};

/// Everything the run needs, resolved from the flags before any work.
struct LightmapRun {
  LightmapParams bake;
  AtlasContent content = AtlasContent::Indirect;
  bool rgbm = false;
  bool preview = false;
  float previewExposureEv = 0;
  std::string output;                  ///< the lit glTF (.glb or .gltf)
  std::string previewPath;             ///< OUT-preview.glb when preview
  std::vector<std::string> pagePaths;  ///< filled once the page count is known
  int directSamples = 64;              ///< --content full: emitter samples per texel
};

LightmapRun resolve(const LightmapOptions& opt) {
  checkOutputFolder(opt.output, "--output");
  checkDistinctFiles({{"--output", opt.output}}, {{"SCENE", opt.scene}, {"LIGHTS", opt.lights}});
  if (!hasExtension(opt.output, ".glb") && !hasExtension(opt.output, ".gltf")) {
    throw InputError("--output: '" + opt.output + "' must end in .glb or .gltf");
  }
  LightmapRun run;
  run.content = parseContent(opt.content);
  run.directSamples = opt.directSamples;
  run.bake.uvSource = opt.uv.empty() ? UvSource::Default : parseUvSource(opt.uv);
  run.bake.uv.texelSize = opt.texelSize;
  run.bake.uv.atlasSize = opt.atlas;
  run.bake.atlas.radiance = opt.previewUnlit;  // the preview's base colour
  run.rgbm = opt.image == "png";
  run.preview = opt.previewUnlit;
  run.previewExposureEv = opt.exposure;
  run.output = opt.output;
  const fs::path out(opt.output);
  if (run.preview) {
    run.previewPath = (out.parent_path() / (out.stem().string() + "-preview.glb")).string();
  }
  return run;
}

std::string pagePath(const std::string& output, int page, bool rgbm) {
  const fs::path out(output);
  return (out.parent_path() /
          (out.stem().string() + "-lightmap" + std::to_string(page) + (rgbm ? ".png" : ".exr")))
      .string();
}

/// RGBM's range: the next power of two at or above the brightest texel, so
/// the pages use the 8 bits they have (recorded in the extras).
float rgbmRangeFor(const std::vector<RgbImage>& pages) {
  float brightest = 0;
  for (const RgbImage& page : pages)
    for (float v : page.rgb)
      if (std::isfinite(v)) brightest = std::max(brightest, v);
  return brightest > 0 ? std::exp2(std::ceil(std::log2(brightest))) : 1.0f;
}

/// Files this run has written, removed again if a later one fails, so that
/// a failed run leaves nothing behind.
class WrittenFiles {
 public:
  void add(const std::string& path) { paths_.push_back(path); }
  void keep() { paths_.clear(); }
  ~WrittenFiles() {
    for (const std::string& p : paths_) {
      std::error_code ignored;
      fs::remove(p, ignored);
    }
  }

 private:
  std::vector<std::string> paths_;
};

void addRow(std::vector<StageReport>& rows, const std::string& name, double seconds,
            const std::string& detail) {
  StageReport r;
  r.name = name;
  r.seconds = seconds;
  r.rssBytes = currentRssBytes();
  r.peakBytes = peakRssBytes();
  r.detail = detail;
  rows.push_back(r);
}

int runLightmap(const LightmapOptions& opt) {
  LightmapRun run = resolve(opt);
  std::vector<StageReport> rows;

  StageTimer loadTimer(rows, "load scene");
  const Scene scene = loadScene(opt.scene);
  printSceneWarnings(scene);
  loadTimer.finish(formatCount(scene.triangleCount()) + " triangles, " +
                   std::to_string(scene.materials.size()) + " materials");

  StageTimer octreeTimer(rows, "octree");
  const LoadedVdl baked = readVdlGrid(opt.lights);
  // The renderer's octree (cosine correction on, float VDLs) and lookup
  // settings (GpuOctreeParams and OctreeShadeParams defaults, as `render`
  // uses them), so the atlas holds what the renderer would compute.
  const GpuOctree octree = buildGpuOctree(baked.grid, GpuOctreeParams{});
  const size_t octreeBytes = octree.poolBytes() + octree.vdlBytes();
  octreeTimer.finish(formatCount(octree.leafCount) + " leaves, " + formatBytes(octreeBytes));

  // --content full: the direct light by the path tracer's own light
  // sampling (src/reference), handed to the atlas bake as a function so that
  // the lightmap stage links no ray tracer.
  std::unique_ptr<DirectIrradiance> direct;
  if (run.content == AtlasContent::Full) {
    direct = std::make_unique<DirectIrradiance>(scene);
    run.bake.atlas.directLight = [&direct, samples = run.directSamples](
                                     const std::vector<AtlasSurfacePoint>& texels, int page) {
      std::vector<DirectIrradiance::Point> points(texels.size());
      for (size_t i = 0; i < texels.size(); ++i) {
        points[i] = {texels[i].position, texels[i].triangle, texels[i].normal};
      }
      return direct->atMany(points, samples, /*seed=*/1, uint64_t(page) << 32);
    };
  }
  // --atlas-on osmesa|egl: the octree rendered into the atlas by GL
  // (render/atlas_gpu.h) in a headless context of that kind.
  std::unique_ptr<GlContext> context;
  std::unique_ptr<GpuAtlasEvaluator> gpu;
  if (opt.atlasOn != "cpu") {
    GlContextParams contextParams;
    contextParams.backend = parseGlBackend(opt.atlasOn);
    context = createGlContext(contextParams);
    if (!opt.quiet) {
      std::printf("%s: %s\n", opt.atlasOn.c_str(), context->info().ToString().c_str());
    }
    gpu = std::make_unique<GpuAtlasEvaluator>();
    run.bake.atlas.evaluator = gpu.get();
  }
  const LightmapBake lm = bakeLightmap(scene, octree, run.bake);
  const LightmapUvs& uvs = lm.uvs;
  const LightmapAtlas& atlas = lm.atlas;
  addRow(rows, "UVs", lm.uvSeconds,
         std::string(lm.fromTexcoord1 ? "TEXCOORD_1, " : "automatic, ") +
             formatCount(size_t(uvs.chartCount)) + " charts");
  addRow(rows, "atlas: raster", atlas.rasterSeconds,
         formatCount(atlas.coveredTexels) + " covered texels");
  addRow(rows, "atlas: evaluate", atlas.evaluateSeconds,
         run.preview ? "irradiance and radiance" : "irradiance");
  addRow(
      rows, "atlas: dilate", atlas.dilateSeconds,
      formatCount(atlas.dilatedTexels) + " texels, " + std::to_string(atlas.dilation) + " rings");
  addRow(rows, "atlas: stitch", atlas.stitchSeconds,
         formatCount(atlas.seamEdges) + " seam edges, mismatch " +
             formatNumber(atlas.seamMismatchBefore) + " -> " +
             formatNumber(atlas.seamMismatchAfter) + " W/m^2");

  // Everything is encoded in memory first; the files are written last.
  StageTimer encodeTimer(rows, "encode");
  LightmapExport ex;
  ex.uv = uvs.uv;
  ex.trianglePage = uvs.trianglePage;
  ex.width = atlas.width;
  ex.height = atlas.height;
  ex.content = contentName(run.content);
  ex.encoding = run.rgbm ? "rgbm-png" : "linear-exr";
  std::vector<std::string> rgbmPages;
  if (run.rgbm) {
    ex.rgbmRange = rgbmRangeFor(atlas.irradiance);
    for (const RgbImage& page : atlas.irradiance) {
      const std::vector<unsigned char> png = encodeRgbmPng(page, ex.rgbmRange);
      rgbmPages.emplace_back(png.begin(), png.end());
    }
  }
  for (int p = 0; p < atlas.pageCount; ++p) {
    run.pagePaths.push_back(pagePath(run.output, p, run.rgbm));
    ex.pageUris.push_back(fs::path(run.pagePaths.back()).filename().string());
  }
  const GltfFiles lit = encodeLightmapGltf(scene, ex, run.output);
  GltfFiles unlit;
  if (run.preview) {
    LightmapExport preview = ex;
    preview.unlit = true;
    preview.previewExposureEv = run.previewExposureEv;
    for (const RgbImage& page : atlas.radiance)
      preview.previewPng.push_back(encodePng(page, run.previewExposureEv));
    unlit = encodeLightmapGltf(scene, preview, run.previewPath);
  }
  encodeTimer.finish(ex.encoding + (run.preview ? " + unlit preview" : ""));

  StageTimer writeTimer(rows, "write");
  WrittenFiles written;
  size_t pageFileBytes = 0;
  for (int p = 0; p < atlas.pageCount; ++p) {
    const std::string& path = run.pagePaths[size_t(p)];
    if (run.rgbm) {
      writeTextAtomically(path, rgbmPages[size_t(p)]);
    } else {
      writeExr(path, atlas.irradiance[size_t(p)]);
    }
    written.add(path);
    pageFileBytes += size_t(fs::file_size(path));
  }
  auto writeGltf = [&](const std::string& path, const GltfFiles& files) {
    if (!files.binUri.empty()) {
      const std::string bin = (fs::path(path).parent_path() / files.binUri).string();
      writeTextAtomically(bin, files.bin);
      written.add(bin);
    }
    writeTextAtomically(path, files.gltf);
    written.add(path);
  };
  writeGltf(run.output, lit);
  if (run.preview) writeGltf(run.previewPath, unlit);
  std::vector<std::string> chartPaths;
  if (opt.chartImage) {
    const fs::path out(run.output);
    for (int p = 0; p < uvs.pageCount; ++p) {
      chartPaths.push_back(
          (out.parent_path() / (out.stem().string() + "-charts" + std::to_string(p) + ".png"))
              .string());
      const std::vector<uint8_t> png = encodePng(chartLayoutImage(uvs, p));
      writeTextAtomically(chartPaths.back(), std::string(png.begin(), png.end()));
      written.add(chartPaths.back());
    }
  }
  written.keep();
  writeTimer.finish(formatCount(size_t(atlas.pageCount) + 1 + (run.preview ? 1 : 0) +
                                chartPaths.size()) +
                    " files");

  if (opt.quiet) return 0;
  printSummary(stdout, rows);
  const size_t texels = size_t(atlas.width) * size_t(atlas.height) * size_t(atlas.pageCount);
  std::printf(
      "\nUVs: %s, %d charts, %d page(s) of %d x %d, utilisation %.3f, worst stretch %.3f, "
      "texel %s scene units\n",
      lm.fromTexcoord1 ? "TEXCOORD_1" : "automatic charts", uvs.chartCount, uvs.pageCount,
      uvs.width, uvs.height, double(uvs.utilisation), double(uvs.worstStretch),
      formatNumber(uvs.texelSize).c_str());
  std::printf("atlas: %s covered + %s dilated texels of %s; seams %s -> %s W/m^2\n",
              formatCount(atlas.coveredTexels).c_str(), formatCount(atlas.dilatedTexels).c_str(),
              formatCount(texels).c_str(), formatNumber(atlas.seamMismatchBefore).c_str(),
              formatNumber(atlas.seamMismatchAfter).c_str());
  std::printf(
      "memory: atlas %s as RGB32F textures (%s as RGBM8), %s in files; octree %s "
      "(pool %s + VDLs %s)\n",
      formatBytes(texels * 12).c_str(), formatBytes(texels * 4).c_str(),
      formatBytes(pageFileBytes).c_str(), formatBytes(octreeBytes).c_str(),
      formatBytes(octree.poolBytes()).c_str(), formatBytes(octree.vdlBytes()).c_str());
  if (run.rgbm) std::printf("RGBM range: %s W/m^2\n", formatNumber(ex.rgbmRange).c_str());
  for (const std::string& path : run.pagePaths) std::printf("wrote %s\n", path.c_str());
  std::printf("wrote %s (%s)\n", run.output.c_str(),
              formatBytes(lit.gltf.size() + lit.bin.size()).c_str());
  if (run.preview) {
    std::printf("wrote %s (%s, unlit preview)\n", run.previewPath.c_str(),
                formatBytes(unlit.gltf.size()).c_str());
  }
  for (const std::string& path : chartPaths) std::printf("wrote %s (chart layout)\n", path.c_str());
  return 0;
}

}  // namespace

std::function<int()> addLightmapCommand(CLI::App& app) {
  auto opt = std::make_shared<LightmapOptions>();
  CLI::App* cmd = app.add_subcommand(
      "lightmap",
      "Bake the light octree into lightmap atlases and export the scene as glTF 2.0 with "
      "lightmap UVs (TEXCOORD_1) and the atlas pages beside it, referenced from each material's "
      "extras.lightmap (docs/lightmap.md).");
  cmd->add_option("scene", opt->scene, "Scene: .gltf, .glb or .obj")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("lights", opt->lights, "Baked VDL grid (.vdb from `lightoctree bake`)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", opt->output,
                  "glTF to write: .glb (one file) or .gltf (+ OUT.bin); the atlas pages go beside "
                  "it as OUT-lightmapN.exr or .png")
      ->required();
  cmd->add_option("--texel-size", opt->texelSize,
                  "Scene units per lightmap texel (automatic charts only; default: a quarter of "
                  "the octree's voxel, which holds nothing finer)")
      ->check(CLI::PositiveNumber);
  cmd->add_option("--atlas", opt->atlas,
                  "Largest atlas page in texels (width = height): charts go on the smallest page "
                  "that holds them, up to this size, then on more pages")
      ->check(CLI::Range(8, 16384))
      ->capture_default_str();
  cmd->add_option("--uv", opt->uv,
                  "Lightmap UVs: texcoord1 (the scene's TEXCOORD_1, which must lie in [0, 1] "
                  "without overlaps) or auto (automatic charts, LSCM, packed). Default: "
                  "TEXCOORD_1 when the scene has one (an invalid one is an error), else auto")
      ->check(CLI::IsMember({"auto", "texcoord1"}));
  cmd->add_option("--content", opt->content,
                  "What the atlas holds: indirect (the light octree) or full (the direct light "
                  "too, ray traced with soft shadows: one complete lightmap for engines)")
      ->check(CLI::IsMember({"indirect", "full"}))
      ->capture_default_str();
  cmd->add_option("--direct-samples", opt->directSamples,
                  "With --content full: emitter samples per texel (shadow rays; punctual lights "
                  "take one each)")
      ->check(CLI::Range(1, 65536))
      ->capture_default_str();
  cmd->add_option("--image", opt->image,
                  "Page images: exr (linear 32-bit float irradiance, W/m^2) or png (RGBM in "
                  "8-bit RGBA, range recorded in extras.lightmap.rgbmRange)")
      ->check(CLI::IsMember({"exr", "png"}))
      ->capture_default_str();
  cmd->add_flag("--preview-unlit", opt->previewUnlit,
                "Also write OUT-preview.glb: every material KHR_materials_unlit with the baked "
                "radiance (albedo / pi * E + emission) as its base colour, for any glTF viewer");
  cmd->add_option("--exposure", opt->exposure,
                  "Exposure of the unlit preview in EV (radiance * 2^EV before the sRGB curve)")
      ->check(CLI::Range(-30.0f, 30.0f))
      ->capture_default_str();
  cmd->add_option("--atlas-on", opt->atlasOn,
                  "Where the octree is rendered into the atlas: cpu (the C++ lookup; the same "
                  "bytes on every machine), osmesa (OpenGL in software) or egl (a GPU, "
                  "headless): the scene shader's lookup run per texel (paper 4.2.3)")
      ->check(CLI::IsMember({"cpu", "osmesa", "egl"}))
      ->capture_default_str();
  cmd->add_flag("--chart-image", opt->chartImage,
                "Also write OUT-chartsN.png: each page's UV layout, one colour per chart, chart "
                "borders darker (v = 0 is the top row)");
  cmd->add_flag("-q,--quiet", opt->quiet, "Only errors");
  return [cmd, opt]() -> int { return cmd->parsed() ? runLightmap(*opt) : -1; };
}

}  // namespace lo::tool
