#include "render_options.h"

#include <CLI/CLI.hpp>
#include <cstdio>

#include "cli_checks.h"
#include "core/error.h"
#include "lightmap/lightmap_bake.h"
#include "report.h"

namespace lo::tool {

RenderSettings ShadingOptions::settings(RenderMode mode, int width, int height) const {
  RenderSettings s;
  s.frame.mode = mode;
  s.frame.width = width;
  s.frame.height = height;
  s.frame.interpolation = interpolation == "on";
  s.frame.specular = specular == "on";
  s.frame.reflections = reflections == "on";
  s.frame.lighting = parseLighting(lighting);
  s.frame.supersample = supersample;
  s.frame.maxVdls = vdls;
  s.renderer.areaLights = areaLights == "on";
  s.renderer.emitterLights = emitterLights;
  s.renderer.shadowMapSize = shadowMapSize;
  setTexels(s.octree, halfFloat ? "half" : texels);
  s.octree.cosineCorrection = cosineCorrection == "on";
  s.octree.tolerance = tolerance;
  s.octree.volumeTolerance = freeSpaceTolerance;
  s.uvSource = parseUvSource(uv);
  s.stitchSeams = stitchSeams == "on";
  s.atlasOnGpu = atlasOn == "gpu";
  return s;
}

void printWarnings(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings) printWarning(w);
}

CLI::Validator onOff() { return CLI::IsMember({"on", "off"}); }

void addShadingOptions(CLI::App* cmd, ShadingOptions& opt, bool window) {
  auto key = [window](const char* keys) { return window ? std::string(" (") + keys + ")" : ""; };
  cmd->add_option("--interpolation", opt.interpolation,
                  "Trilinear interpolation between the 8 neighbouring voxels" + key("key I"))
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--specular", opt.specular,
                  "GGX lobe of the glTF BRDF (off: diffuse only)" + key("key G"))
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--reflections", opt.reflections,
                  "Glossy and metal surfaces reflect a box-projected cube map of the lit scene "
                  "captured at its centre (off: the VDLs light the specular lobe too)")
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--lighting", opt.lighting,
                  "Indirect light from the octree per fragment, or from a lightmap atlas the octree "
                  "is rendered into first (paper 4.2.3: one fetch instead of a tree walk)")
      ->check(CLI::IsMember({"octree", "atlas"}))
      ->capture_default_str();
  cmd->add_option("--uv", opt.uv,
                  "Lightmap UVs for --lighting atlas: default (the scene's TEXCOORD_1 if it has "
                  "one, else automatic charts), auto (charts always), texcoord1 (required)")
      ->check(CLI::IsMember({"default", "auto", "texcoord1"}))
      ->capture_default_str();
  cmd->add_option("--atlas-on", opt.atlasOn,
                  "Where --lighting atlas renders the octree into the atlas: cpu (the C++ "
                  "lookup) or gpu (the scene shader's lookup in this GL context, paper 4.2.3)")
      ->check(CLI::IsMember({"cpu", "gpu"}))
      ->capture_default_str();
  cmd->add_option("--stitch-seams", opt.stitchSeams,
                  "With --lighting atlas: make the lookups on the two sides of every chart seam "
                  "agree (off: see the seams as the charts were baked)")
      ->check(onOff())
      ->capture_default_str();
  if (!window) {
    cmd->add_option("--supersample", opt.supersample,
                    "Anti-aliasing: each pixel the mean of N x N samples, as the path tracer "
                    "integrates a pixel (2: four frames sampling a rotated grid; more: the image "
                    "drawn N times larger, then box-filtered)")
        ->check(wholeIn(1, kMaxSupersample))
        ->capture_default_str();
  }
  if (window) {  // `render` has --exposure auto|EV (picture_options.h)
    cmd->add_option("--exposure", opt.exposure, "Exposure in EV (radiance * 2^EV)" + key("keys , . 0"))
        ->check(numberIn({-30, 30}))
        ->capture_default_str();
  }
  cmd->add_option("--vdls", opt.vdls, "VDLs used per voxel, strongest first" + key("keys [ ]"))
      ->check(wholeIn(1, kMaxVdls))
      ->capture_default_str();
  cmd->add_option("--area-lights", opt.areaLights,
                  "Emissive triangles as area lights: exact irradiance of each, soft shadows "
                  "(up to 128 one-sided triangles, a double-sided one counting twice; more, or "
                  "off: --emitter-lights point lights)")
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--emitter-lights", opt.emitterLights,
                  "Shadowed virtual point lights sampled on emissive triangles when they are not "
                  "area lights (0: none)")
      ->check(wholeIn(0, kMaxEmitterLights))
      ->capture_default_str();
  cmd->add_option("--shadow-map-size", opt.shadowMapSize, "Shadow map resolution per face, at most: many shadowed lights (6 faces per "
                  "emitter VPL) get smaller maps, halved until all fit in 48 MiB (16-bit depth)")
      ->check(wholeIn(kMinShadowMapSize, kMaxShadowMapSize))
      ->capture_default_str();
  cmd->add_option("--cosine-correction", opt.cosineCorrection,
                  "Divide each VDL by the cosine to its voxel's normal on upload, so that the "
                  "shader's max(0, n.d) does not count the baked cosine twice (off: the paper's "
                  "form, darker; see docs/accuracy.md)")
      ->check(onOff())
      ->capture_default_str();
  cmd->add_option("--texels", opt.texels,
                  "VDL texels on the GPU: float (RGBA32F, 16 B), half (RGBA16UI half floats, 8 B; "
                  "clamps above 65504) or compact (8 B: shared-exponent RGB9E5 with a scale per "
                  "octree, nothing clamped)")
      ->check(CLI::IsMember({"float", "half", "compact"}))
      ->capture_default_str();
  cmd->add_flag("--half-float", opt.halfFloat, "The same as --texels half");
  cmd->add_option("--tolerance", opt.tolerance,
                  "Adaptive leaves: siblings whose light agrees within this share of each "
                  "voxel's irradiance, at its own surface, become one coarser leaf (0 = every "
                  "leaf at the bake's depth; docs/octree.md)")
      ->check(numberIn({0, 1}))
      ->capture_default_str();
  cmd->add_option("--free-space-tolerance", opt.freeSpaceTolerance,
                  "The same for the free-space light the --add objects take: eight voxels whose "
                  "irradiance agrees within this share, for 14 normals, become one (0 = none)")
      ->check(numberIn({0, 1}))
      ->capture_default_str();
}

}  // namespace lo::tool
