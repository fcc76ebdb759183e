#pragma once
/// @file render/shader_probes.h
/// @brief Runs the GLSL build of shaders/material_brdf.h on inputs, so a test
/// can check that the shader's BRDF and the C++ build (material/gltf_brdf.h)
/// agree, and reads the light block's layout back from the GL, so a test can
/// check it against the C++ twin (shaders/render_lights.h). Need a current
/// GlContext.

#include <array>
#include <string>
#include <vector>

#include "core/math.h"

namespace lo {

/// One evaluation of the BRDF: unit directions in one space, linear colour.
struct BrdfProbeInput {
  Vec3 n, v, l;
  Vec3 baseColor;
  float metallic = 0;
  float roughness = 1;
  float transmission = 0;
  float specularWeight = 1;  ///< the VDLs' share of the GGX lobe (loBrdfCosWeighted)
  float dielectricF0 = 0.04f;  ///< the dielectric layer's F0
  float specular = 1;          ///< the dielectric layer's weight
};

/// The shader's results for one input (material_brdf.h's functions).
struct BrdfProbeOutput {
  Vec3 cosWeighted;  ///< loBrdfCosWeighted(..., specular on, specularWeight)
  float alpha = 0;   ///< loBrdfAlpha(roughness)
  Vec3 diffuse;      ///< loBrdfLobes' diffuse lobe (alpha from roughness)
  Vec3 specular;     ///< loBrdfLobes' specular lobe
  Vec3 environment;  ///< loEnvironmentBrdf(baseColor, metallic, roughness, clamp(n.v, 0, 1))
  Vec3 brdf;         ///< loBrdf: both lobes, no cosine
  Vec3 diffuseCos;   ///< loBrdfCos(..., specular off)
};

/// One fragment per input and function, into an RGBA32F target; returns the
/// outputs in order.
std::vector<BrdfProbeOutput> runBrdfProbe(const std::vector<BrdfProbeInput>& inputs);

/// A member of the scene shader's std140 LightBlock as the GL laid it out.
struct UniformLayout {
  std::string name;  ///< e.g. "uLights[1].colorFar", "uShadowMatrices[0]"
  int offset = -1;   ///< bytes from the block's start (-1: not an active uniform)
  int arrayStride = 0;
  int matrixStride = 0;
};

/// The LightBlock of the scene program (with direct light) as the GL laid it
/// out: its size in bytes, and the offsets of the named members.
int lightBlockSize();
std::vector<UniformLayout> lightBlockLayout(const std::vector<std::string>& names);

}  // namespace lo
