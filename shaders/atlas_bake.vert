#version 330 core
// Render to atlas on the GPU (paper §4.2.3; render/atlas_gpu.cpp): each
// triangle drawn at its lightmap UV. The vertex stage passes the corners on;
// atlas_bake.geom covers the texels, atlas_bake.frag evaluates the octree.
layout(location = 0) in vec2 aTexel;     // lightmap UV in texels of the page (u * width, v * height)
layout(location = 1) in vec3 aPosition;  // world, relative to the octree's origin
layout(location = 2) in vec3 aNormal;    // vertex normal; zero = none (the face's is used)
layout(location = 3) in int aTriangle;   // the scene triangle
out vec2 gTexel;
out vec3 gPosition;
out vec3 gNormal;
flat out int gTriangle;
void main() {
  gTexel = aTexel;
  gPosition = aPosition;
  gNormal = aNormal;
  gTriangle = aTriangle;
  gl_Position = vec4(0.0, 0.0, 0.0, 1.0);  // placed by the geometry stage
}
