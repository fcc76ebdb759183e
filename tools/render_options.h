#pragma once
/// @file tools/render_options.h
/// @brief The shading flags `render` and `view` share (--interpolation,
/// --specular, --reflections, --exposure, --vdls, --emitter-lights, --shadow-map-size,
/// --half-float, --cosine-correction): one registration and one translation
/// into the renderer's parameters, so both commands draw the same picture
/// from the same flags.

#include <functional>
#include <string>

#include "lightgrid/vdl_grid.h"
#include "octree/gpu_octree.h"
#include "render/atlas_lighting.h"
#include "render/context.h"
#include "render/renderer.h"

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace lo::tool {

struct ShadingOptions {
  std::string interpolation = "on";
  std::string specular = "on";
  std::string reflections = "on";
  std::string lighting = "octree";  ///< octree | atlas
  std::string uv = "default";       ///< lightmap UVs for --lighting atlas: default | auto | texcoord1
  std::string atlasOn = "cpu";      ///< where --lighting atlas bakes: cpu | gpu (the renderer's context)
  std::string stitchSeams = "on";   ///< --lighting atlas: join the charts' seams (docs/lightmap.md)
  int supersample = 1;              ///< render: samples per pixel side (anti-aliasing)
  float exposure = 0;  ///< EV
  int vdls = kMaxVdls;
  std::string areaLights = "on";
  int emitterLights = RendererParams{}.emitterLights;
  int shadowMapSize = RendererParams{}.shadowMapSize;
  bool halfFloat = false;
  std::string texels = "compact";  ///< VDL texels: float | half | compact
  /// Adaptive leaves (GpuOctreeParams::tolerance); 0 = off. 0.1: 2.5x less GPU
  /// memory at equal irradiance error on the test scenes (docs/octree.md).
  float tolerance = 0.1f;
  /// Free-space leaves merge where their light agrees within this share
  /// (GpuOctreeParams::volumeTolerance); 0 = off.
  float freeSpaceTolerance = 0.4f;
  std::string cosineCorrection = "on";

  /// Mode, interpolation, GGX lobe and VDLs of a frame (size left at default).
  RenderParams renderParams(RenderMode mode) const;
  RendererParams rendererParams() const;
  /// The octree's texel format, within the limits of `info` when given.
  GpuOctreeParams octreeParams(const GlInfo* info = nullptr) const;
  /// --lighting, --uv, --stitch-seams, --atlas-on, with the frames' lookup
  /// settings (render/atlas_lighting.h).
  LightingParams lightingParams() const;
  /// lo::prepareLighting with lightingParams() (with --lighting atlas: the
  /// atlas baked and handed to `renderer`); prints what was baked unless
  /// `quiet`. No-op for octree.
  void prepareLighting(Renderer& renderer, const Scene& scene, const GpuOctree& octree,
                       bool quiet) const;
};

/// Registers the flags on `cmd`; `window` adds the keys that change each one
/// in the `view` window to the help text.
void addShadingOptions(CLI::App* cmd, ShadingOptions& opt, bool window);

/// "on" | "off".
CLI::Validator onOff();

/// Whether `baked` holds free-space light for the objects --add placed;
/// if not, a warning that they take the surfaces' light instead.
bool hasLightForAddedObjects(const VdlGrid& baked, const std::string& lightsPath);

/// The light of the objects --add placed: the bake's free-space light
/// (buildVolumeOctree) on `renderer`, or, when `baked` has none, a warning
/// that the objects take the surfaces' light. @throws InputError with
/// --lighting atlas (the atlas has no texels for them).
void setAddedObjectsLight(Renderer& renderer, const VdlGrid& baked, const ShadingOptions& shading,
                          const GpuOctreeParams& params, const std::string& lightsPath);

/// The Renderer's textureUploaded callback of a command that reads no texel
/// after the renderer's construction: each texture's texels freed, and the
/// pages given back, as soon as its GPU copy is made.
std::function<void(int)> freeTexelsOnUpload(Scene& scene);

}  // namespace lo::tool
