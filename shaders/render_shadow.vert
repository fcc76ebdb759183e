#version 330 core
// Shadow-map pass: world-space triangles into one layer of the shadow array.
layout(location = 0) in vec3 aPosition;
layout(location = 2) in vec4 aBaseColor;  // its alpha: factor x COLOR_0 (the alpha test)
layout(location = 5) in vec2 aUv;  // base colour UV: the alpha test of masked materials
uniform mat4 uViewProj;
out vec3 vWorld;
out vec2 vUv;
out float vBaseAlpha;
void main() {
  vWorld = aPosition;
  vUv = aUv;
  vBaseAlpha = aBaseColor.a;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}
