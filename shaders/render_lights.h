/* render_lights.h: the scene shader's light block, declared once for GLSL and
 * C++ (Filament's UibStructs.h habit, without the generator): the shader
 * declares the std140 uniform block from this text, the renderer fills the
 * C++ struct of the same text (render/lights.cpp) and uploads its bytes.
 * Every member is a vec4, a mat4 or an array of them, so std140 puts each at
 * the next multiple of 16 bytes with no padding to write out; the
 * static_asserts below pin the size and every offset, and a render test
 * reads the block's layout back from the GL (glGetActiveUniformsiv) and
 * compares it with these offsets. Needs render_constants.h first.
 */
#ifndef LO_RENDER_LIGHTS_H
#define LO_RENDER_LIGHTS_H

#ifdef __cplusplus
#include <cstddef>
#include <glm/glm.hpp>
namespace lo {
namespace shader {
using glm::ivec4;
using glm::mat4;
using glm::vec4;
static_assert(sizeof(vec4) == 16 && sizeof(ivec4) == 16 && sizeof(mat4) == 64 &&
                  alignof(vec4) <= 16 && alignof(mat4) <= 16,
              "GLM's types must be tightly packed floats to stand in for std140's");
#define LO_STD140_BLOCK(Name) struct Name
#else
#define LO_STD140_BLOCK(Name) layout(std140) uniform Name
#endif

/* One light. Render space: world minus the scene's centre. */
struct GpuLight {
  vec4 positionType;   /* xyz position (an area light's shadow cube), w type (LO_LIGHT_*) */
  vec4 directionRange; /* xyz unit direction light travels (spot, directional, emitter
                          normal; a flat area light's front, else 0), w range (0 = none) */
  vec4 colorFar;       /* rgb: W/sr (point, spot, emitter at normal incidence), W/m^2
                          (directional), 0 (area: its triangles hold their radiance);
                          w shadow far */
  vec4 params;         /* x cos outer, y cos inner, z first shadow layer (-1 = none),
                          w near-field area (m^2) */
  vec4 corner0;        /* area light: xyz its box's lower corner (what lies in the box
                          casts no shadow on it), w its size (the penumbra's light) */
  vec4 corner1;        /* area light: xyz the box's upper corner; w (every shadowed
                          light): the shadow map's tangent per texel (a texel's size at
                          distance 1 from the light) */
  vec4 corner2;        /* area light: x its first triangle in uAreaTriangles, y how many */
};

/* In GLSL the members are globals (uLights[i], ...); in C++ fields. */
LO_STD140_BLOCK(LightBlock) {
  GpuLight uLights[LO_MAX_LIGHTS];
  mat4 uShadowMatrices[LO_MAX_SHADOW_LAYERS]; /* render space -> clip, per shadow layer */
  ivec4 uLightCount;  /* x lights, y of them area lights (the last y) */
  vec4 uShadowParams; /* x the least depth bias (fraction of far: two 16-bit steps), yzw 0 */
  /* The area lights' one-sided triangles, three vec4 each: corners in xyz
   * (wound to face where they emit), the radiance's R, G, B in the w's. */
  vec4 uAreaTriangles[3 * LO_MAX_AREA_TRIANGLES];
};

#undef LO_STD140_BLOCK

#ifdef __cplusplus
static_assert(sizeof(GpuLight) == 7 * 16, "std140 GpuLight: 7 vec4");
static_assert(offsetof(GpuLight, positionType) == 0 && offsetof(GpuLight, directionRange) == 16 &&
                  offsetof(GpuLight, colorFar) == 32 && offsetof(GpuLight, params) == 48 &&
                  offsetof(GpuLight, corner0) == 64 && offsetof(GpuLight, corner1) == 80 &&
                  offsetof(GpuLight, corner2) == 96,
              "std140 GpuLight member offsets");
static_assert(offsetof(LightBlock, uLights) == 0, "std140 LightBlock.uLights");
static_assert(offsetof(LightBlock, uShadowMatrices) == LO_MAX_LIGHTS * sizeof(GpuLight),
              "std140 LightBlock.uShadowMatrices");
static_assert(offsetof(LightBlock, uLightCount) ==
                  offsetof(LightBlock, uShadowMatrices) + LO_MAX_SHADOW_LAYERS * 64,
              "std140 LightBlock.uLightCount");
static_assert(offsetof(LightBlock, uShadowParams) == offsetof(LightBlock, uLightCount) + 16,
              "std140 LightBlock.uShadowParams");
static_assert(offsetof(LightBlock, uAreaTriangles) == offsetof(LightBlock, uShadowParams) + 16,
              "std140 LightBlock.uAreaTriangles");
static_assert(sizeof(LightBlock) ==
                  offsetof(LightBlock, uAreaTriangles) + 3 * LO_MAX_AREA_TRIANGLES * 16,
              "std140 LightBlock size");
static_assert(sizeof(LightBlock) <= 16384,
              "the light block within the least GL_MAX_UNIFORM_BLOCK_SIZE a GL 3.3 driver has");
}  // namespace shader
}  // namespace lo
#endif

#endif /* LO_RENDER_LIGHTS_H */
