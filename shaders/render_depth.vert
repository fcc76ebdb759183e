#version 330 core
// Depth pre-pass: the scene pass's position transform alone, so that the
// expensive scene shader runs once per pixel (GL_LEQUAL against this depth)
// instead of once per overlapping surface. `invariant` on both shaders makes
// the two passes produce bit-identical depths. The base colour UV feeds the
// alpha test of masked materials (render_alpha.h).
layout(location = 0) in vec3 aPosition;
layout(location = 2) in vec4 aBaseColor;  // its alpha: factor x COLOR_0 (the alpha test)
layout(location = 5) in vec2 aUv;
uniform mat4 uViewProj;
invariant gl_Position;
out vec2 vUv;
out float vBaseAlpha;
void main() {
  vUv = aUv;
  vBaseAlpha = aBaseColor.a;
  gl_Position = uViewProj * vec4(aPosition, 1.0);
}
