#version 330 core
// Evaluates the shared layout functions of octree_layout.h on the texels of uInputs, one result texel per input texel, so a
// test can compare the GLSL results with the same functions compiled as C++.
uniform sampler2D uInputs;  // RGBA32F
uniform int uFunction;      // 0: pack direction, 1: unpack direction, 2: addresses
out vec4 result;
#include "octree_layout.h"

void main() {
  vec4 v = texelFetch(uInputs, ivec2(gl_FragCoord.xy), 0);
  if (uFunction == 0) {
    result = vec4(loPackDirection(v.x, v.y, v.z), loPackedTheta(v.w), loPackedPhi(v.w), 0.0);
  } else if (uFunction == 1) {
    float x = loUnpackDirectionX(v.x);
    float y = loUnpackDirectionY(v.x);
    float z = loUnpackDirectionZ(v.x);
    result = vec4(x, y, z, loPackDirection(x, y, z));
  } else {
    uint a = loUnpackAddress(uint(v.x), uint(v.y), uint(v.z));
    uint index = uint(v.w);
    // Addresses are below 2^24, exact in a float.
    result = vec4(float(a), float(loPackAddressR(a) + 256u * loPackAddressG(a)),
                  float(loVdlTexelX(index)), float(loVdlTexelY(index)));
  }
}
