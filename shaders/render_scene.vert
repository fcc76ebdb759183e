#version 330 core
// Scene pass: a render-space triangle soup (world minus the scene's centre)
// with per-vertex material values (triangles never share vertices, so
// per-triangle materials stay exact).
layout(location = 0) in vec3 aPosition;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in vec4 aBaseColor;  // linear base colour factor and alpha x COLOR_0
layout(location = 3) in vec2 aMetallicRoughness;
layout(location = 4) in vec3 aEmission;  // W/(m^2 sr)
layout(location = 5) in vec2 aUv;        // the UV set the base colour texture names
layout(location = 6) in vec2 aNormalUv;  // the UV set the normal map names
layout(location = 7) in vec2 aMetallicRoughnessUv;
layout(location = 8) in vec2 aOcclusionUv;
layout(location = 9) in vec2 aEmissiveUv;
layout(location = 10) in vec3 aLightmap;  // lightmap u, v and page (Renderer::setAtlas)
layout(location = 11) in vec4 aTangent;   // glTF TANGENT (w = +-1), or w = 0: none

uniform mat4 uViewProj;
invariant gl_Position;  // as render_depth.vert: the depth pre-pass must match exactly

out vec3 vPosition;
out vec3 vNormal;
out vec3 vBaseColor;
out float vBaseAlpha;
out vec2 vMetallicRoughness;
out vec3 vEmission;
out vec2 vUv;
out vec2 vNormalUv;
out vec2 vMetallicRoughnessUv;
out vec2 vOcclusionUv;
out vec2 vEmissiveUv;
out vec3 vLightmap;
out vec4 vTangent;

void main() {
  vPosition = aPosition;
  vNormal = aNormal;
  vBaseColor = aBaseColor.rgb;
  vBaseAlpha = aBaseColor.a;
  vMetallicRoughness = aMetallicRoughness;
  vEmission = aEmission;
  vUv = aUv;
  vNormalUv = aNormalUv;
  vMetallicRoughnessUv = aMetallicRoughnessUv;
  vOcclusionUv = aOcclusionUv;
  vEmissiveUv = aEmissiveUv;
  vLightmap = aLightmap;
  vTangent = aTangent;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}
