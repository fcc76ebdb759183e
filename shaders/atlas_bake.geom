#version 330 core
// Conservative rasterisation in UV space (render/atlas_gpu.cpp): a triangle
// becomes the texel-aligned rectangle of its UV bounding box, so that every
// texel its footprint overlaps gets a fragment; atlas_bake.frag then keeps
// exactly the texels the CPU path keeps (lightmap/lightmap_atlas.cpp,
// rasterTriangle). The corners go to the fragments unchanged (flat).
layout(triangles) in;
layout(triangle_strip, max_vertices = 4) out;
in vec2 gTexel[];
in vec3 gPosition[];
in vec3 gNormal[];
flat in int gTriangle[];
uniform vec2 uPageSize;  // texels
flat out vec2 fTexel0;
flat out vec2 fTexel1;
flat out vec2 fTexel2;
flat out vec3 fPosition0;
flat out vec3 fPosition1;
flat out vec3 fPosition2;
flat out vec3 fNormal0;
flat out vec3 fNormal1;
flat out vec3 fNormal2;
flat out int fTriangle;

void corner(vec2 texel) {
  fTexel0 = gTexel[0];
  fTexel1 = gTexel[1];
  fTexel2 = gTexel[2];
  fPosition0 = gPosition[0];
  fPosition1 = gPosition[1];
  fPosition2 = gPosition[2];
  fNormal0 = gNormal[0];
  fNormal1 = gNormal[1];
  fNormal2 = gNormal[2];
  fTriangle = gTriangle[0];
  gl_Position = vec4(texel / uPageSize * 2.0 - 1.0, 0.0, 1.0);
  EmitVertex();
}

void main() {
  vec2 lo = min(min(gTexel[0], gTexel[1]), gTexel[2]);
  vec2 hi = max(max(gTexel[0], gTexel[1]), gTexel[2]);
  // Texels floor(lo) .. ceil(hi) - 1: their centres lie inside this rectangle.
  vec2 a = max(floor(lo), vec2(0.0));
  vec2 b = min(ceil(hi), uPageSize);
  if (b.x <= a.x || b.y <= a.y) return;
  corner(vec2(a.x, a.y));
  corner(vec2(b.x, a.y));
  corner(vec2(a.x, b.y));
  corner(vec2(b.x, b.y));
  EndPrimitive();
}
