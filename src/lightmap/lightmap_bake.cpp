/// @file lightmap/lightmap_bake.cpp
/// @brief UV source choice and the CPU atlas bake behind lightmap_bake.h.

#include "lightmap/lightmap_bake.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/resources.h"

namespace lo {

UvSource parseUvSource(const std::string& name) {
  if (name == "default") return UvSource::Default;
  if (name == "auto") return UvSource::Charts;
  if (name == "texcoord1") return UvSource::Texcoord1;
  throw InputError("unknown UV source '" + name + "' (expected auto or texcoord1)");
}

std::string LightmapBake::ToString() const {
  std::ostringstream os;
  os << (fromTexcoord1 ? "TEXCOORD_1" : "automatic charts") << ": " << uvs.chartCount
     << " charts, " << atlas.pageCount << " page(s) of " << atlas.width << " x " << atlas.height
     << ", texel " << uvs.texelSize << ", utilisation " << uvs.utilisation << ", worst stretch "
     << uvs.worstStretch << "; " << atlas.coveredTexels << " texels covered, "
     << atlas.dilatedTexels << " dilated; UVs " << uvSeconds << " s, atlas " << atlasSeconds
     << " s";
  return os.str();
}

void checkAtlasMemory(const LightmapUvs& uvs, bool radiance) {
  const size_t available = availableMemoryBytes();
  const double texels = double(uvs.pageCount) * double(uvs.width) * double(uvs.height);
  const double perTexel = double(kAtlasBytesPerTexel + (radiance ? kAtlasRadianceBytesPerTexel : 0));
  const double needed = texels * perTexel;
  if (available == 0 || needed <= double(available)) return;
  std::ostringstream os;
  os << "--texel-size " << uvs.texelSize << ": the atlas is " << uvs.pageCount << " page(s) of "
     << uvs.width << " x " << uvs.height << " texels, which need about " << formatBytes(size_t(needed))
     << " (" << perTexel << " bytes per texel" << (radiance ? ", with the preview" : "")
     << "), more than the " << formatBytes(available)
     << " of memory available: use a larger --texel-size (or a smaller --atlas, when the charts "
        "leave a page mostly empty)";
  throw InputError(os.str());
}

namespace {

/// The charts of `uvs` repacked at coarser texels, each step by the root of
/// the pages over `maxPages` and a tenth more, until they fit (at most eight
/// steps: a chart takes a few texels and its gutter at any texel size, so a
/// scene of very many charts may never fit). Returns the note.
std::string capPages(LightmapCharts& charts, LightmapUvParams uv, int maxPages, LightmapUvs& uvs) {
  const float first = uv.texelSize;
  const int pages = uvs.pageCount;
  for (int step = 0; step < 8 && uvs.pageCount > maxPages; ++step) {
    uv.texelSize *= 1.1f * std::sqrt(float(uvs.pageCount) / float(maxPages));
    uvs = charts.pack(uv);
  }
  std::ostringstream os;
  os << "lightmap atlas: texel " << uvs.texelSize << ", not the default " << first
     << " (a quarter voxel), which would take " << pages << " pages of " << uv.atlasSize << " x "
     << uv.atlasSize << "; at most " << maxPages << " are drawn"
     << (uvs.pageCount > maxPages
             ? " (" + std::to_string(uvs.pageCount) + " still: the scene has too many charts)"
             : std::string())
     << ". `lightmap --texel-size` bakes finer pages";
  return os.str();
}

}  // namespace

float defaultLightmapTexel(const GpuOctree& octree) {
  return 0.25f * octree.cubeSize / float(1 << std::max(octree.depth, 0));
}

LightmapBake bakeLightmap(const Scene& scene, const GpuOctree& octree,
                          const LightmapParams& params) {
  using Clock = std::chrono::steady_clock;
  LightmapBake out;
  const auto start = Clock::now();
  std::optional<Progress> uvStep(std::in_place, params.progress, "lightmap: UVs", 1);
  const bool hasTexcoord1 = scene.texcoords1.size() == 2 * scene.positions.size() &&
                            !scene.texcoords1.empty();
  const bool useTexcoord1 = params.uvSource == UvSource::Texcoord1 ||
                            (params.uvSource == UvSource::Default && hasTexcoord1);
  if (useTexcoord1) {
    try {
      out.uvs = lightmapUvsFromTexcoord1(scene, params.uv.atlasSize);
    } catch (const InputError& e) {
      throw InputError(std::string("TEXCOORD_1 cannot serve as lightmap UVs: ") + e.what() +
                       " (use --uv auto for automatic charts)");
    }
    out.fromTexcoord1 = true;
  } else if (params.uv.texelSize > 0) {
    out.uvs = buildLightmapUvs(scene, params.uv);
  } else {
    // A quarter voxel per texel, on the smallest page that holds it: from
    // the charts' area in texels over a fill of about 70%, grown by a
    // quarter (rounded to 16 texels) while the charts take more than one
    // page.
    LightmapUvParams uv = params.uv;
    uv.texelSize = defaultLightmapTexel(octree);
    double area = 0;
    for (size_t t = 0; t < scene.triangleCount(); ++t) area += scene.triangleArea(t);
    const double texels = area / (double(uv.texelSize) * uv.texelSize) / 0.7;
    auto grow = [](int s) { return (s + s / 4 + 15) / 16 * 16; };
    int size = 64;
    while (size < params.uv.atlasSize && double(size) * size < texels) size = grow(size);
    // The charts are cut and flattened once; each size only packs them.
    LightmapCharts charts(scene, uv);
    for (;; size = grow(size)) {
      uv.atlasSize = std::min(size, params.uv.atlasSize);
      // A size whose page cannot hold the charts' area is passed over: its
      // packing would only say so.
      if (uv.atlasSize < params.uv.atlasSize && charts.exceedsOnePage(uv)) continue;
      out.uvs = charts.pack(uv);
      if (out.uvs.pageCount <= 1 || uv.atlasSize >= params.uv.atlasSize) break;
    }
    if (params.maxPages > 0 && out.uvs.pageCount > params.maxPages) {
      out.note = capPages(charts, uv, params.maxPages, out.uvs);
    }
  }
  const auto uvDone = Clock::now();
  uvStep.reset();
  checkAtlasMemory(out.uvs, params.atlas.radiance);
  AtlasBakeParams atlas = params.atlas;
  if (!atlas.progress) atlas.progress = params.progress;
  out.atlas = bakeLightmapAtlas(scene, out.uvs, octree, atlas);
  out.uvSeconds = std::chrono::duration<double>(uvDone - start).count();
  out.atlasSeconds = std::chrono::duration<double>(Clock::now() - uvDone).count();
  return out;
}

}  // namespace lo
