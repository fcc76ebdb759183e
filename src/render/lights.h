#pragma once
// Internal to src/render: the scene's lights as the scene shader reads them
// (the std140 block of shaders/render_lights.h) and their shadow maps.

#include <render_constants.h>

#include <array>
#include <string>
#include <glm/glm.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <vector>

#include "render/gl_resources.h"
#include "render/light_list.h"
#include "render/renderer.h"

namespace lo::render_internal {

/// Index of the s-th of `sampled` triangles of `triangles` in an even sample
/// (a step coprime with the count spreads it over the index range).
size_t sampledTriangle(size_t s, size_t sampled, size_t triangles);

/// The three corners (render space) of each of an even sample of at most
/// `most` of the scene's triangles: the cascades' fill is counted on them,
/// the camera's near plane kept nearer than them.
std::vector<glm::vec3> sampledCorners(const Scene& scene, const RenderSpace& space, size_t most);

/// The light block and the shadow maps of a scene (lights.cpp).
struct SceneLights {
  LightBlock block{};
  GlBuffer ubo;             ///< the block, binding point 0
  GlTexture shadowTexture;  ///< depth array: the layers of every shadowed light
  GlFramebuffer shadowFbo;
  GlSampler depthSampler;  ///< reads the shadow maps' depths (no comparison): PCSS blocker search
  GlProgram shadowProgram;
  int shadowMapSize = 1;
  /// Why the maps are smaller than asked beyond the memory budget (the fill
  /// budget, lights.cpp), or "".
  std::string shadowMapNote;
  double shadowOverlap = 0;  ///< how many times over the scene covers the maps (lights.cpp)
  int emitterLights = 0;   ///< VPLs in the block
  int areaLightCount = 0;  ///< area lights in the block (the last ones): groups of triangles
  int areaTriangleCount = 0;  ///< their triangles (uAreaTriangles)
  /// Directional lights with cascaded shadow maps (indices into the light
  /// block), their cascades refitted when the camera moves.
  std::vector<int> sunLights;
  float cascadeFar[4] = {0, 0, 0, 0};    ///< view depth where each cascade ends
  float cascadeTexel[4] = {0, 0, 0, 0};  ///< world size of one texel of each cascade
  float cascadeDepth[4] = {1, 1, 1, 1};  ///< world depth range of each cascade's map
  std::array<float, 12> fittedCamera{};  ///< the camera the cascades were fitted to
  /// Corners (render space, w = 1) of an even sample of the scene's
  /// triangles, 3 each, and the triangles each stands for: the fitted
  /// cascades' fill is counted on them (fitCascadeMatrices). Empty without
  /// suns.
  std::vector<glm::vec4> cascadeSample;
  double cascadeSampleScale = 1;
  /// The last fit's cascades would have covered more than the fill budget,
  /// so each cascade covers the whole scene, as before the first frame.
  bool cascadesWhole = false;
  /// The fill one fit's drawing may cover: the budget, a sixteenth of it
  /// for interactive frames (RendererParams::interactive).
  double cascadeFillBudget = 0;

  /// Shadow map layers of the lights in the block (6 per point light or VPL).
  int layerCount() const;

  /// Builds the block (punctual lights, then area lights or VPLs) and
  /// uploads it: the step that reads the scene's emission, emissive texels
  /// included. @throws InputError past LO_MAX_LIGHTS.
  void build(const Scene& scene, const RenderSpace& space, const RendererParams& params);

  /// Allocates the shadow maps of the built block and renders each once,
  /// drawing `draw`'s depth-only geometry with the vertex array `vao`.
  template <class DrawDepthOnly>
  void createShadowMaps(GLuint vao, const DrawDepthOnly& draw) {
    allocateShadowMaps();
    renderShadowMaps(vao, draw);
  }

  /// Refits the directional lights' cascades to a camera (render space) and
  /// re-renders those layers, unless the camera is the last one fitted or
  /// the matrices are unchanged. `fits`: how many cameras the frame fits
  /// them to (the probe's six faces), whose fill together keeps to the
  /// budget.
  template <class DrawDepthOnly>
  void fitCascades(const RenderSpace& space, const glm::vec3& eye, const glm::vec3& forward,
                   const glm::vec3& up, float yfov, float aspect, float znear, float zfar, int fits,
                   GLuint vao, const DrawDepthOnly& draw) {
    if (sunLights.empty()) return;
    const std::array<float, 12> key = {eye.x, eye.y, eye.z, forward.x, forward.y, forward.z,
                                       up.x,  up.y,  up.z,  yfov,      aspect,    znear};
    if (key == fittedCamera) return;
    fittedCamera = key;
    if (fitCascadeMatrices(space, eye, forward, yfov, aspect, znear, zfar, fits)) {
      renderCascades(vao, draw);
    }
  }

  /// Draws every shadow map again (a caster moved): the lights' now, the
  /// sun's cascades at the next fitCascades.
  template <class DrawDepthOnly>
  void redrawShadowMaps(GLuint vao, const DrawDepthOnly& draw) {
    renderShadowMaps(vao, draw);
    fittedCamera = {};
  }

 private:
  void allocateShadowMaps();
  /// Binds the shadow framebuffer and the shadow program for depth-only
  /// draws at the maps' size; returns the framebuffer bound before.
  GLint beginShadowPass(GLuint vao);
  void endShadowPass(GLint previous, const char* what);
  /// Points the shadow framebuffer at `layer` and clears it; the program's
  /// view-projection is that layer's matrix.
  void beginLayer(int layer, bool checkComplete);
  /// The shadow program leaves out fragments inside [lower, upper] (empty
  /// when lower > upper).
  void setIgnoredBox(const glm::vec3& lower, const glm::vec3& upper) {
    glUniform3fv(glGetUniformLocation(shadowProgram.get(), "uIgnoreLower"), 1,
                 glm::value_ptr(lower));
    glUniform3fv(glGetUniformLocation(shadowProgram.get(), "uIgnoreUpper"), 1,
                 glm::value_ptr(upper));
  }
  /// Fits the cascades to the camera and uploads their matrices; returns
  /// whether any changed. Cascades whose fitted maps the scene would cover,
  /// times `fits`, past the fill budget cover the whole scene instead, whose
  /// fill build() budgeted and which no camera changes (stacked floors under
  /// a sun: seven drawings for a frame and its probe, 13 s, H13-5-22).
  bool fitCascadeMatrices(const RenderSpace& space, const glm::vec3& eye, const glm::vec3& forward,
                          float yfov, float aspect, float znear, float zfar, int fits);
  /// The slices and their matrices in the block (not uploaded); `whole`:
  /// every slice covers the whole scene.
  void fitCascadeSlices(const RenderSpace& space, const glm::vec3& eye, const glm::vec3& forward,
                        float yfov, float aspect, float znear, float zfar, bool whole);
  /// Texels one drawing of the cascades at their matrices covers, counted on
  /// cascadeSample.
  double cascadeFill() const;

  template <class DrawDepthOnly>
  void renderShadowMaps(GLuint vao, const DrawDepthOnly& draw) {
    const GLint previous = beginShadowPass(vao);
    for (int i = 0; i < block.uLightCount[0]; ++i) {
      const GpuLight& l = block.uLights[i];
      if (l.params[2] < 0) continue;
      glUniform3fv(glGetUniformLocation(shadowProgram.get(), "uLightPosition"), 1,
                   glm::value_ptr(l.positionType));
      glUniform1f(glGetUniformLocation(shadowProgram.get(), "uFar"), l.colorFar[3]);
      // An area light's own box casts no shadow on it (its centre may lie
      // inside its triangles: a glowing cube); other lights ignore nothing.
      const bool area = int(l.positionType[3]) == shader::LO_LIGHT_AREA;
      setIgnoredBox(area ? glm::vec3(l.corner0) : glm::vec3(1.0f),
                    area ? glm::vec3(l.corner1) : glm::vec3(0.0f));
      const int layers = shadowLayersOf(int(l.positionType[3]));
      for (int f = 0; f < layers; ++f) {
        beginLayer(int(l.params[2]) + f, true);
        // Transmissive surfaces cast no shadow (light passes; not tinted).
        draw(shadowProgram.get(), true);
      }
    }
    endShadowPass(previous, "rendering the shadow maps");
  }

  template <class DrawDepthOnly>
  void renderCascades(GLuint vao, const DrawDepthOnly& draw) {
    const GLint previous = beginShadowPass(vao);
    glUniform1f(glGetUniformLocation(shadowProgram.get(), "uFar"), 0.0f);
    setIgnoredBox(glm::vec3(1.0f), glm::vec3(0.0f));
    for (int light : sunLights) {
      const GpuLight& l = block.uLights[light];
      for (int c = 0; c < shader::LO_SUN_CASCADES; ++c) {
        beginLayer(int(l.params[2]) + c, false);
        draw(shadowProgram.get(), true);
      }
    }
    endShadowPass(previous, "rendering the cascaded shadow maps");
  }

 public:
  /// Shadow map layers a light of shader type `type` takes: a cube (6) for
  /// lights that shine all around a point, one per cascade for directional
  /// lights, one for spot lights.
  static int shadowLayersOf(int type);
};

}  // namespace lo::render_internal
