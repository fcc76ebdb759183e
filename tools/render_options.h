#pragma once
/// @file tools/render_options.h
/// @brief The shading flags `render` and `view` share (--interpolation,
/// --specular, --reflections, --exposure, --vdls, --emitter-lights, --shadow-map-size,
/// --texels, --cosine-correction, ...): one registration and one mapping onto
/// the library's RenderSettings, whose defaults they show, so both commands
/// draw the same picture from the same flags as the Python module does.

#include <string>
#include <vector>

#include "render/render_session.h"

namespace CLI {
class App;
class Validator;
}  // namespace CLI

namespace lo::tool {

inline std::string onOffOf(bool on) { return on ? "on" : "off"; }

/// The library's defaults, which the flags show.
inline const RenderSettings kRenderDefaults{};


/// The flags as text ("on" | "off", names), their defaults the library's
/// (kRenderDefaults), so that the command line and Python agree.
struct ShadingOptions {
  std::string interpolation = onOffOf(kRenderDefaults.frame.interpolation);
  std::string specular = onOffOf(kRenderDefaults.frame.specular);
  std::string reflections = onOffOf(kRenderDefaults.frame.reflections);
  std::string lighting = toString(kRenderDefaults.frame.lighting);  ///< octree | atlas
  std::string uv = "default";       ///< lightmap UVs for --lighting atlas: default | auto | texcoord1
  std::string atlasOn = kRenderDefaults.atlasOnGpu ? "gpu" : "cpu";  ///< where --lighting atlas bakes
  std::string stitchSeams = onOffOf(kRenderDefaults.stitchSeams);  ///< join the charts' seams
  int supersample = kRenderDefaults.frame.supersample;  ///< render: samples per pixel side
  float exposure = 0;  ///< EV (view; render's is picture_options.h's)
  int vdls = kRenderDefaults.frame.maxVdls;
  std::string areaLights = onOffOf(kRenderDefaults.renderer.areaLights);
  int emitterLights = kRenderDefaults.renderer.emitterLights;
  int shadowMapSize = kRenderDefaults.renderer.shadowMapSize;
  bool halfFloat = false;
  std::string texels = "compact";  ///< VDL texels: float | half | compact
  /// Adaptive leaves (GpuOctreeParams::tolerance); 0 = off.
  float tolerance = kRenderDefaults.octree.tolerance;
  /// Free-space leaves merge where their light agrees within this share
  /// (GpuOctreeParams::volumeTolerance); 0 = off.
  float freeSpaceTolerance = kRenderDefaults.octree.volumeTolerance;
  std::string cosineCorrection = onOffOf(kRenderDefaults.octree.cosineCorrection);

  /// The library's settings these flags select (render/render_session.h),
  /// frames at `mode` of width x height.
  RenderSettings settings(RenderMode mode, int width, int height) const;
};

/// Registers the flags on `cmd`; `window` adds the keys that change each one
/// in the `view` window to the help text.
void addShadingOptions(CLI::App* cmd, ShadingOptions& opt, bool window);

/// "on" | "off".
CLI::Validator onOff();

/// Prints a session's (or the lookup octrees') warnings, "warning: ..." on
/// stderr.
void printWarnings(const std::vector<std::string>& warnings);

}  // namespace lo::tool
