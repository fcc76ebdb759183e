#version 330 core
// Evaluates the shared BRDF of material_brdf.h on the samples of uInputs (one
// per column: 5 texels of inputs), one output row per function, so a test can
// compare the GLSL results with the same functions compiled as C++
// (render/shader_probes.h lists the rows).
uniform sampler2D uInputs;  // RGBA32F, 5 rows
out vec4 result;
#include "material_brdf.h"

void main() {
  int x = int(gl_FragCoord.x);
  int row = int(gl_FragCoord.y);
  vec4 t0 = texelFetch(uInputs, ivec2(x, 0), 0);
  vec4 t1 = texelFetch(uInputs, ivec2(x, 1), 0);
  vec4 t2 = texelFetch(uInputs, ivec2(x, 2), 0);
  vec4 t3 = texelFetch(uInputs, ivec2(x, 3), 0);
  vec2 layer = texelFetch(uInputs, ivec2(x, 4), 0).xy;
  vec3 n = t0.xyz, v = t1.xyz, l = t2.xyz, baseColor = t3.rgb;
  float metallic = t0.w, roughness = t1.w, transmission = t2.w, specularWeight = t3.w;
  vec3 diffuse, specular;
  loBrdfLobes(n, v, l, baseColor, metallic, loBrdfAlpha(roughness), transmission, layer, diffuse,
              specular);
  if (row == 0) {
    result = vec4(loBrdfCosWeighted(n, v, l, baseColor, metallic, roughness, transmission, layer,
                                    true, specularWeight), loBrdfAlpha(roughness));
  } else if (row == 1) {
    result = vec4(diffuse, 0.0);
  } else if (row == 2) {
    result = vec4(specular, 0.0);
  } else if (row == 3) {
    result = vec4(loEnvironmentBrdf(baseColor, metallic, roughness, clamp(dot(n, v), 0.0, 1.0),
                                    layer), 0.0);
  } else if (row == 4) {
    result = vec4(loBrdf(n, v, l, baseColor, metallic, roughness, transmission, layer), 0.0);
  } else {
    result = vec4(loBrdfCos(n, v, l, baseColor, metallic, roughness, transmission, layer, false),
                  0.0);
  }
}
