#include "render/render_session.h"

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

RenderParams renderFrameDefaults() {
  RenderParams p;
  p.supersample = 2;
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

void setTexels(GpuOctreeParams& octree, const std::string& name) {
  if (name != "float" && name != "half" && name != "compact") {
    throw InputError("texels '" + name + "': expected float, half or compact");
  }
  octree.halfFloat = name == "half";
  octree.compact = name == "compact";
}

void RenderSettings::check() const {
  auto range = [](const char* name, double value, double lo, double hi) {
    if (!(value >= lo && value <= hi)) {  // NaN fails too
      throw InputError(std::string(name) + " " + std::to_string(value) + ": must be " +
                       std::to_string(lo) + ".." + std::to_string(hi));
    }
  };
  range("width", frame.width, 1, kMaxImageSide);
  range("height", frame.height, 1, kMaxImageSide);
  range("supersample", frame.supersample, 1, kMaxSupersample);
  range("vdls", frame.maxVdls, 1, kMaxVdls);
  range("emitter lights", renderer.emitterLights, 0, kMaxEmitterLights);
  range("shadow map size", renderer.shadowMapSize, kMinShadowMapSize, kMaxShadowMapSize);
  range("tolerance", octree.tolerance, 0, 1);
  range("free-space tolerance", octree.volumeTolerance, 0, 1);
  checkRenderMemory(frame);
}

GpuOctree buildRenderOctree(const VdlGrid& grid, const RenderSettings& settings) {
  return buildGpuOctree(grid, settings.octreeParams());
}

namespace {

/// The surfaces' octree of `grid` (none for an empty grid) and, when the
/// scene has objects added after the bake, the free-space light's, or a
/// warning naming the grid that it has none.
LookupOctrees buildOctrees(const Scene& scene, const VdlGrid& grid, const GpuOctreeParams& params,
                           const std::string& gridName) {
  LookupOctrees r;
  if (grid.size() == 0) return r;
  r.surface = buildGpuOctree(grid, params);
  if (scene.hasAddedObjects()) {
    if (!grid.volume.empty()) {
      r.volume = buildVolumeOctree(grid.volume, params);
    } else {
      r.warnings.push_back(gridName +
                           " holds no free-space light (baked with --free-space off, or by an "
                           "older lightoctree): the added objects take the light of the surfaces "
                           "near them");
    }
  }
  return r;
}

}  // namespace

LookupOctrees buildLookupOctrees(const Scene& scene, const VdlGrid& grid,
                                 const RenderSettings& settings, const std::string& gridName) {
  return buildOctrees(scene, grid, settings.octreeParams(), gridName);
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
  settings.check();
  const bool added = scene.hasAddedObjects();
  if (added && settings.frame.lighting == Lighting::Atlas) {
    throw InputError("--add: not with --lighting atlas (the atlas holds the baked surfaces' light "
                     "only); added objects are lit by the octree's free-space light");
  }

  Progress setup(options.progress, "render: set-up", 4);
  StageTimer octreeTimer(s.stages, "octree");
  // The free-space light of the added objects is built now too, so that the
  // grid can go before the renderer's uploads.
  LookupOctrees octrees = buildOctrees(scene, grid, settings.octreeParams(&s.limits), options.gridName);
  grid = VdlGrid{};  // the octrees hold all the renderer reads of it
  returnFreeMemory();
  s.octree = std::move(octrees.surface);
  s.warnings = std::move(octrees.warnings);
  s.octreeSummary = s.octree.ToString();
  s.octreeDepth = s.octree.depth;
  octreeTimer.finish("");
  setup.advance();

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
  if (!s.renderer->shadowMapNote().empty()) s.warnings.push_back(s.renderer->shadowMapNote());
  setup.advance();
  if (options.freeTexels) {
    scene.releaseTexels();  // those no material draws with
    returnFreeMemory();
  }
  if (added) {
    StageTimer volumeTimer(s.stages, "free-space light");
    const bool volume = octrees.volume.depth > 0;
    if (volume) s.renderer->setFreeSpaceLight(octrees.volume);
    octrees.volume = GpuOctree();
    volumeTimer.finish(volume ? "for the added objects" : "none in the bake");
  }
  setup.advance();
  StageTimer lightingTimer(s.stages, "prepare lighting");
  LightingParams lighting = settings.lightingParams();
  lighting.progress = options.progress;
  const std::optional<LightmapBake> atlas = prepareLighting(*s.renderer, scene, s.octree, lighting);
  if (atlas) {
    s.atlasSummary = atlas->ToString() + "; " + formatBytes(s.renderer->atlasBytes()) + " on the GPU";
    if (!atlas->note.empty()) s.warnings.push_back(atlas->note);
  }
  lightingTimer.finish(atlas ? "lightmap atlas" : "");
  setup.advance();
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
  return impl_->renderer->render(camera, frame(mode), impl_->options.progress);
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
