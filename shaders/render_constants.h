/* render_constants.h: constants shared by the scene shader and the renderer
 * (src/render), valid in both C++ and GLSL, so that the value of
 * a mode or a light type is written once: both builds compile this text.
 */
#ifndef LO_RENDER_CONSTANTS_H
#define LO_RENDER_CONSTANTS_H

#ifdef __cplusplus
namespace lo {
namespace shader {
#endif

/* uMode: what the scene pass draws (RenderMode in renderer.h). */
const int LO_MODE_FULL = 0;     /* emission + direct + indirect */
const int LO_MODE_DIRECT = 1;   /* emission + direct */
const int LO_MODE_INDIRECT = 2; /* the light octree alone */
const int LO_MODE_VOXELS = 3;   /* octree leaves coloured by a hash */

/* uAlphaMode: glTF alphaMode of the draw (AlphaMode in scene/scene.h). */
const int LO_ALPHA_OPAQUE = 0;
const int LO_ALPHA_MASK = 1;
const int LO_ALPHA_BLEND = 2;

/* Light.positionType.w: the kind of light (std140 LightBlock). */
const int LO_LIGHT_POINT = 0;
const int LO_LIGHT_SPOT = 1;
const int LO_LIGHT_DIRECTIONAL = 2;
const int LO_LIGHT_EMITTER = 3; /* a virtual point light on an emissive triangle */
const int LO_LIGHT_AREA = 4;    /* an emissive triangle: exact unshadowed irradiance, soft shadows */

/* Emissive triangles drawn as area lights: at most LO_MAX_AREA_TRIANGLES
 * one-sided triangles (a double-sided one counts twice), integrated exactly
 * one by one, in at most LO_MAX_AREA_LIGHTS groups, each shadowed from one
 * cube of 6 shadow layers; a scene with more gets virtual point lights. */
const int LO_MAX_AREA_LIGHTS = 8;
const int LO_MAX_AREA_TRIANGLES = 128;

/* Cascaded shadow maps per directional light (layers of the shadow array;
 * the cascade uniforms are vec4s: at most 4). */
const int LO_SUN_CASCADES = 4;

/* Environment reflections: surfaces of roughness up to LO_PROBE_FULL take
 * their specular indirect light from the probe alone, above LO_PROBE_NONE from
 * the VDLs alone, in between a mix (shaders/render_scene.frag). */
const float LO_PROBE_FULL = 0.5;
const float LO_PROBE_NONE = 0.8;

/* Irradiance normalisation of the probe (shaders/render_scene_probe.glsl):
 * its light is scaled by the octree's irradiance at the surface over the
 * probe's own, at most LO_PROBE_NORMALIZATION_MAX (1: it only takes light
 * away, never adds any). The octree knows the light on the surfaces the
 * photon tracer stores photons on: those with a diffuse lobe and metals
 * rougher than LO_PROBE_GLOSSY_ROUGHNESS (kGlossyRoughness, material/bsdf.h:
 * keep the two equal). */
const float LO_PROBE_NORMALIZATION_MAX = 1.0;
const float LO_PROBE_GLOSSY_ROUGHNESS = 0.2;

/* Array sizes of the std140 LightBlock. */
const int LO_MAX_LIGHTS = 32;
const int LO_MAX_SHADOW_LAYERS = 96;

#ifdef __cplusplus
}  // namespace shader
}  // namespace lo
#endif

#endif /* LO_RENDER_CONSTANTS_H */
