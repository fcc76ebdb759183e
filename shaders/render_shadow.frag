#version 330 core
// Point and spot lights store the linear distance to the light over uFar (the
// lookup compares distances, so the bias is in world units whatever the
// projection); directional lights (uFar == 0) keep the orthographic depth,
// which is already linear.
#include "render_alpha.h"
in vec3 vWorld;
uniform vec3 uLightPosition;
uniform float uFar;
// An area light's own box (a glowing cube around its shadow cube's centre)
// casts no shadow on it; empty (lower > upper) for other lights.
uniform vec3 uIgnoreLower;
uniform vec3 uIgnoreUpper;
void main() {
  loAlphaTest();  // cut-out parts of masked materials cast no shadow
  if (all(greaterThanEqual(vWorld, uIgnoreLower)) && all(lessThanEqual(vWorld, uIgnoreUpper))) discard;
  gl_FragDepth = uFar > 0.0 ? clamp(length(vWorld - uLightPosition) / uFar, 0.0, 1.0)
                            : gl_FragCoord.z;
}
