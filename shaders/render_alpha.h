// render_alpha.h: glTF alpha modes in the depth-only passes (the depth
// pre-pass and the shadow maps). A masked material's fragments whose alpha
// (base colour factor x vertex colour x texture) falls below the cutoff are no surface: they
// neither hide what lies behind nor cast a shadow. The scene pass tests the
// same alpha (render_scene.frag), so the pre-pass depth and the shaded
// surface agree. `#include`d by render_depth.frag and render_shadow.frag.
in vec2 vUv;
in float vBaseAlpha;                   // baseColorFactor's alpha x COLOR_0's
uniform bool uAlphaTest;               // this draw's material is Mask (or Blend, in shadow maps)
uniform sampler2D uBaseColorTexture;   // RGBA16F: linear colour, alpha as stored
uniform bool uHasBaseColorTexture;
uniform float uAlphaCutoff;

void loAlphaTest() {
  if (!uAlphaTest) return;
  float alpha = vBaseAlpha;
  if (uHasBaseColorTexture) alpha *= texture(uBaseColorTexture, vUv).a;
  if (alpha < uAlphaCutoff) discard;
}
