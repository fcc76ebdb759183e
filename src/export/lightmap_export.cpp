#include "export/lightmap_export.h"

#include <algorithm>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>

#include "bake/bake.h"
#include "core/error.h"
#include "core/file.h"
#include "core/file_set.h"
#include "core/printable.h"
#include "image/image.h"
#include "octree/gpu_octree.h"
#include "reference/path_tracer.h"
#include "render/atlas_gpu.h"
#include "scene/gltf_export.h"
#include "vdb/vdb_io.h"

namespace lo {

namespace fs = std::filesystem;

namespace lightmap_export_internal {

/// RGBM's range: the next power of two at or above the brightest texel, so
/// the pages use the 8 bits they have (recorded in the extras).
float rgbmRangeFor(const std::vector<RgbImage>& pages) {
  float brightest = 0;
  for (const RgbImage& page : pages)
    for (float v : page.rgb)
      if (std::isfinite(v)) brightest = std::max(brightest, v);
  return brightest > 0 ? std::exp2(std::ceil(std::log2(brightest))) : 1.0f;
}

/// D/OUT<suffix> for output D/OUT.glb or .gltf.
/// A page as it is written: the stitch's least-squares fit leaves small
/// negative values in gutter texels (dilated, not covered; clamping them in
/// the atlas would open its seams again), which no irradiance is; the files
/// hold them as 0 (the RGBM encoding clamps them too, and GL's RGB9_E5).
RgbImage nonNegative(RgbImage page) {
  for (float& v : page.rgb) v = v > 0 ? v : 0.0f;  // NaN to 0 as well
  return page;
}

std::string besideOutput(const std::string& output, const std::string& suffix) {
  const fs::path out(output);
  return (out.parent_path() / (out.stem().string() + suffix)).string();
}

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

/// Marks for removal at `set`'s commit the files beside `output` named like
/// its numbered outputs (OUT-lightmapN.exr|png, OUT-directionN.png,
/// OUT-chartsN.png) that the set does not write.
/// What numbered output of the export to `stem` the file `name` is named
/// like: "lightmap pages" (STEM-lightmapN.exr|png), "direction pages"
/// (STEM-directionN.png), "chart images" (STEM-chartsN.png), or null.
const char* numberedOutputKind(const std::string& name, const std::string& stem) {
  auto numbered = [&](const std::string& head, const std::string& tail) {
    const std::string prefix = stem + head;
    if (name.size() <= prefix.size() + tail.size() || name.compare(0, prefix.size(), prefix) != 0 ||
        name.compare(name.size() - tail.size(), tail.size(), tail) != 0) {
      return false;
    }
    for (size_t i = prefix.size(); i < name.size() - tail.size(); ++i) {
      if (name[i] < '0' || name[i] > '9') return false;
    }
    return true;
  };
  if (numbered("-lightmap", ".exr") || numbered("-lightmap", ".png")) return "lightmap pages";
  if (numbered("-direction", ".png")) return "direction pages";
  if (numbered("-charts", ".png")) return "chart images";
  return nullptr;
}

void removeStaleSiblings(const std::string& output, AtomicFileSet& set) {
  const fs::path out(output);
  const fs::path folder = out.parent_path().empty() ? fs::path(".") : out.parent_path();
  const std::string stem = out.stem().string();
  const std::vector<std::string> written = set.paths();
  std::error_code ec;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (!numberedOutputKind(name, stem)) continue;
    const std::string path = (out.parent_path() / name).string();
    if (std::find(written.begin(), written.end(), path) == written.end()) set.removeOnCommit(path);
  }
}

/// The export, its octree made by `makeOctree` in the "octree" row.
LightmapExportResult exportWith(const Scene& scene, const std::function<GpuOctree()>& makeOctree,
                                const LightmapExportParams& params) {
  checkLightmapExportPath(params.output);
  LightmapExportResult result;
  result.output = params.output;
  std::vector<StageReport>& rows = result.stages;

  // One task per step, so that a sink may stop the export between them
  // (LightmapExportParams::progress); replaced by the next step's.
  std::optional<Progress> step(std::in_place, params.progress, "lightmap: octree", 1);
  StageTimer octreeTimer(rows, "octree");
  const GpuOctree octree = makeOctree();
  result.octreeLeaves = octree.leafCount;
  result.octreePoolBytes = octree.poolBytes();
  result.octreeVdlBytes = octree.vdlBytes();
  octreeTimer.finish(formatCount(octree.leafCount) + " leaves, " +
                     formatBytes(octree.poolBytes() + octree.vdlBytes()));

  LightmapParams bake = params.lightmap;
  bake.atlas.radiance = params.preview;  // the preview's base colour
  // AtlasContent::Full: the direct light by the path tracer's own light
  // sampling (src/reference), handed to the atlas bake as a function so
  // that the lightmap stage links no ray tracer.
  std::unique_ptr<DirectIrradiance> direct;
  if (params.content == AtlasContent::Full) {
    direct = std::make_unique<DirectIrradiance>(scene);
    bake.atlas.directLight = [&direct, samples = params.directSamples](
                                 const std::vector<AtlasSurfacePoint>& texels, int page,
                                 const std::function<void()>& alive) {
      std::vector<DirectIrradiance::Point> points(texels.size());
      for (size_t i = 0; i < texels.size(); ++i) {
        points[i] = {texels[i].position, texels[i].triangle, texels[i].normal};
      }
      return direct->atMany(points, samples, /*seed=*/1, uint64_t(page) << 32, alive);
    };
  }
  // The octree rendered into the atlas by GL (render/atlas_gpu.h) in a
  // headless context of the kind asked for.
  std::unique_ptr<GlContext> context;
  std::unique_ptr<GpuAtlasEvaluator> gpu;
  if (params.atlasGl) {
    GlContextParams contextParams;
    contextParams.backend = *params.atlasGl;
    context = createGlContext(contextParams);
    result.glInfo = context->info().ToString();
    gpu = std::make_unique<GpuAtlasEvaluator>();
    bake.atlas.evaluator = gpu.get();
  }
  // The UVs and the atlas report their own steps ("lightmap: UVs", "lightmap:
  // atlas": each row of texels), where a sink may stop them.
  step.reset();
  bake.progress = params.progress;
  result.lightmap = bakeLightmap(scene, octree, bake);
  const LightmapUvs& uvs = result.lightmap.uvs;
  const LightmapAtlas& atlas = result.lightmap.atlas;
  addRow(rows, "UVs", result.lightmap.uvSeconds,
         std::string(result.lightmap.fromTexcoord1 ? "TEXCOORD_1, " : "automatic, ") +
             formatCount(size_t(uvs.chartCount)) + " charts");
  addRow(rows, "atlas: raster", atlas.rasterSeconds,
         formatCount(atlas.coveredTexels) + " covered texels");
  addRow(rows, "atlas: evaluate", atlas.evaluateSeconds,
         params.preview ? "irradiance and radiance" : "irradiance");
  addRow(
      rows, "atlas: dilate", atlas.dilateSeconds,
      formatCount(atlas.dilatedTexels) + " texels, " + std::to_string(atlas.dilation) + " rings");
  addRow(rows, "atlas: stitch", atlas.stitchSeconds,
         formatCount(atlas.seamEdges) + " seam edges, mismatch " +
             formatNumber(atlas.seamMismatchBefore) + " -> " +
             formatNumber(atlas.seamMismatchAfter) + " W/m^2");

  // Everything is encoded in memory first; the files are written last.
  step.emplace(params.progress, "lightmap: encode", 1);
  StageTimer encodeTimer(rows, "encode");
  LightmapExport ex;
  ex.uv = uvs.uv;
  ex.trianglePage = uvs.trianglePage;
  ex.width = atlas.width;
  ex.height = atlas.height;
  ex.content = toString(params.content);
  ex.encoding = params.rgbm ? "rgbm-png" : "linear-exr";
  std::vector<std::string> rgbmPages;
  if (params.rgbm) {
    ex.rgbmRange = rgbmRangeFor(atlas.irradiance);
    result.rgbmRange = ex.rgbmRange;
    for (const RgbImage& page : atlas.irradiance) {
      const std::vector<unsigned char> png = encodeRgbmPng(page, ex.rgbmRange);
      rgbmPages.emplace_back(png.begin(), png.end());
    }
  }
  for (int p = 0; p < atlas.pageCount; ++p) {
    result.pagePaths.push_back(lightmapPagePath(params.output, p, params.rgbm));
    ex.pageUris.push_back(fs::path(result.pagePaths.back()).filename().string());
  }
  std::vector<std::vector<unsigned char>> directionPngs;
  // With the direct light in E (content full) the direction would describe
  // only its indirect part: no direction pages then.
  if (params.directionPages && params.content == AtlasContent::Indirect) {
    for (int p = 0; p < atlas.pageCount; ++p) {
      result.directionPaths.push_back(lightmapDirectionPath(params.output, p));
      ex.directionUris.push_back(fs::path(result.directionPaths.back()).filename().string());
      directionPngs.push_back(encodeUnitVectorPng(atlas.direction[size_t(p)]));
    }
  }
  const GltfFiles lit = encodeLightmapGltf(scene, ex, params.output);
  GltfFiles unlit;
  if (params.preview) {
    result.previewPath = besideOutput(params.output, "-preview.glb");
    LightmapExport preview = ex;
    preview.unlit = true;
    preview.previewExposureEv = params.previewExposureEv;
    for (const RgbImage& page : atlas.radiance)
      preview.previewPng.push_back(encodePng(page, params.previewExposureEv));
    unlit = encodeLightmapGltf(scene, preview, result.previewPath);
  }
  result.outputBytes = lit.gltf.size() + lit.bin.size();
  result.previewBytes = unlit.gltf.size();
  encodeTimer.finish(ex.encoding + (params.preview ? " + unlit preview" : ""));

  StageTimer writeTimer(rows, "write");
  // The whole set appears at once, or nothing does: every file goes to its
  // temporary name first, and a failure (a link planted at the preview's
  // name, a full disk, a signal, a sink that stops it) leaves an earlier
  // run's set as it was. A step per file, and the commit's: the last report
  // that may stop the export comes after the last file, before the renames.
  step.reset();
  const size_t files = size_t(atlas.pageCount) + directionPngs.size() + 1 +
                       (params.preview ? 1 : 0) + (params.chartImages ? size_t(uvs.pageCount) : 0);
  Progress written(params.progress, "lightmap: write", files + 1);  // the glTF and its .bin: one
  AtomicFileSet set;
  for (int p = 0; p < atlas.pageCount; ++p) {
    const std::string& path = result.pagePaths[size_t(p)];
    if (params.rgbm) {
      set.addText(path, rgbmPages[size_t(p)]);
    } else {
      writeExr(path, nonNegative(atlas.irradiance[size_t(p)]), &set);
    }
    result.pageFileBytes += size_t(set.bytesOf(path));
    written.advance();
  }
  for (size_t p = 0; p < directionPngs.size(); ++p) {
    const std::string& path = result.directionPaths[p];
    set.addText(path, std::string(directionPngs[p].begin(), directionPngs[p].end()));
    result.pageFileBytes += size_t(set.bytesOf(path));
    written.advance();
  }
  writeGltfFiles(lit, params.output, &set);
  written.advance();
  if (params.preview) {
    writeGltfFiles(unlit, result.previewPath, &set);
    written.advance();
  }
  if (params.chartImages) {
    for (int p = 0; p < uvs.pageCount; ++p) {
      result.chartPaths.push_back(besideOutput(params.output, "-charts" + std::to_string(p) + ".png"));
      const std::vector<uint8_t> png = encodePng(chartLayoutImage(uvs, p));
      set.addText(result.chartPaths.back(), std::string(png.begin(), png.end()));
      written.advance();
    }
  }
  // Numbered files an earlier export left beside OUT that this one does not
  // write (more pages, the other page image, direction pages, chart images)
  // go with the commit, so the folder holds one set.
  removeStaleSiblings(params.output, set);
  if (params.beforeCommit) params.beforeCommit(result, set);
  set.commit();
  written.advance();
  writeTimer.finish(formatCount(size_t(atlas.pageCount) + result.directionPaths.size() + 1 +
                                (params.preview ? 1 : 0) + result.chartPaths.size()) +
                    " files");
  return result;
}

/// printf's `format` of the arguments, appended to `text`.
#if defined(__GNUC__)
__attribute__((format(printf, 2, 3)))
#endif
void appendf(std::string& text, const char* format, ...) {
  va_list args;
  va_start(args, format);
  va_list again;
  va_copy(again, args);
  const int size = std::vsnprintf(nullptr, 0, format, args);
  va_end(args);
  if (size > 0) {
    const size_t at = text.size();
    text.resize(at + size_t(size) + 1);
    std::vsnprintf(&text[at], size_t(size) + 1, format, again);
    text.resize(at + size_t(size));
  }
  va_end(again);
}

}  // namespace lightmap_export_internal

AtlasContent parseAtlasContent(const std::string& name) {
  if (name == "indirect") return AtlasContent::Indirect;
  if (name == "full") return AtlasContent::Full;
  throw InputError("--content: '" + name + "' (expected indirect or full)");
}

bool directionPagesOf(const std::string& directions, AtlasContent content,
                      const std::string& flag) {
  if (directions != "" && directions != "on" && directions != "off") {
    throw InputError(flag + ": '" + printableShort(directions) + "' (expected on or off)");
  }
  if (directions == "on" && content == AtlasContent::Full) {
    throw InputError(flag +
                     " on: a lightmap of the full light writes no direction pages (its "
                     "light comes from other directions than a page would give): leave " +
                     flag + " out, or export the indirect light");
  }
  return directions != "off" && content == AtlasContent::Indirect;
}

const char* toString(AtlasContent content) {
  return content == AtlasContent::Full ? "full" : "indirect";
}

void checkLightmapExportPath(const std::string& output, const char* flag) {
  checkOutputExtension(output, flag, {".glb", ".gltf"});
}

void checkLightmapOutputs(const std::string& output, bool preview, const NamedPaths& inputs) {
  using lightmap_export_internal::besideOutput;
  NamedPaths outputs{{"--output", output}};
  if (hasExtension(output, ".gltf")) outputs.push_back({"--output's buffer", besideOutput(output, ".bin")});
  if (preview) outputs.push_back({"--preview-unlit", besideOutput(output, "-preview.glb")});
  checkDistinctFiles(outputs, inputs);
  // The longest name the set writes (up to 1,000 pages) must fit the file
  // system's limit, found now and not after the bake.
  checkOutputName(besideOutput(output, "-direction999.png"), "--output");
  // The numbered outputs: pages, direction pages, chart images. Every
  // numbered name, whatever this export writes: it replaces them, or removes
  // those an earlier export left (removeStaleSiblings).
  const std::string stem = fs::path(output).stem().string();
  checkFolderOutputs(
      fs::path(output).parent_path().string(),
      [&](const std::string& name) -> std::string {
        const char* kind = lightmap_export_internal::numberedOutputKind(name, stem);
        return kind ? std::string(kind) + " of '" + output + "'" : std::string();
      },
      "--output", inputs);
}

std::string lightmapPagePath(const std::string& output, int page, bool rgbm) {
  return lightmap_export_internal::besideOutput(
      output, "-lightmap" + std::to_string(page) + (rgbm ? ".png" : ".exr"));
}

std::string lightmapDirectionPath(const std::string& output, int page) {
  return lightmap_export_internal::besideOutput(output, "-direction" + std::to_string(page) + ".png");
}

LightmapExportResult exportLightmap(const Scene& scene, const VdlGrid& grid,
                                    const LightmapExportParams& params) {
  // The renderer's octree (cosine correction on, float VDLs): GpuOctreeParams'
  // defaults, as `render` builds it, so that the atlas holds what the
  // renderer would compute.
  return lightmap_export_internal::exportWith(
      scene, [&grid] { return buildGpuOctree(grid, GpuOctreeParams{}); }, params);
}

LightmapExportResult exportLightmap(const Scene& scene, const std::string& lightsPath,
                                    const LightmapExportParams& params) {
  BakeMetadata meta;
  LightmapExportResult result = lightmap_export_internal::exportWith(
      scene,
      [&lightsPath, &scene, &meta, &params] {
        LoadedVdl loaded = readVdlGrid(lightsPath, scene.origin);
        meta = std::move(loaded.meta);
        if (params.warn) {
          std::vector<std::string> warnings = gridWarnings(meta, scene);
          if (params.content == AtlasContent::Full) {
            warnings.push_back(
                directTwiceWarning(meta, "--content full", "use --content indirect"));
          }
          for (const std::string& w : warnings) {
            if (!w.empty()) params.warn(lightsPath + ": " + w);
          }
        }
        return buildGpuOctree(loaded.grid, GpuOctreeParams{});
      },
      params);
  result.gridMetadata = std::move(meta);
  return result;
}

std::string lightmapExportSummary(const LightmapExportResult& r,
                                  const LightmapExportParams& params) {
  using lightmap_export_internal::appendf;
  const LightmapUvs& uvs = r.lightmap.uvs;
  const LightmapAtlas& atlas = r.lightmap.atlas;
  const size_t texels = size_t(atlas.width) * size_t(atlas.height) * size_t(atlas.pageCount);
  std::string text;
  appendf(text,
          "UVs: %s, %d charts, %d page(s) of %d x %d, utilisation %.3f, worst stretch %.3f, "
          "texel %s scene units\n",
          r.lightmap.fromTexcoord1 ? "TEXCOORD_1" : "automatic charts", uvs.chartCount,
          uvs.pageCount, uvs.width, uvs.height, double(uvs.utilisation), double(uvs.worstStretch),
          formatNumber(uvs.texelSize).c_str());
  appendf(text, "atlas: %s covered + %s dilated texels of %s; seams %s -> %s W/m^2\n",
          formatCount(atlas.coveredTexels).c_str(), formatCount(atlas.dilatedTexels).c_str(),
          formatCount(texels).c_str(), formatNumber(atlas.seamMismatchBefore).c_str(),
          formatNumber(atlas.seamMismatchAfter).c_str());
  // Atlas memory: RGB32F is 12 bytes a texel, RGBM8 4.
  appendf(text,
          "memory: atlas %s as RGB32F textures (%s as RGBM8), %s in files; octree %s "
          "(pool %s + VDLs %s)\n",
          formatBytes(texels * 12).c_str(), formatBytes(texels * 4).c_str(),
          formatBytes(r.pageFileBytes).c_str(),
          formatBytes(r.octreePoolBytes + r.octreeVdlBytes).c_str(),
          formatBytes(r.octreePoolBytes).c_str(), formatBytes(r.octreeVdlBytes).c_str());
  if (params.rgbm) appendf(text, "RGBM range: %s W/m^2\n", formatNumber(r.rgbmRange).c_str());
  for (const std::string& path : r.pagePaths) appendf(text, "wrote %s\n", path.c_str());
  for (const std::string& path : r.directionPaths) {
    appendf(text, "wrote %s (directions)\n", path.c_str());
  }
  appendf(text, "wrote %s (%s)\n", r.output.c_str(), formatBytes(r.outputBytes).c_str());
  if (params.preview) {
    appendf(text, "wrote %s (%s, unlit preview)\n", r.previewPath.c_str(),
            formatBytes(r.previewBytes).c_str());
  }
  for (const std::string& path : r.chartPaths)
    appendf(text, "wrote %s (chart layout)\n", path.c_str());
  return text;
}

}  // namespace lo
