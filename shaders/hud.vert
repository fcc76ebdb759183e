#version 330 core
// The viewer's HUD (src/render/hud.cpp): text and its backing box in window
// pixels, y down from the top, with a colour per vertex.
layout(location = 0) in vec2 pixel;
layout(location = 1) in vec4 colour;
uniform vec2 viewport;  // window size in pixels
out vec4 vColour;
void main() {
  vColour = colour;
  gl_Position = vec4(2.0 * pixel.x / viewport.x - 1.0, 1.0 - 2.0 * pixel.y / viewport.y, 0.0, 1.0);
}
