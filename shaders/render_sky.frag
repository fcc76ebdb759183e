#version 330 core
// The sky behind the scene (Scene::sky, scene/scene.h): its radiance where
// the view ray points above the horizon (+Y), black below, as the path
// tracer sees it where a ray escapes. Drawn over the cleared frame before
// the scene (render/scene_pass.cpp).
uniform vec3 uSky;                    // radiance times the exposure scale
uniform vec3 uForward, uRight, uUp;   // view ray = forward + x right + y up, x and y in [-1, 1]
uniform vec2 uViewport;               // pixels
uniform vec2 uPixelOffset;            // where the pixel is sampled, in pixels from its centre
uniform bool uEncodeSrgb;
uniform bool uHasSkyImage;            // uSky scales an equirectangular map
uniform sampler2D uSkyImage;          // row 0 at the zenith; u = 1/2 looks along -Z
out vec4 fragColor;

void main() {
  vec2 ndc = (gl_FragCoord.xy + uPixelOffset) / uViewport * 2.0 - 1.0;
  vec3 ray = uForward + ndc.x * uRight + ndc.y * uUp;
  vec3 c = ray.y > 0.0 ? clamp(uSky, 0.0, 1.0e30) : vec3(0.0);
  if (uHasSkyImage && ray.y > 0.0) {
    vec3 d = normalize(ray);
    vec2 uv = vec2(0.5 + atan(d.x, -d.z) / 6.28318530718, acos(clamp(d.y, -1.0, 1.0)) / 3.14159265359);
    c *= texture(uSkyImage, uv).rgb;
  }
  if (uEncodeSrgb) {
    c = clamp(c, 0.0, 1.0);
    c = mix(c * 12.92, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(vec3(0.0031308), c));
  }
  fragColor = vec4(c, 1.0);
}
