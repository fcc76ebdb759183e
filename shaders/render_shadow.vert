#version 330 core
// Shadow-map pass: world-space triangles into one layer of the shadow array
// (projected by render_shadow.geom, which leaves out edge-on triangles).
layout(location = 0) in vec3 aPosition;
layout(location = 2) in vec4 aBaseColor;  // its alpha: factor x COLOR_0 (the alpha test)
layout(location = 5) in vec2 aUv;  // base colour UV: the alpha test of masked materials
out vec3 gWorld;
out vec2 gUv;
out float gBaseAlpha;
void main() {
  gWorld = aPosition;
  gUv = aUv;
  gBaseAlpha = aBaseColor.a;
}
