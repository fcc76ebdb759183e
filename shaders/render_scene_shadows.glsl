// Shadows of the scene pass: shadow cubes of point lights and VPLs, PCSS of
// area lights, cascades of directional lights (render/lights.cpp renders the
// maps). Part of render_scene.frag, after render_lights.h; LO_DIRECT_LIGHT only.

// Cube face of direction d: the layer offset of a point light's six maps.
int cubeFace(vec3 d) {
  vec3 ad = abs(d);
  if (ad.x >= ad.y && ad.x >= ad.z) return d.x > 0.0 ? 0 : 1;
  if (ad.y >= ad.z) return d.y > 0.0 ? 2 : 3;
  return d.z > 0.0 ? 4 : 5;
}

// The size of one shadow texel of light i where it falls at distance d from
// the light: the map's tangent per texel (render/lights.cpp) times d. The
// offsets and biases below are this many texels, so that a 7.5 cm car and a
// 100 m atrium, or a small object in a large scene, shadow alike: nothing
// in them is in scene units.
float shadowTexel(int i, float d) { return uLights[i].corner1.w * d; }

// The point a shadow map is read at: p moved along n by the normal offset
// of 3 texels, scaled up at grazing angles (toLight the direction to the
// light), where shadow acne appears.
vec3 shadowPoint(vec3 p, vec3 n, vec3 toLight, float texel) {
  float nl = clamp(dot(n, toLight), 0.0, 1.0);
  return p + n * (1.5 * texel) * (1.0 + 2.0 * (1.0 - nl));
}

// The depth bias, as a fraction of the map's far plane: one texel, and
// never under two steps of the 16-bit depth (uShadowParams.x).
float shadowBias(float texel, float far) { return max(0.5 * texel / far, uShadowParams.x); }

// Soft shadow of area light i (PCSS, Fernando 2005) from its shadow cube at
// the triangle's centre: the blockers found in the region of the map that
// can hide part of the light from p give their mean distance d_b; the
// penumbra's angular half-width is then h (d_r - d_b) / (d_r d_b), h half
// the light's size and d_r the receiver's distance, and the map is filtered
// over it with hardware-compared taps (a box filter of the shadow edge:
// smooth and monotonic, no bands). Each tap is compared with the distance of
// the receiver's tangent plane in the tap's own direction, not with p's, so
// that a wide kernel on a surface the light sees at a grazing angle does not
// shadow the surface itself; directions behind the emitter's plane carry no
// light, so what the map holds there (the ceiling around a ceiling light)
// blocks nothing.
// Distance / far of the receiver's tangent plane (through the light centre
// lc's offset `plane` = (ps - lc).n) along the shadow-map direction of uv t,
// or a negative value for directions behind the emitter (normal nE; 0 for
// a light that faces every way: a glowing cube).
float receiverDepth(mat4 clipToRender, vec2 t, vec3 lc, vec3 n, vec3 nE, float plane, float far) {
  vec4 w = clipToRender * vec4(t * 2.0 - 1.0, 0.0, 1.0);
  vec3 dir = normalize(w.xyz / w.w - lc);
  if (dot(nE, nE) > 0.0 && dot(dir, nE) <= 0.0) return -1.0;  // nE = 0: a light facing every way
  float dn = dot(dir, n);
  float receiver = dn < -1e-4 || dn > 1e-4 ? plane / dn : far;
  return receiver > 0.0 ? min(receiver / far, 1.0) : 1.0;
}

float areaShadow(int i, vec3 p, vec3 n, vec3 toLight) {
  // The light read in place (a copy of the 7-vec4 struct is dear on llvmpipe).
#define L uLights[i]
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  vec3 lc = L.positionType.xyz;
  float far = L.colorFar.w;
  float texelSize = shadowTexel(i, length(p - lc));
  float bias = shadowBias(texelSize, far);
  vec3 ps = shadowPoint(p, n, toLight, texelSize);
  vec3 d = ps - lc;
  int layer = first + cubeFace(d);
  vec4 c = uShadowMatrices[layer] * vec4(ps, 1.0);
  vec2 uv = c.xy / c.w * 0.5 + 0.5;
  float dr = length(d);
  if (dr / far > 1.0) return 1.0;
  float plane = dot(d, n);  // the receiver's tangent plane, as seen from the light centre
  // The light's centre below the receiver's horizon (the side of a sphere
  // under a large light, which sees the light's edge but not its centre):
  // what the map holds in any direction from the centre, up to where it
  // crosses that horizon, lies below it, and nothing below a surface's
  // tangent plane lies on a ray that reaches the surface from above it. The
  // map cannot tell what hides the light's visible part; the part itself is
  // exact (polygonIrradiance clips the light at the horizon): count p lit.
  // Judged at p itself, not at the offset point, which would count points
  // that see the centre just above their horizon.
  if (dot(p - lc, n) > 0.0) return 1.0;
  mat4 clipToRender = inverse(uShadowMatrices[layer]);
  float h = 0.5 * L.corner0.w;
  // Blockers from 0.3 d_r out can hide the light: search that cone (in a
  // cube face, an angle's tangent t spans t/2 in uv).
  float search = min(0.5 * h * 0.7 / (0.3 * dr), 0.2);
  // 4 x 4 taps on a grid turned by atan(1/4), so that the blocker estimate,
  // and with it the filter's width, changes in small steps along any edge.
  const int kTaps = 4;
  const vec2 kSearchTurn = vec2(0.970143, 0.242536);  // (cos, sin) of atan(1/4)
  float blockers = 0.0, blockerSum = 0.0;
  for (int y = 0; y < kTaps; ++y) {
    for (int x = 0; x < kTaps; ++x) {
      vec2 g = (vec2(x, y) + 0.5) / float(kTaps) * 2.0 - 1.0;
      vec2 t = uv + vec2(kSearchTurn.x * g.x - kSearchTurn.y * g.y,
                         kSearchTurn.y * g.x + kSearchTurn.x * g.y) * search;
      float receiver = receiverDepth(clipToRender, t, lc, n, L.directionRange.xyz, plane, far);
      // Behind the emitter's plane no light travels: nothing there blocks it.
      if (receiver < 0.0) continue;
      float stored = texture(uShadowDepths, vec3(t, float(layer))).r;
      if (stored < receiver - bias) {
        blockers += 1.0;
        blockerSum += stored * far;
      }
    }
  }
  if (blockers == 0.0) return 1.0;
  float db = max(blockerSum / blockers, 1e-4 * far);
  float texel = 1.0 / float(textureSize(uShadowDepths, 0).x);
  float radius = clamp(0.5 * h * max(dr - db, 0.0) / (dr * db), texel, 0.2);
  // 6 x 6 taps on a grid turned by atan(1/6) (a rook pattern: every edge
  // direction but a few sees 36 distinct tap positions, not 6 columns): 36
  // levels between umbra and light, each blurred by the hardware 2x2
  // comparison, below what the eye resolves as a band.
  const int kFilterTaps = 6;
  const vec2 kTurn = vec2(0.986394, 0.164399);  // (cos, sin) of atan(1/6)
  float lit = 0.0;
  for (int y = 0; y < kFilterTaps; ++y) {
    for (int x = 0; x < kFilterTaps; ++x) {
      vec2 g = (vec2(x, y) + 0.5) / float(kFilterTaps) * 2.0 - 1.0;
      vec2 t = uv + vec2(kTurn.x * g.x - kTurn.y * g.y, kTurn.y * g.x + kTurn.x * g.y) * radius;
      float receiver = receiverDepth(clipToRender, t, lc, n, L.directionRange.xyz, plane, far);
      lit += receiver < 0.0 ? 1.0
                            : texture(uShadowMaps, vec4(t, float(layer), receiver - bias));
    }
  }
  return lit / float(kFilterTaps * kFilterTaps);
}

// Shadow of directional light i from its cascades (render/lights.cpp
// fitCascades): the cascade by the point's view depth, a slope-scaled depth
// bias, and a filter that cannot leak: the map is read as nearest texels, a tap is
// lit only when the 2 x 2 texels around it all are (an erosion of the lit
// area by one texel), and 3 x 3 such taps one texel apart are tent-weighted
// by the point's position between texels (smooth as it moves). A floor point
// next to the wall of a closed room under the sun thus never reads the lit
// ground outside the wall through a texel that straddles the wall's base;
// the price is a shadow one texel larger, on the lit side.
// The fragment's unit geometric normal, turned to the viewer (set by main):
// shadow lookups (receiver plane, offsets, biases) follow the surface's real
// plane, not the normal map's or the interpolated normal's (a tilted
// receiver plane shadows the surface by itself).
vec3 gGeometricNormal;

float sunShadow(int i, vec3 p, vec3 n, vec3 toLight) {
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  float depth = dot(p - uEye, uViewForward);
  int c = depth < uCascadeFar.x ? 0 : depth < uCascadeFar.y ? 1 : depth < uCascadeFar.z ? 2 : 3;
  // Slope-scaled depth bias, no normal offset: a point lifted off the floor
  // by a normal offset rises above the base of a wall next to it in the
  // sun's view and reads that wall's texels as lit. The taps reach two
  // texels out, over which a surface at angle theta to the light changes
  // depth by 2 tan(theta) texels.
  float nl = clamp(abs(dot(gGeometricNormal, toLight)), 0.05, 1.0);
  float slope = min(sqrt(1.0 - nl * nl) / nl, 4.0);
  int layer = first + c;
  vec4 clip = uShadowMatrices[layer] * vec4(p, 1.0);
  vec3 ndc = clip.xyz / clip.w;
  vec2 uv = ndc.xy * 0.5 + 0.5;
  float ref = ndc.z * 0.5 + 0.5 - (0.5 + 2.5 * slope) * uCascadeTexel[c] / uCascadeDepth[c];
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ref > 1.0) return 1.0;
  int size = textureSize(uShadowDepths, 0).x;
  vec2 t = uv * float(size) - 0.5;
  ivec2 base = ivec2(floor(t)) - 1;
  vec2 f = t - floor(t);
  // 4 x 4 nearest comparisons around the point.
  float lit[16];
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      ivec2 q = clamp(base + ivec2(x, y), ivec2(0), ivec2(size - 1));
      lit[4 * y + x] = texelFetch(uShadowDepths, ivec3(q, layer), 0).r >= ref ? 1.0 : 0.0;
    }
  }
  // Each of the 2 x 2 nearest texel centres is lit only if the 3 x 3 texels
  // around it all are; the point interpolates those four bilinearly.
  float e[4];
  for (int y = 0; y < 2; ++y) {
    for (int x = 0; x < 2; ++x) {
      float m = 1.0;
      for (int dy = 0; dy < 3; ++dy) {
        for (int dx = 0; dx < 3; ++dx) m = min(m, lit[4 * (y + dy) + x + dx]);
      }
      e[2 * y + x] = m;
    }
  }
  float sum = mix(mix(e[0], e[1], f.x), mix(e[2], e[3], f.x), f.y);
  return sum;
}

float shadow(int i, vec3 p, vec3 n, vec3 toLight) {
  // The light read in place (a copy of the 7-vec4 struct is dear on llvmpipe).
#define L uLights[i]
  int first = int(L.params.z);
  if (first < 0) return 1.0;
  int type = int(L.positionType.w);
  float texelSize = shadowTexel(i, length(p - L.positionType.xyz));
  vec3 ps = shadowPoint(p, n, toLight, texelSize);
  int layer = first;
  if (type == LO_LIGHT_POINT || type == LO_LIGHT_EMITTER) layer += cubeFace(ps - L.positionType.xyz);
  vec4 c = uShadowMatrices[layer] * vec4(ps, 1.0);
  vec3 ndc = c.xyz / c.w;
  vec2 uv = ndc.xy * 0.5 + 0.5;
  float ref = L.colorFar.w > 0.0 ? length(ps - L.positionType.xyz) / L.colorFar.w
                                 : ndc.z * 0.5 + 0.5;
  if (any(lessThan(uv, vec2(0.0))) || any(greaterThan(uv, vec2(1.0))) || ref > 1.0) return 1.0;
  return texture(uShadowMaps, vec4(uv, float(layer), ref - shadowBias(texelSize, L.colorFar.w)));
}
