#version 330 core
// Shadow-map pass: passes each triangle through, but for point, spot and
// emitter lights (uFar > 0) drops a triangle that the light sees within
// about a degree of edge-on: every point of it is at least 50 times farther
// from the light than its plane is. Such a triangle covers a strip of the map
// a few texels wide at most, which its neighbours of a closed surface cover
// as well; and the software rasteriser (llvmpipe) can take seconds to draw a
// triangle whose plane passes a fraction of a millimetre from a cube face's
// eye (docs/render.md, "The first frame": one such triangle of the shared lamp
// took 0.8 s, as long as the other 77 layers together). A triangle the light
// faces from nearby, a wall beside a lamp, is kept: its nearest point is as
// near as its plane.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in vec3 gWorld[];
in vec2 gUv[];
in float gBaseAlpha[];
out vec3 vWorld;
out vec2 vUv;
out float vBaseAlpha;
uniform mat4 uViewProj;
uniform vec3 uLightPosition;
uniform float uFar;

const float kEdgeOn = 0.02;  // sine of the angle below which a triangle is edge-on

// The point of triangle abc nearest to p (Ericson, Real-Time Collision
// Detection, 5.1.5: by the Voronoi regions of its corners and edges).
vec3 closestOnTriangle(vec3 p, vec3 a, vec3 b, vec3 c) {
  vec3 ab = b - a, ac = c - a, ap = p - a;
  float d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;
  vec3 bp = p - b;
  float d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3) return b;
  float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + ab * (d1 / (d1 - d3));
  vec3 cp = p - c;
  float d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6) return c;
  float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + ac * (d2 / (d2 - d6));
  float va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0) {
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  }
  float denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

void main() {
  if (uFar > 0.0) {
    vec3 n = cross(gWorld[1] - gWorld[0], gWorld[2] - gWorld[0]);
    float planeDistance = abs(dot(n, uLightPosition - gWorld[0]));  // times |n|
    float nearest = length(closestOnTriangle(uLightPosition, gWorld[0], gWorld[1], gWorld[2]) -
                           uLightPosition);
    if (planeDistance < kEdgeOn * nearest * length(n)) return;
  }
  for (int i = 0; i < 3; ++i) {
    vWorld = gWorld[i];
    vUv = gUv[i];
    vBaseAlpha = gBaseAlpha[i];
    gl_Position = uViewProj * vec4(gWorld[i], 1.0);
    EmitVertex();
  }
  EndPrimitive();
}
