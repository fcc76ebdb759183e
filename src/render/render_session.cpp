#include "render/render_session.h"

#include <cstdio>
#include <optional>

#include "core/error.h"

namespace lo {

GpuOctreeParams renderOctreeDefaults() {
  GpuOctreeParams p;
  p.compact = true;
  p.tolerance = 0.1f;
  p.volumeTolerance = 0.4f;
  return p;
}

GpuOctreeParams RenderSettings::octreeParams(const GlInfo* limits) const {
  GpuOctreeParams p = octree;
  if (limits) {
    p.max3DTextureSize = limits->max3DTextureSize;
    p.max2DTextureSize = limits->max2DTextureSize;
  }
  return p;
}

LightingParams RenderSettings::lightingParams() const {
  LightingParams p;
  p.lighting = frame.lighting;
  p.uvSource = uvSource;
  p.shade = shadeParamsOf(frame);
  p.stitchSeams = stitchSeams;
  p.atlasOnGpu = atlasOnGpu;
  return p;
}

GpuOctree buildRenderOctree(const VdlGrid& grid, const RenderSettings& settings) {
  return buildGpuOctree(grid, settings.octreeParams());
}

namespace {

bool hasAddedObjects(const Scene& scene) {
  return scene.movingMaterialsFrom < scene.materials.size();
}

std::string noFreeSpaceLight(const std::string& gridName) {
  return gridName +
         " holds no free-space light (baked with --free-space off, or by an older lightoctree): "
         "the added objects take the light of the surfaces near them";
}

}  // namespace

LookupOctrees buildLookupOctrees(const Scene& scene, const VdlGrid& grid,
                                 const RenderSettings& settings, const std::string& gridName) {
  LookupOctrees r;
  r.surface = buildGpuOctree(grid, settings.octreeParams());
  if (hasAddedObjects(scene)) {
    if (!grid.volume.empty()) {
      r.volume = buildVolumeOctree(grid.volume, settings.octreeParams());
    } else {
      r.warnings.push_back(noFreeSpaceLight(gridName));
    }
  }
  return r;
}

struct RenderSession::Impl {
  RenderSettings settings;
  RenderSessionOptions options;
  GlInfo limits;
  GpuOctree octree;
  std::unique_ptr<Renderer> renderer;
  std::vector<StageReport> stages;
  std::vector<std::string> warnings;
  std::string octreeSummary, atlasSummary;
  int octreeDepth = 0;
  std::optional<LightmapBake> atlas;
};

RenderSession::RenderSession(Scene& scene, VdlGrid grid, const GlContext& context,
                             const RenderSettings& settings, const RenderSessionOptions& options)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.settings = settings;
  s.options = options;
  s.limits = context.info();
  const bool added = hasAddedObjects(scene);
  if (added && settings.frame.lighting == Lighting::Atlas) {
    throw InputError("--add: not with --lighting atlas (the atlas holds the baked surfaces' light "
                     "only); added objects are lit by the octree's free-space light");
  }
  const GpuOctreeParams octreeParams = settings.octreeParams(&s.limits);

  StageTimer octreeTimer(s.stages, "octree");
  if (grid.size() > 0) s.octree = buildGpuOctree(grid, octreeParams);
  // The free-space light of the objects added after the bake: built now so
  // that the grid can go before the renderer's uploads.
  std::optional<GpuOctree> volume;
  if (added) {
    if (!grid.volume.empty()) {
      volume = buildVolumeOctree(grid.volume, octreeParams);
    } else if (grid.size() > 0) {
      s.warnings.push_back(noFreeSpaceLight(options.gridName));
    }
  }
  grid = VdlGrid{};  // the octrees hold all the renderer reads of it
  returnFreeMemory();
  s.octreeSummary = s.octree.ToString();
  s.octreeDepth = s.octree.depth;
  octreeTimer.finish("");

  std::function<void(int)> textureUploaded;
  if (options.freeTexels) {
    textureUploaded = [&scene](int texture) {
      scene.releaseTexels(size_t(texture));
      returnFreeMemory();
    };
  }
  s.renderer = std::make_unique<Renderer>(scene, s.octree, settings.renderer, textureUploaded);
  s.stages.insert(s.stages.end(), s.renderer->startupStages().begin(),
                  s.renderer->startupStages().end());
  if (options.freeTexels) {
    scene.releaseTexels();  // those no material draws with
    returnFreeMemory();
  }
  if (added) {
    StageTimer volumeTimer(s.stages, "free-space light");
    if (volume) s.renderer->setFreeSpaceLight(*volume);
    volumeTimer.finish(volume ? "for the added objects" : "none in the bake");
  }
  StageTimer lightingTimer(s.stages, "prepare lighting");
  const std::optional<LightmapBake> atlas =
      prepareLighting(*s.renderer, scene, s.octree, settings.lightingParams());
  if (atlas) {
    char bytes[64];
    std::snprintf(bytes, sizeof bytes, "; %.1f MiB on the GPU",
                  double(s.renderer->atlasBytes()) / (1024.0 * 1024.0));
    s.atlasSummary = atlas->ToString() + bytes;
  }
  lightingTimer.finish(atlas ? "lightmap atlas" : "");
  if (options.keepOctree) {
    s.atlas = atlas;
  } else {
    s.octree = GpuOctree();  // uploaded; the CPU copy is not needed any more
    returnFreeMemory();
  }
}

RenderSession::~RenderSession() = default;

Renderer& RenderSession::renderer() { return *impl_->renderer; }
const RenderSettings& RenderSession::settings() const { return impl_->settings; }
const LightmapBake* RenderSession::atlas() const { return impl_->atlas ? &*impl_->atlas : nullptr; }
int RenderSession::octreeDepth() const { return impl_->octreeDepth; }
const GpuOctree& RenderSession::octree() const { return impl_->octree; }
const std::vector<StageReport>& RenderSession::stages() const { return impl_->stages; }
std::string RenderSession::octreeSummary() const { return impl_->octreeSummary; }
std::string RenderSession::atlasSummary() const { return impl_->atlasSummary; }
const std::vector<std::string>& RenderSession::warnings() const { return impl_->warnings; }

RenderParams RenderSession::frame(RenderMode mode) const {
  RenderParams p = impl_->settings.frame;
  p.mode = mode;
  return p;
}

RgbImage RenderSession::render(const PinholeCamera& camera, RenderMode mode) {
  return impl_->renderer->render(camera, frame(mode));
}

void RenderSession::setGrid(const VdlGrid& grid, const GpuOctreeParams& octree) {
  Impl& s = *impl_;
  s.settings.octree = octree;
  GpuOctree built = buildGpuOctree(grid, s.settings.octreeParams(&s.limits));
  s.renderer->setOctree(built);
  s.octreeSummary = built.ToString();
  s.octreeDepth = built.depth;
  if (s.options.keepOctree) s.octree = std::move(built);
}

}  // namespace lo
